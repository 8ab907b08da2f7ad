"""Limiting causes: the one vocabulary of per-block and per-corner causes.

The heuristic stores causes as small integer codes into :data:`CAUSES`; the oracle names
its active constraint (``"acceleration X"``, ``"velocity_jump"``, ...) and
:func:`normalise_cause` maps that to the same words; compare derives causes for
profiles that report none and groups blocks by them (DESIGN section 7). The strings
are spelled exactly as listed.

``feed``                programmed F (or the smoothing cap below it: see ``frequency``)
``axis velocity``       MAX_AX_VELO of an axis
``axis acceleration``   MAX_AX_ACCEL: tangential ramps, centripetal acceleration on arcs
``jerk``                MAX_AX_JERK (SOFT ramps that never reach a_max, path jerk on arcs)
                        and PATH_TRANS_JERK_LIM at curvature jumps
``frequency``           LOOKAH_FREQUENCY: velocity smoothing and dynamic adaptation
``corner rule``         G64 overload-factor corner speed (MD32310)
``look-ahead horizon``  v = 0 assumed at the end of the LookAhead horizon
``IPO-cycle cap``       every block needs at least one IPO cycle (v <= L / T_ipo)
``exact stop``          G60 / G9 (NGC G61, G61.1): rest at the block end
``forced stop``         any other rest: program start and end, M0/M1/M2/M30, aux
                        functions without motion, BRISK <-> SOFT change
``dwell``               a G4 block: its whole time is the programmed wait (a hold)
``exact stop settle``   the exact-stop window wait (G601/G602) at a block end (a hold)

The last two are holds (:mod:`reference.holds`): imposed by the program or the machine,
the same on every side, never a planning gap.

Two more words appear in block rows: ``"none"`` (no limit is tight for a meaningful
share of the block's time) and ``"-"`` (a block without motion or time).
"""

from __future__ import annotations

from types import MappingProxyType
from typing import Mapping

CAUSES: tuple[str, ...] = ("feed", "axis velocity", "axis acceleration", "jerk", "frequency",
                           "corner rule", "look-ahead horizon", "IPO-cycle cap",
                           "exact stop", "forced stop", "dwell", "exact stop settle")
(FEED, AXIS_VELOCITY, AXIS_ACCELERATION, JERK, FREQUENCY, CORNER_RULE, HORIZON, IPO_CAP,
 EXACT_STOP, FORCED_STOP, DWELL, EXACT_STOP_SETTLE) = range(len(CAUSES))

#: Row words outside the limit vocabulary.
NO_CAUSE = "none"
NO_TIME = "-"

#: Causes of holds, the waits the program or the machine impose: they enter every
#: profile identically and are no planning decision (not counted in the gap).
HOLD_CAUSES: tuple[str, ...] = (CAUSES[DWELL], CAUSES[EXACT_STOP_SETTLE])

#: Constraint names of the checker and the oracle -> the cause they stand for.
CONSTRAINT_CAUSES: Mapping[str, str] = MappingProxyType({
    "feed": "feed", "velocity": "axis velocity", "acceleration": "axis acceleration",
    "jerk": "jerk", "frequency": "frequency", "velocity_jump": "corner rule"})


def cause_name(code: int) -> str:
    """The cause string of a code."""
    return CAUSES[int(code)]


def stop_cause(reason: str) -> str:
    """The cause of a required rest from its stop reason (``path.stop_reason``)."""
    reason = reason or ""
    if reason.startswith("dwell"):
        return "dwell"
    return "exact stop" if reason.startswith("exact") else "forced stop"


def normalise_cause(label: str, stop_reason: str | None = None,
                    without_motion: bool = False) -> str:
    """A limit label in the shared vocabulary.

    Parameters
    ----------
    label : str
        A cause word (returned as is), or a constraint label such as ``"feed"``,
        ``"velocity X"``, ``"acceleration X"``, ``"velocity_jump"`` or ``"stop"``.
    stop_reason : str, optional
        The block's stop reason, for ``"stop"`` labels and blocks without motion.
    without_motion : bool
        True for a block without motion (its label is its stop reason).

    Returns
    -------
    str
        One of :data:`CAUSES`, ``"none"``, ``"-"``, or the label itself when it is
        none of these (shown as given rather than guessed).
    """
    label = (label or "").strip()
    if not label:
        return NO_TIME
    if label in CAUSES or label in (NO_CAUSE, NO_TIME):
        return label
    head = label.split()[0]
    if head in CONSTRAINT_CAUSES:
        return CONSTRAINT_CAUSES[head]
    if head == "stop" or without_motion:
        return stop_cause(stop_reason or label)
    return label
