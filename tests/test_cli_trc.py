"""The command line with tool radius compensation and tangential control: inspect shows
the offset and tangential blocks, --tool-table feeds cutter compensation, bad tool data
and collisions are bad input (exit 2 naming file and line), and a plan's CSV carries the
rotary axis column (issue 14 items 1 and 4)."""

from __future__ import annotations

import csv
import subprocess
import sys
from pathlib import Path

import pytest

from compare.cli import main

ROOT = Path(__file__).resolve().parents[1]

SQUARE = ("$TC_DP6[1,1]=5\nT1 D1\nG0 X20 Y-20\nG42 G1 X20 Y0 F3000\nG1 X40\nY40\nX0\n"
          "Y0\nX25\nG40 G1 X25 Y-20\nM30\n")
TANG = ("G90 F3000\nTANG(C, X, Y, 1)\nTANGON(C, 0)\nTLIFT(C)\nG1 X20 Y0\nG3 X40 Y20 CR=20\n"
        "G1 Y40\nX0\nTANGOF(C)\nM30\n")


def _write(tmp_path: Path, name: str, text: str) -> Path:
    f = tmp_path / name
    f.write_text(text)
    return f


def test_inspect_shows_the_compensated_blocks_corners_and_segments(tmp_path, capsys):
    assert main(["inspect", str(_write(tmp_path, "sq.mpf", SQUARE))]) == 0
    out = capsys.readouterr().out
    assert "tool radius compensation: 7 blocks, 5 corners" in out
    rows = {r.split()[0]: r.split() for r in out.splitlines()
            if r.strip().startswith(("4 approach", "10 retract"))}
    assert rows["4"][1:] == ["approach", "G42", "5.0000"]
    corner = next(r for r in out.splitlines() if r.strip().startswith("5/6 "))
    assert corner.split()[1:] == ["outside", "90.000", "7.8540", "circle"]
    trc = [r for r in out.splitlines() if " trc " in r]
    assert len(trc) == 4 and trc[0].split()[:4] == ["6", "trc", "7.8540", "5.0000"]


def test_inspect_shows_the_tangential_steps_and_tlift_blocks(tmp_path, capsys):
    assert main(["inspect", str(_write(tmp_path, "t.mpf", TANG))]) == 0
    out = capsys.readouterr().out
    # line, tangent arc, line (all tangent: the axis follows), then a 90 degree corner
    assert "tangential control: 1 tangent step\n" in out
    assert any(r.split()[:4] == ["8", "C", "90.000", "TLIFT"] for r in out.splitlines())
    tl = [r.split() for r in out.splitlines() if " tlift " in r]
    assert len(tl) == 1 and tl[0][:3] == ["8", "tlift", "90.0000"]


def test_tool_table_feeds_linuxcnc_cutter_compensation(tmp_path, capsys):
    prog = _write(tmp_path, "p.ngc", "G21 G90\nT4 M6\nG0 X20 Y-20\nG41 G1 X20 Y0 F2000\n"
                                     "G1 X40\nY40\nG40 G1 X60 Y40\nM2\n")
    # without a tool table the radius is missing: bad input naming the line
    assert main(["inspect", str(prog)]) == 0          # inspect still lists the program
    capsys.readouterr()
    assert main(["plan", str(prog), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"{prog}:4: G41: tool T4 D1 has no radius" in err and "--tool-table" in err
    table = _write(tmp_path, "tool.tbl", "T4 P4 D0.25 Z1 ; quarter inch\n")
    assert main(["plan", str(prog), "--quiet", "--tool-table", str(table),
                 "--tool-table-units", "inch"]) == 0
    capsys.readouterr()
    assert main(["inspect", str(prog), "--tool-table", str(table), "--tool-table-units",
                 "inch"]) == 0
    out = capsys.readouterr().out
    assert "5 contour   G41     3.1750" in out                  # 0.25 in / 2


def test_bad_tool_table_and_collision_are_exit_2_naming_file_and_line(tmp_path):
    prog = _write(tmp_path, "p.ngc", "G21\nG0 X0 Y-20\nG41 D1 G1 X0 Y0 F100\nG1 X9\nM2\n")
    table = _write(tmp_path, "bad.tbl", "T1 P1 D2\nT2 P2 Dx\n")
    r = subprocess.run([sys.executable, "-m", "compare", "plan", str(prog), "--tool-table",
                        str(table)], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 2 and f"{table}:2:" in r.stderr and "Traceback" not in r.stderr
    small = _write(tmp_path, "c.mpf", "$TC_DP6[1,1]=5\nT1 D1\nG0 X0 Y-20\n"
                                      "G41 G1 X0 Y0 F100\nG1 X10\nG3 X14 Y4 CR=4\nG1 Y30\n")
    r = subprocess.run([sys.executable, "-m", "compare", "compare", str(small),
                        "--no-report"], capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert f"{small}:6: the arc (radius 4 mm) is not larger than the tool radius" in r.stderr


def test_bad_tools_section_in_machine_data_is_exit_2_naming_the_key(tmp_path):
    m = tmp_path / "m.toml"
    base = (ROOT / "reference" / "machines" / "default.toml").read_text()
    m.write_text(base + "\n[tools]\n1 = { D1 = 5.0, R2 = 3.0 }\n")
    r = subprocess.run([sys.executable, "-m", "compare", "inspect",
                        str(_write(tmp_path, "p.mpf", SQUARE)), "--machine", str(m)],
                       capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 2 and "tools.1.R2 = 3.0: unknown key" in r.stderr


@pytest.mark.parametrize("machine", ["default", "linuxcnc_xyz"])
def test_plan_csv_carries_the_rotary_axis_and_checks_again(tmp_path, machine, capsys):
    """The CSV of a plan has a column per path axis, the following axis included; fed
    back to ``check`` it projects onto the same path (TLIFT blocks, where only C moves,
    included) with no deviation."""
    prog = _write(tmp_path, "t.mpf", TANG)
    mfile = tmp_path / "m.toml"
    text = (ROOT / "reference" / "machines" / f"{machine}.toml").read_text()
    if machine == "linuxcnc_xyz":                 # an XYZ machine: give it a C axis
        text += ("\n[axis.C]\ntype = \"rotary\"\nMAX_AX_VELO = 50.0\nMAX_AX_ACCEL = 2.0\n"
                 "MAX_AX_JERK = 40.0\nMAX_ACCEL_OVL_FACTOR = 1.0\n")
    mfile.write_text(text)
    out = tmp_path / "plan.csv"
    assert main(["plan", str(prog), "--machine", str(mfile), "--quiet", "--csv",
                 str(out)]) == 0
    rows = list(csv.reader(out.read_text().splitlines()))
    assert rows[0] == ["t", "s", "v", "X", "Y", "Z", "C"]
    last = [float(x) for x in rows[-1]]
    assert last[6] == pytest.approx(180.0)        # the tangent of the final X0 move
    capsys.readouterr()
    assert main(["check", str(out), "--program", str(prog), "--machine", str(mfile),
                 "--quiet"]) in (0, 1)
    report = capsys.readouterr().out
    assert "deviation  ok" in report
