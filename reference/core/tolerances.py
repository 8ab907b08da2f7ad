"""Named numerical tolerances, one per quantity, with units and the reason for each value.

No other module defines a bare epsilon; each test of a tolerance checks its meaning at
0.5x and 1.5x (tests/core/test_tolerances.py).
"""

from __future__ import annotations

#: Positions closer than this are the same point, mm. A thousandth of the 1 um
#: resolution of a typical linear scale, far above float64 noise on 1 m travels (1e-13 mm).
POS_TOL_MM = 1e-6

#: Path lengths below this add no segment (zero-length block), mm. Same as POS_TOL_MM.
MIN_SEGMENT_LENGTH_MM = POS_TOL_MM

#: Velocities below this count as standstill, mm/s. 1e-6 mm/s moves 4 pm per 4 ms IPO
#: cycle, far below any encoder; above float64 noise of v = sqrt(b) near b = 0 (1e-8).
VEL_TOL_MM_S = 1e-6

#: Two unit tangents are the same direction when the angle between them is below this,
#: rad. A 1e-7 rad kink at 100 m/min changes an axis velocity by 1.7e-4 mm/s, far below
#: the smallest overload allowance (A*(ovl-1)*T_ipo >= 0.01 mm/s for real machine data).
TANGENT_TOL_RAD = 1e-7

#: Arc start and end radius may differ by this much, mm (absolute part). LinuxCNC's
#: rs274ngc uses 0.002 mm; SINUMERIK's MD21000 CIRCLE_ERROR_CONST defaults to 0.01 mm.
#: We take the LinuxCNC value: CAM posts write 3-4 decimals, so 0.002 mm still accepts
#: rounding of the last digit while rejecting wrong centres.
ARC_RADIUS_TOL_MM = 0.002

#: Relative part of the arc radius check (MD21010 CIRCLE_ERROR_FACTOR is 0.001 as well):
#: the accepted difference is max(ARC_RADIUS_TOL_MM, ARC_RADIUS_REL_TOL * radius).
ARC_RADIUS_REL_TOL = 1e-3

#: An arc whose start and end radius differ by more than this (and within the tolerance
#: above) is built as a spiral ending at the programmed point; below it, as the circle on
#: the start radius, which then ends at most this far off, mm. 1e-10 mm is ten times
#: below the 1e-9 mm to which consecutive segments must meet, and above the float64
#: round-off of a radius computed from coordinates of up to 10 m (about 1e-11 mm), so
#: exact arcs stay circles.
ARC_SPIRAL_MIN_MM = 1e-10

#: A constraint counts as violated when value/limit exceeds 1 + RATIO_TOL. 1e-6 is
#: above the float64 round-off of the checker's own arithmetic (about 1e-12) and of
#: solvers' primal feasibility (1e-8 scaled) yet small enough that no real excess hides.
RATIO_TOL = 1e-6

#: Relative agreement demanded between two exact methods on the same discrete problem.
DISCRETE_AGREEMENT_RTOL = 1e-5

#: Relative margin by which a construction stays on the safe side of a shared rule
#: (reference.core.rules): a feasible cap is shrunk by it, a relaxed one grown by it, so
#: two evaluations of the same quantity with different round-off never disagree across
#: the threshold. Observed disagreement: 1e-14 relative (a corner speed set from the
#: standstill floor was measured back at 1.0000000000000105e-06 mm/s); 1e-9 is 1e5 times
#: that and still moves no bound by a measurable amount.
ROUNDOFF_MARGIN_REL = 1e-9

#: Curvature vectors (1/mm; deg/mm^2 for rotary axes) whose components all differ by at
#: most this count as continuous at a segment break (the curvature-jump rule).
#: float64 round-off of q'' (about 1e-16 / r) stays below it for radii above 0.1 um,
#: and a jump that small (radius 10^12 mm) gives no measurable acceleration step.
CURVATURE_JUMP_TOL_PER_MM = 1e-12

#: An axis takes part in a motion when its tangent component can exceed this on the
#: segment (1; deg/mm for rotary axes): a 1e-9 component at 1 m/s moves the axis by
#: 4 pm per IPO cycle.
MOVING_AXIS_TOL = 1e-9

#: Longest time one block's motion may take at its programmed feed, s (length / F).
#: 1e6 s (11.6 days) is no machining move, and keeps profile knot times at magnitudes
#: where float64 resolves the shortest phases the planners build: at 1e6 s the time
#: resolution is 2e-10 s, while a block of 1e10 s (F0.001 mm/min over 1000 m) has
#: 2e-6 s, longer than its own braking phase, and its profile no longer integrates.
#: Same bound as the longest dwell (reference.nc.state.MAX_DWELL_S).
MAX_BLOCK_MOTION_S = 1e6

#: Axis acceleration steps at the knots inside a segment, summed per segment and axis,
#: that a jerk-limited planned motion may carry as round-off, as a fraction of the
#: one-cycle allowance ``j_max * t_ipo`` (reference.core.rules, "acceleration steps").
#: The heuristic's S-curves show at most 2e-8 mm/s^2 per knot (their knots recompute
#: the acceleration from closed forms), against 1e-8 * 40 m/s^3 * 4 ms = 1.6e-6 mm/s^2
#: on the default mill; the jerk lower bound allows for it (optimal.jerk.lower), where
#: it moves the bound by about 1e-10 relative.
ACCEL_CONTINUITY_TOL_REL = 1e-8
