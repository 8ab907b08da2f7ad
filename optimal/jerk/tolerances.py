"""Named tolerances and defaults of the jerk oracle (:mod:`optimal.jerk`), one per quantity.

Each value says what it means, its unit and why it has that size.
"""

from __future__ import annotations

#: Default requested relative gap ``(upper - lower) / lower`` of ``bounds="jerk"`` (1 %,
#: the issue's target; the acc oracle's 0.2 % is out of reach while the lower bound on
#: curved paths is the acc relaxation's).
DEFAULT_JERK_GAP_TOL = 1e-2

#: Target number of intervals of the first NLP grid, spread by length (arcs and short
#: segments get more, see :func:`optimal.jerk.oracle.jerk_grid`). 1000 keeps the first
#: solve of a corpus program near a second; refinement doubles it while the gap is open.
DEFAULT_JERK_INITIAL_INTERVALS = 1000

#: Fewest NLP intervals per segment on the first grid (a rest-to-rest S-curve has seven
#: constant-jerk phases; eight intervals let a short block come close to it) ...
MIN_JERK_SEGMENT_INTERVALS = 8

#: ... as long as the first grid stays within this many intervals; programs with more
#: segments start with fewer per segment (at least 2) and rely on refinement.
JERK_SHORT_SEGMENT_BUDGET = 4000

#: Largest number of NLP grid intervals before refinement stops with ``gap_not_met``.
#: IPOPT's time grows a little faster than linearly in the intervals (banded KKT system,
#: more iterations); 10 000 intervals take some seconds to tens of seconds on one core.
DEFAULT_JERK_MAX_GRID = 10_000

#: Largest number of NLP solves (each on a grid twice as fine as the last).
DEFAULT_JERK_MAX_ROUNDS = 3

#: Smallest interval duration the NLP may choose, in its time unit (a quarter of a typical
#: segment's rest-to-rest time, :func:`optimal.jerk.transcription.problem_units`). Keeps
#: ``j = da/dt`` finite; 1e-9 of it is far below any interval the optimum uses.
MIN_INTERVAL_TIME_REL = 1e-9

#: IPOPT's relative convergence tolerance (``tol``) and constraint violation tolerance
#: (``constr_viol_tol``) in the scaled problem (speeds and accelerations near 1): residuals
#: of 1e-9 become acceleration steps at knots far below the one-cycle jerk allowance
#: ``J T_ipo`` in the checker's RATIO_TOL; anything larger is repaired by time scaling.
IPOPT_TOL = 1e-9

#: IPOPT's barrier-parameter strategies, tried in turn, each with its iteration cap: the
#: warm-started solves here take 20-130 iterations; adaptive is usually the faster, but
#: on a program with long arcs at the feed it needed 900 iterations where monotone took
#: 30 (sin_cead_arc.mpf), so it gets a short leash. A solve that fails both is reported
#: as a solver failure (with the valid lower bound), never as a result.
MU_STRATEGIES = (("adaptive", 200), ("monotone", 500))

#: Fraction of the acc optimum's speed used as the warm start (a slower start is closer
#: to jerk feasibility, so IPOPT's restoration phase is rarely needed).
WARM_START_SPEED_FRACTION = 0.9

#: Relative margin taken off the lower bound for float64 round-off in the closed forms
#: (their relative error is below 1e-12).
JERK_LB_ROUNDOFF_REL = 1e-9
