"""Compensated (G41/G42) and tangential (TANG/TLIFT) paths on every bundled machine: both
planners run on the same path, the ``acc`` oracle (a relaxation of both machines' own
bound sets) is optimal within its bracket, the heuristic
keeps its own bound set and is never faster than the certified lower bound (issue 14,
items 3 and 4: "compare runs both planners on the compensated path"; "the tangential
axis is a real axis of the path, so its limits enter both the heuristic and the
oracle")."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest

from compare import cli
from test_corpus_machines import MACHINES, _bundled, _toml

TOOL = "$TC_DP6[1,1]=4\nT1 D1\n"
PROGRAMS = {
    "trc_g450.mpf": TOOL + "G90 G64 F3000\nG0 X20 Y-15\nG42 G450 G1 X20 Y0\nG1 X60\n"
    "G3 X80 Y20 CR=20\nG1 Y40\nX0\nY0\nX30\nG40 G1 X30 Y-15\nM30\n",
    "trc_g451_disc.mpf": TOOL + "G90 G64 BRISK F4000\nG0 X20 Y-15\nG42 G451 G1 X20 Y0\n"
    "G1 X60\nX70 Y30\nG450 DISC=30 X0 Y40\nY0\nX30\nG40 G1 X30 Y-15\nM30\n",
    "trc_inside.mpf": TOOL + "G90 G64 F3000\nG0 X30 Y10\nG41 G1 X30 Y0\nG1 X60\n"
    "G3 X80 Y20 CR=20\nG1 Y40\nX0\nY0\nX35\nG40 G1 X30 Y10\nM30\n",
    "trc_linuxcnc.ngc": "G21 G90 G64\nG10 L1 P2 R3\nT2 M6\nG0 X20 Y-15\n"
    "G41 G1 X20 Y0 F2000\nG1 X60\nG3 X80 Y20 R20\nG1 Y40\nG0 X0\nG1 Y0\nX30\n"
    "G40 G1 X30 Y-15\nM2\n",
    "tang_tlift.mpf": "G90 G64 F3000\nTANG(C, X, Y, 1)\nTANGON(C, 0)\nTLIFT(C)\n"
    "G1 X20 Y0\nG3 X40 Y20 CR=20\nG1 Y40\nZ-2\nX0\nY0\nTANGOF(C)\nM30\n",
    "tang_follow.mpf": "G90 G64 F3000\nTANG(C, X, Y, 1)\nTANGON(C, 0)\nG1 X20 Y0\n"
    "G3 X40 Y20 CR=20\nG1 Y40\nX0 Y35\nY0\nTANGOF(C)\nM30\n",
    "trc_tang_g641.mpf": TOOL + "G90 G641 ADIS=1 F3000\nTANG(C, X, Y, 1)\nTANGON(C, 90)\n"
    "TLIFT(C)\nG0 X20 Y-15\nG42 G1 X20 Y0\nG1 X60\nY40\nX0\nY0\nX30\nG40 G1 X30 Y-15\n"
    "TANGOF(C)\nM30\n",
}


def _machine_file(tmp_path: Path, name: str) -> Path:
    """A bundled machine (or the overload-1.0 variant), with the default machine's C axis
    added where it has none (the LinuxCNC configuration is XYZ only)."""
    d = copy.deepcopy(MACHINES[name]())
    if "C" not in d["axis"]:
        c = copy.deepcopy(_bundled("default")["axis"]["C"])
        c["MAX_ACCEL_OVL_FACTOR"] = d["axis"]["X"]["MAX_ACCEL_OVL_FACTOR"]
        d["axis"]["C"] = c
    f = tmp_path / f"{name}.toml"
    f.write_text(_toml(d))
    return f


@pytest.mark.parametrize("machine", sorted(MACHINES))
@pytest.mark.parametrize("name", sorted(PROGRAMS))
def test_compensated_and_tangential_paths_compare_with_a_certificate(
        name: str, machine: str, tmp_path: Path, capsys) -> None:
    prog = tmp_path / name
    prog.write_text(PROGRAMS[name])
    out = tmp_path / "r.json"
    rc = cli.main(["compare", str(prog), "--machine", str(_machine_file(tmp_path, machine)),
                   "--no-report", "--quiet", "--json", str(out), "--bounds", "acc"])
    err = capsys.readouterr().err
    assert rc in (0, 1), err
    doc = json.loads(out.read_text())
    ora, ref = doc["oracle"], doc["reference"]
    assert ora["status"] == "optimal", ora
    lb, ub, t_ref = ora["lower_bound_s"], ora["upper_bound_s"], ref["time_s"]
    assert lb <= ub <= lb * (1 + 2e-3) + 1e-12
    assert not ref["violations"], ref["violations"]
    assert t_ref >= lb, f"heuristic {t_ref!r} s below the lower bound {lb!r} s"
    # every program block has its row, also the ones that now hold inserted segments
    # (a corner rounding has a row of its own after its block's, with its corner lines)
    lines = [r["line"] for r in doc["blocks"] if "corner_lines" not in r]
    assert lines == sorted(lines) and len(lines) == len(set(lines))


def test_the_tangential_program_on_the_xyz_machine_is_bad_input(tmp_path: Path,
                                                               capsys) -> None:
    """The machine must have the following axis: exit 2 naming the axis and the line."""
    prog = tmp_path / "tang_follow.mpf"
    prog.write_text(PROGRAMS["tang_follow.mpf"])
    rc = cli.main(["compare", str(prog), "--machine", "linuxcnc_xyz", "--no-report",
                   "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2 and "Traceback" not in err
    assert "axis.C" in err and "tang_follow.mpf:3: tangential control turns axis C" in err
