"""Rounding of corners between two circular arcs (issue 13; reference/rounding_arcs.py,
reference/core/rounding.py circle_circle_fillet), against hand geometry and an
independent construction.

spec 5.1: "Rounding locally changes the programmed contour so that an angular transition
becomes tangential ... the neighbouring blocks are shortened and one or two intermediate
blocks are inserted"; RND/RNDM (issue 13): "a programmed rounding radius as a tangent
arc"; 5.3: "ADIS ... the earliest point before the block end where rounding may start,
and the latest point after it where rounding must be finished ... For arcs, measure along
the arc"; 5.4: "The maximum deviation for G642/G643 is set per axis in MD33100
COMPRESS_POS_TOL"; 5.3 and the G644 excerpt: "The rounding distance cannot exceed half
the length of the original participating blocks".

Hand corners (both mirror-symmetric about the corner's bisector, so the fillet's centre
lies on it, ``O = C + mu (-1, 1)``; the corner at C = (10, 0) turns right by 90 degrees,
from heading -y to heading -x):

* INSIDE: the clockwise arc about (5, 0) ends at C, the clockwise arc about (10, 5)
  starts there (both radius 5, both turn the way the corner does): the fillet of radius
  ``r`` lies inside both circles, ``|O - c_j| = 5 - r``: ``(5 - mu)^2 + mu^2 = (5 - r)^2``;
* OUTSIDE: the counter-clockwise arc about (15, 0) ends at C, the counter-clockwise arc
  about (10, -5) starts there (both turn against the corner): outside both,
  ``(5 + mu)^2 + mu^2 = (5 + r)^2``.

The replaced arc length is ``5 atan(mu / (5 -+ mu))`` on each arc, the fillet turns by
``pi/2 +- 2 atan(...)`` and its point nearest C is ``sqrt(2) mu - r`` from it.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from scipy.optimize import brentq, root

from reference.core.constraints import BOUND_SETS, check_profile
from reference.core.geometry import KIND_CODES
from reference.core.rounding import (circle_circle_fillet, circle_fillet_largest_radius,
                                     circle_fillet_radius_for_deviation,
                                     circle_fillet_radius_for_trim,
                                     circle_fillet_radius_within)
from reference.machine import load_machine, machine_from_dict
from reference.nc import parse_text
from reference.planner import plan
from reference.prepare import build_path
from rounding_machines import rounding_machine
from test_rounding_arcs import machine, reasons

ROUNDING = KIND_CODES.index("rounding")
C = np.array([10.0, 0.0])
INSIDE = "G1 X0 Y0\nG2 X10 Y0 I5 J0{w}\nG2 X5 Y5 I0 J5\n"
OUTSIDE = "G1 X15 Y5\nG3 X10 Y0 I0 J-5{w}\nG3 X5 Y-5 I0 J-5\n"
CENTRES = {"inside": ((5.0, 0.0), (10.0, 5.0)), "outside": ((15.0, 0.0), (10.0, -5.0))}


def hand(case: str, r: float) -> dict:
    """The fillet of radius r at the hand corner (module docstring)."""
    iota = 1.0 if case == "inside" else -1.0
    # 2 mu^2 - 2 iota 5 mu + 25 - (5 - iota r)^2 = 0, the small root
    b, c0 = -2.0 * iota * 5.0, 25.0 - (5.0 - iota * r) ** 2
    mu = (-b - math.copysign(math.sqrt(b * b - 8.0 * c0), b)) / 4.0
    mu = c0 / (2.0 * mu) if mu else 0.0
    a = math.atan(mu / (5.0 - iota * mu))
    O = C + mu * np.array([-1.0, 1.0])
    c1, c2 = (np.array(c) for c in CENTRES[case])
    start = c1 + 5.0 * (O - c1) / np.linalg.norm(O - c1)
    end = c2 + 5.0 * (O - c2) / np.linalg.norm(O - c2)
    return {"O": O, "trim": 5.0 * a, "sweep": math.pi / 2 + 2.0 * iota * a,
            "deviation": math.sqrt(2.0) * mu - r, "start": start, "end": end}


def independent(r: float, c1, R1: float, s1: float, c2, R2: float, s2: float) -> dict:
    """The fillet of radius r by scipy root finding (no code of the stage): the angles
    ``phi_j`` of its tangent points on the circles, where the centres ``c_j + (R_j - iota_j
    r) (cos phi_j, sin phi_j)`` coincide, started from the fillet of the two tangents at
    the corner (the origin); ``iota_j`` +1 where the corner turns the way circle j
    does."""
    c1, c2 = np.asarray(c1, float), np.asarray(c2, float)
    u1, u2 = -c1 / R1, -c2 / R2
    t1 = s1 * np.array([-u1[1], u1[0]])
    t2 = s2 * np.array([-u2[1], u2[0]])
    s = math.copysign(1.0, t1[0] * t2[1] - t1[1] * t2[0])
    i1, i2 = (1.0 if s == s1 else -1.0), (1.0 if s == s2 else -1.0)
    p1, p2 = math.atan2(u1[1], u1[0]), math.atan2(u2[1], u2[0])

    def gap(x):
        o1 = c1 + (R1 - i1 * r) * np.array([math.cos(x[0]), math.sin(x[0])])
        o2 = c2 + (R2 - i2 * r) * np.array([math.cos(x[1]), math.sin(x[1])])
        return o1 - o2

    # started from the line-line fillet of the tangents (centre r / cos(theta/2) along
    # the bisector of the turn)
    n = t2 - t1
    o0 = r * n / np.linalg.norm(n) / math.sqrt(max((1.0 + t1 @ t2) / 2.0, 1e-12))
    start = [math.atan2(*(o0 - c)[::-1]) for c in (c1, c2)]
    sol = root(gap, start, tol=1e-14)
    assert np.abs(gap(sol.x)).max() <= 1e-12 * max(R1, R2)
    f1, f2 = sol.x
    O = c1 + (R1 - i1 * r) * np.array([math.cos(f1), math.sin(f1)])
    wrap = lambda x: (x + math.pi) % (2 * math.pi) - math.pi    # noqa: E731
    return {"O": O, "trim_in": R1 * s1 * wrap(p1 - f1), "trim_out": R2 * s2 * wrap(f2 - p2),
            "start": c1 + R1 * np.array([math.cos(f1), math.sin(f1)]),
            "end": c2 + R2 * np.array([math.cos(f2), math.sin(f2)])}


def fillet_segment(path) -> int:
    k = np.flatnonzero(path.kind == ROUNDING)
    assert k.size == 1
    return int(k[0])


def samples(path, seg: int, n: int = 20001) -> np.ndarray:
    s = np.linspace(path.s_breaks[seg], path.s_breaks[seg + 1], n)
    return path.evaluate(s, segment=np.full(n, seg))[0][:, :2]


def assert_tangent_everywhere(path) -> None:
    """Each inserted fillet meets its neighbours in position and tangent (G1)."""
    k = np.flatnonzero(path.kind == ROUNDING)
    brk = np.unique(np.concatenate((k, k + 1)))
    brk = brk[(brk > 0) & (brk < path.n_segments)]
    sb = path.s_breaks[brk]
    qa, ta = path.evaluate(sb, segment=brk - 1)[:2]
    qb, tb = path.evaluate(sb, segment=brk)[:2]
    np.testing.assert_allclose(qa, qb, atol=1e-9)
    np.testing.assert_allclose(ta, tb, atol=1e-9)


@pytest.mark.parametrize("case", ["inside", "outside"])
def test_rnd_between_two_arcs_is_the_tangent_arc_by_hand(case):
    """RND=1 at the hand corners: radius, replaced lengths, ends, turn and deviation by
    hand; the shortened arcs stay on their circles; everything meets tangentially."""
    body = (INSIDE if case == "inside" else OUTSIDE).format(w=" RND=1")
    path = build_path(parse_text("G17 G90 G64 BRISK F600\n" + body), machine())
    t = path.rounding
    assert reasons(path)[-1] == "rounded"
    h = hand(case, 1.0)
    k = fillet_segment(path)
    assert t.radius_mm[-1] == 1.0
    assert t.distance_mm[-1] == pytest.approx(h["trim"], rel=1e-12)
    assert t.length_mm[-1] == pytest.approx(h["sweep"], rel=1e-12)
    assert t.deviation_mm[-1] == pytest.approx(h["deviation"], rel=1e-12)
    q = samples(path, k)
    np.testing.assert_allclose(q[0], h["start"], atol=1e-12)
    np.testing.assert_allclose(q[-1], h["end"], atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(q - h["O"], axis=1), 1.0, atol=1e-12)
    # the fillet's point nearest C is the recorded deviation away
    assert np.linalg.norm(q - C, axis=1).min() == pytest.approx(h["deviation"], rel=1e-7)
    # both arcs lose the same arc length and stay on their circles
    quarter = 2.5 * math.pi
    for seg, centre, full in ((k - 1, CENTRES[case][0], 2 * quarter if case == "inside"
                               else quarter), (k + 1, CENTRES[case][1], quarter)):
        assert path.length[seg] == pytest.approx(full - h["trim"], rel=1e-12)
        qs = samples(path, seg, 50)
        np.testing.assert_allclose(np.linalg.norm(qs - centre, axis=1), 5.0, atol=1e-12)
    assert_tangent_everywhere(path)


def test_g641_keeps_both_ends_within_adis_along_the_arcs():
    """spec 5.3 on an asymmetric corner (radii 5 and 12, both clockwise, a right turn of
    90 degrees at C): the larger of the two replaced arc lengths is ADIS, by the
    independent construction."""
    text = ("G17 G90 G641 ADIS=0.4 BRISK F600\nG1 X0 Y0\nG2 X10 Y0 I5 J0\n"
            "G2 X-2 Y12 I0 J12\n")
    path = build_path(parse_text(text), machine())
    assert reasons(path)[-1] == "rounded"
    r = float(path.rounding.radius_mm[-1])
    ind = independent(r, (-5.0, 0.0), 5.0, -1.0, (0.0, 12.0), 12.0, -1.0)
    assert max(ind["trim_in"], ind["trim_out"]) == pytest.approx(0.4, rel=1e-9)
    assert max(ind["trim_in"], ind["trim_out"]) <= 0.4 * (1 + 1e-12)
    k = fillet_segment(path)
    q = samples(path, k, 3)
    np.testing.assert_allclose(q[0], C + ind["start"], atol=1e-10)
    np.testing.assert_allclose(q[-1], C + ind["end"], atol=1e-10)
    assert path.length[k - 1] == pytest.approx(5.0 * math.pi - ind["trim_in"], rel=1e-12)
    assert path.length[k + 1] == pytest.approx(6.0 * math.pi - ind["trim_out"], rel=1e-12)
    assert_tangent_everywhere(path)


@pytest.mark.parametrize("mode", ["G642", "G643", "G645"])
def test_tolerance_modes_keep_every_axis_within_compress_pos_tol(mode):
    """spec 5.4 on an S-shaped corner (the clockwise arc about (5, 0) into the
    counter-clockwise arc about (10, -8): the fillet lies inside the first circle and
    outside the second): per axis |C_i - M_i| <= MD33100 (0.01 mm), the limiting axis
    using it; M the fillet's point nearest C, on its radius towards C, the fillet by
    the independent construction at the recorded radius (and the inserted segment's
    dense samples come no nearer C than the recorded deviation)."""
    text = (f"G17 G90 {mode} BRISK F600\nG1 X0 Y0\nG2 X10 Y0 I5 J0\n"
            "G3 X2 Y-8 I0 J-8\n")
    path = build_path(parse_text(text), machine())
    assert reasons(path)[-1] == "rounded"
    t = path.rounding
    r = float(t.radius_mm[-1])
    # G643 rounds inside the blocks: the fillet in two halves, one per block (spec 5.5)
    ks = np.flatnonzero(path.kind == ROUNDING)
    assert ks.size == (2 if mode == "G643" else 1)
    q = np.concatenate([samples(path, int(k)) for k in ks])
    ind = independent(r, (-5.0, 0.0), 5.0, -1.0, (0.0, -8.0), 8.0, 1.0)
    # M on the fillet's radius towards C
    O = C + ind["O"]
    M = O + r * (C - O) / np.linalg.norm(C - O)
    assert np.abs(C - M).max() == pytest.approx(0.01, rel=1e-9)
    assert np.abs(C - M).max() <= 0.01 * (1 + 1e-10)   # the construction's round-off
    assert np.linalg.norm(q - C, axis=1).min() == pytest.approx(t.deviation_mm[-1],
                                                                  rel=1e-7)
    assert np.linalg.norm(C - M) == pytest.approx(t.deviation_mm[-1], rel=1e-9)
    np.testing.assert_allclose(np.linalg.norm(q - (C + ind["O"]), axis=1), r, atol=1e-12)
    np.testing.assert_allclose(q[0], C + ind["start"], atol=1e-10)
    np.testing.assert_allclose(q[-1], C + ind["end"], atol=1e-10)
    assert_tangent_everywhere(path)


@pytest.mark.parametrize("case", ["inside", "outside"])
@pytest.mark.parametrize("ctol", [0.01, 0.05])
def test_the_contour_tolerance_radius_is_the_hand_root(case, ctol):
    """spec 5.7: CTOL is the contour tolerance of G642/G645 (COMPRESS_POS_TOL 1 mm per
    axis here, so the contour decides). The fillet kept is the largest within it: its
    hand deviation ``sqrt(2) mu - r`` (module docstring) lies within 3e-11 below CTOL
    (the radius half ROOT_XATOL inside the root in log r, accepted down to two), the
    hand radius of deviation CTOL (by root finding on the hand formula, no code of the
    stage) is its radius to 1e-10, the clamp does not decide, and the inserted segment
    comes no nearer the corner than that deviation."""
    text = f"G17 G90 G642 CTOL={ctol} BRISK F600\n" + (INSIDE if case == "inside"
                                                        else OUTSIDE).format(w="")
    path = build_path(parse_text(text), rounding_machine(tol=1.0))
    assert reasons(path)[-1] == "rounded"
    t = path.rounding
    r = float(t.radius_mm[-1])
    assert not bool(t.clamped[-1])
    dev = hand(case, r)["deviation"]
    assert ctol * (1.0 - 3e-11) <= dev <= ctol
    r_hand = brentq(lambda x: hand(case, x)["deviation"] - ctol, 1e-6, 1.0, xtol=1e-15,
                    rtol=1e-15)
    assert r == pytest.approx(r_hand, rel=1e-10)
    # the corner's fillet is the last rounding (the first corner, into the first
    # arc, is rounded too)
    q = samples(path, int(np.flatnonzero(path.kind == ROUNDING)[-1]))
    assert np.linalg.norm(q - C, axis=1).min() >= dev * (1.0 - 1e-9)


def test_the_block_length_clamp_limits_rnd_between_arcs():
    """spec 5.3 and the G644 excerpt: at most half of each participating block. RND=2
    at the INSIDE corner whose second arc is shortened to 1 mm (about (10, 5) from (10,
    0) by 0.2 rad): the fillet replaces 2.55 mm of each arc, so its radius is cut until
    0.5 mm of the short arc is replaced."""
    end = (10.0 - 5.0 * math.sin(0.2), 5.0 - 5.0 * math.cos(0.2))
    text = ("G17 G90 G64 BRISK F600\nG1 X0 Y0\nG2 X10 Y0 I5 J0 RND=2\n"
            f"G2 X{end[0]:.12f} Y{end[1]:.12f} I0 J5\n")
    path = build_path(parse_text(text), machine())
    t = path.rounding
    assert reasons(path)[-1] == "rounded" and bool(t.clamped[-1])
    r = float(t.radius_mm[-1])
    assert r < 2.0
    ind = independent(r, (-5.0, 0.0), 5.0, -1.0, (0.0, 5.0), 5.0, -1.0)
    assert ind["trim_out"] == pytest.approx(0.5, rel=1e-9)
    assert ind["trim_in"] < 0.5 * 5.0 * math.pi


def test_model_limits_between_arcs_are_named():
    """Arcs in different planes: named, no rounding inserted (spec 5.2 asks every case
    without a rounding block to be named)."""
    text = ("G90 G641 ADIS=0.5 BRISK F3000\nG1 X0 Y0\nG17 G2 X10 Y0 I5 J0\n"
            "G18 G2 X15 Z5 I0 K5\n")
    path = build_path(parse_text(text), machine())
    assert reasons(path)[-1] == ("corner next to a helix or spiral, or out of the arc's "
                                 "plane: rounding not modelled yet")
    assert not np.any(path.kind == ROUNDING)


def _seeded_pairs(k: int, seed: int):
    """k seeded circle pairs through the origin (radii 0.5..50 mm, either sense), the
    corners' deflections up to 178 degrees."""
    rng = np.random.default_rng(seed)
    R1, R2 = rng.uniform(0.5, 50.0, k), rng.uniform(0.5, 50.0, k)
    b1, b2 = rng.uniform(0, 2 * np.pi, k), rng.uniform(0, 2 * np.pi, k)
    c1 = -R1[:, None] * np.column_stack((np.cos(b1), np.sin(b1)))
    c2 = -R2[:, None] * np.column_stack((np.cos(b2), np.sin(b2)))
    s1, s2 = rng.choice((-1.0, 1.0), k), rng.choice((-1.0, 1.0), k)
    u1, u2 = -c1 / R1[:, None], -c2 / R2[:, None]
    t1 = s1[:, None] * np.column_stack((-u1[:, 1], u1[:, 0]))
    t2 = s2[:, None] * np.column_stack((-u2[:, 1], u2[:, 0]))
    theta = np.arccos(np.clip(np.einsum("ij,ij->i", t1, t2), -1.0, 1.0))
    keep = theta < np.radians(178.0)
    r = rng.uniform(0.001, 0.3, k) * np.minimum(R1, R2)
    return [x[keep] for x in (r, c1, R1, s1, c2, R2, s2, t1, t2)]


def test_circle_circle_fillet_on_seeded_corners_against_root_finding():
    """2000 seeded corners: where the fillet is valid it is r from its centre at both
    ends, its centre R_j -+ r from each circle's, its ends on the circles, its tangents
    there those of the arcs in the direction of travel, it turns to the corner's inner
    side, and its ends and replaced lengths agree with scipy root finding on the
    centre distances; the closed-form radii invert the replaced lengths."""
    r, c1, R1, s1, c2, R2, s2, t1, t2 = _seeded_pairs(2000, 7)
    f = circle_circle_fillet(r, c1, R1, s1, c2, R2, s2)
    v = np.flatnonzero(f.valid)
    assert v.size > 1000
    O = f.centre[v]
    for c, R_ in ((c1, R1), (c2, R2)):
        d = np.linalg.norm(O - c[v], axis=1)
        assert np.all(np.minimum(np.abs(d - (R_[v] - r[v])), np.abs(d - (R_[v] + r[v])))
                      <= 1e-12 * R_[v])
    for p, c, R_ in ((f.start, c1, R1), (f.end, c2, R2)):
        np.testing.assert_allclose(np.linalg.norm(p[v] - O, axis=1), r[v], rtol=1e-12)
        np.testing.assert_allclose(np.linalg.norm(p[v] - c[v], axis=1), R_[v], rtol=1e-12)
    # tangents: the arc's direction of travel at each end equals the fillet's
    head_start = s1[v, None] * np.column_stack((c1[v, 1] - f.start[v, 1],
                                                f.start[v, 0] - c1[v, 0])) / R1[v, None]
    np.testing.assert_allclose(f.heading[v], head_start, atol=1e-12)
    # it turns the way the corner does (its centre on that side of its own tangent),
    # and replaces a piece of each arc before and after the corner
    turn = np.sign(t1[v, 0] * t2[v, 1] - t1[v, 1] * t2[v, 0])
    h, rel = f.heading[v], O - f.start[v]
    assert np.all(turn * (h[:, 0] * rel[:, 1] - h[:, 1] * rel[:, 0]) > 0)
    assert np.all(f.trim_in[v] > 0) and np.all(f.trim_out[v] > 0)
    # the independent construction on a subset (deflections up to 150 degrees: nearer
    # a cusp the start from the tangents' fillet lies too far out for the root finder,
    # which may then find the fillet on the outer side)
    theta = np.arccos(np.clip(np.einsum("ij,ij->i", t1, t2), -1.0, 1.0))
    for i in v[theta[v] < np.radians(150.0)][:300]:
        ind = independent(r[i], c1[i], R1[i], s1[i], c2[i], R2[i], s2[i])
        np.testing.assert_allclose(f.centre[i], ind["O"], atol=1e-10 * R1[i])
        assert f.trim_in[i] == pytest.approx(ind["trim_in"], rel=1e-9, abs=1e-12)
        assert f.trim_out[i] == pytest.approx(ind["trim_out"], rel=1e-9, abs=1e-12)
    # closed forms: the radius that replaces a given length, either side
    np.testing.assert_allclose(circle_fillet_radius_for_trim(
        f.trim_in[v], c1[v], R1[v], s1[v], c2[v], R2[v], s2[v]), r[v], rtol=1e-11)
    np.testing.assert_allclose(circle_fillet_radius_for_trim(
        f.trim_out[v], c2[v], R2[v], -s2[v], c1[v], R1[v], -s1[v]), r[v], rtol=1e-11)


def test_largest_fillet_and_the_radius_within_a_length():
    """The largest fillet (INSIDE corner: the largest circle in the lens between the two
    discs, centred on the midpoint (7.5, 2.5) of C and the circles' second crossing
    (5, 5), radius 5 - |(7.5, 2.5) - (5, 0)| = 5 - 2.5 sqrt(2)) and the radius within a
    replaced length: the closed form below the length the largest fillet replaces
    (5 pi/4 by symmetry), the largest radius above it (where the closed form alone
    falls back towards 0 at the second crossing)."""
    c1, c2 = np.array([[-5.0, 0.0]]), np.array([[0.0, 5.0]])
    R, s = np.array([5.0]), np.array([-1.0])
    top = circle_fillet_largest_radius(c1, R, s, c2, R, s)
    assert top[0] == pytest.approx(5.0 - 2.5 * math.sqrt(2.0), rel=1e-12)
    assert circle_circle_fillet(top * (1 - 1e-9), c1, R, s, c2, R, s).valid[0]
    assert not circle_circle_fillet(top * (1 + 1e-9), c1, R, s, c2, R, s).valid[0]
    for trim in (1.0, 3.0):
        r = circle_fillet_radius_within(np.array([trim]), c1, R, s, c2, R, s)
        assert r[0] == pytest.approx(circle_fillet_radius_for_trim(
            np.array([trim]), c1, R, s, c2, R, s)[0], rel=1e-15)
        assert circle_circle_fillet(r, c1, R, s, c2, R, s).trim_in[0] == pytest.approx(
            trim, rel=1e-11)
    far = np.array([7.0])                            # beyond 5 pi / 4 = 3.93
    r_far = circle_fillet_radius_for_trim(far, c1, R, s, c2, R, s)
    assert r_far[0] < top[0]
    assert circle_circle_fillet(r_far, c1, R, s, c2, R, s).trim_in[0] < 3.93
    assert circle_fillet_radius_within(far, c1, R, s, c2, R, s)[0] == top[0]
    # both circles curving away (the OUTSIDE corner): fillets of every radius
    assert np.isinf(circle_fillet_largest_radius(np.array([[5.0, 0.0]]), R, -s,
                                                 np.array([[0.0, -5.0]]), R, -s)[0])


#: A contour of arcs only (every corner between two arcs, either turn, both senses),
#: with its lines only at the start.
ARCS = ("G1 X0 Y0\nG2 X10 Y0 I5 J0\nG2 X-2 Y12 I0 J12\nG3 X-10 Y4 I0 J-8\n"
        "G2 X-16 Y10 I0 J6\nG3 X-11 Y15 I0 J5\nM30\n")


@pytest.mark.parametrize("mfile", ["default", "linuxcnc_xyz"])
@pytest.mark.parametrize("mode", ["G641 ADIS=0.5", "G642 CTOL=0.05", "G645 CTOL=0.05",
                                  "G64 RNDM=0.8"])
@pytest.mark.parametrize("accel", ["BRISK", "SOFT"])
def test_arc_arc_corners_keep_the_limits_and_do_not_slow_the_program(mfile, mode, accel):
    """On both bundled machines: fillets are inserted between the arcs, the heuristic
    keeps every limit of its bound set on the rounded path, and (every mode but RNDM) a
    rounding is only inserted where it does not slow the program (5.2 group 2)."""
    mach = load_machine(mfile)
    times = {}
    for m in ("G64", mode):
        prog = parse_text(f"G17 G90 {m} {accel} F3000\n" + ARCS)
        path = build_path(prog, mach)
        res = plan(prog, mach, path=path)
        assert check_profile(path, mach.limits, res.profile).ok(BOUND_SETS[res.bound_set])
        times[m] = res.time_s
        if m != "G64":
            t = path.rounding
            assert t.n == 4 and "corner between" not in " ".join(
                t.reason_text(i) for i in range(t.n))
            if "RNDM" in m:
                assert t.inserted.all()
            assert_tangent_everywhere(path)
    if "RNDM" not in mode:
        assert times[mode] <= times["G64"] * (1 + 1e-9)


# G644 with the dynamic digits at arc corners: the test machine at F3000 (v = 50 mm/s,
# MAX_AX_ACCEL 2 m/s^2, MAX_AX_JERK 40 m/s^3, an XY plane: both axes weigh 1)
V_F3000, A_TEST, J_TEST = 50.0, 2000.0, 40000.0


@pytest.mark.parametrize("accel", ["BRISK", "SOFT"])
def test_g644_3xxx_at_arc_corners_is_the_smallest_fillet_passed_at_the_path_velocity(
        accel):
    """B1 excerpt (G644, 3xxx): "Any axis that has a velocity jump at a corner traverses
    around the corner with the maximum possible dynamic response ... neither the maximum
    deviations nor the rounding distance are checked. The resulting deviations or
    rounding distances are determined exclusively by the dynamic limits of the
    respective axis and the current path velocity." By hand, with the shares the
    heuristic grants a curved segment (0.75 A centripetal, 0.5 J jerk): the fillet's
    radius is v^2 / (0.75 A) = 1.667 mm under BRISK, under SOFT (the fillet stays an
    arc) also at least sqrt(v^3 / (0.5 J)) = 2.5 mm, at the OUTSIDE corner between two
    arcs and at a line-arc corner (test_rounding_arcs: the line y = 0 into the
    clockwise arc about (25, 0)); both fillets are longer than v T_ipo = 0.2 mm, so the
    IPO cycle does not decide. The tolerance (MD33100 0.01 mm) is not checked. Under
    SOFT the fillet's curvature jumps at its ends (6.3) are allowed the largest
    PATH_TRANS_JERK_LIM, so that they do not decide the speed (with the axis jerk there
    they would allow 17 mm/s, and stopping at the corner is estimated the faster)."""
    from rounding_machines import BASE
    from test_rounding_arcs import LINE_ARC
    from test_rounding_arcs import hand as line_hand
    r = V_F3000 ** 2 / (0.75 * A_TEST)
    spec = copy.deepcopy(BASE)
    spec["channel"].update(SMOOTHING_MODE=3000)
    if accel == "SOFT":
        r = max(r, math.sqrt(V_F3000 ** 3 / (0.5 * J_TEST)))
        assert r == pytest.approx(2.5, rel=1e-12)              # the jerk decides
        for ax in spec["axis"].values():
            ax["PATH_TRANS_JERK_LIM"] = 1e5
    mach = machine_from_dict(spec)
    for body, dev in ((OUTSIDE.format(w=""), hand("outside", r)["deviation"]),
                      (LINE_ARC, line_hand(r)["deviation"])):
        path = build_path(parse_text(f"G17 G90 G644 {accel} F3000\n" + body), mach)
        t = path.rounding
        assert reasons(path)[-1] == "rounded"
        assert t.radius_mm[-1] == pytest.approx(r, rel=1e-12)
        assert t.deviation_mm[-1] == pytest.approx(dev, rel=1e-9)
        assert t.deviation_mm[-1] > 0.01 * math.sqrt(2)          # not checked
        assert t.length_mm[-1] > V_F3000 * 0.004
        # passed at the programmed speed
        assert t.v_round[-1] == pytest.approx(V_F3000, rel=1e-12)
        assert_tangent_everywhere(path)


def test_g644_2xxx_at_an_arc_corner_lasts_one_period_of_the_lowest_frequency():
    """B1 excerpt (G644, 2xxx): "the rounding distance is limited to a minimum value,
    which results from the maximum permissible excitation frequency and the current
    path velocity"; spec 5.8 "2xxx: T_i >= 1/f_i". X at 20 Hz, Y at 10 Hz: the fillet at
    the OUTSIDE corner lasts 1/10 s at F1200, 2 mm of path; its radius by root finding
    on the hand formulas (length r (pi/2 - 2 atan(mu / (5 + mu))))."""
    from rounding_machines import BASE
    spec = copy.deepcopy(BASE)
    spec["channel"].update(SMOOTHING_MODE=2000)
    for ax, f in (("X", 20.0), ("Y", 10.0), ("Z", 20.0)):
        spec["axis"][ax]["LOOKAH_FREQUENCY"] = f
    mach = machine_from_dict(spec)
    path = build_path(parse_text("G17 G90 G644 BRISK F1200\n" + OUTSIDE.format(w="")), mach)
    t = path.rounding
    assert reasons(path)[-1] == "rounded"
    assert t.length_mm[-1] == pytest.approx(20.0 / 10.0, rel=1e-9)
    r = brentq(lambda x: x * hand("outside", x)["sweep"] - 2.0, 0.1, 5.0, xtol=1e-14)
    assert t.radius_mm[-1] == pytest.approx(r, rel=1e-9)


@pytest.mark.parametrize("case", ["inside", "outside"])
def test_closed_form_radius_of_a_contour_deviation_by_hand(case):
    """The tolerance search starts from the radius whose fillet deviates from the corner
    by a given contour deviation ``e`` (closed form, core.rounding): at the hand corners
    the radius where ``sqrt(2) mu - r = e`` (module docstring) by scipy's brentq."""
    (x1, y1), (x2, y2) = CENTRES[case]
    c1 = np.array([[x1 - C[0], y1 - C[1]]])
    c2 = np.array([[x2 - C[0], y2 - C[1]]])
    s = -1.0 if case == "inside" else 1.0
    one = np.ones(1)
    for e in (1e-4, 0.02, 0.1):
        r = circle_fillet_radius_for_deviation(np.array([e]), c1, 5.0 * one, s * one, c2,
                                               5.0 * one, s * one)
        expect = brentq(lambda x: hand(case, x)["deviation"] - e, 1e-9, 1.0, xtol=1e-15)
        assert r[0] == pytest.approx(expect, rel=1e-10)


def test_closed_form_radius_of_a_contour_deviation_between_a_line_and_a_circle():
    """The same closed form between a line and a circle on seeded corners (radii 1..20
    mm, turns of 5..120 degrees, deviations 0.001..0.1 mm), against the forward
    construction: in nine corners of ten it is the smallest radius of that deviation
    (brentq on the forward construction); elsewhere the squared equation's root belongs
    to the mirrored branch, a start that the tolerance search corrects."""
    from reference.core.rounding import fillet_deviation, fillet_radius_for_deviation
    rng = np.random.default_rng(3)
    checked = same = 0
    for _ in range(200):
        R, sense = rng.uniform(1.0, 20.0), rng.choice((-1.0, 1.0))
        ang = rng.uniform(0.0, 2.0 * math.pi)
        u0 = np.array([math.cos(ang), math.sin(ang)])
        centre = -R * u0
        tc = sense * np.array([-u0[1], u0[0]])
        th = np.radians(rng.uniform(5.0, 120.0)) * rng.choice((-1.0, 1.0))
        t = np.array([math.cos(th) * tc[0] - math.sin(th) * tc[1],
                      math.sin(th) * tc[0] + math.cos(th) * tc[1]])
        e = rng.uniform(0.001, 0.1)
        cols = (t[None], centre[None], np.array([R]), np.array([sense]))

        def dev(r):
            d, ok = fillet_deviation(np.array([r]), *cols)
            return float(np.linalg.norm(d[0])) - e if ok[0] else math.inf

        # the smallest radius of that deviation (the branch that shrinks to the corner)
        grid = np.geomspace(1e-9, 0.999 * R, 400)
        above = [g for g in grid if dev(g) > 0]
        if not above:                            # no fillet of that deviation below R
            continue
        hi = above[0]
        expect = brentq(dev, grid[max(np.searchsorted(grid, hi) - 1, 0)], hi, xtol=1e-15)
        got = fillet_radius_for_deviation(np.array([e]), *cols)[0]
        checked += 1
        same += got == pytest.approx(expect, rel=1e-9)
    assert checked > 100 and same >= 0.9 * checked


@pytest.mark.parametrize("digit", [0, 4])
def test_g644_0xxx_at_a_line_arc_corner_rounds_as_3xxx_within_the_tolerance(digit):
    """spec 5.6: "0xxx: Keep each axis within MD33100 COMPRESS_POS_TOL; if the dynamics
    allow, the tolerance is not fully used"; "4xxx: Like 0xxx, but the tolerance is
    fully used where possible". At the line-arc corner of test_rounding_arcs (the line
    y = 0 into the clockwise arc of radius 5 about (25, 0)), BRISK, F3000, MD33100 =
    1 mm per axis: the 3xxx fillet has r = v^2 / (0.75 A) = 1.667 mm (by hand, as in the
    3xxx test above) and its hand deviation stays within 1 mm on both axes, so 0xxx
    takes that fillet; 4xxx the larger one whose deviation reaches 1 mm on an axis."""
    from rounding_machines import BASE
    from test_rounding_arcs import LINE_ARC
    from test_rounding_arcs import hand as line_hand
    r = V_F3000 ** 2 / (0.75 * A_TEST)
    spec = copy.deepcopy(BASE)
    spec["channel"].update(SMOOTHING_MODE=1000 * digit)
    for ax in spec["axis"].values():
        ax["COMPRESS_POS_TOL"] = 1.0
    dev = line_hand(r)["deviation"]
    assert dev < 1.0                                  # so every axis is within 1 mm
    path = build_path(parse_text("G17 G90 G644 BRISK F3000\n" + LINE_ARC),
                      machine_from_dict(spec))
    t = path.rounding
    assert reasons(path)[-1] == "rounded"
    if digit == 0:
        assert t.radius_mm[-1] == pytest.approx(r, rel=1e-12)
        assert t.deviation_mm[-1] == pytest.approx(dev, rel=1e-9)
    else:
        assert t.radius_mm[-1] > r * 1.1 and t.deviation_mm[-1] > dev
