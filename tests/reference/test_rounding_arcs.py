"""Rounding of corners next to arcs (issue 13; reference/rounding_arcs.py,
reference/core/rounding.py line_circle_fillet), against hand geometry.

spec 5.1: "Rounding locally changes the programmed contour so that an angular transition
becomes tangential ... the neighbouring blocks are shortened and one or two intermediate
blocks are inserted"; RND/RNDM (issue 13): "a programmed rounding radius as a tangent
arc"; 5.3: "ADIS ... the earliest point before the block end where rounding may start,
and the latest point after it where rounding must be finished ... For arcs, measure along
the arc"; 5.4: "The maximum deviation for G642/G643 is set per axis in MD33100
COMPRESS_POS_TOL".

The corner of the test contour: the line y = 0 ends at C = (20, 0); the clockwise arc of
radius 5 about (25, 0) starts there going up (+y), a 90 degree left turn. A fillet of
radius r turns left, so its centre is O = (x, r); the arc turns right, so the fillet
touches it from outside: |O - (25, 0)| = 5 + r, x = 25 - sqrt(25 + 10 r).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from reference.core.constraints import BOUND_SETS, check_profile
from reference.core.geometry import KIND_CODES
from reference.machine import load_machine
from reference.nc import parse_text
from reference.planner import plan
from reference.prepare import build_path
from rounding_machines import rounding_machine

ROUNDING = KIND_CODES.index("rounding")
ARC = KIND_CODES.index("arc")
LINE_ARC = "G1 X0 Y0\nG1 X20\nG2 X30 Y0 I5 J0\n"
#: The mirror image in time: the counter-clockwise arc about (5, 0) ends at (10, 0) going
#: up, the line then runs along +x (a right turn; the fillet's centre (10 + 1.7082, -2)
#: for r = 2 by the same formula).
ARC_LINE = "G1 X0 Y0\nG3 X10 Y0 I5 J0\nG1 X30\n"


def machine(**channel):
    """G64 stops at every corner (overload factor 1.0): where the feed is low the
    rounding costs nothing and every parameterised corner is rounded."""
    return rounding_machine(**channel)


def reasons(path) -> list[str]:
    t = path.rounding
    return [t.reason_text(i) for i in range(t.n)]


def fillet(path) -> int:
    k = np.flatnonzero(path.kind == ROUNDING)
    assert k.size == 1
    return int(k[0])


def hand(r: float) -> dict:
    """The fillet of radius r at the line-arc corner by hand (module docstring)."""
    x = 25.0 - math.sqrt(25.0 + 10.0 * r)
    O = np.array([x, r])
    u = (O - [25.0, 0.0]) / np.linalg.norm(O - [25.0, 0.0])
    end = np.array([25.0, 0.0]) + 5.0 * u
    arc_angle = math.atan2(u[1], -u[0])            # from the leftmost point, clockwise
    tangent = np.array([u[1], -u[0]])              # clockwise tangent at the end
    sweep = math.atan2(tangent[1], tangent[0])     # from heading 0, turning left
    return {"O": O, "start": np.array([x, 0.0]), "end": end, "line_trim": 20.0 - x,
            "arc_trim": 5.0 * arc_angle, "sweep": sweep,
            "deviation": math.hypot(20.0 - x, r) - r}


@pytest.mark.parametrize("mirror", [False, True])
def test_rnd_at_a_line_arc_corner_is_the_tangent_arc_by_hand(mirror):
    """RND=2 at the line-arc corner and at its mirror image (arc into line): the fillet,
    its ends, the replaced lengths and the deviation by hand."""
    body = (ARC_LINE.replace("I5 J0\n", "I5 J0 RND=2\n") if mirror
            else LINE_ARC.replace("X20\n", "X20 RND=2\n"))
    path = build_path(parse_text("G17 G90 G64 BRISK F600\n" + body), machine())
    assert reasons(path) == ["rounded"]
    h = hand(2.0)
    t = path.rounding
    assert t.radius_mm[0] == 2.0
    assert t.length_mm[0] == pytest.approx(2.0 * h["sweep"], rel=1e-12)
    assert t.deviation_mm[0] == pytest.approx(h["deviation"], rel=1e-12)
    assert t.distance_mm[0] == pytest.approx(h["line_trim"], rel=1e-12)
    k = fillet(path)
    q0 = path.evaluate(path.s_breaks[k], segment=np.array([k]))[0][0, :2]
    q1 = path.evaluate(path.s_breaks[k + 1], segment=np.array([k]))[0][0, :2]
    if not mirror:
        np.testing.assert_allclose(q0, h["start"], atol=1e-12)
        np.testing.assert_allclose(q1, h["end"], atol=1e-12)
        arc = k + 1
    else:
        # (x, y) -> (30 - x, -y) maps the line-arc corner onto this arc-line corner
        # with the direction of travel reversed
        np.testing.assert_allclose(q0, [30.0 - h["end"][0], -h["end"][1]], atol=1e-12)
        np.testing.assert_allclose(q1, [30.0 - h["start"][0], 0.0], atol=1e-12)
        arc = k - 1
    assert path.length[arc] == pytest.approx(5.0 * math.pi - h["arc_trim"], rel=1e-12)
    # the shortened arc stays on its circle, and everything meets tangentially (G1)
    centre = np.array([5.0, 0.0]) if mirror else np.array([25.0, 0.0])
    s = np.linspace(path.s_breaks[arc], path.s_breaks[arc + 1], 40)
    q = path.evaluate(s, segment=np.full(40, arc))[0][:, :2]
    np.testing.assert_allclose(np.linalg.norm(q - centre, axis=1), 5.0, atol=1e-12)
    sb = path.s_breaks[1:-1]
    seg = np.arange(path.n_segments)
    qa, ta = path.evaluate(sb, segment=seg[:-1])[:2]
    qb, tb = path.evaluate(sb, segment=seg[1:])[:2]
    np.testing.assert_allclose(qa, qb, atol=1e-9)
    np.testing.assert_allclose(ta, tb, atol=1e-9)


def test_g641_keeps_both_ends_within_adis_measured_along_the_arc():
    """spec 5.3: the rounding starts at most ADIS before the corner and ends at most ADIS
    after it, along the line and along the arc; the larger of the two is ADIS."""
    path = build_path(parse_text("G17 G90 G641 ADIS=0.5 BRISK F600\n" + LINE_ARC),
                      machine())
    assert reasons(path) == ["rounded"]
    r = float(path.rounding.radius_mm[0])
    h = hand(r)
    assert max(h["line_trim"], h["arc_trim"]) == pytest.approx(0.5, rel=1e-9)
    assert max(h["line_trim"], h["arc_trim"]) <= 0.5 * (1 + 1e-12)
    k = fillet(path)
    assert path.s_breaks[k] == pytest.approx(20.0 - h["line_trim"], rel=1e-12)


def test_g642_keeps_every_axis_within_compress_pos_tol():
    """spec 5.4: per axis |C_i - M_i| <= MD33100 (0.01 mm), M the fillet's point nearest
    the corner; the axis that limits uses it. Dense samples of the fillet: its smallest
    distance from C is the recorded deviation."""
    path = build_path(parse_text("G17 G90 G642 BRISK F600\n" + LINE_ARC), machine())
    assert reasons(path) == ["rounded"]
    r = float(path.rounding.radius_mm[0])
    h = hand(r)
    C = np.array([20.0, 0.0])
    M = h["O"] + r * (C - h["O"]) / np.linalg.norm(C - h["O"])
    assert np.abs(C - M).max() == pytest.approx(0.01, rel=1e-9)
    k = fillet(path)
    s = np.linspace(path.s_breaks[k], path.s_breaks[k + 1], 20001)
    q = path.evaluate(s, segment=np.full(s.size, k))[0][:, :2]
    assert np.linalg.norm(q - C, axis=1).min() == pytest.approx(
        path.rounding.deviation_mm[0], rel=1e-6)


@pytest.mark.parametrize("ctol", [0.01, 0.05])
def test_the_contour_tolerance_radius_at_a_line_arc_corner_is_the_hand_root(ctol):
    """spec 5.7: CTOL is the contour tolerance of G642/G645 (COMPRESS_POS_TOL 1 mm per
    axis here, so the contour decides). The fillet kept is the largest within it: its
    hand deviation (module docstring) lies within 3e-11 below CTOL, its radius is the
    hand root to 1e-10 (brentq on the hand formula), and the clamp does not decide."""
    path = build_path(parse_text(f"G17 G90 G642 CTOL={ctol} BRISK F600\n" + LINE_ARC),
                      rounding_machine(tol=1.0))
    assert reasons(path) == ["rounded"]
    r = float(path.rounding.radius_mm[0])
    assert not bool(path.rounding.clamped[0])
    assert ctol * (1.0 - 3e-11) <= hand(r)["deviation"] <= ctol
    r_hand = brentq(lambda x: hand(x)["deviation"] - ctol, 1e-6, 1.0, xtol=1e-15,
                    rtol=1e-15)
    assert r == pytest.approx(r_hand, rel=1e-10)


def test_the_block_length_clamp_limits_rnd():
    """spec 5.3 (and the G644 excerpt): at most half of each participating block. RND=2
    on a 1 mm line into the arc would replace 1.71 mm of it: the radius is cut until
    0.5 mm is replaced."""
    text = "G17 G90 G64 BRISK F600\nG1 X19 Y0\nG1 X20 RND=2\nG2 X30 Y0 I5 J0\n"
    path = build_path(parse_text(text), machine())
    t = path.rounding
    assert reasons(path)[-1] == "rounded" and bool(t.clamped[-1])
    h = hand(float(t.radius_mm[-1]))
    assert h["line_trim"] == pytest.approx(0.5, rel=1e-9)
    assert t.radius_mm[-1] < 2.0


def test_model_limits_are_named():
    """(corners between two arcs: tests/reference/test_rounding_arc_arc.py)"""
    # a line leaving the arc's plane
    out = "G17 G90 G641 ADIS=0.5 BRISK F600\nG1 X0 Y0 Z0\nG1 X20 Z5\nG2 X30 Y0 I5 J0\n"
    assert reasons(build_path(parse_text(out), machine()))[-1] == (
        "corner next to a helix or spiral, or out of the arc's plane: rounding not "
        "modelled yet")


@pytest.mark.parametrize("mfile", ["default", "linuxcnc_xyz"])
@pytest.mark.parametrize("mode", ["G641 ADIS=0.5", "G642 CTOL=0.05", "G645 CTOL=0.05"])
@pytest.mark.parametrize("accel", ["BRISK", "SOFT"])
def test_arc_corners_keep_the_limits_and_do_not_slow_the_program(mfile, mode, accel):
    """The heuristic keeps every limit of its bound set on the rounded path, and a
    rounding is only inserted where it does not slow the program (5.2 group 2)."""
    mach = load_machine(mfile)
    body = ("G1 X0 Y0\nG1 X20\nG2 X30 Y0 I5 J0\nG1 X30 Y-20\nG3 X40 Y-20 I5 J0\n"
            "G1 X40 Y10\nG2 X50 Y10 I5 J0\nG1 X60 Y5\nM30\n")
    times = {}
    for m in ("G64", mode):
        prog = parse_text(f"G17 G90 {m} {accel} F3000\n" + body)
        path = build_path(prog, mach)
        res = plan(prog, mach, path=path)
        assert check_profile(path, mach.limits, res.profile).ok(BOUND_SETS[res.bound_set])
        times[m] = res.time_s
    assert times[mode] <= times["G64"] * (1 + 1e-9)


def test_line_circle_fillet_is_tangent_to_both_on_random_corners():
    """Hand geometry on 2000 seeded corners (line direction, circle centre and sense,
    radius): where the fillet exists its centre is r from the line and R -+ r from the
    circle's centre, it leaves the line before the corner and ends on the circle, and
    its radius at either end is normal to the element it touches (tangency)."""
    from reference.core.rounding import (fillet_radius_for_arc_trim,
                                         fillet_radius_for_line_trim, line_circle_fillet)
    rng = np.random.default_rng(3)
    k = 2000
    ang = rng.uniform(0, 2 * np.pi, k)
    t = np.column_stack((np.cos(ang), np.sin(ang)))
    R = rng.uniform(0.5, 50.0, k)
    beta = rng.uniform(0, 2 * np.pi, k)                  # C on the circle: c = -R u0
    c = -R[:, None] * np.column_stack((np.cos(beta), np.sin(beta)))
    sense = rng.choice((-1.0, 1.0), k)
    r = rng.uniform(0.01, 0.3, k) * R
    f = line_circle_fillet(r, t, c, R, sense)
    v = f.valid
    assert v.mean() > 0.3
    n_dist = np.abs(t[v, 0] * f.centre[v, 1] - t[v, 1] * f.centre[v, 0])
    np.testing.assert_allclose(n_dist, r[v], rtol=1e-9, atol=1e-12)
    oc = np.linalg.norm(f.centre[v] - c[v], axis=1)
    assert np.all(np.minimum(np.abs(oc - (R[v] - r[v])), np.abs(oc - (R[v] + r[v])))
                  <= 1e-9 * R[v])
    np.testing.assert_allclose(np.linalg.norm(f.end[v] - c[v], axis=1), R[v], rtol=1e-12)
    np.testing.assert_allclose(np.einsum("ij,ij->i", f.start[v] - f.centre[v], t[v]), 0.0,
                               atol=1e-9 * R[v].max())
    assert np.all(np.einsum("ij,ij->i", f.start[v], t[v]) < 0)      # before the corner
    # the end: fillet radius and circle radius on one line through both centres
    a = f.end[v] - f.centre[v]
    b = f.end[v] - c[v]
    np.testing.assert_allclose(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0], 0.0,
                               atol=1e-9 * R[v].max() ** 2)
    # the closed-form radii invert the replaced lengths
    np.testing.assert_allclose(fillet_radius_for_line_trim(f.line_trim[v], t[v], c[v], R[v],
                                                           sense[v]), r[v], rtol=1e-11)
    np.testing.assert_allclose(fillet_radius_for_arc_trim(f.arc_trim[v], t[v], c[v], R[v],
                                                          sense[v]), r[v], rtol=1e-11)
