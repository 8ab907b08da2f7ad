"""``optimal.solve(..., bounds="jerk")``: the jerk-limited oracle, one pure function.

Pipeline:

1. the ``acc`` oracle on the same path (its lower bound is valid here too, and its final
   grid carries the per-segment ``acc`` relaxation of :mod:`optimal.jerk.lower`);
2. the certified lower bound (:func:`optimal.jerk.lower.jerk_lower_bound`);
3. the jerk NLP on a piece-aware grid (:mod:`optimal.jerk.upper`): solve, verify with
   ``check_profile``, time-scale; while the gap is above ``tol`` and a finer grid still
   can close the gap (extrapolated from the last rounds), solve again on a grid with
   every interval halved;
4. status ``optimal`` when ``(upper - lower) / lower <= tol``, else ``gap_not_met``
   with both (valid) bounds; ``solver_error`` when IPOPT never produced a verified
   profile (then only the lower bound is reported, the upper bound is ``inf``).

Units: mm, s.
"""

from __future__ import annotations

import math
import time
from dataclasses import replace
from typing import Callable

import numpy as np

from reference.core.geometry import Path
from reference.core.holds import DWELL_CAUSE, Holds, dwell_holds, with_holds
from reference.core.limits import MachineLimits
from reference.core.profile import Profile
from reference.core.rows import BlockRow, block_motion, block_rows

from ..grid import Grid, grid_from_counts, initial_counts, split
from ..problem import CAP_NAMES, CAP_ACCELERATION, CAP_VELOCITY
from ..solution import IterationRecord, OptimalSolution
from ..status import SolveStatus
from .lower import jerk_lower_bound
from .tolerances import (DEFAULT_JERK_INITIAL_INTERVALS, DEFAULT_JERK_MAX_GRID,
                         DEFAULT_JERK_MAX_ROUNDS, JERK_SHORT_SEGMENT_BUDGET,
                         MIN_JERK_SEGMENT_INTERVALS)
from .upper import UpperResult, upper_bound_round

ProgressFn = Callable[[str, float], None]

#: A node constraint counts as tight when within this fraction of its limit.
_TIGHT_REL = 1e-4


def solve_jerk(path: Path, limits: MachineLimits, *, acc_solve: Callable[..., OptimalSolution],
               tol: float, max_grid: int = DEFAULT_JERK_MAX_GRID,
               max_rounds: int = DEFAULT_JERK_MAX_ROUNDS,
               initial_intervals: int = DEFAULT_JERK_INITIAL_INTERVALS,
               progress: ProgressFn | None = None, holds: Holds | None = None,
               acc_tol: float | None = None) -> OptimalSolution:
    """Minimum-time motion under the ``jerk`` bound set, with a certified bracket.

    Constraints: those of ``acc`` plus per-axis jerk
    ``|q'_i s''' + 3 q''_i v s'' + q'''_i v^3| <= J_i`` and the rulebook's acceleration
    steps at segment breaks and path ends (:mod:`optimal.jerk.transcription`).

    Parameters
    ----------
    path : Path
        The path.
    limits : MachineLimits
        Machine limits (``j_max``, ``path_trans_jerk`` and ``t_ipo_s`` are used here).
    acc_solve : callable
        The ``acc`` oracle (:func:`optimal.solve`), passed in by the dispatcher.
    tol : float
        Requested relative gap.
    max_grid : int
        Largest NLP grid, intervals.
    max_rounds : int
        Largest number of NLP solves.
    initial_intervals : int
        Target size of the first NLP grid.
    progress : callable, optional
        ``progress(message, fraction)``.
    holds : Holds, optional
        Imposed holds (default: the dwells of ``path.blocks``).
    acc_tol : float, optional
        Gap requested from the inner ``acc`` solve (default ``min(tol / 4, 2e-3)``).

    Returns
    -------
    OptimalSolution
    """
    t_start = time.perf_counter()
    if holds is None:
        holds = dwell_holds(path)
    if path.n_segments == 0:
        return replace(acc_solve(path, limits, "acc", holds=holds, progress=progress),
                       bounds="jerk")
    lim = limits.for_axes(path.axes)
    hold_t = holds.total_s
    sub = (lambda msg, f: progress(f"acc: {msg}", 0.3 * f)) if progress else None
    acc = acc_solve(path, limits, "acc", tol=acc_tol if acc_tol else min(tol / 4, 2e-3),
                    holds=holds, progress=sub)
    tb = time.perf_counter()
    lb_motion, _, _ = jerk_lower_bound(path, lim, limits.t_ipo_s, acc.grid)
    lb = max(acc.lower_bound_s, lb_motion + hold_t)
    t_bound = acc.bound_time_s + time.perf_counter() - tb
    best: UpperResult | None = None
    best_ub = math.inf
    history: list[IterationRecord] = []
    t_build = t_solve = t_check = 0.0
    prev_ub = math.inf
    prev_step = 0.0
    status = SolveStatus.GAP_NOT_MET
    msg = ""
    rounds = 0
    grid = jerk_grid(path, initial_intervals)
    for rounds in range(1, max_rounds + 1):
        if rounds > 1:
            # halve every interval: short segments need nodes as much as long ones
            finer = split(grid, path, np.ones(grid.n_intervals, bool))
            if finer is grid or finer.n_intervals > max_grid:
                break
            grid = finer
        tr = time.perf_counter()
        r = upper_bound_round(path, limits, grid)
        t_build += r.nlp.build_time_s
        t_solve += r.nlp.solve_time_s
        # the rest of the round: transcription, warm start, the checker
        t_check += time.perf_counter() - tr - r.nlp.build_time_s - r.nlp.solve_time_s
        ub = r.profile.duration + hold_t if r.ok else math.inf
        history.append(IterationRecord(grid.n_points, lb, ub, r.objective_s + hold_t,
                                       r.time_scale))
        if r.ok and ub < best_ub:
            best, best_ub = r, ub
        msg = r.message
        gap = (best_ub - lb) / lb if lb > 0 else math.inf
        if progress:
            progress(f"jerk round {rounds}: {grid.n_points} points, gap {gap:.3%}",
                     0.3 + 0.7 * rounds / max_rounds)
        if gap <= tol:
            status = SolveStatus.OPTIMAL
            break
        # a finer grid only tightens the upper bound: stop when even its extrapolated
        # limit (geometric decrease, ratio from the last two rounds, at least 1/2)
        # cannot bring the gap within tol: then the lower bound is the loose side
        if r.ok and math.isfinite(prev_ub):
            step = max(prev_ub - ub, 0.0)
            ratio = min(max(step / prev_step, 0.5), 0.95) if prev_step > 0 else 0.5
            if (ub - step * ratio / (1.0 - ratio) - lb) > tol * lb:
                break
            prev_step = step
        if r.ok:
            prev_ub = ub
    if best is None:
        return OptimalSolution(
            status=SolveStatus.SOLVER_ERROR, profile=None, lower_bound_s=lb,
            upper_bound_s=math.inf, objective_s=math.inf, gap=math.inf, time_scale=1.0,
            segment_times_s=np.full(path.n_segments, np.nan), block_times_s=np.zeros(0),
            blocks=(), grid=acc.grid, active=(), grid_points=int(acc.grid.size),
            iterations=rounds, backend="ipopt", build_time_s=t_build,
            solve_time_s=t_solve, check_time_s=t_check, bound_time_s=t_bound,
            total_time_s=time.perf_counter() - t_start, dwell_s=_dwell_part(holds),
            history=tuple(history), message=f"jerk NLP failed: {msg}", holds=holds,
            bounds="jerk")
    prof_h = with_holds(best.profile, path, holds)
    labels = active_labels(best)
    g = best.problem.grid
    rows = _block_rows(path, g.segment, prof_h, labels, best.interval_times_s, holds)
    gap = (best_ub - lb) / lb if lb > 0 else math.inf
    if status == SolveStatus.OPTIMAL:
        message = f"gap {gap:.4%} <= {tol:.4%} on {g.n_points} points"
    else:
        message = (f"gap {gap:.4%} > {tol:.4%} after {rounds} NLP rounds ({g.n_points} "
                   f"points); bracket [{lb:.6g}, {best_ub:.6g}] s, both bounds are valid")
    if progress:
        progress("done", 1.0)
    return OptimalSolution(
        status=status, profile=prof_h, lower_bound_s=lb, upper_bound_s=best_ub,
        objective_s=best.objective_s + hold_t, gap=gap, time_scale=best.time_scale,
        segment_times_s=prof_h.segment_times(path), block_times_s=prof_h.block_times(path),
        blocks=rows, grid=g.s, active=labels, grid_points=g.n_points, iterations=rounds,
        backend="ipopt", build_time_s=t_build, solve_time_s=t_solve, check_time_s=t_check,
        bound_time_s=t_bound, total_time_s=time.perf_counter() - t_start,
        dwell_s=_dwell_part(holds), report=best.report, history=tuple(history),
        message=message, holds=holds, bounds="jerk")


def jerk_grid(path: Path, n_intervals: int) -> Grid:
    """The first NLP grid: :func:`optimal.grid.initial_counts` per segment, but at least
    :data:`~optimal.jerk.tolerances.MIN_JERK_SEGMENT_INTERVALS` per segment while the
    total stays within ``JERK_SHORT_SEGMENT_BUDGET`` (a jerk-limited S-curve needs
    several constant-jerk pieces; with two intervals a short block is planned far too
    slowly and only refinement would recover it)."""
    m = path.n_segments
    k_min = int(np.clip(JERK_SHORT_SEGMENT_BUDGET // max(m, 1), 2, MIN_JERK_SEGMENT_INTERVALS))
    counts = np.maximum(initial_counts(path, n_intervals), k_min).astype(np.int64)
    return grid_from_counts(path, counts)


def active_labels(r: UpperResult) -> tuple[str, ...]:
    """Which constraint is tight on each interval of a solved jerk NLP.

    Jerk rows first (the constraint this bound set adds), then axis acceleration at
    either node, then the node speed cap (feed, axis velocity, velocity jump, stop).

    Returns
    -------
    tuple[str, ...]
        Length ``N``: ``"jerk X"``, ``"acceleration X"``, ``"velocity X"``, ``"feed"``,
        ``"velocity_jump"``, ``"stop"`` or ``"none"``.
    """
    p = r.problem
    N = p.n_intervals
    names = p.axes
    c = np.clip(r.nlp.c, 0.0, p.c_max)
    a, dt = r.nlp.a, r.nlp.dt
    label = np.full(N, "none", dtype=object)
    done = np.zeros(N, bool)
    jr = p.jerk
    if jr.n:
        cn, an = c[jr.node], a[jr.node]
        an = np.where(jr.node != jr.interval, r.nlp.a_end[jr.interval], a[jr.interval])
        val = (jr.dq * (r.nlp.a_end[jr.interval] - a[jr.interval])
               + dt[jr.interval] * (3 * jr.ddq * cn * an + jr.dddq * cn ** 3))
        tight = np.abs(val) >= (1 - _TIGHT_REL) * jr.limit * dt[jr.interval]
        for k, ax in zip(jr.interval[tight], jr.axis[tight]):
            if not done[k]:
                label[k], done[k] = f"jerk {names[ax]}", True
    ac = p.acc
    if ac.n:
        a_all = np.concatenate((a, np.zeros(p.n_extra)))
        a_all[p.end_index] = r.nlp.a_end
        a_all[:N] = a[:N]
        val = ac.dq * a_all[p.acc_index] + ac.ddq * c[ac.node] ** 2
        tight = np.abs(val) >= (1 - _TIGHT_REL) * ac.limit
        for nd, ax in zip(ac.node[tight], ac.axis[tight]):
            for k in (nd - 1, nd):
                if 0 <= k < N and not done[k]:
                    label[k], done[k] = f"acceleration {names[ax]}", True
    capped = c >= (1 - _TIGHT_REL) * p.c_max
    for k in np.flatnonzero(~done):
        for nd in (k + 1, k):
            if capped[nd]:
                code = int(p.cap_code[nd])
                ax = int(p.cap_axis[nd])
                name = CAP_NAMES[code]
                label[k] = (f"{name} {names[ax]}" if code in (CAP_VELOCITY, CAP_ACCELERATION)
                            and ax >= 0 else name)
                break
    return tuple(str(x) for x in label)


def _dwell_part(holds: Holds) -> float:
    return float(sum(d for d, c in zip(holds.duration_s, holds.cause) if c == DWELL_CAUSE))


def _block_rows(path: Path, segment: np.ndarray, prof: Profile, labels: tuple[str, ...],
                t_int: np.ndarray, holds: Holds) -> tuple[BlockRow, ...]:
    """Per-block rows of the verified profile; each block's cause is the label active for
    most of its grid time."""
    blk_of_int = path.block[segment]
    lab_arr = np.asarray(labels, dtype=object).astype(str)
    causes = []
    for b in path.blocks:
        sel = blk_of_int == b.block
        if b.n_segments > 0 and np.any(sel):
            uniq, inv = np.unique(lab_arr[sel], return_inverse=True)
            causes.append(str(uniq[int(np.argmax(np.bincount(inv, weights=t_int[sel])))]))
        elif b.n_segments > 0:
            causes.append("none")
        else:
            causes.append(b.stop_reason)
    hold = np.zeros(0)
    if path.blocks:
        idx = np.array([b.block for b in path.blocks], dtype=np.int64)
        hold = holds.per_block(int(idx.max()) + 1)[idx]
    return block_rows(path, block_motion(path, prof), causes, hold if path.blocks else None)
