"""Fixtures of the compare tests: programs, the default machine, and stand-in engines."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from fakes import fake_plan, fake_solution  # noqa: E402

from reference.machine import load_machine  # noqa: E402
from reference.nc import parse_text  # noqa: E402
from reference.prepare import prepare, restrict_to_machine  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]

#: A small program with corners, an arc, an exact stop and a dwell.
SMALL = """; small test program <b>markup</b> & "quotes"
N10 G90 G64 F6000
N20 G1 X50 Y0
N30 G1 X50 Y30
N40 G2 X80 Y60 CR=30
N50 G9 G1 X120
N60 G4 F0.2
N70 G1 X120 Y0 F3000
M30
"""


@pytest.fixture(scope="session")
def machine():
    return load_machine(None)


@pytest.fixture
def small_program(tmp_path) -> Path:
    p = tmp_path / "small.mpf"
    p.write_text(SMALL)
    return p


def path_of(text: str, machine, dialect: str = "sinumerik", file: str = "t.mpf"):
    program = parse_text(text, file, dialect)
    return program, restrict_to_machine(prepare(program), machine.limits)


@pytest.fixture
def fake_engines(monkeypatch):
    """Replace the heuristic and the oracle by the fakes (CLI tests of compare alone)."""
    from compare import engines

    def run_heuristic(program, machine, progress=None, *, path=None):
        if path is None:
            path = restrict_to_machine(prepare(program), machine.limits)
        return fake_plan(path, machine.limits)

    def run_oracle(path, limits, bounds, progress=None, *, tol=None, holds=None,
                   max_grid=None):
        return fake_solution(path, limits)

    monkeypatch.setattr(engines, "run_heuristic", run_heuristic)
    monkeypatch.setattr(engines, "run_oracle", run_oracle)
    monkeypatch.setattr(engines, "oracle_bound_sets", lambda: ("acc",))
    return engines
