"""Tool data for tool radius compensation: machine.toml [tools], LinuxCNC tool table
files, and the program's own tool data ($TC_DP6, G10 L1, G41.1 D) in the parser."""

from __future__ import annotations

import copy
import tomllib
from importlib import resources
from pathlib import Path

import pytest

from reference import parse_text
from reference.core.errors import MachineDataError, NCSyntaxError
from reference.machine import machine_from_dict
from reference.tools import load_linuxcnc_tool_table


def _default() -> dict:
    return copy.deepcopy(tomllib.loads(resources.files("reference.machines")
                                       .joinpath("default.toml").read_text()))


def test_tools_table_of_machine_data():
    d = _default()
    d["tools"] = tomllib.loads('1 = { D1 = 5.0, D2 = -4.9 }\n"END MILL 10" = 5\n')
    tools = machine_from_dict(d, "m.toml").tools
    assert tools.radius(1, 1) == 5.0 and tools.radius(1, 2) == -4.9
    assert tools.radius("END MILL 10", 1) == 5.0 and tools.radius(2, 1) is None


@pytest.mark.parametrize("text, key, rule", [
    ("1 = { D1 = 5.0, X2 = 1 }", "tools.1.X2", "unknown key; a cutting edge is D1"),
    ("1 = { D1 = \"5\" }", "tools.1.D1", "must be a number"),
    ("1 = { D1 = 5000.0 }", "tools.1.D1", "at most 1000 mm"),
    ("1 = {}", "tools.1", "at least one cutting edge"),
    ("1 = true", "tools.1", "must be a number"),
])
def test_bad_tools_entries_name_the_key(text, key, rule):
    d = _default()
    d["tools"] = tomllib.loads(text)
    with pytest.raises(MachineDataError, match=rf"m\.toml: {key.replace('.', chr(92) + '.')}"
                                               rf" = .*{rule}"):
        machine_from_dict(d, "m.toml")


def test_linuxcnc_tool_table(tmp_path: Path):
    f = tmp_path / "tool.tbl"
    f.write_text("T1 P1 D0.25 Z+1.0 ;quarter inch end mill\n"
                 "\n; a comment line\n"
                 "t2 p2 d6 x0 z-3.5\n"
                 "T3 P3 Z1 ;no diameter\n")
    mm = load_linuxcnc_tool_table(f)
    assert (mm.radius(1, 1), mm.radius(2, 1), mm.radius(3, 1)) == (0.125, 3.0, 0.0)
    inch = load_linuxcnc_tool_table(f, "inch")
    assert inch.radius(1, 1) == pytest.approx(0.125 * 25.4)


@pytest.mark.parametrize("line, what", [
    ("T1 P1 D3 Q", "unexpected 'Q'"),
    ("P1 D3", "needs T<tool number>"),
    ("T1.5 P1 D3", "must be a whole number"),
    ("T1 T2 D3", "T appears twice"),
    ("T1 D99999", "check the units"),
])
def test_bad_tool_table_lines_name_file_and_line(tmp_path: Path, line, what):
    f = tmp_path / "tool.tbl"
    f.write_text(f"T9 P9 D1\n{line}\n")
    with pytest.raises(MachineDataError, match=rf"tool\.tbl:2: .*{what}"):
        load_linuxcnc_tool_table(f)


def test_missing_tool_table_file(tmp_path: Path):
    with pytest.raises(MachineDataError, match="file not found"):
        load_linuxcnc_tool_table(tmp_path / "none.tbl")


def test_program_tool_data_per_block():
    p = parse_text("R1=2\n$TC_DP6[1,1]=5\n$TC_DP6[1,2]=R1*2\nT1\nD2\nT1\nD0\n", "t.mpf")
    b = p.blocks
    assert (b[3].trc_tool, b[3].tool_radius_mm) == ((1, 1), 5.0)     # T alone: D1
    assert (b[4].trc_tool, b[4].tool_radius_mm) == ((1, 2), 4.0)
    assert (b[5].trc_tool, b[5].tool_radius_mm) == ((1, 1), 5.0)     # a new T: D1 again
    assert b[6].tool_radius_mm == 0.0                                 # D0: no offset
    assert b[1].kept_unmodelled == () and not p.warnings             # modelled, no stop


@pytest.mark.parametrize("text, msg", [
    ("$TC_DP6[1]=5\n", "needs two indices"),
    ("$TC_DP6[1,0]=5\n", "edge >= 1"),
    ("$TC_DP6[1,1]\n", "expected \\$TC_DP6\\[tool, edge\\] = radius"),
])
def test_bad_tc_dp6_names_the_line(text, msg):
    with pytest.raises(NCSyntaxError, match=rf"t\.mpf:1:.*{msg}"):
        parse_text(text, "t.mpf")


def test_ngc_tool_data_words():
    p = parse_text("G21\nG10 L1 P3 R2.5\nT3 M6\nG41\nG40\nG41.1 D6\nG40\nG41 D5\n", "t.ngc",
                   dialect="ngc")
    b = p.blocks
    assert (b[3].trc_tool, b[3].tool_radius_mm) == ((3, 1), 2.5)      # the current tool
    assert (b[5].trc_tool, b[5].tool_radius_mm) == (None, 3.0)        # diameter 6
    assert (b[7].trc_tool, b[7].tool_radius_mm) == ((5, 1), None)     # the machine's table
    with pytest.raises(NCSyntaxError, match=r"t\.ngc:1:.*G41\.1 with no D word"):
        parse_text("G41.1 G1 X1 F1\n", "t.ngc", dialect="ngc")
    with pytest.raises(NCSyntaxError, match=r"t\.ngc:1:.*D must be a whole tool number"):
        parse_text("G41 D2.5\n", "t.ngc", dialect="ngc")
