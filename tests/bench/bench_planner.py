"""Reference planner throughput and its relation to the oracle (``make bench``).

Rows, all measured in this run:

* blocks per second of the whole pipeline from NC text to profile (parse, prepare, plan)
  for 10^3, 10^4 and 10^5 short G1 blocks (SOFT, G64, a wandering CAM-like polyline),
  against the target of 20 000 blocks/s; the same with the planner's own
  ``check_profile``; the scaling exponent k of time ~ N^k (1 = linear);
* the planner alone on a short-block program with LookAhead smoothing and dynamic
  adaptation switched on;
* heuristic vs oracle on the same path (``optimal.solve(path, limits, bounds="acc")``,
  BRISK program so that both keep the same bound set): the ratio of the computing times
  and the ratio of the motion times ``t_ref / t_opt`` (upper and lower bound of the
  oracle). Prints "oracle not available" when the oracle package cannot be imported.
"""

from __future__ import annotations

import dataclasses
import statistics
import sys
import time
from pathlib import Path as FsPath

import numpy as np

sys.path.insert(0, str(FsPath(__file__).resolve().parents[2]))

from reference.machine import load_machine  # noqa: E402
from reference.nc import parse_text  # noqa: E402
from reference.planner import PlannerParameters, plan  # noqa: E402

TARGET_BLOCKS_PER_S = 20_000


def make_program(n: int, mode: str = "SOFT", seed: int = 1) -> str:
    """``n`` short G1 moves (0.05..0.5 mm) wandering in XY, as in bench_parse."""
    rng = np.random.default_rng(seed)
    steps = rng.uniform(0.05, 0.5, n)
    ang = np.cumsum(rng.normal(0.0, 0.2, n))
    xy = np.cumsum(np.c_[steps * np.cos(ang), steps * np.sin(ang)], axis=0)
    lines = [f"G90 G64 {mode} F6000"]
    lines += [f"N{i + 1} G1 X{x:.4f} Y{y:.4f}" for i, (x, y) in enumerate(xy)]
    lines.append("M30")
    return "\n".join(lines) + "\n"


def _median_time(fn, repeat: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def throughput_rows(machine) -> None:
    """Blocks per second from text to profile, with and without the self-check."""
    sizes = (1_000, 10_000, 100_000)
    totals = []
    for n in sizes:
        text = make_program(n)
        rep = 5 if n < 100_000 else 3

        def pipeline(check: bool):
            return plan(parse_text(text, "bench.mpf", "sinumerik"), machine, check=check)

        t_all, p = _median_time(lambda: pipeline(False), rep)
        t_chk, pc = _median_time(lambda: pipeline(True), max(1, rep - 2))
        totals.append(t_all)
        print(f"text->profile    N={n:>7}  {n / t_all:>10,.0f} blocks/s  ({t_all * 1e3:8.1f} ms)"
              f"  target {TARGET_BLOCKS_PER_S} blocks/s: ratio "
              f"{(n / t_all) / TARGET_BLOCKS_PER_S:.2f}", flush=True)
        print(f"text->checked    N={n:>7}  {n / t_chk:>10,.0f} blocks/s  ({t_chk * 1e3:8.1f} ms)"
              f"  self-check ok: {pc.ok}; motion {p.time_s:.3f} s", flush=True)
    k = np.polyfit(np.log(sizes), np.log(totals), 1)[0]
    print(f"text->profile scaling exponent (time ~ N^k): k = {k:.2f} (1 = linear)")


def feature_rows(machine) -> None:
    """Planner alone with smoothing and adaptation on (10^4 blocks), against the bare
    LookAhead (no smoothing stage: the machine data have no "off", MD20460 = 0 selects
    100 %)."""
    n = 10_000
    prog = parse_text(make_program(n), "bench.mpf", "sinumerik")
    ch = dataclasses.replace(machine.channel, lookahead_smooth_factor_pct=5.0,
                             adapt_path_dynamic=(1.5, 1.5))
    m2 = dataclasses.replace(machine, channel=ch)
    bare = PlannerParameters(smoothing_rounds=0)
    t_plain, _ = _median_time(lambda: plan(prog, machine, check=False, parameters=bare), 3)
    t_feat, _ = _median_time(lambda: plan(prog, m2, check=False), 3)
    print(f"plan only        N={n:>7}  {n / t_plain:>10,.0f} blocks/s; with smoothing 5 % + "
          f"adaptation 1.5: {n / t_feat:,.0f} blocks/s (ratio {t_feat / t_plain:.2f})")


def oracle_rows(machine) -> None:
    """Heuristic vs oracle on the same path (BRISK program, bound set acc)."""
    try:
        import optimal
    except Exception as exc:  # the oracle is another engineer's package
        print(f"heuristic/oracle: oracle not available ({type(exc).__name__}: {exc})")
        return
    for n in (1_000, 10_000):
        prog = parse_text(make_program(n, mode="BRISK"), "bench.mpf", "sinumerik")
        t_h, p = _median_time(lambda: plan(prog, machine, check=False), 3)
        t0 = time.perf_counter()
        try:
            sol = optimal.solve(p.path, machine.limits, bounds="acc")
        except Exception as exc:
            print(f"heuristic/oracle N={n:>7}: oracle failed ({type(exc).__name__}: {exc})")
            continue
        t_o = time.perf_counter() - t0
        ub = float(getattr(sol, "upper_bound_s", float("nan")))
        lb = float(getattr(sol, "lower_bound_s", float("nan")))
        status = getattr(getattr(sol, "status", None), "value", getattr(sol, "status", "?"))
        print(f"heuristic/oracle N={n:>7}  computing time {t_h * 1e3:8.1f} ms / "
              f"{t_o * 1e3:9.1f} ms = ratio {t_h / t_o:.4f}; motion time t_ref/UB "
              f"{p.time_s / ub:.4f}, t_ref/LB {p.time_s / lb:.4f} (oracle {status})",
              flush=True)


def main() -> None:
    """Print all rows."""
    machine = load_machine()
    throughput_rows(machine)
    feature_rows(machine)
    oracle_rows(machine)


if __name__ == "__main__":
    main()
