"""The CLI on hostile programs (issue 9): exit 2 with one line naming file:line:col for
bad input, never exit 3, a traceback or a numpy warning; exit 0 for the real-program
features that are now implemented."""

from __future__ import annotations

import json
import re
import warnings
from pathlib import Path

import jsonschema
import pytest

from compare.cli import main
from compare.export import schema

NO_MOTION = {"empty.mpf": "", "comment.mpf": "; only a comment\n", "g90.mpf": "G90\n",
             "g90.ngc": "G90\n", "tool.mpf": "T1\nM6\n"}
N_BLOCKS = {"empty.mpf": 0, "comment.mpf": 0, "g90.mpf": 1, "g90.ngc": 1, "tool.mpf": 2}


def _run(argv: list[str], capsys) -> tuple[int, str, str]:
    with warnings.catch_warnings():
        warnings.simplefilter("error")           # no numpy warning may reach the user
        code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def _args(command: str, prog: Path, tmp_path: Path) -> list[str]:
    args = [command, str(prog), "--quiet"]
    if command == "compare":
        args += ["--report", str(tmp_path / "rep")]
    return args


@pytest.mark.parametrize("name", sorted(NO_MOTION))
@pytest.mark.parametrize("command", ["plan", "optimize", "compare"])
def test_a_program_without_motion_is_bad_input(tmp_path, capsys, name, command):
    prog = tmp_path / name
    prog.write_text(NO_MOTION[name])
    code, out, err = _run(_args(command, prog, tmp_path), capsys)
    assert code == 2
    n = N_BLOCKS[name]
    assert err.strip() == (f"feedoracle: {prog}: the program has no motion ({n} block"
                           f"{'' if n == 1 else 's'}, none moves an axis): nothing to plan, "
                           "optimize or compare")
    assert "no certified bounds" not in err + out
    assert not (tmp_path / "rep").exists()          # no partial report left behind


def test_inspect_lists_a_program_without_motion_with_a_note(tmp_path, capsys):
    prog = tmp_path / "g90.mpf"
    prog.write_text("G90\n")
    code, out, err = _run(["inspect", str(prog)], capsys)
    assert code == 0
    assert "0 segments" in out
    assert "no motion" in err


BAD = [
    ("nest.mpf", "G1 F1000 X=" + "(" * 500 + "1" + ")" * 500 + "\n", r":1:\d+: expression "
     r"nested too deeply"),
    ("nest.ngc", "G1 F1000 X" + "[" * 500 + "1" + "]" * 500 + "\n", r":1:\d+: expression "
     r"nested too deeply"),
    ("f0.mpf", "G1 X5 F0\n", r":1:7: G1 with feed F0"),
    ("big.mpf", "G1 F1000 X123456789012345678901234567890\n", r":1:10: position X = "),
    ("nines.mpf", "G1 F1000 X" + "9" * 400 + "\n", r":1:10: the value of X is too large"),
    ("exp.mpf", "G1 F1000 X1e308\n", r":1:12: 'E308' glued to a number"),
    ("bspline.mpf", "G1 F1000 X1\nBSPLINE X10 Y5\nG1 X20\n", r":2:1: BSPLINE \(B spline\) "
     r"is not supported"),
    ("m98.ngc", "G1 F100 X1\nM98 P1000\nM2\n", r":2:5: M98 P1000: there is no subprogram"),
    ("par.ngc", "G1 F100 X#99999\nM2\n", r":1:10: parameter number #99999 is out of range"),
]


@pytest.mark.parametrize("name, text, match", BAD, ids=[b[0] for b in BAD])
@pytest.mark.parametrize("command", ["inspect", "compare"])
def test_bad_programs_exit_2_naming_line_and_column(tmp_path, capsys, name, text, match,
                                                    command):
    prog = tmp_path / name
    prog.write_text(text)
    code, out, err = _run(_args(command, prog, tmp_path), capsys)
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1
    assert re.match(rf"feedoracle: {re.escape(str(prog))}{match}", lines[0]), lines[0]


def test_g64_negative_p_is_a_warning_and_compares(tmp_path, capsys):
    prog = tmp_path / "g64.ngc"
    prog.write_text("G64 P-1\nG1 F100 X10\nM2\n")
    code, out, err = _run(["compare", str(prog), "--no-report", "--quiet",
                           "--machine", "linuxcnc_xyz"], capsys)
    assert code == 0
    assert f"{prog}:1: warning: G64 P-1: a negative tolerance means no tolerance" in err


MACHINE_A = """\
[machine]
name = "mill with A"
ipo_cycle_ms = 4.0
[axis.X]
MAX_AX_VELO = 30000.0
MAX_AX_ACCEL = 2.0
MAX_AX_JERK = 40.0
[axis.Y]
MAX_AX_VELO = 30000.0
MAX_AX_ACCEL = 2.0
MAX_AX_JERK = 40.0
[axis.Z]
MAX_AX_VELO = 20000.0
MAX_AX_ACCEL = 1.5
MAX_AX_JERK = 30.0
[axis.A]
type = "rotary"
MAX_AX_VELO = 30.0
MAX_AX_ACCEL = 1.0
MAX_AX_JERK = 20.0
"""

REAL = [
    ("toolname.mpf", 'G1 F1000 X1\nT="DRILL 8.5"\nM6\nG1 X20\nM30\n'),
    ("pos.mpf", "G1 F1000 X10\nPOS[A]=90\nG1 X20\nM30\n"),
    ("roty.mpf", "ROT Y-90\nG1 F1000 X10\nG1 Y10\nG2 X0 Y0 I-5 J-5\nROT\nM30\n"),
]


@pytest.mark.parametrize("name, text", REAL, ids=[r[0] for r in REAL])
def test_real_program_features_compare_and_validate(tmp_path, capsys, name, text):
    prog = tmp_path / name
    prog.write_text(text)
    machine = tmp_path / "m.toml"
    machine.write_text(MACHINE_A)
    out_json = tmp_path / "r.json"
    code, out, err = _run(["compare", str(prog), "--machine", str(machine), "--no-report",
                           "--quiet", "--json", str(out_json)], capsys)
    assert code == 0, err
    doc = json.loads(out_json.read_text())
    jsonschema.validate(doc, schema())
    assert doc["oracle"]["status"] == "optimal"
    assert doc["oracle"]["lower_bound_s"] <= doc["oracle"]["upper_bound_s"]


def test_check_against_a_program_without_motion_is_bad_input(tmp_path, capsys):
    prog = tmp_path / "g90.mpf"
    prog.write_text("G90\n")
    traj = tmp_path / "t.csv"
    traj.write_text("t,X,Y,Z\n0,0,0,0\n0.004,0,0,0\n")
    code, out, err = _run(["check", str(traj), "--program", str(prog), "--quiet"], capsys)
    assert code == 2
    assert err.strip().startswith(f"feedoracle: {prog}: the program has no motion")


@pytest.mark.parametrize("command, module, name, who", [
    ("optimize", "optimal", "solve", "acc oracle"),
    ("plan", "reference.planner", "plan", "heuristic")])
def test_an_invalid_motion_built_by_an_engine_is_an_internal_error(tmp_path, capsys,
                                                                    monkeypatch, command,
                                                                    module, name, who):
    """The oracle and the heuristic build every profile from the validated program, path
    and limits, so a ProfileError from inside them is their own bug: exit 3 with a line
    saying so, not exit 2 as if the program were bad (the FIR candidate once ran 30 mm
    past the path end of a line whose ramps took exactly 1/f, and the CLI blamed the
    input)."""
    import importlib
    from reference.core.errors import ProfileError

    def broken(*args, **kwargs):
        raise ProfileError("profile starts at s = 0 mm and ends at s = 56.5 mm but the "
                           "path is 26.1 mm long")

    monkeypatch.setattr(importlib.import_module(module), name, broken)
    prog = tmp_path / "line.ngc"
    prog.write_text("G21 G90 G1 X20 F6000\nM2\n")
    code, out, err = _run([command, str(prog), "--quiet"], capsys)
    assert code == 3
    assert f"{who} built an invalid motion" in err and "Traceback" not in err
