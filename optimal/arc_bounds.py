"""Tighter ingredients of the lower-bound relaxation on lines, arcs and helices.

Four parts, each proved where it is defined and each only used where it is at least as
tight as the ingredient of :mod:`optimal.bounds` it joins (the relaxation keeps both):

1. :func:`tangential_slope_bound`: a bound of ``|b'|`` free of ``b`` (below);
2. the remainder of the interval-exact rows with ``int |e| <= M D^2 / 4`` (below);
3. :func:`envelope_times`: the time of an interval from one-axis comparison envelopes
   (``b`` relaxes exponentially towards an axis' static limit), instead of a tent of
   slope ``M``;
4. :func:`lower_envelopes` / :func:`envelope_rows`: the curved rows with ``int e``
   bounded below by lower comparison envelopes, affine in the end values.

The relaxation of :mod:`optimal.bounds` loses, on every interval ``I_k`` of length
``D``, a remainder proportional to a bound ``M_k`` of ``|b'| = 2 |a|`` (the term
``int q''_j e`` of the interval-exact rows, and the tent of step 4). That module bounds
``|a|`` from one axis at a time, ``|a| <= (A_j + sup|q''_j| B) / inf|q'_j|``; on an arc
the best axis has ``inf|q'_j|`` near ``1/sqrt 2`` and pays the centripetal part
``sup|q''_j| B`` too, so ``M`` is about ``2 (1 + sqrt 2) sqrt 2 A ~ 6.8 A`` on a circle at
its speed limit. This module gives a bound that does not depend on ``b`` at all.

Tangential projection (why it is valid)
=======================================
On a line, a circular arc or a helix (``Path.dradius == 0``) the packed geometry is
``q(s) = o + r (cos phi e1 + sin phi e2) + d s`` with ``phi = theta0 + omega s``,
``e1, e2`` orthonormal and ``d`` orthogonal to both (:func:`reference.core.geometry.
arc_segments` removes the in-plane part of ``d``). Hence

* ``q' = r omega (-sin phi e1 + cos phi e2) + d`` has the constant norm
  ``|q'|^2 = (r omega)^2 + |d|^2``, and
* ``q' . q'' = 0`` (differentiate ``|q'|^2 = const``).

For any motion with ``|q'_j a + q''_j b| <= A_j`` for every axis ``j`` (the axis
accelerations ``acc_j``), the dot product with ``q'`` removes ``b``:
``q' . acc = |q'|^2 a + (q' . q'') b = |q'|^2 a``, so

    ``|a| <= sum_j |q'_j(s)| A_j / |q'|^2``   pointwise, and on ``I_k``
    ``|b'| <= M_tan,k := 2 sum_j sup_{I_k} |q'_j| A_j / |q'|^2``.

No step uses ``b``; the bound holds for every feasible motion. It never exceeds the
one-axis bound by more than the ratio ``sum_j |q'_j| / |q'|`` (at most ``sqrt n``) and is
2.4-3.4 times smaller on a circle at its speed limit, where the one-axis bound also pays
the centripetal term. Spirals (``dradius != 0``) have ``q' . q'' != 0`` and keep the
one-axis bound only; so do clothoids (``sharpness != 0``), whose packed rows are not of
the helical form above (the argument is only made for that form).

The remainder of the interval-exact rows
========================================
``e = b - b_lin`` (``b_lin`` the chord through the end values, ``delta = b_1 - b_0``)
vanishes at both ends and has ``e' = b' - delta / D`` in ``[-p, m]`` with
``p = M + delta / D >= 0`` and ``m = M - delta / D >= 0``. On each maximal sub-interval of
width ``w`` where ``e`` keeps its sign, ``|e|`` is at most the tent of slopes ``m`` and
``p`` (rising, then falling; or the mirror), of area ``m p w^2 / (2 (m + p))``. The widths
add up to at most ``D``, so ``sum w^2 <= D^2`` and

    ``int |e| <= m p D^2 / (2 (m + p)) = (M^2 - (delta/D)^2) D^2 / (4 M) <= M D^2 / 4``,

hence ``|int q''_j e / 2| <= sup|q''_j| M D^2 / 8`` (the module :mod:`optimal.bounds`
used the point-wise envelope ``2 M t (D - t) / D`` instead, whose integral is
``M D^2 / 3``, giving ``/ 6``).

Units: mm, s. Shapes: ``N`` intervals, ``n`` axes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.core.geometry import Path
from reference.core.limits import AxisArrays

from .tolerances import ENVELOPE_CHUNK

#: Divisor of ``sup|q''_j| M D^2`` in the remainder of an interval-exact row:
#: ``|int q''_j e / 2| <= sup|q''_j| M D^2 / 8`` (module docstring).
REMAINDER_DIVISOR = 8.0


def tangential_slope_bound(path: Path, lim: AxisArrays, segment: np.ndarray,
                           dq_mid: np.ndarray, dq_hi: np.ndarray) -> np.ndarray:
    """``M_tan = 2 sum_j sup|q'_j| A_j / |q'|^2`` on lines, arcs and helices (docstring).

    Parameters
    ----------
    path : Path
        The path.
    lim : AxisArrays
        Limits in the path's axis order.
    segment : numpy.ndarray of int, shape (N,)
        Segment of every interval.
    dq_mid : numpy.ndarray, shape (N, n)
        ``q'`` at the interval mid-points (its norm is that of the whole segment).
    dq_hi : numpy.ndarray, shape (N, n)
        Upper bounds of ``|q'_j|`` on the intervals.

    Returns
    -------
    numpy.ndarray, shape (N,)
        Bound of ``|db/ds|``, mm/s^2; ``inf`` on spirals (no bound from this argument)
        and where ``q' = 0``.
    """
    norm2 = np.sum(dq_mid * dq_mid, axis=1)
    acc = np.sum(dq_hi * lim.a_max[None, :], axis=1)
    ok = (path.dradius[segment] == 0) & (path.sharpness[segment] == 0) & (norm2 > 0)
    out = np.full(segment.size, np.inf)
    out[ok] = 2.0 * acc[ok] / norm2[ok]
    return out


def slope_peak(b0: np.ndarray, b1: np.ndarray, slope: np.ndarray, D: np.ndarray
               ) -> np.ndarray:
    """Largest value on an interval of a function with end values at most ``b0, b1``
    and ``|b'| <= slope``: ``min(b0 + M t, b1 + M (D - t))`` at its crossing.

    Shapes ``(N,)``; ``inf`` where ``slope`` is not finite.
    """
    good = np.isfinite(slope) & (slope > 0)
    M = np.where(good, slope, 1.0)
    tp = np.clip((b1 - b0 + M * D) / (2 * M), 0.0, D)
    peak = np.minimum(b0 + M * tp, b1 + M * (D - tp))
    return np.where(good, peak, np.where(slope == 0, np.maximum(b0, b1), np.inf))


# --------------------------------------------------------------------------- envelopes
def _one_axis_rates(A: np.ndarray, c_lo: np.ndarray, lo: np.ndarray, hi: np.ndarray):
    """Root ``r = A / c_lo`` and the rates ``2 c_lo / lo`` (below it) and
    ``2 c_lo / hi`` (above it) of ``F(b)`` (docstring of :func:`envelope_times`);
    ``usable`` where ``c_lo > 0`` and ``lo > 0``. Shapes ``(N, n)``."""
    usable = (c_lo > 0) & (lo > 0) & np.isfinite(A)
    c = np.where(usable, c_lo, 1.0)
    r = np.where(usable, A / c, np.inf)
    beta_lo = np.where(usable, 2 * c / np.where(usable, lo, 1.0), 0.0)
    beta_hi = np.where(usable, 2 * c / np.where(usable, hi, 1.0), 0.0)
    return usable, r, beta_lo, beta_hi


def _relax(b0, r, beta_lo, beta_hi, t):
    """``y(t)`` of ``y' = F(y)``, ``y(0) = b0``: ``r - (r - b0) e^{-beta t}`` with
    ``beta = beta_lo`` below the root and ``beta_hi`` above it."""
    beta = np.where(b0 <= r, beta_lo, beta_hi)
    return b0 + (r - b0) * (-np.expm1(-beta * t)), beta


def _time_under(b0, r, beta_lo, beta_hi, B, t1):
    """``int_0^t1 dt / sqrt(min(y(t), B))`` for the relaxation ``y`` of :func:`_relax`
    (``0 < b0 <= B``, ``r`` finite, ``beta > 0``), closed form.

    With ``w = sqrt(y / r)``: ``d/dt [t + (2 / beta) ln(1 + w)] = 1 / w`` on both sides of
    the root, so ``int dt / sqrt(y) = [t + (2 / beta) ln(1 + w)] / sqrt(r)``. Below the
    root ``y`` rises and may reach ``B`` at ``t_B = ln((r - b0) / (r - B)) / beta``; the
    rest of the way ``min(y, B) = B``.
    """
    beta = np.where(b0 <= r, beta_lo, beta_hi)
    rising = (b0 < r) & (B < r)
    with np.errstate(divide="ignore", invalid="ignore"):
        tB = np.where(rising, np.log((r - b0) / np.where(rising, r - B, 1.0)) / beta, np.inf)
    te = np.minimum(t1, np.maximum(tB, 0.0))
    # y1 - b0 formed directly (not as the difference of y1 and b0, which cancels when
    # b0 >> r and beta te is small, and the log below would amplify that error by w)
    dy = (r - b0) * (-np.expm1(-beta * te))
    y1 = b0 + dy
    sy0, sy1 = np.sqrt(b0), np.sqrt(np.maximum(y1, 0.0))
    sr = np.sqrt(r)
    # ln((1 + w1) / (1 + w0)) without cancellation: w1 - w0 = (y1 - y0) / (sr (sy1 + sy0))
    dw = dy / (sr * (sy1 + sy0))
    part = (te + (2.0 / beta) * np.log1p(dw / (1.0 + sy0 / sr))) / sr
    return part + np.maximum(t1 - te, 0.0) / np.sqrt(B)


def _envelope_times(D: np.ndarray, b0: np.ndarray, b1: np.ndarray, B: np.ndarray,
                   A: np.ndarray, dq_mid: np.ndarray, ddq_mid: np.ndarray, lo: np.ndarray,
                   hi: np.ndarray, k3: np.ndarray, iterations: int = 8) -> np.ndarray:
    """Lower estimate of the time on every interval from one-axis comparison envelopes.

    Why it is one
    -------------
    Take an axis ``j`` whose tangent keeps its sign ``sigma`` on ``I_k`` (``inf|q'_j| =
    lo_j > 0``) and let ``c_j(s) = sigma q''_j(s)``, so ``c_j >= c_lo := sigma
    q''_j(mid) - (D / 2) sup|q'''_j|`` on ``I_k``. The row ``|q'_j a + q''_j b| <= A_j``
    gives, for every feasible motion (``b >= 0``),

    * forward: ``|q'_j| a <= A_j - c_j b <= A_j - c_lo b``, hence
      ``b' = 2a <= F(b) := 2 (A_j - c_lo b) / lo_j`` where that is ``>= 0`` and
      ``2 (A_j - c_lo b) / hi_j`` where it is negative (a negative numerator over the
      largest ``|q'_j|``);
    * backward: ``-|q'_j| a <= A_j + c_j b``, the same with ``c_j`` replaced by
      ``-c_j`` (``-b'`` bounded, ``s`` run backwards from ``s_{k+1}``).

    With ``c_lo > 0``, ``F`` is decreasing and Lipschitz, so by the comparison lemma
    ``b(s_k + t) <= y_f(t)``, the solution of ``y' = F(y)``, ``y(0) = b_k``, which relaxes
    exponentially towards the root ``r = A_j / c_lo`` (:func:`_relax`); likewise
    ``b(s_{k+1} - t) <= y_b(t)`` from the end value. ``b_k, b_{k+1}`` are upper bounds of
    ``b`` at the nodes (the relaxation's optimum): the comparison lemma (``b`` absolutely
    continuous, ``b' <= F(b)`` almost everywhere, ``F`` Lipschitz, ``b <= y`` at the
    start) needs no more. Also ``b <= B`` on ``I_k``. For *any* split
    ``t*`` in ``[0, D]``, ``1 / sqrt(b) >= 1 / sqrt(min(y_f, B))`` on ``[0, t*]`` and
    ``>= 1 / sqrt(min(y_b, B))`` on ``[t*, D]``, so the time on ``I_k`` is at least the
    sum of the two closed-form integrals (:func:`_time_under`). ``t*`` is the crossing of
    ``y_f`` and ``y_b`` by bisection (only its accuracy, not the validity, depends on
    it). The axis of each side is the one whose envelope is lowest at the mid-point.

    Intervals where no axis qualifies on a side (lines, a tangent component changing
    sign, ``c_lo <= 0``) get 0 here (the tent of :func:`optimal.bounds.tent_times`
    remains); the caller takes the larger of the two valid estimates.

    Parameters
    ----------
    D : numpy.ndarray, shape (N,)
        Interval lengths, mm.
    b0, b1 : numpy.ndarray, shape (N,)
        Upper bounds of ``b`` at the interval ends, mm^2/s^2.
    B : numpy.ndarray, shape (N,)
        Upper bound of ``b`` on each interval, mm^2/s^2.
    A : numpy.ndarray, shape (n,)
        Axis acceleration limits, mm/s^2.
    dq_mid, ddq_mid : numpy.ndarray, shape (N, n)
        ``q'`` and ``q''`` at the interval mid-points.
    lo, hi : numpy.ndarray, shape (N, n)
        Lower and upper bounds of ``|q'_j|`` on the intervals.
    k3 : numpy.ndarray, shape (N, n)
        Upper bound of ``|q'''_j|`` on the intervals' segments, 1/mm^2.
    iterations : int
        Bisection steps for the split (D / 256 after 8: the split only moves the estimate
        by a second-order amount, never its validity).

    Returns
    -------
    numpy.ndarray, shape (N,)
        Seconds (0 where not applicable).
    """
    N = D.size
    out = np.zeros(N)
    if N == 0:
        return out
    sig = np.sign(dq_mid)
    half = 0.5 * D[:, None]
    Ab = np.broadcast_to(A[None, :], dq_mid.shape)
    fwd = _one_axis_rates(Ab, sig * ddq_mid - half * k3, lo, hi)
    bwd = _one_axis_rates(Ab, -sig * ddq_mid - half * k3, lo, hi)
    Bc = np.where(np.isfinite(B), B, np.inf)
    x0 = np.minimum(np.maximum(b0, 0.0), Bc)
    x1 = np.minimum(np.maximum(b1, 0.0), Bc)

    def pick(rates, x):
        usable, r, bl, bh = rates
        y, _ = _relax(x[:, None], np.where(usable, r, x[:, None]), bl, bh, half)
        y = np.where(usable, y, np.inf)
        j = np.argmin(y, axis=1)
        ar = np.arange(N)
        return usable[ar, j], r[ar, j], bl[ar, j], bh[ar, j]

    uf, rf, blf, bhf = pick(fwd, x0)
    ub, rb, blb, bhb = pick(bwd, x1)
    ok = uf & ub & np.isfinite(Bc) & (x0 > 0) & (x1 > 0) & (Bc > 0)
    if not np.any(ok):
        return out
    d, x0, x1, Bc = D[ok], x0[ok], x1[ok], Bc[ok]
    rf, blf, bhf, rb, blb, bhb = rf[ok], blf[ok], bhf[ok], rb[ok], blb[ok], bhb[ok]
    lo_t, hi_t = np.zeros(d.size), d.copy()
    for _ in range(iterations):          # crossing of y_f(t) and y_b(D - t)
        mid = 0.5 * (lo_t + hi_t)
        yf, _ = _relax(x0, rf, blf, bhf, mid)
        yb, _ = _relax(x1, rb, blb, bhb, d - mid)
        left = yf < yb
        lo_t = np.where(left, mid, lo_t)
        hi_t = np.where(left, hi_t, mid)
    ts = 0.5 * (lo_t + hi_t)
    out[ok] = (_time_under(x0, rf, blf, bhf, Bc, ts)
               + _time_under(x1, rb, blb, bhb, Bc, d - ts))
    return out


# --------------------------------------------------------------------------- rows
def _phi_psi(kappa: np.ndarray, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``Phi = int_0^tau e^{2 kappa t} dt`` and ``Psi = int_0^tau Phi(t) dt``, stable at
    ``kappa -> 0`` (``tau`` and ``tau^2 / 2``)."""
    x = 2.0 * kappa * tau
    small = np.abs(x) < 1e-3
    xs = np.where(small, 1.0, x)
    with np.errstate(over="ignore", invalid="ignore"):
        f1 = np.where(small, 1 + x * (0.5 + x * (1 / 6 + x / 24)), np.expm1(xs) / xs)
        f2 = np.where(small, 0.5 + x * (1 / 6 + x * (1 / 24 + x / 120)),
                      (np.expm1(xs) - xs) / (xs * xs))
    return tau * f1, tau * tau * f2


def _lower_rates(A: np.ndarray, c_lo: np.ndarray, lo: np.ndarray, hi: np.ndarray):
    """``g = 2 A / lo`` and ``kappa`` (``c_lo / hi`` if ``c_lo >= 0`` else ``c_lo / lo``)
    of the affine bound ``(A - c(s) b) / |q'(s)| <= A / lo - kappa b`` (``b >= 0``);
    ``usable`` where ``lo > 0``. Shapes ``(N, n)``."""
    usable = (lo > 0) & np.isfinite(A)
    los = np.where(usable, lo, 1.0)
    his = np.where(usable, hi, 1.0)
    kappa = np.where(c_lo >= 0, c_lo / his, c_lo / los)
    return usable, np.where(usable, 2 * A / los, np.inf), np.where(usable, kappa, 0.0)


def envelope_rows(env: "LowerEnvelopes", k3: np.ndarray, slope: np.ndarray, j: int,
                  c: np.ndarray):
    """Second-order form of the interval-exact row of axis ``j`` where ``c > 0``.

    Why it is valid
    ---------------
    The row ``sigma int (q'_j a + q''_j b) <= A_j D`` reads exactly
    ``sigma [q'_j b] / 2 + sigma (I0 b_k + I1 b_{k+1}) + sigma int q''_j e / 2 <= A_j D``
    (:mod:`optimal.bounds`, ``e = b - b_lin``). With ``c = sigma q''_j(mid) > 0`` and
    ``|sigma q''_j(s) - c| <= |s - mid| sup|q'''_j|``,
    ``sigma int q''_j e >= c int e - sup|q'''_j| int |s - mid| |e| >= c int e
    - sup|q'''_j| M D^3 / 16`` (``|e| <= 2 M t (D - t) / D``). And
    ``int e = int b - D (b_k + b_{k+1}) / 2 >= int L - D (b_k + b_{k+1}) / 2`` for any
    lower bound ``L`` of ``b`` on the interval. Lower envelopes, by the comparison lemma
    from the *actual* end values: forward, ``b' = 2 a >= -2 (A_m - ct_m b) / |q'_m|``
    (``ct_m = -sigma_m q''_m``, any axis ``m`` whose tangent keeps its sign
    ``sigma_m``), which is ``>= -(g - 2 kappa b)`` with ``g = 2 A_m / inf|q'_m|`` and
    ``kappa`` from the interval bounds (:func:`_lower_rates`); so
    ``b(s_k + t) >= z_f(t) = b_k e^{2 kappa t} - g Phi(t)``. Backward from ``b_{k+1}``
    the same with the acceleration side (``c_m = sigma_m q''_m``); or, for either side,
    ``|b'| <= M`` (``kappa = 0``, ``g = M``). ``z`` is affine in its start value, so
    with ``L = z_f`` on ``[0, t*]`` and ``z_b`` on ``[t*, D]`` for any split ``t*``,
    ``int L = Phi_f(t*) b_k - g_f Psi_f(t*) + Phi_b(D - t*) b_{k+1} - g_b Psi_b(D - t*)``
    and the row becomes linear in ``(b_k, b_{k+1})``:

        ``old row + (c / 2) [(Phi_f - D/2) b_k + (Phi_b - D/2) b_{k+1}]
        <= A_j D + (c / 2) (g_f Psi_f + g_b Psi_b) + sup|q'''_j| M D^3 / 32``.

    Validity holds for every split and every choice of axes; the guide values (an
    earlier relaxation's optimum) only choose them, so that the envelope from the side
    where ``b`` moves at its capacity is used: then ``L`` follows ``b`` to ``O(D^2)``
    and the row is tight to third order per interval (the old remainder
    ``sup|q''_j| M D^2 / 8`` is second order).

    Parameters
    ----------
    env : LowerEnvelopes
        The envelopes and splits of every interval (:func:`lower_envelopes`).
    k3 : numpy.ndarray, shape (N, n)
        Upper bounds of the third derivative ``|q^(3)_j|`` on the intervals, 1/mm^2.
    slope : numpy.ndarray, shape (N,)
        Bound ``M`` of ``|b'|`` on the intervals, mm/s^2.
    j : int
        Axis of the row.
    c : numpy.ndarray, shape (N,)
        ``sigma q''_j(mid)``; the row is formed where ``c > 0``.

    Returns
    -------
    ok : numpy.ndarray of bool, shape (N,)
        Where the row is formed.
    dc1, dc2 : numpy.ndarray, shape (N,)
        Added to the coefficients of ``b_k`` and ``b_{k+1}`` (row divided by ``D``).
    rhs : numpy.ndarray, shape (N,)
        The right-hand side's addition ``((c/2)(g_f Psi_f + g_b Psi_b) +
        sup|q'''_j| M D^3 / 32) / D`` (mm/s^2) where ``ok``.
    """
    ok = env.ok & (c > 0)
    dc1 = np.zeros(c.size)
    dc2 = np.zeros(c.size)
    rhs = np.zeros(c.size)
    if not np.any(ok):
        return ok, dc1, dc2, rhs
    d, cc = env.D[ok], c[ok]
    dc1[ok] = 0.5 * cc * (env.phi_f[ok] - 0.5 * d) / d
    dc2[ok] = 0.5 * cc * (env.phi_b[ok] - 0.5 * d) / d
    rhs[ok] = (0.5 * cc * (env.g_f[ok] * env.psi_f[ok] + env.g_b[ok] * env.psi_b[ok])
               + k3[ok, j] * slope[ok] * d ** 3 / 32) / d
    return ok, dc1, dc2, rhs


@dataclass(frozen=True, slots=True, eq=False)
class LowerEnvelopes:
    """The lower envelopes of every interval and their integrals up to the split
    (:func:`lower_envelopes`); shapes ``(N,)``."""

    ok: np.ndarray        # envelopes on both sides exist and stay finite
    D: np.ndarray         # interval lengths, mm
    phi_f: np.ndarray     # Phi_f(t*), coefficient of b_k in int_0^t* z_f
    psi_f: np.ndarray     # Psi_f(t*)
    g_f: np.ndarray       # g of the forward envelope, mm/s^2
    phi_b: np.ndarray     # Phi_b(D - t*), coefficient of b_{k+1}
    psi_b: np.ndarray     # Psi_b(D - t*)
    g_b: np.ndarray       # g of the backward envelope, mm/s^2


def _lower_envelopes(D: np.ndarray, guide0: np.ndarray, guide1: np.ndarray, A: np.ndarray,
                    dq_mid: np.ndarray, ddq_mid: np.ndarray, lo: np.ndarray,
                    hi: np.ndarray, k3: np.ndarray, slope: np.ndarray,
                    iterations: int = 8) -> LowerEnvelopes:
    """Choose the lower envelopes and the split of every interval (:func:`envelope_rows`).

    The candidates of each side are every axis whose tangent keeps its sign, and
    ``|b'| <= M``; the one highest at the mid-point when started from the guide value
    is taken, and ``t*`` is where the two meet (bisection). Validity does not depend on
    these choices, only the tightness does.

    Parameters
    ----------
    D : numpy.ndarray, shape (N,)
        Interval lengths, mm.
    guide0, guide1 : numpy.ndarray, shape (N,)
        Guide values of ``b`` at the interval ends (any finite numbers), mm^2/s^2.
    A : numpy.ndarray, shape (n,)
        Axis acceleration limits, mm/s^2.
    dq_mid, ddq_mid, lo, hi, k3 : numpy.ndarray, shape (N, n)
        Mid-point ``q'`` and ``q''``, bounds of ``|q'_j|`` and of the third derivative.
    slope : numpy.ndarray, shape (N,)
        Bound ``M`` of ``|b'|`` on the intervals (``inf``: none), mm/s^2.
    iterations : int
        Bisection steps for the split.

    Returns
    -------
    LowerEnvelopes
    """
    N = D.size
    sig = np.sign(dq_mid)
    half = 0.5 * D[:, None]
    Ab = np.broadcast_to(A[None, :], dq_mid.shape)
    fin_m = np.isfinite(slope) & (slope > 0)
    # candidates: every axis, plus |b'| <= M (last column)
    uf, gf, kf = _lower_rates(Ab, -sig * ddq_mid - half * k3, lo, hi)
    ub, gb, kb = _lower_rates(Ab, sig * ddq_mid - half * k3, lo, hi)
    Mcol = np.where(fin_m, slope, np.inf)[:, None]
    uf = np.c_[uf, fin_m]
    ub = np.c_[ub, fin_m]
    gf, gb = np.c_[gf, Mcol], np.c_[gb, Mcol]
    kf, kb = np.c_[kf, np.zeros(N)], np.c_[kb, np.zeros(N)]
    g0 = np.maximum(guide0, 0.0)[:, None]
    g1 = np.maximum(guide1, 0.0)[:, None]

    def best(usable, g, kappa, start):
        ph, _ = _phi_psi(kappa, np.broadcast_to(half, kappa.shape))
        with np.errstate(over="ignore", invalid="ignore"):
            z = start * np.exp(2 * kappa * half) - np.where(usable, g, 0.0) * ph
        z = np.where(usable & np.isfinite(z), z, -np.inf)
        m = np.argmax(z, axis=1)
        ar = np.arange(N)
        return usable[ar, m], g[ar, m], kappa[ar, m]

    okf, gf1, kf1 = best(uf, gf, kf, g0)
    okb, gb1, kb1 = best(ub, gb, kb, g1)
    ok = okf & okb & fin_m & np.isfinite(gf1) & np.isfinite(gb1)
    # the envelopes must stay finite over the whole interval (no overflow of e^{2 kappa D})
    ok &= (np.abs(2 * kf1 * D) < 50.0) & (np.abs(2 * kb1 * D) < 50.0)
    zero = np.zeros(N)
    if not np.any(ok):
        return LowerEnvelopes(ok, D, zero, zero, zero, zero, zero, zero)
    d = D[ok]
    x0, x1 = g0[ok, 0], g1[ok, 0]
    gfo, kfo, gbo, kbo = gf1[ok], kf1[ok], gb1[ok], kb1[ok]

    def z(x, g, kappa, t):
        ph, _ = _phi_psi(kappa, t)
        return x * np.exp(2 * kappa * t) - g * ph

    lo_t, hi_t = np.zeros(d.size), d.copy()
    for _ in range(iterations):            # where z_f(t) meets z_b(D - t)
        mid = 0.5 * (lo_t + hi_t)
        above = z(x0, gfo, kfo, mid) > z(x1, gbo, kbo, d - mid)
        lo_t = np.where(above, mid, lo_t)
        hi_t = np.where(above, hi_t, mid)
    ts = 0.5 * (lo_t + hi_t)
    phf, psf = zero.copy(), zero.copy()
    phb, psb = zero.copy(), zero.copy()
    phf[ok], psf[ok] = _phi_psi(kfo, ts)
    phb[ok], psb[ok] = _phi_psi(kbo, d - ts)
    return LowerEnvelopes(ok, D, phf, psf, np.where(ok, gf1, 0.0), phb, psb,
                          np.where(ok, gb1, 0.0))


# --------------------------------------------------------------------------- chunking
def _chunked(fn, D, per_interval, shared, kwargs):
    """Run the element-wise ``fn`` on chunks of :data:`ENVELOPE_CHUNK` intervals: its
    temporaries are a few dozen ``(chunk, n + 1)`` arrays, so the memory it needs stays
    bounded whatever the grid size (the results are the same: every interval is
    computed on its own)."""
    N = D.size
    if N <= ENVELOPE_CHUNK:
        return fn(D, *per_interval, *shared, **kwargs), None
    parts = [fn(D[lo:lo + ENVELOPE_CHUNK], *(a[lo:lo + ENVELOPE_CHUNK] for a in per_interval),
                *shared, **kwargs) for lo in range(0, N, ENVELOPE_CHUNK)]
    return None, parts


def envelope_times(D: np.ndarray, b0: np.ndarray, b1: np.ndarray, B: np.ndarray,
                   A: np.ndarray, dq_mid: np.ndarray, ddq_mid: np.ndarray, lo: np.ndarray,
                   hi: np.ndarray, k3: np.ndarray, iterations: int = 8) -> np.ndarray:
    """Lower estimate of the time on every interval from one-axis comparison envelopes
    (the argument, parameters and returns: :func:`_envelope_times`), in chunks of
    :data:`ENVELOPE_CHUNK` intervals."""
    one, parts = _chunked(lambda d, x0, x1, b, dm, ddm, l, h, k, a: _envelope_times(
        d, x0, x1, b, a, dm, ddm, l, h, k, iterations), D,
        (b0, b1, B, dq_mid, ddq_mid, lo, hi, k3), (A,), {})
    return one if parts is None else np.concatenate(parts)


def lower_envelopes(D: np.ndarray, guide0: np.ndarray, guide1: np.ndarray, A: np.ndarray,
                    dq_mid: np.ndarray, ddq_mid: np.ndarray, lo: np.ndarray,
                    hi: np.ndarray, k3: np.ndarray, slope: np.ndarray,
                    iterations: int = 8) -> "LowerEnvelopes":
    """Choose the lower envelopes and the split of every interval
    (:func:`_lower_envelopes` has the argument), in chunks of :data:`ENVELOPE_CHUNK`
    intervals."""
    one, parts = _chunked(lambda d, g0, g1, dm, ddm, l, h, k, m, a: _lower_envelopes(
        d, g0, g1, a, dm, ddm, l, h, k, m, iterations), D,
        (guide0, guide1, dq_mid, ddq_mid, lo, hi, k3, slope), (A,), {})
    if parts is None:
        return one
    return LowerEnvelopes(*(np.concatenate([getattr(p, f) for p in parts])
                            for f in LowerEnvelopes.__slots__))
