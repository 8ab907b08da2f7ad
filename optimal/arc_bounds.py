"""Tighter a-priori bounds of the lower-bound relaxation on lines, arcs and helices.

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
one-axis bound only.

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

import numpy as np

from reference.core.geometry import Path
from reference.core.limits import AxisArrays

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
    ok = (path.dradius[segment] == 0) & (norm2 > 0)
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
