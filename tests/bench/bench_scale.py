"""Whole-process scale of the CLI (``make bench``; issue 9, item 5).

Rows, all measured in this run, each ``feedoracle`` run a fresh process (start-up,
imports, parsing, writing the table included) timed by ``/usr/bin/time`` when present,
else by ``resource.getrusage(RUSAGE_CHILDREN)`` around a wrapper process:

* ``plan`` of 10^4, 10^5 and 10^6 short G1 blocks (a wandering CAM-like polyline, as in
  bench_planner): blocks per second against the target of 20 000 blocks/s, peak RSS
  against the budget of 2 GB, and the scaling exponent k of time ~ N^k and RSS ~ N^k
  (1 = linear) from the three sizes;
* ``compare`` of 10^5 mixed blocks (short lines and short arcs alternating): wall time,
  peak RSS against 2 GB, and the oracle's status and bracket ``UB/LB - 1``.

Set ``BENCH_SCALE_MAX=100000`` to skip the 10^6 run (about a minute and a half alone).
"""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path as FsPath

import numpy as np

ROOT = FsPath(__file__).resolve().parents[2]
TARGET_BLOCKS_PER_S = 20_000
RSS_BUDGET_B = 2 * 1024 ** 3
SIZES = (10_000, 100_000, 1_000_000)
COMPARE_SIZE = 100_000


def lines_program(n: int, seed: int = 1) -> str:
    """``n`` short G1 moves (0.05..0.5 mm) wandering in XY."""
    rng = np.random.default_rng(seed)
    steps = rng.uniform(0.05, 0.5, n)
    ang = np.cumsum(rng.normal(0.0, 0.2, n))
    xy = np.cumsum(np.c_[steps * np.cos(ang), steps * np.sin(ang)], axis=0)
    out = ["G90 G64 SOFT G1 F6000 X0 Y0"]
    out += [f"G1 X{x:.4f} Y{y:.4f}" for x, y in xy]
    out.append("M30")
    return "\n".join(out) + "\n"


def mixed_program(n: int, seed: int = 2) -> str:
    """``n`` blocks alternating a short line and a short arc (10..40 degrees, r 1..5 mm),
    tangent where they meet, the direction wandering like CAM output."""
    rng = np.random.default_rng(seed)
    x = y = 0.0
    head = 0.0
    out = ["G90 G64 SOFT G17 G1 F3000 X0 Y0"]
    for i in range(n):
        if i % 2 == 0:
            step = rng.uniform(0.2, 1.0)
            x += step * math.cos(head)
            y += step * math.sin(head)
            out.append(f"G1 X{x:.4f} Y{y:.4f}")
        else:
            r = rng.uniform(1.0, 5.0)
            sweep = math.radians(rng.uniform(10.0, 40.0))
            ccw = rng.random() < 0.5
            side = 1.0 if ccw else -1.0
            cx, cy = x - side * r * math.sin(head), y + side * r * math.cos(head)
            a0 = math.atan2(y - cy, x - cx)
            a1 = a0 + side * sweep
            nx, ny = cx + r * math.cos(a1), cy + r * math.sin(a1)
            out.append(f"{'G3' if ccw else 'G2'} X{nx:.6f} Y{ny:.6f} "
                       f"I{cx - x:.6f} J{cy - y:.6f}")
            x, y, head = nx, ny, head + side * sweep
    out.append("M30")
    return "\n".join(out) + "\n"


def run_cli(argv: list[str]) -> tuple[float, float, int]:
    """Wall time (s), peak RSS (bytes) and exit code of one ``feedoracle`` process."""
    script = FsPath(sys.executable).parent / "feedoracle"     # the venv's entry point
    exe = [str(script)] if script.exists() else [sys.executable, "-m", "compare.cli"]
    timer = shutil.which("time") or ("/usr/bin/time" if os.path.exists("/usr/bin/time")
                                     else None)
    with tempfile.NamedTemporaryFile("r", suffix=".time") as tf:
        cmd = exe + argv
        if timer:
            cmd = [timer, "-f", "%e %M", "-o", tf.name] + cmd
        t0 = time.perf_counter()
        p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                           cwd=ROOT, text=True)
        wall = time.perf_counter() - t0
        if timer:
            fields = tf.read().split()
            rss = float(fields[-1]) * 1024
        else:
            import resource
            rss = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024
    if p.returncode not in (0, 1):
        print(f"   {' '.join(argv)}: exit {p.returncode}: {p.stderr.strip()[-300:]}")
    return wall, rss, p.returncode


def _exponent(ns, ys) -> float:
    return float(np.polyfit(np.log(ns), np.log(ys), 1)[0])


def main() -> int:
    top = int(os.environ.get("BENCH_SCALE_MAX", SIZES[-1]))
    sizes = [n for n in SIZES if n <= top]
    tmp = FsPath(tempfile.mkdtemp(prefix="bench_scale_"))
    try:
        print(f"   {'case':<34} {'wall s':>8} {'blocks/s':>10} {'/target':>8} "
              f"{'RSS MB':>8} {'/2 GB':>7}")
        walls, rsss = [], []
        for n in sizes:
            f = tmp / f"lines_{n}.mpf"
            f.write_text(lines_program(n))
            wall, rss, _ = run_cli(["plan", str(f), "--quiet"])
            walls.append(wall)
            rsss.append(rss)
            print(f"   {'plan ' + format(n, ',') + ' short G1':<34} {wall:>8.2f} "
                  f"{n / wall:>10.0f} {n / wall / TARGET_BLOCKS_PER_S:>8.2f} "
                  f"{rss / 2 ** 20:>8.0f} {rss / RSS_BUDGET_B:>7.2f}")
        if len(sizes) >= 2:
            print(f"   scaling exponent plan time ~ N^k: k = {_exponent(sizes, walls):.2f}; "
                  f"RSS ~ N^k: k = {_exponent(sizes, rsss):.2f} (1 = linear; fit over "
                  f"{', '.join(format(n, '.0e') for n in sizes)}; start-up weighs on the "
                  "smallest)")
            print(f"   scaling exponent between the two largest: time k = "
                  f"{_exponent(sizes[-2:], walls[-2:]):.2f}, RSS k = "
                  f"{_exponent(sizes[-2:], rsss[-2:]):.2f}")
        f = tmp / "mixed.mpf"
        f.write_text(mixed_program(COMPARE_SIZE))
        js = tmp / "mixed.json"
        wall, rss, code = run_cli(["compare", str(f), "--quiet", "--no-report",
                                   "--json", str(js)])
        status, bracket = "-", math.nan
        if js.exists():
            o = json.loads(js.read_text()).get("oracle", {})
            status = o.get("status", "-")
            lb, ub = o.get("lower_bound_s"), o.get("upper_bound_s")
            if lb and ub:
                bracket = ub / lb - 1
        n = COMPARE_SIZE
        print(f"   {'compare ' + format(n, ',') + ' mixed lines/arcs':<34} {wall:>8.2f} "
              f"{n / wall:>10.0f} {'':>8} {rss / 2 ** 20:>8.0f} {rss / RSS_BUDGET_B:>7.2f}")
        print(f"   compare oracle status {status}, bracket UB/LB - 1 = "
              f"{100 * bracket:.2f} % (exit {code})")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
