"""Fuzz the CLI with generated NC programs and machine files (issue 9 item 4).

Property-based (Hypothesis) tests: for every generated SINUMERIK (``.mpf``) or LinuxCNC
(``.ngc``) program and every generated machine file, ``feedoracle inspect``, ``plan`` and
``compare --no-report`` exit 0, 1 or 2, never 3; print no traceback and no numpy warning;
stay under the memory budget; and on exit 2 name the file and line (or the machine-data
key). What "behaves" means in detail, and how memory and time are capped, is in
:mod:`fuzz_harness`; what is generated, in :mod:`fuzz_strategies`; seeded mutants of the
real programs of the corpus are in :mod:`test_fuzz_corpus`.

Running: ``make test`` runs the ``ci`` Hypothesis profile (a few derandomized examples
per test, the same on every run); ``make fuzz`` (``FEEDORACLE_FUZZ=1``) runs the ``fuzz``
profile with many random examples and shrinks a failure to a small program.
``FEEDORACLE_FUZZ_EXAMPLES=N`` sets the number of examples of either profile. A failing
example is printed with the program text; it reproduces with
``feedoracle compare PROGRAM --no-report``.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest
from hypothesis import event, given, reject
from hypothesis import strategies as st

from fuzz_harness import COMPARE_ARGS, assert_clean, known_bug, run_cli
from fuzz_strategies import machine_texts, programs

pytestmark = pytest.mark.fuzz

#: A small program with lines, a corner, an arc, an exact stop and a dwell: every machine
#: file is tried on it, so that a machine that loads is also planned and optimized.
MACHINE_PROBE = """\
G90 G17 G64 F3000
G1 X20 Y0
G1 X20 Y10
G2 X30 Y20 CR=10
G9 G1 X40
G4 F0.1
G1 X0 Y0 F6000
M30
"""


def _commands(prog: Path, machine: str | None) -> list[list[str]]:
    extra = ["--machine", machine] if machine else []
    return [["inspect", str(prog), "--quiet", *extra],
            ["plan", str(prog), "--quiet", *extra],
            ["compare", str(prog), "--quiet", "--no-report", *COMPARE_ARGS, *extra]]


def _judge(outcome, files: list[Path]) -> None:
    """Assert the outcome is clean; a known bug (test_fuzz_found.py) is counted and the
    example dropped, so that the search goes on for other bugs."""
    bug = known_bug(outcome)
    if bug is not None:
        event(f"known bug: {bug}")
        reject()
    event(f"{outcome.argv[0]} exit {outcome.code}")
    assert_clean(outcome, files)


def _check_program(text: str, suffix: str, machine: str | None) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        prog = Path(tmp) / f"fuzz{suffix}"
        prog.write_text(text, encoding="utf-8", newline="")
        for argv in _commands(prog, machine):
            outcome = run_cli(argv)
            _judge(outcome, [prog])


@given(text=programs("sin"), machine=st.sampled_from([None, "linuxcnc_xyz"]))
def test_generated_sinumerik_programs(text, machine):
    _check_program(text, ".mpf", machine)


@given(text=programs("ngc"), machine=st.sampled_from([None, "linuxcnc_xyz"]))
def test_generated_linuxcnc_programs(text, machine):
    _check_program(text, ".ngc", machine)


@given(raw=machine_texts())
def test_generated_machine_files(raw):
    with tempfile.TemporaryDirectory() as tmp:
        prog = Path(tmp) / "probe.mpf"
        prog.write_text(MACHINE_PROBE)
        machine = Path(tmp) / "fuzz.toml"
        machine.write_bytes(raw)
        for argv in _commands(prog, str(machine)):
            outcome = run_cli(argv)
            _judge(outcome, [prog, machine])
