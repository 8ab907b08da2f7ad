"""Rows of the frequency rule over runs of short segments: between two speed peaks the
motion falls and rises for ``1/f`` each (bound set ``jerk+freq``).

A zig-zag of short steps between low corner caps (examples/slot.ngc: ten steps of
1.02 mm, corner caps of 4.1 mm/s, 20 Hz) is crossed fastest by rising and falling once
per step, 0.1 s a step. The rows of :mod:`optimal.freq.windows` bound three segments at
a time, each leaning on its neighbours' jerk floors, and where they overlap the
relaxation spreads what the rule adds over them (0.076 s a step). The rows here bound a
whole run at once, and they hold for every motion the checker accepts under
``jerk+freq`` that is no slower than ``T_up``: the relaxation with them is a lower bound
of ``min(minimum, T_up)``, as in :mod:`optimal.freq.windows`.

Proof
=====
Notation of :mod:`optimal.freq.windows` (:class:`~optimal.freq.windows.RuleEnvelope`):
``u_j`` bounds the speed at break ``j``, ``Vc_k`` the speed on segment ``k``, ``g_k`` the
duration of any phase that moves segment ``k``'s axes, ``dr`` what the accelerations
outside phases change the speed by over the whole motion; ``F_k`` is the relaxation's
floor of segment ``k`` (it holds for every accepted motion). Take a run of segments
``a .. b`` and a motion; ``g = min g_k`` over the run, ``W_k = max(u_k, u_{k+1}) + dr``.

1. *Flat or peaked.* Let ``V_k`` be the largest speed on segment ``k``. If ``V_k <=
   W_k`` the segment takes ``T_k >= L_k / min(W_k, Vc_k)``, and ``T_k >= F_k``: its time
   is at least ``C_k = max(F_k, L_k / min(W_k, Vc_k))``. Otherwise it is *peaked*: its
   largest speed is at an instant ``t*_k`` strictly inside its time, and
   ``V_k > u_j + dr`` at both its breaks ``j``. (Where ``Vc_k <= W_k`` no segment is
   peaked.)
2. *Between two peaks.* Let ``k < k'`` be peaked, at break ``j`` (``k < j <= k'``) at time
   ``tau`` the speed is at most ``u_j``. Between ``t*_k`` and ``tau`` it falls by more than
   ``dr``: a fall phase ``P`` meets ``(t*_k, tau)``. ``P`` does not start before ``t*_k``
   (the speed falls all through a fall phase, and before ``t*_k`` on segment ``k`` it is
   below ``V_k``; before the segment, at its first break, it is at most ``u_k < V_k``).
   Alike, a rise phase ``Q`` meets ``(tau, t*_{k'})`` and ends by ``t*_{k'}``. The two
   are disjoint intervals, ``P`` holds an instant before ``tau`` and ``Q`` one after, so
   ``P`` lies before ``Q``: ``t*_{k'} - t*_k >= |P| + |Q| >= 2 g`` (a phase lasts at
   least its effective duration; it moves the axes of a segment of the run). With flat
   segments ``k < i < k'`` between them (``S`` their ``sum C_i``, ``D`` their length,
   ``W*`` the largest ``min(W_i, Vc_i)``): ``P`` may run ``x`` into them, falling, so at
   most at ``u = u_{k+1}``, and ``Q`` ``y`` at most at ``u' = u_{k'}``; the flats take
   at least ``x + y + (D - u x - u' y)+ / W*``, and ``(g - x)+ + (g - y)+`` of the phases
   lie outside them. The sum is least at ``x = y = g`` (``u, u' <= W*``), so
   ``t*_{k'} - t*_k >= max(S, 2 g + (D - (u + u') g)+ / W*)``.
3. *The ends.* Before the first peak ``k1`` lie the flats ``a .. k1 - 1``, and the rise
   ``Q`` to ``V_{k1}`` ends by ``t*_{k1}``. Where break ``a`` is a path end or a hold, no
   phase runs through it: as in step 2, ``t*_{k1} - t_a >= max(S, g + (D - u_{k1} g)+ /
   W*)``. Elsewhere ``Q`` may start ``c`` before ``t_a``, on segment ``a - 1``: that is
   a creep at most at ``u_a`` as in :mod:`optimal.freq.windows`, and segment ``a - 1``
   takes at least its creep cost ``P(c)`` (:func:`~optimal.freq.windows.creep_cells`,
   with the neighbour's own phase beside the creep);
   what is left of ``Q`` is ``(g - c)+``: ``T_{a-1} + t*_{k1} - t_a >= max(S, r + (D -
   u_{k1} r)+ / W*) + P(c)``, ``r = (g - c)+``, least over the cells of ``c``. With no
   peak in the run, the neighbour takes at least the least ``P``. After the last peak
   alike (the fall, segment ``b + 1``).
4. *The row.* ``T_{a-1} + .. + T_{b+1}`` (the neighbours where they are in) is at least
   the smallest of these sums over the choice of peaked segments: a shortest path over
   the segments (:func:`_chain_bound`). Between peaks more than :data:`CHAIN_WINDOW`
   segments apart the path takes ``S`` alone (still a bound), so its cost is linear in
   the run's length.

Runs: maximal runs of segments on which a peak costs more than the floor and so does
crossing flat (``min(2 g_k, C_k) > F_k``); elsewhere the row cannot bind. A run is cut at
holds (step 3 holds the rest there).

Units: mm, s, mm/s.
"""

from __future__ import annotations

import numpy as np

from reference.core.geometry import Path
from reference.core.limits import AxisArrays

from ..jerk.relaxation import RunFloors
from ..tolerances import LB_ROUNDOFF_REL
from .windows import WINDOW_MIN_GAIN_REL, RuleEnvelope, creep_cells, rule_envelope

__all__ = ["CHAIN_WINDOW", "chain_rows"]

#: Earlier peaks within this many segments get the gap of step 2 in full; beyond, the
#: flats' sum alone (the path's cost grows with it, not with the run's length squared).
CHAIN_WINDOW = 32


def chain_rows(path: Path, lim: AxisArrays, t_ipo: float, acc_grid_s: np.ndarray,
               floors: np.ndarray, t_upper: float,
               hold_breaks: np.ndarray | None = None,
               rule: RuleEnvelope | None = None) -> RunFloors:
    """The rows of the module docstring; arguments as
    :func:`optimal.freq.windows.window_rows` (``floors``: the relaxation's own floor per
    segment, s; ``rule``: the rule's bounds of the same arguments, where the caller has
    them).

    Returns
    -------
    RunFloors
        One row per run, over the run and its neighbours.
    """
    m = path.n_segments
    none = RunFloors(np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0))
    if m == 0 or not np.isfinite(t_upper):
        return none
    if rule is None:
        rule = rule_envelope(path, lim, t_ipo, acc_grid_s, t_upper, hold_breaks)
    floors = np.asarray(floors, dtype=np.float64)
    L = path.length
    w = np.maximum(rule.u[:-1], rule.u[1:]) + rule.dr
    peak_ok = np.isfinite(rule.vc) & (rule.vc > w)
    w_flat = np.minimum(w, rule.vc)                # the speed of a flat segment at most
    with np.errstate(divide="ignore"):
        flat = np.maximum(floors, L / w_flat)
    gain = 1.0 + WINDOW_MIN_GAIN_REL
    binds = ((rule.g > 0) & (np.minimum(2.0 * rule.g, flat) * (1.0 - LB_ROUNDOFF_REL)
                             > floors * gain))
    # maximal runs of binding segments, cut at the holds
    starts = np.flatnonzero(binds & (~np.r_[False, binds[:-1]] | rule.cut[:-1]))
    lo, hi, value = [], [], []
    for a in starts:
        b = a + 1
        while b < m and binds[b] and not rule.cut[b]:
            b += 1
        g = float(np.min(rule.g[a:b]))
        start = _EndCost(rule, a, g, leaving=True)
        end = _EndCost(rule, b, g, leaving=False)
        v = _chain_bound(flat[a:b], L[a:b], w_flat[a:b], rule.u[a:b + 1], peak_ok[a:b], g,
                         start, end) * (1.0 - LB_ROUNDOFF_REL)
        r0, r1 = a - (not rule.cut[a]), b + (not rule.cut[b])
        if v > float(np.sum(floors[r0:r1])) * gain:
            lo.append(r0)
            hi.append(r1)
            value.append(v)
    if not lo:
        return none
    return RunFloors(np.asarray(lo, np.int64), np.asarray(hi, np.int64), np.asarray(value))


class _EndCost:
    """Step 3 at break ``j``, one end of a run: :meth:`__call__` bounds the time from the
    peak nearest the end to it, plus the neighbour's beyond it (none at a cut)."""

    def __init__(self, rule: RuleEnvelope, j: int, g: float, leaving: bool):
        self.g = g
        if rule.cut[j]:              # no phase runs through: c = 0, no neighbour
            self.cb, self.P = np.zeros(1), np.zeros(1)
            self.tail, self.least = np.inf, 0.0
            return
        nb = j - 1 if leaving else j
        cells = creep_cells(rule, np.array([nb]), np.array([j]), np.array([g]), leaving)
        self.cb, self.P = cells.cb[0], cells.P[0]
        self.tail, self.least = float(cells.tail[0]), float(cells.least[0])

    def __call__(self, S: np.ndarray, D: np.ndarray, w_star: np.ndarray,
                 u_near: np.ndarray) -> np.ndarray:
        """The bound, s, shape of ``S``: ``S`` the flats' time between the peak and the
        end (s), ``D`` their length (mm), ``w_star`` their speed at most (mm/s, ``inf``
        for none) and ``u_near`` the speed bound at the peak segment's break on this
        side, mm/s."""
        r = np.maximum(self.g - self.cb, 0.0)[None, :]            # (1, cells)
        spread = _flats_beyond(D[:, None], u_near[:, None] * r, w_star[:, None])
        inside = np.min(np.maximum(S[:, None], r + spread) + self.P[None, :], axis=1)
        return np.minimum(inside, S + self.tail)


def _flats_beyond(D: np.ndarray, covered: np.ndarray, w_star: np.ndarray) -> np.ndarray:
    """Step 2: the least time on flats of length ``D`` (mm) beyond the ``covered`` mm the
    phases that run into them cover, crossed at most at ``w_star`` (mm/s), s; 0 where
    there are no flats (``D = 0``, ``w_star`` 0 or ``inf``)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(D > 0, np.maximum(D - covered, 0.0) / w_star, 0.0)


def _chain_bound(flat: np.ndarray, L: np.ndarray, w_flat: np.ndarray, u: np.ndarray,
                 peak_ok: np.ndarray, g: float, start: _EndCost, end: _EndCost) -> float:
    """Step 4: the smallest time of a run and its neighbours over the choice of peaked
    segments, s.

    Over the run's n segments: ``flat`` the time of each crossed flat (``C_k``), ``L``
    the lengths, ``w_flat`` the speed of each crossed flat at most, ``u`` the speed
    bounds at its n + 1 breaks, ``peak_ok`` where a peak may be, ``g`` the shortest
    phase. ``D[k]``, the least time from the run's start (its neighbour's included) to
    the peak of ``k``, is ``start(...)`` over the flats before ``k`` or ``D[k0]`` plus
    step 2's gap over earlier peaks ``k0``; the run then takes ``min_k D[k] + end(...)``
    over the flats after ``k``, or with no peak ``sum C`` and its neighbours' least.
    """
    n = flat.size
    P = np.concatenate(([0.0], np.cumsum(flat)))          # flats' time before k
    LP = np.concatenate(([0.0], np.cumsum(L)))
    w_before = np.concatenate(([np.inf], np.maximum.accumulate(w_flat)))[:n]
    w_after = np.concatenate((np.maximum.accumulate(w_flat[::-1])[::-1][1:], [np.inf]))
    first = start(P[:-1], LP[:-1], w_before, u[:-1])      # the first peak at k
    last = end(P[n] - P[1:], LP[n] - LP[1:], w_after, u[1:])
    D = np.full(n, np.inf)
    far_min = np.inf         # min of D[k0] - P[k0 + 1] over k0 < k - CHAIN_WINDOW
    f = 0                    # the next peak to leave the window
    for k in np.flatnonzero(peak_ok):
        while f < k - CHAIN_WINDOW:        # beyond the window the gap is at least S
            far_min = min(far_min, D[f] - P[f + 1])
            f += 1
        d = min(float(first[k]), far_min + P[k])
        lo = max(0, k - CHAIN_WINDOW)
        k0 = np.arange(lo, k)
        # the flats between k0 and k: their time, length and top speed (0 for none)
        S = P[k] - P[k0 + 1]
        Dl = LP[k] - LP[k0 + 1]
        w_star = np.concatenate((np.maximum.accumulate(w_flat[lo + 1:k][::-1])[::-1], [0.0]))
        spread = _flats_beyond(Dl, (u[k0 + 1] + u[k]) * g, w_star)
        d = min(d, float(np.min(D[k0] + np.maximum(S, 2.0 * g + spread), initial=np.inf)))
        D[k] = d
    return float(min(np.min(D + last, initial=np.inf),
                     P[n] + start.least + end.least))
