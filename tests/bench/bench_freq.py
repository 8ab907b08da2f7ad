"""The jerk+freq oracle against the jerk oracle on the same path, as ratios.

Path: the stadium of ``bench_jerk.py`` (default machine, 2 laps). At about 1,000 and
10,000 NLP grid intervals (``initial_intervals``; one round, ``tol`` wide open so both
stop after their first verified profile): wall time of ``optimal.solve(bounds="jerk")``
and of ``bounds="jerk+freq"`` (which runs that jerk solve inside, plus four acc solves and
the candidates' checks), and ``freq / jerk``. Also both brackets.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path as FsPath

HERE = FsPath(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))
sys.path.insert(0, str(HERE))

import optimal  # noqa: E402
from bench_jerk import stadium_gcode  # noqa: E402
from reference.machine import load_machine  # noqa: E402
from reference.nc import parse_text  # noqa: E402
from reference.prepare import build_path  # noqa: E402

SIZES = (1_000, 10_000)


def main() -> int:
    machine = load_machine(None)
    path = build_path(parse_text(stadium_gcode(), "stadium.mpf"), machine)
    print(f"stadium: {path.n_segments} segments, {path.total_length:.1f} mm, default machine")
    print(f"{'N':>7} {'jerk s':>9} {'freq s':>9} {'freq/jerk':>10}  brackets (jerk | freq)")
    for n in SIZES:
        opts = dict(initial_intervals=n, tol=1.0)
        t0 = time.perf_counter()
        j = optimal.solve(path, machine.limits, bounds="jerk", **opts)
        t1 = time.perf_counter()
        f = optimal.solve(path, machine.limits, bounds="jerk+freq", **opts)
        t2 = time.perf_counter()
        print(f"{j.grid_points:>7} {t1 - t0:>9.2f} {t2 - t1:>9.2f} {(t2 - t1) / (t1 - t0):>10.2f}"
              f"  [{j.lower_bound_s:.4f}, {j.upper_bound_s:.4f}] | "
              f"[{f.lower_bound_s:.4f}, {f.upper_bound_s:.4f}]", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
