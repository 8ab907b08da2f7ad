"""Model parameters of the reference planner where the manuals are silent.

Siemens does not publish the LookAhead algorithm (spec/sinumerik-model.md section 0:
everything tagged [I] is a calibratable model). Every choice the heuristic makes beyond
the machine data is one named field of :class:`PlannerParameters`, with its default and
the reason for it. Machine data (MD/SD values) stay in
:class:`reference.machine.Machine`; this record holds only the *model's* knobs.

It also names the planner's numerical tolerances (guideline G7), one per quantity.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

from ..core.errors import MachineDataError

#: Relative tolerance when deciding whether a speed *reaches* a limit (for the limiting
#: cause of a block or corner), 1. Far above the float64 round-off of the closed-form
#: profiles (1e-12) and far below any physically meaningful speed difference.
CAUSE_REL_TOL = 1e-6

#: Relative mismatch accepted between a segment profile's distance and the segment
#: length before it counts as an internal error, 1 (round-off of the peak solve is
#: about 1e-13; the profile knots are re-anchored to the exact break positions).
DISTANCE_REL_TOL = 1e-9

#: Newton/bisection iterations of the peak-speed solve. The safeguarded Newton method
#: converges quadratically on the C1 distance function; 60 bisection steps alone would
#: already shrink the bracket to 2^-60 of its width.
PEAK_SOLVE_ITERATIONS = 60



@dataclass(frozen=True, slots=True)
class PlannerParameters:
    """Calibration knobs of the heuristic (spec/sinumerik-model.md 12.6), all documented.

    Attributes
    ----------
    arc_centripetal_share : float
        Share of each axis acceleration MAX_AX_ACCEL the centripetal term ``v^2 |q''_i|``
        may use at an arc's speed cap (0 < x < 1). The arc speed is capped at
        ``sqrt(x * A_i / |q''_i|)`` and the tangential acceleration is whatever the
        per-axis vector sum leaves (model note 6.4; LinuxCNC uses 0.75 = 0.866^2).
        Default 0.75.
    arc_jerk_velocity_share : float
        SOFT only: share of the axis jerk that the term ``v^3 |q'''_i|`` (path jerk on
        arcs at constant speed) may use at the arc's speed cap, 0 < x < 1. Default 0.5.
    arc_jerk_accel_share : float
        SOFT only: share of the axis jerk that the term ``3 |q''_i| v a`` may use; the
        tangential acceleration on an arc is lowered until it fits. Default 0.5.
    soft_merge_cap_ratio : float
        SOFT only: consecutive segments are planned as one jerk-limited unit (the
        acceleration continues through the block transition) when the transition does
        not bind and the *effective* caps of the unit stay within this ratio
        (0 < x <= 1). The unit runs at its smallest cap; a segment's effective cap is
        the smaller of its cap and the speed it could reach on its own (rising over
        half of it from its neighbours' caps and falling back), so short blocks, which
        could not use a higher cap anyway, merge freely while long blocks keep their
        own caps. 1.0 merges only equal effective caps. Default 0.95.
    soft_merge_accel_ratio : float
        SOFT only: a break is merged into a unit only if the path acceleration that may
        cross it (axis acceleration steps spread over one IPO cycle within the jerk
        limits, :func:`reference.planner.corners.through_acceleration`) is at least this
        share of the neighbouring segments' acceleration, and the smaller acceleration
        and the smaller jerk of the two segments are at least this share of the larger
        (a unit runs with its smallest: a short curved segment at its cap would
        otherwise slow the ramps on the lines beside it); the unit then accelerates at
        most with that value (0 < x <= 1). Default 0.5.
    smoothing_rounds : int
        LOOKAH_SMOOTH_FACTOR: rounds of bump removal, shortest bumps first; each round
        can merge neighbouring bumps into a larger one. 0 removes none: the bare
        LookAhead, for studies (the control has no such setting: MD20460 = 0 selects
        its internal 100 %). Default 3.
    adaptation_rounds : int
        ADAPT_PATH_DYNAMIC: rounds of "measure process durations, lower the dynamics,
        re-plan". Default 2.
    """

    arc_centripetal_share: float = 0.75
    arc_jerk_velocity_share: float = 0.5
    arc_jerk_accel_share: float = 0.5
    soft_merge_cap_ratio: float = 0.95
    soft_merge_accel_ratio: float = 0.5
    smoothing_rounds: int = 3
    adaptation_rounds: int = 2

    def __post_init__(self) -> None:
        open_unit = ("arc_centripetal_share", "arc_jerk_velocity_share",
                     "arc_jerk_accel_share")
        for f in fields(self):
            val = getattr(self, f.name)
            if f.name in open_unit and not (0.0 < val < 1.0):
                raise MachineDataError(f"planner.{f.name}", val, "must be in (0, 1)")
        for name in ("soft_merge_cap_ratio", "soft_merge_accel_ratio"):
            val = getattr(self, name)
            if not (0.0 < val <= 1.0):
                raise MachineDataError(f"planner.{name}", val, "must be in (0, 1]")
        for name in ("smoothing_rounds", "adaptation_rounds"):
            val = getattr(self, name)
            if not (isinstance(val, int) and val >= 0):
                raise MachineDataError(f"planner.{name}", val, "must be an integer >= 0")


DEFAULT_PARAMETERS = PlannerParameters()
