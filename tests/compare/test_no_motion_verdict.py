"""A program without motion through the library: zero times, and a verdict that says why
there is no certificate instead of contradicting itself (the CLI rejects it earlier)."""

from __future__ import annotations

import optimal
from compare.comparison import compare
from reference.machine import load_machine
from reference.nc import parse_text
from reference.planner import plan


def test_no_motion_verdict_names_the_zero_lower_bound():
    program = parse_text("G90\n", "p.mpf", "sinumerik")
    machine = load_machine(None)
    ref = plan(program, machine)
    assert ref.path.n_segments == 0 and ref.profile.duration == 0.0
    sol = optimal.solve(ref.path, machine.limits, bounds="acc")
    c = compare(ref, sol, limits=machine.limits, program=program, machine=machine.name)
    v = c.verdict(None)
    assert not v.ok and v.status == "no certificate"
    assert "lower bound is 0 s (the path has no motion)" in v.text
    assert "status optimal" not in v.text
