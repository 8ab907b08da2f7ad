"""Certified lower bound and checker-verified upper bound of the minimum time.

Lower bound: why it is one
==========================
Let ``b(s) = v(s)^2`` be *any* motion that satisfies the continuous problem: ``b`` is
Lipschitz (``b' = 2a``), ``b <= (v_max_j / |q'_j|)^2`` and ``b <= F^2`` everywhere,
``|q'_j(s) a + q''_j(s) b| <= A_j`` almost everywhere, ``b = 0`` at stops and
``v |t_out_j - t_in_j| <= jump_j`` at breaks. Its time is ``T = int ds / sqrt(b)``.

1. *A-priori bounds per interval* ``I_k = [s_k, s_{k+1}]`` (one segment, length ``D``):
   ``b <= Bbar_k`` on ``I_k``, where ``Bbar_k`` is the smallest of the feed, the axis
   velocity caps with ``|q'_j|`` bounded below on ``I_k`` (mid value minus
   ``D/2 sup|q''_j|``) and, on arcs, the two-axis elimination
   ``|q'_l q''_j - q'_j q''_l| b <= |q'_l| A_j + |q'_j| A_i`` (``a`` eliminated; the
   coefficient is bounded below via ``sup|q'''|``). Then ``|a| <= (A_j + sup|q''_j| Bbar)
   / inf|q'_j|`` for every axis ``j``, so ``|b'| <= M_k`` (twice the best such bound);
   on lines, arcs and helices also ``|b'| <= 2 sum_j sup|q'_j| A_j / |q'|^2``, free of
   ``b`` (``q' . q'' = 0`` there; proof in :mod:`optimal.arc_bounds`), and ``M_k`` is the
   smaller of the two.
2. *Interval-exact rows.* Integrating ``q'_j a + q''_j b`` over ``I_k`` by parts
   (``a = b'/2``) gives exactly
   ``[q'_j b]_{s_k}^{s_{k+1}} / 2 + int q''_j b / 2 ds``, and its average is at most
   ``A_j`` (and at least ``-A_j``). Writing ``b = b_lin + e`` with ``b_lin`` the chord
   through the end values, ``int |e| <= M D^2 / 4`` (tents of slope ``M`` on each
   one-signed part of ``e``, :mod:`optimal.arc_bounds`), so
   ``|int q''_j e / 2| <= sup|q''_j| M D^2 / 8 =: E_jk``. Hence the end values satisfy the
   linear rows ``sigma ([q'_j b]/2 + w0 b_k + w1 b_{k+1}) <= A_j D + E_jk`` with
   ``w0, w1 = int q''_j (1 - t/D) / 2, int q''_j (t/D) / 2`` (closed form on helices).
   On spiral arcs and on clothoids (curvature varying along the segment; the kinds
   without the helix closed forms, :func:`_varying_curvature`) ``sup|q''_j|`` and
   ``sup|q'''_j|`` are the segment's worst values
   (:func:`reference.core.geometry.plane_amplitudes`) and the weights come by parts,
   ``w0 = (dq/D - q'_j(s_k)) / 2``, ``w1 = (q'_j(s_{k+1}) - dq/D) / 2`` (``dq`` the
   exact chord; both identities hold for every smooth curve), whose round-off bound
   times ``Bbar_k`` is added to ``E_jk``.
   On lines ``q'' = 0``: the row is the exact ``|q'_j (b_{k+1} - b_k)| / (2D) <= A_j``.
   From the second round on (or with node bounds from a coarser grid) each curved row
   where ``sigma q''_j(mid) > 0`` is replaced by a sharper form (dropping the old one
   only relaxes, and the new one is valid on its own): ``int e`` is
   bounded below by lower comparison envelopes from both actual end values, affine in
   them, so the row stays linear (:func:`optimal.arc_bounds.envelope_rows`, proof
   there); the previous round's optimum only chooses the envelopes and their split.
   Rows that are not in lattice form are relaxed further (one term dropped, ``b >= 0``).
2b. *Energy rows.* For every axis, ``(q'_j^2 b)' = 2 q'_j (q'_j a + q''_j b)`` (the
   squared axis velocity ``v_j^2 = q'_j^2 b``), so integrating over ``I_k`` with
   ``|q'_j a + q''_j b| <= A_j`` gives exactly
   ``|q'_j(s_{k+1})^2 b_{k+1} - q'_j(s_k)^2 b_k| <= 2 A_j int_{I_k} |q'_j| ds``: an axis
   gains or loses at most ``2 A_j`` of squared velocity per mm of its travel. No
   remainder, any geometry; the travel is the exact chord ``|Delta q_j|`` where ``q'_j``
   keeps its sign (``inf|q'_j| > 0``; on lines and helices in the cancellation-free form
   ``D (sinc(omega D / 2) (q'_mid - d) + d)``, on spirals the chord of the exact positions
   plus its round-off bound) and ``D sup|q'_j|`` elsewhere. These rows are what makes the
   bound converge fast where the optimum follows an axis' acceleration limit along an
   arc: the averaged rows above admit node values that only a motion dipping inside
   the intervals could reach, and the time estimate of step 4 does not charge for the
   dip, a first-order loss (measured on 60 tangent S-bends, 7,797 points: the bound's
   distance below the converged time fell from 0.28 % to 0.11 %, at 15,593 points from
   0.11 % to 0.04 %).
3. *Node caps* are those of the continuous problem at the nodes (velocity on both sides,
   feed, stops, the junction rule with the checker's allowance), plus ``Bbar`` of both
   neighbouring intervals. So the node values ``(b(s_k))`` are feasible for this
   relaxed discrete problem, whose greatest element ``bhat`` (solved exactly by
   :mod:`optimal.backends.fast`) therefore dominates them: ``b(s_k) <= bhat_k``.
4. *Time.* On ``I_k``, ``b(s) <= min(Bbar_k, bhat_k + M t, bhat_{k+1} + M (D - t))``
   (Lipschitz from both ends), so ``T >= sum_k int_0^D dt / sqrt(that tent)``, a closed
   form. On arcs the one-axis comparison envelopes of
   :func:`optimal.arc_bounds.envelope_times` (exponential relaxation towards the axis'
   static limit, from both ends) give another valid estimate; each interval takes the
   larger. This is ``lower_bound_s`` (less ``LB_ROUNDOFF_REL`` for round-off), plus dwells.

5. *Energy node bounds inside curved intervals.* Cut a curved interval into ``P`` equal
   pieces. At an inner point ``s``, integrating step 2b's identity from either end
   gives, for every axis with ``q'_j(s) != 0``,
   ``b(s) <= (q'_j(s_k)^2 bhat_k + 2 A_j int_{s_k}^{s} |q'_j|) / q'_j(s)^2`` and the same
   from ``s_{k+1}`` (the travel: where ``q'_j`` keeps its sign on the interval, the sum
   of the pieces' exact chords, on helices in the cancellation-free form of step 2b;
   else length times ``sup|q'_j|``); also the tent of step 4. These hold for every feasible motion, and
   the energy bound is *equal* to ``b(s)`` where one axis stays at its acceleration
   limit, which is where the tent and the one-axis envelopes of step 4 lose most. Step
   4 on the pieces with these node bounds (the parent's bounds of ``b``, ``|b'|``,
   ``|q'_j|`` and ``|q'''_j|`` hold on every piece; the pieces' own mid-point values
   and a-priori bound tighten them) bounds the time on each piece; their sum is a lower
   estimate of the interval's time, and each interval takes the larger of this and
   step 4 (:func:`subnode_times`, used by the oracle with
   :data:`~optimal.tolerances.LB_SUB_PIECES` pieces).

Every step only weakens constraints or over-estimates ``b``; the bound holds for every
grid. On lines it is exact wherever the optimum accelerates at the limit. On arcs the
node values converge at second order with the energy rows (step 2b) where the optimum
follows an axis limit. With steps 1-4 alone, most of the remaining distance below the
minimum time was the time estimate inside the intervals, not the node values (200
tangent S-bends, 12,213 equal-spaced points: step 4 from the *true* node values still
lost 0.23 %, from the relaxation's 0.29 %); step 5 with 4 pieces brings the bound from
0.285 % to 0.064 % below the converged time there (0.092 % to about 0.02 % at 24,094
points), so on arc-dense paths it is now the grid optimum behind the upper bound that
sets the number of grid points (0.16 % above at 12,213 points).

Upper bound
===========
The motion behind the grid optimum, judged by ``check_profile`` and time-scaled until it
is accepted, lives in :mod:`optimal.upper`.

Units: mm, s. Shapes: ``N`` intervals, ``n`` axes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.core.geometry import Path, plane_amplitudes
from reference.core.limits import AxisArrays

from .arc_bounds import (REMAINDER_DIVISOR, envelope_rows, envelope_times, lower_envelopes,
                         slope_peak, tangential_slope_bound)
from .backends.fast import sweep
from .grid import Grid
from .problem import (CAP_BOUND, DiscreteProblem, RowWriter, _assemble, common_node_caps,
                      interval_geometry, interval_times, moving_axes, pair_mvc)
from .tolerances import ENVELOPE_CHUNK, LB_ROUND_IMPROVEMENT, LB_ROUNDOFF_REL, LB_ROUNDS


@dataclass(frozen=True, slots=True, eq=False)
class Relaxation:
    """The lower-bound relaxation on one grid and its a-priori interval bounds.

    Attributes
    ----------
    problem : DiscreteProblem
        The relaxed discrete problem (``kind = "relaxed"``).
    b_bar : numpy.ndarray, shape (N,)
        Upper bound of ``b`` on each interval, mm^2/s^2.
    slope : numpy.ndarray, shape (N,)
        Upper bound ``M_k`` of ``|db/ds|`` on each interval, mm/s^2.
    """

    problem: DiscreteProblem
    b_bar: np.ndarray
    slope: np.ndarray


def _g_series(x: np.ndarray) -> np.ndarray:
    """``(sin x - x cos x) / x^2`` without cancellation (odd, ~ x/3 near 0)."""
    out = np.empty_like(x)
    small = np.abs(x) < 1e-2
    xs = x[small]
    x2 = xs * xs
    out[small] = xs * (1 / 3 - x2 * (1 / 30 - x2 * (1 / 840 - x2 / 45360)))
    xl = x[~small]
    out[~small] = (np.sin(xl) - xl * np.cos(xl)) / (xl * xl)
    return out


@dataclass(frozen=True, slots=True, eq=False)
class _IntervalData:
    """Grid-dependent data of the relaxation, computed once per grid."""

    ds: np.ndarray            # (N,)
    dq0: np.ndarray           # (N, n) tangent at interval starts
    dq1: np.ndarray           # (N, n) tangent at interval ends
    k2: np.ndarray            # (N, n) sup |q''_j| on the segment
    lo: np.ndarray            # (N, n) inf |q'_j| on the interval
    I0: np.ndarray            # (N, n) int q''_j (1 - t/D) / 2
    I1: np.ndarray            # (N, n) int q''_j (t/D) / 2
    b_static: np.ndarray      # (N,) a-priori bound of b on the interval
    node_mvc: np.ndarray      # (N + 1,) static maximum-velocity curve at the nodes
    axes_used: np.ndarray     # indices of moving axes
    ierr: np.ndarray          # (N, n) round-off bound of |I0| + |I1| (spirals; else 0)
    slope_tan: np.ndarray     # (N,) b-free bound of |b'| (optimal.arc_bounds; inf spirals)
    dq_mid: np.ndarray        # (N, n) q' at interval mid-points
    ddq_mid: np.ndarray       # (N, n) q'' at interval mid-points
    hi: np.ndarray            # (N, n) sup |q'_j| on the interval
    k3: np.ndarray            # (N, n) sup |q'''_j| on the segment
    travel: np.ndarray        # (N, n) upper bound of the axis travel int |q'_j| on I_k
    mono: np.ndarray          # (N, n) -1/+1: b falls/rises where above the axis' S_j; 0
    s_max: np.ndarray         # (N, n) sup of S_j = A_j / |q''_j| on I_k (where mono != 0)


def _sinusoid_range(c: np.ndarray, ph: np.ndarray, off: np.ndarray, pa: np.ndarray,
                    pb: np.ndarray, va: np.ndarray, vb: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Range of ``c cos(phi - ph) + off`` for ``phi`` between ``pa`` and ``pb``.

    ``va, vb`` are its values at the ends (evaluated by the caller with the path's own
    formulas, so that the ends agree with the rest of the code to the last bit); the
    interior extremes are at ``phi = ph + k pi`` with values ``(-1)^k c + off``.

    Shapes: ``c, ph, off, va, vb`` (K, n); ``pa, pb`` (K,).
    """
    lo = np.minimum(va, vb)
    hi = np.maximum(va, vb)
    p0 = np.minimum(pa, pb)[:, None]
    p1 = np.maximum(pa, pb)[:, None]
    k = np.ceil((p0 - ph) / np.pi)
    for _ in range(3):                 # 2 interior extremes at most below 2 pi of sweep
        crit = ph + k * np.pi
        inside = (crit > p0) & (crit < p1)
        val = c * np.where(np.mod(k, 2) == 0, 1.0, -1.0) + off
        lo = np.where(inside, np.minimum(lo, val), lo)
        hi = np.where(inside, np.maximum(hi, val), hi)
        k = k + 1
    wide = (p1 - p0)[:, 0] >= 2.0 * np.pi
    if np.any(wide):                   # the whole sinusoid: both extremes
        lo[wide] = np.minimum(lo[wide], -np.abs(c[wide]) + off[wide])
        hi[wide] = np.maximum(hi[wide], np.abs(c[wide]) + off[wide])
    return lo, hi


def derivative_ranges(path: Path, grid: Grid, dq0: np.ndarray, ddq0: np.ndarray,
                      dq1: np.ndarray, ddq1: np.ndarray) -> tuple[np.ndarray, ...]:
    """Exact ranges of every axis' ``q'_j`` and ``q''_j`` on the line, circle and helix
    intervals.

    On a circle or helix with plane vectors ``e1, e2``, radius ``r``, rate ``omega`` and
    linear part ``d``: ``q'_j = r omega |e_j| cos(phi - atan2(-e1_j, e2_j)) + d_j`` and
    ``q''_j = -r omega^2 |e_j| cos(phi - atan2(e2_j, e1_j))`` (``|e_j|`` the axis' share
    of the arc plane): their extremes on an interval are at its ends and at the interior
    extremes of the sinusoid (:func:`_sinusoid_range`). On lines both are constant.
    Spirals and clothoids are left to the caller (``exact`` is False there).

    Returns
    -------
    t_lo, t_hi, k_lo, k_hi : numpy.ndarray, shape (N, n)
        Smallest and largest ``q'_j`` and ``q''_j`` on each interval.
    exact : numpy.ndarray of bool, shape (N,)
        Where the ranges are exact (lines, circles, helices).
    tol : numpy.ndarray, shape (N, n)
        Round-off bound of the ``q'`` range (a few ulps of its size); the ``q''`` range
        carries ``tol`` times ``|omega|``.
    """
    seg = grid.segment
    t_lo, t_hi = np.minimum(dq0, dq1), np.maximum(dq0, dq1)
    k_lo, k_hi = np.minimum(ddq0, ddq1), np.maximum(ddq0, ddq1)
    exact = ~_varying_curvature(path, seg)         # not on spirals and clothoids
    circ_all = np.flatnonzero(exact & (path.radius[seg] > 0))
    amp = np.zeros_like(dq0)
    # in chunks of intervals: a dozen (chunk, n) temporaries each
    for lo in range(0, circ_all.size, ENVELOPE_CHUNK):
        circ = circ_all[lo:lo + ENVELOPE_CHUNK]
        sc = seg[circ]
        e1, e2 = path.e1[sc], path.e2[sc]
        r, w = path.radius[sc], path.omega[sc]
        plane = np.sqrt(e1 ** 2 + e2 ** 2)
        pa = path.theta0[sc] + w * (grid.s[circ] - path.s_breaks[sc])
        pb = path.theta0[sc] + w * (grid.s[circ + 1] - path.s_breaks[sc])
        c1 = (r * w)[:, None] * plane
        t_lo[circ], t_hi[circ] = _sinusoid_range(c1, np.arctan2(-e1, e2), path.d[sc], pa, pb,
                                                 dq0[circ], dq1[circ])
        c2 = -(r * w * w)[:, None] * plane
        k_lo[circ], k_hi[circ] = _sinusoid_range(c2, np.arctan2(e2, e1), np.zeros_like(c2),
                                                 pa, pb, ddq0[circ], ddq1[circ])
        amp[circ] = np.abs(c1)
    tol = 64.0 * np.finfo(np.float64).eps * (amp + np.abs(path.d[seg]) + 1.0)
    return t_lo, t_hi, k_lo, k_hi, exact, tol


def _interval_data(path: Path, lim: AxisArrays, grid: Grid,
                   geometry: tuple[np.ndarray, ...] | None = None) -> _IntervalData:
    seg = grid.segment
    ds = np.diff(grid.s)
    N = ds.size
    n = path.n_axes
    dq0, ddq0, dq1, ddq1 = (interval_geometry(path, grid) if geometry is None
                            else geometry)
    mid = 0.5 * (grid.s[:-1] + grid.s[1:])
    _, dqm, ddqm, _ = path.evaluate(mid, segment=seg)
    r = path.radius[seg]
    w = path.omega[seg]
    plane = np.sqrt(path.e1[seg] ** 2 + path.e2[seg] ** 2)          # (N, n)
    k2 = np.abs(r * w * w)[:, None] * plane                          # sup |q''_j|
    k3 = np.abs(r * w ** 3)[:, None] * plane                         # sup |q^(3)_j|
    spi = np.flatnonzero(_varying_curvature(path, seg))  # worst over the segment
    if spi.size:
        amp = plane_amplitudes(path)
        k2[spi] = amp.curvature[seg[spi], None] * plane[spi]
        k3[spi] = np.hypot(amp.jerk_t, amp.jerk_n)[seg[spi], None] * plane[spi]
    half = 0.5 * ds[:, None]
    lo = np.maximum(np.abs(dqm) - half * k2, 0.0)                    # inf |q'_j| on I_k
    hi = np.abs(dqm) + half * k2                                     # sup |q'_j| on I_k
    # exact on lines, circles and helices (the Lipschitz bounds above are first order:
    # at an interval ending where q'_j = 0 they give inf 0 and twice the sup)
    t_lo, t_hi, k_lo, k_hi, exact, t_tol = derivative_ranges(path, grid, dq0, ddq0, dq1,
                                                             ddq1)
    keeps = exact[:, None] & ((t_lo >= t_tol) | (t_hi <= -t_tol))   # no sign change
    lo = np.where(exact[:, None], np.where(keeps, np.minimum(np.abs(t_lo), np.abs(t_hi))
                                           - t_tol, 0.0), lo)
    lo = np.maximum(lo, 0.0)
    hi = np.where(exact[:, None], np.maximum(np.abs(t_lo), np.abs(t_hi)) + t_tol, hi)
    # one sign up to round-off (e.g. the interval ends exactly where q'_j = 0): the
    # travel is still the chord, within D times the round-off bound
    one_sign = exact[:, None] & ((t_lo >= -t_tol) | (t_hi <= t_tol))
    # ---- a-priori bound of b on each interval
    b_bar = _static_bound(path, lim, seg, dqm, ddqm, lo, hi, k3, ds)
    # ---- exact static bound at the nodes, from both sides
    node_mvc = np.full(N + 1, np.inf)
    node_mvc[:-1] = pair_mvc(dq0, ddq0, lim.a_max)
    node_mvc[1:] = np.minimum(node_mvc[1:], pair_mvc(dq1, ddq1, lim.a_max))
    # ---- closed-form weights of the interval-exact rows
    phi_m = path.theta0[seg] + w * (mid - path.s_breaks[seg])
    x = w * 0.5 * ds
    with np.errstate(invalid="ignore", divide="ignore"):
        sinc = np.where(x != 0, np.sin(x) / np.where(x != 0, x, 1.0), 1.0)
    g = _g_series(x)
    along = -path.e1[seg] * np.sin(phi_m)[:, None] + path.e2[seg] * np.cos(phi_m)[:, None]
    S0 = (sinc * ds)[:, None] * ddqm                                  # int q'' du
    S1 = (-(r * w * w) * 2.0 * (0.5 * ds) ** 2 * g)[:, None] * along  # int u q'' du
    I0 = S0 / 4 - S1 / (2 * ds[:, None])
    I1 = S0 / 4 + S1 / (2 * ds[:, None])
    ierr = np.zeros((N, n))
    if spi.size:
        I0[spi], I1[spi], ierr[spi] = _spiral_weights(path, grid, spi, dq0[spi], dq1[spi])
    slope_tan = tangential_slope_bound(path, lim, seg, dqm, hi)
    # axis travel int |q'_j| on I_k (energy rows): where q'_j keeps its sign it is the
    # exact chord |q_j(s_{k+1}) - q_j(s_k)|, on lines and helices in the cancellation-free
    # form D (sinc(omega D / 2) (q'_mid - d) + d); elsewhere D sup|q'_j|
    chord = np.abs(ds[:, None] * (sinc[:, None] * (dqm - path.d[seg]) + path.d[seg]))
    if spi.size:
        q0 = path.evaluate(grid.s[spi], segment=seg[spi])[0]
        q1 = path.evaluate(grid.s[spi + 1], segment=seg[spi])[0]
        chord[spi] = np.abs(q1 - q0) + ierr[spi] * ds[spi, None]
    chord_ok = (lo > 0) | one_sign
    travel = np.where(chord_ok, np.minimum(chord + np.where(one_sign, t_tol, 0.0)
                                           * ds[:, None], ds[:, None] * hi),
                      ds[:, None] * hi)
    # monotone envelopes (:func:`_monotone_peak`): q'_j and q''_j of one sign each
    kmin = np.where(k_lo > 0, k_lo, np.where(k_hi < 0, -k_hi, 0.0))   # inf |q''_j|
    t_pos, t_neg = t_lo >= -t_tol, t_hi <= t_tol
    one = exact[:, None] & (t_pos ^ t_neg) & (kmin > np.abs(path.omega[seg])[:, None] * t_tol)
    sign_t = np.where(t_pos, 1.0, -1.0)
    sign_k = np.where(k_lo > 0, 1.0, -1.0)
    mono = np.where(one, -sign_t * sign_k, 0.0)
    with np.errstate(divide="ignore"):
        s_max = np.where(one, lim.a_max[None, :] / np.where(one, kmin, 1.0), np.inf)
    return _IntervalData(ds, dq0, dq1, k2, lo, I0, I1, b_bar, node_mvc,
                         moving_axes(dq0, ddq0, dq1, ddq1), ierr, slope_tan, dqm, ddqm,
                         hi, k3, travel, mono, s_max)


def _static_bound(path: Path, lim: AxisArrays, seg: np.ndarray, dqm: np.ndarray,
                  ddqm: np.ndarray, lo: np.ndarray, hi: np.ndarray, k3: np.ndarray,
                  ds: np.ndarray) -> np.ndarray:
    """A-priori bound of ``b`` on intervals of length ``ds`` (step 1 of the module
    docstring): the feed, the axis velocity caps with ``inf|q'_j| >= lo``, and on arcs
    the two-axis elimination with its coefficient bounded below from the mid-point
    values ``dqm, ddqm`` and ``sup|q'_j| <= hi``, ``sup|q'''_j| <= k3``. Shape (N,)."""
    n = dqm.shape[1]
    half = 0.5 * ds
    feed = path.feed[seg]
    b_bar = np.where(np.isfinite(feed), feed ** 2, np.inf)
    with np.errstate(divide="ignore"):
        vcap = np.where(lo > 0, (lim.v_max[None, :] / np.where(lo > 0, lo, 1.0)) ** 2,
                        np.inf)
    b_bar = np.minimum(b_bar, vcap.min(axis=1))
    ia = np.flatnonzero(path.radius[seg] > 0)
    if ia.size:
        for j in range(n):
            for m in range(j + 1, n):
                W = dqm[ia, m] * ddqm[ia, j] - dqm[ia, j] * ddqm[ia, m]
                dW = hi[ia, m] * k3[ia, j] + hi[ia, j] * k3[ia, m]
                Wlo = np.abs(W) - half[ia] * dW
                ok = Wlo > 0
                if np.any(ok):
                    num = hi[ia, m] * lim.a_max[j] + hi[ia, j] * lim.a_max[m]
                    val = np.full(ia.size, np.inf)
                    val[ok] = num[ok] / Wlo[ok]
                    b_bar[ia] = np.minimum(b_bar[ia], val)
    return b_bar


def _monotone_peak(geo: _IntervalData, b_node: np.ndarray) -> np.ndarray:
    """Bound of ``b`` on each interval from one-signed geometry and node bounds.

    Where ``q'_j`` and ``q''_j`` keep their signs on an interval and ``|q''_j| > 0``, a
    motion with ``b > S_j = A_j / |q''_j|`` at a point meets
    ``|q'_j a + q''_j b| <= A_j`` only with ``sign(a) = -sign(q'_j q''_j)`` (the centripetal
    part alone exceeds the limit, so the tangential part must take it back): above the
    curve ``S_j`` the speed can only fall (``mono = -1``) or only rise (``mono = +1``)
    along ``s``. Going from a point ``s`` with ``b(s) > sup S_j`` towards the interval
    start (``mono = -1``), ``b`` stays above ``sup S_j`` and does not decrease, so
    ``b(s) <= b(s_k)``; hence ``b <= max(b(s_k), sup S_j)`` on the interval, and with
    ``mono = +1`` the same from the end. The node bounds are valid for every feasible
    motion, so these are too. This is what bounds the speed where the optimum threads
    the minimum of the maximum-velocity curve on an arc (a first-order loss of the
    Lipschitz tent there).

    Returns
    -------
    numpy.ndarray, shape (N,)
        mm^2/s^2, ``inf`` where no axis qualifies.
    """
    return _monotone_pair(geo, b_node[:-1], b_node[1:])


def _monotone_pair(geo: _IntervalData, b_start: np.ndarray, b_end: np.ndarray
                   ) -> np.ndarray:
    """:func:`_monotone_peak` from the bounds at each interval's two ends, shape (N,)."""
    b0 = np.maximum(b_start, 0.0)[:, None]
    b1 = np.maximum(b_end, 0.0)[:, None]
    cand = np.where(geo.mono < 0, np.maximum(b0, geo.s_max),
                    np.where(geo.mono > 0, np.maximum(b1, geo.s_max), np.inf))
    return cand.min(axis=1) if cand.shape[1] else np.full(cand.shape[0], np.inf)


def _varying_curvature(path: Path, seg: np.ndarray) -> np.ndarray:
    """True for segments whose curvature varies along them (spirals, clothoids): no
    helix closed forms there, the generic by-parts weights and worst-case suprema are
    used instead. Shape (len(seg),)."""
    return (path.dradius[seg] != 0) | (path.sharpness[seg] != 0)


def _clothoid_position_scale(path: Path, seg: np.ndarray) -> np.ndarray:
    """Magnitude bounding the round-off of clothoid positions, shape (K, n), mm.

    A clothoid position is ``Z + X e1 + Y e2`` with ``|X|, |Y| <= L`` from the Fresnel
    integrals, which scipy evaluates to a few units of round-off relative to
    ``sqrt(pi/c)`` times values at most ``L / sqrt(pi/c)``; the sum then carries at most
    a few ulps of ``|Z_j| + 2 L``. ``|Z_j| + 4 L`` (used with the same ``16 eps`` as the
    spirals' bound) leaves a factor of two on top.
    """
    return np.abs(path.origin[seg]) + 4.0 * path.length[seg][:, None]


def _spiral_weights(path: Path, grid: Grid, iv: np.ndarray, dq0: np.ndarray,
                    dq1: np.ndarray) -> tuple[np.ndarray, ...]:
    """``I0, I1`` on spiral intervals ``iv`` by parts, and their round-off bound.

    ``int_0^D q'' (1 - u/D) du = dq/D - q'(0)`` and ``int_0^D q'' u/D du = q'(D) - dq/D``
    hold for every smooth curve; ``dq`` is the chord of the exact positions. Each position
    carries at most ``16 eps (|o_j| + r_max (1 + t_end) + |d_j| L)`` of round-off (a few
    operations on those magnitudes, and the angle to ``4 eps max(t_end, 1)``), so
    ``|I0| + |I1|`` is off by at most twice that over ``D``. Shapes ``(K, n)``.
    """
    seg = grid.segment[iv]
    D = (grid.s[iv + 1] - grid.s[iv])[:, None]
    q0 = path.evaluate(grid.s[iv], segment=seg)[0]
    q1 = path.evaluate(grid.s[iv + 1], segment=seg)[0]
    chord = (q1 - q0) / D
    t_end = np.abs(path.omega[seg]) * path.length[seg]
    r_max = np.maximum(path.radius[seg], path.radius[seg] + path.dradius[seg] * t_end)
    scale = (np.abs(path.origin[seg]) + (r_max * (1.0 + t_end))[:, None]
             + np.abs(path.d[seg]) * path.length[seg][:, None])
    clo = np.flatnonzero(path.sharpness[seg])
    if clo.size:
        scale[clo] = _clothoid_position_scale(path, seg[clo])
    err = 2.0 * 16.0 * np.finfo(np.float64).eps * scale / D
    return 0.5 * (chord - dq0), 0.5 * (dq1 - chord), err


def _slope_bound(geo: _IntervalData, lim: AxisArrays, B: np.ndarray) -> np.ndarray:
    """``M = min_j 2 (A_j + sup|q''_j| B) / inf|q'_j|``: bound of ``|b'|`` where b <= B,
    or the b-free tangential bound where smaller."""
    lo = geo.lo
    with np.errstate(divide="ignore", invalid="ignore"):
        curv = np.where(geo.k2 > 0, geo.k2 * B[:, None], 0.0)      # 0 * inf -> 0
        acap = np.where(lo > 0, (lim.a_max[None, :] + curv) / np.where(lo > 0, lo, 1.0),
                        np.inf)
    return np.minimum(2.0 * acap.min(axis=1), geo.slope_tan)


def _gronwall_peak(geo: _IntervalData, lim: AxisArrays, b_node: np.ndarray) -> np.ndarray:
    """Bound of ``b`` on each interval from bounds of its end values.

    With ``|b'| <= alpha + beta b`` (``alpha = 2 A_j / inf|q'_j|``,
    ``beta = 2 sup|q''_j| / inf|q'_j|`` for one axis ``j``), ``b`` stays below
    ``(b_k + c) e^{beta t} - c`` from the left and the mirror image from the right
    (``c = alpha / beta``); the bound is the largest value of the smaller of the two.
    """
    return _gronwall_pair(geo, lim, b_node[:-1], b_node[1:])


def _gronwall_pair(geo: _IntervalData, lim: AxisArrays, b_start: np.ndarray,
                   b_end: np.ndarray) -> np.ndarray:
    """:func:`_gronwall_peak` from the bounds at each interval's two ends, shape (N,)."""
    b0 = np.maximum(b_start, 0.0)
    b1 = np.maximum(b_end, 0.0)
    ref = np.maximum(b0, b1)
    lo = geo.lo
    with np.errstate(divide="ignore", invalid="ignore"):
        score = np.where(lo > 0, (lim.a_max[None, :] + geo.k2 * ref[:, None])
                         / np.where(lo > 0, lo, 1.0), np.inf)
    j = np.argmin(score, axis=1)
    ar = np.arange(j.size)
    loj = lo[ar, j]
    ok = loj > 0
    alpha = np.where(ok, 2 * lim.a_max[j] / np.where(ok, loj, 1.0), np.inf)
    beta = np.where(ok, 2 * geo.k2[ar, j] / np.where(ok, loj, 1.0), np.inf)
    D = geo.ds
    out = np.full(j.size, np.inf)
    lin = ok & (beta == 0)
    if np.any(lin):
        a, x0, x1, d = alpha[lin], b0[lin], b1[lin], D[lin]
        tp = np.clip((x1 - x0 + a * d) / (2 * a), 0.0, d)
        out[lin] = np.minimum(x0 + a * tp, x1 + a * (d - tp))
    ex = ok & (beta > 0) & (beta * D < 50.0)
    if np.any(ex):
        bt, c = beta[ex], alpha[ex] / beta[ex]
        x0, x1, d = b0[ex], b1[ex], D[ex]
        tp = np.clip((np.log((x1 + c) / (x0 + c)) + bt * d) / (2 * bt), 0.0, d)
        f = x0 + (x0 + c) * np.expm1(bt * tp)
        g = x1 + (x1 + c) * np.expm1(bt * (d - tp))
        out[ex] = np.minimum(f, g)
    # the b-free tangential slope bound gives a plain tent (optimal.arc_bounds)
    return np.minimum(out, slope_peak(b0, b1, geo.slope_tan, D))


def _relaxed_problem(path: Path, lim: AxisArrays, grid: Grid, geo: _IntervalData,
                     B: np.ndarray, b_node: np.ndarray | None = None,
                     guide: np.ndarray | None = None) -> Relaxation:
    N = geo.ds.size
    ds = geo.ds
    slope = _slope_bound(geo, lim, B)
    good = np.isfinite(B) & np.isfinite(slope)
    caps = common_node_caps(path, lim, grid, geo.dq0, geo.dq1, permissive=True)
    left = np.arange(N)
    caps.add(left[good], B[good], CAP_BOUND)
    caps.add(left[good] + 1, B[good], CAP_BOUND)
    fin_mvc = np.isfinite(geo.node_mvc)
    caps.add(np.flatnonzero(fin_mvc), geo.node_mvc[fin_mvc], CAP_BOUND)
    if b_node is not None:
        fin = np.isfinite(b_node)
        caps.add(np.flatnonzero(fin), np.maximum(b_node[fin], 0.0), CAP_BOUND)
    margin = np.where(good, slope, 0.0) * ds * ds / REMAINDER_DIVISOR
    E = np.where(good[:, None], geo.k2 * margin[:, None]
                 + geo.ierr * np.where(good, B, 0.0)[:, None], np.inf)
    rows = RowWriter(N, 4 * len(geo.axes_used))
    if guide is not None:       # second-order rows (optimal.arc_bounds.envelope_rows)
        slope_g = np.where(good, slope, np.inf)
        env = lower_envelopes(ds, guide[:-1], guide[1:], lim.a_max, geo.dq_mid,
                              geo.ddq_mid, geo.lo, geo.hi, geo.k3, slope_g)
    for j in geo.axes_used:
        hrow = lim.a_max[j] + E[:, j] / ds
        fin = np.isfinite(hrow)
        for sigma in (1.0, -1.0):
            c1 = sigma * (-0.5 * geo.dq0[:, j] + geo.I0[:, j]) / ds
            c2 = sigma * (0.5 * geo.dq1[:, j] + geo.I1[:, j]) / ds
            c1 = np.where(fin, c1, 0.0)
            c2 = np.where(fin, c2, 0.0)
            both = (c1 > 0) & (c2 > 0)
            if np.any(both):
                # relax: drop one term at a time (b >= 0)
                caps.add(left[both], hrow[both] / c1[both], CAP_BOUND)
                caps.add(left[both] + 1, hrow[both] / c2[both], CAP_BOUND)
            rows.append(np.where(both, 0.0, c1), np.where(both, 0.0, c2),
                        np.where(fin, hrow, 1.0), j)
            if guide is None:
                continue
            # the same row in second-order form (optimal.arc_bounds.envelope_rows)
            ok, dc1, dc2, rhs = envelope_rows(env, geo.k3, slope_g, int(j),
                                              sigma * geo.ddq_mid[:, j])
            h2 = lim.a_max[j] + rhs + geo.ierr[:, j] * np.where(good, B, 0.0) / ds
            ok &= fin & good & np.isfinite(h2)
            if not np.any(ok):
                continue
            n1 = np.where(ok, c1 + dc1, 0.0)
            n2 = np.where(ok, c2 + dc2, 0.0)
            both = ok & (n1 > 0) & (n2 > 0)
            if np.any(both):
                caps.add(left[both], h2[both] / n1[both], CAP_BOUND)
                caps.add(left[both] + 1, h2[both] / n2[both], CAP_BOUND)
            # where formed it replaces the first-order row in the same column (dropping
            # a valid row only relaxes; this keeps the sweep's column count)
            l1, l2, lh = rows.last()
            l1[ok] = np.where(both, 0.0, n1)[ok]
            l2[ok] = np.where(both, 0.0, n2)[ok]
            lh[ok] = h2[ok]
        # energy rows (step 2b of the module docstring): exact, no remainder
        e0 = geo.dq0[:, j] ** 2
        e1 = geo.dq1[:, j] ** 2
        he = 2.0 * lim.a_max[j] * geo.travel[:, j]
        for c1, c2 in ((-e0, e1), (e0, -e1)):
            rows.append(c1, c2, he, j)
    prob = _assemble(path, lim, grid, caps, rows, "relaxed")
    return Relaxation(prob, B, slope)


def build_relaxation(path: Path, lim: AxisArrays, grid: Grid,
                     b_node: np.ndarray | None = None) -> Relaxation:
    """The relaxed discrete problem of the module docstring on ``grid``.

    Parameters
    ----------
    path : Path
        Path with at least one segment.
    lim : AxisArrays
        Limits in the path's axis order.
    grid : Grid
        Nodes.
    b_node : numpy.ndarray, shape (N + 1,), optional
        Valid upper bounds of ``b`` at the nodes (the optimum of an earlier relaxation
        on this grid); they tighten the interval bounds (:func:`_gronwall_peak`).

    Returns
    -------
    Relaxation
    """
    geo = _interval_data(path, lim, grid)
    B = geo.b_static
    if b_node is not None:
        B = np.minimum(B, _gronwall_peak(geo, lim, b_node))
    return _relaxed_problem(path, lim, grid, geo, B, b_node)


def tent_times(s: np.ndarray, b: np.ndarray, b_bar: np.ndarray, slope: np.ndarray
               ) -> np.ndarray:
    """Lower estimate of the time on every interval (step 4 of the module docstring).

    ``int_0^D dt / sqrt(min(Bbar, b_k + M t, b_{k+1} + M (D - t)))`` in closed form.

    Parameters
    ----------
    s : numpy.ndarray, shape (N + 1,)
        Nodes, mm.
    b : numpy.ndarray, shape (N + 1,)
        Upper bounds of ``b`` at the nodes (the relaxation's optimum), mm^2/s^2.
    b_bar, slope : numpy.ndarray, shape (N,)
        Interval bounds of ``b`` and ``|b'|``; where not finite the estimate is 0.

    Returns
    -------
    numpy.ndarray, shape (N,)
        Seconds.
    """
    return _tent_pair(np.diff(s), b[:-1], b[1:], b_bar, slope)


def _tent_pair(D: np.ndarray, b_start: np.ndarray, b_end: np.ndarray, b_bar: np.ndarray,
               slope: np.ndarray) -> np.ndarray:
    """:func:`tent_times` from interval lengths and the bounds at each interval's two
    ends, shape (N,)."""
    good = np.isfinite(b_bar) & np.isfinite(slope) & (slope > 0)
    B = np.where(good, b_bar, 1.0)
    M = np.where(good, slope, 1.0)
    b0 = np.minimum(np.maximum(b_start, 0.0), B)
    b1 = np.minimum(np.maximum(b_end, 0.0), B)
    tp = np.clip((b1 - b0 + M * D) / (2 * M), 0.0, D)

    def ramp(b_start, length):
        tc = np.clip((B - b_start) / M, 0.0, length)
        top = np.sqrt(b_start + M * tc) + np.sqrt(b_start)
        up = np.where(tc > 0, 2 * tc / np.where(top > 0, top, 1.0), 0.0)
        flat = np.where(length - tc > 0, (length - tc) / np.sqrt(np.where(B > 0, B, 1.0)),
                        0.0)
        return up + np.where(B > 0, flat, np.where(length - tc > 0, np.inf, 0.0))

    t = ramp(b0, tp) + ramp(b1, D - tp)
    return np.where(good, t, 0.0)


def lower_bound(path: Path, lim: AxisArrays, grid: Grid, *, rounds: int = LB_ROUNDS,
                b_node: np.ndarray | None = None,
                geometry: tuple[np.ndarray, ...] | None = None,
                sub_pieces: int = 1
                ) -> tuple[float, np.ndarray, Relaxation, np.ndarray]:
    """Certified lower bound of the motion time on ``grid`` (dwells excluded).

    Round 0 uses the a-priori interval bounds; each further round bounds ``b`` inside
    the intervals from the previous round's node values (still valid for every
    feasible motion, step 1 of the module docstring), which shrinks the Lipschitz
    margins. Rounds stop early when the bound improves by less than
    ``LB_ROUND_IMPROVEMENT``.

    Parameters
    ----------
    path, lim, grid
        Problem data.
    rounds : int
        Largest number of rounds.
    b_node : numpy.ndarray, shape (N + 1,), optional
        Upper bounds of ``b`` at the nodes that hold for *every* feasible motion (for
        example mapped from a relaxation on a coarser grid with :func:`node_bounds_on`);
        they are added as node caps and start the interval bounds.
    geometry : tuple of numpy.ndarray, optional
        :func:`optimal.problem.interval_geometry` of ``grid`` when the caller has it.
    sub_pieces : int
        Curved intervals also get the time estimate on this many equal sub-pieces
        with energy node bounds (step 5 of the module docstring, :func:`subnode_times`);
        1: none.

    Returns
    -------
    lb_s : float
        Seconds, already reduced by ``LB_ROUNDOFF_REL``.
    t_lb : numpy.ndarray, shape (N,)
        Per-interval lower estimates, s.
    relaxation : Relaxation
        The relaxed problem of the best round.
    b_hat : numpy.ndarray, shape (N + 1,)
        Its greatest element, mm^2/s^2.
    """
    geo = _interval_data(path, lim, grid, geometry)
    B = geo.b_static
    if b_node is not None:
        B = np.minimum(B, np.minimum(_gronwall_peak(geo, lim, b_node),
                                     _monotone_peak(geo, b_node)))
    best = None
    guide = b_node if b_node is not None and np.all(np.isfinite(b_node)) else None
    for _ in range(max(rounds, 1)):
        rel = _relaxed_problem(path, lim, grid, geo, B, b_node, guide)
        b_hat, _, _ = sweep(rel.problem)
        # the interval bound sharpened by this round's node bounds (valid for every
        # feasible motion, as b_hat is)
        b_in = np.minimum(rel.b_bar, _monotone_peak(geo, b_hat))
        t = tent_times(grid.s, b_hat, b_in, rel.slope)
        # arcs: one-axis comparison envelopes, valid too; keep the larger estimate
        t = np.maximum(t, envelope_times(geo.ds, b_hat[:-1], b_hat[1:], b_in,
                                         lim.a_max, geo.dq_mid, geo.ddq_mid, geo.lo,
                                         geo.hi, geo.k3))
        T = float(t.sum())
        improved = best is None or T > best[0] * (1 + LB_ROUND_IMPROVEMENT)
        if best is None or T > best[0]:
            best = (T, t, rel, b_hat)
        if not improved:
            break
        B = np.minimum(B, np.minimum(_gronwall_peak(geo, lim, b_hat),
                                     _monotone_peak(geo, b_hat)))
        guide = b_hat
    T, t, rel, b_hat = best
    if sub_pieces > 1:
        b_in = np.minimum(rel.b_bar, _monotone_peak(geo, b_hat))
        t = np.maximum(t, subnode_times(path, lim, grid, geo, b_hat, b_in, rel.slope,
                                        sub_pieces))
        T = float(t.sum())
    return T * (1.0 - LB_ROUNDOFF_REL), t, rel, b_hat


def subnode_times(path: Path, lim: AxisArrays, grid: Grid, geo: "_IntervalData",
                  b_hat: np.ndarray, b_in: np.ndarray, slope: np.ndarray,
                  pieces: int) -> np.ndarray:
    """Lower estimate of the time on every curved interval from ``pieces`` equal
    sub-pieces (step 5 of the module docstring), s; 0 on lines (exact there already).

    Parameters
    ----------
    path, lim, grid
        Problem data.
    geo : _IntervalData
        :func:`_interval_data` of ``grid``.
    b_hat : numpy.ndarray, shape (N + 1,)
        Node bounds valid for every feasible motion (the relaxation's optimum),
        mm^2/s^2.
    b_in, slope : numpy.ndarray, shape (N,)
        Bounds of ``b`` and ``|b'|`` on each interval, valid for every feasible motion.
    pieces : int
        Sub-pieces per curved interval (>= 2).

    Returns
    -------
    numpy.ndarray, shape (N,)
    """
    N = grid.n_intervals
    out = np.zeros(N)
    cur = np.flatnonzero(path.radius[grid.segment] > 0)
    if pieces < 2 or cur.size == 0:
        return out
    b_hat = np.maximum(np.asarray(b_hat, dtype=np.float64), 0.0)
    A = lim.a_max[None, :]
    frac = np.arange(pieces + 1) / pieces
    step = max(ENVELOPE_CHUNK // pieces, 1)
    for lo in range(0, cur.size, step):
        k = cur[lo:lo + step]                                   # parents (K,)
        K = k.size
        s0, D = grid.s[k], geo.ds[k]
        seg = grid.segment[k]
        d = D / pieces
        # node bounds at the inner nodes x = i D / pieces, i = 1 .. pieces - 1, (K, P - 1)
        x = D[:, None] * frac[None, 1:-1]
        tent = np.minimum(b_in[k, None], np.minimum(b_hat[k, None] + slope[k, None] * x,
                                                    b_hat[k + 1, None]
                                                    + slope[k, None] * (D[:, None] - x)))
        # energy bounds: (q'_j^2 b)' = 2 q'_j (q'_j a + q''_j b), so from either end
        # q'_j(s)^2 b(s) <= q'_j(end)^2 b_end + 2 A_j (travel of axis j in between);
        # the travel is the sum of the pieces' exact chords where q'_j keeps its sign on
        # the parent (helix form without cancellation, from the piece's mid-point
        # tangent), else length times sup|q'_j|
        mids = D[:, None] * (frac[:-1] + 0.5 / pieces)[None, :]
        pts = np.concatenate((s0[:, None] + x, s0[:, None] + mids), axis=1)
        segs = np.repeat(seg, pts.shape[1])
        _, dq_all, ddq_all, _ = path.evaluate(pts.ravel(), segment=segs)
        n = dq_all.shape[1]
        P1 = pieces - 1
        dq_node = dq_all.reshape(K, -1, n)[:, :P1]
        dq_mid = dq_all.reshape(K, -1, n)[:, P1:]                  # (K, P, n)
        ddq_mid = ddq_all.reshape(K, -1, n)[:, P1:]
        y = (0.5 * path.omega[seg] * d)[:, None, None]
        with np.errstate(invalid="ignore", divide="ignore"):
            sinc = np.where(y != 0, np.sin(y) / np.where(y != 0, y, 1.0), 1.0)
        dd = path.d[seg][:, None, :]
        chord = np.abs(d[:, None, None] * (sinc * (dq_mid - dd) + dd))
        worst = d[:, None, None] * geo.hi[k][:, None, :]
        exact = (~_varying_curvature(path, seg)[:, None, None]
                 & (geo.lo[k] > 0)[:, None, :])
        piece = np.where(exact, np.minimum(chord, worst), worst)    # (K, P, n)
        cum = np.cumsum(piece, axis=1)
        t_left = cum[:, :-1]                                        # (K, P - 1, n)
        t_right = cum[:, -1:] - t_left
        num = np.minimum(geo.dq0[k][:, None, :] ** 2 * b_hat[k, None, None]
                         + 2.0 * A * t_left,
                         geo.dq1[k][:, None, :] ** 2 * b_hat[k + 1, None, None]
                         + 2.0 * A * t_right)
        den = dq_node ** 2
        with np.errstate(divide="ignore", invalid="ignore"):
            energy = np.where(den > 0, num / np.where(den > 0, den, 1.0),
                              np.inf).min(axis=2)
        u = np.empty((K, pieces + 1))
        u[:, 0], u[:, -1] = b_hat[k], b_hat[k + 1]
        u[:, 1:-1] = np.minimum(tent, energy)
        # step 4 on the pieces: the parent's bounds hold on every piece (a sup over the
        # parent bounds the sup over a part, an inf the inf)
        par = np.repeat(k, pieces)
        dq_mid, ddq_mid = dq_mid.reshape(-1, n), ddq_mid.reshape(-1, n)
        dp = np.repeat(d, pieces)
        # inf and sup of |q'_j| on each piece: the parent's, or from the piece's own
        # mid-point value and sup|q''_j| when tighter
        lo_p = np.maximum(geo.lo[par], np.abs(dq_mid) - 0.5 * dp[:, None] * geo.k2[par])
        hi_p = np.minimum(geo.hi[par], np.abs(dq_mid) + 0.5 * dp[:, None] * geo.k2[par])
        B_p = np.minimum(b_in[par], _static_bound(path, lim, grid.segment[par], dq_mid,
                                                  ddq_mid, lo_p, hi_p, geo.k3[par], dp))
        sub = _IntervalData(
            ds=dp, dq0=geo.dq0[par], dq1=geo.dq1[par], k2=geo.k2[par],
            lo=lo_p, I0=geo.I0[par], I1=geo.I1[par], b_static=B_p,
            node_mvc=np.zeros(0), axes_used=geo.axes_used, ierr=geo.ierr[par],
            slope_tan=geo.slope_tan[par], dq_mid=dq_mid, ddq_mid=ddq_mid, hi=hi_p,
            k3=geo.k3[par],
            travel=geo.travel[par], mono=geo.mono[par], s_max=geo.s_max[par])
        u0, u1 = u[:, :-1].ravel(), u[:, 1:].ravel()
        B = np.minimum(B_p, np.minimum(_gronwall_pair(sub, lim, u0, u1),
                                     _monotone_pair(sub, u0, u1)))
        sl = np.minimum(slope[par], _slope_bound(sub, lim, B))
        t = np.maximum(_tent_pair(sub.ds, u0, u1, B, sl),
                       envelope_times(sub.ds, u0, u1, B, lim.a_max, sub.dq_mid,
                                      sub.ddq_mid, sub.lo, sub.hi, sub.k3))
        out[k] = t.reshape(K, pieces).sum(axis=1)
    return out


def node_bounds_on(new: Grid, old: Grid, b_hat: np.ndarray, b_bar: np.ndarray
                   ) -> np.ndarray:
    """Valid node bounds on a refined grid from a relaxation on the coarser one.

    Old nodes keep the old optimum ``b_hat`` (it dominates every feasible motion there);
    new nodes inside old interval ``k`` get that interval's bound ``b_bar[k]``.

    Parameters
    ----------
    new, old : Grid
        ``new`` contains every node of ``old``.
    b_hat : numpy.ndarray, shape (N_old + 1,)
    b_bar : numpy.ndarray, shape (N_old,)

    Returns
    -------
    numpy.ndarray, shape (N_new + 1,)
    """
    idx = np.searchsorted(old.s, new.s, side="left")
    idx = np.clip(idx, 0, old.s.size - 1)
    on_old = old.s[idx] == new.s
    k = np.clip(idx - 1, 0, b_bar.size - 1)
    return np.where(on_old, b_hat[idx], b_bar[k])


def speed_envelope_bounds(path: Path, lim: AxisArrays, grid: Grid
                          ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Pointwise speed bounds valid for every feasible motion, from the relaxation on ``grid``.

    ``b(s) <= min(B_k, b_hat_k + M_k (s - s_k), b_hat_{k+1} + M_k (s_{k+1} - s))`` on
    interval ``k`` for every motion of the continuous problem (steps 1 and 3 of the module
    docstring: ``b_hat`` is the greatest element of the relaxation, ``B_k`` the interval
    bound sharpened by it, ``M_k`` the slope bound of ``b``).

    Returns
    -------
    b_hat : numpy.ndarray, shape (N + 1,)
        mm^2/s^2.
    B : numpy.ndarray, shape (N,)
        mm^2/s^2 (``inf`` where nothing bounds it).
    M : numpy.ndarray, shape (N,)
        mm/s^2 (``inf`` where nothing bounds it).
    t : numpy.ndarray, shape (N,)
        The lower estimate of the time on each interval, s: each holds on its own for
        every feasible motion (step 4 integrates pointwise bounds of ``b``), so sums over
        any intervals bound the time spent there; reduced by ``LB_ROUNDOFF_REL``.
    """
    _, t, rel, b_hat = lower_bound(path, lim, grid)
    geo = _interval_data(path, lim, grid)
    return (b_hat, np.minimum(rel.b_bar, _monotone_peak(geo, b_hat)), rel.slope,
            t * (1.0 - LB_ROUNDOFF_REL))
