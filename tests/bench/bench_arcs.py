"""Oracle on arc-dense paths against toppra, side by side in one run (issue 10).

Paths (G-code text through the normal pipeline, default machine: V = 500 mm/s,
A = 2000 mm/s^2 on X, Y, Z):

* ``stadium``: 2 laps of a stadium, half circles R 20 mm joined by 80 mm lines, F15000;
* ``sbend200``: 200 tangent half circles of alternating sense (G3/G2 by CR), radius
  2..10 mm (seeded), F12000;
* ``cam1e4`` / ``cam1e5``: seeded random CAM-like programs of 10^4 / 10^5 lines and arcs
  (G2/G3 by CR, radius 0.5..20 mm, sweep 10..120 deg, lines 0.5..10 mm), mostly tangent
  with a sharp corner every tenth piece or so, F8000.

Rows: the one-time load of the compiled sweep (numba, excluded from the timed rows, as
toppra's import is); ``optimal.solve`` at the default tolerance (0.2 %) with its status,
bracket and grid size (median of 3 runs on the small cases), against toppra (seidel, interpolation scheme) with 160 nodes per arc and 80 per
line, and the ratio ``oracle time / toppra time`` (toppra gives no bound at all; its time
is also placed against the oracle's certified bracket). ``--profile`` prints a cProfile
of the oracle on the S-bend case. ``--quick`` skips the 10^5 case.
"""

from __future__ import annotations

import cProfile
import io
import pstats
import sys
import time
from pathlib import Path as FsPath

import numpy as np

HERE = FsPath(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))
sys.path.insert(0, str(HERE.parent / "optimal"))

import optimal  # noqa: E402
from optimal.grid import grid_from_counts  # noqa: E402
from reference.machine import load_machine  # noqa: E402
from reference.nc import parse_text  # noqa: E402
from reference.prepare import build_path  # noqa: E402

TOPPRA_PER_ARC = 160
TOPPRA_PER_LINE = 80


def stadium_gcode(R: float = 20.0, L: float = 80.0, laps: int = 2, F: float = 15000.0):
    """Two laps of a stadium (counter-clockwise), G-code text."""
    out = ["G17 G90 G64 G71", f"G0 X0 Y0 Z0", f"G1 F{F:g}"]
    for _ in range(laps):
        out += [f"G1 X{L:g} Y0", f"G3 X{L:g} Y{2 * R:g} CR={R:g}",
                f"G1 X0 Y{2 * R:g}", f"G3 X0 Y0 CR={R:g}"]
    out.append("M30")
    return "\n".join(out)


def sbend_gcode(n: int = 200, seed: int = 10, F: float = 12000.0):
    """``n`` tangent half circles of alternating sense, radius 2..10 mm."""
    rng = np.random.default_rng(seed)
    out = ["G17 G90 G64 G71", "G0 X0 Y0 Z0", f"G1 F{F:g}"]
    x = 0.0
    for i in range(n):
        R = rng.uniform(2.0, 10.0)
        x += 2 * R
        out.append(f"{'G3' if i % 2 == 0 else 'G2'} X{x:.6f} Y0 CR={R:.6f}")
    out.append("M30")
    return "\n".join(out)


def cam_gcode(n: int, seed: int = 7, F: float = 8000.0):
    """Seeded CAM-like lines and arcs (G2/G3 by CR), mostly tangent."""
    rng = np.random.default_rng(seed)
    out = ["G17 G90 G64 G71", "G0 X0 Y0 Z0", f"G1 F{F:g}"]
    p = np.zeros(2)
    h = 0.0                                             # heading, rad
    for _ in range(n):
        if rng.random() < 0.1:                          # a sharp corner
            h += rng.uniform(-2.0, 2.0)
        if rng.random() < 0.5:
            ln = rng.uniform(0.5, 10.0)
            p = p + ln * np.array([np.cos(h), np.sin(h)])
            out.append(f"G1 X{p[0]:.6f} Y{p[1]:.6f}")
        else:
            R = rng.uniform(0.5, 20.0)
            sw = np.deg2rad(rng.uniform(10.0, 120.0))
            sgn = 1.0 if rng.random() < 0.5 else -1.0      # +1 left (G3), -1 right (G2)
            c = p + sgn * R * np.array([-np.sin(h), np.cos(h)])
            a0 = np.arctan2(p[1] - c[1], p[0] - c[0])
            a1 = a0 + sgn * sw
            p = c + R * np.array([np.cos(a1), np.sin(a1)])
            h += sgn * sw
            out.append(f"{'G3' if sgn > 0 else 'G2'} X{p[0]:.6f} Y{p[1]:.6f} CR={R:.6f}")
    out.append("M30")
    return "\n".join(out)


class _FeedPath:
    """The path plus a virtual axis ``q = s`` (``q' = 1``, ``q'' = 0``): its velocity limit
    is the programmed feed, which toppra's joint constraints cannot express otherwise."""

    def __init__(self, path):
        self.path = path

    def __call__(self, s, order=0):
        scalar = np.ndim(s) == 0
        ss = np.atleast_1d(np.asarray(s, float))
        out = self.path.evaluate(ss)[order]
        extra = ss if order == 0 else (np.ones_like(ss) if order == 1 else np.zeros_like(ss))
        out = np.c_[out, extra]
        return out[0] if scalar else out

    @property
    def dof(self):
        return self.path.n_axes + 1

    @property
    def path_interval(self):
        return np.array([0.0, self.path.total_length])


def toppra_feed_solve(path, limits, gridpoints):
    """toppra (seidel, interpolation) with the axis limits and the feed (one feed for the
    whole path, the programs here have one); returns ``(time_s, sd)``."""
    import toppra
    import toppra.algorithm as algo
    import toppra.constraint as constraint

    toppra.setup_logging("WARNING")
    lim = limits.for_axes(path.axes)
    feed = float(np.min(path.feed))
    v = np.r_[lim.v_max, feed]
    a = np.r_[lim.a_max, 1e30]
    pc_v = constraint.JointVelocityConstraint(np.c_[-v, v])
    pc_a = constraint.JointAccelerationConstraint(
        np.c_[-a, a], discretization_scheme=constraint.DiscretizationType.Interpolation)
    inst = algo.TOPPRA([pc_v, pc_a], _FeedPath(path), gridpoints=np.asarray(gridpoints),
                       solver_wrapper="seidel")
    _, sd, _ = inst.compute_parameterization(0, 0)
    if sd is None:
        return None, None
    sd = np.maximum(sd, 0.0)
    return float(np.sum(2 * np.diff(gridpoints) / (sd[:-1] + sd[1:]))), sd


def toppra_grid(path):
    """160 nodes per arc, 80 per line (every break a node)."""
    counts = np.where(path.radius > 0, TOPPRA_PER_ARC, TOPPRA_PER_LINE)
    return grid_from_counts(path, counts)


def fmt_t(t: float) -> str:
    return f"{t * 1e3:.1f} ms" if t < 10 else f"{t:.2f} s"


def run_case(name, text, machine, *, with_toppra=True, repeat=1):
    path = build_path(parse_text(text, name), machine)
    arcs = int(np.sum(path.radius > 0))
    times = []
    sol = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        sol = optimal.solve(path, machine.limits)
        times.append(time.perf_counter() - t0)
    t_or = float(np.median(times))
    print(f"{name}: {path.n_segments} pieces ({arcs} arcs), L = {path.total_length:.1f} mm")
    print(f"    oracle  tol 0.2 %: {fmt_t(t_or)}, status {sol.status}, bracket "
          f"[{sol.lower_bound_s:.5f}, {sol.upper_bound_s:.5f}] s = {sol.gap:.3%}, "
          f"{sol.grid_points} points, {sol.iterations} rounds (build "
          f"{fmt_t(sol.build_time_s)}, solve {fmt_t(sol.solve_time_s)}, check "
          f"{fmt_t(sol.check_time_s)}, bound {fmt_t(sol.bound_time_s)})")
    if not with_toppra:
        print(f"    toppra: skipped")
        return path, t_or, None
    grid = toppra_grid(path)
    t_top = []
    T_top = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        T_top, sd = toppra_feed_solve(path, machine.limits, grid.s)
        t_top.append(time.perf_counter() - t0)
    tt = float(np.median(t_top))
    lo, hi = sol.lower_bound_s - sol.dwell_s, sol.upper_bound_s - sol.dwell_s
    where = ("inside the bracket" if T_top is not None and lo <= T_top <= hi else
             (f"{(T_top - lo) / lo:+.3%} from LB" if T_top is not None and T_top < lo
              else (f"{(T_top - hi) / hi:+.3%} from UB" if T_top is not None else "failed")))
    print(f"    toppra {TOPPRA_PER_ARC}/arc: {fmt_t(tt)}, {grid.n_points} nodes, T = "
          f"{T_top if T_top is None else f'{T_top:.5f}'} s ({where}), no bound")
    print(f"    oracle/toppra {name}: ratio = {t_or / tt:.2f}")
    return path, t_or, tt


def main(argv=None) -> None:
    """Print the rows (``--profile``: cProfile of the S-bend case; ``--quick``)."""
    argv = sys.argv[1:] if argv is None else argv
    machine = load_machine()
    if "--profile" in argv:
        path = build_path(parse_text(sbend_gcode(), "sbend200"), machine)
        pr = cProfile.Profile()
        pr.enable()
        optimal.solve(path, machine.limits)
        pr.disable()
        buf = io.StringIO()
        pstats.Stats(pr, stream=buf).sort_stats("cumulative").print_stats(30)
        print(buf.getvalue())
        return
    # the compiled sweep (optimal.backends.kernel) loads once per process: measured and
    # shown on its own row, then every case runs warm, as toppra does after its import
    t0 = time.perf_counter()
    from optimal.backends.kernel import greatest_element
    greatest_element(np.ones(3), np.zeros((2, 1)), np.zeros((2, 1)), np.zeros((2, 1)))
    print(f"compiled sweep: loaded once per process in {fmt_t(time.perf_counter() - t0)} "
          f"(not in the rows below; small problems keep the numpy sweep and never load it)")
    run_case("stadium", stadium_gcode(), machine, repeat=3)
    run_case("sbend200", sbend_gcode(), machine, repeat=3)
    sizes, tims = [], []
    for n in (10_000,) + (() if "--quick" in argv else (100_000,)):
        # toppra has no junction rule (stop or velocity jump at the sharp corners),
        # so it solves another problem here: oracle alone, as in the issue
        path, t_or, _ = run_case(f"cam1e{len(str(n)) - 1}", cam_gcode(n), machine,
                                 with_toppra=False)
        sizes.append(path.n_segments)
        tims.append(t_or)
    if len(sizes) > 1:
        k = np.polyfit(np.log(sizes), np.log(tims), 1)[0]
        print(f"oracle on cam programs: time ~ pieces^k, k = {k:.2f}")


if __name__ == "__main__":
    main()
