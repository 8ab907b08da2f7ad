"""``optimal.solve(..., bounds="jerk+freq")``: the frequency-bounded oracle, one pure function.

Pipeline:

1. the ``jerk`` oracle and the ``acc`` oracle on the same path, without the imposed
   holds (they are a constant added to both bounds and inserted at the end, as the other
   bound sets do; a motion with its holds cannot be time-scaled);
2. lower bound: ``max`` of the jerk oracle's certified bound (``jerk`` is a relaxation
   of ``jerk+freq``: fewer constraints) and :func:`optimal.freq.lower.freq_lower_bound`
   (proof there), plus the holds;
3. upper bound: the faster of the verified candidates of :mod:`optimal.freq.upper`;
4. status ``optimal`` when ``(upper - lower) / lower <= tol``, else ``gap_not_met`` with
   both valid bounds; ``solver_error`` when no candidate could be verified.

Units: mm, s.
"""

from __future__ import annotations

import math
import time
from typing import Callable

import numpy as np

from reference.core.geometry import Path
from reference.core.holds import NO_HOLDS, Holds, dwell_holds, with_holds
from reference.core.limits import MachineLimits
from reference.core.rows import block_motion, block_rows

from ..solution import IterationRecord, OptimalSolution
from ..status import SolveStatus
from .lower import freq_lower_bound
from .upper import fir_filtered, scaled, verified

ProgressFn = Callable[..., object]

#: Factors on the axis accelerations of the extra acc solves whose FIR-filtered optima
#: are candidates (1 is always tried). Higher factors give shorter ramps, closer to the
#: FIR closed form on lines, but faster arcs (then slowed down by the checker's scaling).
FIR_ACCEL_FACTORS = (2.0, 4.0, 8.0)


def _raised(limits: MachineLimits, g: float) -> MachineLimits:
    from dataclasses import replace as dc_replace
    return dc_replace(limits, axes=tuple(dc_replace(a, a_max=a.a_max * g)
                                         for a in limits.axes))


#: Default requested gap (DESIGN/issue: 2 % where achievable).
DEFAULT_FREQ_GAP_TOL = 2e-2


def solve_freq(path: Path, limits: MachineLimits, *, solve: Callable[..., object],
               tol: float = DEFAULT_FREQ_GAP_TOL, holds: Holds | None = None,
               progress: ProgressFn | None = None, jerk_tol: float | None = None
               ) -> OptimalSolution:
    """Minimum-time motion under ``jerk+freq``, with a certified bracket.

    Parameters
    ----------
    path : Path
    limits : MachineLimits
    solve : callable
        :func:`optimal.solve` (passed in by the dispatcher), for the inner ``jerk`` and
        ``acc`` solves.
    tol : float
        Requested relative gap.
    holds : Holds, optional
        Imposed holds (default: the dwells of ``path.blocks``).
    progress : callable, optional
        ``progress(message, fraction)``.
    jerk_tol : float, optional
        Gap requested from the inner jerk solve (default ``tol / 2``, at most 1 %).

    Returns
    -------
    OptimalSolution
        ``bounds = "jerk+freq"``; ``active`` names ``frequency`` on every interval when
        the frequency rule decided the upper bound, else the jerk solve's labels.
    """
    t_start = time.perf_counter()
    if holds is None:
        holds = dwell_holds(path)
    hold_t = holds.total_s
    sub = (lambda msg, f=-1.0: progress(f"jerk: {msg}", 0.8 * max(f, 0.0))) if progress \
        else None
    jt = jerk_tol if jerk_tol else min(tol / 2, 1e-2)
    jerk = solve(path, limits, "jerk", tol=jt, holds=NO_HOLDS, progress=sub)
    if path.n_segments == 0:
        from dataclasses import replace
        return replace(solve(path, limits, "acc", holds=holds), bounds="jerk+freq")
    acc = solve(path, limits, "acc", holds=NO_HOLDS)
    # FIR candidates from acc optima with raised accelerations too: their shorter ramps
    # leave more of each phase to the filter (optimal.freq.upper.fir_filtered)
    accs = [acc]
    for g in FIR_ACCEL_FACTORS:
        try:
            accs.append(solve(path, _raised(limits, g), "acc", holds=NO_HOLDS, tol=1e-2))
        except Exception:       # noqa: BLE001 - a candidate only; the others stand
            pass
    moving = path.moving_axes()
    work = path.restricted(moving) if 0 < moving.size < path.n_axes else path
    tb = time.perf_counter()
    lb_freq = freq_lower_bound(work, limits.for_axes(work.axes))
    lb = max(jerk.lower_bound_s, lb_freq) + hold_t
    t_bound = jerk.bound_time_s + acc.bound_time_s + time.perf_counter() - tb
    tc = time.perf_counter()
    cands = []
    if jerk.profile is not None:
        c = scaled(path, limits, jerk.profile)
        if c is not None:
            cands.append(c)
    for g, a_sol in zip((1.0,) + FIR_ACCEL_FACTORS, accs):
        if a_sol.profile is not None and np.all(a_sol.profile.j == 0.0):
            c = verified(f"fir (acc x{g:g})", path, limits,
                         fir_filtered(path, limits, a_sol.profile))
            if c is not None:
                cands.append(c)
    t_check = time.perf_counter() - tc
    common = dict(grid=jerk.grid, grid_points=jerk.grid_points, iterations=jerk.iterations,
                  backend=jerk.backend, build_time_s=jerk.build_time_s + acc.build_time_s,
                  solve_time_s=jerk.solve_time_s + acc.solve_time_s,
                  check_time_s=jerk.check_time_s + acc.check_time_s + t_check,
                  bound_time_s=t_bound, dwell_s=jerk.dwell_s if holds is NO_HOLDS else
                  float(sum(d for d, c_ in zip(holds.duration_s, holds.cause)
                            if c_ == "dwell")),
                  holds=holds, bounds="jerk+freq")
    if not cands:
        return OptimalSolution(
            status=SolveStatus.SOLVER_ERROR, profile=None, lower_bound_s=lb,
            upper_bound_s=math.inf, objective_s=math.inf, gap=math.inf, time_scale=1.0,
            segment_times_s=np.full(path.n_segments, np.nan), block_times_s=np.zeros(0),
            blocks=(), active=(), total_time_s=time.perf_counter() - t_start,
            history=(IterationRecord(jerk.grid_points, lb, math.inf, math.inf, 1.0),),
            message="no candidate motion passed the checker under jerk+freq", **common)
    best = min(cands, key=lambda c: c.duration)
    ub = best.duration + hold_t
    gap = (ub - lb) / lb if lb > 0 else math.inf
    status = SolveStatus.OPTIMAL if gap <= tol else SolveStatus.GAP_NOT_MET
    prof_h = with_holds(best.profile, path, holds)
    freq_decides = best.name.startswith("fir") or best.time_scale > 1.0
    active = (("frequency",) * len(jerk.active)) if freq_decides else jerk.active
    jerk_cause = [r.cause for r in jerk.blocks] if len(jerk.blocks) == len(path.blocks) \
        else ["none" if b.n_segments > 0 else b.stop_reason for b in path.blocks]
    causes = [("frequency" if freq_decides and b.n_segments > 0 else c_)
              for b, c_ in zip(path.blocks, jerk_cause)]
    hold = None
    if path.blocks:
        idx = np.array([b.block for b in path.blocks], dtype=np.int64)
        hold = holds.per_block(int(idx.max()) + 1)[idx]
    rows = block_rows(path, block_motion(path, prof_h), causes, hold) if path.blocks else ()
    names = ", ".join(f"{c.name} {c.duration + hold_t:.6g} s (x{c.time_scale:.4g})"
                      for c in cands)
    lb_src = "frequency rule" if lb_freq > jerk.lower_bound_s else "jerk oracle"
    message = (f"gap {gap:.4%} {'<=' if status == SolveStatus.OPTIMAL else '>'} {tol:.4%}; "
               f"bracket [{lb:.6g}, {ub:.6g}] s, lower bound from the {lb_src}, "
               f"candidates: {names}")
    if progress:
        progress("done", 1.0)
    return OptimalSolution(
        status=status, profile=prof_h, lower_bound_s=lb, upper_bound_s=ub,
        objective_s=best.duration + hold_t, gap=gap, time_scale=best.time_scale,
        segment_times_s=prof_h.segment_times(path), block_times_s=prof_h.block_times(path),
        blocks=rows, active=active, total_time_s=time.perf_counter() - t_start,
        report=best.report, history=(IterationRecord(jerk.grid_points, lb, ub,
                                                      best.duration + hold_t,
                                                      best.time_scale),),
        message=message, **common)
