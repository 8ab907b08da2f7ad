"""Hostile machine data: every broken file is a MachineDataError naming the key (exit 2).

Each case comes from issue 9 (86 broken machine files); the CLI tests at the end check
that the error reaches the user as one line with exit code 2, never a traceback.
"""

from __future__ import annotations

import copy
from pathlib import Path

import pytest

from compare.cli import main
from reference.core.errors import MachineDataError
from reference.machine import _AXIS_KEYS, _CHANNEL_KEYS, load_machine, machine_from_dict

BASE = {
    "machine": {"name": "t", "ipo_cycle_ms": 4.0},
    "channel": {"lookahead_blocks": 50},
    "axis": {ax: {"MAX_AX_VELO": 30000.0, "MAX_AX_ACCEL": 2.0, "MAX_AX_JERK": 40.0,
                  "MAX_ACCEL_OVL_FACTOR": 1.2, "LOOKAH_FREQUENCY": 20.0}
             for ax in "XYZ"},
}

GOOD_TOML = """\
[machine]
name = "{name}"
ipo_cycle_ms = 4.0
# {comment}

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
"""


def _with(path: str, value) -> dict:
    d = copy.deepcopy(BASE)
    node = d
    *head, last = path.split(".")
    for k in head:
        node = node.setdefault(k, {})
    node[last] = value
    return d


@pytest.mark.parametrize("section", ["machine", "channel"])
@pytest.mark.parametrize("value", [5, "fast", [1, 2], True])
def test_a_section_that_is_a_value_names_the_section(section, value):
    d = copy.deepcopy(BASE)
    d[section] = value
    with pytest.raises(MachineDataError, match=rf"^<dict>: {section} = .*must be a table"):
        machine_from_dict(d)


@pytest.mark.parametrize("path", [
    "axis.X.MAX_AX_ACCEL", "axis.Y.MAX_AX_JERK", "axis.Z.SOFT_ACCEL_FACTOR",
    "channel.MAX_PATH_JERK", "axis.X.G00_ACCEL_FACTOR", "axis.X.LOOKAH_FREQUENCY",
    "axis.X.G00_JERK_FACTOR", "axis.X.PATH_TRANS_JERK_LIM", "axis.X.POSCTRL_GAIN",
    "axis.X.COMPRESS_POS_TOL", "axis.X.STOP_LIMIT_FINE", "channel.SMOOTH_CONTUR_TOL",
    "channel.G0_TOLERANCE_FACTOR", "machine.ipo_cycle_ms"])
def test_a_denormal_value_is_below_the_plausible_minimum(path):
    with pytest.raises(MachineDataError, match=rf"{path} = 1e-300: is below the plausible "
                                               r"minimum"):
        machine_from_dict(_with(path, 1e-300))


def test_every_number_key_with_a_lower_bound_has_a_plausible_minimum():
    # the rule is applied to every key a planner divides by or scales a limit with; the
    # exceptions are the keys whose lower end is a meaningful "off" (0 %, a feed-forward
    # weight of 0) or a count
    exempt = {"SMOOTHING_MODE", "LOOKAH_SMOOTH_FACTOR", "lookahead_blocks", "MAX_AX_VELO",
              "MAX_ACCEL_OVL_FACTOR", "VELO_FFW_WEIGHT", "ACCEL_REDUCTION_FACTOR",
              # TRC corner switches: 0 turns each off (no intersection instead of a
              # circle, no DISC, no 840C rule); nothing is divided by them
              "CUTCOM_CURVE_INSERT_LIMIT", "CUTCOM_MAX_DISC", "CUTCOM_840C_MD6"}
    for table in (_CHANNEL_KEYS, _AXIS_KEYS):
        for key, spec in table.items():
            if spec.lo is not None and key not in exempt:
                assert spec.low is not None and spec.low > spec.lo, key


def test_values_at_the_plausible_minimum_load():
    d = _with("axis.X.MAX_AX_ACCEL", _AXIS_KEYS["MAX_AX_ACCEL"].low)
    m = machine_from_dict(d)
    assert m.limits.axes[0].a_max == pytest.approx(0.1)      # 1e-4 m/s^2 = 0.1 mm/s^2


@pytest.mark.parametrize("value", [[float("inf"), float("inf")], [1.0, float("nan")],
                                   [1.0, 1e300], [11.0, 1.0]])
def test_adapt_path_dynamic_must_be_finite_and_plausible(value):
    with pytest.raises(MachineDataError, match=r"channel\.ADAPT_PATH_DYNAMIC = .*must be two "
                                               r"numbers >= 1\.0 and <= 10"):
        machine_from_dict(_with("channel.ADAPT_PATH_DYNAMIC", value))


@pytest.mark.parametrize("name", ["", "   ", "two\nlines", "bell\a", "x" * 201])
def test_machine_name_must_be_one_printable_line(name):
    with pytest.raises(MachineDataError, match=r"machine\.name = .*printable text"):
        machine_from_dict(_with("machine.name", name))


def test_machine_name_with_markup_is_kept_and_escaped_in_the_report(tmp_path):
    name = '<script>alert("x")</script> & <b>mill</b>'
    toml = tmp_path / "m.toml"
    toml.write_text(GOOD_TOML.format(name=name.replace('"', '\\"'), comment=""),
                    encoding="utf-8")
    assert load_machine(toml).name == name
    prog = tmp_path / "p.mpf"
    prog.write_text("G1 F3000 X10\nG1 Y10\n")
    report = tmp_path / "rep"
    assert main(["compare", str(prog), "--machine", str(toml), "--report", str(report),
                 "--quiet"]) == 0
    page = (report / "p.html").read_text(encoding="utf-8")
    assert "<script>alert" not in page
    assert "&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt; &amp; &lt;b&gt;mill" in page


def test_utf16_with_bom_is_decoded(tmp_path):
    toml = tmp_path / "m16.toml"
    toml.write_bytes(GOOD_TOML.format(name="Fräse", comment="Umlaut ü").encode("utf-16"))
    m = load_machine(toml)
    assert m.name == "Fräse"
    assert m.limits.axes[0].a_max == pytest.approx(2000.0)


def test_utf8_with_bom_is_decoded(tmp_path):
    toml = tmp_path / "m8.toml"
    toml.write_bytes(GOOD_TOML.format(name="Fräse", comment="").encode("utf-8-sig"))
    assert load_machine(toml).name == "Fräse"


def test_latin1_is_rejected_naming_the_file_and_line(tmp_path):
    toml = tmp_path / "m1.toml"
    toml.write_bytes(GOOD_TOML.format(name="mill", comment="Maschine für Teile")
                     .encode("latin-1"))
    with pytest.raises(MachineDataError, match=rf"{toml}: .*is not UTF-8 text \(byte \d+, "
                                               r"line 4\)"):
        load_machine(toml)


def test_utf16_without_bom_is_a_clear_error(tmp_path):
    toml = tmp_path / "m16le.toml"
    toml.write_bytes(GOOD_TOML.format(name="mill", comment="").encode("utf-16-le"))
    with pytest.raises(MachineDataError, match=rf"{toml}"):
        load_machine(toml)


# ------------------------------------------------------------------------- the CLI
@pytest.mark.parametrize("edit, match", [
    (lambda t: t.replace('[machine]\nname = "mill"\nipo_cycle_ms = 4.0\n# \n',
                         "machine = 5\n"), r"machine = 5: must be a table"),
    (lambda t: t.replace("MAX_AX_ACCEL = 2.0", "MAX_AX_ACCEL = 1e-300", 1),
     r"axis\.X\.MAX_AX_ACCEL = 1e-300: is below the plausible minimum"),
    (lambda t: t.replace("MAX_AX_JERK = 40.0", "MAX_AX_JERK = 1e-300", 1),
     r"axis\.X\.MAX_AX_JERK = 1e-300: is below the plausible minimum"),
    (lambda t: t.replace("MAX_AX_JERK = 40.0", "MAX_AX_JERK = 40.0\nSOFT_ACCEL_FACTOR = 1e-300",
                         1), r"axis\.X\.SOFT_ACCEL_FACTOR = 1e-300: is below the plausible"),
    (lambda t: t + "\n[channel]\nADAPT_PATH_DYNAMIC = [inf, inf]\n",
     r"channel\.ADAPT_PATH_DYNAMIC"),
])
@pytest.mark.parametrize("command", ["plan", "compare"])
def test_cli_exit_2_naming_the_key(tmp_path, capsys, edit, match, command):
    toml = tmp_path / "m.toml"
    toml.write_text(edit(GOOD_TOML.format(name="mill", comment="")), encoding="utf-8")
    prog = tmp_path / "p.mpf"
    prog.write_text("G1 F3000 X10\n")
    args = [command, str(prog), "--machine", str(toml), "--quiet"]
    if command == "compare":
        args.append("--no-report")
    assert main(args) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert err.startswith(f"feedoracle: {toml}: ")
    import re
    assert re.search(match, err), err


def test_cli_latin1_machine_file_exit_2(tmp_path, capsys):
    toml = tmp_path / "m.toml"
    toml.write_bytes(GOOD_TOML.format(name="mill", comment="für").encode("latin-1"))
    prog = tmp_path / "p.mpf"
    prog.write_text("G1 F3000 X10\n")
    assert main(["plan", str(prog), "--machine", str(toml), "--quiet"]) == 2
    assert "is not UTF-8 text" in capsys.readouterr().err
