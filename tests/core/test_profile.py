"""Profile: exact integration, time lookup, splitting and block accounting."""

from __future__ import annotations

import numpy as np
import pytest

from reference.core import BlockSpan, Profile, ProfileError, path_from_pieces
from reference.core.geometry import line_segments

GEO = np.array([True, True, True])


def test_trapezoid_duration_closed_form():
    L, v, a = 100.0, 400.0, 2000.0
    ta = v / a
    prof = Profile.from_phases([ta, (L - v * v / a) / v, ta], [a, 0, -a], [0, 0, 0])
    assert prof.duration == pytest.approx(L / v + v / a)
    assert prof.s[-1] == pytest.approx(L) and prof.v[-1] == pytest.approx(0, abs=1e-9)
    same = Profile.from_path_velocity([0, v * v / (2 * a), L - v * v / (2 * a), L],
                                      [0, v, v, 0])
    assert same.duration == pytest.approx(prof.duration)


def test_state_and_time_at_are_inverse():
    prof = Profile.from_phases([0.1, 0.2, 0.1], [0, 1000, 1000], [10000, 0, -10000])
    t = np.linspace(0, prof.duration, 101)
    s = prof.state(t)[0]
    np.testing.assert_allclose(prof.time_at(s[1:]), t[1:], atol=1e-9)


def test_time_at_first_and_last_around_a_hold():
    # move 10 mm, hold 2 s at rest, move on
    prof = Profile.from_phases([1.0, 1.0, 2.0, 1.0, 1.0], [10, -10, 0, 10, -10], [0] * 5)
    assert prof.time_at([10.0], "first")[0] == pytest.approx(2.0)
    assert prof.time_at([10.0], "last")[0] == pytest.approx(4.0)


def test_time_at_matches_bisection_on_random_intervals():
    """``time_at`` inverts ``s(t)`` inside an interval (its docstring): against a plain
    bisection on the interval's cubic, to round-off of the interval length, on random
    intervals with constant, rising and falling speed, from rest and to rest."""
    rng = np.random.default_rng(5)
    for case in range(300):
        h = rng.uniform(1e-4, 0.2)
        a0 = 0.0 if case % 5 == 0 else rng.uniform(-300.0, 300.0)
        jj = 0.0 if case % 2 else rng.uniform(-2e4, 2e4)
        tt = np.linspace(0.0, h, 401)
        v0 = 0.0 if case % 7 == 0 else rng.uniform(0.0, 100.0)
        v0 -= min(np.min(v0 + a0 * tt + jj * tt ** 2 / 2), 0.0)     # v >= 0 throughout
        if case % 11 == 0:              # braking to rest at the interval end
            a0, jj, v0 = -abs(a0) - 1.0, 0.0, (abs(a0) + 1.0) * h
        v1 = max(v0 + a0 * h + jj * h ** 2 / 2, 0.0)
        ds = v0 * h + a0 * h ** 2 / 2 + jj * h ** 3 / 6
        if not ds > 0:
            continue
        prof = Profile(t=[0.0, h], s=[0.0, ds], v=[v0, v1], a=[a0], j=[jj], block=[0])
        q = rng.uniform(0.0, 1.0, 50) * ds
        lo, hi = np.zeros(q.size), np.full(q.size, h)
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            below = v0 * mid + a0 * mid ** 2 / 2 + jj * mid ** 3 / 6 < q
            lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
        np.testing.assert_allclose(prof.time_at(q), 0.5 * (lo + hi), rtol=0, atol=1e-13 * h)


def test_split_at_keeps_the_motion():
    prof = Profile.from_phases([0.1, 0.3, 0.1], [0, 1000, 1000], [10000, 0, -10000])
    cut = prof.split_at([1.0, 7.5, 20.0])
    t = np.linspace(0, prof.duration, 333)
    for a, b in zip(prof.state(t), cut.state(t)):
        np.testing.assert_allclose(a, b, atol=1e-9)
    assert np.all(np.isin([1.0, 7.5, 20.0], cut.s))


def test_cuts_on_knots_are_dropped_as_isin_drops_them():
    """``split_at`` ignores cuts on existing knots (its docstring); the bisection that
    finds them must drop exactly what ``numpy.isin`` over the knots drops, holds (equal
    neighbouring knots) included."""
    prof = Profile.from_phases([1.0, 1.0, 2.0, 1.0, 1.0], [10, -10, 0, 10, -10], [0] * 5)
    rng = np.random.default_rng(3)
    cuts = np.concatenate((prof.s, rng.uniform(0.0, prof.s[-1], 40), [5.0, 10.0]))
    k, tc, sc = prof._cuts(cuts)
    ref = np.unique(cuts)
    ref = ref[(ref > prof.s[0]) & (ref < prof.s[-1])]
    ref = ref[~np.isin(ref, prof.s)]
    np.testing.assert_array_equal(np.sort(sc), ref)
    assert not np.isin(sc, prof.s).any()


def test_a_cut_a_hair_short_of_a_rest_is_that_rest():
    """A motion coming to rest approaches its stop as a cubic, so a cut 1e-14 mm short
    of the stop (round-off of a break position) is crossed microseconds before it: the
    sliver split off held the tail of the deceleration, and where the pieces of two
    motions were joined at that stop it read as a phase of 5 us (a frequency ratio of
    16,000). Within POS_TOL_MM of a knot at rest, the cut is that knot; near a moving
    knot, and farther from a rest, it still splits."""
    from reference.core.tolerances import POS_TOL_MM
    prof = Profile.from_phases([0.1, 0.1, 0.1, 0.1], [0, 1000, 0, -1000],
                               [10000, -10000, -10000, 10000])
    stop = float(prof.s[-1])
    assert prof.v[-1] == 0.0
    assert prof.split_at([stop - 1e-14]).n_intervals == prof.n_intervals
    assert prof.split_at([stop - 0.5 * POS_TOL_MM]).n_intervals == prof.n_intervals
    assert prof.split_at([stop - 1e-3]).n_intervals == prof.n_intervals + 1
    moving = float(prof.s[2])                       # at full speed
    assert prof.v[2] > 0
    assert prof.split_at([moving - 1e-9]).n_intervals == prof.n_intervals + 1


def test_block_times_sum_to_duration_and_hold_goes_to_dwell_block():
    pts = np.array([[0, 0, 0], [10, 0, 0], [20, 0, 0]], float)
    spans = (BlockSpan(0, 1, "", "G1", 0.0, 10.0, 0, 1),
             BlockSpan(1, 2, "", "none", 10.0, 10.0, 1, 0, stop_reason="dwell", dwell_s=0.5),
             BlockSpan(2, 3, "", "G1", 10.0, 20.0, 1, 1))
    p = path_from_pieces(("X", "Y", "Z"), [line_segments(pts[:-1], pts[1:], GEO, np.array([0, 2]))],
                         blocks=spans)
    prof = Profile.from_phases([1, 1, 0.5, 1, 1], [10, -10, 0, 10, -10], [0] * 5)
    bt = prof.block_times(p)
    assert bt.tolist() == pytest.approx([2.0, 0.5, 2.0])
    assert bt.sum() == pytest.approx(prof.duration)
    np.testing.assert_allclose(prof.segment_times(p), [2.0, 2.0])



def test_segment_times_of_some_segments_against_the_closed_form():
    """A rest-to-rest trapezoid over 50 lines of 1 mm (ramps of 0.1 s at 1000 mm/s^2 to
    100 mm/s, 5 mm each): the time of segment ``[j, j + 1]`` is ``T(j + 1) - T(j)`` with
    ``T(s) = sqrt(2 s / a)`` on the rise, ``0.1 + (s - 5) / v`` at cruise and the mirror
    on the fall. Asked for some segments only (as the block rows ask for those of the
    blocks with roundings), each comes out so, the others 0; and
    ``block_and_segment_times`` gives the same."""
    n = 50
    x = np.arange(n + 1, dtype=float)
    pts = np.column_stack((x, np.zeros(n + 1), np.zeros(n + 1)))
    spans = (BlockSpan(0, 1, "", "G1", 0.0, float(n), 0, n),)
    p = path_from_pieces(("X", "Y", "Z"),
                         [line_segments(pts[:-1], pts[1:], GEO, np.zeros(n, np.int64))],
                         blocks=spans)
    prof = Profile.from_phases([0.1, 0.4, 0.1], [1000.0, 0.0, -1000.0], [0.0, 0.0, 0.0])
    a, v = 1000.0, 100.0

    def T(s):
        s = np.asarray(s, float)
        return np.where(s <= 5.0, np.sqrt(2.0 * s / a),
                        np.where(s <= 45.0, 0.1 + (s - 5.0) / v,
                                 0.6 - np.sqrt(2.0 * np.maximum(n - s, 0.0) / a)))

    exact = T(x[1:]) - T(x[:-1])
    rng = np.random.default_rng(7)
    for segs in (np.array([0, n - 1]), np.array([4, 5, 6]), np.arange(n),
                 *(np.unique(rng.integers(0, n, size=k)) for k in (1, 5, 20))):
        got = prof.segment_times(p, segs)
        np.testing.assert_allclose(got[segs], exact[segs], rtol=1e-12, atol=1e-15)
        rest = np.setdiff1d(np.arange(n), segs)
        assert np.all(got[rest] == 0.0)
        bt, st = prof.block_and_segment_times(p, segs)
        np.testing.assert_array_equal(st, got)
        assert bt[0] == pytest.approx(0.6, rel=1e-14)

@pytest.mark.parametrize("kw, match", [
    (dict(t=[0, np.nan], s=[0, 1], v=[0, 0], a=[0], j=[0], block=[0]), r"t\[1\] is not finite"),
    (dict(t=[0, 1, 0.5], s=[0, 1, 2], v=[0, 0, 0], a=[0, 0], j=[0, 0], block=[0, 0]),
     "time runs backwards at knot 2"),
    (dict(t=[0, 1], s=[0, 5], v=[0, 0], a=[0], j=[0], block=[0]),
     r"integrated position 0 mm does not meet the next knot 5 mm"),
    (dict(t=[0, 1], s=[0, 0.5], v=[0, -1], a=[-1], j=[0], block=[0]), "negative path velocity"),
    (dict(t=[0, 1], s=[0, 1], v=[1, 1], a=[0, 0], j=[0], block=[0]), "knot arrays must have 3 entries for 2 intervals"),
])
def test_profile_errors(kw, match):
    with pytest.raises(ProfileError, match=match):
        Profile(**{k: np.asarray(v, dtype=float if k != "block" else int) for k, v in kw.items()})


def test_zero_velocity_interval_is_an_error():
    with pytest.raises(ProfileError, match=r"zero at both ends of \[0, 1\] mm"):
        Profile.from_path_velocity([0, 1, 2, 3], [0, 0, 0, 0])
