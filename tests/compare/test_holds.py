"""Holds (dwell, exact-stop settle) are the machine's waits, not the planner's.

Hand-derived answers: the settle time of a first-order position loop
``ln((1 - ffw) v / Kv / window) / Kv`` and a rest-to-rest BRISK trapezoid ``L/v + v/A``,
written out here with the machine data's numbers, never by calling the code under test.
"""

from __future__ import annotations

import copy
import math
import tomllib
from importlib import resources

import numpy as np
import pytest

import optimal
from compare.comparison import compare
from compare.export import CSV_COLUMNS, blocks_csv, comparison_dict
from compare.report_html import render_report
from reference.core.errors import MachineDataError, ProfileError
from reference.core.geometry import BlockSpan, line_segments, path_from_pieces
from reference.core.holds import DWELL_CAUSE, SETTLE_CAUSE, Holds, with_holds, without_holds
from reference.core.profile import Profile
from reference.holds import imposed_holds
from reference.machine import machine_from_dict
from reference.nc import parse_text
from reference.planner import PlannerParameters, plan
from reference.prepare import prepare, restrict_to_machine

DEFAULT_DICT = tomllib.loads(resources.files("reference.machines").joinpath(
    "default.toml").read_text())

#: The default machine's data, as the file gives them (written out: the test's closed
#: forms must not read them back through the code under test).
KV = 1.0 * 1000.0 / 60.0          # POSCTRL_GAIN 1 (m/min)/mm = 16.67 1/s
FINE, COARSE = 0.01, 0.04         # STOP_LIMIT_FINE / _COARSE, mm
A_X = 2000.0                      # MAX_AX_ACCEL 2 m/s^2, mm/s^2
V_X_MAX = 30000.0 / 60.0          # MAX_AX_VELO 30000 mm/min, mm/s


def settle(e0: float, window: float, kv: float = KV) -> float:
    """First-order decay e0 exp(-kv t) into the window, by hand."""
    return max(0.0, math.log(e0 / window) / kv)


def machine(**axis_keys):
    d = copy.deepcopy(DEFAULT_DICT)
    for ax in d["axis"]:
        d["axis"][ax].update(axis_keys)
    return machine_from_dict(d, "<test>")


def run(text: str, m=None, name: str = "t.mpf"):
    m = m or machine()
    program = parse_text(text, name)
    p = plan(program, m)
    sol = optimal.solve(p.path, m.limits, bounds="acc", holds=p.holds)
    return program, p, sol, compare(p, sol, limits=m.limits, program=program)


# ----------------------------------------------------------------- the closed forms
def test_settle_is_the_first_order_decay_of_the_programmed_lag():
    text = "G90 G64 BRISK F6000\nG1 X100 G9 {}\nM30\n"
    v = 6000.0 / 60.0                                           # F6000 = 100 mm/s
    for crit, window in (("G601", FINE), ("G602", COARSE)):
        program = parse_text(text.format(crit), "t.mpf")
        h = plan(program, machine()).holds
        assert h.cause == (SETTLE_CAUSE,) and h.block.tolist() == [1]
        assert h.duration_s[0] == pytest.approx(settle(v / KV, window), rel=1e-12)
    assert plan(parse_text(text.format("G603"), "t.mpf"), machine()).holds.n == 0


def test_settle_takes_the_slowest_axis_and_the_feed_forward_weight():
    # diagonal at F6000: each axis runs at 100/sqrt(2) mm/s; half feed-forward halves e0
    text = "G90 BRISK G60 G601 F6000\nG1 X100 Y100\nM30\n"
    v_axis = 100.0 / math.sqrt(2.0)
    h = plan(parse_text(text, "t.mpf"), machine()).holds
    assert h.duration_s[0] == pytest.approx(settle(v_axis / KV, FINE), rel=1e-12)
    h = plan(parse_text(text, "t.mpf"), machine(VELO_FFW_WEIGHT=0.5)).holds
    assert h.duration_s[0] == pytest.approx(settle(0.5 * v_axis / KV, FINE), rel=1e-12)
    assert plan(parse_text(text, "t.mpf"), machine(VELO_FFW_WEIGHT=1.0)).holds.n == 0
    # a window wider than the lag: no wait (e0 = 6 mm at 100 mm/s)
    assert plan(parse_text(text, "t.mpf"), machine(STOP_LIMIT_FINE=7.0)).holds.n == 0


def test_settle_of_a_rapid_uses_the_axis_velocity():
    text = "G90 BRISK G60 G601\nG0 X100\nM30\n"
    h = plan(parse_text(text, "t.mpf"), machine()).holds
    assert h.duration_s[0] == pytest.approx(settle(V_X_MAX / KV, FINE), rel=1e-12)


def test_holds_do_not_depend_on_the_planners_choices():
    # a 2 mm block never reaches F6000 (v = sqrt(A L) = 63 mm/s): the model still takes
    # the programmed speed, so the value is the same whatever profile any side plans
    text = "G90 BRISK G60 G601 F6000\nG1 X2\nM30\n"
    program = parse_text(text, "t.mpf")
    m = machine()
    a = plan(program, m).holds
    b = plan(program, m, parameters=PlannerParameters(soft_merge_cap_ratio=0.5)).holds
    path = restrict_to_machine(prepare(program), m.limits)
    c = imposed_holds(program, path, m)
    assert a.same_as(b) and a.same_as(c)
    assert a.duration_s[0] == pytest.approx(settle(100.0 / KV, FINE), rel=1e-12)


def test_ngc_exact_stop_waits_for_no_window_but_dwell_holds():
    text = "G21 G90 G61.1\nG1 X100 F6000\nG4 P0.25\nG1 X0\nM2\n"
    h = plan(parse_text(text, "t.ngc", dialect="ngc"), machine()).holds
    assert h.cause == (DWELL_CAUSE,) and h.duration_s.tolist() == [0.25]


def test_ffw_weight_is_validated():
    with pytest.raises(MachineDataError, match="VELO_FFW_WEIGHT"):
        machine(VELO_FFW_WEIGHT=1.5)
    with pytest.raises(MachineDataError, match="VELO_FFW_WEIGHT"):
        machine(VELO_FFW_WEIGHT=-0.1)


# ----------------------------------------------------------------- the comparison
def test_single_exact_stop_line_planned_optimally_has_no_gap():
    """G60 G601 on one line, BRISK: the heuristic's trapezoid is the optimum, the settle
    wait is the machine's: gap 0 within the oracle's bracket, the settle on its own row
    cause."""
    program, p, sol, c = run("G90 BRISK G60 G601 G1 X100 F6000\nM30\n")
    L, v = 100.0, 100.0
    t_settle = settle(v / KV, FINE)                                  # 0.3838 s
    assert p.time_s == pytest.approx(L / v + v / A_X + t_settle, rel=1e-9)
    assert c.hold_s == pytest.approx(t_settle, rel=1e-12)
    band = (c.oracle.upper_bound_s - c.hold_s) / (c.oracle.lower_bound_s - c.hold_s) - 1
    assert 0.0 <= band <= 0.002                                      # the oracle's bracket
    assert c.gap_lower <= 1e-9 and 0.0 <= c.gap_upper <= band + 1e-9
    row = next(r for r in c.rows if r.line == 1)
    assert row.hold_cause == "exact stop settle"
    assert row.hold_s == pytest.approx(t_settle, rel=1e-12)
    assert row.limit_reference == "feed"                             # the motion's cause
    assert abs(row.gap_s) <= band * (row.t_oracle_s - row.hold_s) + 1e-9
    # both totals wait the same settle; before, it counted as a 37 % "gap"
    assert c.t_reference_s / c.oracle.upper_bound_s - 1 <= 1e-9
    # the holds are in the JSON, the CSV and the HTML table under their cause
    doc = comparison_dict(c)
    b = next(b for b in doc["blocks"] if b["line"] == 1)
    assert b["hold_cause"] == "exact stop settle" and b["hold_s"] == row.hold_s
    assert doc["gap"]["hold_s"] == c.hold_s
    assert {"hold_s", "hold_cause"} <= set(CSV_COLUMNS)
    assert "exact stop settle" in blocks_csv(c)
    assert "<td class='t'>exact stop settle</td>" in render_report(c)


def test_dwell_block_shows_dwell_and_adds_nothing_to_the_gap():
    program, p, sol, c = run("G90 BRISK G64 F6000\nG1 X100\nG4 F0.5\nX200\nM30\n")
    row = next(r for r in c.rows if r.line == 3)
    assert row.limit_reference == row.limit_oracle == row.hold_cause == "dwell"
    assert row.t_reference_s == row.t_oracle_s == row.hold_s == pytest.approx(0.5, rel=1e-12)
    assert row.gap_s == 0.0 and math.isnan(row.gap_rel)
    # two rest-to-rest BRISK moves: optimal on both sides, gap 0 on motion times
    t_move = 100.0 / 100.0 + 100.0 / A_X
    assert p.time_s == pytest.approx(2 * t_move + 0.5, rel=1e-9)
    assert c.gap_lower <= 1e-9 <= c.gap_upper + 1e-9 and c.gap_upper <= 0.002


def test_a_program_of_holds_only_has_gap_zero():
    program, p, sol, c = run("G90 G4 F1.5\nM30\n")
    assert c.t_reference_s == c.oracle.lower_bound_s == c.oracle.upper_bound_s == 1.5
    assert c.gap_lower == 0.0 and c.gap_upper == 0.0
    assert [r.limit_reference for r in c.rows if r.hold_s] == ["dwell"]


def test_oracle_and_heuristic_wait_the_same_at_the_same_breaks():
    text = ("G90 SOFT G64 F6000\nG1 X50\nX100 G9\nG4 F0.3\nG4 F0.1\nY50 G9 G602\n"
            "G0 X0 Y0\nM30\n")
    program, p, sol, c = run(text)

    def holds_of(prof: Profile):
        k = np.flatnonzero((np.diff(prof.s) == 0) & (np.diff(prof.t) > 0))
        return prof.s[k], np.diff(prof.t)[k], prof.block[k]

    s_r, h_r, b_r = holds_of(p.profile)
    s_o, h_o, b_o = holds_of(sol.profile)
    # the same holds in the same blocks; as differences of absolute knot times (which
    # differ between the two motions) the durations agree to the round-off of t
    assert np.array_equal(b_r, b_o)
    assert np.allclose(h_r, h_o, rtol=1e-12, atol=0.0)
    assert np.allclose(s_r, s_o, rtol=0, atol=1e-9) and s_r.tolist() == [100.0, 100.0,
                                                                            100.0, 150.0]
    assert h_r[1:3] == pytest.approx([0.3, 0.1], rel=1e-12)
    assert h_r[0] == pytest.approx(settle(100.0 / KV, FINE), rel=1e-12)
    assert h_r[3] == pytest.approx(settle(100.0 / KV, COARSE), rel=1e-12)
    # both bounds contain them: a lower bound below the holds would be wrong
    assert c.oracle.lower_bound_s > c.hold_s == pytest.approx(float(h_r.sum()), rel=1e-12)


def test_compare_refuses_an_oracle_solved_with_other_holds():
    m = machine()
    program = parse_text("G90 BRISK G60 G601 G1 X100 F6000\nM30\n", "t.mpf")
    p = plan(program, m)
    sol = optimal.solve(p.path, m.limits, bounds="acc")        # no settle given
    with pytest.raises(ValueError, match="holds"):
        compare(p, sol, limits=m.limits, program=program)


# ----------------------------------------------------------------- with_holds
def _two_lines():
    seg = line_segments(np.array([[0.0, 0, 0], [10.0, 0, 0]]),
                        np.array([[10.0, 0, 0], [20.0, 0, 0]]), np.ones(3, bool),
                        np.array([0, 1]))
    spans = (BlockSpan(0, 1, "", "G1", 0.0, 10.0, 0, 1),
             BlockSpan(1, 2, "", "G1", 10.0, 20.0, 1, 1),
             BlockSpan(2, 3, "", "none", 20.0, 20.0, 2, 0, dwell_s=0.5))
    return path_from_pieces(("X", "Y", "Z"), [seg], blocks=spans,
                            stop_reason=("start", "exact stop G9", "end"))


def test_with_holds_inserts_in_order_and_shifts_later_knots_and_without_holds_undoes_it():
    path = _two_lines()
    # rest to rest over 10 mm in 1 s twice (v peak 20 mm/s at a = +-40)
    prof = Profile(t=[0, 0.5, 1, 1.5, 2], s=[0, 5, 10, 15, 20], v=[0, 20, 0, 20, 0],
                   a=[40, -40, 40, -40], j=[0, 0, 0, 0], block=[-1, -1, -1, -1])
    holds = Holds(break_index=[1, 1, 2], block=[0, 7, 2], duration_s=[0.25, 0.125, 0.5],
                  cause=(SETTLE_CAUSE, DWELL_CAUSE, DWELL_CAUSE))
    out = with_holds(prof, path, holds)
    assert out.t.tolist() == [0, 0.5, 1, 1.25, 1.375, 1.875, 2.375, 2.875]
    assert out.s.tolist() == [0, 5, 10, 10, 10, 15, 20, 20]
    assert out.block.tolist() == [-1, -1, 0, 7, -1, -1, 2]
    assert out.duration == pytest.approx(2.875)
    # and back: without_holds takes exactly those intervals out again
    back = without_holds(out, path, holds)
    for f in ("t", "s", "v", "a", "j", "block"):
        np.testing.assert_array_equal(getattr(back, f), getattr(prof, f))
    with pytest.raises(ProfileError, match="not in the profile"):
        without_holds(prof, path, holds)
    moving = Profile(t=[0, 1, 2], s=[0, 10, 20], v=[0, 20, 0], a=[20, -20], j=[0, 0],
                     block=[-1, -1])                       # passes break 1 at 10 mm/s
    with pytest.raises(ProfileError, match="does not rest"):
        with_holds(moving, path, Holds(break_index=[1], block=[0], duration_s=[0.1],
                                       cause=(DWELL_CAUSE,)))


def test_holds_reject_bad_entries():
    with pytest.raises(ValueError, match="cause"):
        Holds(break_index=[0], block=[0], duration_s=[1.0], cause=("coffee",))
    with pytest.raises(ValueError, match="> 0"):
        Holds(break_index=[0], block=[0], duration_s=[0.0], cause=(DWELL_CAUSE,))
    with pytest.raises(ValueError, match="non-decreasing"):
        Holds(break_index=[2, 1], block=[0, 1], duration_s=[1.0, 1.0], cause=(DWELL_CAUSE, DWELL_CAUSE))


def test_hold_causes_are_words_of_the_one_vocabulary():
    from reference.core.causes import CAUSES
    from reference.core.holds import HOLD_CAUSES
    assert HOLD_CAUSES == ("dwell", "exact stop settle")
    assert set(HOLD_CAUSES) <= set(CAUSES)


def test_recorded_heuristic_with_a_final_settle_and_dwells_reads_back_without_gap(tmp_path):
    """A recording cannot show the waits after its last motion (it is trimmed there):
    the imposed holds at the path ends are put back, interior waits are measured."""
    from compare.export import profile_samples, write_samples_csv
    from compare.recorded import check_recorded
    text = "G4 F0.2\nG90 BRISK G64 F6000\nG1 X100 G9\nG4 F0.3\nG1 X200 G9 G601\nG4 F0.1\nM30\n"
    m = machine()
    program = parse_text(text, "t.mpf")
    p = plan(program, m)
    header, data = profile_samples(p.path, p.profile, m.limits.t_ipo_s)
    write_samples_csv(header, data, tmp_path / "ipo.csv")
    res = check_recorded(tmp_path / "ipo.csv", program, m)
    c = res.comparison
    t_settle = settle(100.0 / KV, FINE)
    assert c.hold_s == pytest.approx(0.2 + 0.3 + 0.1 + 2 * t_settle, rel=1e-12)
    assert c.t_reference_s == pytest.approx(p.time_s, abs=2 * m.limits.t_ipo_s)
    assert abs(c.gap_lower) < 0.01 and abs(c.gap_upper) < 0.01
    by_line = {r.line: r for r in c.rows}
    assert by_line[5].hold_cause == "exact stop settle"
    assert [by_line[k].limit_reference for k in (1, 4, 6)] == ["dwell"] * 3
