"""Spiral arcs (radius mismatch within tolerance): they end at the programmed point, with
exact derivatives and arc length (seeded, in G17/G18/G19, against finite differences,
scipy quadrature and hand geometry)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from reference.core.geometry import (arc_segment, path_from_pieces, plane_amplitudes,
                                     spiral_angle, spiral_plane_length)

AX = ("X", "Y", "Z", "A", "B")
GEO = np.array([True, True, True, False, False])
PLANES = {"G17": (0, 1), "G18": (2, 0), "G19": (1, 2)}


def random_spiral(rng, plane, clockwise, rel_mismatch):
    """An arc from radius r0 to r0 (1 + rel_mismatch) with a helix and extra axes."""
    u, v = PLANES[plane]
    w = 3 - u - v
    c = rng.uniform(-50, 50, 5)
    r0 = rng.uniform(0.5, 200)
    r1 = r0 * (1 + rel_mismatch)
    a0, a1 = rng.uniform(-np.pi, np.pi, 2)
    start, end = c.copy(), c.copy()
    start[u] += r0 * np.cos(a0)
    start[v] += r0 * np.sin(a0)
    end[u] += r1 * np.cos(a1)
    end[v] += r1 * np.sin(a1)
    end[w] = start[w] + rng.uniform(-20, 20)
    end[3:] = start[3:] + rng.uniform(-90, 90, 2)
    sweep = (a0 - a1) % (2 * np.pi) if clockwise else (a1 - a0) % (2 * np.pi)
    return start, end, c, (u, v), r0, r1, sweep


def build(start, end, c, plane, clockwise, tol=np.inf):
    """One arc; the geometry accepts any mismatch below ``tol`` (the NC layer checks it)."""
    return path_from_pieces(AX, [arc_segment(start, end, c, plane, clockwise, 0, GEO, 0, tol)])


def fd_errors(seg, s, h):
    """Largest |central difference - exact| of q', q'', q''' over ``s``, per order."""
    out = []
    for k in range(3):
        fd = (seg.evaluate(s + h)[k] - seg.evaluate(s - h)[k]) / (2 * h)
        out.append(np.abs(fd - seg.evaluate(s)[k + 1]).max())
    return out


@pytest.mark.parametrize("plane", ["G17", "G18", "G19"])
@pytest.mark.parametrize("clockwise", [False, True])
def test_spiral_ends_at_the_programmed_point_with_exact_derivatives(plane, clockwise):
    rng = np.random.default_rng(100 + list(PLANES).index(plane) * 2 + clockwise)
    for rel in (1e-3, -1e-3, 2e-6, -3e-5, 0.2, -0.15):     # 0.2: a short, strong spiral
        start, end, c, pl, r0, r1, sweep = random_spiral(rng, plane, clockwise, rel)
        p = build(start, end, c, pl, clockwise)
        seg = p.segment(0)
        assert seg.dradius == pytest.approx((r1 - r0) / sweep, rel=1e-9)
        np.testing.assert_allclose(seg.start, start, rtol=0, atol=1e-9)
        np.testing.assert_allclose(seg.end, end, rtol=0, atol=1e-9)
        L = seg.length
        s = rng.uniform(0.05 * L, 0.95 * L, 25)
        h = 1e-4 * max(L, 1.0) ** 0.5
        amp = plane_amplitudes(p)
        scale = (1.0, float(amp.curvature[0]), float(np.hypot(amp.jerk_t, amp.jerk_n)[0]))
        for k, err in enumerate(fd_errors(seg, s, h)):
            assert err <= 1e-6 * scale[k] + 1e-9, (rel, k, err, scale[k])
        # the arc length is that of the geometry axes: |q'_geo| = 1
        ss = np.linspace(0, L, 101)
        np.testing.assert_allclose(np.linalg.norm(seg.evaluate(ss)[1][:, :3], axis=1), 1.0,
                                   rtol=1e-12)


@pytest.mark.parametrize("plane", ["G17", "G18", "G19"])
def test_spiral_length_against_quadrature_and_radius_linear_in_angle(plane):
    rng = np.random.default_rng(7 + list(PLANES).index(plane))
    u, v = PLANES[plane]
    w = 3 - u - v
    for rel in (1e-3, -1e-3, 1e-7, 0.2, -0.15):
        cw = bool(rng.integers(0, 2))
        start, end, c, pl, r0, r1, sweep = random_spiral(rng, plane, cw, rel)
        seg = build(start, end, c, pl, cw).segment(0)
        # independent reference: the plane curve r = r0 + k t by quadrature; the helix
        # axis moves linearly along the path, so the length is the hypotenuse
        k = (r1 - r0) / sweep
        sigma, err = quad(lambda t: np.hypot(r0 + k * t, k), 0.0, sweep, epsabs=0.0,
                          epsrel=2e-14, limit=200)
        assert err <= 1e-12 * sigma
        ref = np.hypot(sigma, end[w] - start[w])
        assert seg.length == pytest.approx(ref, rel=1e-13, abs=0.0)
        # radius linear in the swept angle (hand geometry from the evaluated points)
        ss = np.linspace(0, seg.length, 201)
        q = seg.evaluate(ss)[0]
        du, dv = q[:, u] - c[u], q[:, v] - c[v]
        ang = np.unwrap(np.arctan2(dv, du))
        swept = np.abs(ang - ang[0])
        np.testing.assert_allclose(np.hypot(du, dv), r0 + (r1 - r0) * swept / sweep,
                                   rtol=0, atol=1e-9)
        # helix axis and extra axes move linearly with the path length
        frac = ss / seg.length
        for j in (w, 3, 4):
            np.testing.assert_allclose(q[:, j], start[j] + frac * (end[j] - start[j]),
                                       rtol=0, atol=1e-9)


def test_closed_form_length_and_inverse():
    rng = np.random.default_rng(3)
    r0 = rng.uniform(0.1, 1000, 200)
    t_end = rng.uniform(1e-3, 20, 200)
    k = rng.uniform(-0.9, 0.9, 200) * r0 / t_end          # the radius stays positive
    for i in range(0, 200, 20):
        ref, _ = quad(lambda t: np.hypot(r0[i] + k[i] * t, k[i]), 0, t_end[i],
                      epsabs=0.0, epsrel=2e-14, limit=400)
        got = spiral_plane_length(r0[i:i + 1], k[i:i + 1], t_end[i:i + 1])[0]
        assert got == pytest.approx(ref, rel=1e-13, abs=0.0)
    # k -> 0 is the circle, without cancellation
    assert spiral_plane_length(np.array([7.0]), np.array([1e-300]), np.array([2.0]))[0] \
        == pytest.approx(14.0, rel=1e-15)
    t = rng.uniform(0, 1, 200) * t_end
    sig = spiral_plane_length(r0, k, t)
    back = spiral_angle(r0, k, sig, t_end)
    np.testing.assert_allclose(back, t, rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize("plane", ["G17", "G18", "G19"])
def test_plane_amplitudes_bound_the_spiral(plane):
    rng = np.random.default_rng(11 + list(PLANES).index(plane))
    for rel in (1e-3, -1e-3, 0.2, -0.15):
        start, end, c, pl, *_ = random_spiral(rng, plane, bool(rng.integers(0, 2)), rel)
        p = build(start, end, c, pl, False)
        amp = plane_amplitudes(p)
        ss = np.linspace(0, p.length[0], 4001)
        _, dq, ddq, dddq = p.evaluate(ss)
        e1, e2 = p.e1[0], p.e2[0]
        plane_of = lambda x: np.c_[x @ e1, x @ e2]      # noqa: E731 (in-plane part)
        pt, pc, pj = plane_of(dq), plane_of(ddq), plane_of(dddq)
        tang = pt / np.linalg.norm(pt, axis=1)[:, None]
        np.testing.assert_allclose(np.linalg.norm(pt, axis=1), amp.speed[0], rtol=1e-12)
        curv = np.linalg.norm(pc, axis=1)
        assert curv.max() <= amp.curvature[0] * (1 + 1e-12)
        assert curv.max() >= amp.curvature[0] * (1 - 1e-9)      # attained at r_min
        jt = np.abs(np.sum(pj * tang, axis=1))
        jn = np.abs(tang[:, 0] * pj[:, 1] - tang[:, 1] * pj[:, 0])
        assert jt.max() <= amp.jerk_t[0] * (1 + 1e-9)
        assert jn.max() <= amp.jerk_n[0] * (1 + 1e-9) + 1e-15
        phi = np.unwrap(np.arctan2(np.sum((p.evaluate(ss)[0] - p.origin[0]) * e2, axis=1),
                                   np.sum((p.evaluate(ss)[0] - p.origin[0]) * e1, axis=1)))
        assert np.abs(np.diff(phi) / np.diff(ss)).max() <= amp.omega_max[0] * (1 + 1e-6)


def test_exact_arc_stays_the_circle():
    start = np.array([10.0, 0, 0, 0, 0])
    end = np.array([0.0, 10.0, 2.0, 0, 0])
    p = build(start, end, np.zeros(5), (0, 1), False)
    assert p.dradius[0] == 0.0
    s = np.linspace(0, p.length[0], 7)
    q = p.evaluate(s)[0]
    phi = p.omega[0] * s
    np.testing.assert_array_equal(q[:, 0], p.origin[0, 0] + 10.0 * np.cos(phi))


def test_spiral_that_ends_on_its_start_ray_is_a_full_turn():
    start = np.array([10.0, 0, 0, 0, 0])
    end = np.array([10.005, 0, 0, 0, 0])             # same angle, radius + 0.005 mm
    seg = build(start, end, np.zeros(5), (0, 1), False, tol=0.01).segment(0)
    assert abs(seg.omega) * seg.length == pytest.approx(2 * np.pi)
    np.testing.assert_allclose(seg.end, end, atol=1e-12)
