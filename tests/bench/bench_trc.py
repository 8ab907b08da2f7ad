"""The cost of tool radius compensation and tangential control in the heuristic.

A seeded CAM-like polyline of 10^4 lines (0.5..5 mm, turns of 5..120 degrees, F6000;
the polyline of bench_rounding.py) is planned by the heuristic (``build_path`` +
``plan`` without its check) as programmed (G40), with G42 and a 0.1 mm tool under G450
and G451, and with tangential control of C (with and without TLIFT), on the default
machine. Rows: wall time per block against the programmed contour, measured in the same
run (median of 3), split into the path (``build_path``) and the plan; the number of
inserted segments; the planned motion times. Target: at most 3 x the programmed
contour's time per block. The inserted segments (a G450 circle per outside corner, a
TLIFT block per corner) can double the segment count, and with it the plan's time; the
two stages themselves are per-element loops in Python, some 10 (TANG) to 30 (TRC)
microseconds per block (vectorising them is the way to the 1.3 x of the rounding stage).
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path as FsPath

HERE = FsPath(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))
sys.path.insert(0, str(HERE))

from bench_rounding import polyline  # noqa: E402
from reference.core.geometry import KIND_CODES  # noqa: E402
from reference.machine import load_machine  # noqa: E402
from reference.nc import parse_text  # noqa: E402
from reference.planner import plan  # noqa: E402
from reference.prepare import build_path  # noqa: E402

TARGET = 3.0


def timed(text: str, machine, repeat: int = 3):
    """Median wall times of build_path and of plan (no check), s; the last path, plan."""
    prog = parse_text(text)
    t_path, t_plan, path, res = [], [], None, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        path = build_path(prog, machine)
        t1 = time.perf_counter()
        res = plan(prog, machine, path=path, check=False)
        t_path.append(t1 - t0)
        t_plan.append(time.perf_counter() - t1)
    return statistics.median(t_path), statistics.median(t_plan), path, res


def main(argv=None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    n = 2000 if "--quick" in argv else 10000
    body = polyline(n)
    machine = load_machine()
    head = "$TC_DP6[1,1]=0.1\nT1 D1\nG90 G64 F6000\nG1 X0 Y0\n{on}G1 "
    cases = {
        "G42 G450": "G42 G450 ",
        "G42 G451": "G42 G451 ",
        "TANG": "TANG(C, X, Y, 1)\nTANGON(C, 0)\n",
        "TANG TLIFT": "TANG(C, X, Y, 1)\nTANGON(C, 0)\nTLIFT(C)\n",
    }
    p0, q0, base, r0 = timed(head.format(on="") + body, machine)
    total0 = p0 + q0
    worst = 0.0
    for name, on in cases.items():
        p, q, path, r = timed(head.format(on=on) + body, machine)
        inserted = sum(1 for k in path.kind if KIND_CODES[int(k)] in ("trc", "tlift"))
        ratio = (p + q) / total0
        worst = max(worst, ratio)
        print(f"  {name:<11} {n} blocks: path {1e6 * p / n:6.1f} + plan {1e6 * q / n:6.1f} "
              f"us/block vs programmed {1e6 * p0 / n:6.1f} + {1e6 * q0 / n:6.1f}  "
              f"ratio = {ratio:.2f};  {inserted} inserted segments; motion "
              f"{r.profile.duration:.2f} s vs {r0.profile.duration:.2f} s", flush=True)
    print(f"  worst ratio {worst:.2f} (target <= {TARGET})")


if __name__ == "__main__":
    main()
