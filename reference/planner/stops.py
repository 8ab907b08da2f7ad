"""Stage: stops that only the heuristic makes.

:func:`segment_modes` reads the acceleration mode of every segment (BRISK, SOFT, or the
machine default) and forces rest where the mode changes: "the axes stop between the
blocks anyway" at a BRISK <-> SOFT change (spec/sinumerik-model.md 5.2). Stops the path
itself requires (exact stop, dwell, M0/M30, ...) were decided by
:func:`reference.prepare.prepare` and are only classified here. The waits at those
stops (dwell, exact-stop settle) are not the heuristic's:
:func:`reference.holds.imposed_holds` computes them for every side alike.

The acceleration modes form the dispatch table :data:`ACCEL_MODES`: every later stage
asks the table (jerk-limited or not, which bound set, which acceleration factor) instead
of branching on mode names.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.geometry import Path
from ..machine import Machine
from ..nc.program import Program


@dataclass(frozen=True, slots=True)
class AccelMode:
    """How one group-21 acceleration mode plans.

    Attributes
    ----------
    name : str
        ``"BRISK"``, ``"SOFT"`` or ``"DRIVE"``.
    jerk_limited : bool
        True: 7-phase S-curves with the path jerk; False: trapezoids (jerk = inf).
    bound_set : str
        Constraint set of :data:`reference.core.constraints.BOUND_SETS` this mode keeps.
    uses_soft_accel_factor : bool
        MD32433 SOFT_ACCEL_FACTOR scales the axis acceleration in this mode.
    note : str
        Modelling note for the stage trace ("" if none).
    """

    name: str
    jerk_limited: bool
    bound_set: str
    uses_soft_accel_factor: bool
    note: str = ""


#: The dispatch table of acceleration modes (codes are indices into this tuple).
ACCEL_MODES: tuple[AccelMode, ...] = (
    AccelMode("BRISK", jerk_limited=False, bound_set="acc", uses_soft_accel_factor=False),
    AccelMode("SOFT", jerk_limited=True, bound_set="jerk", uses_soft_accel_factor=True),
    AccelMode("DRIVE", jerk_limited=False, bound_set="acc", uses_soft_accel_factor=False,
              note="DRIVE: trapezoids with the knee-shaped characteristic above "
                   "ACCEL_REDUCTION_SPEED_POINT (MD35220/35230/35240, "
                   "reference.planner.drive); the oracle accelerates with MAX_AX_ACCEL, so "
                   "the gap includes the reduction"),
)
MODE_CODE = {m.name: i for i, m in enumerate(ACCEL_MODES)}
JERK_LIMITED = np.array([m.jerk_limited for m in ACCEL_MODES])

#: Stop classes of a break (index into STOP_CAUSES).
STOP_NONE, STOP_EXACT, STOP_FORCED = 0, 1, 2


@dataclass(frozen=True, slots=True, eq=False)
class SegmentModes:
    """Acceleration mode per segment and the stops of every break.

    Attributes
    ----------
    mode : numpy.ndarray of int, shape (m,)
        Index into :data:`ACCEL_MODES`.
    stop : numpy.ndarray of bool, shape (m + 1,)
        Rest required at break ``k`` (path stops plus mode changes).
    stop_class : numpy.ndarray of int, shape (m + 1,)
        ``STOP_EXACT`` (G60/G9/G61 exact stop), ``STOP_FORCED`` (anything else) or
        ``STOP_NONE``.
    mode_change : numpy.ndarray of bool, shape (m + 1,)
        Breaks where BRISK and SOFT meet (a forced stop made by the heuristic).
    exact_stop_block : numpy.ndarray of int, shape (m + 1,)
        The NC block whose exact stop ends at break ``k`` (-1 if none).
    default_mode : int
        The machine's default mode (index into :data:`ACCEL_MODES`).
    """

    mode: np.ndarray
    stop: np.ndarray
    stop_class: np.ndarray
    mode_change: np.ndarray
    exact_stop_block: np.ndarray
    default_mode: int

    @property
    def jerk_limited(self) -> np.ndarray:
        """True per segment when its mode plans jerk-limited profiles."""
        return JERK_LIMITED[self.mode]

    @property
    def bound_set(self) -> str:
        """``"jerk"`` when every segment is jerk-limited, else ``"acc"`` (a BRISK segment
        has acceleration steps by design). Without segments: the default mode's set."""
        if not self.mode.size:
            return ACCEL_MODES[self.default_mode].bound_set
        return "jerk" if np.all(self.jerk_limited) else "acc"


def segment_modes(program: Program, path: Path, machine: Machine) -> SegmentModes:
    """Acceleration mode per segment and the stops at every break.

    Parameters
    ----------
    program : Program
        The parsed program (block modes: ``accel_mode``, ``exact_stop_here``).
    path : Path
        Its path.
    machine : Machine
        For the default acceleration mode (``channel.acceleration_mode``).

    Returns
    -------
    SegmentModes
    """
    m = path.n_segments
    default = MODE_CODE[machine.channel.acceleration_mode]
    blocks = program.blocks
    # per program block, then per segment (a block may have several segments)
    mode_of = np.array([MODE_CODE.get(blk.accel_mode or "", default) for blk in blocks],
                       dtype=np.int64)
    mode = mode_of[path.block] if m else np.zeros(0, dtype=np.int64)
    jl = JERK_LIMITED[mode] if m else np.zeros(0, bool)
    change = np.zeros(m + 1, dtype=bool)
    if m >= 2:
        change[1:m] = jl[1:] != jl[:-1]
    stop = path.stop | change
    exact = np.zeros(m + 1, dtype=bool)
    es_block = np.full(m + 1, -1, dtype=np.int64)
    if m:
        ends_exact = np.array([blk.exact_stop_here for blk in blocks], dtype=bool)[path.block]
        exact[1:] = ends_exact
        es_block[1:] = np.where(ends_exact, path.block, -1)
        # G61 exact path stops (looked at only where the motion stops: ``exact`` counts
        # nowhere else)
        at = np.flatnonzero(stop)
        exact[at] |= np.array([path.stop_reason[k].startswith("exact path G61")
                               for k in at.tolist()], dtype=bool)
    stop_class = np.where(exact & stop, STOP_EXACT, np.where(stop, STOP_FORCED, STOP_NONE))
    return SegmentModes(mode=mode, stop=stop, stop_class=stop_class, mode_change=change,
                        exact_stop_block=es_block, default_mode=default)
