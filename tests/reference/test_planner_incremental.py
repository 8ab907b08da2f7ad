"""The planner's shortcuts give what the plain computation gives.

Some stages avoid work whose result they know: the velocity smoothing replaces only the
profiles of the bumps it accepted instead of planning every unit again after each round.
The reference here is the plain computation itself, run independently on the stage's
output: every unit planned again from the final caps and node speeds must give the very
same numbers (bit for bit), on rounded and unrounded programs and on both bundled
machines.
"""

from __future__ import annotations

import numpy as np
import pytest

import reference.planner.engine as engine
from reference.machine import load_machine, machine_from_dict
from reference.nc import parse_text
from reference.planner.profiles import UnitProfiles
from seeded_programs import polyline

MACHINES = ("default", "linuxcnc_xyz")


def with_smoothing(name: str, factor: float):
    """A bundled machine with LOOKAH_SMOOTH_FACTOR = ``factor`` %."""
    m = load_machine(name)
    if m.channel.lookahead_smooth_factor_pct == factor:
        return m
    import tomllib
    from importlib import resources
    d = tomllib.loads(resources.files("reference.machines").joinpath(f"{name}.toml")
                      .read_text())
    d["channel"]["LOOKAH_SMOOTH_FACTOR"] = factor
    return machine_from_dict(d, f"<{name}>")


PROGRAMS = {
    # short bumps on the lines between roundings (BRISK), several rounds
    "rounded BRISK": "G90 G642 CTOL=0.02 BRISK F6000\nG1 X0 Y0\nG1 " + polyline(400, 5),
    "rounded SOFT": "G90 G645 CTOL=0.02 SOFT F6000\nG1 X0 Y0\nG1 " + polyline(400, 5),
    "G64 BRISK": "G90 G64 BRISK F6000\nG1 X0 Y0\nG1 " + polyline(400, 5),
    # alternating feeds: many short bumps that merge over the rounds
    "alternating feeds": "G90 G64 BRISK\n" + "\n".join(
        f"G1 X{i + 1}.0 F{6000 if i % 2 else 5400}" for i in range(100)) + "\nM30\n",
}


@pytest.mark.parametrize("name", MACHINES)
@pytest.mark.parametrize("program", sorted(PROGRAMS))
@pytest.mark.parametrize("factor", (1.0, 100.0))
def test_smoothing_profiles_equal_a_full_replan(monkeypatch, name, program, factor):
    """The smoothing stage's profiles are those of every unit planned again from its
    final caps and node speeds (it splices in only the accepted bumps' profiles)."""
    seen = []
    real = engine.smooth_velocity

    def spy(units, speeds, prof, *args):
        out = real(units, speeds, prof, *args)
        seen.append(out)
        return out

    monkeypatch.setattr(engine, "smooth_velocity", spy)
    engine.plan(parse_text(PROGRAMS[program], "t.mpf"), with_smoothing(name, factor),
                check=False)
    (res,) = seen
    full = engine._replan(res.units, np.arange(res.units.n_units), res.speeds.v)
    for f in UnitProfiles.__dataclass_fields__:
        np.testing.assert_array_equal(getattr(res.profiles, f), getattr(full, f), err_msg=f)
    if name == "default" and factor == 100.0:
        assert res.n_bumps > 0          # the case exercises the splice
