"""Oracle benchmark: the default (fast) method against toppra and the SOCP.

Path: ``polyline200`` of the formulation note (section 4): a seeded random 2-D polyline
of 200 segments (2..20 mm, turns up to 115 deg) with Kunz-Stilman circular blends of
0.1 mm deviation, 399 pieces; V = (250, 200, 100) mm/s, A = (3000, 2000, 1000) mm/s^2.

Rows (medians of repeated runs, measured side by side in this run):

* ``oracle_fast/toppra  N=...``: our build + exact sweep against toppra's constraint
  set-up + ``compute_parameterization`` (seidel, interpolation scheme) on the *same*
  grid (uniform by length, every segment break a node) for N = 10^3, 10^4, 10^5
  intervals. Accuracy of both: the time error against the oracle's certified interval
  (``solve(tol=5e-4)``) and the checker's worst ratio (velocity /
  acceleration) of each grid profile;
* ``oracle_fast/socp`` (and ``/lp``) on the same discrete problem;
* the scaling exponent ``k`` of ``time ~ N^k`` and the tracemalloc peak at two sizes;
* one full ``optimal.solve`` (refinement to the default 0.2 % gap) for reference.
"""

from __future__ import annotations

import statistics
import sys
import time
import tracemalloc
from pathlib import Path as FsPath

import numpy as np

HERE = FsPath(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))
sys.path.insert(0, str(HERE.parent / "optimal"))

import optimal  # noqa: E402
from optimal.backends import solve_discrete  # noqa: E402
from optimal.grid import grid_from_counts  # noqa: E402
from optimal.problem import build_grid_problem  # noqa: E402
from oracle_cases import machine, random_blended_polyline, toppra_solve  # noqa: E402
from reference.core.constraints import check_profile  # noqa: E402
from reference.core.profile import Profile  # noqa: E402

SIZES = (1_000, 10_000, 100_000)


def grid_of_size(path, n: int):
    """Exactly ``n`` intervals spread by length, at least 2 per segment."""
    m = path.n_segments
    share = path.length / path.total_length * (n - 2 * m)
    counts = 2 + np.floor(share).astype(np.int64)
    rest = n - int(counts.sum())
    if rest > 0:
        counts[np.argsort(-(share - np.floor(share)))[:rest]] += 1
    return grid_from_counts(path, counts)


def median_time(fn, repeat: int):
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def fast_solve(path, lim_arrays, grid):
    prob = build_grid_problem(path, lim_arrays, grid)
    return solve_discrete(prob, "fast")


def worst_ratios(path, limits, s, v):
    rep = check_profile(path, limits, Profile.from_path_velocity(s, v))
    return rep.worst("velocity").ratio, rep.worst("acceleration").ratio


def fmt_ms(t: float) -> str:
    return f"{t * 1e3:.1f} ms" if t < 10 else f"{t:.2f} s"


def main() -> None:
    """Print the ratio rows."""
    path = random_blended_polyline(200, 1)
    limits = machine((250.0, 200.0, 100.0), (3000.0, 2000.0, 1000.0))
    la = limits.for_axes(path.axes)
    print(f"path polyline200: {path.n_segments} pieces, L = {path.total_length:.1f} mm")

    t_ref, ref = median_time(lambda: optimal.solve(path, limits, tol=5e-4), 1)
    lo, hi = ref.lower_bound_s, ref.upper_bound_s
    print(f"reference optimum: [{lo:.5f}, {hi:.5f}] s  ({ref.grid_points} points, "
          f"{fmt_ms(t_ref)}, status {ref.status})")

    def err(T):  # distance of a grid time from the certified interval, relative
        if T is None:
            return float("nan")
        return 0.0 if lo <= T <= hi else min(abs(T - lo), abs(T - hi)) / hi

    fast_times = []
    for n in SIZES:
        grid = grid_of_size(path, n)
        rep = 5 if n < 100_000 else 3
        t_fast, res = median_time(lambda: fast_solve(path, la, grid), rep)
        fast_times.append(t_fast)
        rep_t = 3 if n < 100_000 else 1
        t_top, (T_top, sd, _, _) = median_time(lambda: toppra_solve(path, limits, grid.s),
                                               rep_t)
        rv_f, ra_f = worst_ratios(path, limits, grid.s, np.sqrt(res.b))
        rv_t, ra_t = (worst_ratios(path, limits, grid.s, sd) if sd is not None
                      else (float("nan"),) * 2)
        print(f"oracle_fast/toppra  N={n:<7d} ratio={t_fast / t_top:.3f}  "
              f"(fast {fmt_ms(t_fast)}, toppra {fmt_ms(t_top)})")
        print(f"    accuracy N={n}: T fast {res.time_s:.5f} s (off the certified interval "
              f"by {err(res.time_s):.2e}, checker v {rv_f:.4f} a {ra_f:.4f}); "
              f"T toppra {T_top:.5f} s (off by {err(T_top):.2e}, checker v {rv_t:.4f} "
              f"a {ra_t:.4f})")
    k = np.polyfit(np.log(SIZES), np.log(fast_times), 1)[0]
    print(f"oracle_fast scaling exponent (time ~ N^k, N = 1e3..1e5): k = {k:.2f}")
    print(f"oracle_fast N=100000 in {fmt_ms(fast_times[-1])} (target < 1 s)")

    for n in (1_000, 10_000):
        grid = grid_of_size(path, n)
        prob = build_grid_problem(path, la, grid)
        t_fast, res = median_time(lambda: solve_discrete(prob, "fast"), 5)
        t_socp, soc = median_time(lambda: solve_discrete(prob, "clarabel"), 1)
        t_lp, lp = median_time(lambda: solve_discrete(prob, "highs"), 1)
        print(f"oracle_fast/socp    N={n:<7d} ratio={t_fast / t_socp:.4f}  "
              f"(fast {fmt_ms(t_fast)}, socp {fmt_ms(t_socp)}; |dT|/T = "
              f"{abs(soc.time_s - res.time_s) / res.time_s:.1e}, socp status {soc.status})")
        print(f"oracle_fast/lp      N={n:<7d} ratio={t_fast / t_lp:.4f}  "
              f"(fast {fmt_ms(t_fast)}, lp {fmt_ms(t_lp)}; |dT|/T = "
              f"{abs(lp.time_s - res.time_s) / res.time_s:.1e})")

    peaks = []
    for n in (10_000, 100_000):
        grid = grid_of_size(path, n)
        tracemalloc.start()
        fast_solve(path, la, grid)
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
    print(f"oracle_fast memory peak: N=10000 {peaks[0] / 1e6:.1f} MB, N=100000 "
          f"{peaks[1] / 1e6:.1f} MB, ratio {peaks[1] / peaks[0]:.2f} (linear: 10)")

    t_full, sol = median_time(lambda: optimal.solve(path, limits), 1)
    print(f"optimal.solve (gap <= 0.2 %): {fmt_ms(t_full)}, {sol.grid_points} points, "
          f"{sol.iterations} rounds, gap {sol.gap:.3%}; split: build {fmt_ms(sol.build_time_s)}"
          f", solve {fmt_ms(sol.solve_time_s)}, check {fmt_ms(sol.check_time_s)}, lower "
          f"bound {fmt_ms(sol.bound_time_s)}")


if __name__ == "__main__":
    main()
