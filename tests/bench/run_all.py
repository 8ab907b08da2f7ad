"""Run every benchmark script in this folder (``make bench``) and print their rows.

Each ``bench_*.py`` is a standalone script that prints ratio rows side by side with the
implementation it is compared to, measured in the same run. Timings are medians of
repeated runs (``time.perf_counter``); memory peaks come from ``tracemalloc``.
"""

from __future__ import annotations

import runpy
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main() -> int:
    """Run all benchmarks in name order; returns 0 if every script finished."""
    sys.path.insert(0, str(HERE.parents[1]))
    failed = []
    for script in sorted(HERE.glob("bench_*.py")):
        print(f"== {script.name}", flush=True)
        try:
            runpy.run_path(str(script), run_name="__main__")
        except SystemExit as exc:
            if exc.code not in (0, None):
                failed.append(script.name)
        except Exception as exc:  # a broken benchmark must not hide the others
            print(f"   FAILED: {type(exc).__name__}: {exc}", flush=True)
            failed.append(script.name)
    if failed:
        print("failed benchmarks: " + ", ".join(failed))
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
