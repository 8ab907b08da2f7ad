"""Limiting causes: the fixed vocabulary of per-block and per-corner causes.

The comparison report groups blocks by these strings (DESIGN section 7), so they are
spelled exactly as listed; stages store them as small integer codes into :data:`CAUSES`.

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
"""

from __future__ import annotations

CAUSES: tuple[str, ...] = ("feed", "axis velocity", "axis acceleration", "jerk", "frequency",
                           "corner rule", "look-ahead horizon", "IPO-cycle cap",
                           "exact stop", "forced stop", "dwell", "exact stop settle")
(FEED, AXIS_VELOCITY, AXIS_ACCELERATION, JERK, FREQUENCY, CORNER_RULE, HORIZON, IPO_CAP,
 EXACT_STOP, FORCED_STOP, DWELL, EXACT_STOP_SETTLE) = range(len(CAUSES))


def cause_name(code: int) -> str:
    """The cause string of a code."""
    return CAUSES[int(code)]
