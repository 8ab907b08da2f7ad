"""Clothoid (Euler spiral) segments of the path (reference/core/geometry.py), against
independent references: positions by numerical quadrature of the tangent
(scipy.integrate.quad of cos/sin(c sigma^2 / 2)), derivatives by finite differences of
the positions, and the corner-pair shape against hand geometry."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from reference.core.geometry import (KIND_CODES, clothoid_pair_shape, clothoid_pieces,
                                     line_segments, path_from_pieces, plane_amplitudes)

AX = ("X", "Y", "Z")
GEO = np.array([True, True, True])
ROUND = KIND_CODES.index("rounding")


def corner_path(theta: float, half: float, plane=None):
    """Line of 10 mm along t1, a clothoid pair of piece length ``half`` turning by
    ``theta``, a line of 10 mm along t2 (in a tilted plane)."""
    if plane is None:
        u = np.array([1.0, 0.0, 0.0])
        v = np.array([0.0, 1.0, 0.0])
    else:
        u, v = plane
    t1 = u
    t2 = math.cos(theta) * u + math.sin(theta) * v
    p0 = np.array([1.0, -2.0, 3.0])
    ps = p0 + 10.0 * t1
    pair = clothoid_pieces(ps[None], t1[None], t2[None], np.array([half]), np.array([1]),
                           ROUND)
    d_unit, _ = clothoid_pair_shape(np.array([theta]))
    corner = ps + half * d_unit[0] * t1
    pe = corner + half * d_unit[0] * t2
    pieces = [line_segments(p0[None], ps[None], GEO, np.array([0])), pair,
              line_segments(pe[None], (pe + 10.0 * t2)[None], GEO, np.array([2]))]
    return path_from_pieces(AX, pieces), corner, t1, t2


@pytest.mark.parametrize("theta", [0.3, 1.5707963267948966, 2.8])
def test_positions_match_quadrature_of_the_tangent(theta):
    path, _, t1, _ = corner_path(theta, 0.7)
    c = theta / 0.7 ** 2
    seg = path.segment(1)
    for sigma in (0.0, 0.1, 0.35, 0.7):
        x = quad(lambda u: math.cos(c * u * u / 2), 0, sigma, epsabs=1e-14, epsrel=1e-13)[0]
        y = quad(lambda u: math.sin(c * u * u / 2), 0, sigma, epsabs=1e-14, epsrel=1e-13)[0]
        q = seg.evaluate(sigma)[0][0]
        np.testing.assert_allclose(q, seg.origin + x * seg.e1 + y * seg.e2, atol=1e-13)


@pytest.mark.parametrize("theta", [0.3, 1.5707963267948966, 2.8])
def test_the_pair_is_g2_continuous_and_ends_on_the_second_line(theta):
    path, corner, t1, t2 = corner_path(theta, 0.7, plane=(
        np.array([0.6, 0.8, 0.0]), np.array([0.0, 0.0, 1.0])))
    assert path.n_segments == 4
    for k in range(3):
        a = path.evaluate(path.s_breaks[k + 1], side="left")
        b = path.evaluate(path.s_breaks[k + 1], side="right")
        np.testing.assert_allclose(a[0], b[0], atol=1e-12)        # position
        np.testing.assert_allclose(a[1], b[1], atol=1e-12)        # tangent
        np.testing.assert_allclose(a[2], b[2], atol=1e-12)        # curvature vector
    # curvature zero where the pair meets the lines, kappa_max = theta / L_s in the middle
    mid = path.evaluate(path.s_breaks[2])[2][0]
    assert np.linalg.norm(mid) == pytest.approx(theta / 0.7, rel=1e-12)
    # symmetric: the middle point is on the corner's bisector at the deviation
    _, e_unit = clothoid_pair_shape(np.array([theta]))
    m = path.evaluate(path.s_breaks[2])[0][0]
    assert np.linalg.norm(m - corner) == pytest.approx(0.7 * e_unit[0], rel=1e-12)
    np.testing.assert_allclose(np.dot(m - corner, t2 + t1), 0.0, atol=1e-12)


def test_derivatives_match_finite_differences():
    path, _, _, _ = corner_path(1.2, 0.5)
    h = 1e-4
    for k in (1, 2):
        s = np.linspace(path.s_breaks[k] + 2 * h, path.s_breaks[k + 1] - 2 * h, 7)
        seg = np.full(s.size, k)
        q = [path.evaluate(s + o * h, segment=seg) for o in (-2, -1, 0, 1, 2)]
        pos = [x[0] for x in q]
        d1 = (pos[3] - pos[1]) / (2 * h)
        d2 = (pos[3] - 2 * pos[2] + pos[1]) / h ** 2
        d3 = (pos[4] - 2 * pos[3] + 2 * pos[1] - pos[0]) / (2 * h ** 3)
        np.testing.assert_allclose(q[2][1], d1, atol=1e-7)
        np.testing.assert_allclose(q[2][2], d2, atol=1e-5)
        np.testing.assert_allclose(q[2][3], d3, atol=2e-3)
        np.testing.assert_allclose(np.linalg.norm(q[2][1], axis=1), 1.0, rtol=1e-13)


def test_amplitudes_bound_the_derivatives_per_axis():
    theta, half = 2.0, 0.4
    path, _, _, _ = corner_path(theta, half, plane=(
        np.array([0.6, 0.8, 0.0]), np.array([0.0, 0.0, 1.0])))
    amp = plane_amplitudes(path)
    for k in (1, 2):
        s = np.linspace(path.s_breaks[k], path.s_breaks[k + 1], 2001)
        _, dq, ddq, dddq = path.evaluate(s, segment=np.full(s.size, k))
        rho = np.sqrt(path.e1[k] ** 2 + path.e2[k] ** 2)
        assert np.all(np.abs(dq) <= rho * amp.speed[k] + 1e-12)
        assert np.all(np.abs(ddq) <= rho * amp.curvature[k] * (1 + 1e-12))
        assert np.all(np.abs(dddq) <= rho * np.hypot(amp.jerk_t[k], amp.jerk_n[k])
                      * (1 + 1e-12))
        # and they are attained (kappa_max at the middle)
        assert np.max(np.linalg.norm(ddq, axis=1)) == pytest.approx(theta / half, rel=1e-9)
    assert amp.curvature[1] == pytest.approx(theta / half)
    assert amp.jerk_n[1] == pytest.approx(theta / half ** 2)


def test_pair_shape_small_angle_limit():
    """For small theta the clothoid pair of piece length L_s has d -> L_s and the
    deviation -> L_s theta / 6 (Y = c L^3 / 6 with c = theta / L^2)."""
    d, e = clothoid_pair_shape(np.array([1e-4]))
    assert d[0] == pytest.approx(1.0, rel=1e-7)
    assert e[0] == pytest.approx(1e-4 / 6, rel=1e-6)


def test_derivative_norm_bounds_hold_up_to_the_fifth():
    """The checker's pruning bounds (reference.core.geometry.clothoid_derivative_norms)
    against the derivatives: q' .. q''' exact, q'''' and q5 by central differences of
    the exact q'''."""
    from reference.core.geometry import clothoid_derivative_norms
    for theta, half in ((0.4, 0.2), (1.5, 1.0), (2.9, 0.05)):
        path, _, _, _ = corner_path(theta, half)
        c = theta / half ** 2
        norms = clothoid_derivative_norms(np.array([c]), np.array([half]))
        h = half * 1e-3
        for k in (1, 2):
            s = np.linspace(path.s_breaks[k] + 2 * h, path.s_breaks[k + 1] - 2 * h, 301)
            seg = np.full(s.size, k)
            ev = [path.evaluate(s + o * h, segment=seg)[3] for o in (-2, -1, 0, 1, 2)]
            q4 = (ev[3] - ev[1]) / (2 * h)
            q5 = (ev[3] - 2 * ev[2] + ev[1]) / h ** 2
            _, dq, ddq, dddq = path.evaluate(s, segment=seg)
            for m, val in enumerate((dq, ddq, dddq, q4, q5)):
                tol = 1e-12 if m < 3 else 1e-3
                assert np.all(np.linalg.norm(val, axis=1) <= norms[m][0] * (1 + tol)), m


def test_a_batch_of_mixed_rows_is_each_kind_evaluated_alone():
    """Path.evaluate on lines and clothoids mixed (in random order, repeated rows) gives
    bit for bit what the lines alone and the clothoids alone give: each row by its own
    formula, whatever else is in the batch."""
    path = corner_path(0.9, 2.0)[0]
    rng = np.random.default_rng(4)
    s = rng.uniform(0.0, path.total_length, 500)
    seg = path.segment_index(s)
    mixed = path.evaluate(s)
    clo = path.sharpness[seg] != 0
    assert clo.any() and (~clo).any()
    for sel in (clo, ~clo):
        alone = path.evaluate(s[sel])
        for a, b in zip(mixed, alone, strict=True):
            assert np.array_equal(a[sel], b)
