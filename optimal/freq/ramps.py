"""``acc+freq`` and ``jerk+freq`` upper bound per rest-to-rest piece: the ramp plan.

On a rest-to-rest piece every speed change can be a *ramp*: a constant path acceleration
lasting ``tau = max(1/f, |dv| / A)`` (``A = min_i A_i / |d_i|`` on a line, ``d`` its unit
direction; on a curve the budget of the next section; ``f`` the smallest LOOKAH_FREQUENCY
of the axes moving on it). A constant acceleration is a phase whose effective duration
is its duration (:mod:`reference.core.phases`), so a motion of ramps of at least ``1/f``
meets the frequency rule, and it keeps the axis accelerations within their limits. The
plan chooses the speed at every break and, on every segment, a *hump*: a ramp from the
break speed up to a plateau, the plateau, and a ramp down to the next break speed
(either ramp may be absent):

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

Curves
------
On an arc, a helix, a spiral or a clothoid the axis accelerations also carry the
centripetal part ``q''_i v^2``, and the axis jerks the terms ``3 q''_i v s''`` and
``q'''_i v^3``. Each curve gets a plateau cap ``V`` (a share of its curvature-limited
speed, :data:`RAMP_CURVE_SHARES`, one share for the whole piece, the fastest plan kept)
and the budgets ``A``, ``J`` that keep every axis within its limits at every point of the
curve and every speed up to ``V`` (:func:`_budgets`: exact suprema on circles and
helices, where the tangent and the radius are orthogonal, the parts added on spirals and
clothoids). With those constants the plan above is unchanged: every speed on the segment
is at most ``V``, every path acceleration at most ``A``. At a break where the curvature
jumps the plan's path acceleration is zero, so under ``jerk+freq`` only the centripetal
step ``|dq''_i| v^2`` counts there, and the break takes the rulebook's cap for it.
Measured on the default machine: ``lcnc_test_12mmflat`` (91 lines, 39 arcs) ``acc+freq``
upper bound 38.843 -> 38.320 s, ``jerk+freq`` 40.439 -> 39.241 s; ``sin_cead_arc`` 35.863
-> 35.710 s (bracket 1.00 -> 0.57 %); ``lcnc_sam_tolerance_issue`` ``jerk+freq`` 3.625 ->
2.71 s. On ``lcnc_arc_arc_sawtooth`` (6 mm arcs between cusps crossed at 1 mm/s) the
plan (6.01 s) stays above the other candidates (5.31 s): one budget per arc, taken at its
top speed, is too cautious where every arc is a hump of its own.

Units: mm, s, mm/s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from reference.core.geometry import Path, axis_tangent_amplitudes, plane_amplitudes
from reference.core.limits import MachineLimits
from reference.core.profile import Profile
from reference.core.rules import curvature_jump_speed_cap

from ..problem import junction_speed_caps
from .lower import rest_pieces, segment_periods

__all__ = ["RAMP_BUDGET_ROUNDOFF_REL", "RAMP_CROSS_JERK_SHARE", "RAMP_CURVE_SHARES",
           "RAMP_PASSES", "ramp_plan"]

#: Most forward-backward rounds of the break speeds (each round lowers speeds only, so
#: they settle; a piece of ``m`` segments needs at most ``m`` rounds).
RAMP_PASSES = 64

#: An S-curve whose constant-acceleration part is below this share of its duration is
#: built as a triangle (round-off of ``tau - 2 a_p / J`` where the shortest ramp binds).
_TRIANGLE_REL = 1e-9

#: Halvings of the bisections (plateau speed, S-curve reach): 2^-60 of the bracket.
_HALVINGS = 60


def _shortest(dv: float, A: float, J: float) -> float:
    """Shortest ramp of a speed change ``dv``, s: ``dv / A`` at constant acceleration
    (``J = inf``), else the S-curve's ``2 sqrt(dv / J)`` or ``dv / A + A / J``; ``inf``
    where ``A`` or ``J`` is 0 (no change fits)."""
    if A <= 0.0 or J <= 0.0:
        return math.inf
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
    if A <= 0.0 or J <= 0.0:
        return a
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
    # shortest ramp's), in the form without cancellation: J (tau - sqrt(disc)) / 2 loses
    # every digit where tau >> a_p / J (long ramps of a small budget, on curves)
    disc = max(tau * tau - 4.0 * abs(dv) / J, 0.0)
    ap = min(2.0 * abs(dv) / (tau + math.sqrt(disc)), A)
    tj = ap / J
    tc = tau - 2.0 * tj
    if tc <= _TRIANGLE_REL * tau:
        # a triangle of acceleration, up to round-off: a constant part of ~1e-17 s would
        # not advance the position in floating point, and the checker would cut the
        # phase in two there; its jerk 4 |dv| / tau^2 (at most J, tau being at least the
        # shortest ramp) keeps the change exact
        jj = 4.0 * abs(dv) / (tau * tau)
        return [tau / 2.0, tau / 2.0], [0.0, sg * jj * tau / 2.0], [sg * jj, -sg * jj]
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


#: Shares of a curved segment's curvature-limited speed tried as its plateau cap, highest
#: first. A curve's centripetal acceleration ``|q''_i| v^2`` leaves its ramps
#: ``(A_i - |q''_i| V^2) / |q'_i|`` at speeds up to ``V``: at the full share nothing is
#: left and the curve is crossed at constant speed (best on long curves: the lines beside
#: it ramp), lower shares trade plateau speed for ramps (best where curves meet at corners
#: and must dip). One share for the whole piece; the fastest plan is kept.
RAMP_CURVE_SHARES = (1.0, 0.97, 0.9, 0.8, 0.65, 0.5)

#: Budgets below this share of the segment's budget without its curvature terms are
#: round-off of a curve crossed at its curvature limit (``A_i - |q''_i| V^2`` of a ``V``
#: computed from it), and count as none: a ramp of such a budget would last ~1e14 times
#: the segment's crossing time, and its integration would lose the position.
RAMP_BUDGET_ROUNDOFF_REL = 1e-9

#: Under ``jerk+freq``, the part of a curve's jerk room (``J_i - |q'''_i| V^3``) its
#: ramps' acceleration may spend on the cross term ``3 |q''_i| v s''``; the rest is left
#: to the ramps' own jerk ``|q'_i| s'''``.
RAMP_CROSS_JERK_SHARE = 0.5


@dataclass(frozen=True)
class _Kinematics:
    """Per segment and axis, shape (m, n) each: suprema of the axis derivatives of the
    path on the segment.

    ``d`` is ``|d_i|`` (the constant part of ``q'_i``), ``p``, ``k`` and ``k3`` the
    suprema of the rotating parts of ``q'_i``, of ``|q''_i|`` and of ``|q'''_i|``: the
    in-plane amplitudes of :func:`reference.core.geometry.plane_amplitudes` times
    ``sqrt(e1_i^2 + e2_i^2)`` (a vector in the plane has components at most its norm
    times that; ``q'''``'s tangential and normal parts by the norm of the two).
    ``circular`` (shape (m,)): lines, circles and helices, where the rotating part of
    ``q'`` and ``q''`` are orthogonal in the plane at every point (the tangent and the
    radius of the circle) and ``q'''`` is along the tangent, so that the exact suprema of
    :func:`_budgets` apply; elsewhere (spirals, clothoids) their parts are added.
    """

    d: np.ndarray
    p: np.ndarray
    k: np.ndarray
    k3: np.ndarray
    circular: np.ndarray

    @classmethod
    def of(cls, work: Path) -> "_Kinematics":
        amp = plane_amplitudes(work)
        D, P = axis_tangent_amplitudes(work, amp)
        rho = np.sqrt(work.e1 ** 2 + work.e2 ** 2)
        circular = (work.dradius == 0) & (work.sharpness == 0)
        return cls(D, P, rho * amp.curvature[:, None],
                   rho * np.hypot(amp.jerk_t, amp.jerk_n)[:, None], circular)


def _largest(h, hi: np.ndarray) -> np.ndarray:
    """Largest ``x`` in ``[0, hi]`` with ``h(x) <= 0`` for ``h`` increasing (elementwise,
    by bisection; 0 where ``h(0) > 0``, ``hi`` where ``h(hi) <= 0``)."""
    lo = np.zeros_like(hi)
    top = np.where(np.isfinite(hi), hi, 0.0)
    ok = h(lo) <= 0.0
    done = ok & (h(top) <= 0.0)
    up = top.copy()
    for _ in range(_HALVINGS):
        mid = 0.5 * (lo + up)
        fits = h(mid) <= 0.0
        lo = np.where(fits, mid, lo)
        up = np.where(fits, up, mid)
    return np.where(done, top, np.where(ok, lo, 0.0))


def _budgets(kin: _Kinematics, lim, V: np.ndarray, jerk: bool
             ) -> tuple[np.ndarray, np.ndarray]:
    """Path acceleration and jerk ``A, J`` (mm/s^2, mm/s^3, shape (m,)) that keep every
    axis within its limits at every point of the segments and every speed up to ``V``.

    With ``q'_i = d_i + p_i T``, ``q''_i = k_i N``, ``q'''_i = -k3_i T`` on circles and
    helices (``T``, ``N`` the in-plane tangent and normal components, ``T^2 + N^2 <= 1``
    per axis after the amplitudes), the rulebook's axis kinematics give
    ``|q'_i s'' + q''_i v^2| <= d_i |s''| + sqrt((p_i s'')^2 + (k_i v^2)^2)`` and
    ``|q'_i s''' + 3 q''_i v s'' + q'''_i v^3| <= d_i |s'''| + sqrt((p_i |s'''| + k3_i
    v^3)^2 + (3 k_i v s'')^2)``; on spirals and clothoids the parts are added
    (``(d_i + p_i) |s''| + k_i v^2`` and ``(d_i + p_i) |s'''| + 3 k_i v |s''| + k3_i
    v^3``). ``A`` is the largest acceleration these keep within ``A_i`` at ``v = V``
    (under ``jerk`` first held to what leaves :data:`RAMP_CROSS_JERK_SHARE` of the
    jerk room ``J_i - k3_i V^3`` to the cross term), ``J`` the largest jerk then within
    ``J_i``. 0 where nothing is left (the segment is then crossed at constant speed);
    ``J`` is ``inf`` without ``jerk``."""
    Vc = V[:, None]
    d, p, k, k3 = kin.d, kin.p, kin.k, kin.k3
    circ = kin.circular[:, None]
    q1 = d + p
    mv = q1 > 0
    a_i, j_i = lim.a_max[None, :], lim.j_max[None, :]
    c2 = k * Vc * Vc                                  # centripetal part at V
    with np.errstate(divide="ignore", invalid="ignore"):
        hi_a = np.where(mv, a_i / np.where(mv, np.maximum(d, p), 1.0), np.inf)
        A_ax = _largest(lambda x: np.where(
            circ, d * x + np.hypot(p * x, c2), q1 * x + c2) - a_i, hi_a)
        A = np.min(np.where(mv, A_ax, np.inf), axis=1)
        A_line = np.min(np.where(mv, a_i / np.where(mv, q1, 1.0), np.inf), axis=1)
        if not jerk:
            return _no_residue(A, A_line), np.full(V.shape, np.inf)
        room = j_i - k3 * Vc ** 3
        cross = np.where(k * Vc > 0, RAMP_CROSS_JERK_SHARE * room
                         / np.where(k * Vc > 0, 3.0 * k * Vc, 1.0), np.inf)
        A = np.maximum(np.minimum(A, np.min(np.where(mv, cross, np.inf), axis=1)), 0.0)
        c3 = k3 * Vc ** 3
        x3 = 3.0 * k * Vc * A[:, None]                # cross term at V and A
        hi_j = np.where(mv, j_i / np.where(mv, np.maximum(d, p), 1.0), np.inf)
        J_ax = _largest(lambda x: np.where(
            circ, d * x + np.hypot(p * x + c3, x3), q1 * x + x3 + c3) - j_i, hi_j)
        J = np.min(np.where(mv, J_ax, np.inf), axis=1)
        J_line = np.min(np.where(mv, j_i / np.where(mv, q1, 1.0), np.inf), axis=1)
    return _no_residue(A, A_line), _no_residue(J, J_line)


def _no_residue(x: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """``x`` with values below :data:`RAMP_BUDGET_ROUNDOFF_REL` of ``scale`` set to 0."""
    return np.where(x <= RAMP_BUDGET_ROUNDOFF_REL * scale, 0.0, x)


def _piece(L: np.ndarray, A: np.ndarray, F: np.ndarray, T: np.ndarray, J: np.ndarray,
           v_inner: np.ndarray, sb: np.ndarray, blocks: np.ndarray) -> Profile | None:
    """The ramp plan of one rest-to-rest piece of ``n`` segments.

    Parameters
    ----------
    L, A, F, T, J : numpy.ndarray, shape (n,)
        Lengths (mm), path acceleration budgets (mm/s^2), plateau caps (mm/s), periods
        ``1/f`` (s), path jerk budgets (mm/s^3, ``inf`` for constant ramps).
    v_inner : numpy.ndarray, shape (n - 1,)
        Caps at the inner breaks, mm/s.
    sb : numpy.ndarray, shape (n + 1,)
        Break positions, mm.
    blocks : numpy.ndarray of int, shape (n,)
        Block of each segment.

    Returns
    -------
    Profile or None
        None where a segment cannot be crossed (it stays at rest: a curve with no room
        to ramp next to a stop).
    """
    n = L.size
    v = np.empty(n + 1)
    v[0] = v[n] = 0.0
    v[1:n] = np.minimum(np.minimum(v_inner, F[:-1]), F[1:])
    if not np.all(np.isfinite(v)):
        return None
    for _ in range(RAMP_PASSES):
        before = v.copy()
        for i in range(n):                       # forward: what each rise can reach
            v[i + 1] = min(v[i + 1], _reach(v[i], L[i], A[i], J[i], T[i]))
        for i in range(n - 1, -1, -1):           # backward: what each fall can shed
            v[i] = min(v[i], _reach(v[i + 1], L[i], A[i], J[i], T[i]))
        if np.array_equal(v, before):
            break
    # the humps, integrated segment by segment, each ending exactly at its break
    t_k, s_k, v_k = [0.0], [float(sb[0])], [0.0]
    a_k: list[float] = []
    j_k: list[float] = []
    b_k: list[int] = []
    for i in range(n):
        h, a0, jk = _segment(float(v[i]), float(v[i + 1]), L[i], F[i], A[i], J[i], T[i])
        if not h:
            return None      # stuck at rest (a curve with no room to ramp beside a stop)
        part = Profile.from_phases(h, a0, jk, s0=float(sb[i]), v0=float(v[i]))
        s_part = part.s.copy()
        s_part[-1] = float(sb[i + 1])
        t_k.extend(t_k[-1] + part.t[1:])
        s_k.extend(s_part[1:])
        v_k.extend(part.v[1:])
        a_k.extend(part.a)
        j_k.extend(part.j)
        b_k.extend([int(blocks[i])] * len(h))
    if not a_k:
        return None
    v_arr = np.array(v_k)
    v_arr[-1] = 0.0                  # rest at the piece's end, round-off removed
    return Profile(t=np.array(t_k), s=np.array(s_k), v=v_arr, a=np.array(a_k),
                   j=np.array(j_k), block=np.array(b_k))


def ramp_plan(path: Path, limits: MachineLimits, jerk: bool = False
              ) -> dict[int, Profile]:
    """The ramp plan of every rest-to-rest piece.

    Lines take the budgets of the module docstring, curves (arcs, helices, spirals,
    clothoids) those of :func:`_budgets` at a plateau cap of a share
    (:data:`RAMP_CURVE_SHARES`) of their curvature-limited speed. Under ``jerk+freq`` a
    break where the curvature jumps also takes the rulebook's cap for that step
    (:func:`reference.core.rules.curvature_jump_speed_cap`): the plan's path acceleration
    is zero at every break, so the step is the centripetal one alone.

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
        positions absolute, time from 0); pieces without a plan (a segment without a
        period or a length, an unbounded cap) are left out.
    """
    out: dict[int, Profile] = {}
    moving = path.moving_axes()
    work = path.restricted(moving) if 0 < moving.size < path.n_axes else path
    lim = limits.for_axes(work.axes)
    m = work.n_segments
    if m == 0:
        return out
    per = segment_periods(work, lim)
    kin = _Kinematics.of(work)
    q1, q2, q3 = kin.d + kin.p, kin.k, kin.k3
    mv = q1 > 0
    curved = np.any(q2 > 0, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        cap = np.minimum(work.feed, np.min(np.where(
            mv, lim.v_max[None, :] / np.where(mv, q1, 1.0), np.inf), axis=1))
        # the curvature-limited speed: no tangential acceleration (or jerk) left at all
        pos2, pos3 = q2 > 0, q3 > 0
        v_curve = np.min(np.where(
            pos2, np.sqrt(lim.a_max[None, :] / np.where(pos2, q2, 1.0)), np.inf), axis=1)
        if jerk:
            v_curve = np.minimum(v_curve, np.min(np.where(
                pos3, np.cbrt(lim.j_max[None, :] / np.where(pos3, q3, 1.0)), np.inf),
                axis=1))
    v_j, _ = junction_speed_caps(work, lim, permissive=False)
    sb = work.s_breaks
    if jerk and m >= 2:
        _, _, k_in, _ = work.evaluate(sb[1:m], segment=np.arange(m - 1))
        _, _, k_out, _ = work.evaluate(sb[1:m], segment=np.arange(1, m))
        v_j[1:m] = np.minimum(v_j[1:m], curvature_jump_speed_cap(
            k_in, k_out, np.maximum(lim.path_trans_jerk, lim.j_max), limits.t_ipo_s))
    L_all = work.length
    # the caps and budgets of every share, for the whole path at once (a share changes
    # nothing on lines: a path without curves takes the first alone; the pieces only
    # take their rows)
    budgets = []
    for share in (RAMP_CURVE_SHARES if np.any(curved) else RAMP_CURVE_SHARES[:1]):
        F = np.minimum(cap, share * v_curve)
        budgets.append((F, *_budgets(kin, lim, F, jerk)))
    for k, (lo, hi) in enumerate(rest_pieces(work)):
        seg = np.arange(lo, hi)
        if np.any(per[seg] <= 0) or not np.all(np.isfinite(cap[seg]) & (L_all[seg] > 0)):
            continue
        best: Profile | None = None
        for F_all, A_all, J_all in (budgets if np.any(curved[seg]) else budgets[:1]):
            F, A, J = F_all[seg], A_all[seg], J_all[seg]
            if not np.all(np.isfinite(A)) or (jerk and not np.all(np.isfinite(J))):
                continue
            prof = _piece(L_all[seg].astype(float), A, F, per[seg].astype(float), J,
                          v_j[lo + 1:hi], sb[lo:hi + 1], work.block[seg])
            if prof is not None and (best is None or prof.duration < best.duration):
                best = prof
        if best is not None:
            out[k] = best
    return out
