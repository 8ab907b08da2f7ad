"""Certified lower bound from the frequency rule (bound sets ``acc+freq``, ``jerk+freq``).

The rule (:mod:`reference.core.phases`): every acceleration or deceleration phase ``P``, a
maximal time span in which ``s''`` keeps one sign with ``|s''| > eta * max|s''|``
(``eta = FREQ_ACCEL_TOL_REL``), has an effective duration ``2 min(t_c - t_0, t_1 - t_c)``
of at least ``1/f_P``, ``f_P`` the smallest LOOKAH_FREQUENCY of the axes moving in it; the
checker accepts down to ``g_P = (1/f_P) / (1 + RATIO_TOL)``. By integration by parts
``int_P (v_1 - v) dt = dv_P (t_c - t_0)`` and ``int_P (v - v_0) dt = dv_P (t_1 - t_c)``,
so every phase **loses at least** ``dv_P g_P / 2`` against either of its end speeds.

Proof of :func:`piece_lower_bounds`
-----------------------------------
Cut the path at its stop breaks (``path.stop``) into rest-to-rest pieces ``k`` of length
``L_k``. An accepted profile has ``v <= e`` at each stop (``e = VEL_TOL_MM_S``) within the
position tolerance ``p = POS_TOL_MM max(1, L)`` of the break. Let ``t_a, t_b`` be the times
of the smallest speed within that tolerance of the piece's first and last break (a
minimum of ``v``, so no phase runs through them), ``V`` the largest speed in between, at
``t*``, and ``T_k = t_b - t_a``; the motion covers at least ``L_k - 2p`` in ``[t_a, t_b]``,
and these spans of different pieces are disjoint.

* ``f_P <= fbar_k``, the largest over the segments of piece ``k`` and its two neighbours of
  the smallest f of the axes moving on the segment: every phase inside ``[t_a, t_b]``
  touches one of them, and its axes include that segment's.
* ``V <= Vcap_k``: at most the feed (``v <= F (1 + RATIO_TOL)``) and the axis speed
  limits of one of those segments: ``min_i V_i / |d_i|`` on a line, ``sqrt(n) max_i V_i``
  on a curve (some ``|q'_i| >= 1/sqrt(n)`` since ``q'`` is a unit vector), times
  ``1 + RATIO_TOL``.
* Between ``t_a`` and ``t*`` the speed rises by at least ``V - e``. Outside phases
  ``|s''| <= eta abar`` (``abar`` bounds ``|s''|`` of every accepted profile, below), so
  the rise phases carry ``sum dv_P >= V - e - eta abar (t* - t_a)``; each loses at least
  ``dv_P gbar / 2`` against ``V >= v_1`` (``gbar = (1/fbar_k)/(1 + RATIO_TOL)``), and
  ``V - v >= 0`` elsewhere. With the fall alike:
  ``int (V - v) dt >= (2 (V - e) - eta abar T_k) gbar / 2``, and since the distance is
  ``V T_k - int (V - v) dt``:

      T_k >= F(V) = (L_k - 2p + (V - e) gbar) / (V + c),   c = eta abar gbar / 2.

  ``F`` is monotone in ``V``, so ``T_k >= min(F(Vcap_k), F(0+))``. On a rest-to-rest
  line this is ``L/v + 1/f`` up to ``e``, ``p`` and ``eta``: the closed form of DESIGN 6.
* Also ``T_k >= min(2 gbar, tau_k)``: either the rise and the fall each hold a phase
  (disjoint, each lasting at least its effective duration ``>= gbar``), or one of them
  holds none, then ``v <= e + eta abar (t - t_a)`` and covering ``L_k - 2p`` takes at
  least the positive root ``tau_k`` of ``eta abar tau^2 + e tau = L_k - 2p``.

Summed over the pieces (disjoint spans; holds excluded, as in the other bound sets):
``T >= sum_k max(min(F_k(Vcap), F_k(0+)), min(2 gbar_k, tau_k))``. Bound on ``|s''|``:
every segment is parameterised by the arc length of a set of its axes (the geometry axes
where they move, else all moving ones: :mod:`reference.core.geometry`), so their part
``q'_G`` of ``q'`` is a unit vector all along it and ``q'_G . q''_G = 0``; the axis
accelerations ``q' s'' + q'' v^2`` of those axes then have ``s''`` as their component
along ``q'_G``: ``|s''| <= |(A_i)_G| <= (sum_i A_i^2)^(1/2)``, at every instant, whatever
the speed and the curvature. With the checker's slack, ``abar = (sum_i A_i^2)^(1/2)
(1 + RATIO_TOL)``. (It was ``sqrt(n) (A_max + kappa_max n V_max^2)``, from one axis with
``|q'_i| >= 1/sqrt(n)``: on lcnc_sam_tolerance_issue.ngc's 0.3 mm arcs 1000 times larger,
which made the drift ``eta abar T`` of the speed outside phases some 10 mm/s.)

The jerk proxy ``2 A f`` is not used: it bounds FIR-shaped profiles only. The bound is
combined with the base oracle's certified bound by ``max`` (both hold for every profile
the checker accepts under the frequency set).

Units: mm, s, Hz.
"""

from __future__ import annotations

import math

import numpy as np

from reference.core.geometry import Path
from reference.core.limits import AxisArrays
from reference.core.phases import FREQ_ACCEL_TOL_REL, min_phase_duration, moving_axes_by_segment
from reference.core.tolerances import POS_TOL_MM, RATIO_TOL, VEL_TOL_MM_S

__all__ = ["freq_lower_bound", "path_accel_bound", "path_rate_bounds", "piece_lower_bounds",
           "rest_pieces", "segment_periods", "segment_speed_caps"]


def rest_pieces(path: Path, extra_breaks: np.ndarray | None = None) -> np.ndarray:
    """Segment index ranges of the rest-to-rest pieces, shape (P, 2): ``[lo, hi)``.

    Pieces end at the stop breaks (``path.stop``) and at ``extra_breaks`` (break indices
    where a motion is at rest anyway, e.g. corners whose speed cap is zero).
    """
    stops = np.flatnonzero(path.stop)
    extra = np.zeros(0, np.int64) if extra_breaks is None else np.asarray(extra_breaks)
    cuts = np.unique(np.concatenate(([0], stops, extra, [path.n_segments])))
    return np.stack((cuts[:-1], cuts[1:]), axis=1)


def segment_periods(path: Path, lim: AxisArrays) -> np.ndarray:
    """``1/f`` of each segment, ``f`` the smallest f of the axes moving on it, s, (m,)."""
    moving = moving_axes_by_segment(path)
    f = np.where(moving, lim.frequency_hz[None, :], np.inf).min(axis=1)
    return min_phase_duration(f)


def _neighbourhood_max(x: np.ndarray, lo: int, hi: int) -> float:
    """Largest ``x`` over segments ``lo - 1 .. hi`` (clipped to the path)."""
    return float(np.max(x[max(lo - 1, 0):min(hi + 1, x.size)]))


def path_rate_bounds(path: Path, per_axis: np.ndarray) -> np.ndarray:
    """Largest path rate (speed or acceleration) a per-axis bound allows, per segment.

    ``min_i x_i / |d_i|`` on lines (constant unit direction ``d``); ``sqrt(n) max_i x_i``
    on arcs, helices, spirals and clothoids (some ``|q'_i| >= 1/sqrt(n)`` at every point,
    ``q'`` being a unit vector).

    Parameters
    ----------
    path : Path
    per_axis : numpy.ndarray, shape (n,)
        Per-axis bound (``v_max`` or ``a_max``).

    Returns
    -------
    numpy.ndarray, shape (m,)
    """
    curved = (path.radius * np.abs(path.omega) > 0) | (path.sharpness != 0)
    with np.errstate(divide="ignore"):
        line = np.min(np.where(np.abs(path.d) > 0, per_axis[None, :] / np.abs(path.d),
                               np.inf), axis=1)
    return np.where(curved, math.sqrt(path.n_axes) * float(np.max(per_axis)), line)


def segment_speed_caps(path: Path, lim: AxisArrays) -> np.ndarray:
    """Upper bound on the path speed any accepted profile reaches on each segment, mm/s.

    ``min(F, path_rate_bounds(v_max))``, times ``1 + RATIO_TOL`` (the checker's slack).
    Shape (m,).
    """
    return np.minimum(path_rate_bounds(path, lim.v_max), path.feed) * (1.0 + RATIO_TOL)


def path_accel_bound(path: Path, lim: AxisArrays) -> float:
    """``abar``: a bound on ``|s''|`` of every accepted profile, mm/s^2 (module
    docstring, last paragraph). ``path`` is used only for its axes (``lim`` is in their
    order)."""
    return math.sqrt(float(np.sum(np.square(lim.a_max)))) * (1.0 + RATIO_TOL)


def piece_lower_bounds(path: Path, lim: AxisArrays) -> np.ndarray:
    """Lower bound on the time of each rest-to-rest piece from the frequency rule, s.

    See the module docstring for the proof.

    Parameters
    ----------
    path : Path
        Restricted to its moving axes.
    lim : AxisArrays
        Limits of ``path.axes``.

    Returns
    -------
    numpy.ndarray, shape (P,)
        One per piece of :func:`rest_pieces`, holds excluded.
    """
    if path.n_segments == 0:
        return np.zeros(0)
    per = segment_periods(path, lim)
    vcap = segment_speed_caps(path, lim)
    pieces = rest_pieces(path)
    a_bar = path_accel_bound(path, lim)
    eta, e = FREQ_ACCEL_TOL_REL, VEL_TOL_MM_S
    p = POS_TOL_MM * max(1.0, float(path.total_length))
    out = np.zeros(pieces.shape[0])
    for k, (lo, hi) in enumerate(pieces):
        L = max(float(np.sum(path.length[lo:hi])) - 2.0 * p, 0.0)
        # the smallest 1/f that a phase of this piece may have (largest f nearby)
        g = float(np.min(per[max(lo - 1, 0):min(hi + 1, per.size)])) / (1.0 + RATIO_TOL)
        V = _neighbourhood_max(vcap, lo, hi)
        c = eta * a_bar * g / 2.0
        f_cap = (L + (V - e) * g) / (V + c) if np.isfinite(V) else g
        f_zero = (L - e * g) / c if c > 0 else math.inf
        lost = max(min(f_cap, f_zero), 0.0)
        root = (2.0 * L / (e + math.sqrt(e * e + 4.0 * eta * a_bar * L))) if L > 0 else 0.0
        out[k] = max(lost, min(2.0 * g, root))
    return out


def freq_lower_bound(path: Path, lim: AxisArrays) -> float:
    """Lower bound on the motion time (holds excluded) from the frequency rule alone, s.

    The sum of :func:`piece_lower_bounds`; see the module docstring for the proof.
    """
    return float(np.sum(piece_lower_bounds(path, lim)))
