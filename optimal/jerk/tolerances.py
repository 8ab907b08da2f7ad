"""Named tolerances and defaults of the jerk oracle (:mod:`optimal.jerk`), one per quantity.

Each value says what it means, its unit and why it has that size.
"""

from __future__ import annotations

#: Default requested relative gap ``(upper - lower) / lower`` of ``bounds="jerk"`` (1 %,
#: the issue's target; the acc oracle's 0.2 % is out of reach while the lower bound on
#: curved paths is the acc relaxation's).
DEFAULT_JERK_GAP_TOL = 1e-2

#: Target number of intervals of the first grid (NLP and relaxation alike), spread by
#: length (arcs and short segments get more, see :func:`optimal.jerk.oracle.jerk_grid`).
#: Refinement then adds nodes only where the bracket is. Measured on the corpus and the
#: examples (SOFT default machine): 300 reached 1 % 1.1-3x faster than 1000 on seven of
#: ten programs, but needed six rounds on a full-circle program that 1000 closed in one;
#: 400 sits between.
DEFAULT_JERK_INITIAL_INTERVALS = 400

#: Fewest NLP intervals per segment on the first grid (a rest-to-rest S-curve has seven
#: constant-jerk phases; eight intervals let a short block come close to it) ...
MIN_JERK_SEGMENT_INTERVALS = 8

#: ... as long as the first grid stays within this many intervals; programs with more
#: segments start with fewer per segment (at least 2) and rely on refinement.
JERK_SHORT_SEGMENT_BUDGET = 4000

#: A segment end gets graded nodes (:func:`optimal.jerk.oracle.graded_nodes`) when the
#: ``acc`` optimum's speed there is below its largest speed on the segment by more than
#: this fraction (5 %: smaller changes take a ramp short enough for the equal spacing).
GRADE_SPEED_CHANGE_REL = 0.05

#: First graded node at ``d * 2**GRADE_FIRST_EXPONENT`` from the end, ``d`` the estimated
#: ramp distance: a quarter of it, so that the first jerk phase (a third to a half of a
#: short ramp) has a node near its end.
GRADE_FIRST_EXPONENT = -2

#: Most graded nodes per segment end (2**16 covers segments 16 000 ramp lengths long).
GRADE_MAX_NODES_PER_END = 16

#: Largest number of NLP grid intervals before refinement stops with ``gap_not_met``.
#: IPOPT's time grows a little faster than linearly in the intervals (banded KKT system,
#: more iterations); 10 000 intervals take some seconds to tens of seconds on one core.
DEFAULT_JERK_MAX_GRID = 10_000

#: Largest number of rounds (each solves the NLP and the relaxation on grids refined
#: where the bracket is).
DEFAULT_JERK_MAX_ROUNDS = 6

#: Smallest interval duration the NLP may choose, in its time unit (a quarter of a typical
#: segment's rest-to-rest time, :func:`optimal.jerk.transcription.problem_units`). Keeps
#: ``j = da/dt`` finite; 1e-9 of it is far below any interval the optimum uses.
MIN_INTERVAL_TIME_REL = 1e-9

#: IPOPT's relative convergence tolerance (``tol``) and constraint violation tolerance
#: (``constr_viol_tol``) in the scaled problem (speeds and accelerations near 1): residuals
#: of 1e-9 become acceleration steps at knots far below the one-cycle jerk allowance
#: ``J T_ipo`` in the checker's RATIO_TOL; anything larger is repaired by time scaling.
IPOPT_TOL = 1e-9

#: IPOPT's attempts, tried in turn until one succeeds: ``(barrier strategy, iteration
#: cap, expand, scaled)``; ``expand`` solves on the scalar (SX) expansion of the MX graph,
#: which costs ten times the build time but follows a different, sometimes better, path;
#: ``scaled`` measures every variable in its own unit and takes the jerk rows times the
#: interval's duration (:mod:`optimal.jerk.backends.ipopt`). Measured on the corpus and the
#: examples (SOFT default machine, 13 programs): monotone first took 193 s in all against
#: 277 s for adaptive first (adaptive wandered for 200 iterations on a 250 mm/min raster
#: that monotone solves in 79, and needed 371 on long arcs at the feed against 171); on
#: sin_cead_arc.mpf monotone on the MX graph failed where the SX graph took 171 iterations.
#: The scaled form solves what no attempt of the plain one did (slow feeds: a 10 mm line
#: at F100 on the default machine, sin_cead_loop.mpf on the LinuxCNC machine, slow lines
#: beside rapid moves) but is not faster where the plain one converges
#: (lcnc_arc_arc_sawtooth, default machine: 106 s against 52 s with it first), so it
#: comes second. A solve that fails every attempt is reported as a solver failure (with
#: the valid lower bound), never as a result.
MU_STRATEGIES = (("monotone", 300, False, False), ("monotone", 300, False, True),
                 ("monotone", 500, True, True), ("adaptive", 200, False, True))

#: Fraction of the acc optimum's speed used as the warm start (a slower start is closer
#: to jerk feasibility, so IPOPT's restoration phase is rarely needed).
WARM_START_SPEED_FRACTION = 0.9

#: Relative margin taken off the lower bound for float64 round-off in the closed forms
#: (their relative error is below 1e-12).
JERK_LB_ROUNDOFF_REL = 1e-9

#: Clarabel's feasibility and gap tolerances for the jerk relaxation
#: (:mod:`optimal.jerk.relaxation`), in its scaled units (speeds^2, accelerations and
#: times near 1). 1e-6 of the bound is a thousandth of the 1 % bracket the jerk oracle
#: aims at; the last decades to 1e-8 cost a third of the iterations (measured on the
#: square and the demo, 52 against 35).
RELAX_SOLVER_TOL = 1e-6

#: Clarabel's iteration cap for the relaxation (it takes 20-40 on the corpus; a run that
#: needs more has stalled and gives no bound, the per-segment floors remain).
RELAX_SOLVER_MAX_ITER = 200

#: Relative margin taken off the relaxation's objective (the smaller of Clarabel's primal
#: and dual values, less also their own relative difference) before it is reported as a
#: lower bound: ten times the solver's tolerance, so that an optimum reported within
#: tolerance is still below the true one. A run ("Solved" or "AlmostSolved") whose primal
#: and dual objectives differ by more than this gives no bound.
RELAX_SOLVER_MARGIN_REL = 1e-5

#: Largest share of the bracket (the verified profile's time on each relaxation interval
#: less the relaxation's own time there) whose carriers are refined in one round, on both
#: grids (:func:`optimal.jerk.oracle._refine_marks`).
JERK_REFINE_SHARE = 0.9

#: Share of its contribution an interval keeps, summed over its halves, after halving:
#: the refinement's prediction (first-order convergence of the relaxation, 0.5).
JERK_REFINE_RESIDUAL = 0.5

#: A round refines so that the predicted bracket lands at this fraction of the tolerance.
JERK_REFINE_TARGET = 0.7
