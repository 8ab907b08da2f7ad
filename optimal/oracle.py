"""``optimal.solve``: minimum-time motion along a path with certified bounds.

Pipeline (one pure function, no state kept between calls):

1. validate (bound set, feeds, limits for every axis);
2. piece-aware initial grid (:mod:`optimal.grid`);
3. repeat: build the grid problem (:mod:`optimal.problem`), solve it with the chosen
   backend, verify its profile with ``check_profile`` and time-scale it (upper bound),
   solve the relaxation (lower bound, :mod:`optimal.bounds`); stop when
   ``(upper - lower) / lower <= tol``; otherwise halve the intervals that carry most of
   the gap (and the arc intervals of blocks where the checker found the grid profile too
   fast) and go on, up to ``max_grid`` intervals;
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
from .upper import line_tents, upper_interval_times, verified_profile
from .status import SolveStatus
from .jerk.tolerances import DEFAULT_JERK_GAP_TOL
from .freq.oracle import DEFAULT_FREQ_GAP_TOL
from .tolerances import (ACTIVE_TOL_REL, DEFAULT_GAP_TOL, DEFAULT_INITIAL_INTERVALS,
                         DEFAULT_MAX_GRID, DEFAULT_MAX_ITERATIONS, REFINE_GAP_SHARE,
                         LB_ROUNDS, LB_ROUNDS_WARM, REFINE_RESIDUAL, REFINE_TARGET,
                         SLOPE_SOLVES)

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
    """

    upper_bound_s: float
    grid: Grid
    labels: tuple[str, ...]
    result: DiscreteResult
    profile: Profile
    time_scale: float
    report: ConstraintReport
    interval_times_s: np.ndarray


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
    N = problem.n_intervals
    axes = problem.axes
    cap = problem.cap
    tight_node = np.where(cap > 0, b >= cap * (1 - ACTIVE_TOL_REL), b <= 0)

    def cap_label(k: int) -> str:
        code = int(problem.cap_code[k])
        ax = int(problem.cap_axis[k])
        if code in (CAP_VELOCITY, CAP_ACCELERATION) and ax >= 0:
            return f"{CAP_NAMES[code]} {axes[ax]}"
        return CAP_NAMES[code]

    lhs = problem.c1 * b[:-1, None] + problem.c2 * b[1:, None]
    scale = np.abs(problem.c1 * b[:-1, None]) + np.abs(problem.c2 * b[1:, None]) + problem.h
    used = (problem.c1 != 0) | (problem.c2 != 0)
    tight_row = used & (lhs >= problem.h - ACTIVE_TOL_REL * scale)
    any_row = tight_row.any(axis=1)
    first_row = np.argmax(tight_row, axis=1)
    out = []
    steady = (CAP_FEED, CAP_VELOCITY, CAP_ACCELERATION)
    for k in range(N):
        c0, c1 = int(problem.cap_code[k]), int(problem.cap_code[k + 1])
        if (tight_node[k] and tight_node[k + 1] and c0 == c1 and c0 in steady
                and problem.cap_axis[k] == problem.cap_axis[k + 1]):
            out.append(cap_label(k))
        elif any_row[k]:
            out.append(f"acceleration {axes[int(problem.row_axis[first_row[k]])]}")
        elif tight_node[k + 1]:
            out.append(cap_label(k + 1))
        elif tight_node[k]:
            out.append(cap_label(k))
        else:
            out.append("none")
    return tuple(out)


def _refine_marks(path: Path, grid: Grid, t_prim: np.ndarray, t_lb: np.ndarray, lam: float,
                  report: ConstraintReport | None, budget: int, target_s: float
                  ) -> tuple[np.ndarray, int]:
    """Intervals to refine and into how many pieces (2 or 4).

    The fewest of the largest carriers of the gap whose halving is predicted to bring
    the gap below ``target_s`` (a halved interval keeps about :data:`REFINE_RESIDUAL` of
    its share), at most :data:`REFINE_GAP_SHARE` of it; when halving that share is not
    predicted to be enough, the carriers are quartered instead (keeping about
    ``REFINE_RESIDUAL^2``), which saves a round. Plus the arc intervals of blocks where
    the checker needed time scaling. At most ``budget`` new intervals.
    """
    N = grid.n_intervals
    mark = np.zeros(N, bool)
    pieces = 2
    d = np.maximum(lam * t_prim - t_lb, 0.0)
    disc = np.maximum(t_prim - t_lb, 0.0)
    total = float(disc.sum())
    if total > 0:
        order = np.argsort(-disc, kind="stable")
        cum = np.cumsum(disc[order])
        excess = max(total - max(target_s, 0.0), 0.0)
        share = excess / (1.0 - REFINE_RESIDUAL)
        if share > REFINE_GAP_SHARE * total:
            pieces = 4
            share = min(excess / (1.0 - REFINE_RESIDUAL ** 2), REFINE_GAP_SHARE * total)
        n_take = int(np.searchsorted(cum, share)) + 1
        mark[order[:n_take]] = True
    scale_part = (lam - 1.0) * float(t_prim.sum())
    if report is not None and lam > 1.0 and scale_part > 0.2 * float(d.sum()):
        power = {"velocity": 1, "feed": 1, "velocity_jump": 1, "acceleration": 2}
        bad_blocks = set()
        for name, pw in power.items():
            br = np.asarray(report.block_ratios.get(name, np.zeros(0)))
            thr = 1.0 + 0.5 * (lam ** pw - 1.0)
            bad_blocks.update(np.flatnonzero(br > thr).tolist())
            w = report.worst(name)
            if w.ratio > 1.0:
                k = int(np.clip(np.searchsorted(grid.s, w.s) - 1, 0, N - 1))
                mark[max(k - 2, 0):k + 3] = True
        if bad_blocks:
            blk = path.block[grid.segment]
            arc = path.radius[grid.segment] > 0
            mark |= np.isin(blk, list(bad_blocks)) & arc
    if int(mark.sum()) * (pieces - 1) > budget:
        pieces = 2
    n_mark = int(mark.sum())
    if n_mark > budget:
        idx = np.flatnonzero(mark)
        keep = idx[np.argsort(-d[idx], kind="stable")[:max(budget, 0)]]
        mark[:] = False
        mark[keep] = True
    return mark, pieces


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
    grid = initial_grid(path, min(initial_intervals, max_grid))
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
            rounds=LB_ROUNDS if b_node is None else LB_ROUNDS_WARM, geometry=geometry)
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
            mark, pieces = _refine_marks(path, grid, t_prim, t_lb, 1.0, None, budget,
                                         REFINE_TARGET * tol * best_lb)
            new_grid = subdivide(grid, path, mark, pieces)
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
            best = _Candidate(upper_bound_s=ub, grid=grid,
                              labels=active_labels(problem, res.b), result=res,
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
        mark, pieces = _refine_marks(path, grid, t_prim, t_lb, lam, report, budget,
                                     REFINE_TARGET * tol * best_lb)
        new_grid = subdivide(grid, path, mark, pieces)
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
    rows = _block_rows(path, g, prof_h, labels, lam * best.interval_times_s, holds)
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
                t_int: np.ndarray, holds: Holds) -> tuple[BlockRow, ...]:
    """The oracle's rows: the motion measured on its verified profile (holds included),
    the cause the constraint active for most of the block's grid time."""
    # per block, the label with the largest grid time (ties: the first label in sorted
    # order), by one sort over (block, label) pairs instead of a pass per block
    blk_of_int = path.block[grid.segment]
    uniq, code = np.unique(np.asarray(labels, dtype=str), return_inverse=True)
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
