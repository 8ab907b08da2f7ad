"""Parse + path building throughput (issue: 100 000 short G1 blocks well under 5 s).

Prints blocks per second for 10^3..10^5 blocks of short G1 moves, for the parser alone
and for parse + prepare, and the scaling exponent of the whole pipeline.
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from reference.nc import parse_text
from reference.prepare import prepare


def make_program(n: int, seed: int = 1) -> str:
    """A SINUMERIK program of ``n`` short G1 moves (0.05..0.5 mm) wandering in XY."""
    rng = np.random.default_rng(seed)
    steps = rng.uniform(0.05, 0.5, n)
    ang = np.cumsum(rng.normal(0.0, 0.2, n))
    xy = np.cumsum(np.c_[steps * np.cos(ang), steps * np.sin(ang)], axis=0)
    lines = ["G90 G64 SOFT F6000"]
    lines += [f"N{i + 1} G1 X{x:.4f} Y{y:.4f}" for i, (x, y) in enumerate(xy)]
    lines.append("M30")
    return "\n".join(lines) + "\n"


def _median_time(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    """Print throughput rows."""
    sizes = (1_000, 10_000, 100_000)
    totals = []
    for n in sizes:
        text = make_program(n)
        rep = 5 if n < 100_000 else 3
        t_parse = _median_time(lambda: parse_text(text, "bench.mpf", "sinumerik"), rep)
        t_all = _median_time(lambda: prepare(parse_text(text, "bench.mpf", "sinumerik")), rep)
        totals.append(t_all)
        print(f"parse            N={n:>7}  {n / t_parse:>10,.0f} blocks/s  ({t_parse * 1e3:8.1f} ms)")
        print(f"parse+prepare    N={n:>7}  {n / t_all:>10,.0f} blocks/s  ({t_all * 1e3:8.1f} ms)"
              f"  target 100000 blocks < 5 s: ratio {t_all / 5.0 * (100_000 / n):.3f}")
    k = np.polyfit(np.log(sizes), np.log(totals), 1)[0]
    print(f"parse+prepare scaling exponent (time ~ N^k): k = {k:.2f}")


if __name__ == "__main__":
    main()
