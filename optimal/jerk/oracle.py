"""``optimal.solve(..., bounds="jerk")``: the jerk-limited oracle, one pure function.

Pipeline:

1. the ``acc`` oracle on the same path (its lower bound is valid here too, its optimum
   says where the speed changes, and its relaxation bounds the speeds);
2. per-segment floors (:func:`optimal.jerk.lower.jerk_lower_bound`), valid for every
   jerk-feasible motion segment by segment (also the per-block lower bounds);
3. the first grid (:func:`jerk_grid`): equal intervals per segment, graded toward the
   segment ends where the ``acc`` optimum changes speed;
4. rounds on that grid: the convex relaxation (:mod:`optimal.jerk.relaxation`, the
   lower bound) and the jerk NLP (:mod:`optimal.jerk.upper`: solve, exact profile,
   ``check_profile``, time scaling: the upper bound); then both are refined together
   where the verified profile spends more time than the relaxation
   (:func:`_refine_marks`), until the gap is met, the grid budget or the round budget
   ends;
5. status ``optimal`` when ``(upper - lower) / lower <= tol``, else ``gap_not_met``
   with both (valid) bounds; ``solver_error`` when the NLP never produced a verified
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

from ..bounds import lower_bound
from ..grid import Grid, grid_from_counts, initial_counts, split, subdivide
from ..problem import CAP_NAMES, CAP_ACCELERATION, CAP_VELOCITY
from ..solution import IterationRecord, OptimalSolution
from ..status import SolveStatus
from .lower import grid_on, jerk_lower_bound
from .relaxation import jerk_relaxation
from .tolerances import (DEFAULT_JERK_INITIAL_INTERVALS, DEFAULT_JERK_MAX_GRID,
                         DEFAULT_JERK_MAX_ROUNDS, GRADE_FIRST_EXPONENT,
                         GRADE_MAX_NODES_PER_END, GRADE_SPEED_CHANGE_REL,
                         JERK_LB_ROUNDOFF_REL,
                         JERK_REFINE_RESIDUAL, JERK_REFINE_SHARE, JERK_REFINE_TARGET,
                         JERK_SHORT_SEGMENT_BUDGET,
                         MIN_JERK_SEGMENT_INTERVALS)
from .upper import UpperResult, profile_times_at, upper_bound_round

ProgressFn = Callable[[str, float], None]

#: A node constraint counts as tight when within this fraction of its limit.
_TIGHT_REL = 1e-4


def solve_jerk(path: Path, limits: MachineLimits, *, acc_solve: Callable[..., OptimalSolution],
               tol: float, max_grid: int = DEFAULT_JERK_MAX_GRID,
               max_rounds: int = DEFAULT_JERK_MAX_ROUNDS,
               initial_intervals: int = DEFAULT_JERK_INITIAL_INTERVALS,
               progress: ProgressFn | None = None, holds: Holds | None = None,
               acc_tol: float | None = None, nlp_backend: str = "ipopt") -> OptimalSolution:
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
        Largest grid of the NLP and of the relaxation, intervals.
    max_rounds : int
        Largest number of rounds.
    initial_intervals : int
        Target size of the first NLP grid.
    progress : callable, optional
        ``progress(message, fraction)``.
    holds : Holds, optional
        Imposed holds (default: the dwells of ``path.blocks``).
    acc_tol : float, optional
        Gap requested from the inner ``acc`` solve (default ``min(tol / 4, 2e-3)``).
    nlp_backend : {"ipopt", "scp"}
        Solver of the upper bound's NLP (:mod:`optimal.jerk.backends`; ``scp`` is the
        cross-check: same optimum, about 12x slower, measured in ``bench_jerk.py``).

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
    hold_t = holds.total_s
    sub = (lambda msg, f: progress(f"acc: {msg}", 0.2 * f)) if progress else None
    acc = acc_solve(path, limits, "acc", tol=acc_tol if acc_tol else min(tol / 4, 2e-3),
                    holds=holds, progress=sub)
    # bounds and the relaxation on the moving axes (exact: the others never move)
    moving = path.moving_axes()
    work = path.restricted(moving) if 0 < moving.size < path.n_axes else path
    lim = limits.for_axes(work.axes)
    t_ipo = limits.t_ipo_s
    tb = time.perf_counter()
    lb_seg_total, acc_seg, jerk_seg = jerk_lower_bound(work, lim, t_ipo, acc.grid)
    floors = np.maximum(acc_seg, jerk_seg) * (1.0 - JERK_LB_ROUNDOFF_REL)
    lb = max(acc.lower_bound_s, lb_seg_total + hold_t)
    t_bound = acc.bound_time_s + time.perf_counter() - tb
    grid_u = jerk_grid(path, initial_intervals, limits, acc.profile, max_grid // 2)
    # The relaxation runs on the NLP's own nodes: its bound and the NLP's profile then
    # differ interval by interval, which is what the refinement needs, and neither grid
    # is refined where the other one already is fine (measured: on the acc oracle's finer
    # grid the relaxation cost several times the NLP and its bound was no better where
    # the NLP grid was coarse).
    grid_l = grid_on(work, grid_u.s)
    best: UpperResult | None = None
    best_ub = math.inf
    history: list[IterationRecord] = []
    t_build = t_solve = t_check = 0.0
    status = SolveStatus.GAP_NOT_MET
    msg = ""
    relax_note = ""
    rounds = 0
    for rounds in range(1, max_rounds + 1):
        tl = time.perf_counter()
        _, t_acc, _, b_hat = lower_bound(work, lim, grid_l)
        rel = jerk_relaxation(work, lim, t_ipo, grid_l, b_hat, t_acc, floors,
                              holds.break_index)
        t_bound += time.perf_counter() - tl
        if rel.ok:
            lb = max(lb, rel.lower_bound_s + hold_t)
            tau_l = rel.tau
        else:
            relax_note = f" (the relaxation ended {rel.status} on {grid_l.n_points} points)"
            tau_l = t_acc
        tr = time.perf_counter()
        r = upper_bound_round(path, limits, grid_u, None if best is None else best.profile,
                              nlp_backend, holds)
        t_build += r.nlp.build_time_s
        t_solve += r.nlp.solve_time_s
        t_check += time.perf_counter() - tr - r.nlp.build_time_s - r.nlp.solve_time_s
        ub = r.profile.duration + hold_t if r.ok else math.inf
        if r.ok and ub < best_ub:
            best, best_ub = r, ub
        msg = r.message
        history.append(IterationRecord(grid_u.n_points, lb, best_ub,
                                       (best.objective_s + hold_t) if best else math.inf,
                                       best.time_scale if best else 1.0))
        gap = (best_ub - lb) / lb if lb > 0 else math.inf
        if progress:
            progress(f"jerk round {rounds}: {grid_u.n_points} points, gap {gap:.3%}",
                     0.2 + 0.8 * rounds / max_rounds)
        if gap <= tol:
            status = SolveStatus.OPTIMAL
            break
        if best is None or rounds == max_rounds:
            break
        # refine where the bracket is: on each interval, the time the verified profile
        # spends there less the relaxation's own time
        t_ub = profile_times_at(best.profile, grid_l.s)
        d = np.maximum(np.diff(t_ub) - tau_l, 0.0)
        mark, pieces = _refine_marks(d, JERK_REFINE_TARGET * tol * (lb - hold_t))
        n_mark = int(mark.sum())
        if grid_u.n_intervals + n_mark * (pieces - 1) > max_grid:
            pieces = 2
        # near the cap, the largest carriers that still fit are halved rather than none:
        # the last round uses the grid's budget (lcnc_arc_arc_sawtooth, default machine:
        # it stopped at 7,439 intervals with 1.85 %; filling the 10,000 gives 1.05 %)
        room = max_grid - grid_u.n_intervals
        if n_mark > room > 0:
            fits = np.argsort(-np.where(mark, d, -np.inf), kind="stable")[:room]
            mark = np.zeros_like(mark)
            mark[fits] = True
            n_mark = room
        if n_mark == 0 or grid_u.n_intervals + n_mark > max_grid:
            break
        grid_u = subdivide(grid_u, path, mark, pieces)
        grid_l = grid_on(work, grid_u.s)
    if best is None:
        return OptimalSolution(
            status=SolveStatus.SOLVER_ERROR, profile=None, lower_bound_s=lb,
            upper_bound_s=math.inf, objective_s=math.inf, gap=math.inf, time_scale=1.0,
            segment_times_s=np.full(path.n_segments, np.nan), block_times_s=np.zeros(0),
            blocks=(), grid=acc.grid, active=(), grid_points=int(acc.grid.size),
            iterations=rounds, backend=nlp_backend, build_time_s=t_build,
            solve_time_s=t_solve, check_time_s=t_check, bound_time_s=t_bound,
            total_time_s=time.perf_counter() - t_start, dwell_s=_dwell_part(holds),
            history=tuple(history), message=f"jerk NLP failed: {msg}", holds=holds,
            bounds="jerk", segment_lower_bounds_s=floors)
    prof_h = with_holds(best.profile, path, holds)
    labels = active_labels(best)
    g = best.problem.grid
    rows = _block_rows(path, g.segment, prof_h, labels, best.interval_times_s, holds)
    gap = (best_ub - lb) / lb if lb > 0 else math.inf
    if status == SolveStatus.OPTIMAL:
        message = f"gap {gap:.4%} <= {tol:.4%} on {g.n_points} points{relax_note}"
    else:
        message = (f"gap {gap:.4%} > {tol:.4%} after {rounds} rounds ({g.n_points} points); "
                   f"bracket [{lb:.6g}, {best_ub:.6g}] s, both bounds are valid"
                   f"{relax_note}")
    if progress:
        progress("done", 1.0)
    return OptimalSolution(
        status=status, profile=prof_h, lower_bound_s=lb, upper_bound_s=best_ub,
        objective_s=best.objective_s + hold_t, gap=gap, time_scale=best.time_scale,
        segment_times_s=prof_h.segment_times(path), block_times_s=prof_h.block_times(path),
        blocks=rows, grid=g.s, active=labels, grid_points=g.n_points, iterations=rounds,
        backend=nlp_backend, build_time_s=t_build, solve_time_s=t_solve,
        check_time_s=t_check,
        bound_time_s=t_bound, total_time_s=time.perf_counter() - t_start,
        dwell_s=_dwell_part(holds), report=best.report, history=tuple(history),
        message=message, holds=holds, bounds="jerk", segment_lower_bounds_s=floors)


def _refine_marks(d: np.ndarray, target_s: float) -> tuple[np.ndarray, int]:
    """Intervals to refine and into how many pieces (2 or 4).

    ``d`` (>= 0, s) is each relaxation interval's share of the bracket. Both bounds
    converge at first order there (:mod:`optimal.jerk.relaxation`), so a halved interval
    keeps about :data:`JERK_REFINE_RESIDUAL` of its share: take the fewest largest
    carriers whose halving is predicted to bring the bracket to ``target_s``, at most
    :data:`JERK_REFINE_SHARE` of it; when halving that share is not predicted to be
    enough, quarter them instead.
    """
    total = float(d.sum())
    mark = np.zeros(d.size, bool)
    if total <= 0:
        return mark, 2
    order = np.argsort(-d, kind="stable")
    cum = np.cumsum(d[order])
    excess = max(total - max(target_s, 0.0), 0.0)
    share = excess / (1.0 - JERK_REFINE_RESIDUAL)
    pieces = 2
    if share > JERK_REFINE_SHARE * total:
        pieces = 4
        share = min(excess / (1.0 - JERK_REFINE_RESIDUAL ** 2), JERK_REFINE_SHARE * total)
    n_take = int(np.searchsorted(cum, share)) + 1
    mark[order[:n_take]] = True
    return mark, pieces


def jerk_grid(path: Path, n_intervals: int, limits: MachineLimits | None = None,
              speed: Profile | None = None, max_intervals: int | None = None) -> Grid:
    """The first grid of the jerk oracle (NLP and relaxation).

    :func:`optimal.grid.initial_counts` equal intervals per segment, at least
    :data:`~optimal.jerk.tolerances.MIN_JERK_SEGMENT_INTERVALS` while the total stays
    within ``JERK_SHORT_SEGMENT_BUDGET`` (a jerk-limited S-curve needs several
    constant-jerk pieces; with two intervals a short block is planned far too slowly and
    only refinement would recover it); then, given the ``acc`` optimum's ``speed``, nodes
    graded toward every segment end where that speed changes by more than
    :data:`~optimal.jerk.tolerances.GRADE_SPEED_CHANGE_REL` (see :func:`graded_nodes`).

    Parameters
    ----------
    path : Path
    n_intervals : int
        Target size before grading.
    limits : MachineLimits, optional
        Axis limits on ``path.axes`` (needed for grading).
    speed : Profile, optional
        The ``acc`` optimum (needed for grading).
    max_intervals : int, optional
        Largest grid; grading stops adding nodes beyond it.

    Returns
    -------
    Grid
    """
    m = path.n_segments
    k_min = int(np.clip(JERK_SHORT_SEGMENT_BUDGET // max(m, 1), 2, MIN_JERK_SEGMENT_INTERVALS))
    counts = np.maximum(initial_counts(path, n_intervals), k_min).astype(np.int64)
    base = grid_from_counts(path, counts)
    if limits is None or speed is None or speed.n_intervals == 0:
        return base
    room = (max_intervals if max_intervals is not None else DEFAULT_JERK_MAX_GRID) \
        - base.n_intervals
    extra = graded_nodes(path, limits, speed, base.s, counts, max(room, 0))
    if extra.size == 0:
        return base
    return grid_on(path, np.unique(np.concatenate((base.s, extra))))


def graded_nodes(path: Path, limits: MachineLimits, speed: Profile, s_base: np.ndarray,
                 counts: np.ndarray, budget: int) -> np.ndarray:
    """Nodes graded geometrically toward the segment ends where the speed changes.

    A jerk-limited change of speed by ``dv`` along a segment takes about the distance
    ``d = v_mean * t`` with ``t = dv / A + A / J`` (or ``2 sqrt(dv / J)`` when the
    acceleration limit is not reached), ``A`` and ``J`` the path acceleration and jerk
    the axis limits allow along the end tangent. On a long segment of equal intervals the
    whole S-curve falls into the first interval, where one constant-jerk piece cannot
    follow it: the NLP then finds only a much slower motion, or none (a raster at
    250 mm/min with 330 mm rows: IPOPT failed both barrier strategies). Nodes at
    ``d * 2**k`` from the end, ``k`` from :data:`GRADE_FIRST_EXPONENT` up, until the
    spacing reaches the segment's equal spacing, give the NLP pieces of the right size
    wherever the optimum's ramps are, at a cost logarithmic in ``L / d``.

    Parameters
    ----------
    path : Path
    limits : MachineLimits
        On ``path.axes``.
    speed : Profile
        The ``acc`` optimum, whose knot speeds say where the speed changes.
    s_base : numpy.ndarray, shape (N + 1,)
        The equal-spacing nodes.
    counts : numpy.ndarray of int, shape (m,)
        Equal intervals per segment.
    budget : int
        Most nodes to add (the ends with the largest ``L / d`` ratio lose theirs first).

    Returns
    -------
    numpy.ndarray, shape (K,)
        Added path positions, mm (strictly inside segments).
    """
    lim = limits.for_axes(path.axes)
    m = path.n_segments
    L = path.length
    sb = path.s_breaks
    # the acc optimum's speed at each break and its largest speed on each segment
    ks, kv = speed.s, speed.v
    v_break = np.interp(sb, ks, kv)
    seg_of_knot = np.clip(path.segment_index(np.clip(ks, 0.0, path.total_length)), 0, m - 1)
    v_peak = np.maximum(v_break[:-1], v_break[1:])
    np.maximum.at(v_peak, seg_of_knot, kv)
    # path acceleration and jerk along each end's tangent
    ends = np.concatenate((sb[:-1], sb[1:]))
    seg2 = np.concatenate((np.arange(m), np.arange(m)))
    _, dq, _, _ = path.evaluate(ends, segment=seg2)
    adq = np.abs(dq)
    with np.errstate(divide="ignore"):
        A = np.min(np.where(adq > 0, lim.a_max / adq, np.inf), axis=1)
        J = np.min(np.where(adq > 0, lim.j_max / adq, np.inf), axis=1)
    v_end = np.concatenate((v_break[:-1], v_break[1:]))
    v_top = np.concatenate((v_peak, v_peak))
    dv = v_top - v_end
    grade = (dv > GRADE_SPEED_CHANGE_REL * v_top) & np.isfinite(A) & np.isfinite(J) \
        & (A > 0) & (J > 0)
    if not np.any(grade):
        return np.zeros(0)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(dv * J > A * A, dv / A + A / J, 2.0 * np.sqrt(dv / J))
        d = 0.5 * (v_end + v_top) * t
        h = np.concatenate((L / counts, L / counts))
        # nodes d * 2**k for k >= GRADE_FIRST_EXPONENT while below h and half the segment
        top = np.minimum(h, 0.5 * np.concatenate((L, L)))
        n = np.where(grade & (d > 0), np.floor(np.log2(top / d)) - GRADE_FIRST_EXPONENT, 0)
    n = np.clip(np.nan_to_num(n, nan=0.0), 0, GRADE_MAX_NODES_PER_END).astype(np.int64)
    if n.sum() > budget:
        # keep the finest levels everywhere: cap the count per end until it fits
        for cap in range(GRADE_MAX_NODES_PER_END, -1, -1):
            if np.minimum(n, cap).sum() <= budget:
                break
        n = np.minimum(n, cap)
    idx = np.repeat(np.arange(n.size), n)
    first = np.concatenate(([0], np.cumsum(n)[:-1]))
    k = np.arange(idx.size) - first[idx] + GRADE_FIRST_EXPONENT
    dist = d[idx] * np.exp2(k)
    start_end = idx < m
    seg = seg2[idx]
    pos = np.where(start_end, sb[seg] + dist, sb[seg + 1] - dist)
    inside = (pos > sb[seg]) & (pos < sb[seg + 1])
    return pos[inside]


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
