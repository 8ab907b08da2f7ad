"""Exact path geometry: lines, arcs and helices in any plane and any number of axes.

Every segment is a *helical piece* parameterised by the arc length ``s`` of the
geometry axes (X, Y, Z) where they move, otherwise of all moving axes:

.. math::

    q(s) = o + r\\,(e_1 \\cos\\varphi + e_2 \\sin\\varphi) + d\\,s,\\qquad
    \\varphi = \\theta_0 + \\omega s,\\quad 0 \\le s \\le L

A line has ``r = 0`` (so ``q = o + d s``); an arc or helix has ``r > 0`` with ``e1, e2``
the orthonormal plane axes and ``d`` the linear motion of the helix axis and of every
extra axis (rotary axes move linearly with the path). The derivatives are exact:

``q' = r w (-e1 sin + e2 cos) + d``, ``q'' = -r w^2 (e1 cos + e2 sin)``,
``q''' = r w^3 (e1 sin - e2 cos)``.

*Spiral arcs.* An arc whose programmed end radius differs from its start radius (within
the control's tolerance) is a spiral: the radius changes linearly with the swept angle
``t = |phi - theta0|``, ``r(t) = r0 + k t`` (``k = dradius``, mm/rad), so the arc ends
exactly at the programmed point, while the helix axis and every extra axis still move
as ``d s``. Its in-plane part has the constant speed ``g = |dp/ds|`` (``g^2 + |d_geo|^2
= 1``) and the exact plane arc length of an Archimedean-type spiral
(:func:`spiral_plane_length`); ``s -> t`` inverts it by Newton's method
(:func:`spiral_angle`). ``omega`` then stores the mean rate ``sweep / length``, so
``|omega| length`` is still the swept angle. A circle is the case ``k = 0`` and is
evaluated by the closed forms above.

*Clothoids (Euler spirals).* A corner rounding that must be curvature continuous
(:mod:`reference.rounding`) is built from clothoid pieces: plane curves whose curvature
grows linearly with the arc length from zero, ``kappa(sigma) = c sigma`` (``c =
sharpness``, 1/mm^2), where ``sigma`` is the distance from the piece's zero-curvature
end ``Z``. With ``e1`` the unit tangent at ``Z`` (pointing to growing ``sigma``) and
``e2`` the unit normal it turns towards, the angle is ``phi = c sigma^2 / 2`` and

``p(sigma) = Z + X(sigma) e1 + Y(sigma) e2``, ``X = sqrt(pi/c) C(sigma sqrt(c/pi))``,
``Y = sqrt(pi/c) S(sigma sqrt(c/pi))`` (``C``, ``S`` the Fresnel integrals),
``p' = T = cos phi e1 + sin phi e2``, ``p'' = kappa N`` (``N = -sin phi e1 + cos phi
e2``), ``p''' = c N - kappa^2 T``, exact and arc-length parametrised (``|p'| = 1``).

A piece whose curvature grows along the path has ``Z`` at its start (``sigma = s``,
``sharpness > 0``); one whose curvature falls to zero at its end has ``Z`` there
(``sigma = L - s``, stored as ``sharpness < 0``), so its odd derivatives change sign.
Its packed row: ``origin = Z``, ``e1``, ``e2`` as above, ``d = 0``, ``radius = 1 /
kappa_max`` and ``omega = kappa_max`` (``kappa_max = |c| L``): every "curved" test
(``radius > 0``) holds, ``radius * omega = 1`` is its in-plane speed and ``|omega|``
bounds its angular rate (``|omega| L`` is twice its swept angle ``|c| L^2 / 2``).

A :class:`Path` stores all pieces as packed arrays (one row per segment) so that
evaluation at 10^5 points is one vectorised numpy expression.

Units: mm for linear axes, degrees for rotary axes, ``s`` in mm.
Shapes: ``m`` segments, ``n`` axes, ``N`` evaluation points.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from .arrays import row_dots, row_norms
from .errors import PathError
from .rounding import RoundingTable
from .tolerances import ARC_SPIRAL_MIN_MM, MIN_SEGMENT_LENGTH_MM, MOVING_AXIS_TOL, POS_TOL_MM

SegmentKind = Literal["line", "arc", "rounding", "trc", "tlift"]
KIND_CODES: tuple[str, ...] = ("line", "arc", "rounding", "trc", "tlift")


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a, dtype=np.float64)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, slots=True, eq=False)
class HelicalSegment:
    """One path segment (line, arc or helix) with exact derivatives.

    Attributes
    ----------
    origin, e1, e2, d : numpy.ndarray
        Shape ``(n,)``: see the module docstring. ``e1``/``e2`` are zero for lines.
    radius : float
        Arc radius in mm, 0 for lines.
    omega : float
        Angular rate ``dphi/ds`` in rad/mm (positive = counter-clockwise in the plane
        spanned by ``e1``, ``e2``), 0 for lines.
    theta0 : float
        Angle at ``s = 0``, rad.
    length : float
        Path length, mm.
    source_block : int
        Index of the NC block this segment belongs to.
    kind : str
        ``"line"``, ``"arc"``, or the kind of an inserted block.
    dradius : float
        Spiral rate ``dr/dt``, mm per rad of swept angle; 0 for lines and circles.
    sharpness : float
        Clothoid curvature rate ``dkappa/dsigma``, 1/mm^2 (negative: the curvature falls
        to zero at the end; module docstring); 0 for every other segment.
    """

    origin: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    d: np.ndarray
    radius: float
    omega: float
    theta0: float
    length: float
    source_block: int
    kind: str = "line"
    dradius: float = 0.0
    sharpness: float = 0.0

    def evaluate(self, s: np.ndarray | float) -> tuple[np.ndarray, ...]:
        """Position and its first three derivatives with respect to ``s``.

        Parameters
        ----------
        s : array_like, shape (N,)
            Local path positions in ``[0, length]``, mm.

        Returns
        -------
        q, dq, ddq, dddq : numpy.ndarray
            Each of shape ``(N, n)``: mm, 1, 1/mm, 1/mm^2 (degrees for rotary axes).
        """
        s = np.atleast_1d(np.asarray(s, dtype=np.float64))
        return _eval_helical(
            self.origin[None], self.e1[None], self.e2[None], self.d[None],
            np.array([self.radius]), np.array([self.omega]), np.array([self.theta0]),
            np.zeros(len(s), dtype=np.intp), s, np.array([self.dradius]),
            np.array([self.length]), np.array([self.sharpness]))

    @property
    def start_tangent(self) -> np.ndarray:
        """``q'(0)``, shape ``(n,)`` (unit length over the geometry axes)."""
        return self.evaluate(0.0)[1][0]

    @property
    def end_tangent(self) -> np.ndarray:
        """``q'(L)``, shape ``(n,)``."""
        return self.evaluate(self.length)[1][0]

    @property
    def start_curvature(self) -> np.ndarray:
        """Curvature vector ``q''(0)``, shape ``(n,)``, 1/mm."""
        return self.evaluate(0.0)[2][0]

    @property
    def end_curvature(self) -> np.ndarray:
        """Curvature vector ``q''(L)``, shape ``(n,)``, 1/mm."""
        return self.evaluate(self.length)[2][0]

    @property
    def start(self) -> np.ndarray:
        """Start point, shape ``(n,)``."""
        return self.evaluate(0.0)[0][0]

    @property
    def end(self) -> np.ndarray:
        """End point, shape ``(n,)``."""
        return self.evaluate(self.length)[0][0]


def _eval_helical(origin, e1, e2, d, radius, omega, theta0, idx, s, dradius=None,
                  length=None, sharpness=None, tangent_only=False, two_derivatives=False):
    """Vectorised kernel: rows ``idx`` of the packed arrays at local positions ``s``.

    ``dradius`` and ``length`` (shape ``(m,)``) are needed only when some row is a
    spiral, ``sharpness`` and ``length`` when some row is a clothoid; without them the
    circle/line closed forms run alone, as fast as before. ``tangent_only``: where every
    row is a circle or a line, only ``dq`` is computed (the others are ``None``; the
    same ``dq``, by the same expressions), for callers that need the tangents alone.
    ``two_derivatives``: only ``dq`` and ``ddq`` (``q`` and ``dddq`` are ``None``; the
    same numbers, by the same expressions), for :meth:`Path.junction_derivatives`: a
    clothoid's position needs its Fresnel integrals, and on a path with both kinds of
    rows each part is scattered into the result row by row (about 25 ns a row).
    """
    cl = np.flatnonzero(sharpness[idx]) if sharpness is not None else np.zeros(0, np.intp)
    if cl.size:
        # the circle/line/spiral rows and the clothoid rows each by their own formula
        # (row by row the numbers of evaluating every row as a circle first and
        # overwriting the clothoids, without that work on the clothoid rows: most rows
        # of a path with G645 transitions); rows gathered by ``take`` (the same rows,
        # faster than fancy indexing)
        rows = idx[cl]
        parts = _eval_clothoid(None if two_derivatives else origin.take(rows, axis=0),
                               e1.take(rows, axis=0), e2.take(rows, axis=0),
                               sharpness[rows], length[rows], s[cl], two_derivatives)
        if cl.size == idx.size:
            return parts
        rest = np.flatnonzero(sharpness[idx] == 0)
        other = _eval_helical(origin, e1, e2, d, radius, omega, theta0, idx[rest], s[rest],
                              dradius, length, two_derivatives=two_derivatives)
        out = []
        for a, b in zip(other, parts):
            arr = None
            if b is not None:
                arr = np.empty((idx.size,) + b.shape[1:])
                arr[rest], arr[cl] = a, b
            out.append(arr)
        return tuple(out)
    r = radius[idx]
    w = omega[idx]
    sp = np.flatnonzero(dradius[idx]) if dradius is not None else np.zeros(0, np.intp)
    # rows of the (m, n) arrays by ``take``: the same rows as ``e1[idx]``, gathered
    # about 4x faster (numpy's fancy indexing of rows costs ~25 ns a row)
    E1, E2, DL = e1.take(idx, axis=0), e2.take(idx, axis=0), d.take(idx, axis=0)
    if sp.size == 0:
        rc, wc = r[:, None], w[:, None]
        phi = theta0[idx][:, None] + wc * s[:, None]
        c, sn = np.cos(phi), np.sin(phi)
        along = E2 * c - E1 * sn           # unit tangential direction of the circle
        dq = (rc * wc) * along + DL
        if tangent_only:
            return None, dq, None, None
        radial = E1 * c + E2 * sn          # unit radial direction (zero rows for lines)
        ddq = -(rc * wc * wc) * radial
        if two_derivatives:
            return None, dq, ddq, None
        q = origin.take(idx, axis=0) + rc * radial + DL * s[:, None]
        dddq = -(rc * wc * wc * wc) * along
        return q, dq, ddq, dddq
    # With spirals: q = o + A R + d s, q' = B T + C R + d, q'' = D R + E T,
    # q''' = F T + G R, per-point coefficients (circle values, spiral rows overwritten).
    phi = theta0[idx] + w * s
    A, B, C = r.copy(), r * w, np.zeros_like(r)
    D, E = -(r * w * w), np.zeros_like(r)
    F, G = -(r * w * w * w), np.zeros_like(r)
    rows = idx[sp]
    ts, phs, (A[sp], B[sp], C[sp], D[sp], E[sp], F[sp], G[sp]) = _spiral_coefficients(
        radius[rows], omega[rows], theta0[rows], dradius[rows], length[rows], s[sp])
    phi[sp] = phs
    c, sn = np.cos(phi)[:, None], np.sin(phi)[:, None]
    radial = E1 * c + E2 * sn
    along = E2 * c - E1 * sn
    dq = B[:, None] * along + C[:, None] * radial + DL
    ddq = D[:, None] * radial + E[:, None] * along
    if two_derivatives:
        return None, dq, ddq, None
    q = origin.take(idx, axis=0) + A[:, None] * radial + DL * s[:, None]
    dddq = F[:, None] * along + G[:, None] * radial
    return q, dq, ddq, dddq


def _fresnel(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(S(z), C(z))``, the Fresnel integrals (scipy, loaded on first use: ``import
    reference`` stays light, and paths without clothoids never load it)."""
    from scipy.special import fresnel
    return fresnel(z)


def _eval_clothoid(origin, e1, e2, sharpness, length, s, two_derivatives=False):
    """Clothoid rows at local positions ``s`` (module docstring), shapes (N, n) / (N,).

    Position from the Fresnel integrals (``scipy.special.fresnel``, accurate to a few
    units of float64 round-off); derivatives in closed form. For ``sharpness < 0`` the
    zero-curvature end is at ``s = L`` and ``sigma = L - s``, so ``q' = -p'``,
    ``q'' = p''`` and ``q''' = -p'''``. ``two_derivatives``: the first two derivatives
    alone (``origin`` is not used; the position and the third derivative are ``None``).
    """
    c = np.abs(sharpness)
    back = sharpness < 0
    sigma = np.where(back, length - s, s)
    sigma = np.clip(sigma, 0.0, length)
    phi = 0.5 * c * sigma * sigma
    kappa = c * sigma
    cos, sin = np.cos(phi)[:, None], np.sin(phi)[:, None]
    tan = cos * e1 + sin * e2
    nor = cos * e2 - sin * e1
    sign = np.where(back, -1.0, 1.0)[:, None]
    dq = sign * tan
    ddq = kappa[:, None] * nor
    if two_derivatives:
        return None, dq, ddq, None
    scale = np.sqrt(np.pi / c)
    fs, fc = _fresnel(sigma / scale)
    q = origin + (scale * fc)[:, None] * e1 + (scale * fs)[:, None] * e2
    dddq = sign * (c[:, None] * nor - (kappa * kappa)[:, None] * tan)
    return q, dq, ddq, dddq


def clothoid_derivative_norms(c: np.ndarray, length: np.ndarray) -> list[np.ndarray]:
    """Bounds of ``|q^(m)|``, ``m = 1..5``, on clothoid pieces of curvature rate ``c``
    and length ``L`` (``kappa = c sigma <= K = c L``), shape (N,) each.

    With ``T``, ``N`` the unit tangent and normal (``T' = kappa N``, ``N' = -kappa T``,
    ``kappa' = c``): ``q' = T``, ``q'' = kappa N``, ``q''' = c N - kappa^2 T``,
    ``q'''' = -3 c kappa T - kappa^3 N``, ``q5 = (kappa^4 - 3 c^2) T - 6 c kappa^2 N``;
    ``T``, ``N`` orthonormal, so the norms are at most ``1``, ``K``, ``hypot(c, K^2)``,
    ``hypot(3 c K, K^3)`` and ``hypot(max(K^4, 3 c^2), 6 c K^2)``.
    """
    K = c * length
    return [np.ones_like(c), K, np.hypot(c, K * K), np.hypot(3 * c * K, K ** 3),
            np.hypot(np.maximum(K ** 4, 3 * c * c), 6 * c * K * K)]


def clothoid_pieces(start: np.ndarray, t_in: np.ndarray, t_out: np.ndarray,
                    half_length: np.ndarray, block: np.ndarray, kind_code: int
                    ) -> dict[str, np.ndarray]:
    """Packed rows of symmetric clothoid pairs turning from ``t_in`` to ``t_out``.

    Pair ``k`` starts at ``start[k]`` tangent to ``t_in[k]`` with zero curvature; its
    first piece (curvature rising, ``sharpness > 0``) turns by ``theta/2`` over
    ``half_length`` (``theta`` the angle between the directions), the second (curvature
    falling to zero, ``sharpness < 0``) turns by the other ``theta/2`` and ends tangent to
    ``t_out`` with zero curvature. The pieces are interleaved (first, second, first,
    ...): ``2k`` rows.

    Parameters
    ----------
    start, t_in, t_out : numpy.ndarray, shape (k, n)
        Start points and unit directions (in a plane; ``0 < theta < pi``).
    half_length : numpy.ndarray, shape (k,)
        Length of each piece ``L_s``, mm (``c = theta / L_s^2``, ``kappa_max = theta /
        L_s``).
    block : numpy.ndarray of int, shape (k,)
        Block each pair is attributed to.
    kind_code : int
        Segment kind code.

    Returns
    -------
    dict
        Packed rows (keys of :class:`Path`, plus ``sharpness``).
    """
    k = half_length.size
    n = start.shape[1]
    theta = 2.0 * np.arctan2(row_norms(t_out - t_in), row_norms(t_out + t_in))
    c = theta / half_length ** 2
    kmax = theta / half_length
    nor = t_out - row_dots(t_out, t_in)[:, None] * t_in
    nor /= row_norms(nor)[:, None]
    # the end: by symmetry about the bisector, the chord from start to end is
    # 2 L_s (Fx cos(theta/2) + Fy sin(theta/2)) along the mean direction
    scale = np.sqrt(np.pi / c)
    fs, fc = _fresnel(half_length / scale)
    X, Y = scale * fc, scale * fs
    d = X + Y * np.tan(theta / 2.0)                    # tangent distance to the corner
    corner = start + d[:, None] * t_in
    end = corner + d[:, None] * t_out
    back_n = -t_in + row_dots(t_in, t_out)[:, None] * t_out
    back_n /= row_norms(back_n)[:, None]
    origin = np.empty((2 * k, n))
    e1 = np.empty((2 * k, n))
    e2 = np.empty((2 * k, n))
    origin[0::2], e1[0::2], e2[0::2] = start, t_in, nor
    origin[1::2], e1[1::2], e2[1::2] = end, -t_out, back_n
    rep = np.repeat
    return clothoid_rows(origin, e1, e2, np.column_stack((c, -c)).ravel(),
                         rep(half_length, 2), rep(np.asarray(block, np.int64), 2), kind_code,
                         kmax=rep(kmax, 2))


def clothoid_rows(origin: np.ndarray, e1: np.ndarray, e2: np.ndarray, sharpness: np.ndarray,
                  length: np.ndarray, block: np.ndarray, kind_code: int,
                  kmax: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Packed rows (keys of :class:`Path`, plus ``sharpness``) of clothoid pieces whose
    curvature is zero at their origin: the one packing of every inserted clothoid
    (rounding pairs, G645 transitions).

    Parameters
    ----------
    origin, e1, e2 : numpy.ndarray, shape (m, n)
        Zero-curvature end, unit tangent and unit normal there (the side it turns to).
    sharpness : numpy.ndarray, shape (m,)
        Curvature rate, 1/mm^2 (negative: traversed towards the zero-curvature end).
    length : numpy.ndarray, shape (m,)
        Piece lengths, mm.
    block : numpy.ndarray of int, shape (m,)
    kind_code : int
    kmax : numpy.ndarray, shape (m,), optional
        Largest curvature, 1/mm (default ``|sharpness| length``; a caller that has it
        from its construction passes it, so its rows stay as they were).
    """
    m, n = origin.shape
    kmax = np.abs(sharpness) * length if kmax is None else kmax
    return {
        "origin": origin, "e1": e1, "e2": e2, "d": np.zeros((m, n)),
        "radius": 1.0 / kmax, "omega": kmax, "theta0": np.zeros(m), "length": length,
        "block": np.asarray(block, np.int64), "kind": np.full(m, kind_code, dtype=np.int8),
        "dradius": np.zeros(m), "sharpness": sharpness,
    }


def clothoid_pair_shape(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Tangent distance and contour deviation of a symmetric clothoid pair of unit
    piece length turning by ``theta``, shape (k,) each (both scale with the piece
    length ``L_s``).

    The first piece ends at ``(X, Y) = (sqrt(pi/c) C(z), sqrt(pi/c) S(z))``,
    ``z = sqrt(c/pi)`` (``L_s = 1``, ``c = theta``) with tangent angle ``theta/2``;
    that point lies on the corner's bisector, so the tangent distance from the corner
    is ``d = X + Y tan(theta/2)`` and the largest distance of the pair from the corner
    (at that middle point, the nearest) is ``e = Y / cos(theta/2)``.
    """
    c = np.asarray(theta, dtype=np.float64)
    scale = np.sqrt(np.pi / c)
    fs, fc = _fresnel(1.0 / scale)
    X, Y = scale * fc, scale * fs
    return X + Y * np.tan(c / 2.0), Y / np.cos(c / 2.0)


def spiral_plane_length(r0: np.ndarray, k: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Exact plane arc length of the spiral ``r = r0 + k tau`` over ``0 <= tau <= t``.

    ``sigma(t) = int_0^t sqrt((r0 + k tau)^2 + k^2) dtau`` has the closed form
    ``(F(r1) - F(r0)) / k`` with ``F(u) = (u sqrt(u^2 + k^2) + k^2 asinh(u / |k|)) / 2``
    and ``r1 = r0 + k t``. Both differences are rewritten without cancellation
    (``u1 S1 - u0 S0 = k t (u0 + u1)(u0^2 + u1^2 + k^2) / (u1 S1 + u0 S0)`` and
    ``asinh a - asinh b = asinh(a sqrt(1 + b^2) - b sqrt(1 + a^2))``), giving

    ``sigma = [t (u0 + u1)(u0^2 + u1^2 + k^2) / (u1 S1 + u0 S0)
    + k asinh(k t (u0 + u1) / (u1 S0 + u0 S1))] / 2``, ``S = sqrt(u^2 + k^2)``.

    Every quantity in the first term is a sum, product or quotient of positive numbers
    and the second term is non-negative (``k asinh(k x)``) and small, so the result has a
    relative error of a few units of float64 round-off (bound: 20 eps = 4.4e-15, checked
    against ``scipy.integrate.quad`` in the tests) for every ``k``, also ``k -> 0``,
    where it tends to ``r0 t``.

    Parameters
    ----------
    r0 : numpy.ndarray, shape (N,)
        Start radius, mm (> 0).
    k : numpy.ndarray, shape (N,)
        Radius change per rad of swept angle, mm/rad; ``r0 + k t > 0``.
    t : numpy.ndarray, shape (N,)
        Swept angle, rad (>= 0).

    Returns
    -------
    numpy.ndarray, shape (N,)
        Plane arc length, mm.
    """
    u0 = r0
    u1 = r0 + k * t
    kk = k * k
    s0 = np.sqrt(u0 * u0 + kk)
    s1 = np.sqrt(u1 * u1 + kk)
    ssum = u0 + u1
    first = t * ssum * (u0 * u0 + u1 * u1 + kk) / (u1 * s1 + u0 * s0)
    second = k * np.arcsinh(k * t * ssum / (u1 * s0 + u0 * s1))
    return 0.5 * (first + second)


#: Newton steps of :func:`spiral_angle` at most. From its start (error about
#: (k/r)^2 t) Newton converges quadratically: two or three steps reach round-off.
_SPIRAL_NEWTON_MAX = 8


def spiral_angle(r0: np.ndarray, k: np.ndarray, sigma: np.ndarray,
                 t_end: np.ndarray) -> np.ndarray:
    """Swept angle ``t`` at plane arc length ``sigma`` on the spiral ``r = r0 + k t``.

    Inverts :func:`spiral_plane_length` by Newton's method (``dsigma/dt =
    sqrt(r^2 + k^2) > 0``), started from the root of ``r0 t + k t^2 / 2 = sigma`` (exact
    up to ``(k/r)^2``), clipped to ``[0, t_end]``. It stops when every step is below four
    units of round-off of ``max(t_end, 1)``, so ``s -> t`` is consistent with the length
    to float64 precision: ``|sigma(t) - sigma| <= 4 eps max(t_end, 1) sqrt(r^2 + k^2)``
    plus the round-off of :func:`spiral_plane_length` (about 1e-15 relative), far below
    the 1e-9 mm continuity of the path.

    Parameters
    ----------
    r0, k : numpy.ndarray, shape (N,)
        Start radius (mm) and radius change per rad (mm/rad).
    sigma : numpy.ndarray, shape (N,)
        Plane arc lengths, mm.
    t_end : numpy.ndarray, shape (N,)
        Swept angle of the whole arc, rad.

    Returns
    -------
    numpy.ndarray, shape (N,)
        Swept angles, rad.
    """
    disc = np.maximum(r0 * r0 + 2.0 * k * sigma, 0.0)
    t = np.clip(2.0 * sigma / (r0 + np.sqrt(disc)), 0.0, t_end)
    stop = 4.0 * np.finfo(np.float64).eps * np.maximum(t_end, 1.0)
    for _ in range(_SPIRAL_NEWTON_MAX):
        r = r0 + k * t
        step = (spiral_plane_length(r0, k, t) - sigma) / np.sqrt(r * r + k * k)
        t = np.clip(t - step, 0.0, t_end)
        if np.all(np.abs(step) <= stop):
            break
    return t


def _spiral_speed(r0, k, omega, length):
    """In-plane speed ``g = |dp/ds|`` and swept angle of spiral rows, shape (N,)."""
    t_end = np.abs(omega) * length
    return spiral_plane_length(r0, k, t_end) / length, t_end


def _spiral_coefficients(r0, omega, theta0, k, length, s):
    """Swept angle, angle and derivative coefficients of spiral rows, each shape (N,).

    With ``p(t) = r(t) R``, ``R = e1 cos phi + e2 sin phi``, ``T = dR/dphi``,
    ``phi = theta0 + e t`` (``e = sign(omega)``) and the arc-length map ``t(s)``
    (``t1 = dt/ds = g / S``, ``S = sqrt(r^2 + k^2)``, ``t2 = -g^2 r k / S^4``,
    ``t3 = -g^3 k^2 (k^2 - 3 r^2) / S^7``), from ``p_t = k R + e r T``,
    ``p_tt = 2 e k T - r R`` and ``p_ttt = -3 k R - e r T``:
    ``q' = p_t t1 + d``, ``q'' = p_tt t1^2 + p_t t2``,
    ``q''' = p_ttt t1^3 + 3 p_tt t1 t2 + p_t t3``. Returned as the coefficients
    ``A .. G`` of :func:`_eval_helical`.
    """
    g, t_end = _spiral_speed(r0, k, omega, length)
    e = np.where(omega < 0, -1.0, 1.0)
    t = spiral_angle(r0, k, g * s, t_end)
    r = r0 + k * t
    kk = k * k
    S2 = r * r + kk
    S = np.sqrt(S2)
    t1 = g / S
    t2 = -(g * g) * r * k / (S2 * S2)
    t3 = -(g * g * g) * kk * (kk - 3.0 * r * r) / (S2 * S2 * S2 * S)
    t11 = t1 * t1
    t111 = t11 * t1
    A = r
    B, C = e * r * t1, k * t1
    D, E = -r * t11 + k * t2, e * (2.0 * k * t11 + r * t2)
    F = e * (-r * t111 + 6.0 * k * t1 * t2 + r * t3)
    G = -3.0 * k * t111 - 3.0 * r * t1 * t2 + k * t3
    return t, theta0 + e * t, (A, B, C, D, E, F, G)


@dataclass(frozen=True, slots=True, eq=False)
class PlaneAmplitudes:
    """Per segment, suprema over the segment of the in-plane (rotating) motion.

    For an axis ``j`` with plane weight ``rho_j = sqrt(e1_j^2 + e2_j^2)``:
    ``|q'_j| <= |d_j| + rho_j speed``, ``|q''_j| <= rho_j curvature`` and
    ``|q'''_j| <= rho_j hypot(jerk_t, jerk_n)``. The in-plane tangent has the constant
    length ``speed``, ``q''`` is normal to it, ``jerk_t`` bounds the tangential and
    ``jerk_n`` the normal part of ``q'''``. On circles these are the exact constants
    ``r|w|``, ``r w^2``, ``r|w|^3``, 0 and ``omega_max = |w|``. On spirals (``r`` from
    ``r_min`` to ``r_max``; the plane curvature ``kappa(r) = (r^2 + 2k^2) /
    (r^2 + k^2)^{3/2}`` falls as ``r`` grows): ``speed = g``, ``curvature =
    g^2 kappa(r_min)``, ``jerk_t = g^3 kappa(r_min)^2``, ``jerk_n = g^3 |k| r_max
    (r_max^2 + 4k^2) / (r_min^2 + k^2)^3 >= g^3 |dkappa/dsigma|`` and ``omega_max =
    g / sqrt(r_min^2 + k^2) >= |dphi/ds|``. On clothoids (``kappa = |c| sigma`` up
    to ``kappa_max = |c| L``): ``speed = 1``, ``curvature = kappa_max``, ``jerk_t =
    kappa_max^2``, ``jerk_n = |c|`` and ``omega_max = kappa_max``. Lines have zeros.

    Attributes
    ----------
    speed, curvature, jerk_t, jerk_n : numpy.ndarray, shape (m,)
        1, 1/mm, 1/mm^2, 1/mm^2.
    omega_max : numpy.ndarray, shape (m,)
        Largest angular rate ``|dphi/ds|``, rad/mm.
    """

    speed: np.ndarray
    curvature: np.ndarray
    jerk_t: np.ndarray
    jerk_n: np.ndarray
    omega_max: np.ndarray


def plane_amplitudes(path: "Path") -> PlaneAmplitudes:
    """Suprema of the in-plane motion of every segment (see :class:`PlaneAmplitudes`).

    Parameters
    ----------
    path : Path

    Returns
    -------
    PlaneAmplitudes
    """
    r, w = path.radius, path.omega
    speed = np.abs(r * w)
    curvature = np.abs(r * w * w)
    jerk_t = np.abs(r * w ** 3)
    jerk_n = np.zeros_like(r)
    omega_max = np.abs(w)
    sp = np.flatnonzero(path.dradius)
    if sp.size:
        r0, k = r[sp], path.dradius[sp]
        g, t_end = _spiral_speed(r0, k, w[sp], path.length[sp])
        r1 = r0 + k * t_end
        rmin, rmax = np.minimum(r0, r1), np.maximum(r0, r1)
        kk = k * k
        smin2 = rmin * rmin + kk
        kappa = (rmin * rmin + 2.0 * kk) / (smin2 * np.sqrt(smin2))
        speed[sp] = g
        curvature[sp] = g * g * kappa
        jerk_t[sp] = g ** 3 * kappa * kappa
        jerk_n[sp] = g ** 3 * np.abs(k) * rmax * (rmax * rmax + 4.0 * kk) / smin2 ** 3
        omega_max[sp] = g / np.sqrt(smin2)
    cl = np.flatnonzero(path.sharpness)
    if cl.size:
        # clothoids: unit in-plane speed, kappa <= kappa_max = |c| L, the tangential part
        # of q''' is -kappa^2 T (<= kappa_max^2), the normal part c N, and the angular
        # rate dphi/ds = kappa <= kappa_max
        c = np.abs(path.sharpness[cl])
        kmax = c * path.length[cl]
        speed[cl] = 1.0
        curvature[cl] = kmax
        jerk_t[cl] = kmax * kmax
        jerk_n[cl] = c
        omega_max[cl] = kmax
    return PlaneAmplitudes(speed, curvature, jerk_t, jerk_n, omega_max)




def axis_tangent_amplitudes(path: "Path", amp: PlaneAmplitudes | None = None
                            ) -> tuple[np.ndarray, np.ndarray]:
    """Per segment and axis, the two parts of ``|q'_i|``: constant and rotating.

    Parameters
    ----------
    path : Path
    amp : PlaneAmplitudes, optional
        :func:`plane_amplitudes` of ``path`` when already computed.

    Returns
    -------
    D, P : numpy.ndarray, shape (m, n)
        ``|d_i|`` and ``sqrt(e1_i^2 + e2_i^2)`` times the in-plane speed amplitude (its
        supremum on spirals and clothoids), so ``|q'_i| <= D + P`` on the whole segment.
    """
    if amp is None:
        amp = plane_amplitudes(path)
    rho = np.sqrt(path.e1 ** 2 + path.e2 ** 2)
    return np.abs(path.d), rho * amp.speed[:, None]


def moving_axes(D: np.ndarray, P: np.ndarray) -> np.ndarray:
    """The rule for which axes move on a segment: ``D + P > MOVING_AXIS_TOL``.

    One rule for the heuristic's limits and the checker's frequency rule (which axes'
    LOOKAH_FREQUENCY applies). ``D, P`` from :func:`axis_tangent_amplitudes`; shape (m, n).
    """
    return (D + P) > MOVING_AXIS_TOL
def _path_length(delta: np.ndarray, geometry: np.ndarray) -> np.ndarray:
    """Length of linear moves ``delta`` (shape ``(m, n)``) by the path-length rule."""
    geo = np.sqrt(np.sum(delta[:, geometry] ** 2, axis=1))
    allax = np.sqrt(np.sum(delta ** 2, axis=1))
    return np.where(geo > MIN_SEGMENT_LENGTH_MM, geo, allax)


def line_segments(starts: np.ndarray, ends: np.ndarray, geometry: np.ndarray,
                  blocks: np.ndarray) -> dict[str, np.ndarray]:
    """Packed parameters of straight segments (vectorised).

    Parameters
    ----------
    starts, ends : numpy.ndarray, shape (m, n)
        End points, mm / degrees.
    geometry : numpy.ndarray of bool, shape (n,)
        True for the geometry axes X, Y, Z.
    blocks : numpy.ndarray of int, shape (m,)
        Source NC block of each segment.

    Returns
    -------
    dict
        Packed arrays (keys as in :class:`Path`) for the ``m`` lines.
    """
    starts = np.asarray(starts, dtype=np.float64)
    ends = np.asarray(ends, dtype=np.float64)
    m, n = starts.shape
    delta = ends - starts
    length = _path_length(delta, geometry)
    with np.errstate(invalid="ignore", divide="ignore"):
        d = np.where(length[:, None] > 0, delta / length[:, None], 0.0)
    zeros = np.zeros((m, n))
    return dict(origin=starts, e1=zeros, e2=zeros.copy(), d=d, radius=np.zeros(m),
                omega=np.zeros(m), theta0=np.zeros(m), length=length,
                block=np.asarray(blocks, dtype=np.int64),
                kind=np.zeros(m, dtype=np.int8), dradius=np.zeros(m))


def arc_segments(starts: np.ndarray, ends: np.ndarray, centers: np.ndarray,
                 e1: np.ndarray, e2: np.ndarray, clockwise: np.ndarray, turns: np.ndarray,
                 geometry: np.ndarray, blocks: np.ndarray, radius_tol: np.ndarray
                 ) -> dict[str, np.ndarray]:
    """Packed parameters of many circular or spiral arcs or helices at once (vectorised).

    An arc whose end radius differs from its start radius by more than
    :data:`ARC_SPIRAL_MIN_MM` (and at most ``radius_tol``) becomes a spiral whose radius
    changes linearly with the swept angle, so it ends exactly at ``ends`` (as the controls
    interpolate it); see the module docstring. Otherwise it is the circle on the start
    radius.

    Parameters
    ----------
    starts, ends, centers : numpy.ndarray, shape (m, n)
        Start and end points and arc centres (absolute; only the in-plane part of the
        centre is used), mm / degrees.
    e1, e2 : numpy.ndarray, shape (m, n)
        Orthonormal plane vectors; counter-clockwise turns from ``e1`` to ``e2``
        (G17: X->Y, G18: Z->X, G19: Y->Z).
    clockwise : numpy.ndarray of bool, shape (m,)
        True for G2.
    turns : numpy.ndarray of int, shape (m,)
        Additional full turns (>= 0).
    geometry : numpy.ndarray of bool, shape (n,)
        True for the geometry axes.
    blocks : numpy.ndarray of int, shape (m,)
        Source NC block of each arc.
    radius_tol : numpy.ndarray, shape (m,)
        Largest accepted difference between start and end radius, mm.

    Returns
    -------
    dict
        Packed arrays for the ``m`` arcs (``dradius`` non-zero on spirals).

    Raises
    ------
    PathError
        The first arc (in order) with zero radius or with start and end radius
        differing by more than its ``radius_tol``; ``PathError.block`` names its block.
    """
    starts = np.asarray(starts, dtype=np.float64)
    ends = np.asarray(ends, dtype=np.float64)
    ps, pe = starts - centers, ends - centers
    su, sv = np.sum(ps * e1, axis=1), np.sum(ps * e2, axis=1)
    eu, ev = np.sum(pe * e1, axis=1), np.sum(pe * e2, axis=1)
    r0, r1 = np.hypot(su, sv), np.hypot(eu, ev)
    bad = (r0 <= POS_TOL_MM) | (np.abs(r1 - r0) > radius_tol)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        if r0[i] <= POS_TOL_MM:
            raise PathError("arc with zero radius (centre on the start point)", int(blocks[i]))
        raise PathError(
            f"arc start radius {r0[i]:.6g} mm and end radius {r1[i]:.6g} mm differ by "
            f"{abs(r1[i] - r0[i]):.3g} mm (> {radius_tol[i]:.3g} mm)", int(blocks[i]))
    th0, th1 = np.arctan2(sv, su), np.arctan2(ev, eu)
    spiral = np.abs(r1 - r0) > ARC_SPIRAL_MIN_MM
    # Direction decides the sweep; an arc ending where it started (in the plane) is a
    # full turn, as both dialects define it.
    closed = np.hypot(eu - su, ev - sv) <= POS_TOL_MM
    if spiral.any():
        # a spiral that ends on its start ray (only the radius differs) is a full turn too
        turn = np.abs(np.remainder(th1 - th0 + np.pi, 2 * np.pi) - np.pi)
        closed |= spiral & (r0 * turn <= POS_TOL_MM)
    two_pi = 2 * np.pi
    sweep = np.where(clockwise, np.where(closed, -two_pi, -((th0 - th1) % two_pi)),
                     np.where(closed, two_pi, (th1 - th0) % two_pi))
    sweep = sweep + np.where(clockwise, -1.0, 1.0) * two_pi * turns
    delta = ends - starts
    lin = (delta - np.sum(delta * e1, axis=1)[:, None] * e1
           - np.sum(delta * e2, axis=1)[:, None] * e2)
    geo_lin = np.sqrt(np.sum(lin[:, geometry] ** 2, axis=1))
    plane_len = r0 * sweep
    dradius = np.zeros(r0.size)
    if spiral.any():
        i = np.flatnonzero(spiral)
        t_end = np.abs(sweep[i])
        dradius[i] = (r1[i] - r0[i]) / t_end
        plane_len[i] = spiral_plane_length(r0[i], dradius[i], t_end)
    length = np.hypot(plane_len, geo_lin)
    origin = starts - r0[:, None] * (np.cos(th0)[:, None] * e1 + np.sin(th0)[:, None] * e2)
    return dict(origin=origin, e1=np.array(e1, dtype=np.float64),
                e2=np.array(e2, dtype=np.float64), d=lin / length[:, None], radius=r0,
                omega=sweep / length, theta0=th0, length=length,
                block=np.asarray(blocks, dtype=np.int64),
                kind=np.full(r0.size, KIND_CODES.index("arc"), dtype=np.int8),
                dradius=dradius)


def arc_segment(start: np.ndarray, end: np.ndarray, center: np.ndarray,
                plane, clockwise: bool, turns: int,
                geometry: np.ndarray, block: int, radius_tol: float) -> dict[str, np.ndarray]:
    """Packed parameters of one circular or spiral arc or helix (see :func:`arc_segments`).

    Parameters
    ----------
    start, end, center : numpy.ndarray, shape (n,)
        Start and end points and the arc centre, mm / degrees.
    plane : tuple of two int, or tuple of two numpy.ndarray of shape (n,)
        The plane as axis indices ``(u, v)`` or as orthonormal vectors ``(e1, e2)``;
        counter-clockwise means from the first to the second.
    clockwise : bool
        True for G2.
    turns : int
        Additional full turns (>= 0).
    geometry : numpy.ndarray of bool, shape (n,)
        True for the geometry axes.
    block : int
        Source NC block.
    radius_tol : float
        Largest accepted difference between start and end radius, mm.

    Returns
    -------
    dict
        Packed arrays for one segment.

    Raises
    ------
    PathError
        Zero radius, or start and end radius differing by more than ``radius_tol``
        (a smaller difference gives a spiral ending at ``end``).
    """
    start = np.asarray(start, dtype=np.float64)
    n = start.size
    if isinstance(plane[0], (int, np.integer)):
        e1 = np.zeros(n)
        e2 = np.zeros(n)
        e1[plane[0]] = 1.0
        e2[plane[1]] = 1.0
    else:
        e1 = np.asarray(plane[0], dtype=np.float64)
        e2 = np.asarray(plane[1], dtype=np.float64)
    return arc_segments(start[None], np.asarray(end, dtype=np.float64)[None],
                        np.asarray(center, dtype=np.float64)[None], e1[None], e2[None],
                        np.array([clockwise]), np.array([turns]), geometry,
                        np.array([block]), np.array([radius_tol]))


@dataclass(frozen=True, slots=True)
class BlockSpan:
    """Where one NC block lies on the path.

    Attributes
    ----------
    block : int
        Index of the block in the program.
    line : int
        1-based source line.
    label : str
        Block number or label, ``""`` if none.
    kind : str
        ``"G0"``, ``"G1"``, ``"G2"``, ``"G3"`` or ``"none"`` (no path motion), or the kind
        of an inserted block (``"rounding"``, ...).
    s_start, s_end : float
        Path positions of the block's start and end, mm (equal for zero-length blocks).
    first_segment, n_segments : int
        Segment range ``[first_segment, first_segment + n_segments)``.
    feed_mm_s : float
        Programmed path feed, mm/s; ``inf`` for rapid (G0) and non-motion blocks.
    stop_reason : str
        Why the motion must be at rest at the block *end* (``""`` if it need not):
        ``"exact stop G60"``, ``"exact stop G9"``, ``"dwell"``, ``"M0"``, ...
    dwell_s : float
        Time the block waits at rest (G4), s.
    """

    block: int
    line: int
    label: str
    kind: str
    s_start: float
    s_end: float
    first_segment: int
    n_segments: int
    feed_mm_s: float = float("inf")
    stop_reason: str = ""
    dwell_s: float = 0.0

    @property
    def length(self) -> float:
        """Block path length, mm."""
        return self.s_end - self.s_start


#: Columns of :class:`BlockSpans`, in the order of :class:`BlockSpan`'s fields.
SPAN_COLUMNS = ("block", "line", "label", "kind", "s_start", "s_end", "first_segment",
                "n_segments", "feed_mm_s", "stop_reason", "dwell_s")
_SPAN_INT = ("block", "line", "first_segment", "n_segments")
_SPAN_FLOAT = ("s_start", "s_end", "feed_mm_s", "dwell_s")
_SPAN_TEXT = ("label", "kind", "stop_reason")


class BlockSpans(Sequence):
    """Where every NC block lies on the path: a read-only sequence of :class:`BlockSpan`
    stored as columns.

    The stages that move blocks along the path (rounding, tool radius compensation,
    tangential control) and the per-block rows work on the columns; a
    :class:`BlockSpan` is built only where one is asked for (the tuple of all of them
    once, on the first iteration, and kept). 10^5 spans as objects cost some 40 MB and
    0.2 s to build again after every stage that moves them.

    Attributes
    ----------
    block, line, first_segment, n_segments : numpy.ndarray of int64, shape (nb,)
        As in :class:`BlockSpan` (read-only).
    s_start, s_end, feed_mm_s, dwell_s : numpy.ndarray of float64, shape (nb,)
        As in :class:`BlockSpan`, mm, mm/s, s (read-only).
    label, kind, stop_reason : tuple[str, ...]
        As in :class:`BlockSpan`, length ``nb``.
    """

    __slots__ = SPAN_COLUMNS + ("_items",)

    def __init__(self, block, line, label, kind, s_start, s_end, first_segment, n_segments,
                 feed_mm_s=None, stop_reason=None, dwell_s=None) -> None:
        n = len(block)
        cols = {"block": block, "line": line, "s_start": s_start, "s_end": s_end,
                "first_segment": first_segment, "n_segments": n_segments,
                "feed_mm_s": np.full(n, np.inf) if feed_mm_s is None else feed_mm_s,
                "dwell_s": np.zeros(n) if dwell_s is None else dwell_s}
        for name in _SPAN_INT:
            a = np.ascontiguousarray(cols[name], dtype=np.int64)
            a.setflags(write=False)
            object.__setattr__(self, name, a)
        for name in _SPAN_FLOAT:
            object.__setattr__(self, name, _readonly(cols[name]))
        for name, val in (("label", label), ("kind", kind),
                          ("stop_reason", ("",) * n if stop_reason is None else stop_reason)):
            object.__setattr__(self, name, tuple(val))
        for name in SPAN_COLUMNS:
            if len(getattr(self, name)) != n:
                raise PathError(f"block spans: column {name!r} has {len(getattr(self, name))}"
                                f" entries, expected {n}")
        object.__setattr__(self, "_items", None)

    def __setattr__(self, name, value):
        raise AttributeError("BlockSpans is read-only")

    @classmethod
    def of(cls, spans) -> "BlockSpans":
        """``spans`` as :class:`BlockSpans` (itself if it is one; a sequence of
        :class:`BlockSpan` keeps its objects as the items)."""
        if isinstance(spans, BlockSpans):
            return spans
        spans = tuple(spans)
        out = cls(*([getattr(sp, name) for sp in spans] for name in SPAN_COLUMNS))
        object.__setattr__(out, "_items", spans)
        return out

    def moved(self, s_start, s_end, first_segment, n_segments) -> "BlockSpans":
        """The same blocks at new path positions and segment ranges (shape (nb,) each)."""
        return BlockSpans(self.block, self.line, self.label, self.kind, s_start, s_end,
                          first_segment, n_segments, self.feed_mm_s, self.stop_reason,
                          self.dwell_s)

    @property
    def length(self) -> np.ndarray:
        """Block path lengths, mm, shape (nb,)."""
        return self.s_end - self.s_start

    def _all(self) -> tuple[BlockSpan, ...]:
        items = self._items
        if items is None:
            cols = [getattr(self, name) for name in SPAN_COLUMNS]
            items = tuple(BlockSpan(*row) for row in zip(*(
                c if isinstance(c, tuple) else c.tolist() for c in cols)))
            object.__setattr__(self, "_items", items)
        return items

    def __len__(self) -> int:
        return int(self.block.size)

    def __getitem__(self, i):
        if self._items is not None or isinstance(i, slice):
            return self._all()[i]
        i = range(len(self))[i]          # negative indices, IndexError
        return BlockSpan(*(c[i] if isinstance(c, tuple) else c[i].item()
                           for c in (getattr(self, name) for name in SPAN_COLUMNS)))

    def __iter__(self):
        return iter(self._all())

    def __eq__(self, other) -> bool:
        if not isinstance(other, (BlockSpans, tuple, list)):
            return NotImplemented
        return len(self) == len(other) and tuple(self) == tuple(other)

    __hash__ = None

    def __repr__(self) -> str:
        return f"BlockSpans({len(self)} blocks)"

    def __reduce__(self):
        return (BlockSpans, tuple(getattr(self, name) for name in SPAN_COLUMNS))


@dataclass(frozen=True, slots=True, eq=False)
class Path:
    """An ordered sequence of segments parameterised by cumulative path length.

    Attributes
    ----------
    axes : tuple[str, ...]
        Axis names, length ``n``.
    geometry : numpy.ndarray of bool, shape (n,)
        True for geometry axes (X, Y, Z), whose path speed the feed F limits.
    rotary : numpy.ndarray of bool, shape (n,)
        True for rotary axes (degrees).
    origin, e1, e2, d : numpy.ndarray, shape (m, n)
        Packed helical parameters (see module docstring).
    radius, omega, theta0, length : numpy.ndarray, shape (m,)
        Packed helical parameters; ``length`` in mm. On spirals ``radius`` is the start
        radius and ``omega`` the mean angular rate ``sweep / length``.
    block : numpy.ndarray of int, shape (m,)
        Source NC block of each segment.
    kind : numpy.ndarray of int8, shape (m,)
        Index into :data:`KIND_CODES`.
    feed : numpy.ndarray, shape (m,)
        Programmed path-speed cap per segment, mm/s (``inf`` for G0: axis limits only).
    rapid : numpy.ndarray of bool, shape (m,)
        True for G0 segments.
    stop : numpy.ndarray of bool, shape (m + 1,)
        True where the motion must be at rest at break ``k`` (``k = 0`` is the start,
        ``k = m`` the end; both are always True).
    stop_reason : tuple[str, ...]
        Length ``m + 1``: why the motion stops at each break (``""`` if it need not).
    blocks : BlockSpans
        One span per NC block of the program, in program order (zero-length blocks too);
        any sequence of :class:`BlockSpan` is taken and stored as :class:`BlockSpans`.
    source : str
        Program file the path was built from.
    dradius : numpy.ndarray, shape (m,)
        Spiral rate ``dr/dt``, mm per rad of swept angle (0 for lines and circles; the
        default ``None`` means all zero).
    rounding : RoundingTable or None
        What the corner-rounding stage decided per corner
        (:class:`reference.core.rounding.RoundingTable`); ``None`` when the stage did
        not run or no block is in a rounding mode.
    sharpness : numpy.ndarray, shape (m,)
        Clothoid curvature rate, 1/mm^2 (module docstring; 0 on every other segment; the
        default ``None`` means all zero).
    """

    axes: tuple[str, ...]
    geometry: np.ndarray
    rotary: np.ndarray
    origin: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    d: np.ndarray
    radius: np.ndarray
    omega: np.ndarray
    theta0: np.ndarray
    length: np.ndarray
    block: np.ndarray
    kind: np.ndarray
    feed: np.ndarray
    rapid: np.ndarray
    stop: np.ndarray
    stop_reason: tuple[str, ...]
    blocks: BlockSpans
    source: str = ""
    dradius: np.ndarray | None = None
    rounding: RoundingTable | None = None
    sharpness: np.ndarray | None = None
    s_breaks: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "blocks", BlockSpans.of(self.blocks))
        if self.dradius is None:
            object.__setattr__(self, "dradius", np.zeros(np.shape(self.length)))
        if self.sharpness is None:
            object.__setattr__(self, "sharpness", np.zeros(np.shape(self.length)))
        for name in ("origin", "e1", "e2", "d", "radius", "omega", "theta0", "length",
                     "feed", "dradius", "sharpness"):
            object.__setattr__(self, name, _readonly(getattr(self, name)))
        for name in ("geometry", "rotary", "rapid", "stop"):
            a = np.ascontiguousarray(getattr(self, name), dtype=bool)
            a.setflags(write=False)
            object.__setattr__(self, name, a)
        for name, dt in (("block", np.int64), ("kind", np.int8)):
            a = np.ascontiguousarray(getattr(self, name), dtype=dt)
            a.setflags(write=False)
            object.__setattr__(self, name, a)
        m = self.length.size
        n = len(self.axes)
        if self.origin.shape != (m, n) or self.d.shape != (m, n):
            raise PathError(f"packed arrays have shape {self.origin.shape}, expected {(m, n)}")
        if self.stop.shape != (m + 1,) or len(self.stop_reason) != m + 1:
            raise PathError("stop flags must have one entry per segment break (m + 1)")
        if m and not np.all(self.length > 0):
            raise PathError("segments must have positive length")
        sb = np.concatenate(([0.0], np.cumsum(self.length)))
        sb.setflags(write=False)
        object.__setattr__(self, "s_breaks", sb)

    # ---------------------------------------------------------------- queries
    @property
    def n_segments(self) -> int:
        """Number of segments ``m``."""
        return int(self.length.size)

    @property
    def n_axes(self) -> int:
        """Number of axes ``n``."""
        return len(self.axes)

    @property
    def total_length(self) -> float:
        """Total path length, mm."""
        return float(self.s_breaks[-1])

    def segment(self, i: int) -> HelicalSegment:
        """Segment ``i`` as a standalone object (local ``s`` from 0 to its length)."""
        return HelicalSegment(
            origin=self.origin[i], e1=self.e1[i], e2=self.e2[i], d=self.d[i],
            radius=float(self.radius[i]), omega=float(self.omega[i]),
            theta0=float(self.theta0[i]), length=float(self.length[i]),
            source_block=int(self.block[i]), kind=KIND_CODES[int(self.kind[i])],
            dradius=float(self.dradius[i]), sharpness=float(self.sharpness[i]))

    @property
    def segments(self) -> tuple[HelicalSegment, ...]:
        """All segments as objects (builds ``m`` objects; prefer :meth:`evaluate`)."""
        return tuple(self.segment(i) for i in range(self.n_segments))

    def segment_index(self, s: np.ndarray | float, side: Literal["left", "right"] = "right"
                      ) -> np.ndarray:
        """Index of the segment that holds each ``s``.

        Parameters
        ----------
        s : array_like, shape (N,)
            Global path positions, mm.
        side : {"right", "left"}
            At a segment break, ``"right"`` picks the segment that starts there and
            ``"left"`` the one that ends there. The path ends are clamped.

        Returns
        -------
        numpy.ndarray of int, shape (N,)
        """
        s = np.atleast_1d(np.asarray(s, dtype=np.float64))
        idx = np.searchsorted(self.s_breaks, s, side="right" if side == "right" else "left") - 1
        return np.clip(idx, 0, self.n_segments - 1)

    def evaluate(self, s: np.ndarray | float, side: Literal["left", "right"] = "right",
                 segment: np.ndarray | None = None) -> tuple[np.ndarray, ...]:
        """Exact position and derivatives at global path positions.

        Parameters
        ----------
        s : array_like, shape (N,)
            Global path positions in ``[0, total_length]``, mm.
        side : {"right", "left"}
            Which segment to use exactly at a break (see :meth:`segment_index`).
        segment : numpy.ndarray of int, shape (N,), optional
            Segment of each point, when the caller knows it (skips the search).

        Returns
        -------
        q, dq, ddq, dddq : numpy.ndarray
            Each of shape ``(N, n)``: position (mm), tangent ``dq/ds`` (1),
            curvature vector ``d2q/ds2`` (1/mm) and ``d3q/ds3`` (1/mm^2).
        """
        s = np.atleast_1d(np.asarray(s, dtype=np.float64))
        idx = self.segment_index(s, side) if segment is None else np.asarray(segment)
        local = s - self.s_breaks[idx]
        return _eval_helical(self.origin, self.e1, self.e2, self.d, self.radius,
                             self.omega, self.theta0, idx, local, self.dradius, self.length,
                             self.sharpness)

    def moving_axes(self) -> np.ndarray:
        """Indices of the axes that move somewhere on the path (a non-zero in-plane or
        linear component on some segment), in axis order."""
        amp = (np.any(self.e1 != 0, axis=0) | np.any(self.e2 != 0, axis=0)
               | np.any(self.d != 0, axis=0))
        return np.flatnonzero(amp)

    def restricted(self, axes: np.ndarray) -> "Path":
        """The same path on a subset of its axes (columns ``axes``, in that order).

        Exact when the dropped axes never move (:meth:`moving_axes`): their derivatives
        are zero everywhere, so lengths, tangents, curvatures and every axis rule of the
        kept axes are unchanged, and the dropped ones constrain nothing. Used by the
        oracle to size its arrays by the axes that move (a 2-D contour on an XYZ machine
        needs two columns, not three).

        Parameters
        ----------
        axes : numpy.ndarray of int, shape (k,)
            Column indices to keep.

        Returns
        -------
        Path
        """
        ax = np.asarray(axes, dtype=np.int64)
        return Path(axes=tuple(self.axes[i] for i in ax), geometry=self.geometry[ax],
                    rotary=self.rotary[ax], origin=self.origin[:, ax], e1=self.e1[:, ax],
                    e2=self.e2[:, ax], d=self.d[:, ax], radius=self.radius,
                    omega=self.omega, theta0=self.theta0, length=self.length,
                    block=self.block, kind=self.kind, feed=self.feed, rapid=self.rapid,
                    stop=self.stop, stop_reason=self.stop_reason, blocks=self.blocks,
                    source=self.source, dradius=self.dradius, rounding=self.rounding,
                    sharpness=self.sharpness)

    def tangents(self, s: np.ndarray | float, side: Literal["left", "right"] = "right",
                 segment: np.ndarray | None = None) -> np.ndarray:
        """Exact tangents ``dq/ds`` at global path positions, shape (N, n): the
        second output of :meth:`evaluate` (the same numbers), without the others where
        every row is a circle or a line."""
        s = np.atleast_1d(np.asarray(s, dtype=np.float64))
        idx = self.segment_index(s, side) if segment is None else np.asarray(segment)
        return _eval_helical(self.origin, self.e1, self.e2, self.d, self.radius,
                             self.omega, self.theta0, idx, s - self.s_breaks[idx],
                             self.dradius, self.length, self.sharpness,
                             tangent_only=True)[1]

    def junction_tangents(self, lo: int = 0, hi: int | None = None
                          ) -> tuple[np.ndarray, np.ndarray]:
        """Tangents on both sides of every interior break (or of breaks ``lo + 1`` to
        ``hi``: junctions ``lo:hi``, for callers that work in chunks).

        Parameters
        ----------
        lo, hi : int, optional
            Junction range; junction ``k`` lies between segments ``k`` and ``k + 1``.
            Default: all ``m - 1``.

        Returns
        -------
        t_in, t_out : numpy.ndarray, shape (hi - lo, n)
            ``q'`` at the end of segment ``k`` and at the start of segment ``k + 1``.
        """
        m = self.n_segments
        hi = m - 1 if hi is None else min(hi, m - 1)
        lo = max(0, lo)
        if hi <= lo:
            z = np.zeros((0, self.n_axes))
            return z, z
        idx_in = np.arange(lo, hi)
        _, t_in, _, _ = _eval_helical(self.origin, self.e1, self.e2, self.d, self.radius,
                                      self.omega, self.theta0, idx_in, self.length[lo:hi],
                                      self.dradius, self.length, self.sharpness,
                                      tangent_only=True)
        _, t_out, _, _ = _eval_helical(self.origin, self.e1, self.e2, self.d, self.radius,
                                       self.omega, self.theta0, idx_in + 1,
                                       np.zeros(hi - lo), self.dradius, self.length,
                                       self.sharpness, tangent_only=True)
        return t_in, t_out

    def junction_curvatures(self) -> tuple[np.ndarray, np.ndarray]:
        """Curvature vectors ``q''`` on both sides of every interior break, shape (m-1, n)."""
        m = self.n_segments
        if m < 2:
            z = np.zeros((0, self.n_axes))
            return z, z
        idx_in = np.arange(m - 1)
        _, _, k_in, _ = _eval_helical(self.origin, self.e1, self.e2, self.d, self.radius,
                                      self.omega, self.theta0, idx_in, self.length[:-1],
                                      self.dradius, self.length, self.sharpness)
        _, _, k_out, _ = _eval_helical(self.origin, self.e1, self.e2, self.d, self.radius,
                                       self.omega, self.theta0, idx_in + 1, np.zeros(m - 1),
                                       self.dradius, self.length, self.sharpness)
        return k_in, k_out

    def junction_derivatives(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`junction_tangents` and :meth:`junction_curvatures` of every interior
        break from one evaluation of each side: ``(t_in, t_out, k_in, k_out)``, each
        shape (m - 1, n)."""
        m = self.n_segments
        if m < 2:
            z = np.zeros((0, self.n_axes))
            return z, z, z, z
        idx_in = np.arange(m - 1)
        _, t_in, k_in, _ = _eval_helical(self.origin, self.e1, self.e2, self.d, self.radius,
                                         self.omega, self.theta0, idx_in, self.length[:-1],
                                         self.dradius, self.length, self.sharpness,
                                         two_derivatives=True)
        _, t_out, k_out, _ = _eval_helical(self.origin, self.e1, self.e2, self.d,
                                           self.radius, self.omega, self.theta0, idx_in + 1,
                                           np.zeros(m - 1), self.dradius, self.length,
                                           self.sharpness, two_derivatives=True)
        return t_in, t_out, k_in, k_out

    def block_of(self, s: np.ndarray | float) -> np.ndarray:
        """NC block index at each global path position (segment rule ``side="right"``)."""
        return self.block[self.segment_index(s)]


def path_from_pieces(axes: tuple[str, ...], pieces: list[dict[str, np.ndarray]], *,
                     feed: np.ndarray | float | None = None,
                     rapid: np.ndarray | None = None,
                     stop_reason: tuple[str, ...] | None = None,
                     blocks: tuple[BlockSpan, ...] | None = None,
                     rotary: tuple[bool, ...] | None = None,
                     source: str = "") -> Path:
    """Assemble a :class:`Path` from packed pieces (from :func:`line_segments`,
    :func:`arc_segment`).

    Parameters
    ----------
    axes : tuple[str, ...]
        Axis names; X, Y and Z are the geometry axes.
    pieces : list of dict
        Packed parameter dicts, concatenated in order.
    feed : float or numpy.ndarray of shape (m,), optional
        Path-speed cap per segment, mm/s (default ``inf``).
    rapid : numpy.ndarray of bool, shape (m,), optional
        G0 flags (default all False).
    stop_reason : tuple[str, ...], optional
        Length ``m + 1``; the path ends always stop (default: only the ends).
    blocks : tuple[BlockSpan, ...], optional
        Block table; by default one block per segment source block.
    rotary : tuple[bool, ...], optional
        Rotary flags per axis (default: A, B, C are rotary).
    source : str
        File name for messages.

    Returns
    -------
    Path
    """
    keys = ("origin", "e1", "e2", "d", "radius", "omega", "theta0", "length", "block", "kind",
            "dradius", "sharpness")
    n = len(axes)
    if pieces:
        packed = {k: np.concatenate([p[k] if k in p else np.zeros(p["length"].shape)
                                     for p in pieces]) for k in keys}
    else:
        packed = {k: np.zeros((0, n)) if k in ("origin", "e1", "e2", "d") else np.zeros(0)
                  for k in keys}
    m = packed["length"].size
    feed_arr = np.full(m, np.inf) if feed is None else np.broadcast_to(
        np.asarray(feed, dtype=np.float64), (m,)).copy()
    rapid_arr = np.zeros(m, bool) if rapid is None else np.asarray(rapid, bool)
    if stop_reason is None:
        stop_reason = ("start",) + ("",) * (m - 1) + ("end",) if m else ("start",)
    stop_reason = tuple(stop_reason)
    if m:
        stop_reason = (stop_reason[0] or "start",) + stop_reason[1:-1] + (stop_reason[-1] or "end",)
    stop = np.array([bool(r) for r in stop_reason])
    geometry = np.array([a in ("X", "Y", "Z") for a in axes])
    rot = np.array([a in ("A", "B", "C") for a in axes]) if rotary is None else np.array(rotary)
    if blocks is None:
        sb = np.concatenate(([0.0], np.cumsum(packed["length"])))
        spans = []
        blk = packed["block"]
        ids = np.unique(blk) if m else np.zeros(0, int)
        for b in ids:
            segs = np.flatnonzero(blk == b)
            first, last = int(segs[0]), int(segs[-1])
            spans.append(BlockSpan(block=int(b), line=int(b) + 1, label="",
                                   kind=KIND_CODES[int(packed["kind"][first])],
                                   s_start=float(sb[first]), s_end=float(sb[last + 1]),
                                   first_segment=first, n_segments=last - first + 1,
                                   feed_mm_s=float(feed_arr[first]),
                                   stop_reason=stop_reason[last + 1]))
        blocks = tuple(spans)
    return Path(axes=tuple(axes), geometry=geometry, rotary=rot, feed=feed_arr,
                rapid=rapid_arr, stop=stop, stop_reason=stop_reason, blocks=blocks,
                source=source, **packed)
