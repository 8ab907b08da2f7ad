"""Every corpus program compares on every bundled machine and on an overload-factor-1.0
machine under the ``acc`` bound set (a relaxation of every machine's own set): exit 0 or
1, oracle status optimal, bracket met, and the heuristic (which the checker accepts) is
never faster than the certified lower bound. The ``jerk`` certificate on the corpus is
:mod:`tests.optimal.test_jerk_corpus`.

The LinuxCNC machine (overload factor 1.0) once crashed the oracle on most real LinuxCNC
programs while every other test was green; this test is why that cannot come back.

``sin_cead_edge_cases.mpf`` is a parser test that also moves an extruder ``E`` and an
extra axis ``ELX`` besides A/B/C: no milling machine has those, and a machine without
limits for a programmed axis is bad input (exit 2 naming the axis and line, checked
below). It is compared on each machine extended by those axes (limits copied from X).
"""

from __future__ import annotations

import copy
import json
import tomllib
from importlib import resources
from pathlib import Path

import pytest

from compare import cli
from shared_inputs import NO_CORPUS, corpus_file, corpus_listing

PROGRAMS = corpus_listing("*.ngc") + corpus_listing("*.mpf")
#: Axes a program moves beyond X, Y, Z (the parser test's extruder and extra axis).
EXTRA_AXES = {"sin_cead_edge_cases.mpf": ("A", "B", "C", "E", "ELX")}

pytestmark = pytest.mark.skipif(not PROGRAMS, reason=NO_CORPUS)


def _bundled(name: str) -> dict:
    return tomllib.loads(resources.files("reference.machines").joinpath(f"{name}.toml")
                        .read_text())


def _toml(d: dict) -> str:
    """A machine dict as TOML (scalars, strings and lists are all machine data uses)."""
    def val(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, list):
            return "[" + ", ".join(val(x) for x in v) + "]"
        return repr(v)
    out = []
    for sec in ("machine", "channel"):
        if sec in d:
            out.append(f"[{sec}]")
            out += [f"{k} = {val(v)}" for k, v in d[sec].items()]
    for ax, keys in d.get("axis", {}).items():
        out.append(f"[axis.{ax}]")
        out += [f"{k} = {val(v)}" for k, v in keys.items()]
    return "\n".join(out) + "\n"


MACHINES = {
    "default": lambda: _bundled("default"),
    "linuxcnc_xyz": lambda: _bundled("linuxcnc_xyz"),
    "default_ovl_1.0": lambda: _with_overload(_bundled("default"), 1.0),
}


def _with_overload(d: dict, ovl: float) -> dict:
    d = copy.deepcopy(d)
    d["machine"]["name"] = f"{d['machine']['name']}, overload factor {ovl}"
    for ax in d["axis"].values():
        ax["MAX_ACCEL_OVL_FACTOR"] = ovl
    return d


def _machine_file(tmp_path: Path, name: str, program: str) -> Path:
    d = MACHINES[name]()
    for ax in EXTRA_AXES.get(program, ()):
        if ax not in d["axis"]:
            d["axis"][ax] = copy.deepcopy(d["axis"]["X"])
    f = tmp_path / f"{name}.toml"
    f.write_text(_toml(d))
    return f


@pytest.mark.parametrize("machine", sorted(MACHINES))
@pytest.mark.parametrize("program", PROGRAMS, ids=lambda p: p.name)
def test_corpus_program_compares_with_a_certificate(program: Path, machine: str,
                                                    tmp_path: Path, capsys) -> None:
    mfile = _machine_file(tmp_path, machine, program.name)
    out = tmp_path / "r.json"
    rc = cli.main(["compare", str(program), "--machine", str(mfile), "--no-report",
                   "--quiet", "--json", str(out), "--bounds", "acc"])
    err = capsys.readouterr().err
    assert rc in (0, 1), err
    assert "Traceback" not in err
    doc = json.loads(out.read_text())
    ora, ref = doc["oracle"], doc["reference"]
    assert ora["status"] == "optimal", ora
    lb, ub, t_ref = ora["lower_bound_s"], ora["upper_bound_s"], ref["time_s"]
    assert lb <= ub <= lb * (1 + 2e-3) + 1e-12           # the default bracket, 0.2 %
    assert not ref["violations"], ref["violations"]
    assert t_ref >= lb, f"heuristic {t_ref!r} s below the lower bound {lb!r} s"


def test_a_machine_without_a_programmed_axis_is_bad_input(tmp_path: Path, capsys) -> None:
    prog = corpus_file("sin_cead_edge_cases.mpf")
    mfile = tmp_path / "default.toml"
    mfile.write_text(_toml(_bundled("default")))
    rc = cli.main(["compare", str(prog), "--machine", str(mfile), "--no-report", "--quiet"])
    err = capsys.readouterr().err
    assert rc == 2
    assert "sin_cead_edge_cases.mpf:" in err and "[axis." in err and "Traceback" not in err
