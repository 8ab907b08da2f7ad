"""Machine data: loading, unit conversion, and every error message."""

from __future__ import annotations

import copy

import pytest

from reference.core.errors import MachineDataError
from reference.machine import BUNDLED_MACHINES, load_machine, machine_from_dict

BASE = {
    "machine": {"name": "t", "ipo_cycle_ms": 4.0},
    "channel": {"lookahead_blocks": 50},
    "axis": {ax: {"MAX_AX_VELO": 30000.0, "MAX_AX_ACCEL": 2.0, "MAX_AX_JERK": 40.0,
                  "MAX_ACCEL_OVL_FACTOR": 1.2, "LOOKAH_FREQUENCY": 20.0}
             for ax in "XYZ"},
}


def _with(path: str, value) -> dict:
    d = copy.deepcopy(BASE)
    node = d
    *head, last = path.split(".")
    for k in head:
        node = node.setdefault(k, {})
    node[last] = value
    return d


def test_units_are_converted_once_to_mm_and_s():
    m = machine_from_dict(BASE)
    x = m.limits.axis("X")
    assert x.v_max == pytest.approx(500.0)        # 30000 mm/min
    assert x.a_max == pytest.approx(2000.0)       # 2 m/s^2
    assert x.j_max == pytest.approx(40000.0)      # 40 m/s^3
    assert m.limits.t_ipo_s == pytest.approx(0.004)
    # the G64 allowance of the model note: 2 m/s^2 * 0.2 * 4 ms = 1.6 mm/s
    arr = m.limits.for_axes(("X", "Y"))
    assert arr.jump[0] == pytest.approx(1.6)


def test_rotary_axis_in_rev_units():
    d = _with("axis.C", {"type": "rotary", "MAX_AX_VELO": 50.0, "MAX_AX_ACCEL": 2.0,
                         "MAX_AX_JERK": 40.0})
    c = machine_from_dict(d).limits.axis("C")
    assert c.rotary and c.v_max == pytest.approx(50 * 360 / 60)
    assert c.a_max == pytest.approx(720.0)


@pytest.mark.parametrize("name", BUNDLED_MACHINES)
def test_bundled_machines_load(name):
    m = load_machine(name)
    assert {"X", "Y", "Z"} <= set(m.limits.names)


def test_default_machine_when_none():
    assert load_machine(None).name == load_machine("default").name


@pytest.mark.parametrize("path, value, match", [
    ("axis.X.MAX_AX_ACCEL", -1.0, r"axis\.X\.MAX_AX_ACCEL = -1\.0: must be > 0 m/s\^2"),
    ("axis.X.MAX_AX_ACCEL", 0.0, r"axis\.X\.MAX_AX_ACCEL = 0\.0: must be > 0"),
    ("axis.X.MAX_AX_ACCEL", 2000.0, r"above the plausible maximum 200 m/s\^2; check the unit"),
    ("axis.X.MAX_AX_VELO", "fast", r"axis\.X\.MAX_AX_VELO = 'fast': must be a number in mm/min"),
    ("axis.X.MAX_AX_VELO", True, r"must be a number in mm/min"),
    ("axis.X.MAX_AX_VELO", 0.5, r"must be > 1 mm/min"),
    ("axis.X.MAX_ACCEL_OVL_FACTOR", 0.9, r"must be >= 1\.0 \(1\.0 = stop at every corner\)"),
    ("axis.X.MAX_AX_JERKK", 1.0, r"axis\.X\.MAX_AX_JERKK = 1\.0: unknown key \(did you mean MAX_AX_JERK\?\)"),
    ("channel.LOOKAH_SMOOTH", 1.0, r"channel\.LOOKAH_SMOOTH = 1\.0: unknown key"),
    ("channel.ADAPT_PATH_DYNAMIC", [0.5, 1.0], r"must be two numbers >= 1\.0"),
    ("channel.acceleration_mode", "FAST", r"must be BRISK or SOFT"),
    ("machine.ipo_cycle_ms", 0, r"machine\.ipo_cycle_ms = 0: must be > 0 ms"),
    ("axis.X.type", "linearr", r"must be linear or rotary"),
    ("spindle.S1", {}, r"spindle = .*unknown section"),
])
def test_machine_data_errors_name_key_value_and_rule(path, value, match):
    with pytest.raises(MachineDataError, match=match):
        machine_from_dict(_with(path, value))


def test_missing_required_key_and_axis():
    d = copy.deepcopy(BASE)
    del d["axis"]["X"]["MAX_AX_JERK"]
    with pytest.raises(MachineDataError, match=r"axis\.X\.MAX_AX_JERK = None: is required"):
        machine_from_dict(d)
    d = copy.deepcopy(BASE)
    del d["axis"]["Z"]
    with pytest.raises(MachineDataError, match=r"axis\.Z = None: geometry axes"):
        machine_from_dict(d)
    d = copy.deepcopy(BASE)
    del d["machine"]["ipo_cycle_ms"]
    with pytest.raises(MachineDataError, match=r"ipo_cycle_ms = None: is required"):
        machine_from_dict(d)


def test_file_errors(tmp_path):
    with pytest.raises(MachineDataError, match=r"file not found"):
        load_machine(tmp_path / "nope.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[machine\nname = 1\n")
    with pytest.raises(MachineDataError, match=r"bad\.toml: .*is not valid TOML"):
        load_machine(bad)


def test_limits_are_immutable():
    m = machine_from_dict(BASE)
    with pytest.raises(AttributeError):
        m.limits.t_ipo_s = 1.0  # type: ignore[misc]
