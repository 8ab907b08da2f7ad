"""The frequency rule as the planner's own bound set (issue 12, item 4).

Model note 7.4 (b1-840dsl-dynamic-adaptation.txt): with ADAPT_PATH_DYNAMIC > 1 a velocity
change shorter than ``t_adapt = 1/f`` gets lower dynamics, by at most that factor, so that
it lasts ``t_adapt``. The heuristic then declares ``acc+freq`` (BRISK) or ``jerk+freq``
(SOFT) when its own profile meets the frequency rule, and ``--bounds auto`` compares
under exactly that set. References: the closed form ``L/v + 1/f`` of a rest-to-rest
line whose ramps are stretched to ``1/f`` (DESIGN 6) and the hand ramp time
``2 sqrt(dv lambda / J)`` of a jerk-limited ramp.
"""

from __future__ import annotations

import copy
import math
import tomllib
from importlib import resources
from pathlib import Path as FsPath

import pytest

from compare.engines import resolve_bounds
from compare.pipeline import compare_program
from reference.core.constraints import BOUND_SETS
from reference.machine import machine_from_dict
from reference.nc import parse_text
from reference.planner import plan


def machine(mode: str, adapt: list[float], name: str = "default.toml"):
    d = copy.deepcopy(tomllib.loads(resources.files("reference.machines")
                                    .joinpath(name).read_text()))
    d["channel"]["ADAPT_PATH_DYNAMIC"] = adapt
    d["channel"]["acceleration_mode"] = mode
    return machine_from_dict(d, f"<{name}, adaptation>")


# a slow rest-to-rest line: the ramps to 10 mm/s are far shorter than 1/f = 50 ms
PROGRAM = "G90 G64 G1 X100 F600\nM30\n"


@pytest.mark.parametrize("mode, base", [("BRISK", "acc"), ("SOFT", "jerk")])
def test_full_adaptation_meets_the_rule_and_the_plan_declares_it(mode, base):
    m = machine(mode, [10.0, 10.0])
    f = m.limits.axis("X").frequency_hz
    p = plan(parse_text(PROGRAM, "t.mpf"), m)
    assert p.bound_set == f"{base}+freq"
    assert p.report.ok(BOUND_SETS[p.bound_set])
    # both ramps stretched to exactly 1/f, each symmetric: L/v + 1/f (DESIGN 6)
    assert p.profile.duration == pytest.approx(100.0 / 10.0 + 1.0 / f, rel=1e-9)
    assert any("meets the frequency rule" in e.note for e in p.trace)


def test_a_capped_adaptation_does_not_declare_the_rule_and_says_where():
    # SOFT, factor 1.2 on the jerk: the ramp 2 sqrt(dv lambda / J) stays below 1/f
    m = machine("SOFT", [1.0, 1.2])
    ax = m.limits.axis("X")
    t_ramp = 2 * math.sqrt(10.0 * 1.2 / ax.j_max)
    assert t_ramp < 1 / ax.frequency_hz
    p = plan(parse_text(PROGRAM, "t.mpf"), m)
    assert p.bound_set == "jerk"
    (note,) = [e.note for e in p.trace if "frequency rule not declared" in e.note]
    assert f"lasts {t_ramp:.6g} s" in note and "block 0" in note


def test_auto_takes_the_declared_set():
    assert resolve_bounds("auto", "acc+freq") == ("acc+freq", ())
    assert resolve_bounds("auto", "jerk+freq") == ("jerk+freq", ())


def test_compare_auto_runs_the_oracle_under_the_planner_set():
    m = machine("BRISK", [10.0, 10.0])
    c = compare_program(parse_text(PROGRAM, "t.mpf"), m)
    assert c.reference_bounds == "acc+freq"
    assert c.oracle.bounds == "acc+freq"
    # the heuristic's time is the closed form, which the oracle reaches: gap ~ 0
    assert c.oracle.lower_bound_s <= c.t_reference_s * (1 + 1e-9)
    assert c.oracle.upper_bound_s <= c.t_reference_s * (1 + 1e-6)


def test_oracle_is_not_slower_than_the_heuristic_on_a_contour_with_corners():
    # the demo contour (corners, arcs, an exact stop, a dwell) under BRISK with full
    # adaptation on the LinuxCNC machine (no velocity jump at corners): the heuristic
    # meets acc+freq with a motion built its own way (LookAhead, adapted ramps), so the
    # oracle's verified motion must be at least as fast and its bound below it
    m = machine("BRISK", [10.0, 10.0], "linuxcnc_xyz.toml")
    text = (FsPath(__file__).parents[2] / "examples" / "demo.mpf").read_text()
    c = compare_program(parse_text(text.replace(" SOFT", " BRISK"), "demo.mpf"), m)
    assert c.reference_bounds == c.oracle.bounds == "acc+freq"
    assert c.oracle.lower_bound_s <= c.t_reference_s
    assert c.oracle.upper_bound_s <= c.t_reference_s
