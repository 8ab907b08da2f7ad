"""``optimal.solve``: minimum-time motion along a path with certified bounds.

Pipeline (one pure function, no state kept between calls):

1. validate (bound set, feeds, limits for every axis);
2. piece-aware initial grid (:mod:`optimal.grid`; nodes spread by length on curved
   segments, two intervals per line, where both bounds are exact at any length);
3. repeat: build the grid problem (:mod:`optimal.problem`), solve it with the chosen
   backend, verify its profile with ``check_profile`` and time-scale it (upper bound),
   solve the relaxation (lower bound, :mod:`optimal.bounds`); stop when
   ``(upper - lower) / lower <= tol``; otherwise cut the intervals that carry the gap
   into 2, 4 or 8 pieces, the cuts with the best predicted gain per new point first
   (and halve the arc intervals of blocks where the checker found the grid profile too
   fast), and go on, up to ``max_grid`` intervals;
4. report the best bounds seen (both stay valid on every grid), the accepted profile,
   times per segment and per NC block, and the active constraint along the path.

Units: mm, s.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from functools import partial
from typing import Callable, Mapping

import numpy as np

from reference.core.constraints import BOUND_SETS, ConstraintReport
from reference.core.errors import InfeasibleError
from reference.core.geometry import Path
from reference.core.holds import DWELL_CAUSE, Holds, dwell_holds, with_holds
from reference.core.limits import MachineLimits
from reference.core.profile import Profile
from reference.core.rows import BlockRow, block_motion, block_rows

from .backends import DEFAULT_BACKEND, get_backend
from .bounds import lower_bound, node_bounds_on
from .grid import Grid, initial_grid, subdivide
from .problem import (CAP_ACCELERATION, CAP_FEED, CAP_NAMES, CAP_VELOCITY, DiscreteProblem,
                      DiscreteResult, acceleration_slopes, build_grid_problem, check_feed,
                      interval_geometry, interval_times, slopes_keep_positive)
from .solution import IterationRecord, OptimalSolution
from .upper import line_phase_times, line_tents, upper_interval_times, verified_profile
from .status import SolveStatus
from .jerk.tolerances import DEFAULT_JERK_GAP_TOL
from .freq.oracle import DEFAULT_FREQ_GAP_TOL
from .tolerances import (ACTIVE_TOL_REL, DEFAULT_GAP_TOL, DEFAULT_INITIAL_INTERVALS,
                         DEFAULT_MAX_GRID, DEFAULT_MAX_ITERATIONS, LB_ROUNDS,
                         LB_ROUNDS_PIECES, LB_ROUNDS_WARM, LB_SUB_PIECES, REFINE_MAX_PIECES,
                         REFINE_RESIDUAL, REFINE_TARGET, SLOPE_SOLVES)

SUPPORTED_BOUNDS = ("acc", "jerk", "acc+freq", "jerk+freq")

ProgressFn = Callable[[str, float], None]

# the result types live in optimal.solution; re-exported here for existing imports
__all__ = ["BlockRow", "IterationRecord", "OptimalSolution", "SUPPORTED_BOUNDS",
           "active_labels", "solve"]


# --------------------------------------------------------------------------- loop state
@dataclass(frozen=True, slots=True, eq=False)
class _Candidate:
    """The best verified round so far: everything the final result is built from.

    Attributes
    ----------
    upper_bound_s : float
        Duration of the verified profile plus the imposed holds, s.
    grid : Grid
        The grid of that round.
    labels : tuple[str, ...]
        The constraint active on each interval of its grid problem
        (:func:`active_labels`; the problem itself is not kept: it is the largest object
        of a round).
    result : DiscreteResult
        The backend's solution of the grid problem.
    profile : Profile
        The grid profile after time scaling (the one ``check_profile`` accepted),
        without the holds.
    time_scale : float
        Factor ``lam >= 1`` the grid profile was slowed down by.
    report : ConstraintReport
        The checker's report on the grid profile before time scaling.
    interval_times_s : numpy.ndarray, shape (N,)
        Time of the unscaled grid profile on each grid interval, s.
    phases : _LinePhases
        The phases of the line intervals' tents and their constraints
        (:func:`_line_phases`).
    """

    upper_bound_s: float
    grid: Grid
    labels: tuple[str, ...]
    result: DiscreteResult
    profile: Profile
    time_scale: float
    report: ConstraintReport
    interval_times_s: np.ndarray
    phases: "_LinePhases"


@dataclass(frozen=True, slots=True, eq=False)
class _LinePhases:
    """Accelerate, cruise and brake on the line intervals of a grid solution.

    Attributes
    ----------
    line : numpy.ndarray of int, shape (L,)
        The line intervals.
    times_s : numpy.ndarray, shape (L, 3)
        Unscaled time of each phase, s.
    labels : numpy.ndarray of object, shape (L, 3)
        The constraint that sets each phase: ``"acceleration <axis>"`` on the ramps,
        ``"feed"`` or ``"velocity <axis>"`` while cruising.
    """

    line: np.ndarray
    times_s: np.ndarray
    labels: np.ndarray


@dataclass(frozen=True, slots=True, eq=False)
class _WarmStart:
    """The last relaxation, kept to give the next (finer) grid valid node bounds
    (:func:`optimal.bounds.node_bounds_on`).

    Attributes
    ----------
    grid : Grid
        Grid of the relaxation.
    b_hat : numpy.ndarray, shape (N + 1,)
        Its optimum at the nodes, mm^2/s^2.
    b_bar : numpy.ndarray, shape (N,)
        Its bound inside each interval, mm^2/s^2.
    """

    grid: Grid
    b_hat: np.ndarray
    b_bar: np.ndarray


# --------------------------------------------------------------------------- helpers
def _block_name(path: Path, blk: int) -> str:
    span = next((b for b in path.blocks if b.block == blk), None)
    if span is None:
        return f"block {blk}"
    lab = f", {span.label}" if span.label else ""
    return f"block {blk} (line {span.line}{lab})"


def active_labels(problem: DiscreteProblem, b: np.ndarray) -> tuple[str, ...]:
    """Which constraint is tight on each interval of a solved grid problem.

    Parameters
    ----------
    problem : DiscreteProblem
        The grid problem.
    b : numpy.ndarray, shape (N + 1,)
        Its solution.

    Returns
    -------
    tuple[str, ...]
        Length ``N``: ``"feed"``, ``"velocity X"``, ``"acceleration X"``,
        ``"velocity_jump"``, ``"stop"`` or ``"none"``.
    """
    axes = tuple(problem.axes)
    n_ax = len(axes)
    cap = problem.cap
    tight_node = np.where(cap > 0, b >= cap * (1 - ACTIVE_TOL_REL), b <= 0)
    # every label once; intervals pick indices into this table (one pass, no loop per
    # interval): node caps by (code, axis), then "acceleration <axis>" rows, then "none"
    names = sorted(CAP_NAMES)
    table = [f"{CAP_NAMES[c]} {axes[a]}" if c in (CAP_VELOCITY, CAP_ACCELERATION) and a >= 0
             else CAP_NAMES[c] for c in names for a in range(-1, n_ax)]
    row_base, none_idx = len(table), len(table) + n_ax
    table += [f"acceleration {a}" for a in axes] + ["none"]
    code = np.asarray(problem.cap_code, dtype=np.int64)
    cap_axis = np.asarray(problem.cap_axis, dtype=np.int64)
    node_idx = (np.searchsorted(names, code) * (n_ax + 1)
                + np.clip(cap_axis, -1, n_ax - 1) + 1)

    lhs = problem.c1 * b[:-1, None] + problem.c2 * b[1:, None]
    scale = np.abs(problem.c1 * b[:-1, None]) + np.abs(problem.c2 * b[1:, None]) + problem.h
    used = (problem.c1 != 0) | (problem.c2 != 0)
    tight_row = used & (lhs >= problem.h - ACTIVE_TOL_REL * scale)
    any_row = tight_row.any(axis=1)
    first_row = np.argmax(tight_row, axis=1)
    row_axis = np.asarray(problem.row_axis, dtype=np.int64)
    c0, c1 = code[:-1], code[1:]
    steady = (np.isin(c0, (CAP_FEED, CAP_VELOCITY, CAP_ACCELERATION))
              & tight_node[:-1] & tight_node[1:] & (c0 == c1)
              & (cap_axis[:-1] == cap_axis[1:]))
    idx = np.select(
        [steady, any_row, tight_node[1:], tight_node[:-1]],
        [node_idx[:-1], row_base + (row_axis[first_row] if row_axis.size
                                    else np.zeros_like(first_row)),
         node_idx[1:], node_idx[:-1]],
        default=none_idx)
    return tuple(np.asarray(table, dtype=object)[idx].tolist())


def _line_phases(work: Path, lim, grid: Grid, b: np.ndarray, tents) -> _LinePhases:
    """The phases of the tents on the line intervals (:func:`optimal.upper.grid_profile`)
    and the constraint of each: on a line the ramps run at the path acceleration of the
    axis with the smallest ``A_j / |u_j|``, the cruise at the smaller of the feed and the
    axis velocity caps ``V_j / |u_j|`` (``u`` the unit direction)."""
    line, times = line_phase_times(grid.s, b, tents)
    seg = grid.segment[line]
    u = np.abs(work.d[seg])
    axes = np.asarray(work.axes, dtype=object)
    with np.errstate(divide="ignore"):
        inv = np.where(u > 0, 1.0 / np.where(u > 0, u, 1.0), np.inf)
    acc_ax = np.argmin(lim.a_max[None, :] * inv, axis=1)
    vel = lim.v_max[None, :] * inv
    vel_ax = np.argmin(vel, axis=1)
    feed = work.feed[seg] <= vel[np.arange(seg.size), vel_ax]
    ramp = np.char.add("acceleration ", axes[acc_ax].astype(str)).astype(object)
    cruise = np.where(feed, "feed",
                      np.char.add("velocity ", axes[vel_ax].astype(str))).astype(object)
    return _LinePhases(line, times, np.stack([ramp, cruise, ramp], axis=1))


def _with_phases(labels: tuple[str, ...], phases: _LinePhases) -> tuple[str, ...]:
    """Interval labels where a line interval takes the label of its longest phase (its
    node caps only bound the tent's ends)."""
    if phases.line.size == 0:
        return labels
    out = np.asarray(labels, dtype=object)
    pick = np.argmax(phases.times_s, axis=1)
    out[phases.line] = phases.labels[np.arange(pick.size), pick]
    return tuple(out.tolist())


def _refine_marks(path: Path, grid: Grid, t_prim: np.ndarray, t_lb: np.ndarray, lam: float,
                  report: ConstraintReport | None, budget: int, target_s: float
                  ) -> np.ndarray:
    """Into how many equal pieces (1, 2, 4, ... :data:`REFINE_MAX_PIECES`) to cut every
    interval.

    Prediction model: an interval cut into ``2^l`` pieces keeps about
    ``REFINE_RESIDUAL^l`` of its share of the gap (grid time minus lower-bound time).
    Each cut of a level costs ``2^(l - 1)`` new intervals and gains
    ``d REFINE_RESIDUAL^(l - 1) (1 - REFINE_RESIDUAL)``; the cuts with the best gain per
    new interval are taken (for each interval the gains per interval fall level by
    level, so the order takes its levels in turn) until the predicted gap reaches
    ``target_s``, within ``budget`` new intervals: a gap spread evenly over the path is
    halved everywhere, one carried by a few intervals is cut finer there, and both
    predicted to land in one round. Plus the arc intervals of blocks where the checker
    needed time scaling.
    """
    N = grid.n_intervals
    level = np.zeros(N, dtype=np.int64)
    d = np.maximum(lam * t_prim - t_lb, 0.0)
    disc = np.maximum(t_prim - t_lb, 0.0)
    total = float(disc.sum())
    need = total - max(target_s, 0.0)
    n_lev = int(REFINE_MAX_PIECES).bit_length() - 1
    if need > 0 and budget > 0 and n_lev > 0:
        R = REFINE_RESIDUAL
        lev = np.arange(n_lev)
        gain = disc[:, None] * (R ** lev * (1.0 - R))[None, :]         # (N, L)
        cost = np.broadcast_to(2.0 ** lev, gain.shape)
        order = np.argsort(-(gain / cost).ravel(), kind="stable")
        cum_gain = np.cumsum(gain.ravel()[order])
        cum_cost = np.cumsum(cost.ravel()[order])
        n_take = min(int(np.searchsorted(cum_gain, need)) + 1,
                     int(np.searchsorted(cum_cost, budget, side="right")))
        taken = order[:n_take] // n_lev
        level = np.bincount(taken, minlength=N).astype(np.int64)
    pieces = np.left_shift(1, level)
    scale_part = (lam - 1.0) * float(t_prim.sum())
    if report is not None and lam > 1.0 and scale_part > 0.2 * float(d.sum()):
        power = {"velocity": 1, "feed": 1, "velocity_jump": 1, "acceleration": 2}
        bad_blocks = set()
        extra = np.zeros(N, bool)
        for name, pw in power.items():
            br = np.asarray(report.block_ratios.get(name, np.zeros(0)))
            thr = 1.0 + 0.5 * (lam ** pw - 1.0)
            bad_blocks.update(np.flatnonzero(br > thr).tolist())
            w = report.worst(name)
            if w.ratio > 1.0:
                k = int(np.clip(np.searchsorted(grid.s, w.s) - 1, 0, N - 1))
                extra[max(k - 2, 0):k + 3] = True
        if bad_blocks:
            blk = path.block[grid.segment]
            arc = path.radius[grid.segment] > 0
            extra |= np.isin(blk, list(bad_blocks)) & arc
        pieces = np.where(extra, np.maximum(pieces, 2), pieces)
    # the budget: keep the cuts of the largest carriers of the (scaled) gap
    if int((pieces - 1).sum()) > budget:
        idx = np.flatnonzero(pieces > 1)
        keep = idx[np.argsort(-d[idx], kind="stable")]
        room = np.cumsum(pieces[keep] - 1) <= max(budget, 0)
        pieces[keep[~room]] = 1
    return pieces


def _dwell_part(holds: Holds) -> float:
    return float(sum(d for d, c in zip(holds.duration_s, holds.cause) if c == DWELL_CAUSE))


def _empty_solution(path: Path, limits: MachineLimits, t0: float, backend: str,
                    holds: Holds) -> OptimalSolution:
    total = holds.total_s
    prof = with_holds(Profile(t=[0.0], s=[0.0], v=[0.0], a=[], j=[], block=[]), path, holds)
    n_blocks = (max(b.block for b in path.blocks) + 1) if path.blocks else 0
    bt = prof.block_times(path) if path.blocks else np.zeros(0)
    rows = block_rows(path, block_motion(path, prof), [b.stop_reason for b in path.blocks],
                      _hold_per_span(path, holds))
    return OptimalSolution(
        status=SolveStatus.OPTIMAL, profile=prof, lower_bound_s=total, upper_bound_s=total,
        objective_s=total, gap=0.0, time_scale=1.0, segment_times_s=np.zeros(0),
        block_times_s=np.asarray(bt if n_blocks else np.zeros(0)), blocks=rows,
        grid=np.zeros(1), active=(), grid_points=1, iterations=0, backend=backend,
        build_time_s=0.0, solve_time_s=0.0, check_time_s=0.0, bound_time_s=0.0,
        total_time_s=time.perf_counter() - t0, dwell_s=_dwell_part(holds),
        message="path without motion: time = hold time", holds=holds)


# --------------------------------------------------------------------------- solve
def solve(path: Path, limits: MachineLimits, bounds: str = "acc", *,
          tol: float | None = None, backend: str = DEFAULT_BACKEND,
          backend_options: Mapping[str, object] | None = None,
          max_grid: int = DEFAULT_MAX_GRID, max_iterations: int = DEFAULT_MAX_ITERATIONS,
          initial_intervals: int | None = None,
          progress: ProgressFn | None = None, holds: Holds | None = None,
          nlp_backend: str = "ipopt") -> OptimalSolution:
    """Minimum-time motion along ``path`` with a certified lower and a verified upper bound.

    The imposed holds (dwell, exact-stop settle) are no planning decision: the motion is
    optimised without them and they are inserted at their breaks afterwards
    (:func:`reference.core.holds.with_holds`, as the heuristic does), so both bounds and
    the profile contain exactly ``holds.total_s`` of waiting.

    Constraints (bound set ``"acc"``): programmed feed per segment (path speed of the
    geometry axes; none for G0, where only the axes' limits apply), axis velocity, axis
    acceleration including the centripetal part on arcs and helices, rest at
    ``path.stop`` breaks (start, end, exact and forced stops), and at non-tangential
    breaks the axis velocity jump of the machine data (``v <= min_i jump_i /
    |t_out_i - t_in_i|``; with ``MAX_ACCEL_OVL_FACTOR = 1`` the motion stops there).

    Parameters
    ----------
    path : Path
        The path (lines, arcs, helices) with feeds, stops and the block table.
    limits : MachineLimits
        Machine limits; must define every axis of the path.
    bounds : str
        Bound set: ``"acc"`` (velocity and acceleration), ``"acc+freq"`` and
        ``"jerk+freq"`` (also the frequency rule; :func:`optimal.freq.solve_freq`, default
        gap 2 %) or ``"jerk"`` (also axis jerk;
        solved by :func:`optimal.jerk.solve_jerk`, see there; ``backend``,
        ``backend_options``, ``max_grid`` and ``max_iterations`` then apply to the
        ``acc`` solve inside it, ``initial_intervals`` to its NLP grid).
    tol : float, optional
        Requested relative gap ``(upper - lower) / lower`` (default 0.2 % for ``acc``,
        1 % for ``jerk``).
    backend : str
        Backend of the grid problem (``"fast"`` default, ``"highs"``, ``"clarabel"``).
    backend_options : Mapping, optional
        Backend-specific options.
    max_grid : int
        Largest number of grid intervals before giving up with ``"gap_not_met"``.
    max_iterations : int
        Largest number of refinement rounds.
    initial_intervals : int, optional
        Target size of the initial grid (default
        :data:`~optimal.tolerances.DEFAULT_INITIAL_INTERVALS` for ``acc``,
        :data:`~optimal.jerk.tolerances.DEFAULT_JERK_INITIAL_INTERVALS` for ``jerk``).
    progress : callable, optional
        Called as ``progress(stage_message, fraction_done)`` during refinement.
    holds : Holds, optional
        The imposed holds (:func:`reference.holds.imposed_holds`, the same the heuristic
        was given). Default: the dwells of ``path.blocks`` only (no machine data here to
        compute exact-stop settle times).
    nlp_backend : {"ipopt", "scp"}
        ``bounds="jerk"`` only: the solver of the upper bound's NLP
        (:mod:`optimal.jerk.backends`; ``backend`` is the inner ``acc`` solve's).

    Returns
    -------
    OptimalSolution

    Raises
    ------
    ValueError
        Unknown bound set, option or backend; ``tol <= 0``.
    InfeasibleError
        A block with zero feed, or any other problem without a motion (names the block
        and its source line).
    MachineDataError
        An axis of the path has no limits.
    BackendNotFoundError
        The backend's package is not installed (the message says what to install).
    """
    t_start = time.perf_counter()
    if bounds not in BOUND_SETS:
        raise ValueError(f"unknown bound set {bounds!r}; known: {', '.join(BOUND_SETS)}")
    if bounds not in SUPPORTED_BOUNDS:
        raise ValueError(f"bound set {bounds!r} is not supported by the oracle yet "
                         f"(supported: {', '.join(SUPPORTED_BOUNDS)})")
    if tol is None:
        tol = {"jerk": DEFAULT_JERK_GAP_TOL, "acc+freq": DEFAULT_FREQ_GAP_TOL,
               "jerk+freq": DEFAULT_FREQ_GAP_TOL}.get(bounds, DEFAULT_GAP_TOL)
    if not (isinstance(tol, (int, float)) and math.isfinite(tol) and tol > 0):
        raise ValueError(f"tol = {tol!r}: must be a finite number > 0")
    if not (isinstance(max_grid, int) and max_grid >= 2):
        raise ValueError(f"max_grid = {max_grid!r}: must be an int >= 2")
    if not (isinstance(max_iterations, int) and max_iterations >= 1):
        raise ValueError(f"max_iterations = {max_iterations!r}: must be an int >= 1")
    if initial_intervals is not None and not (isinstance(initial_intervals, int)
                                              and initial_intervals >= 1):
        raise ValueError(f"initial_intervals = {initial_intervals!r}: must be an int >= 1")
    if bounds in ("acc+freq", "jerk+freq"):
        # the frequency oracle (optimal.freq) runs the base (and acc) oracles inside
        from .freq import solve_freq
        inner = partial(solve, backend=backend, backend_options=backend_options,
                        max_grid=max_grid, max_iterations=max_iterations,
                        initial_intervals=initial_intervals)
        return solve_freq(path, limits, solve=inner, base=bounds.split("+")[0], tol=tol,
                          holds=holds, progress=progress)
    if bounds == "jerk":
        from .jerk.backends import NLP_BACKENDS
        if nlp_backend not in NLP_BACKENDS:
            raise ValueError(f"nlp_backend = {nlp_backend!r}: unknown "
                             f"(known: {', '.join(NLP_BACKENDS)})")
        # the jerk oracle (optimal.jerk) runs this acc oracle inside, given as a function
        from .jerk import solve_jerk
        # (backend, its options and the grid limits apply to that inner acc solve)
        acc_solve = partial(solve, backend=backend, backend_options=backend_options,
                            max_grid=max_grid, max_iterations=max_iterations)
        return solve_jerk(path, limits, acc_solve=acc_solve, tol=tol, progress=progress,
                          holds=holds, nlp_backend=nlp_backend,
                          **({} if initial_intervals is None
                                          else {"initial_intervals": initial_intervals}))
    solve_fn = get_backend(backend)
    if holds is None:
        holds = dwell_holds(path)
    lim = limits.for_axes(path.axes)
    if path.n_segments == 0:
        if progress:
            progress("no motion", 1.0)
        return _empty_solution(path, limits, t_start, backend, holds)
    check_feed(path)
    hold_t = holds.total_s          # every hold: a constant added to every motion's time
    # grids, rows and bounds on the axes that move (exact: the others have zero
    # derivatives and constrain nothing); the checker judges the profile on the path
    moving = path.moving_axes()
    work = path.restricted(moving) if 0 < moving.size < path.n_axes else path
    lim = limits.for_axes(work.axes)

    if initial_intervals is None:
        initial_intervals = DEFAULT_INITIAL_INTERVALS
    sub_pieces = LB_SUB_PIECES
    # lines get the fewest intervals: both bounds are exact on a line interval
    grid = initial_grid(path, min(initial_intervals, max_grid), lines_by_length=False)
    t_build = t_solve = t_check = t_bound = 0.0
    history: list[IterationRecord] = []
    best: _Candidate | None = None
    best_lb = 0.0
    warm: _WarmStart | None = None
    status = SolveStatus.GAP_NOT_MET
    gaps: list[float] = []     # first gap, for the progress fraction
    frac = 0.0
    it = 0
    for it in range(1, max_iterations + 1):
        # lower bound first (the relaxation is the largest object of a round; it is
        # gone before the grid problem is built): while the grid optimum is farther
        # than tol from it, the gap cannot be met and the checker can wait
        problem = res = None
        te = time.perf_counter()
        b_node = (node_bounds_on(grid, warm.grid, warm.b_hat, warm.b_bar)
                  if warm is not None else None)
        geometry = interval_geometry(work, grid)
        lb, t_lb, rel, b_hat = lower_bound(
            work, lim, grid, b_node=b_node,
            rounds=(LB_ROUNDS_WARM if b_node is not None
                    else LB_ROUNDS_PIECES if sub_pieces > 1 else LB_ROUNDS),
            geometry=geometry,
            sub_pieces=sub_pieces)
        warm = _WarmStart(grid, b_hat, rel.b_bar)
        del rel, b_node
        t_bound += time.perf_counter() - te
        problem, res, gamma, dt_b, dt_s = _solve_grid(work, lim, grid, solve_fn,
                                                      backend_options, geometry)
        del geometry
        t_build += dt_b
        t_solve += dt_s
        if res.status == SolveStatus.INFEASIBLE:
            k = _first_blocked_interval(problem, res)
            blk = int(path.block[grid.segment[k]])
            raise InfeasibleError(f"{_block_name(path, blk)}: no motion reaches "
                                  f"s = {grid.s[k]:.6g}..{grid.s[k + 1]:.6g} mm "
                                  f"({res.message})", blk)
        if res.b is None or res.status not in (SolveStatus.OPTIMAL,
                                               SolveStatus.OPTIMAL_INACCURATE):
            status = SolveStatus.SOLVER_ERROR
            msg = f"backend {backend!r}: {res.status} ({res.message})"
            break
        tents = line_tents(work, lim, grid)
        t_prim = upper_interval_times(grid.s, res.b, gamma, tents)
        t_grid = float(t_prim.sum()) + hold_t
        best_lb = max(best_lb, lb + hold_t)
        budget = min(max_grid - grid.n_intervals, grid.n_intervals)
        last = budget <= 0 or it == max_iterations
        disc_gap = (t_grid - best_lb) / best_lb if best_lb > 0 else math.inf
        new_grid = None
        if not (disc_gap <= tol or last):
            pieces = _refine_marks(path, grid, t_prim, t_lb, 1.0, None, budget,
                                   REFINE_TARGET * tol * best_lb)
            new_grid = subdivide(grid, path, pieces > 1, pieces)
            if new_grid is grid:
                last, new_grid = True, None
        if new_grid is not None:
            history.append(IterationRecord(grid.n_points, lb + hold_t, math.inf, t_grid, 1.0))
            gap = max(disc_gap,
                      (best.upper_bound_s - best_lb) / best_lb if best else disc_gap)
            frac = _report_progress(progress, it, grid, gap, tol, max_grid, frac, gaps)
            grid = new_grid
            continue
        # upper bound: the checker judges the grid profile, time scaling fixes excesses
        block_of = path.block[grid.segment]
        td = time.perf_counter()
        prof, lam, report = verified_profile(path, limits, grid.s, res.b, block_of, bounds,
                                             gamma, tents)
        t_check += time.perf_counter() - td
        ub = prof.duration + hold_t
        if best is None or ub < best.upper_bound_s:
            phases = _line_phases(work, lim, grid, res.b, tents)
            best = _Candidate(upper_bound_s=ub, grid=grid,
                              labels=_with_phases(active_labels(problem, res.b), phases),
                              phases=phases, result=res,
                              profile=prof, time_scale=lam, report=report,
                              interval_times_s=t_prim)
        history.append(IterationRecord(grid.n_points, lb + hold_t, ub, t_grid, lam))
        gap = (best.upper_bound_s - best_lb) / best_lb if best_lb > 0 else math.inf
        frac = _report_progress(progress, it, grid, gap, tol, max_grid, frac, gaps)
        if gap <= tol:
            status = SolveStatus.OPTIMAL
            break
        if last:
            break
        pieces = _refine_marks(path, grid, t_prim, t_lb, lam, report, budget,
                               REFINE_TARGET * tol * best_lb)
        new_grid = subdivide(grid, path, pieces > 1, pieces)
        if new_grid is grid:
            break
        grid = new_grid

    t_total = time.perf_counter() - t_start
    if best is None:
        return OptimalSolution(
            status=SolveStatus.SOLVER_ERROR, profile=None, lower_bound_s=best_lb,
            upper_bound_s=math.inf, objective_s=math.inf, gap=math.inf, time_scale=1.0,
            segment_times_s=np.full(path.n_segments, np.nan), block_times_s=np.zeros(0),
            blocks=(), grid=grid.s, active=(), grid_points=grid.n_points, iterations=it,
            backend=backend, build_time_s=t_build, solve_time_s=t_solve,
            check_time_s=t_check, bound_time_s=t_bound, total_time_s=t_total,
            dwell_s=_dwell_part(holds), history=tuple(history), message=msg, holds=holds)
    ub, g, lam = best.upper_bound_s, best.grid, best.time_scale
    prof_h = with_holds(best.profile, path, holds)
    seg_t = prof_h.segment_times(path)
    blk_t = prof_h.block_times(path)
    labels = best.labels
    rows = _block_rows(path, g, prof_h, labels, lam * best.interval_times_s, holds,
                       best.phases, lam)
    gap = (ub - best_lb) / best_lb if best_lb > 0 else math.inf
    if status == SolveStatus.SOLVER_ERROR:
        message = msg
    elif status == SolveStatus.OPTIMAL:
        message = f"gap {gap:.4%} <= {tol:.4%} on {g.n_points} points"
    else:
        if grid.n_intervals >= max_grid:
            budget = f"grid budget max_grid = {max_grid} intervals reached"
        elif it >= max_iterations:
            budget = f"round budget max_iterations = {max_iterations} reached"
        else:
            budget = "no interval can be split further"
        message = (f"gap {gap:.4%} > {tol:.4%}: {budget} after {it} rounds ({g.n_points} "
                   f"points); bracket [{best_lb:.6g}, {ub:.6g}] s, both bounds are valid")
    if progress:
        progress("done", 1.0)
    return OptimalSolution(
        status=status, profile=prof_h, lower_bound_s=best_lb, upper_bound_s=ub,
        objective_s=float(best.interval_times_s.sum()) + hold_t, gap=gap, time_scale=lam,
        segment_times_s=seg_t, block_times_s=blk_t, blocks=rows, grid=g.s, active=labels,
        grid_points=g.n_points, iterations=it, backend=best.result.backend,
        build_time_s=t_build, solve_time_s=t_solve, check_time_s=t_check,
        bound_time_s=t_bound, total_time_s=time.perf_counter() - t_start,
        dwell_s=_dwell_part(holds), report=best.report, history=tuple(history),
        message=message, holds=holds)


def _solve_grid(work: Path, lim, grid: Grid, solve_fn, options, geometry=None) -> tuple[DiscreteProblem, DiscreteResult, np.ndarray, float, float]:
    """The grid problem with second-order rows (:mod:`optimal.problem`), solved.

    Solve without slopes, estimate the slopes from that solution
    (:func:`optimal.problem.acceleration_slopes`) and solve again with them; where a slope would let ``b`` sag towards 0 inside its interval it
    is dropped and the problem solved once more. Every problem solved is a valid grid
    problem (the checker judges its profile); the slopes only make it accurate.

    Returns
    -------
    problem, result, gamma, build_s, solve_s
        The last problem, its solution, the slopes it used, and the time spent
        building and solving, s.
    """
    t_build = t_solve = 0.0
    res = problem = None
    g = guess = None
    if geometry is None:
        geometry = interval_geometry(work, grid)
    for attempt in range(SLOPE_SOLVES + 2):
        ta = time.perf_counter()
        problem = None              # the previous problem goes before the next is built
        problem = build_grid_problem(work, lim, grid, g, guess, geometry)
        tb = time.perf_counter()
        res = solve_fn(problem, options)
        tc = time.perf_counter()
        t_build += (tb - ta) + res.build_time_s
        t_solve += tc - tb - res.build_time_s
        g = problem.gamma
        if res.b is None or res.status not in (SolveStatus.OPTIMAL,
                                               SolveStatus.OPTIMAL_INACCURATE):
            break
        ok = slopes_keep_positive(grid, res.b, g)
        if not np.all(ok):
            g = np.where(ok, g, 0.0)           # drop the sagging slopes, solve again
            continue
        if attempt + 1 >= SLOPE_SOLVES:
            break
        g, guess = acceleration_slopes(grid, res.b), res.b
    return problem, res, np.asarray(problem.gamma), t_build, t_solve


def _report_progress(progress, it, grid, gap, tol, max_grid, frac, gaps) -> float:
    """Call ``progress`` with a monotone fraction: log-progress of the gap towards tol
    or of the grid towards its limit, whichever is further."""
    if progress is None:
        return frac
    if not gaps:
        gaps.append(max(gap, tol * 1.0001) if math.isfinite(gap) else 1.0)
    g0 = gaps[0]
    done = (math.log(g0 / max(gap, tol)) / math.log(g0 / tol)
            if g0 > tol and math.isfinite(gap) else 0.0)
    frac = max(frac, min(0.99, max(done, grid.n_intervals / max_grid)))
    progress(f"round {it}: {grid.n_points} points, gap {gap:.3%}", frac)
    return frac


def _first_blocked_interval(problem: DiscreteProblem, res: DiscreteResult) -> int:
    if res.b is None:
        return 0
    dt = interval_times(problem.s, res.b)
    bad = np.flatnonzero(~np.isfinite(dt))
    return int(bad[0]) if bad.size else 0


def _block_rows(path: Path, grid: Grid, prof: Profile, labels: tuple[str, ...],
                t_int: np.ndarray, holds: Holds, phases: _LinePhases | None = None,
                lam: float = 1.0) -> tuple[BlockRow, ...]:
    """The oracle's rows: the motion measured on its verified profile (holds included),
    the cause the constraint active for most of the block's grid time (on line
    intervals counted phase by phase: ``phases``, times scaled by ``lam``)."""
    # per block, the label with the largest grid time (ties: the first label in sorted
    # order), by one sort over (block, label) pairs instead of a pass per block
    blk_of_int = path.block[grid.segment]
    labels = np.asarray(labels, dtype=object)
    t_int = np.asarray(t_int, dtype=np.float64)
    if phases is not None and phases.line.size:
        other = np.ones(blk_of_int.size, bool)
        other[phases.line] = False
        blk_of_int = np.concatenate((blk_of_int[other],
                                     np.repeat(blk_of_int[phases.line], 3)))
        labels = np.concatenate((labels[other], phases.labels.ravel()))
        t_int = np.concatenate((t_int[other], lam * phases.times_s.ravel()))
    uniq, code = np.unique(labels.astype(str), return_inverse=True)
    key = blk_of_int * max(uniq.size, 1) + code
    ukey, inv = np.unique(key, return_inverse=True)
    wsum = np.bincount(inv, weights=t_int, minlength=ukey.size)
    kblk, kcode = ukey // max(uniq.size, 1), ukey % max(uniq.size, 1)
    order = np.lexsort((kcode, -wsum, kblk))
    first = np.ones(order.size, bool)
    first[1:] = kblk[order][1:] != kblk[order][:-1]
    best = dict(zip(kblk[order][first].tolist(), uniq[kcode[order][first]].tolist()))
    causes = [(best.get(b.block, "none") if b.n_segments > 0 else b.stop_reason)
              for b in path.blocks]
    return block_rows(path, block_motion(path, prof), causes, _hold_per_span(path, holds))


def _hold_per_span(path: Path, holds: Holds) -> np.ndarray:
    """Imposed hold of every entry of ``path.blocks``, s."""
    if not path.blocks:
        return np.zeros(0)
    idx = np.array([b.block for b in path.blocks], dtype=np.int64)
    return holds.per_block(int(idx.max()) + 1)[idx]
