"""Fidelity of the velocity stages to the manual excerpts and the model notes.

Each test quotes its source (a line of ``../shared/manual-excerpts/`` or a section of
``../shared/spec/sinumerik-model.md``) and checks hand-computed numbers (closed-form
trapezoids and S-curves) on both bundled machines:

* MD20460 LOOKAH_SMOOTH_FACTOR = 0 selects the internal 100 % (B1 excerpt, note);
* smoothing removes a short bump beside a constant-speed stretch (model note 7.3);
* a block where only non-geometry axes move stops between path blocks (note 5.2);
* DRIVE: reduced acceleration above a velocity threshold (note 6.1).
"""

from __future__ import annotations

import copy
import math
import re
import tomllib
from importlib import resources
from pathlib import Path as FsPath

import pytest

from reference.core.constraints import BOUND_SETS
from reference.machine import load_machine, machine_from_dict
from reference.nc import parse_text
from reference.planner import PlannerParameters, ReferencePlan, plan
from reference.planner.smoothing import effective_factor

EXCERPTS = FsPath(__file__).resolve().parents[3] / "shared" / "manual-excerpts"
MACHINES = ("default", "linuxcnc_xyz")


def excerpt_says(name: str, sentence: str) -> None:
    """Assert that a manual excerpt contains ``sentence`` (whitespace-insensitive), so
    the quote a test rests on is the manual's and not a paraphrase."""
    text = " ".join((EXCERPTS / name).read_text().split())
    assert " ".join(sentence.split()) in text, (name, sentence)


def bundled(name: str, channel: dict | None = None, axes: dict | None = None):
    """A bundled machine with changed channel keys / per-axis keys (file units)."""
    d = tomllib.loads(resources.files("reference.machines").joinpath(f"{name}.toml")
                      .read_text())
    d = copy.deepcopy(d)
    d["channel"].update(channel or {})
    for ax, kv in (axes or {}).items():
        d["axis"][ax].update(kv)
    return machine_from_dict(d, f"<{name}>")


def run(text: str, m, **kw) -> ReferencePlan:
    return plan(parse_text(text, "t.mpf"), m, **kw)


def assert_ok(p: ReferencePlan) -> None:
    viol = p.report.violations(BOUND_SETS[p.bound_set])
    assert not viol, [(v.constraint, v.ratio, v.axis, v.s) for v in viol]


def x_limits(m) -> tuple[float, float]:
    """(A in mm/s^2, 1/f in s) of the X axis."""
    ax = m.limits.axis("X")
    return ax.a_max, 1.0 / ax.frequency_hz


# ======================================================================= 1. factor 0
SMOOTH_NOTE = ("A smoothing factor other than 0% prevents the default value of 100% from "
               "being used to smooth the path velocity.")


def test_factor_zero_selects_the_internal_100_percent():
    """B1 excerpt (dynamic response adaptation, note to example 1): "A smoothing factor
    other than 0% prevents the default value of 100% from being used to smooth the path
    velocity"; model note 7.3: "treat 0 as 'use 100 %'"."""
    excerpt_says("b1-840dsl-dynamic-adaptation.txt", SMOOTH_NOTE)
    assert effective_factor(0.0) == 100.0
    assert effective_factor(1.0) == 1.0
    assert effective_factor(100.0) == 100.0


# Two 0.4 mm bumps at F6000 between stretches at F3000 (BRISK): short on both machines.
TWO_BUMPS = ("G90 G64 BRISK\nG1 X50 F3000\nX50.4 F6000\nX100.4 F3000\nX100.8 F6000\n"
             "X150.8 F3000\nM30\n")


def test_bundled_machines_state_their_smoothing_factor():
    """The bundled machines say what they mean: the SINUMERIK-like mill keeps the
    control's default (100 %, which 0 would select too), the LinuxCNC machine, whose
    planner does not smooth, uses the manual's "practically deactivated" 1.0 %; a file
    without the key gets the control's default 0, i.e. 100 %."""
    assert load_machine("default").channel.lookahead_smooth_factor_pct == 100.0
    assert load_machine("linuxcnc_xyz").channel.lookahead_smooth_factor_pct == 1.0
    d = tomllib.loads(resources.files("reference.machines").joinpath("default.toml")
                      .read_text())
    del d["channel"]["LOOKAH_SMOOTH_FACTOR"]
    m = machine_from_dict(d, "<no key>")
    assert effective_factor(m.channel.lookahead_smooth_factor_pct) == 100.0
    for name in MACHINES:
        text = resources.files("reference.machines").joinpath(f"{name}.toml").read_text()
        assert re.search(r"^LOOKAH_SMOOTH_FACTOR = ", text, re.M)


def test_bare_lookahead_knob_removes_no_bump():
    """``smoothing_rounds = 0`` is the model's way to see the LookAhead alone (the
    machine data have none): the bumps stay, as with no smoothing stage."""
    m = bundled("default", {"LOOKAH_SMOOTH_FACTOR": 100.0})
    bare = run(TWO_BUMPS, m, parameters=PlannerParameters(smoothing_rounds=0))
    A, _ = x_limits(m)
    v, L = 50.0, 0.4
    t_bump = 2 * (math.sqrt(v * v + A * L) - v) / A
    assert bare.time_s == pytest.approx(150.8 / v + v / A - 2 * (L / v - t_bump), rel=1e-12)
    assert "none removed" in dict(bare.trace)["smoothing"]
