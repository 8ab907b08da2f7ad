"""Certified lower bound of the minimum time under the ``jerk`` bound set.

The problem
===========
A *jerk-feasible motion* is a motion ``s(t)`` with ``b = v^2`` as in the ``acc`` problem
(axis velocity, axis acceleration, feed, rest at ``path.stop`` breaks, the velocity-jump
rule at corners) whose path acceleration is absolutely continuous between segment
breaks with ``|q'_i s''' + 3 q''_i v s'' + q'''_i v^3| <= J_i`` almost everywhere, and
whose axis acceleration steps only at segment breaks and at the path ends, by at most
``Jstep_i T_ipo`` (:func:`reference.core.rules.step_jerk_limit`; the surroundings of the
path ends rest with zero acceleration). This is the issue's definition and what the
upper bound's profiles satisfy. (``check_profile`` also accepts a step of up to
``J_i T_ipo`` at *every* knot of a profile, so a profile with many knots could build up
acceleration in steps; such motions are not jerk-limited and not in this set.)

Why the bound holds
===================
1. *Segments.* Every motion's time is the sum of the times ``T_g`` it spends on the
   segments ``g``; any valid lower bound of each ``T_g`` may be used, and the largest of
   several is one too: ``T >= sum_g max_i LB_g,i``.
2. *Acc relaxation.* Every jerk-feasible motion is ``acc``-feasible. In the ``acc``
   relaxation of :func:`optimal.bounds.lower_bound` every feasible motion has
   ``b(s_k) <= bhat_k`` at the nodes and ``b <= tent`` inside every interval (steps 3-4
   of that module's docstring), so the tent time of each interval bounds the time
   *every* feasible motion spends there, and their sum over a segment's intervals
   bounds ``T_g``. Node bounds that hold for every jerk-feasible motion (step 5) may be
   given to that relaxation as extra node caps; its proof is unchanged.
3. *Straight runs between stops.* A run that is one line segment with direction
   ``u = q'`` has ``q'' = q''' = 0``: the axis constraints are exactly ``|v| <= V``,
   ``|s''| <= A``, ``|s'''| <= J`` with ``V = min(F, min_i V_i / |u_i|)``,
   ``A = min_i A_i / |u_i|``, ``J = min_i J_i / |u_i|``, and the path acceleration at
   its ends is at most ``a_s`` in size, the largest value the acceleration-step rule at
   rest allows (:func:`break_accelerations`: ``J T_ipo`` at the path start and end,
   unbounded at a 180 degree reversal). The minimum time of this 1-D problem, rest to
   rest with boundary acceleration up to ``a_s``, is that of the classical double-S
   profile that starts at ``s'' = a_s`` (Biagiotti & Melchiorri 2008, section 3.4;
   ruckig with ``current_acceleration = a_s``, ``target_acceleration = -a_s``
   computes the same, tests/optimal/test_jerk.py): accelerate as fast as the jerk and
   acceleration limits allow to the peak speed, cruise, decelerate symmetrically.
   :func:`rest_to_rest_time` gives it in closed form by extending the first jerk ramp
   back to zero acceleration (a virtual start at speed ``-a_s^2 / (2J)``). When the
   move is too short for that ramp (peak speed below ``a_s^2 / (2J)``, a few um on real
   machines) it returns the jerk-free time, a weaker bound.
4. *Peak speed on every segment* (:func:`peak_times`). On a segment of length ``L``
   take ``v <= vb0, |s''| <= as0`` at its start and ``v <= vb1, |s''| <= as1`` at its
   end (``bhat`` at the breaks and the step rule's allowance there,
   :func:`break_accelerations`), and path bounds ``v <= V``, ``|s''| <= A``,
   ``|s'''| <= J`` valid on the whole segment (exact on lines; on curves from
   :func:`_curve_limits`). First with a continuous path acceleration:

   a. *End peak.* If the speed peaks at an end, ``v <= p <= max(vb0, vb1)``
      throughout, and the speed can grow no faster than the fastest ramp
      ``F0(t) = vb0 + int_0^t min(A, as0 + J tau)`` from the start, nor (backwards)
      ``F1`` from the end: :func:`envelope_times` with the speed cap ``p``.
   b. *Inside peak.* If it peaks at ``t*`` inside, at ``p`` with ``s''(t*) = 0``: at
      every ``t < t*`` with ``s''(t) > 0`` the acceleration needs at least
      ``s''(t) / J`` to fall to zero (it is zero at ``t*``), during which the speed
      gains ``s''(t)^2 / (2 J)``, so ``v(t) <= p - s''(t)^2 / (2 J)``. With ``v <= F0``
      this gives ``v(t) <= v*(t)``, the fastest rise to ``p`` with zero acceleration
      (:func:`rise`: jerk ``+J``, a plateau at ``A``, jerk ``-J``, reaching ``p`` at
      ``tau0(p)`` after ``d0(p)``): before its landing phase ``v* = F0``; in it
      ``v*(t) = p - a*(t)^2 / (2J)`` with ``a*`` falling at rate ``J``, and a motion
      with ``s''(t) >= a*(t)`` is below ``v*`` by the inequality, one with
      ``s''(t) < a*(t)`` had ``s'' < a*`` all through the landing phase (its jerk is
      at least ``-J``) and started it no faster. So ``t* >= tau0(p)``, the distance to
      ``t*`` is at most ``d0(p) + p (t* - tau0(p))``, likewise from the end, and
      ``T >= g(p) = tau0 + tau1 + max(0, L - d0 - d1) / p``. ``tau`` and ``d`` grow with
      ``p`` and ``d' >= p tau'`` (``v*`` grows pointwise with ``p``, by the same
      comparison), so ``g`` falls while ``d0 + d1 <= L`` and rises after: its least
      value is at ``V`` or where ``d0 + d1 = L``.

   The bound is the smaller of a and b. *Steps inside the segment*: the rulebook lets
   the path acceleration step by ``eps`` in total inside a segment (``sqrt(n)`` times
   the largest axis budget ``ACCEL_CONTINUITY_TOL_REL J_i T_ipo``: some axis has
   ``|q'_i| >= 1/sqrt(n)``). Removing the steps leaves a continuous acceleration within
   ``eps`` of ``s''`` whose speed is within ``eps t`` of ``v`` and whose distance is
   within ``eps t^2 / 2`` of ``L``; so every motion faster than ``t_cap`` (twice the
   step-free bound) meets the bound with ``V + eps t_cap``, ``A + eps``,
   ``as + eps`` and ``L - eps t_cap^2 / 2``, and the bound is the smaller of that and
   ``t_cap``. On a straight run between two stops this is the exact minimum (step 3).
5. *Curvature-jump caps* (:func:`curvature_break_caps`): at a tangential break where the
   curvature vector jumps, the centripetal step ``dk v^2`` must fit the one-cycle
   allowance up to what a path-acceleration step can cancel; that bounds ``v^2`` there
   for every jerk-feasible motion (the ``acc`` problem has no such rule).
6. ``LB = sum_g max(step 2, step 3 or 0, step 4) (1 - JERK_LB_ROUNDOFF_REL) + holds``,
   never below the ``acc`` oracle's own certified lower bound, which is valid too (jerk
   limits only remove motions). Rest at stops is ``v = 0`` exactly, as in the ``acc``
   relaxation.

7. *Reach envelope* (:func:`reach_speed_caps`, used by the ``jerk+freq`` turn programme,
   :mod:`optimal.freq.humps`). On segment ``g``, at distance ``y`` from its start break
   ``k``, every jerk-feasible motion that lasts at most ``T_up`` has ``v <= P(y)``, the
   ``p`` with ``D(p) = y``, where ``D(p) = int_vb^p u / ahat(u) du``, ``vb`` the speed
   bound at the break, ``ahat(u) = min(A + eps, sqrt(alpha + 2 J u))`` and
   ``alpha = a_out^2 + 2 J eps T_up + 2 eps A + eps^2`` (``A``, ``J``, ``eps`` and the
   break's allowance ``a_out`` of step 4). Write ``s'' = c + sigma`` with ``sigma`` the
   steps inside the segment summed so far (``|sigma| <= eps``) and ``c`` absolutely
   continuous, ``|c'| <= J``, ``|c| <= a_out`` just after the break. Where ``c > 0``,
   ``(c^2)' = 2 c c' <= 2 J c <= 2 J (s'' + eps)``; integrated from the last time
   ``c <= 0`` (or from the break) this gives ``c^2 <= a_out^2 + 2 J (v + eps T_up)``
   (``v >= 0``, at most ``T_up`` since the break), and ``s'' <= c + eps`` is at most
   ``ahat(v)`` (``(x + eps)^2 <= x^2 + 2 eps A + eps^2`` for ``x <= A``; where ``c <= 0``,
   ``s'' <= eps``). With ``h(u) = u / ahat(u) >= 0`` and ``v`` going from ``v(0) <= vb``
   to ``p`` over the distance ``y``: ``y = int v dt >= int h(v) max(s'', 0) dt >=
   int h(v) s'' dt = int_v(0)^p h >= D(p)``, and ``D`` grows with ``p``. Run backwards
   in time a motion is jerk-feasible with the arriving allowance ``a_in`` of the end
   break, so the same holds from the end; the cap is the smaller of the two. On a line
   from rest (``vb = a_out = eps = 0``) ``P`` is the speed of the jerk ramp ``+J`` from
   rest at that distance: the cap is reached.

Where it is loose: on arcs the path acceleration and jerk bounds of step 4 are norms
over the axes (up to ``sqrt(n)`` above the pointwise values), and neighbouring segments
are coupled only through the node bounds and the step allowances at their common break.
The convex relaxation of :mod:`optimal.jerk.relaxation` takes these bounds as per-segment
floors and adds the coupling and the axis-wise jerk.

Units: mm, s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from reference.core.geometry import Path, plane_amplitudes
from reference.core.limits import AxisArrays
from reference.core.rules import RELAXED, curvature_jumps, is_tangential, step_jerk_limit
from reference.core.tolerances import ACCEL_CONTINUITY_TOL_REL, VEL_TOL_MM_S

from ..bounds import lower_bound
from ..grid import grid_on
from .tolerances import JERK_LB_ROUNDOFF_REL



def rest_to_rest_time(L: float, V: float, A: float, J: float, a_s: float = 0.0) -> float:
    """Minimum time of a straight move of length ``L`` from rest to rest.

    Parameters
    ----------
    L : float
        Distance, mm (> 0).
    V, A, J : float
        Path speed, acceleration and jerk limits, mm/s, mm/s^2, mm/s^3 (> 0).
    a_s : float
        Largest path acceleration allowed at the start and at the end (in size),
        mm/s^2 (clipped to ``[0, min(A, sqrt(2 J V))]``: no motion under ``V`` leaves
        rest faster).

    Returns
    -------
    float
        Seconds; the jerk-free bound ``L/V + V/A`` or ``2 sqrt(L/A)`` when the move is
        too short for the jerk ramp (see the module docstring, step 3).
    """
    # a motion leaving rest at acceleration a gains at least a^2 / (2 J) of speed before
    # its acceleration can fall to zero, so under v <= V it leaves (and, mirrored,
    # arrives) at no more than sqrt(2 J V): the allowance beyond that is none (at a
    # reversal, where the step rule allows any acceleration, the virtual start of the
    # closed form lay below -V and its distance came out negative: 7.22 s for a 1 mm
    # move at 10 mm/min that takes 6.00 s)
    a_s = min(max(a_s, 0.0), A, math.sqrt(2.0 * J * V))
    delta = a_s * a_s / (2.0 * J)
    a2j = A * A / J

    def half(vp: float) -> tuple[float, float]:
        # virtual S-ramp from -delta (a = 0) to vp; the real one starts a_s / J later
        dv = vp + delta
        tv = dv / A + A / J if dv >= a2j else 2.0 * math.sqrt(dv / J)
        return tv - a_s / J, 0.5 * (vp - delta) * tv + a_s ** 3 / (3.0 * J * J)

    t_v, d_v = half(V)
    if 2.0 * d_v <= L:
        return 2.0 * t_v + (L - 2.0 * d_v) / V
    if 2.0 * half(delta)[1] < L:
        vp = brentq(lambda x: 2.0 * half(x)[1] - L, delta, V, xtol=1e-15 * V, rtol=1e-15)
        return 2.0 * half(vp)[0]
    return L / V + V / A if V * V / A <= L else 2.0 * math.sqrt(L / A)


def _max_fixed(f: np.ndarray, g: np.ndarray, gamma: np.ndarray, z_max: float,
               w_nonneg: np.ndarray) -> np.ndarray:
    """Largest ``z`` in ``[0, z_max]`` with some ``w`` (``w >= 0`` on rows where
    ``w_nonneg``) meeting ``|g_i w + f_i z| <= gamma_i`` for every axis, per row.

    The set of such ``z`` is an interval containing 0 (the projection of a convex set
    that contains the origin); for fixed ``z`` the ``w`` allowed by each axis form an
    interval, and the constraint holds iff their intersection (with ``[0, inf)``
    where ``w_nonneg``) is not empty. Bisection; the upper end of the final bracket is
    returned, so the result is never below the true maximum.

    Parameters
    ----------
    f, g : numpy.ndarray, shape (k, n)
    gamma : numpy.ndarray, shape (n,) or (k, n)
    z_max : float
    w_nonneg : numpy.ndarray of bool, shape (k,)

    Returns
    -------
    numpy.ndarray, shape (k,)
    """
    def feasible(z: np.ndarray) -> np.ndarray:
        c = f * z[:, None]
        gz = g != 0
        with np.errstate(divide="ignore", invalid="ignore"):
            e1 = np.where(gz, (-gamma - c) / np.where(gz, g, 1.0), -np.inf)
            e2 = np.where(gz, (gamma - c) / np.where(gz, g, 1.0), np.inf)
        lo = np.max(np.minimum(e1, e2), axis=1)
        lo = np.where(w_nonneg, np.maximum(lo, 0.0), lo)
        hi = np.min(np.maximum(e1, e2), axis=1)
        ok_zero = np.all(gz | (np.abs(c) <= gamma), axis=1)
        return ok_zero & (lo <= hi)

    k = f.shape[0]
    lo = np.zeros(k)
    hi = np.full(k, z_max)
    top = feasible(hi)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        ok = feasible(mid)
        lo = np.where(ok, mid, lo)
        hi = np.where(ok, hi, mid)
    return np.where(top, z_max, hi)


def break_accelerations(path: Path, lim: AxisArrays, t_ipo: float, a_cap: float,
                        b_break: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Largest path acceleration (in size) on arriving at and on leaving every break
    that the acceleration-step rule allows.

    Crossing a break at ``v`` steps axis ``i``'s acceleration by
    ``t_out_i a_r - t_in_i a_l + dk_i v^2`` (``dk`` the jump of ``q''``), held to
    ``Jstep_i T_ipo``: ``J_i`` without a curvature jump and at rest, PATH_TRANS_JERK_LIM
    with one while moving (:func:`reference.core.rules.step_jerk_limit`), so the larger
    of the two is a relaxation. With ``v^2 <= b_break`` the centripetal part is at most
    ``|dk_i| b_break``, which is added to the allowance. At a stop the path decelerates
    into the rest (``a_l <= 0``) and accelerates out of it (``a_r >= 0``); elsewhere both
    signs are possible and the set is symmetric, so the largest ``|a|`` is the largest
    ``a``. Outside the path the motion rests (tangent and curvature 0). Each side's
    bound is taken over all values of the other side: a relaxation.

    Parameters
    ----------
    path : Path
    lim : AxisArrays
    t_ipo : float
        IPO cycle, s.
    a_cap : float
        Upper end of the search, mm/s^2.
    b_break : numpy.ndarray, shape (m + 1,)
        Valid upper bounds of ``v^2`` at the breaks, mm^2/s^2.

    Returns
    -------
    a_in, a_out : numpy.ndarray, shape (m + 1,)
        Bounds of ``|a_l|`` and ``|a_r|`` at every break, mm/s^2.
    """
    m = path.n_segments
    n = len(path.axes)
    t_in = np.zeros((m + 1, n))
    t_out = np.zeros((m + 1, n))
    k_in = np.zeros((m + 1, n))
    k_out = np.zeros((m + 1, n))
    _, d0, c0, _ = path.evaluate(path.s_breaks[:-1], segment=np.arange(m))
    _, d1, c1, _ = path.evaluate(path.s_breaks[1:], segment=np.arange(m))
    t_out[:m], k_out[:m] = d0, c0
    t_in[1:], k_in[1:] = d1, c1
    dk = np.abs(k_out - k_in)
    jstep = np.maximum(step_jerk_limit(curvature_jumps(k_in, k_out), lim.j_max,
                                       lim.path_trans_jerk), lim.j_max[None, :])
    gamma = jstep * t_ipo + dk * np.maximum(np.asarray(b_break), 0.0)[:, None]
    # step = t_out a_r + t_in x with x = -a_l (>= 0 and a_r >= 0 at a stop)
    a_in = _max_fixed(t_in, t_out, gamma, a_cap, path.stop)
    a_out = _max_fixed(t_out, t_in, gamma, a_cap, path.stop)
    return a_in, a_out


def _ramp(p: np.ndarray, vb: np.ndarray, a_s: np.ndarray, A: np.ndarray, J: np.ndarray
          ) -> tuple[np.ndarray, np.ndarray]:
    """Time and distance for the fastest ramp ``F(t) = vb + int_0^t min(A, a_s + J tau)``
    to reach the speed ``p`` (both 0 where ``p <= vb``: that end does not bind)."""
    t1 = (A - a_s) / J
    F1 = vb + a_s * t1 + J * t1 * t1 / 2
    Q1 = vb * t1 + a_s * t1 * t1 / 2 + J * t1 ** 3 / 6
    dp = np.maximum(p - vb, 0.0)
    t_q = (-a_s + np.sqrt(a_s * a_s + 2 * J * dp)) / J
    d = (p - F1) / A
    t = np.where(p <= F1, t_q, t1 + d)
    dist = np.where(p <= F1, vb * t_q + a_s * t_q * t_q / 2 + J * t_q ** 3 / 6,
                    Q1 + F1 * d + A * d * d / 2)
    return t, dist


def rise(p: np.ndarray, vb: np.ndarray, a0: np.ndarray, A: np.ndarray, J: np.ndarray
         ) -> tuple[np.ndarray, np.ndarray]:
    """Time and distance of the fastest rise to the speed ``p`` with zero acceleration
    (step 4 of the module docstring), vectorised.

    From speed ``vb`` with acceleration at most ``a0`` (``0 <= a0 <= A``), under
    ``s'' <= A`` and ``|s'''| <= J``: jerk ``+J`` up to ``min(A, apk)``, a plateau at
    ``A`` when needed, then jerk ``-J`` down to zero acceleration at ``p``. When even the
    landing from ``a0`` would overshoot ``p`` it lands at once from the acceleration
    ``sqrt(2 J (p - vb))``. Zero time and distance where ``p <= vb``.

    Parameters
    ----------
    p, vb, a0, A, J : numpy.ndarray, shape (k,)
        Target and start speed (mm/s), start and largest acceleration (mm/s^2), jerk
        (mm/s^3).

    Returns
    -------
    tau, dist : numpy.ndarray, shape (k,)
        Seconds and mm.
    """
    gain = np.maximum(p - vb, 0.0)
    a0 = np.clip(a0, 0.0, A)
    direct = vb + a0 * a0 / (2.0 * J) >= p
    # landing at once: -J from a_l = sqrt(2 J gain) <= a0
    a_l = np.sqrt(2.0 * J * gain)
    t_l = a_l / J
    d_l = vb * t_l + a_l * t_l * t_l / 2 - J * t_l ** 3 / 6
    # ramp up to apk (plateau at A when apk > A), then land
    apk = np.minimum(np.sqrt(J * gain + a0 * a0 / 2), A)
    t1 = np.maximum(apk - a0, 0.0) / J
    v1 = vb + a0 * t1 + J * t1 * t1 / 2
    d1 = vb * t1 + a0 * t1 * t1 / 2 + J * t1 ** 3 / 6
    t3 = apk / J
    gain3 = apk * apk / (2.0 * J)
    t2 = np.maximum(p - gain3 - v1, 0.0) / A
    v2 = v1 + A * t2
    d2 = v1 * t2 + A * t2 * t2 / 2
    d3 = v2 * t3 + apk * t3 * t3 / 2 - J * t3 ** 3 / 6
    tau = np.where(gain <= 0, 0.0, np.where(direct, t_l, t1 + t2 + t3))
    dist = np.where(gain <= 0, 0.0, np.where(direct, d_l, d1 + d2 + d3))
    return tau, dist


def peak_times(L: np.ndarray, vb0: np.ndarray, vb1: np.ndarray, as0: np.ndarray,
               as1: np.ndarray, V: np.ndarray, A: np.ndarray, J: np.ndarray,
               eps: float | np.ndarray = 0.0, t_cap: np.ndarray | None = None
               ) -> np.ndarray:
    """Lower bound of the time on a segment from its peak speed (step 4 of the module
    docstring), vectorised over segments.

    Every motion whose speed peaks inside the segment, at ``p`` with zero acceleration,
    takes ``T >= g(p) = tau0(p) + tau1(p) + max(0, L - d0(p) - d1(p)) / p`` (:func:`rise`
    from each end); ``g`` falls while ``d0 + d1 <= L`` and rises after, so its least value
    on ``0 < p <= V`` is at ``V`` or where ``d0 + d1 = L`` (bisection; the lower end of
    the final bracket gives a time never above the bound). Every motion whose speed
    peaks at an end has ``p <= max(vb0, vb1)`` (:func:`envelope_times` with that speed
    cap). The bound is the smaller of the two. ``eps`` (mm/s^2, the segment's budget of
    acceleration steps) enters through loosened parameters, module docstring.

    Parameters
    ----------
    L, vb0, vb1, as0, as1, V, A, J : numpy.ndarray, shape (k,)
        As :func:`envelope_times`.
    eps : float or numpy.ndarray, shape (k,)
        Acceleration steps allowed inside the segment in total, mm/s^2.
    t_cap : numpy.ndarray, shape (k,), optional
        The time below which the loosened parameters are claimed, s (default twice the
        step-free bound). The proof holds for any value; one fixed across lengths makes
        the bound nondecreasing in ``L`` (every other parameter fixed): both branches
        cover ``L`` under a fixed envelope, and their bisections' lower ends do not
        fall as ``L`` grows.

    Returns
    -------
    numpy.ndarray, shape (k,)
        Seconds.
    """
    eps = np.broadcast_to(np.asarray(eps, dtype=np.float64), L.shape)

    def bound(Lx, Vx, Ax, a0x, a1x):
        vb0x, vb1x = np.minimum(vb0, Vx), np.minimum(vb1, Vx)
        a0x, a1x = np.clip(a0x, 0.0, Ax), np.clip(a1x, 0.0, Ax)
        # peak at an end: the speed never exceeds the larger end speed
        Vb = np.minimum(Vx, np.maximum(vb0x, vb1x))
        end_peak = np.where(Vb > 0, envelope_times(Lx, vb0x, vb1x, a0x, a1x,
                                                   np.where(Vb > 0, Vb, 1.0), Ax, J),
                            np.inf)

        def both(p):
            t0, d0 = rise(p, vb0x, a0x, Ax, J)
            t1, d1 = rise(p, vb1x, a1x, Ax, J)
            return t0 + t1, d0 + d1

        tV, dV = both(Vx)
        lo, hi = np.zeros(Lx.size), Vx.copy()
        for _ in range(100):
            mid = 0.5 * (lo + hi)
            short = both(mid)[1] < Lx
            lo = np.where(short, mid, lo)
            hi = np.where(short, hi, mid)
        inside = np.where(dV <= Lx, tV + (Lx - dV) / Vx, both(lo)[0])
        return np.minimum(inside, end_peak)

    free = bound(L, V, A, as0, as1)
    # steps inside the segment (module docstring): parameters loosened for every motion
    # that takes less than t_cap, so the bound is min(t_cap, that)
    if t_cap is None:
        t_cap = 2.0 * free
    Lx = np.maximum(L - eps * t_cap ** 2 / 2, 0.0)
    with_eps = bound(Lx, V + eps * t_cap, A + eps, as0 + eps, as1 + eps)
    return np.where(eps > 0, np.minimum(t_cap, with_eps), free)


def envelope_times(L: np.ndarray, vb0: np.ndarray, vb1: np.ndarray, as0: np.ndarray,
                   as1: np.ndarray, V: np.ndarray, A: np.ndarray, J: np.ndarray
                   ) -> np.ndarray:
    """Lower bound of the time to travel ``L`` on a segment between two breaks (step 4
    of the module docstring), vectorised over segments.

    Every motion with ``v <= vb0``, ``|s''| <= as0`` at its start, ``v <= vb1``,
    ``|s''| <= as1`` at its end, ``v <= V``, ``|s''| <= A`` and ``|s'''| <= J``
    throughout has ``v(t) <= min(V, F0(t), F1(T - t))`` with ``Fe(t) = vbe +
    int_0^t min(A, ase + J tau) dtau`` (the speed can grow no faster from either end).
    ``F0`` rises and ``F1(T - t)`` falls in ``t``, so their minimum peaks where both
    equal some ``p`` and the distance ``L <= I(T) = int_0^T min(V, F0, F1(T - .))`` is
    that of the two ramps to ``p`` (plus a cruise at ``V``): with ``te(p), de(p)`` the
    time and distance of ramp ``e`` to ``p`` (zero when ``p <= vbe``), ``T >=
    t0(V) + t1(V) + (L - d0(V) - d1(V)) / V`` when both ramps reach ``V`` within ``L``,
    else ``T >= t0(p) + t1(p)`` with ``d0(p) + d1(p) = L``. Both sums grow with ``p``;
    bisection on ``p`` returns the lower end of its final bracket (distance short of
    ``L``), so the time returned is never above the bound.

    Parameters
    ----------
    L, vb0, vb1, as0, as1, V, A, J : numpy.ndarray, shape (k,)
        Length (mm); speed bounds at the start, at the end and throughout (mm/s);
        acceleration bounds at the start and at the end and throughout (mm/s^2); jerk
        bound (mm/s^3).

    Returns
    -------
    numpy.ndarray, shape (k,)
        Seconds.
    """
    vb0, vb1 = np.minimum(vb0, V), np.minimum(vb1, V)
    as0, as1 = np.clip(as0, 0.0, A), np.clip(as1, 0.0, A)

    def ramps(p):
        t0, d0 = _ramp(p, vb0, as0, A, J)
        t1, d1 = _ramp(p, vb1, as1, A, J)
        return t0 + t1, d0 + d1

    tV, dV = ramps(V)
    cruise = dV <= L
    lo = np.minimum(vb0, vb1)
    hi = V.astype(np.float64).copy()
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        short = ramps(mid)[1] < L
        lo = np.where(short, mid, lo)
        hi = np.where(short, hi, mid)
    t_peak = ramps(lo)[0]
    return np.where(cruise, tV + np.maximum(L - dV, 0.0) / V, t_peak)


def _line_limits(path: Path, lim: AxisArrays, seg: np.ndarray):
    """Path speed, acceleration and jerk limits ``V, A, J`` of line segments ``seg``
    (exact: every axis value is ``|q'_i|`` times the path value)."""
    u = np.abs(path.d[seg])
    with np.errstate(divide="ignore"):
        inv = np.where(u > 0, 1.0 / np.where(u > 0, u, 1.0), np.inf)
    V = np.minimum(path.feed[seg], np.min(lim.v_max[None, :] * inv, axis=1))
    A = np.min(lim.a_max[None, :] * inv, axis=1)
    J = np.min(lim.j_max[None, :] * inv, axis=1)
    return V, A, J


def _curve_limits(path: Path, lim: AxisArrays, seg: np.ndarray, B: np.ndarray):
    """Path acceleration and jerk bounds ``A, J`` valid everywhere on curved segments
    ``seg`` where ``v^2 <= B``.

    At every point ``sum_i q'_i^2 >= 1`` over the axes that move on the segment (``s`` is
    the arc length of a subset of them). If ``|q'_i| |x| <= X_i`` for every axis, then
    ``|x| <= ||X||_2`` (otherwise every ``|q'_i| < X_i / |x|`` and the squares sum to
    less than 1). With ``|q'_i s''| <= A_i + |q''_i| B`` and
    ``|q'_i s'''| <= J_i + 3 |q''_i| v |s''| + |d3q_i| v^3`` (the rulebook's axis
    kinematics, ``d3q = q'''``) and the segment's suprema of ``|q''_i|`` and ``|d3q_i|``
    (:func:`reference.core.geometry.plane_amplitudes`) this gives ``A`` and ``J``.
    """
    amp = plane_amplitudes(path)
    rho = np.sqrt(path.e1[seg] ** 2 + path.e2[seg] ** 2)
    k2 = rho * amp.curvature[seg][:, None]
    k3 = rho * np.hypot(amp.jerk_t[seg], amp.jerk_n[seg])[:, None]
    reach = np.abs(path.d[seg]) + rho * amp.speed[seg][:, None]
    moving = reach > 0
    Bc = B[:, None]
    A_ax = np.where(moving, lim.a_max[None, :] + k2 * Bc, 0.0)
    A = np.sqrt(np.sum(A_ax ** 2, axis=1))
    v = np.sqrt(Bc)
    J_ax = np.where(moving, lim.j_max[None, :] + 3 * k2 * v * A[:, None] + k3 * v ** 3, 0.0)
    return A, np.sqrt(np.sum(J_ax ** 2, axis=1))


@dataclass(frozen=True, slots=True, eq=False)
class SegmentEnvelope:
    """What steps 3 and 4 of the module docstring know of every segment.

    Attributes
    ----------
    vb : numpy.ndarray, shape (m + 1,)
        Upper bound of the speed at each break, mm/s.
    a_in, a_out : numpy.ndarray, shape (m + 1,)
        Largest path acceleration (in size) on arriving at and on leaving each break
        (:func:`break_accelerations`), mm/s^2.
    V, A, J : numpy.ndarray, shape (m,)
        Path speed, acceleration and jerk bounds valid on the whole segment (exact on
        lines, :func:`_curve_limits` on curves), mm/s, mm/s^2, mm/s^3.
    eps : float
        The path acceleration's steps allowed inside a segment in total, mm/s^2.
    line : numpy.ndarray of bool, shape (m,)
        Moving line segments.
    used : numpy.ndarray of int64
        Segments the bound applies to (moving, ``V > 0``).
    """

    vb: np.ndarray
    a_in: np.ndarray
    a_out: np.ndarray
    V: np.ndarray
    A: np.ndarray
    J: np.ndarray
    eps: float
    line: np.ndarray
    used: np.ndarray

    def peak_time(self, seg: np.ndarray, L: np.ndarray, vb0: np.ndarray | None = None,
                  vb1: np.ndarray | None = None, as0: np.ndarray | None = None,
                  as1: np.ndarray | None = None, t_cap: np.ndarray | None = None
                  ) -> np.ndarray:
        """Step 4 (:func:`peak_times`) on segments ``seg`` (repeats allowed) of lengths
        ``L`` (a piece of the segment with its geometry, mm), with end bounds that
        default to the segment's own; shape of ``seg``, s."""
        return peak_times(L, self.vb[seg] if vb0 is None else vb0,
                          self.vb[seg + 1] if vb1 is None else vb1,
                          self.a_out[seg] if as0 is None else as0,
                          self.a_in[seg + 1] if as1 is None else as1,
                          self.V[seg], self.A[seg], self.J[seg], self.eps, t_cap)


def segment_envelope(path: Path, lim: AxisArrays, t_ipo: float, b_break: np.ndarray,
                     b_seg: np.ndarray) -> SegmentEnvelope:
    """The per-segment bounds of steps 3 and 4 (:class:`SegmentEnvelope`).

    Parameters
    ----------
    path : Path
    lim : AxisArrays
    t_ipo : float
        IPO cycle, s.
    b_break : numpy.ndarray, shape (m + 1,)
        Upper bounds of ``v^2`` at the breaks valid for every feasible motion, mm^2/s^2.
    b_seg : numpy.ndarray, shape (m,)
        Upper bounds of ``v^2`` on every segment, valid likewise, mm^2/s^2.

    Returns
    -------
    SegmentEnvelope
    """
    m = path.n_segments
    moving = np.any(path.d != 0, axis=1) | (path.radius > 0)
    line = (path.radius == 0) & moving
    curve = path.radius > 0
    V = np.sqrt(np.maximum(b_seg, 0.0))
    A = np.full(m, np.inf)
    J = np.full(m, np.inf)
    seg_l = np.flatnonzero(line)
    if seg_l.size:
        V_l, A[seg_l], J[seg_l] = _line_limits(path, lim, seg_l)
        V[seg_l] = np.minimum(V[seg_l], V_l)
    seg_c = np.flatnonzero(curve)
    if seg_c.size:
        A[seg_c], J[seg_c] = _curve_limits(path, lim, seg_c, np.maximum(b_seg[seg_c], 0.0))
    seg = np.flatnonzero(moving & (V > 0))
    if seg.size:
        a_in, a_out = break_accelerations(path, lim, t_ipo, float(np.max(A[seg])), b_break)
    else:
        a_in = a_out = np.zeros(m + 1)
    vb = np.sqrt(np.maximum(b_break, 0.0))
    # the path acceleration's steps inside a segment: axis steps are q'_i times it and
    # some axis has |q'_i| >= 1/sqrt(n), so it steps by at most sqrt(n) max_i eps_i
    eps = math.sqrt(len(path.axes)) * float(np.max(ACCEL_CONTINUITY_TOL_REL * lim.j_max)) * t_ipo
    return SegmentEnvelope(vb, a_in, a_out, V, A, J, eps, line, seg)


def segment_times(path: Path, lim: AxisArrays, t_ipo: float, b_break: np.ndarray,
                  b_seg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Steps 3 and 4 of the module docstring: per-segment jerk bounds.

    Parameters
    ----------
    path : Path
    lim : AxisArrays
    t_ipo : float
        IPO cycle, s.
    b_break : numpy.ndarray, shape (m + 1,)
        Upper bounds of ``v^2`` at the breaks valid for every feasible motion, mm^2/s^2.
    b_seg : numpy.ndarray, shape (m,)
        Upper bounds of ``v^2`` on every segment, valid likewise, mm^2/s^2.

    Returns
    -------
    envelope : numpy.ndarray, shape (m,)
        Step 4 on every segment, s.
    runs : numpy.ndarray, shape (R,)
        Step 3 on every run that is one line segment (0 on other runs), s.
    """
    m = path.n_segments
    env = np.zeros(m)
    stops = np.flatnonzero(path.stop)
    runs = np.zeros(max(stops.size - 1, 0))
    e = segment_envelope(path, lim, t_ipo, b_break, b_seg)
    seg = e.used
    if seg.size == 0:
        return env, runs
    env[seg] = e.peak_time(seg, path.length[seg])
    for r in np.flatnonzero(np.diff(stops) == 1):
        k = int(stops[r])
        if e.line[k] and e.V[k] > 0:
            # the 1-D bound is symmetric in its ends: the larger allowance is a relaxation
            a_k = max(float(e.a_out[k]), float(e.a_in[k + 1]))
            runs[r] = rest_to_rest_time(float(path.length[k]), float(e.V[k]), float(e.A[k]),
                                        float(e.J[k]), a_k)
    return env, runs


def curvature_break_caps(path: Path, lim: AxisArrays, t_ipo: float, b_max: np.ndarray
                         ) -> np.ndarray:
    """Upper bounds of ``v^2`` at tangential breaks where the curvature jumps (step 5).

    Crossing such a break at ``v`` steps axis ``i``'s acceleration by
    ``t_out_i a_r - t_in_i a_l + (q''_out_i - q''_in_i) v^2``; the rulebook holds the step
    to ``Jstep_i T_ipo`` (PATH_TRANS_JERK_LIM, :func:`reference.core.rules.step_jerk_limit`
    with :func:`reference.core.rules.curvature_jumps`). Writing ``t_out a_r - t_in a_l =
    t_out delta + (t_out - t_in) a_l`` with ``|a_l| <= a_bnd`` (some geometry axis has
    ``|t_i| >= 1/sqrt(n)``, so ``|a| <= sqrt(n) (max A + max|q''| b_max)``), a crossing at
    ``v^2 = z`` needs some ``delta`` with ``|t_out_i delta + dk_i z| <= Jstep_i T_ipo +
    |t_out_i - t_in_i| a_bnd`` for all ``i``; the largest such ``z`` (from above) bounds
    ``v^2`` there, or the speed is at standstill level (``VEL_TOL_MM_S``, where the
    checker applies MAX_AX_JERK instead: the cap is raised to that level).

    Parameters
    ----------
    path : Path
    lim : AxisArrays
    t_ipo : float
        IPO cycle, s.
    b_max : numpy.ndarray, shape (m + 1,)
        Valid upper bounds of ``v^2`` at the breaks (the search range), mm^2/s^2.

    Returns
    -------
    numpy.ndarray, shape (m + 1,)
        mm^2/s^2, ``b_max`` where nothing is claimed.
    """
    m = path.n_segments
    out = np.asarray(b_max, dtype=np.float64).copy()
    if m < 2:
        return out
    t_in, t_out = path.junction_tangents()
    k_in, k_out = path.junction_curvatures()
    sel = np.flatnonzero(is_tangential(t_in, t_out, RELAXED) & curvature_jumps(k_in, k_out))
    if sel.size == 0:
        return out
    n = len(path.axes)
    zmax = np.maximum(out[sel + 1], 0.0)
    kap = np.max(np.abs(k_in[sel]), axis=1)
    a_bnd = math.sqrt(n) * (float(np.max(lim.a_max)) + kap * zmax)
    jstep = step_jerk_limit(np.ones(sel.size, bool), lim.j_max, lim.path_trans_jerk)
    gamma = jstep * t_ipo + np.abs(t_out[sel] - t_in[sel]) * a_bnd[:, None]
    dk = k_out[sel] - k_in[sel]
    z = np.empty(sel.size)
    for r in range(sel.size):     # one bisection per break (vectorised over its axes)
        z[r] = _max_fixed(dk[r:r + 1], t_out[sel[r]:sel[r] + 1], gamma[r],
                          float(zmax[r]), np.zeros(1, bool))[0]
    out[sel + 1] = np.minimum(out[sel + 1], np.maximum(z, VEL_TOL_MM_S ** 2))
    return out


def speed_bounds(path: Path, lim: AxisArrays, t_ipo: float, acc_grid_s: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Steps 2 and 5 of the module docstring: the ``acc`` relaxation on ``acc_grid_s``
    with the curvature-jump caps.

    Returns
    -------
    acc_seg : numpy.ndarray, shape (m,)
        The relaxation's time on each segment, s.
    b_break : numpy.ndarray, shape (m + 1,)
        Upper bounds of ``v^2`` at the breaks, mm^2/s^2.
    b_seg : numpy.ndarray, shape (m,)
        Upper bounds of ``v^2`` on each segment (its intervals' a-priori bounds and its
        node bounds), mm^2/s^2.
    """
    grid = grid_on(path, np.asarray(acc_grid_s, dtype=np.float64))
    _, t_lb, rel, b_hat = lower_bound(path, lim, grid)
    caps = curvature_break_caps(path, lim, t_ipo, b_hat[grid.break_node])
    if np.any(caps < b_hat[grid.break_node]):
        b_node = b_hat.copy()
        b_node[grid.break_node] = np.minimum(b_node[grid.break_node], caps)
        _, t_lb, rel, b_hat = lower_bound(path, lim, grid, b_node=b_node)
    acc_seg = np.bincount(grid.segment, weights=t_lb, minlength=path.n_segments)
    b_seg = np.zeros(path.n_segments)
    np.maximum.at(b_seg, grid.segment, np.maximum(rel.b_bar, np.maximum(b_hat[:-1],
                                                                         b_hat[1:])))
    return acc_seg, b_hat[grid.break_node], b_seg


#: Relative raise of the reach caps of :func:`reach_speed_caps` over the computed root
#: (its closed form and bisection carry round-off of about 1e-15 relative; the cap must
#: never fall below the true ``P(y)``).
REACH_ROUNDOFF_REL = 1e-9
#: Bisection steps of :func:`reach_speed_caps` on ``[vb, sqrt(vb^2 + 2 A y)]`` (the
#: ``acc`` reach is the upper end): 2^-60 of that interval, far below the round-off raise.
REACH_BISECTIONS = 60


def reach_distance(p: np.ndarray, vb: np.ndarray, alpha: np.ndarray, A: np.ndarray,
                   J: np.ndarray) -> np.ndarray:
    """``D(p)`` of step 7: the least distance over which the speed can rise from ``vb``
    to ``p`` with ``s'' <= min(A, sqrt(alpha + 2 J u))`` at speed ``u``, mm (0 where
    ``p <= vb``), vectorised (every argument broadcast to one shape; ``alpha`` in
    mm^2/s^4, ``A`` mm/s^2, ``J`` mm/s^3, speeds mm/s)."""
    ustar = np.maximum((A * A - alpha) / (2.0 * J), 0.0)
    p = np.maximum(p, vb)
    # written as differences over [vb, p] (not of antiderivatives, whose values near
    # p^2 / 2A would lose the short distances next to a break to cancellation):
    # below ustar int u / sqrt(alpha + 2 J u) du with w = alpha + 2 J u,
    # (w1 - w0) / (sqrt(w1) + sqrt(w0)) ((2/3) (w1 + sqrt(w1 w0) + w0) - 2 alpha) / (4 J^2);
    # above it int u / A du = (x1 - x0) (x1 + x0) / 2A
    x0, x1 = np.minimum(vb, ustar), np.minimum(p, ustar)
    w0, w1 = alpha + 2.0 * J * x0, alpha + 2.0 * J * x1
    r0, r1 = np.sqrt(w0), np.sqrt(w1)
    with np.errstate(invalid="ignore", divide="ignore"):
        low = np.where(x1 > x0, 2.0 * J * (x1 - x0) / (r1 + r0)
                       * ((2.0 / 3.0) * (w1 + r1 * r0 + w0) - 2.0 * alpha)
                       / (4.0 * J * J), 0.0)
    y0, y1 = np.maximum(vb, ustar), np.maximum(p, ustar)
    return np.maximum(low, 0.0) + (y1 - y0) * (y1 + y0) / (2.0 * A)


def _reach_side(y: np.ndarray, vb: np.ndarray, a_s: np.ndarray, A: np.ndarray,
                J: np.ndarray, eps: float, t_upper: float) -> np.ndarray:
    """``P(y)`` of step 7 from one break (shape of ``y``), mm/s."""
    A1 = A + eps
    alpha = a_s * a_s + 2.0 * J * eps * t_upper + 2.0 * eps * A + eps * eps
    lo = vb.copy()
    hi = np.sqrt(vb * vb + 2.0 * A1 * np.maximum(y, 0.0))   # D(p) >= (p^2 - vb^2) / 2A'
    for _ in range(REACH_BISECTIONS):
        mid = 0.5 * (lo + hi)
        short = reach_distance(mid, vb, alpha, A1, J) <= y
        lo = np.where(short, mid, lo)
        hi = np.where(short, hi, mid)
    return hi * (1.0 + REACH_ROUNDOFF_REL)


def reach_speed_caps(path: Path, env: SegmentEnvelope, s: np.ndarray, t_upper: float
                     ) -> np.ndarray:
    """Upper bounds of the speed at path positions ``s`` for every jerk-feasible motion
    lasting at most ``t_upper`` (step 7), mm/s, shape of ``s``; ``inf`` on segments
    without finite acceleration and jerk bounds and on those that do not move.

    Parameters
    ----------
    path : Path
    env : SegmentEnvelope
        :func:`segment_envelope` of ``path``.
    s : numpy.ndarray, shape (N,)
        Positions, mm (inside ``[0, path.total_length]``).
    t_upper : float
        s; a verified upper bound of the minimum time keeps the minimum among the motions
        bounded.
    """
    s = np.asarray(s, dtype=np.float64)
    out = np.full(s.shape, np.inf)
    if path.n_segments == 0 or not math.isfinite(t_upper):
        return out
    sb = path.s_breaks
    seg = np.clip(np.searchsorted(sb, s, side="right") - 1, 0, path.n_segments - 1)
    A, J = env.A[seg], env.J[seg]
    ok = np.isfinite(A) & np.isfinite(J) & (J > 0) & np.isin(seg, env.used)
    if not np.any(ok):
        return out
    i = np.flatnonzero(ok)
    g = seg[i]
    y0 = np.maximum(s[i] - sb[g], 0.0)
    y1 = np.maximum(sb[g + 1] - s[i], 0.0)
    p0 = _reach_side(y0, env.vb[g], env.a_out[g], A[i], J[i], env.eps, t_upper)
    p1 = _reach_side(y1, env.vb[g + 1], env.a_in[g + 1], A[i], J[i], env.eps, t_upper)
    out[i] = np.minimum(p0, p1)
    return out


#: Nodes :func:`reach_nodes` adds on each side of every break at most, spaced
#: geometrically from :data:`REACH_NODE_FIRST_REL` of the zone to the zone's end; the
#: zone is :data:`REACH_ZONE_FACTOR` times the distance over which the fastest ramp from
#: the break reaches the acceleration bound (beyond it the reach and the ``acc`` envelope
#: differ by a shift that fades; measured on lcnc_sam_tolerance_issue, 40 nodes over 3 mm
#: and 120 over 20 mm gave the turn programme's bound 2.1097 and 2.1112 s).
REACH_NODES_PER_SIDE = 40
REACH_NODE_FIRST_REL = 1e-3
REACH_ZONE_FACTOR = 4.0
#: Nodes :func:`reach_nodes` adds over the whole path at most (fewer per side on long
#: programmes; below 4 per side none): the programme's cells grow with them.
REACH_MAX_NODES = 40_000


def reach_nodes(path: Path, env: SegmentEnvelope,
                max_nodes: int = REACH_MAX_NODES) -> np.ndarray:
    """Positions near every break where the reach envelope of step 7 bends, mm, sorted
    (for a grid on which :func:`reach_speed_caps` is sampled; any nodes give a valid
    bound, these a tighter one). Empty where the budget leaves fewer than 4 per side."""
    used = env.used[np.isfinite(env.A[env.used]) & np.isfinite(env.J[env.used])]
    if used.size == 0:
        return np.zeros(0)
    per_side = min(REACH_NODES_PER_SIDE, int(max_nodes) // (2 * used.size))
    if per_side < 4:
        return np.zeros(0)
    A, J = env.A[used], env.J[used]
    sb = path.s_breaks
    half = 0.5 * (sb[used + 1] - sb[used])
    out = []
    for vb, a_s, start, sign in ((env.vb[used], env.a_out[used], sb[used], 1.0),
                                 (env.vb[used + 1], env.a_in[used + 1], sb[used + 1], -1.0)):
        t1 = np.maximum(A - np.minimum(a_s, A), 0.0) / J
        zone = REACH_ZONE_FACTOR * (vb * t1 + a_s * t1 * t1 / 2 + J * t1 ** 3 / 6)
        zone = np.minimum(zone, half)
        frac = np.geomspace(REACH_NODE_FIRST_REL, 1.0, per_side)
        d = zone[:, None] * frac[None, :]
        out.append((start[:, None] + sign * d)[zone > 0].ravel())
    pts = np.concatenate(out)
    return np.unique(pts[(pts > 0) & (pts < path.total_length)])


def jerk_lower_bound(path: Path, lim: AxisArrays, t_ipo: float, acc_grid_s: np.ndarray
                     ) -> tuple[float, np.ndarray, np.ndarray]:
    """Certified lower bound of the motion time (holds excluded), module docstring.

    Parameters
    ----------
    path : Path
        The path (at least one segment).
    lim : AxisArrays
        Limits in the path's axis order.
    t_ipo : float
        IPO cycle, s.
    acc_grid_s : numpy.ndarray, shape (N + 1,)
        Nodes of the grid on which the ``acc`` relaxation is evaluated (every segment
        break a node; the ``acc`` oracle's final grid is a good one).

    Returns
    -------
    lb_s : float
        Lower bound, s.
    acc_seg, jerk_seg : numpy.ndarray, shape (m,)
        Per segment: the ``acc`` relaxation's bound and the larger of the straight-line
        bounds (0 on arcs), s; on runs that are one line the run bound (step 3) is in
        ``jerk_seg``.
    """
    acc_seg, b_break, b_seg = speed_bounds(path, lim, t_ipo, acc_grid_s)
    env, runs = segment_times(path, lim, t_ipo, b_break, b_seg)
    jerk_seg = env.copy()
    stops = np.flatnonzero(path.stop)
    one = np.flatnonzero(runs > 0)
    jerk_seg[stops[one]] = np.maximum(jerk_seg[stops[one]], runs[one])
    lb = float(np.maximum(acc_seg, jerk_seg).sum()) * (1.0 - JERK_LB_ROUNDOFF_REL)
    return lb, acc_seg, jerk_seg
