"""compare(): per-block accounting, the gap interval, causes, notes and the verdict."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from conftest import SMALL, path_of
from fakes import FakeSolution, fake_plan, fake_solution, toy_profile

from optimal import SolveStatus
from compare.comparison import ComparedBlock, OracleResult, Side, compare, compare_profiles
from reference.core.causes import normalise_cause
from reference.core.constraints import BOUND_SETS, check_profile, scale_time
from reference.core.errors import InternalError
from reference.core.geometry import BlockSpan, line_segments, path_from_pieces


@pytest.fixture
def small(machine):
    program, path = path_of(SMALL, machine)
    return program, path, fake_plan(path, machine.limits), fake_solution(path, machine.limits)


def test_block_times_sum_to_the_totals_on_both_sides(small, machine):
    program, path, plan, sol = small
    c = compare(plan, sol, program=program)
    assert len(c.rows) == len(path.blocks)
    assert sum(r.t_reference_s for r in c.rows) == pytest.approx(plan.profile.duration, rel=1e-12)
    assert sum(r.t_oracle_s for r in c.rows) == pytest.approx(sol.profile.duration, rel=1e-12)
    assert sum(r.gap_s for r in c.rows) == pytest.approx(c.t_reference_s - c.t_oracle_s,
                                                         abs=1e-12)
    assert sum(r.length_mm for r in c.rows) == pytest.approx(path.total_length)


def test_gap_interval_is_t_ref_over_ub_and_lb(small):
    program, path, plan, sol = small
    c = compare(plan, sol, program=program)
    t = plan.profile.duration
    assert c.gap_lower == pytest.approx(t / sol.upper_bound_s - 1, rel=1e-14)
    assert c.gap_upper == pytest.approx(t / sol.lower_bound_s - 1, rel=1e-14)
    assert c.gap_lower < c.gap_upper
    assert c.gap_lower_valid and c.certified


def test_rows_carry_speeds_sources_and_causes(small):
    program, path, plan, sol = small
    c = compare(plan, sol, program=program)
    by_line = {r.line: r for r in c.rows}
    r = by_line[3]                                   # N20 G1 X50 Y0: corner at its end
    assert r.source == "N20 G1 X50 Y0" and r.label == "N20" and r.kind == "G1"
    assert r.v_entry_reference == 0.0 and r.v_entry_oracle == 0.0      # program start
    assert 0 < r.v_exit_reference <= r.v_peak_reference <= 100.0 + 1e-9
    assert r.limit_reference == "axis acceleration"                  # what the plan says
    assert r.limit_oracle == "feed"                                  # derived
    stop = by_line[6]                                # N50 G9: exact stop at its end
    assert stop.v_exit_reference == 0.0 and stop.v_exit_oracle == 0.0
    assert stop.stop_reason.startswith("exact stop")


def test_negative_block_gap_gets_a_note(small, machine):
    program, path, plan, sol = small
    # an "oracle" that is slower than the plan in the first moving block only
    slow = toy_profile(path, machine.limits, 0.35)
    # (its lower bound stays below the plan's time, as every certified bound must)
    fake = FakeSolution(SolveStatus.OPTIMAL, slow, 0.99 * plan.profile.duration, slow.duration)
    c = compare(plan, fake, program=program)
    neg = [r for r in c.rows if r.gap_s < -1e-6]
    assert neg and all("negative by" in r.note for r in neg)
    assert all("at every point of the path" in r.note for r in neg)      # acc bounds
    assert any("negative gap" in n for n in c.notes)
    assert not [r for r in c.rows if r.gap_s >= 0 and r.note]


def test_jerk_bounded_oracle_explains_negative_gaps_differently(small):
    program, path, plan, sol = small
    c = compare(plan, FakeSolution(SolveStatus.OPTIMAL, plan.profile, 1.0, 2.0), program=program)
    note_rows = [r for r in c.rows if r.note]
    assert not note_rows                                  # identical profiles: no gap
    # a jerk oracle explains a negative gap by the global optimum
    from compare.comparison import _gap_note
    text = _gap_note(-0.01, 0.5, 0.002, "jerk", 1, 2, 3, 4)
    assert "minimises the total time, not each block" in text


def test_soft_heuristic_against_acc_oracle_is_a_relaxation(small):
    program, path, plan, sol = small
    c = compare(replace(plan, bound_set="jerk", report=None), sol, program=program)
    assert not c.gap_lower_valid
    assert any("relaxation" in n and "the gap's upper end, with LB, is valid" in n for n in c.notes)
    # the jerk bound set judges the plan's jerk: the fake (BRISK-like) breaks it
    v = c.verdict(None)
    assert any(x.constraint == "jerk" for x in c.reference_violations)
    assert not v.ok and v.status == "violation"
    # without that violation the verdict gives only the certified upper end
    v = replace(c, reference_ratio_tol=1e9).verdict(None)
    assert v.ok and "at most" in v.text and "relaxation" in v.text


def test_verdict_gate_uses_the_upper_end(small):
    program, path, plan, sol = small
    c = compare(plan, sol, program=program)
    assert c.verdict(None).ok
    assert c.verdict(c.gap_upper + 1e-6).ok
    v = c.verdict((c.gap_lower + c.gap_upper) / 2)        # between the ends: fails
    assert not v.ok and v.status == "gap above gate"


def test_oracle_without_certificate_fails(small):
    program, path, plan, sol = small
    bad = FakeSolution(SolveStatus.SOLVER_ERROR, None, math.nan, math.nan)
    c = compare(plan, bad, program=program)
    assert not c.certified
    v = c.verdict(None)
    assert not v.ok and v.status == "no certificate"
    assert all(math.isnan(r.t_oracle_s) for r in c.rows)


def test_inserted_blocks_are_attributed_to_their_corner(machine):
    # two lines with an inserted "rounding" segment between them (block index 2)
    pieces = [line_segments(np.array([[0, 0, 0.]]), np.array([[9, 0, 0.]]),
                            np.array([True] * 3), np.array([0]))]
    ins = line_segments(np.array([[9, 0, 0.]]), np.array([[10, 1, 0.]]),
                        np.array([True] * 3), np.array([2]))
    ins["kind"][:] = 2                                     # "rounding"
    pieces.append(ins)
    pieces.append(line_segments(np.array([[10, 1, 0.]]), np.array([[10, 10, 0.]]),
                                np.array([True] * 3), np.array([1])))
    L = [9.0, math.sqrt(2), 9.0]
    sb = np.concatenate(([0], np.cumsum(L)))
    spans = (BlockSpan(0, 2, "N10", "G1", sb[0], sb[1], 0, 1, 50.0),
             BlockSpan(2, 2, "", "rounding", sb[1], sb[2], 1, 1, 50.0),
             BlockSpan(1, 3, "N20", "G1", sb[2], sb[3], 2, 1, 50.0))
    path = path_from_pieces(("X", "Y", "Z"), pieces, feed=50.0, blocks=spans)
    plan = fake_plan(path, machine.limits)
    c = compare(plan, fake_solution(path, machine.limits))
    rows = {r.block: r for r in c.rows}
    assert rows[2].inserted and rows[2].corner == (2, 3) and rows[2].line == 2
    assert not rows[0].inserted and rows[0].corner is None
    assert sum(r.t_reference_s for r in c.rows) == pytest.approx(plan.profile.duration)


def test_oracle_labels_map_to_the_shared_vocabulary():
    span = BlockSpan(3, 7, "", "G1", 0.0, 1.0, 0, 1, stop_reason="exact stop G9")
    idle = BlockSpan(4, 8, "", "none", 1.0, 1.0, 1, 0, stop_reason="dwell G4 0.2 s")
    assert normalise_cause("acceleration X") == "axis acceleration"
    assert normalise_cause("velocity Z") == "axis velocity"
    assert normalise_cause("velocity_jump") == "corner rule"
    assert normalise_cause("feed") == "feed"
    assert normalise_cause("stop", span.stop_reason) == "exact stop"
    assert normalise_cause("dwell G4 0.2 s", idle.stop_reason,
                           idle.n_segments == 0) == "dwell"
    assert normalise_cause("") == "-"
    assert normalise_cause("look-ahead horizon") == "look-ahead horizon"


def test_compare_profiles_accepts_any_side(small, machine):
    program, path, plan, sol = small
    side = Side("recorded", plan.profile, "acc")
    oracle = OracleResult("optimal", sol.profile, sol.lower_bound_s, sol.upper_bound_s)
    c = compare_profiles(path, machine.limits, side, oracle, program="x.mpf")
    assert c.reference_name == "recorded"
    assert "recorded trajectory" in c.verdict(None).text
    assert all(isinstance(r, ComparedBlock) for r in c.rows)
    assert all(r.limit_reference for r in c.rows)            # derived causes


def test_a_lower_bound_above_an_accepted_profile_is_a_bug_not_a_gap(small):
    """The certificate: a profile the checker accepts is never below LB. A comparison
    that finds one raises InternalError (exit 3), never prints a negative gap as ok."""
    program, path, plan, sol = small
    t = plan.profile.duration
    bad = FakeSolution(SolveStatus.OPTIMAL, plan.profile, t * (1 + 1e-6), t * 1.01)
    with pytest.raises(InternalError, match="certificate broken"):
        compare(plan, bad, program=program)
    # at the bound itself (round-off below it) the claim holds
    ok = FakeSolution(SolveStatus.OPTIMAL, plan.profile, t * (1 + 1e-12), t * 1.01)
    assert compare(plan, ok, program=program).gap_upper == pytest.approx(0.0, abs=1e-9)


def test_a_planner_faster_than_the_oracles_verified_motion_is_said_so(small, machine):
    program, path, plan, sol = small
    # an oracle whose verified motion is slower than the plan (a loose upper bound):
    # the plan meets the same acc limits, so it is itself a motion of the oracle's set
    slow = toy_profile(path, machine.limits, 0.35)
    fake = FakeSolution(SolveStatus.GAP_NOT_MET, slow, 0.9 * plan.profile.duration,
                        slow.duration)
    c = compare(plan, fake, program=program)
    assert plan.report.ok(BOUND_SETS["acc"]) and c.gap_lower < 0 < c.gap_upper
    v = c.verdict(None)
    assert v.ok and "meets the same acc limits" in v.text and "at least 0" in v.text
    assert v.text.startswith(f"the heuristic is 0.0 – {100 * c.gap_upper:.1f} % slower")
    # the gap interval of DESIGN 7 is reported as it is, the report says why it is >= 0
    assert c.gap_lower == pytest.approx(plan.profile.duration / slow.duration - 1)
    assert c.reference_bounds_optimum
    from compare.report_html import render_report
    assert "so the gap is at least 0" in render_report(c)
    # when the plan does not meet the oracle's limits (here: too fast for them, its own
    # check waived), nothing is said
    prof = scale_time(plan.profile, 0.5)              # twice as fast: over the feed
    fast = replace(plan, profile=prof, report=check_profile(path, machine.limits, prof))
    assert not fast.report.ok(BOUND_SETS["acc"])
    broken = replace(compare(fast, replace(fake, upper_bound_s=10 * fast.profile.duration),
                             program=program), reference_ratio_tol=1e9)
    assert broken.gap_lower < 0 and "at least 0" not in broken.verdict(None).text
    assert not broken.reference_bounds_optimum
    # an upper bound below the plan's time: nothing to say either
    assert "at least 0" not in compare(plan, sol, program=program).verdict(None).text


def test_a_stricter_oracle_set_the_planner_breaks_is_named_in_the_verdict(small, machine):
    """``--bounds acc+freq`` for a planner that declares ``acc``: the oracle's set adds
    the frequency rule, which the (fake) plan breaks, so the plan can be faster than the
    certified lower bound without a broken certificate. The verdict names the rule it
    breaks and says the interval is not its gap to an optimum it is held to; against an
    ``acc`` oracle it reads as before."""
    from reference.core.constraints import time_scale_factor
    program, path, _, _ = small
    # every axis at 2 Hz: phases of at least 0.5 s, which the fake plan's ramps are not
    lim = replace(machine.limits, axes=tuple(replace(a, frequency_hz=2.0)
                                             for a in machine.limits.axes))
    plan, sol = fake_plan(path, lim), fake_solution(path, lim)
    freq = BOUND_SETS["acc+freq"]
    # precondition: the plan breaks the frequency rule and nothing of its own set
    assert plan.report.violations(("frequency",)) and not plan.report.violations(
        BOUND_SETS["acc"])
    # a stricter "optimum": the oracle's motion slowed down until the rule holds, its
    # lower bound above the plan's time (as the frequency rule allows)
    rep = check_profile(path, lim, sol.profile)
    slow = scale_time(sol.profile, time_scale_factor(rep, freq) * (1 + 1e-6))
    assert check_profile(path, lim, slow).ok(freq)
    lb = 1.05 * plan.profile.duration
    strict = FakeSolution(SolveStatus.OPTIMAL, slow, lb, max(slow.duration, lb),
                          bounds="acc+freq")
    c = compare(plan, strict, program=program)
    assert c.gap_upper < 0 and [v.constraint for v in c.stricter_violations] == ["frequency"]
    v = c.verdict(None)
    assert v.ok and "not the stricter acc+freq set" in v.text and "frequency" in v.text
    assert "not its gap to an optimum it is held to" in v.text
    # the report's banner is amber, not green: the numbers are not its optimality gap
    from compare.report.page import banner
    assert banner(c, v)[0] == "warn" and "stricter bound set" in banner(c, v)[1]
    # the same planner against an acc oracle (below its time, as a certificate must be)
    same = compare(plan, replace(strict, bounds="acc", lower_bound_s=0.99 * plan.profile
                                 .duration), program=program)
    assert not same.stricter_violations
    assert "slower than the time-optimal motion" in same.verdict(None).text
