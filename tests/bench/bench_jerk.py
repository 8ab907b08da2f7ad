"""The jerk oracle's NLP against a plain IPOPT solve of the direct NLP, side by side.

Path: a stadium (G-code through the normal pipeline, default machine: tangent lines and
half circles, curvature jumps at every line/arc joint, SOFT jerk limits), 2 laps.

At 1,000, 2,000 and 5,000 grid intervals (and the scaling exponent of ours):

* ``ours``: :func:`optimal.jerk.upper.upper_bound_round`: the scaled transcription,
  warm started from the acc grid optimum, IPOPT, exact profile, ``check_profile`` and
  time scaling (so its time is a verified upper bound);
* ``plain``: the direct s-domain NLP of the formulation note (section 1.7: variables
  ``c = s'``, ``a``, ``dt``; ``c_{k+1}^2 - c_k^2 = (a_k + a_{k+1}) ds``,
  ``dt (c_k + c_{k+1}) = 2 ds``, node axis accelerations within ``A``, their
  differences within ``J dt``) in mm and s, unscaled, IPOPT with default options,
  warm started from the same acc optimum; its time is the grid objective, not verified.

Rows print both wall times and ``ours / plain`` (below 1: ours is faster), then the
bracket of ``optimal.solve(bounds="jerk")`` at its default settings.

Then the SCP cross-check backend (:mod:`optimal.jerk.backends.scp`) against the IPOPT
backend on the same transcription and warm start, at 1,000 and 5,000 intervals: wall
time ratio ``scp / ipopt`` and objective ratio ``T scp / T ipopt`` (Clarabel subproblems;
OSQP subproblems at 1,000 only, they need thousands of ADMM iterations each).

copp (the ``copp-py`` package, TOPP3-SOCP) has its own rows at equal nodes in
``bench_copp.py``.

Last, a dwell at a reversal (:data:`DWELL_GCODE`): the whole path in one solve against
its two rest-to-rest pieces solved on their own, whose bounds plus the dwell bracket the
same optimum (the one solve's upper bound may not fall below the pieces' lower bound).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path as FsPath

import numpy as np

HERE = FsPath(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))

import casadi as ca  # noqa: E402

import optimal  # noqa: E402
from optimal.backends import get_backend  # noqa: E402
from optimal.grid import initial_grid  # noqa: E402
from optimal.jerk.backends import ipopt, scp  # noqa: E402
from optimal.jerk.transcription import build_jerk_problem  # noqa: E402
from optimal.jerk.upper import upper_bound_round, warm_start  # noqa: E402
from optimal.problem import build_grid_problem, common_node_caps  # noqa: E402
from reference.machine import load_machine  # noqa: E402
from reference.nc import parse_text  # noqa: E402
from reference.prepare import build_path  # noqa: E402

SIZES = (1000, 2000, 5000)
SCP_SIZES = ((1000, ("clarabel", "osqp")), (5000, ("clarabel",)))


def stadium_gcode(R: float = 20.0, L: float = 80.0, laps: int = 2, F: float = 15000.0):
    out = ["G17 G90 G64 G71 SOFT", "G0 X0 Y0 Z0", f"G1 F{F:g}"]
    for _ in range(laps):
        out += [f"G1 X{L:g} Y0", f"G3 X{L:g} Y{2 * R:g} CR={R:g}",
                f"G1 X0 Y{2 * R:g}", f"G3 X0 Y0 CR={R:g}"]
    out.append("M30")
    return "\n".join(out)


def plain_nlp(path, limits, grid):
    """The direct NLP (formulation note 1.7), unscaled; returns (seconds, T, status)."""
    lim = limits.for_axes(path.axes)
    acc = get_backend("fast")(build_grid_problem(path, lim, grid), None)
    seg = grid.segment
    _, dq0, ddq0, _ = path.evaluate(grid.s[:-1], segment=seg)
    _, dq1, ddq1, _ = path.evaluate(grid.s[1:], segment=seg)
    caps = common_node_caps(path, lim, grid, dq0, dq1, permissive=False)
    N = grid.n_intervals
    ds = np.diff(grid.s)
    # node geometry from the interval that starts there (the last node: the last interval)
    dq = np.vstack((dq0, dq1[-1:]))
    ddq = np.vstack((ddq0, ddq1[-1:]))
    t0 = time.perf_counter()
    x = ca.SX.sym("x", 3 * N + 2)
    c, a, dt = x[:N + 1], x[N + 1:2 * N + 2], x[2 * N + 2:]
    g, lo, hi = [c[1:] ** 2 - c[:-1] ** 2 - (a[:-1] + a[1:]) * ca.DM(ds),
                 dt * (c[:-1] + c[1:]) - 2 * ca.DM(ds)], [np.zeros(N)] * 2, [np.zeros(N)] * 2
    for i in range(len(path.axes)):
        Ai = ca.DM(dq[:, i]) * a + ca.DM(ddq[:, i]) * c * c
        g += [Ai, Ai[1:] - Ai[:-1] - lim.j_max[i] * dt, Ai[1:] - Ai[:-1] + lim.j_max[i] * dt]
        lo += [np.full(N + 1, -lim.a_max[i]), np.full(N, -np.inf), np.zeros(N)]
        hi += [np.full(N + 1, lim.a_max[i]), np.zeros(N), np.full(N, np.inf)]
    solver = ca.nlpsol("plain", "ipopt", {"x": x, "f": ca.sum1(dt), "g": ca.vertcat(*g)},
                       {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes",
                        "ipopt.max_iter": 3000})
    c0 = np.sqrt(np.maximum(acc.b, 0.0))
    a0 = np.zeros(N + 1)
    a0[:-1] = (acc.b[1:] - acc.b[:-1]) / (2 * ds)
    vs = c0[:-1] + c0[1:]
    dt0 = 2 * ds / np.where(vs > 0, vs, 1.0)
    sol = solver(x0=np.concatenate((c0, a0, dt0)),
                 lbx=np.concatenate((np.zeros(N + 1), np.full(N + 1, -np.inf), np.zeros(N))),
                 ubx=np.concatenate((np.sqrt(caps.cap), np.full(2 * N + 1, np.inf))),
                 lbg=np.concatenate(lo), ubg=np.concatenate(hi))
    secs = time.perf_counter() - t0
    T = float(np.sum(np.asarray(sol["x"]).ravel()[2 * N + 2:]))
    return secs, T, str(solver.stats().get("return_status"))


def scp_rows(path, limits) -> None:
    """SCP vs IPOPT on the same grid NLP and warm start (wall time of the solve only)."""
    lim = limits.for_axes(path.axes)
    print(f"{'N':>6} {'subproblem':>10} {'scp s':>8} {'ipopt s':>8} {'time ratio':>10} "
          f"{'T ratio - 1':>12}  scp: iterations, message")
    for n, subs in SCP_SIZES:
        grid = initial_grid(path, n)
        problem = build_jerk_problem(path, lim, grid, limits.t_ipo_s)
        start = warm_start(path, lim, grid, problem)
        t0 = time.perf_counter()
        ref = ipopt.solve_nlp(problem, *start)
        t_ref = time.perf_counter() - t0
        for sub in subs:
            t0 = time.perf_counter()
            r = scp.solve_nlp(problem, *start, subproblem=sub)
            t_scp = time.perf_counter() - t0
            ratio = float(np.sum(r.dt) / np.sum(ref.dt))
            print(f"{grid.n_intervals:>6} {sub:>10} {t_scp:8.2f} {t_ref:8.2f} "
                  f"{t_scp / t_ref:10.2f} {ratio - 1:12.2e}  {r.iterations}, {r.message}"
                  f"{'' if ref.success else '; IPOPT: ' + ref.message}", flush=True)


def main() -> int:
    machine = load_machine()
    path = build_path(parse_text(stadium_gcode(), "stadium.mpf"), machine)
    limits = machine.limits
    print(f"stadium: {path.n_segments} segments, {path.total_length:.1f} mm, default machine")
    print(f"{'N':>6} {'ours s':>8} {'plain s':>8} {'ratio':>6} {'T ours (UB)':>12} "
          f"{'T plain (grid)':>15}  ours: build s, IPOPT s, iterations; plain status")
    sizes, ours_s = [], []
    for n in SIZES:
        grid = initial_grid(path, n)
        t0 = time.perf_counter()
        r = upper_bound_round(path, limits, grid)
        ours = time.perf_counter() - t0
        plain_s, plain_T, status = plain_nlp(path, limits, grid)
        t_ours = r.profile.duration if r.ok else float("inf")
        sizes.append(grid.n_intervals)
        ours_s.append(ours)
        print(f"{grid.n_intervals:>6} {ours:8.2f} {plain_s:8.2f} {ours / plain_s:6.2f} "
              f"{t_ours:12.5f} {plain_T:15.5f}  {r.nlp.build_time_s:.2f}, "
              f"{r.nlp.solve_time_s:.2f}, {r.nlp.iterations}; {status}", flush=True)
    slope = np.polyfit(np.log(sizes), np.log(ours_s), 1)[0]
    print(f"ours: time ~ N^{slope:.2f} over N = {sizes[0]}..{sizes[-1]}")
    scp_rows(path, limits)
    t0 = time.perf_counter()
    sol = optimal.solve(path, limits, bounds="jerk", tol=1e-2)
    secs = time.perf_counter() - t0
    print(f"optimal.solve(bounds='jerk', tol=1%): {sol.status}, bracket "
          f"[{sol.lower_bound_s:.5f}, {sol.upper_bound_s:.5f}] s, UB/LB - 1 = "
          f"{sol.gap:.2%}, {sol.grid_points} points, {secs:.2f} s")
    dwell_rows(machine)
    return 0


#: A 20 mm line to a 0.1 s dwell, then six 1.02 mm steps of a zig-zag whose first one
#: reverses X: the dwell rests at zero acceleration between the two pieces.
DWELL_GCODE = ("G21 G90 G17 G64 P0.05\nG1 X20 F6000\nG4 P0.1\nG1 X19 Y-0.2 F3000\n"
               + "".join(f"G1 X{19 - i} Y{-0.2 * ((i + 1) % 2):.1f}\n" for i in range(1, 6))
               + "M2\n")


def dwell_rows(machine) -> None:
    """The jerk oracle on a path with a dwell at a reversal, against the same two
    rest-to-rest pieces solved on their own (their optimum is exactly the sum plus the
    dwell, which nothing in the single solve may beat): wall time ratio, bounds."""
    from reference.core.holds import NO_HOLDS
    path = build_path(parse_text(DWELL_GCODE, "dwell.ngc", dialect="ngc"), machine)
    limits = machine.limits
    t0 = time.perf_counter()
    whole = optimal.solve(path, limits, bounds="jerk", tol=1e-2)
    t_whole = time.perf_counter() - t0
    line = build_path(parse_text("G21 G90 G17 G64 P0.05\nG1 X20 F6000\nM2\n", "line.ngc",
                                 dialect="ngc"), machine)
    zig = build_path(parse_text("G21 G90 G17 G64 P0.05\n" + "".join(
        f"G1 X{-1 - i} Y{-0.2 * ((i + 1) % 2):.1f} F3000\n" for i in range(6)) + "M2\n",
        "zig.ngc", dialect="ngc"), machine)
    t0 = time.perf_counter()
    parts = [optimal.solve(p, limits, bounds="jerk", tol=1e-2, holds=NO_HOLDS)
             for p in (line, zig)]
    t_parts = time.perf_counter() - t0
    lo = sum(p.lower_bound_s for p in parts) + 0.1
    hi = sum(p.upper_bound_s for p in parts) + 0.1
    print(f"dwell at a reversal (line, G4 0.1 s, zig-zag): one solve {t_whole:.2f} s, the "
          f"two pieces {t_parts:.2f} s, ratio {t_whole / t_parts:.2f}; bracket "
          f"[{whole.lower_bound_s:.4f}, {whole.upper_bound_s:.4f}] s ({whole.status}) "
          f"against the pieces' [{lo:.4f}, {hi:.4f}] s (bounds ratio LB "
          f"{whole.lower_bound_s / lo:.4f}, UB {whole.upper_bound_s / hi:.4f})")


if __name__ == "__main__":
    raise SystemExit(main())
