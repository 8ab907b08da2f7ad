"""Stage: stops that only the heuristic makes, and the exact-stop settle time.

Two pure functions:

* :func:`segment_modes` reads the acceleration mode of every segment (BRISK, SOFT, or
  the machine default) and forces rest where the mode changes: "the axes stop between
  the blocks anyway" at a BRISK <-> SOFT change (spec/sinumerik-model.md 5.2). Stops the
  path itself requires (exact stop, dwell, M0/M30, ...) were decided by
  :func:`reference.prepare.prepare` and are only classified here.
* :func:`settle_times` gives the hold at the end of every exact-stop block (G60 modal,
  G9 non-modal) from the block-change criterion (model note section 3):

  - G603 "interpolator end": the next block starts when the set speed is 0: no hold;
  - G601 / G602 "fine / coarse window": a first-order position loop with gain ``Kv``
    (MD32200 POSCTRL_GAIN) lets the following error decay from ``e0`` into the window
    ``w`` (MD36010 STOP_LIMIT_FINE, default 0.01 mm / MD36000 STOP_LIMIT_COARSE,
    default 0.04 mm): ``t_i = max(0, ln(e0_i / w_i) / Kv_i)``, hold = max over the axes
    that move in the block.
  - ``e0`` (following error at interpolator end) is a model choice, the named parameter
    :attr:`PlannerParameters.settle_lag_factor`: ``e0_i = factor * |v_i| / Kv_i`` with
    ``v_i`` the axis speed before the final braking process (the lag ``v/Kv`` of a loop
    without feed-forward). The fine window is smaller, so G601 waits longer than G602,
    and G603 not at all.

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
from ..core.tolerances import MOVING_AXIS_TOL
from .parameters import PlannerParameters


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
              note="DRIVE planned as BRISK (the knee-shaped characteristic above "
                   "ACCEL_REDUCTION_SPEED_POINT is not modelled; its a_max is the bound)"),
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
    mode = np.array([MODE_CODE.get(blocks[int(b)].accel_mode or "", default)
                     for b in path.block], dtype=np.int64)
    jl = JERK_LIMITED[mode] if m else np.zeros(0, bool)
    change = np.zeros(m + 1, dtype=bool)
    if m >= 2:
        change[1:m] = jl[1:] != jl[:-1]
    stop = path.stop | change
    exact = np.zeros(m + 1, dtype=bool)
    es_block = np.full(m + 1, -1, dtype=np.int64)
    if m:
        ends_exact = np.array([blocks[int(b)].exact_stop_here for b in path.block])
        exact[1:] = ends_exact
        es_block[1:] = np.where(ends_exact, path.block, -1)
        g61 = np.array([r.startswith("exact path G61") for r in path.stop_reason])
        exact |= g61
    stop_class = np.where(exact & stop, STOP_EXACT, np.where(stop, STOP_FORCED, STOP_NONE))
    return SegmentModes(mode=mode, stop=stop, stop_class=stop_class, mode_change=change,
                        exact_stop_block=es_block, default_mode=default)


#: Exact-stop window per block-change criterion: AxisSettings field, or None (no wait).
_CRITERION_WINDOW = {"G601": "stop_fine_mm", "G602": "stop_coarse_mm", "G603": None}


def settle_times(program: Program, path: Path, machine: Machine, modes: SegmentModes,
                 v_before_brake: np.ndarray, params: PlannerParameters) -> np.ndarray:
    """Hold time at every break ending an exact-stop block (G601/G602 settling).

    Parameters
    ----------
    program : Program
    path : Path
    machine : Machine
        Axis settings: ``kv_per_s``, ``stop_fine_mm``, ``stop_coarse_mm``.
    modes : SegmentModes
    v_before_brake : numpy.ndarray, shape (m + 1,)
        Path speed at the start of the final braking process into each break, mm/s.
    params : PlannerParameters
        ``settle_lag_factor`` (the e0 model).

    Returns
    -------
    numpy.ndarray, shape (m + 1,)
        Settle time per break, s (0 where no exact stop waits).
    """
    m = path.n_segments
    out = np.zeros(m + 1)
    ks = np.flatnonzero(modes.exact_stop_block >= 0)
    if ks.size == 0 or params.settle_lag_factor == 0.0:
        return out
    settings = [machine.settings_of(a) for a in path.axes]
    kv = np.array([st.kv_per_s for st in settings])
    # axis tangents at the end of the segment before each exact-stop break
    _, dq, _, _ = path.evaluate(path.s_breaks[ks], side="left")
    for row, k in enumerate(ks):
        blk = program.blocks[int(modes.exact_stop_block[k])]
        field = _CRITERION_WINDOW.get(blk.exact_stop_criterion)
        if field is None:
            continue
        window = np.array([getattr(st, field) for st in settings])
        v_axis = np.abs(dq[row]) * v_before_brake[k]
        moving = np.abs(dq[row]) > MOVING_AXIS_TOL
        e0 = params.settle_lag_factor * v_axis / kv
        with np.errstate(divide="ignore"):
            t = np.where(moving & (e0 > window), np.log(e0 / window) / kv, 0.0)
        out[k] = float(t.max()) if t.size else 0.0
    return out
