"""The free phase ends of ``acc+freq`` (optimal.freq.free_phases) against independent
references: the closed form ``L/v + 1/f`` of DESIGN 6 on rest-to-rest lines (the NLP
may not beat it: its rows are the rule; nor fall short of it by more than its margins),
and hand-built motions of the rule's second case (tests/optimal/test_freq.py), judged by
the checker. Every motion here is judged by ``check_profile``, never by the NLP itself.
"""

from __future__ import annotations

import numpy as np
import pytest

import optimal
from oracle_cases import line_path
from reference.core.constraints import BOUND_SETS, check_profile
from reference.core.phases import acceleration_phases
from reference.core.profile import Profile
from optimal.freq.free_phases import (FREE_RULE_MARGIN, _move_key, _valid, free_phase_motions,
                                      layout_profile, piece_model, seed_layout, solve_layout)
from test_freq import N0, _labelled, machine

ACC_FREQ = BOUND_SETS["acc+freq"]
#: What the NLP's motion may lose against the closed form, relative: each of its two
#: phases keeps ``g (1 + FREE_RULE_MARGIN)`` (at most 2 FREE_RULE_MARGIN of the time), and
#: the creep inside the phases (25e-6 of the largest path acceleration) costs less than
#: that again; measured 4e-6 to 1e-5.
CLOSED_FORM_SLACK = 4 * FREE_RULE_MARGIN


def _nlp_of(path, lim, seed):
    """The NLP's motion on the path's one piece from the phases of ``seed``."""
    model = piece_model(path, lim.for_axes(path.axes), 0, path.n_segments)
    codes, sigma = seed_layout(model, seed)
    lay = solve_layout(model, codes, sigma, lambda s: np.interp(s, seed.s, seed.v))
    return lay, layout_profile(path, model, lay)


@pytest.mark.parametrize("L, feed", [(20.0, 200.0), (10.0, 50.0), (2.0, 10.0), (0.3, 2.0),
                                     (100.0, 100.0)])
def test_nlp_meets_the_closed_form_on_a_line(L, feed):
    # machine(): A = 2000 mm/s^2, f = 10 Hz; feed / A < 1/f on every line here, so the
    # fastest motion the rule accepts takes exactly L / feed + 1/f (DESIGN 6), from the
    # acc optimum (phases of feed / A) as the seed
    lim = machine(f=10.0)
    path = line_path([[0, 0, 0], [L, 0, 0]], feed=np.array([feed]))
    closed = L / feed + 0.1
    lay, prof = _nlp_of(path, lim, optimal.solve(path, lim, bounds="acc").profile)
    assert lay.ok and lay.codes == (1,)
    assert prof.duration == pytest.approx(lay.time_s, rel=1e-12)
    assert closed * (1 - 1e-12) <= prof.duration <= closed * (1 + CLOSED_FORM_SLACK)
    rep = check_profile(path, lim, prof)
    assert rep.ok(ACC_FREQ), rep.violations(ACC_FREQ)


def test_search_joins_the_falls_through_a_feed_cap():
    # tests/optimal/test_freq.py's line falling through a feed cap (30 mm at 100 mm/s,
    # 5 mm at 50 mm/s): the hand motion falls in one phase (0.46875 s), the ramps of 1/f
    # take 0.525 s. From the ramps, the first layout joins the two falls and comes within
    # 0.5 % of the hand motion (measured 0.36 %: the nodes fall where the hand motion's
    # acceleration steps only approximately)
    lim = machine(f=10.0)
    path = line_path([[0, 0, 0], [30.0, 0, 0], [35.0, 0, 0]], feed=np.array([100.0, 50.0]))
    ramps = Profile.from_phases([0.1, 0.175, 0.1, 0.05, 0.1],
                                [1000.0, 0, -500.0, 0, -500.0], np.zeros(5),
                                block=[0, 0, 0, 1, 1])
    found = free_phase_motions(path, lim.for_axes(path.axes), ramps)
    assert set(found) == {0}
    prof = found[0]
    assert prof.duration <= 0.46875 * (1 + 5e-3)
    assert acceleration_phases(prof).n == 2
    rep = check_profile(path, lim, prof)
    assert rep.ok(ACC_FREQ), rep.violations(ACC_FREQ)


def _wiggle_case():
    """tests/optimal/test_freq.py's line of five blocks with a wiggle between two point
    caps, and the ramps of 1/f on it (0.8980 s)."""
    lengths = [30.0, 0.01, 2.8, 0.01, 20.0]
    pts = np.zeros((6, 3))
    pts[1:, 0] = np.cumsum(lengths)
    path = line_path(pts, feed=np.array([100.0, 17.0, 60.0, 1.5, 100.0]))
    v_top = (2.8 - 0.1 * 18.5 / 2) / 0.1
    ramps = _labelled(path, [0.1, (30.0 - 5.0 - 5.85) / 100.0, 0.1, 0.01 / 17.0, 0.1, 0.1,
                             0.01 / 1.5, 0.1, (20.0 - 5.075 - 5.0) / 100.0, 0.1],
                      [1000.0, 0.0, -830.0, 0.0, (v_top - 17.0) / 0.1,
                       (1.5 - v_top) / 0.1, 0.0, 985.0, 0.0, -1000.0])
    return path, ramps


def test_search_beats_the_hand_motion_through_a_wiggle_and_stays_above_the_lower_bound():
    # The hand motion of test_freq.py crosses the wiggle in one fall (0.84197 s); the
    # first layout keeps the ramps' five phases (0.8908 s), the search drops the wiggle's
    # rise with its ends and moves the falls' ends (0.83639 s), and the last solve on
    # finer nodes gives 0.83564 s, 0.75 % faster than the hand motion and accepted by
    # the checker. The oracle's certified lower bound
    # (0.82515 s) must stay below it: an independent check of the bound by a motion the
    # bound's own proof never saw
    lim = machine(f=10.0)
    path, ramps = _wiggle_case()
    lay, first = _nlp_of(path, lim, ramps)
    assert len(lay.codes) == 5
    found = free_phase_motions(path, lim.for_axes(path.axes), ramps)
    prof = found[0]
    assert prof.duration < 0.84197 < first.duration
    rep = check_profile(path, lim, prof)
    assert rep.ok(ACC_FREQ), rep.violations(ACC_FREQ)
    sol = optimal.solve(path, lim, bounds="acc+freq", initial_intervals=N0)
    assert sol.lower_bound_s <= prof.duration
    # the oracle's search starts from its own fastest motion and stops once the
    # bracket is met (measured 0.83564 s, 1.27 %)
    assert sol.upper_bound_s < 0.84197 and sol.gap <= 0.02
    assert check_profile(path, lim, sol.profile).ok(ACC_FREQ)


def test_a_motion_the_checker_refuses_is_not_taken():
    # accept() stands for the checker in the oracle: refusing every motion leaves the
    # seed as it is (nothing returned), and the search asks once per solve at most
    lim = machine(f=10.0)
    path, ramps = _wiggle_case()
    asked = []
    found = free_phase_motions(path, lim.for_axes(path.axes), ramps, max_solves=6,
                               accept=lambda k, p: asked.append(k) or False)
    assert found == {}
    assert 1 <= len(asked) <= 6 and set(asked) == {0}


def test_search_stops_once_the_bracket_is_met():
    # enough: where the seed meets it already, nothing is solved; where the first
    # layout's motion (0.8908 s against the ramps' 0.8980 s) meets it, only that one
    lim = machine(f=10.0)
    path, ramps = _wiggle_case()
    for enough, n in ((ramps.duration, 0), (ramps.duration - 1e-3, 1)):
        asked = []
        found = free_phase_motions(path, lim.for_axes(path.axes), ramps, enough=enough,
                                   accept=lambda k, p: asked.append(k) or True)
        assert len(asked) == n and set(found) == set(range(n))


def test_layout_codes():
    # codes: 2k on interior break k, 2k + 1 in gap k; an odd count (the phases alternate
    # from a rise to a fall), nondecreasing, at most one end per break
    assert _valid((1,), 0) and _valid((1, 2, 3), 2) and _valid((3, 3, 3), 2)
    assert not _valid((1, 3), 2)           # an even count of ends: no fall to rest
    assert not _valid((2, 2, 3), 2)        # two ends on one break
    assert not _valid((3, 1, 3), 2)        # out of order
    assert not _valid((0,), 1) and not _valid((5,), 1)
    # the key of a move: what changes, with one end of context on either side
    assert _move_key((1, 2, 3, 5, 7), (1, 2, 4, 5, 7)) == ((2, 3, 5), (2, 4, 5))
    assert _move_key((1, 2, 3, 5, 7), (1, 5, 7)) == ((1, 2, 3, 5), (1, 5))


@pytest.mark.parametrize("case", ["line-arc-line R2", "line-arc-line R0.5", "blended 0",
                                  "blended 1"])
def test_arc_rows_are_conservative(case):
    # On arcs the model bounds |q'_j| |s''| + |q''_j| v^2 by the segment's suprema of
    # both parts: every motion of the NLP must pass the checker (which samples the axis
    # acceleration between the nodes), here one rise and one fall from a slow flat start
    # (the layout with its end in the first gap and in the last)
    from oracle_cases import line_arc_line, random_blended_polyline
    lim = machine(f=10.0)
    path = {"line-arc-line R2": lambda: line_arc_line(2.0, 10.0, feed=100.0),
            "line-arc-line R0.5": lambda: line_arc_line(0.5, 3.0, feed=150.0),
            "blended 0": lambda: random_blended_polyline(12, 0),
            "blended 1": lambda: random_blended_polyline(12, 1)}[case]()
    model = piece_model(path, lim.for_axes(path.axes), 0, path.n_segments)
    C = model.n_breaks
    sb = model.s_break
    for codes, mid in (((1,), 0.5 * (sb[0] + sb[1])), ((2 * C + 1,), 0.5 * (sb[-2] + sb[-1]))):
        lay = solve_layout(model, codes, np.array([mid]), lambda s: np.ones_like(s),
                           max_iter=3000)
        assert lay.ok
        rep = check_profile(path, lim, layout_profile(path, model, lay))
        assert rep.ok(ACC_FREQ), rep.violations(ACC_FREQ)


def test_a_short_arc_takes_two_periods():
    # A half circle of radius 1 mm at F80 (machine(): 10 Hz): a rise and a fall of at
    # least 1/f each, and at the peak pi / 0.1 = 31.4 mm/s (below the feed; centripetal
    # 987 mm/s^2 and the path acceleration 628 mm/s^2 within A) the two meet: exactly
    # 2/f = 0.2 s, the NLP neither below it nor above by more than its margins
    from oracle_cases import semicircle
    lim = machine(f=10.0)
    path = semicircle(1.0, feed=80.0)
    model = piece_model(path, lim.for_axes(path.axes), 0, path.n_segments)
    lay = solve_layout(model, (1,), np.array([0.5 * path.total_length]),
                       lambda s: np.ones_like(s), max_iter=3000)
    prof = layout_profile(path, model, lay)
    assert lay.ok and 0.2 * (1 - 1e-12) <= prof.duration <= 0.2 * (1 + CLOSED_FORM_SLACK)
    assert check_profile(path, lim, prof).ok(ACC_FREQ)
