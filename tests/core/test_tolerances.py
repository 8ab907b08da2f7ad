"""Each named tolerance means what its comment says: tested at 0.5x and 1.5x."""

from __future__ import annotations

import numpy as np
import pytest

from reference.core import AxisLimits, MachineLimits, Profile, path_from_pieces
from reference.core.constraints import check_profile
from reference.core.errors import NCSyntaxError, PathError
from reference.core.geometry import arc_segment, line_segments
from reference.core.tolerances import (ARC_RADIUS_TOL_MM, ARC_SPIRAL_MIN_MM,
                                       MIN_SEGMENT_LENGTH_MM, RATIO_TOL, TANGENT_TOL_RAD,
                                       VEL_TOL_MM_S)
from reference.nc import parse_text
from reference.prepare import prepare

GEO = np.array([True, True, True])
AX = ("X", "Y", "Z")
LIM = MachineLimits(tuple(AxisLimits(a, 500.0, 2000.0, 40000.0) for a in AX), 0.004)


@pytest.mark.parametrize("factor, ok", [(0.5, True), (1.5, False)])
def test_arc_radius_tolerance(factor, ok):
    r = 1.0      # small enough that the absolute part (not ARC_RADIUS_REL_TOL * r) applies
    end = np.array([0.0, r + factor * ARC_RADIUS_TOL_MM, 0.0])
    call = lambda: arc_segment(np.array([r, 0, 0.0]), end, np.zeros(3), (0, 1), False, 0,  # noqa
                               GEO, 0, ARC_RADIUS_TOL_MM)
    if ok:
        call()
    else:
        with pytest.raises(PathError):
            call()
    text = f"G1 X{r} Y0 F100\nG3 X0 Y{r + factor * ARC_RADIUS_TOL_MM:.6f} I-{r} J0\n"
    if ok:
        parse_text(text, "t.mpf")
    else:
        with pytest.raises(NCSyntaxError, match="differ by"):
            parse_text(text, "t.mpf")


@pytest.mark.parametrize("factor, spiral", [(0.5, False), (1.5, True)])
def test_spiral_threshold(factor, spiral):
    r = 1.0
    end = np.array([0.0, r + factor * ARC_SPIRAL_MIN_MM, 0.0])
    p = path_from_pieces(AX, [arc_segment(np.array([r, 0, 0.0]), end, np.zeros(3), (0, 1),
                                          False, 0, GEO, 0, ARC_RADIUS_TOL_MM)])
    assert bool(p.dradius[0] != 0) is spiral
    # a circle ends at most ARC_SPIRAL_MIN_MM off; a spiral ends on the point
    gap = np.abs(p.segment(0).end - end).max()
    assert gap <= (1e-15 if spiral else ARC_SPIRAL_MIN_MM)


@pytest.mark.parametrize("factor, segments", [(0.5, 1), (1.5, 2)])
def test_min_segment_length(factor, segments):
    d = factor * MIN_SEGMENT_LENGTH_MM
    p = prepare(parse_text(f"G1 X10 F100\nG1 X{10 + d:.9f}\n", "t.mpf"))
    assert p.n_segments == segments


@pytest.mark.parametrize("factor, ok", [(0.5, True), (1.5, False)])
def test_velocity_tolerance_at_a_stop(factor, ok):
    pts = np.array([[0, 0, 0], [10, 0, 0.0]])
    p = path_from_pieces(AX, [line_segments(pts[:-1], pts[1:], GEO, np.array([0]))])
    v_end = factor * VEL_TOL_MM_S
    a = (v_end ** 2 - 100.0 ** 2) / (2 * 5.0)
    # accelerate to 100 mm/s over 5 mm, then brake to v_end at the end
    prof = Profile.from_path_velocity([0, 5, 10], [0, 100, v_end])
    assert check_profile(p, LIM, prof).worst("stop").violated is (not ok)
    del a


@pytest.mark.parametrize("factor, ok", [(0.5, True), (1.5, False)])
def test_ratio_tolerance(factor, ok):
    pts = np.array([[0, 0, 0], [100, 0, 0.0]])
    p = path_from_pieces(AX, [line_segments(pts[:-1], pts[1:], GEO, np.array([0]))])
    a = 2000.0 * (1 + factor * RATIO_TOL)
    v = 300.0
    prof = Profile.from_phases([v / a, (100 - v * v / a) / v, v / a], [a, 0, -a], [0, 0, 0])
    assert check_profile(p, LIM, prof).ok(("acceleration",)) is ok


@pytest.mark.parametrize("factor, stops", [(0.5, False), (1.5, True)])
def test_tangent_tolerance_decides_a_g61_corner(factor, stops):
    th = factor * TANGENT_TOL_RAD
    text = (f"G61 G1 X100 F100\nG1 X{100 + 100 * np.cos(th):.12f} "
            f"Y{100 * np.sin(th):.12f}\n")
    p = prepare(parse_text(text, "t.ngc", "ngc"))
    assert bool(p.stop[1]) is stops


@pytest.mark.parametrize("factor, ok", [(0.5, True), (1.5, False)])
def test_block_motion_time_bound_at_half_and_one_and_a_half(factor, ok):
    """A block moving MAX_BLOCK_MOTION_S * factor at its feed: kept at 0.5x, an error at
    its line at 1.5x (F6 mm/min = 0.1 mm/s, so the length is 0.1 mm/s times the time)."""
    from reference.core.errors import PathError
    from reference.core.tolerances import MAX_BLOCK_MOTION_S
    from reference.machine import load_machine
    from reference.nc import parse_text
    from reference.prepare import build_path
    length = 0.1 * factor * MAX_BLOCK_MOTION_S
    prog = parse_text(f"G90 G1 X0 Y0 F6\nX{length:.6f}\nM30\n", "slow.mpf")
    if ok:
        assert build_path(prog, load_machine()).n_segments == 1
    else:
        with pytest.raises(PathError, match=r"slow.mpf:2: .* above the 1e\+06 s"):
            build_path(prog, load_machine())
