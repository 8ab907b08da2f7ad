"""``reference.build_path``: the one path the heuristic and the oracle share.

The heuristic's plan must run on exactly the path ``build_path`` gives (field by field,
on hand-built programs and on every corpus program); a path handed to ``plan`` is used as
is (same object), and one of another program is refused. Geometry against hand values.
"""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path as FsPath

import numpy as np
import pytest

import reference
from reference.core.errors import FeedOracleError, MachineDataError
from reference.machine import load_machine
from reference.nc import parse_file, parse_text
from reference.planner import plan
from shared_inputs import corpus_cases, corpus_listing

ROOT = FsPath(__file__).resolve().parents[2]
SUFFIXES = (".mpf", ".spf", ".ngc", ".nc", ".tap")
# without ../shared the corpus cases are one skipped case that says so
PROGRAMS = [ROOT / "examples" / "demo.mpf", ROOT / "examples" / "slot.ngc"] + corpus_cases(
    sorted(p for p in corpus_listing() if p.suffix.lower() in SUFFIXES))

SQUARE_ARC = "N10 G90 G64 F6000\nN20 G1 X30 Y0\nN30 G1 Y40\nN40 G3 X0 Y70 CR=30\nM30\n"


def _same_path(a, b) -> None:
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            np.testing.assert_array_equal(x, y, err_msg=f.name)
        else:
            assert x == y, f.name


def test_hand_geometry_of_lines_and_a_quarter_arc():
    machine = load_machine()
    path = reference.build_path(parse_text(SQUARE_ARC, "sq.mpf"), machine)
    assert path.axes == ("X", "Y", "Z")
    # 30 mm, 40 mm and a quarter circle of radius 30 about (0, 40)
    np.testing.assert_allclose(path.length, [30.0, 40.0, math.pi * 30 / 2], rtol=1e-12)
    assert path.total_length == pytest.approx(70.0 + 15.0 * math.pi, rel=1e-12)
    assert [s.line for s in path.blocks] == [1, 2, 3, 4, 5]
    assert path.stop_reason[0] == "start" and path.stop_reason[-1] == "M30 program end"


def test_axes_the_machine_lacks_are_dropped_or_named():
    machine = load_machine()
    # U named (in a block without motion of U) but never moved: not part of the path
    p = parse_text("N10 G90 G1 X10 U0 F600\nN20 X20\nM30\n", "u.mpf")
    assert "U" not in reference.build_path(p, machine).axes
    moved = parse_text("N10 G90 G1 X10 F600\nN20 U5\nM30\n", "u.mpf")
    with pytest.raises(MachineDataError, match=r"u\.mpf:2: the program moves axis U"):
        reference.build_path(moved, machine)


@pytest.mark.parametrize("machine_name", ["default", "linuxcnc_xyz"])
@pytest.mark.parametrize("prog", PROGRAMS, ids=lambda p: p.name)
def test_the_heuristic_plans_on_exactly_build_path(prog, machine_name):
    machine = load_machine(machine_name)
    program = parse_file(prog)
    try:
        path = reference.build_path(program, machine)
    except FeedOracleError as exc:          # e.g. an axis the machine lacks: same error
        with pytest.raises(type(exc), match=re.escape(str(exc))):
            plan(program, machine, check=False)
        return
    _same_path(plan(program, machine, check=False).path, path)


def test_a_given_path_is_used_as_is_and_another_programs_refused():
    machine = load_machine()
    program = parse_text(SQUARE_ARC, "sq.mpf")
    path = reference.build_path(program, machine)
    assert plan(program, machine, path=path, check=False).path is path
    other = reference.build_path(parse_text("N10 G90 G1 X5 F600\nM30\n", "other.mpf"), machine)
    with pytest.raises(ValueError, match=r"not the path of 'sq\.mpf'"):
        plan(program, machine, path=other)
