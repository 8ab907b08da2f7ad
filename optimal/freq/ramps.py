"""``acc+freq`` and ``jerk+freq`` upper bound on straight pieces: the ramp plan.

On a rest-to-rest piece made of straight segments every speed change can be a *ramp*: a
constant path acceleration lasting ``tau = max(1/f, |dv| / A)`` (``A = min_i A_i / |d_i|``
on a line, ``d`` its unit direction; ``f`` the smallest LOOKAH_FREQUENCY of the axes
moving on it). A constant acceleration is a phase whose effective duration is its
duration (:mod:`reference.core.phases`), so a motion of ramps of at least ``1/f`` meets the
frequency rule, and it keeps the axis accelerations on lines. The plan chooses the speed
at every break and, on every segment, a *hump*: a ramp from the break speed up to a
plateau, the plateau, and a ramp down to the next break speed (either ramp may be
absent):

1. break speeds start at their caps (the junction rule of
   :func:`optimal.problem.junction_speed_caps`, the speed caps of both segments, rest at
   the piece's ends); forward and backward passes then lower them until every segment
   can make its change with one ramp: a change on a segment of length ``L`` from ``a`` to
   ``b != a`` covers ``tau (a + b) / 2`` (``= (b^2 - a^2) / (2 A)`` where ``A`` binds,
   ``= (a + b) / (2 f)`` where ``1/f`` does), so the largest reachable ``b`` is
   ``2 L f - a`` or ``sqrt(a^2 + 2 A L)``, and where not even the smallest change fits,
   the segment keeps its speed;
2. on every segment the plateau is the highest speed (at most the segment's cap) whose
   two ramps fit in its length: the time ``tau_up + tau_down + (L - D_up - D_down) / P``
   falls as ``P`` grows in both regimes, so the highest fitting plateau is the fastest
   hump for those break speeds.

Under ``jerk+freq`` every ramp is a symmetric S-curve instead (jerk ``J = min_i J_i /
|d_i|``, acceleration at most ``A``): the shortest lasts ``2 sqrt(dv / J)`` or ``dv / A +
A / J``, a longer one (to ``1/f``) a trapezoid of acceleration with the peak ``a_p`` of
``tau = dv / a_p + a_p / J``. It starts and ends at zero acceleration, is symmetric (its
effective duration is its duration) and covers ``tau (a + b) / 2`` as the constant ramp
does, so the plan is the same with that ``tau``. At a corner the path acceleration is zero
on both sides, so the axis accelerations do not step there; each segment's phases are
integrated on their own and end exactly at its break, so that no phase carries one
segment's jerk a round-off onto the next direction.

This is the motion of the closed form of DESIGN 6 (a rest-to-rest line at ``v`` with
``v/A < 1/f`` takes ``L/v + 1/f``) on every segment between corners; at a corner between
long segments it dips to the corner's cap with ramps of ``1/f`` on both sides, which the
lower bound of :mod:`optimal.freq.humps` charges too. Where segments are too short for a
ramp at the speeds beside them (many short segments at low speed) the passes make them
cruise, which is feasible but slow. A ramp on one segment next to one on the next, of the
same sign and with no cruise between, is one phase of the two; each ramp lasting its own
``1/f`` keeps that phase's effective duration at least the shorter of the two. Whatever
the construction assumes, the candidate is judged by ``check_profile`` like every other
(:func:`optimal.freq.upper.verified`).

Units: mm, s, mm/s.
"""

from __future__ import annotations

import math

import numpy as np

from reference.core.geometry import Path
from reference.core.limits import MachineLimits
from reference.core.profile import Profile

from ..problem import junction_speed_caps
from .lower import rest_pieces, segment_periods

__all__ = ["RAMP_PASSES", "ramp_plan"]

#: Most forward-backward rounds of the break speeds (each round lowers speeds only, so
#: they settle; a piece of ``m`` segments needs at most ``m`` rounds).
RAMP_PASSES = 64

#: Halvings of the bisections (plateau speed, S-curve reach): 2^-60 of the bracket.
_HALVINGS = 60


def _shortest(dv: float, A: float, J: float) -> float:
    """Shortest ramp of a speed change ``dv``, s: ``dv / A`` at constant acceleration
    (``J = inf``), else the S-curve's ``2 sqrt(dv / J)`` or ``dv / A + A / J``."""
    if not math.isfinite(J):
        return dv / A
    return 2.0 * math.sqrt(dv / J) if dv <= A * A / J else dv / A + A / J


def _ramp(a: float, b: float, A: float, J: float, T: float) -> tuple[float, float]:
    """Duration and length of the ramp from ``a`` to ``b``, (s, mm); none where equal."""
    if a == b:
        return 0.0, 0.0
    tau = max(T, _shortest(abs(b - a), A, J))
    return tau, tau * (a + b) / 2.0


def _reach(a: float, L: float, A: float, J: float, T: float) -> float:
    """The largest speed reachable from ``a`` with one ramp on a length ``L``, mm/s:
    ``2 L / T - a`` where the ramp lasts ``T``, else where the shortest ramp covers ``L``
    (``sqrt(a^2 + 2 A L)`` at constant acceleration, by bisection for S-curves); ``a``
    itself where no change fits (a ramp from ``a`` covers at least ``a T``)."""
    b = 2.0 * L / T - a
    if b > a and _shortest(b - a, A, J) > T:
        if not math.isfinite(J):
            b = math.sqrt(a * a + 2.0 * A * L)
        else:
            # the S-curve reaches less than the constant acceleration
            lo, hi = 0.0, math.sqrt(a * a + 2.0 * A * L) - a
            for _ in range(_HALVINGS):
                mid = 0.5 * (lo + hi)
                if _shortest(mid, A, J) * (a + mid / 2.0) <= L:
                    lo = mid
                else:
                    hi = mid
            b = a + lo
    return max(b, a)


def _plateau(a: float, b: float, L: float, F: float, A: float, J: float,
             T: float) -> float:
    """The highest plateau ``P`` in ``[max(a, b), F]`` whose two ramps fit in ``L``."""
    lo = max(a, b)
    if _ramp(a, F, A, J, T)[1] + _ramp(F, b, A, J, T)[1] <= L:
        return F
    hi = F
    for _ in range(_HALVINGS):
        mid = 0.5 * (lo + hi)
        if _ramp(a, mid, A, J, T)[1] + _ramp(mid, b, A, J, T)[1] <= L:
            lo = mid
        else:
            hi = mid
    return lo


def _phases(a: float, b: float, tau: float, A: float, J: float
            ) -> tuple[list[float], list[float], list[float]]:
    """Constant-jerk phases of the symmetric ramp from ``a`` to ``b`` lasting ``tau``:
    (durations, start accelerations, jerks); one constant-acceleration phase where
    ``J`` is infinite."""
    dv = b - a
    if not math.isfinite(J):
        return [tau], [dv / tau], [0.0]
    sg = 1.0 if dv > 0 else -1.0
    # the smaller root of a_p^2 / J - tau a_p + |dv| = 0 (at most A: tau is at least the
    # shortest ramp's)
    disc = max(tau * tau - 4.0 * abs(dv) / J, 0.0)
    ap = min(J * (tau - math.sqrt(disc)) / 2.0, A)
    tj = ap / J
    tc = max(tau - 2.0 * tj, 0.0)
    return [tj, tc, tj], [0.0, sg * ap, sg * ap], [sg * J, 0.0, -sg * J]


def _segment(a: float, b: float, L: float, F: float, A: float, J: float, T: float
             ) -> tuple[list[float], list[float], list[float]]:
    """Constant-jerk phases of the fastest hump on one segment between break speeds
    ``a`` and ``b``: (durations, start accelerations, jerks)."""
    P = _plateau(a, b, L, F, A, J, T)
    t_up, d_up = _ramp(a, P, A, J, T)
    t_dn, d_dn = _ramp(P, b, A, J, T)
    cruise = max(L - d_up - d_dn, 0.0) / P if P > 0 else 0.0
    h: list[float] = []
    a0: list[float] = []
    jk: list[float] = []
    for x, y, tau in ((a, P, t_up), (P, P, cruise), (P, b, t_dn)):
        if tau <= 0.0:
            continue
        ph = ([tau], [0.0], [0.0]) if x == y else _phases(x, y, tau, A, J)
        for dur, acc0, jj in zip(*ph):
            if dur > 0.0:
                h.append(dur)
                a0.append(acc0)
                jk.append(jj)
    return h, a0, jk


def ramp_plan(path: Path, limits: MachineLimits, jerk: bool = False
              ) -> dict[int, Profile]:
    """The ramp plan of every rest-to-rest piece made of straight segments.

    Parameters
    ----------
    path : Path
    limits : MachineLimits
    jerk : bool
        S-curve ramps under the axis jerk limits (``jerk+freq``); else ramps of constant
        acceleration (``acc+freq``).

    Returns
    -------
    dict
        Piece index (of :func:`optimal.freq.lower.rest_pieces`) to the motion on it (path
        positions absolute, time from 0); pieces with a curved segment are left out.
    """
    out: dict[int, Profile] = {}
    moving = path.moving_axes()
    work = path.restricted(moving) if 0 < moving.size < path.n_axes else path
    lim = limits.for_axes(work.axes)
    m = work.n_segments
    if m == 0:
        return out
    per = segment_periods(work, lim)
    line = (work.radius * np.abs(work.omega) == 0) & (work.sharpness == 0)
    d = np.abs(work.d)
    with np.errstate(divide="ignore"):
        acc = np.min(np.where(d > 0, lim.a_max[None, :] / d, np.inf), axis=1)
        cap = np.minimum(work.feed, np.min(np.where(d > 0, lim.v_max[None, :] / d, np.inf),
                                           axis=1))
        jmax = (np.min(np.where(d > 0, lim.j_max[None, :] / d, np.inf), axis=1) if jerk
                else np.full(m, np.inf))
    v_j, _ = junction_speed_caps(work, lim, permissive=False)
    L_all = work.length
    sb = work.s_breaks
    for k, (lo, hi) in enumerate(rest_pieces(work)):
        seg = np.arange(lo, hi)
        if not np.all(line[seg]) or np.any(per[seg] <= 0) or not np.all(
                np.isfinite(acc[seg]) & np.isfinite(cap[seg]) & (L_all[seg] > 0)):
            continue
        n = hi - lo
        L, A, F, T = (L_all[seg].astype(float), acc[seg].astype(float),
                      cap[seg].astype(float), per[seg].astype(float))
        J = jmax[seg].astype(float)
        if jerk and not np.all(np.isfinite(J) & (J > 0)):
            continue
        # break speeds: caps of the junction and of both segments, rest at the ends
        v = np.empty(n + 1)
        v[0] = v[n] = 0.0
        v[1:n] = np.minimum(np.minimum(v_j[lo + 1:hi], F[:-1]), F[1:])
        if not np.all(np.isfinite(v)):
            continue
        for _ in range(RAMP_PASSES):
            before = v.copy()
            for i in range(n):                       # forward: what each rise can reach
                v[i + 1] = min(v[i + 1], _reach(v[i], L[i], A[i], J[i], T[i]))
            for i in range(n - 1, -1, -1):           # backward: what each fall can shed
                v[i] = min(v[i], _reach(v[i + 1], L[i], A[i], J[i], T[i]))
            if np.array_equal(v, before):
                break
        # the humps, integrated segment by segment, each ending exactly at its break
        t_k, s_k, v_k = [0.0], [float(sb[lo])], [0.0]
        a_k: list[float] = []
        j_k: list[float] = []
        b_k: list[int] = []
        for i in range(n):
            h, a0, jk = _segment(float(v[i]), float(v[i + 1]), L[i], F[i], A[i], J[i], T[i])
            if not h:
                continue
            part = Profile.from_phases(h, a0, jk, s0=float(sb[lo + i]), v0=float(v[i]))
            s_part = part.s.copy()
            s_part[-1] = float(sb[lo + i + 1])
            t_k.extend(t_k[-1] + part.t[1:])
            s_k.extend(s_part[1:])
            v_k.extend(part.v[1:])
            a_k.extend(part.a)
            j_k.extend(part.j)
            b_k.extend([int(work.block[lo + i])] * len(h))
        if a_k:
            v_arr = np.array(v_k)
            v_arr[-1] = 0.0                  # rest at the piece's end, round-off removed
            out[k] = Profile(t=np.array(t_k), s=np.array(s_k), v=v_arr, a=np.array(a_k),
                             j=np.array(j_k), block=np.array(b_k))
    return out
