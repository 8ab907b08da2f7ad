"""Named numerical tolerances and defaults of the oracle, one per quantity (G7).

Each value says what it means, its unit and why it has that size. Backend-specific
solver tolerances live in :mod:`optimal.backends.tolerances`.
"""

from __future__ import annotations

#: Default requested relative gap ``(upper - lower) / lower`` at which refinement stops
#: (0.2 %, the issue's default).
DEFAULT_GAP_TOL = 2e-3

#: Default largest number of grid intervals before refinement gives up with status
#: ``"gap_not_met"`` (both bounds are still valid then; the message names the budget and
#: the bracket). One interval costs about 1.2 kB at the peak of a solve (measured: 315 MB
#: peak RSS for 10^4 CAM lines and arcs on 134,691 points, 150 MB of it the interpreter
#: and the path), so 10^6 intervals stay near 1.3 GB. The 10^4-piece CAM benchmark ends
#: at 1.3 * 10^5 points, so an ordinary program never meets this cap; ``compare`` derives
#: it from ``--max-grid-points`` instead.
DEFAULT_MAX_GRID = 1_000_000

#: Default largest number of refinement rounds (each at most doubles the grid).
DEFAULT_MAX_ITERATIONS = 40

#: Default number of intervals of the initial grid spread over the path by length (each
#: segment gets at least :data:`MIN_SEGMENT_INTERVALS`, arcs more, see below).
DEFAULT_INITIAL_INTERVALS = 1000

#: Fewest intervals per segment. Two, so that a segment between two stops has a node in
#: its interior where the speed can be positive (one interval with v = 0 at both ends
#: would take infinite time).
MIN_SEGMENT_INTERVALS = 2

#: Fewest intervals per arc or helix of the initial grid. The formulation note (pitfall
#: 1) asks for 8-16 against grids that are not piece-aware, whose time can be 50 % short;
#: here every break is a node, no interval sweeps more than :data:`MAX_ARC_STEP_RAD`, both
#: bounds are certified on any grid and refinement adds points where the bracket is, so
#: the minimum only sizes the start. 4 measured best on the short arcs of CAM output
#: (10^4 alternating lines and 10-40 deg arcs: 36,108 points in one round against 50,001
#: with 8; 10^4 CAM pieces: 129,695 final points against 134,691).
MIN_ARC_INTERVALS = 4

#: Largest angle swept by one interval of the initial grid on an arc, rad (5.625 deg:
#: 16 intervals per quarter turn).
MAX_ARC_STEP_RAD = 0.098174770424681

#: Relative margin taken off the lower bound to absorb float64 round-off in the
#: recurrences and closed-form integrals (their relative error is below 1e-12).
LB_ROUNDOFF_REL = 1e-9

#: A constraint counts as active (tight) at a node or interval when its slack is below
#: this fraction of the constraint's scale.
ACTIVE_TOL_REL = 1e-7

#: Relative precision of the fixed point of the vectorised recurrence (policy
#: iteration stops when no node changes by more than this, relative to the largest
#: finite cap). Well below the 1e-5 agreement demanded between exact methods.
RECURRENCE_RTOL = 1e-12

#: Policy-iteration rounds of the vectorised recurrence before falling back to the
#: sequential (pure Python) sweep, which is exact by construction.
RECURRENCE_MAX_ROUNDS = 60

#: Rows (intervals times row columns) from which the sweep runs compiled
#: (:mod:`optimal.backends.kernel`). The numpy sweep costs about 0.18 us per row
#: (measured on 200 S-bends: 263 ms for 1.5 million rows in 9 sweeps), the compiled one
#: about 25x less but 0.5 s once per process to load numba and the cached kernel; at
#: 10^5 rows one numpy sweep costs 18 ms and a solve of that size runs 5-10 of them on
#: growing grids, so the load is recovered within the solve.
COMPILED_MIN_ROWS = 100_000

#: Chunk length of the blocked prefix scan of clipped affine maps: bounds the size of
#: products of slopes (no overflow) while keeping the Python loop over chunks short.
SCAN_CHUNK = 256

#: Rounds of the lower-bound relaxation on one grid: each bounds ``b`` inside the
#: intervals by the previous round's node values (Gronwall envelope), shrinking the
#: Lipschitz margins where the a-priori bounds are loose (e.g. one axis much stiffer).
LB_ROUNDS = 4

#: Rounds of the relaxation on a grid refined from an earlier one: its node bounds
#: (:func:`optimal.bounds.node_bounds_on`) already play the part of the first round's
#: optimum, and a second round moved the bound by less than 1e-5 (relative) on the
#: S-bend and CAM benchmarks.
LB_ROUNDS_WARM = 1

#: Sub-pieces per curved interval of the lower bound's time estimate
#: (:func:`optimal.bounds.subnode_times`, step 5 of :mod:`optimal.bounds`): the time
#: inside an interval is bounded on this many equal pieces whose inner nodes get energy
#: bounds. Measured on 200 tangent S-bends at 12,213 equal-spaced points (distance of the
#: bound below the converged time): 1 piece 0.285 %, 2 pieces 0.125 %, 4 pieces 0.064 %,
#: 8 pieces about 0.04 %; 4 cost about as much again as the relaxation, and with them the
#: S-bend and 10^4-piece CAM benchmarks (``tests/bench/bench_arcs.py``) need 2 rounds
#: and 13,007 / 89,828 points instead of 3 and 16,991 / 2 and 119,453.
LB_SUB_PIECES = 4
#: Rounds of the relaxation on the first grid when the time estimate uses sub-pieces
#: (:data:`LB_SUB_PIECES` > 1): the second round sharpened the estimate of step 4 alone
#: (by up to 1.4 % on the anisotropic hand cases at 30 intervals), but with the
#: sub-pieces' energy node bounds it moved no bound at all, measured on the corpus and
#: examples on both bundled machines, the arc hand cases of ``tests/optimal`` and
#: ``tests/bench/bench_arcs.py``; it cost 40 % of the relaxation there.
LB_ROUNDS_PIECES = 1
#: Stop the lower-bound rounds when the bound improves by less than this (relative).
LB_ROUND_IMPROVEMENT = 1e-4

#: Most pieces one interval is cut into in one refinement round
#: (``optimal.oracle._refine_marks``); a power of two.
REFINE_MAX_PIECES = 8

#: Share of its gap contribution that an interval keeps, summed over its two halves, after
#: it is halved: the refinement's prediction model (an interval cut into ``2^l`` pieces
#: keeps ``REFINE_RESIDUAL^l``; ``optimal.oracle._refine_marks`` takes the cuts with the
#: best predicted gain per new point). Measured on the S-bend and CAM benchmarks
#: (``tests/bench/bench_arcs.py``) with the energy rows of the lower bound: 0.3-0.4
#: (between the first-order 0.5 and the second-order 0.25); with the sub-piece time
#: estimate of the lower bound 0.35 still lands both in two rounds (0.45: 10 % more
#: points on the CAM case, 0.55: 35 % more).
REFINE_RESIDUAL = 0.35

#: A round refines so that the predicted gap lands at this fraction of the requested one
#: (a margin for the prediction's error: a round that falls just short costs a whole
#: further round, one that overshoots only some grid points).
REFINE_TARGET = 0.7

#: Intervals per chunk of the element-wise envelope computations of the lower bound
#: (:func:`optimal.arc_bounds.lower_envelopes`, :func:`~optimal.arc_bounds.envelope_times`):
#: their temporaries are a few dozen ``(chunk, n + 1)`` float arrays, so 2^16 intervals
#: keep them near 50 MB at any grid size (measured: unchunked they added 690 B per
#: interval to the peak of a solve).
ENVELOPE_CHUNK = 1 << 16

#: Solves of the grid problem per refinement round (:func:`optimal.oracle._solve_grid`):
#: the first without slopes, the second with the slopes estimated from the first
#: solution. The sweep costs a few
#: per cent of a round, and the estimated slopes make the grid optimum second-order
#: accurate where it follows an axis limit along an arc.
SLOPE_SOLVES = 2
