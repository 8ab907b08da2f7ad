"""The one per-block row model: block_motion against hand-computed trapezoids."""

from __future__ import annotations

import numpy as np
import pytest

from reference.core import BlockSpan, Profile, path_from_pieces
from reference.core.geometry import line_segments
from reference.core.rows import BlockRow, block_motion, block_rows

GEO = np.array([True, True, True])


def _two_blocks_and_a_dwell():
    pts = np.array([[0, 0, 0], [50, 0, 0], [100, 0, 0]], float)
    spans = (BlockSpan(0, 1, "N10", "G1", 0.0, 50.0, 0, 1),
             BlockSpan(1, 2, "N20", "G1", 50.0, 100.0, 1, 1),
             BlockSpan(2, 3, "N30", "none", 100.0, 100.0, 2, 0, stop_reason="dwell",
                       dwell_s=0.5))
    return path_from_pieces(("X", "Y", "Z"), [line_segments(pts[:-1], pts[1:], GEO,
                                                             np.array([0, 1]))], blocks=spans)


def test_block_motion_of_a_trapezoid_by_hand():
    # 0 -> 100 mm/s at 1000 mm/s^2 (5 mm, 0.1 s), cruise 90 mm (0.9 s), brake (0.1 s),
    # then 0.5 s at rest: block 0 takes 0.1 + 45/100 s and leaves at full speed
    path = _two_blocks_and_a_dwell()
    prof = Profile.from_phases([0.1, 0.9, 0.1, 0.5], [1000, 0, -1000, 0], [0, 0, 0, 0])
    m = block_motion(path, prof)
    np.testing.assert_allclose(m.time_s, [0.55, 0.55, 0.5], rtol=1e-12)
    np.testing.assert_allclose(m.v_entry, [0.0, 100.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(m.v_exit, [100.0, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(m.v_peak, [100.0, 100.0, 0.0], atol=1e-9)
    rows = block_rows(path, m, ["axis acceleration", "feed", "dwell"],
                      np.array([0.0, 0.0, 0.5]))
    assert rows[1] == BlockRow(block=1, line=2, label="N20", kind="G1", length_mm=50.0,
                               time_s=pytest.approx(0.55), v_entry=pytest.approx(100.0),
                               v_exit=pytest.approx(0.0, abs=1e-9),
                               v_peak=pytest.approx(100.0), cause="feed", hold_s=0.0)
    assert rows[2].cause == "dwell" and rows[2].hold_s == 0.5


def test_peak_inside_an_interval_is_found():
    # one constant-jerk piece whose speed peaks inside it: v = 20 t - 50 t^2 on [0, 0.4]
    # peaks at t = 0.2 with v = 2 mm/s; both knots are at rest
    prof = Profile.from_phases([0.4], [20.0], [-100.0])
    L = float(prof.s[-1])
    spans = (BlockSpan(0, 1, "", "G1", 0.0, L, 0, 1),)
    pts = np.array([[0, 0, 0], [L, 0, 0]], float)
    path = path_from_pieces(("X", "Y", "Z"), [line_segments(pts[:-1], pts[1:], GEO,
                                                             np.array([0]))], blocks=spans)
    m = block_motion(path, prof)
    assert m.v_peak[0] == pytest.approx(2.0, rel=1e-12)
