"""Certified lower bound for the ``jerk+freq`` bound set (DESIGN section 6).

The rule (:mod:`reference.core.phases`): every acceleration or deceleration phase, a
maximal time span in which ``s''`` keeps one sign with ``|s''| > eta * max|s''|``
(``eta = FREQ_ACCEL_TOL_REL``), lasts at least ``1/f``, ``f`` the smallest
LOOKAH_FREQUENCY of the axes moving in it; the checker accepts a phase down to
``(1/f) / (1 + RATIO_TOL)``.

Proof of :func:`freq_lower_bound`
---------------------------------
Cut the path at its stop breaks (``path.stop``: start, end, exact and forced stops) into
rest-to-rest pieces ``k`` of length ``L_k``, crossed in the time spans ``[t_a, t_b]``; an
accepted profile has ``v <= eps`` at each stop (``eps = VEL_TOL_MM_S``) and ``v >= 0``.
Let ``T_k = min over the segments of piece k of 1/f_seg``, ``f_seg`` the smallest f of
the axes moving on the segment (:func:`reference.core.phases.moving_axes_by_segment`).

1. *Either* piece ``k`` holds an acceleration phase ``U_k`` and a deceleration phase
   ``D_k`` that both overlap its time span: let ``t_m`` be where ``v`` is largest in
   the piece. If no phase of positive sign overlapped ``(t_a, t_m)``, then ``s'' <=
   eta a_bar`` there (``a_bar`` bounds ``|s''|`` of every accepted profile, below), so
   ``v(t) <= eps + eta a_bar (t - t_a)`` up to ``t_m`` and beyond it too (``v <=
   v(t_m)``), and covering ``L_k`` takes at least the positive root ``tau_k`` of
   ``eta a_bar tau^2 + eps tau = L_k``. The same holds for the fall on ``(t_m, t_b)``.
2. A phase overlapping the rise of piece ``k`` and the rise of piece ``k' > k`` would
   contain the fall of piece ``k`` in between, where ``v`` drops from its peak to at
   most ``eps``, so ``s''`` changes sign inside it: impossible. So the ``U_k`` (and the
   ``D_k``) of different pieces are different phases; phases are disjoint time spans.
3. ``U_k`` overlaps the piece's time span, so the axes moving on one of its segments
   move in ``U_k``: its ``f`` is at most that segment's, and it lasts at least
   ``T_k / (1 + RATIO_TOL)``; likewise ``D_k``.

Hence the motion time is at least ``min(S, min_k tau_k)`` with ``S = sum_k 2 T_k /
(1 + RATIO_TOL)`` (case 1 for every piece, phases disjoint), or one piece is slow and
alone takes ``tau_k``. Bound on ``|s''|``: at every instant some axis has ``|q'_i| >=
1/sqrt(n)`` (``q'`` restricted to the geometry axes is a unit vector, or to the moving
axes where only those move), so ``|s''| <= sqrt(n) (A_i + |q''_i| v^2)`` with ``v <=
sqrt(n) V_max`` and ``|q''_i|`` at most the segment's in-plane curvature bound
(:func:`reference.core.geometry.plane_amplitudes`): ``a_bar = sqrt(n) (A_max + kappa_max
n V_max^2)``, times ``(1 + RATIO_TOL)`` for the checker's slack.

The closed form ``L/v + 1/f`` of DESIGN 6 is **not** used: it bounds FIR-shaped profiles
only, and the rule accepts faster ones (tests/core/test_phases.py). Neither is the jerk
proxy ``2 A f``. The bound is combined with the jerk oracle's certified bound by
``max`` (both hold for every profile the checker accepts under ``jerk+freq``).

Units: mm, s, Hz.
"""

from __future__ import annotations

import math

import numpy as np

from reference.core.geometry import Path, plane_amplitudes
from reference.core.limits import AxisArrays
from reference.core.phases import FREQ_ACCEL_TOL_REL, min_phase_duration, moving_axes_by_segment
from reference.core.tolerances import RATIO_TOL, VEL_TOL_MM_S

__all__ = ["freq_lower_bound", "rest_pieces", "segment_periods"]


def rest_pieces(path: Path) -> np.ndarray:
    """Segment index ranges of the rest-to-rest pieces, shape (P, 2): ``[lo, hi)``."""
    stops = np.flatnonzero(path.stop)
    cuts = np.unique(np.concatenate(([0], stops, [path.n_segments])))
    return np.stack((cuts[:-1], cuts[1:]), axis=1)


def segment_periods(path: Path, lim: AxisArrays) -> np.ndarray:
    """``1/f`` of each segment, ``f`` the smallest f of the axes moving on it, s, (m,)."""
    moving = moving_axes_by_segment(path)
    f = np.where(moving, lim.frequency_hz[None, :], np.inf).min(axis=1)
    return min_phase_duration(f)


def freq_lower_bound(path: Path, lim: AxisArrays) -> float:
    """Lower bound on the motion time (holds excluded) from the frequency rule alone, s.

    See the module docstring for the proof.
    """
    if path.n_segments == 0:
        return 0.0
    per = segment_periods(path, lim)
    pieces = rest_pieces(path)
    n = path.n_axes
    kappa = float(np.max(plane_amplitudes(path).curvature, initial=0.0))
    a_bar = math.sqrt(n) * (float(np.max(lim.a_max)) + kappa * n * float(np.max(lim.v_max)) ** 2)
    c = FREQ_ACCEL_TOL_REL * a_bar * (1.0 + RATIO_TOL)
    S = 0.0
    tau = math.inf
    for lo, hi in pieces:
        L = float(np.sum(path.length[lo:hi]))
        S += 2.0 * float(np.min(per[lo:hi])) / (1.0 + RATIO_TOL)
        eps = VEL_TOL_MM_S
        root = (2.0 * L / (eps + math.sqrt(eps * eps + 4.0 * c * L))) if L > 0 else 0.0
        tau = min(tau, root)
    return min(S, tau)
