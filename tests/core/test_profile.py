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
