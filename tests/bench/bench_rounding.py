"""Corner rounding's cost in the heuristic (issue 13: at most 30 % per block).

A seeded CAM-like polyline of 10^4 lines (0.5..5 mm, turns of 5..120 degrees, F6000)
is planned by the heuristic (``build_path`` + ``plan``, the planner's own check
included) under G64 and under each rounding mode, on the default machine with BRISK and
SOFT. Rows: wall time per block of the rounded program against the same program under
G64, measured in the same run (median of 3): planning (``build_path`` + ``plan`` without
its check) and, separately, ``check_profile`` of the plan (it samples every arc at 0.125
degree of sweep, so each small rounding arc costs it hundreds of points), with the number
of corners rounded and the planned motion time of both (the rounding's effect).
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path as FsPath

import numpy as np

HERE = FsPath(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))

from reference.core.constraints import check_profile  # noqa: E402
from reference.machine import load_machine  # noqa: E402
from reference.nc import parse_text  # noqa: E402
from reference.planner import plan  # noqa: E402
from reference.prepare import build_path  # noqa: E402

TARGET = 1.30


def polyline(n: int, seed: int = 13) -> str:
    """``n`` G1 lines with seeded lengths and turns (body only, no mode words)."""
    rng = np.random.default_rng(seed)
    heading, x, y = 0.0, 0.0, 0.0
    out = []
    for _ in range(n):
        heading += np.radians(rng.uniform(5.0, 120.0)) * rng.choice((-1.0, 1.0))
        step = rng.uniform(0.5, 5.0)
        x += step * np.cos(heading)
        y += step * np.sin(heading)
        out.append(f"X{x:.4f} Y{y:.4f}")
    return "\n".join(out) + "\nM30\n"


def timed(text: str, machine, repeat: int = 3):
    """Median wall times of (build_path + plan without check) and of the planner's own
    check, s; the last plan and path."""
    t_plan, t_check, res, path = [], [], None, None
    prog = parse_text(text)
    for _ in range(repeat):
        t0 = time.perf_counter()
        path = build_path(prog, machine)
        res = plan(prog, machine, path=path, check=False)
        t1 = time.perf_counter()
        check_profile(path, machine.limits, res.profile)
        t_plan.append(t1 - t0)
        t_check.append(time.perf_counter() - t1)
    return statistics.median(t_plan), statistics.median(t_check), res, path


def main(argv=None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    n = 2000 if "--quick" in argv else 10000
    body = polyline(n)
    machine = load_machine()
    worst = 0.0
    for accel in ("BRISK", "SOFT"):
        head = f"G90 {accel} F6000\nG1 X0 Y0\nG1 "
        t64, c64, r64, _ = timed(head.replace("G90", "G90 G64") + body, machine)
        for mode in ("G641 ADIS=0.2", "G642 CTOL=0.02", "G642", "G645 CTOL=0.02"):
            t, c, r, path = timed(head.replace("G90", f"G90 {mode}") + body, machine)
            tab = path.rounding
            n_in = int(tab.inserted.sum()) if tab is not None else 0
            ratio = t / t64
            worst = max(worst, ratio)
            print(f"  {accel:<5} {mode:<15} {n} blocks: plan {1e6 * t / n:6.1f} us/block vs "
                  f"G64 {1e6 * t64 / n:6.1f}  ratio = {ratio:.2f};  check {1e6 * c / n:6.1f} "
                  f"vs {1e6 * c64 / n:6.1f} us/block  ratio = {c / c64:.1f}  ({n_in} of "
                  f"{n - 1} corners rounded; motion {r.time_s:.1f} s vs {r64.time_s:.1f} s "
                  "under G64)", flush=True)
    print(f"  rounding/G64 heuristic planning time per block (build_path + plan, without "
          f"the check): worst ratio = {worst:.2f} (target <= {TARGET:.2f}) "
          f"{'ok' if worst <= TARGET else 'ABOVE TARGET'}")


if __name__ == "__main__":
    main()
