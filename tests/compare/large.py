"""Large mixed programs for the report tests, compared with the stand-in engines.

The program generator is the benchmark's (``tests/bench/bench_report.py``), so the tests
and ``make bench`` look at the same kind of program.
"""

from __future__ import annotations

import functools
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))

from bench_report import make_mixed_program  # noqa: E402
from conftest import path_of  # noqa: E402
from fakes import fake_plan, fake_solution  # noqa: E402

from compare.comparison import compare  # noqa: E402
from reference.machine import load_machine  # noqa: E402


@functools.lru_cache(maxsize=4)
def mixed_comparison(n: int):
    """The comparison of an ``n``-block mixed program on the default machine (cached:
    several tests read the same one)."""
    machine = load_machine(None)
    program, path = path_of(make_mixed_program(n), machine, file=f"mixed_{n}.mpf")
    return compare(fake_plan(path, machine.limits), fake_solution(path, machine.limits),
                   program=program, machine=machine.name)
