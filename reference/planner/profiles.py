"""Stage: velocity profiles of planning units between given entry and exit speeds.

A *planning unit* is a stretch of path of length ``L`` with one speed cap ``C`` and one
set of limits: acceleration/jerk ``(A_u, J_u)`` for speeding up and ``(A_d, J_d)`` for
slowing down. Its profile starts at ``v0`` and ends at ``v1`` with zero acceleration at
both ends (the block-wise model of spec/sinumerik-model.md 7.2) and is time-optimal
for these conditions: rise ``v0 -> vp``, cruise at ``vp``, fall ``vp -> v1`` with the
largest peak ``vp <= C`` whose rise and fall fit into ``L``.

One kernel serves both acceleration modes; the mode only picks the jerk (the dispatch
table :data:`reference.planner.stops.ACCEL_MODES`):

* **SOFT** (finite ``J``): every rise or fall is a jerk-limited S-curve. Its cases, as
  Ruckig enumerates them: *acceleration-limited* when ``dv >= A^2/J`` (phases
  ``+J``, ``a = A``, ``-J``: duration ``dv/A + A/J``), else *jerk-limited* (phases
  ``+J``, ``-J``, peak acceleration ``sqrt(dv J)``: duration ``2 sqrt(dv/J)``). The unit
  case adds *cruise* (``vp = C``) or *no cruise* (``C`` never reached).
* **BRISK** (``J = inf``): the same formulas with ``A/J = 0`` give the trapezoid: ramps
  of constant acceleration, duration ``dv/A``, distance ``(v_hi^2 - v_lo^2)/(2A)``.

* **DRIVE** (``J = inf`` and a finite *knee*): the trapezoid with acceleration ``A``
  up to the knee speed ``v_k`` and ``r A`` above it (``0 < r <= 1``, the knee-shaped
  characteristic of :mod:`reference.planner.drive`). With the time and the distance
  from rest, ``T(v) = v/A + max(v - v_k, 0) (1/r - 1)/A`` and
  ``E(v) = v^2/(2A) + max(v^2 - v_k^2, 0) (1/r - 1)/(2A)``, a ramp between two speeds
  takes ``T(v_hi) - T(v_lo)`` over ``E(v_hi) - E(v_lo)`` (``ds = v dv / a(v)``); the
  reachable speed inverts ``E``, a square root on each side of the knee. The rise uses
  phases 0 (``A``, below the knee) and 1 (``r A``), the fall phases 4 (``r A``) and 5
  (``A``). Units without a knee pass ``knee = inf`` (or nothing) and plan as before.

Closed forms: the ramp duration and distance above; the speed reachable over a distance
(:func:`ramp_reach`) is the root of a depressed cubic (jerk-limited) or a quadratic
(acceleration-limited). The peak without cruise (:func:`solve_peak`) is the root of a
monotone C1 function, found by safeguarded Newton in its exact bracket. Every unit is then
verified by one checker (:func:`verify_units`, guideline G9).

All functions are vectorised over units. Units: mm, s, mm/s, mm/s^2, mm/s^3.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.arrays import row_any, row_max, row_sums
from ..core.errors import InfeasibleError
from .parameters import CAUSE_REL_TOL, DISTANCE_REL_TOL, PEAK_SOLVE_ITERATIONS

#: Phase layout of a unit: rise (3 phases), cruise (1), fall (3).
N_PHASES = 7

#: Bits of :attr:`UnitProfiles.case`.
CASE_RISE, CASE_RISE_ACC, CASE_CRUISE, CASE_FALL, CASE_FALL_ACC = 1, 2, 4, 8, 16


def case_name(code: int) -> str:
    """Readable case label of a unit, e.g. ``"RISE_ACC+CRUISE+FALL_JERK"``.

    ``ACC`` = the ramp reaches the acceleration limit, ``JERK`` = it stays jerk-limited
    (never reaches ``A``), ``CRUISE`` = the speed cap is reached.
    """
    parts = []
    if code & CASE_RISE:
        parts.append("RISE_ACC" if code & CASE_RISE_ACC else "RISE_JERK")
    if code & CASE_CRUISE:
        parts.append("CRUISE")
    if code & CASE_FALL:
        parts.append("FALL_ACC" if code & CASE_FALL_ACC else "FALL_JERK")
    return "+".join(parts) or "HOLD"


# ----------------------------------------------------------------- ramp formulas
def _finite_j(jerk: np.ndarray) -> np.ndarray:
    return np.where(np.isfinite(jerk), jerk, 1.0)


def ramp_time(dv, acc, jerk) -> np.ndarray:
    """Duration of a velocity change ``dv >= 0`` with zero acceleration at both ends.

    Parameters
    ----------
    dv : array_like
        Speed change, mm/s (>= 0).
    acc, jerk : array_like
        Acceleration (mm/s^2, > 0) and jerk (mm/s^3, > 0; ``inf`` for BRISK).

    Returns
    -------
    numpy.ndarray
        ``dv/A + A/J`` if ``dv >= A^2/J`` else ``2 sqrt(dv/J)``, s.
    """
    dv, acc, jerk = np.broadcast_arrays(*(np.asarray(x, dtype=np.float64)
                                          for x in (dv, acc, jerk)))
    thr = acc * acc / jerk
    jf = _finite_j(jerk)
    with np.errstate(invalid="ignore"):
        jerk_lim = 2.0 * np.sqrt(np.maximum(dv, 0.0) / jf)
    return np.where(dv >= thr, dv / acc + acc / jerk, jerk_lim)


def ramp_distance(v_lo, v_hi, acc, jerk, knee=None, ratio=None) -> np.ndarray:
    """Distance of the fastest ramp between two speeds (either direction), mm.

    ``knee``, ``ratio`` (optional, BRISK only): DRIVE's knee speed (mm/s, ``inf`` for
    none) and the share of ``acc`` above it.
    """
    v_lo = np.asarray(v_lo, dtype=np.float64)
    v_hi = np.asarray(v_hi, dtype=np.float64)
    plain = 0.5 * (v_lo + v_hi) * ramp_time(np.abs(v_hi - v_lo), acc, jerk)
    if knee is None:
        return plain
    knee, ratio = _knee_args(knee, ratio)
    drive = np.abs(knee_effort(v_hi, acc, knee, ratio) - knee_effort(v_lo, acc, knee, ratio))
    return np.where(np.isfinite(knee), drive, plain)


def _knee_args(knee, ratio):
    """``(knee, ratio)`` as float arrays (``inf`` and 1 when ``knee`` is None)."""
    if knee is None:
        return np.asarray(np.inf), np.asarray(1.0)
    return np.asarray(knee, dtype=np.float64), np.asarray(ratio, dtype=np.float64)


def knee_time(v, acc, knee, ratio) -> np.ndarray:
    """``T(v)``: time to reach speed ``v`` from rest with ``A`` up to the knee and
    ``ratio * A`` above it, s (``knee = inf``: ``v/A``)."""
    v = np.asarray(v, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        above = np.maximum(v - knee, 0.0)
    return v / acc + np.where(above > 0, above * (1.0 / ratio - 1.0), 0.0) / acc


def knee_effort(v, acc, knee, ratio) -> np.ndarray:
    """``E(v)``: distance to reach speed ``v`` from rest (see :func:`knee_time`), mm."""
    v = np.asarray(v, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        above = np.maximum(v * v - np.asarray(knee) ** 2, 0.0)
    return (v * v + np.where(above > 0, above * (1.0 / ratio - 1.0), 0.0)) / (2.0 * acc)


def knee_ramp_time(v_lo, v_hi, acc, knee, ratio) -> np.ndarray:
    """Duration of a DRIVE ramp between two speeds (either order), s."""
    return np.abs(knee_time(v_hi, acc, knee, ratio) - knee_time(v_lo, acc, knee, ratio))


def knee_reach(v, dist, acc, knee, ratio) -> np.ndarray:
    """Largest speed reachable from ``v`` over ``dist`` (DRIVE ramp), mm/s."""
    x = knee_effort(v, acc, knee, ratio) + np.maximum(dist, 0.0)
    knee = np.asarray(knee, dtype=np.float64)
    with np.errstate(invalid="ignore", over="ignore"):
        e_k = np.where(np.isfinite(knee), knee * knee / (2.0 * acc), np.inf)
        below = np.sqrt(2.0 * acc * np.minimum(x, e_k))
        above = np.sqrt(np.where(np.isfinite(knee), knee * knee, 0.0)
                        + 2.0 * ratio * acc * np.maximum(x - e_k, 0.0))
    return np.where(x <= e_k, below, above)


def _ramp_distance_slope(v_lo, v_hi, acc, jerk) -> np.ndarray:
    """d(ramp_distance)/d(v_hi) for v_hi >= v_lo (C1; large but finite at dv = 0)."""
    dv = np.maximum(v_hi - v_lo, 0.0)
    thr = acc * acc / jerk
    jf = _finite_j(jerk)
    with np.errstate(divide="ignore"):
        dT = np.where(dv >= thr, 1.0 / acc, 1.0 / np.sqrt(np.maximum(dv * jf, 1e-300)))
    return 0.5 * ramp_time(dv, acc, jerk) + 0.5 * (v_lo + v_hi) * dT


def _ramp_distance_and_slope(v_lo, v_hi, acc, jerk, knee=None, ratio=None):
    """``ramp_distance(v_lo, v_hi)`` and its derivative in ``v_hi`` (v_hi >= v_lo)."""
    if knee is not None:
        d, sl = _ramp_distance_and_slope(v_lo, v_hi, acc, jerk)
        knee, ratio = _knee_args(knee, ratio)
        dk = knee_effort(v_hi, acc, knee, ratio) - knee_effort(v_lo, acc, knee, ratio)
        sk = v_hi / (acc * np.where(v_hi > knee, ratio, 1.0))
        fin = np.isfinite(knee)
        return np.where(fin, dk, d), np.where(fin, sk, sl)
    dv = np.maximum(v_hi - v_lo, 0.0)
    thr = acc * acc / jerk
    jf = _finite_j(jerk)
    accl = dv >= thr
    r = np.sqrt(dv / jf)
    T = np.where(accl, dv / acc + acc / jerk, 2.0 * r)
    with np.errstate(divide="ignore"):
        dT = np.where(accl, 1.0 / acc, 1.0 / np.maximum(r * jf, 1e-300))
    vs = v_lo + v_hi
    return 0.5 * vs * T, 0.5 * T + 0.5 * vs * dT


def _ramp_distance_and_slope_brisk(v_lo, v_hi, acc, jerk):
    """:func:`_ramp_distance_and_slope` where every ``jerk`` is ``inf`` and every ``acc``
    finite (BRISK): ``A^2/J = 0``, so every ramp takes the acceleration-limited branch,
    whose operations these are (the same numbers, without the jerk-limited branch that
    ``numpy.where`` would compute and discard)."""
    dv = np.maximum(v_hi - v_lo, 0.0)
    T = dv / acc + acc / jerk
    vs = v_lo + v_hi
    return 0.5 * vs * T, 0.5 * T + 0.5 * vs * (1.0 / acc)


def _depressed_cubic_root(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The real root of ``x^3 + p x + q = 0`` for ``p >= 0``, ``q <= 0`` (one root, >= 0).

    Stable Cardano form ``u - p/(3u)`` where ``q^2/4`` dominates, the hyperbolic form
    ``2 sqrt(p/3) sinh(asinh(y)/3)`` (no cancellation for small ``y``) elsewhere, then
    one Newton step.
    """
    q2 = 0.25 * q * q
    p3 = p * p * p / 27.0
    card = q2 >= p3
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        u = np.cbrt(-0.5 * q + np.sqrt(q2 + p3))
        x_card = np.where(u > 0, u - p / (3.0 * np.where(u > 0, u, 1.0)), 0.0)
        ps = np.where(card, 1.0, p)
        y = np.sqrt(np.where(card, 0.0, q2 / p3))
        x_hyp = 2.0 * np.sqrt(ps / 3.0) * np.sinh(np.arcsinh(y) / 3.0)
    x = np.where(card, x_card, x_hyp)
    f = x * x * x + p * x + q
    df = 3.0 * x * x + p
    x = np.where(df > 0, x - f / np.where(df > 0, df, 1.0), x)
    return np.maximum(x, 0.0)


def ramp_reach(v, dist, acc, jerk, knee=None, ratio=None) -> np.ndarray:
    """Largest speed ``v2 >= v`` with ``ramp_distance(v, v2) <= dist``.

    By symmetry it is also the largest speed from which a ramp ends at ``v`` within
    ``dist`` (the braking cone of the LookAhead's backward pass).

    Parameters
    ----------
    v : array_like
        Speed at one end, mm/s (>= 0).
    dist : array_like
        Available distance, mm (>= 0; ``inf`` gives ``inf``).
    acc, jerk : array_like
        Limits; ``jerk = inf`` for BRISK (then ``sqrt(v^2 + 2 A dist)``).
    knee, ratio : array_like, optional
        DRIVE (BRISK only): knee speed, mm/s (``inf``: none), and the share of ``acc``
        above it (:func:`knee_reach`).

    Returns
    -------
    numpy.ndarray
        mm/s.
    """
    if knee is not None:
        plain = ramp_reach(v, dist, acc, jerk)
        knee, ratio = _knee_args(knee, ratio)
        with np.errstate(invalid="ignore"):
            drive = knee_reach(v, dist, acc, knee, ratio)
        return np.where(np.isfinite(knee) & np.isfinite(dist), drive, plain)
    v, dist, acc, jerk = np.broadcast_arrays(*(np.asarray(x, dtype=np.float64)
                                               for x in (v, dist, acc, jerk)))
    fin = np.isfinite(dist)
    every = bool(fin.all())             # then the arrays themselves, not gathered copies
    if not every and not fin.any():
        return np.full(v.shape, np.inf)
    if every:
        v_, d_, a_, j_ = v, np.maximum(dist, 0.0), acc, jerk
    else:
        v_, d_, a_, j_ = v[fin], np.maximum(dist[fin], 0.0), acc[fin], jerk[fin]
    thr = a_ * a_ / j_
    # acceleration-limited: dv^2 + b dv + c = 0 (stable root; c <= 0 in this branch)
    b = 2.0 * v_ + thr
    c = 2.0 * v_ * thr - 2.0 * a_ * d_
    disc = np.maximum(b * b - 4.0 * c, 0.0)
    den = b + np.sqrt(disc)
    dv_acc = np.where(den > 0, -2.0 * c / np.where(den > 0, den, 1.0), 0.0)
    # jerk-limited: x^3 + 2 v x - d sqrt(J) = 0 with dv = x^2
    jfin = np.isfinite(j_)
    dv = dv_acc
    if jfin.any():
        x = _depressed_cubic_root(2.0 * v_, -d_ * np.sqrt(_finite_j(j_)))
        dv_jerk = x * x
        dv = np.where(jfin & (dv_jerk <= thr), dv_jerk, dv_acc)
    if every:
        return np.asarray(v_ + np.maximum(dv, 0.0))
    out = np.full(v.shape, np.inf)
    out[fin] = v_ + np.maximum(dv, 0.0)
    return out


def ramp_peak_accel(dv, acc, jerk) -> np.ndarray:
    """Largest |acceleration| of a ramp: ``min(A, sqrt(dv J))`` (``A`` for BRISK)."""
    dv = np.asarray(dv, dtype=np.float64)
    jf = _finite_j(np.asarray(jerk, dtype=np.float64))
    return np.where(np.isfinite(jerk), np.minimum(acc, np.sqrt(np.maximum(dv, 0.0) * jf)),
                    acc)


# ----------------------------------------------------------------- unit peak
def solve_peak(v0, v1, length, cap, acc_up, jerk_up, acc_dn, jerk_dn, knee=None,
               ratio=None) -> np.ndarray:
    """Peak speed of time-optimal unit profiles.

    The peak ``vp`` is the largest value in ``[max(v0, v1), cap]`` with
    ``g(vp) = ramp_distance(v0, vp) + ramp_distance(v1, vp) - L <= 0``; ``g`` is
    increasing and C1, so the root is unique. Where ``g(cap) <= 0`` the unit cruises at
    ``cap``; elsewhere a safeguarded Newton iteration runs in the bracket
    ``[max(v0, v1), min(cap, reach(v0), reach(v1))]`` and returns the lower end (whose
    distance never exceeds ``L``).

    With a DRIVE knee ``g`` is C1 on each side of the knee and continuous across it
    (its slope drops there); the safeguarded iteration handles the kink.

    Parameters
    ----------
    v0, v1, length, cap, acc_up, jerk_up, acc_dn, jerk_dn : numpy.ndarray, shape (n,)
    knee, ratio : numpy.ndarray, shape (n,), optional
        DRIVE knee speed (``inf``: none) and share of the acceleration above it.

    Returns
    -------
    numpy.ndarray, shape (n,)
        mm/s.
    """
    v0, v1, L, cap = (np.asarray(x, dtype=np.float64) for x in (v0, v1, length, cap))
    has_knee = knee is not None and bool(np.any(np.isfinite(knee)))
    if has_knee:
        knee = np.broadcast_to(np.asarray(knee, dtype=np.float64), v0.shape)
        ratio = np.broadcast_to(np.asarray(ratio, dtype=np.float64), v0.shape)
    kk = (lambda idx: (knee[idx], ratio[idx])) if has_knee else (lambda idx: (None, None))
    # all BRISK (no jerk limit, no knee): the ramps' acceleration-limited formulas alone
    brisk = (not has_knee and not np.isfinite(jerk_up).any()
             and not np.isfinite(jerk_dn).any() and bool(np.isfinite(acc_up).all())
             and bool(np.isfinite(acc_dn).all()))
    lo = np.maximum(v0, v1)
    hi = np.minimum(cap, np.minimum(ramp_reach(v0, L, acc_up, jerk_up, *kk(slice(None))),
                                    ramp_reach(v1, L, acc_dn, jerk_dn, *kk(slice(None)))))
    hi = np.maximum(hi, lo)

    def g_slope(x, idx):
        if brisk:
            d0, s0 = _ramp_distance_and_slope_brisk(v0[idx], x, acc_up[idx], jerk_up[idx])
            d1, s1 = _ramp_distance_and_slope_brisk(v1[idx], x, acc_dn[idx], jerk_dn[idx])
        else:
            d0, s0 = _ramp_distance_and_slope(v0[idx], x, acc_up[idx], jerk_up[idx],
                                              *kk(idx))
            d1, s1 = _ramp_distance_and_slope(v1[idx], x, acc_dn[idx], jerk_dn[idx],
                                              *kk(idx))
        return d0 + d1 - L[idx], s0 + s1

    vp = hi.copy()
    todo = np.flatnonzero(g_slope(hi, slice(None))[0] > 0)
    if todo.size == 0:
        return vp
    # start at the root of the acceleration-limited bound of g (a quadratic, exact for
    # BRISK and for ramps that reach A on both sides): g <= g_upper, so g(x_q) <= 0;
    # with a knee the bound takes the reduced acceleration everywhere
    au, ju, ad, jd = acc_up[todo], jerk_up[todo], acc_dn[todo], jerk_dn[todo]
    if has_knee:
        r = np.where(np.isfinite(knee[todo]), ratio[todo], 1.0)
        au, ad = au * r, ad * r
    w0, w1, Lt = v0[todo], v1[todo], L[todo]
    alpha = 0.5 / au + 0.5 / ad
    beta = 0.5 * au / ju + 0.5 * ad / jd
    gamma = (-w0 * w0 / (2 * au) + w0 * au / (2 * ju) - w1 * w1 / (2 * ad)
             + w1 * ad / (2 * jd) - Lt)
    x_q = (-beta + np.sqrt(np.maximum(beta * beta - 4 * alpha * gamma, 0.0))) / (2 * alpha)
    a = np.clip(x_q, lo[todo], hi[todo])
    b = hi[todo].copy()
    x = a.copy()
    act = np.arange(todo.size)              # still iterating (indices into todo)
    eps4 = 4.0 * np.finfo(float).eps
    for _ in range(PEAK_SOLVE_ITERATIONS):
        idx = todo[act]
        xa, aa, ba = x[act], a[act], b[act]
        gx, slope = g_slope(xa, idx)
        pos = gx > 0
        ba = np.where(pos, xa, ba)
        aa = np.where(pos, aa, xa)
        with np.errstate(divide="ignore", invalid="ignore"):
            xn = xa - gx / slope
        bad = ~np.isfinite(xn) | (xn <= aa) | (xn >= ba)
        # g(x) <= 0 within round-off of 0: x is the root (feasible side); the Newton
        # step from there may leave the bracket by round-off (then "bad"), and bisecting
        # away from the root would take some 30 steps to come back (the quadratic start
        # is such a root for every BRISK unit)
        root = (gx <= 0) & (np.abs(gx) <= eps4 * L[idx])
        xa = np.where(bad, np.where(root, xa, 0.5 * (aa + ba)), xn)
        a[act], b[act], x[act] = aa, ba, xa
        # converged: bracket at round-off width, or the step no longer moves x
        done = (ba - aa <= eps4 * np.maximum(ba, 1.0)) | (
            (~bad | root) & (np.abs(gx) <= eps4 * L[idx]))
        act = act[~done]
        if act.size == 0:
            break
    # accept the iterate when its distance does not exceed L; else step it just below
    # the root; the lower bracket end (g <= 0 by construction) is the last resort
    gx, slope = g_slope(x, todo)
    over = gx > 0
    if over.any():
        idx = todo[over]
        with np.errstate(divide="ignore", invalid="ignore"):
            xs = x[over] - gx[over] / slope[over] * (1.0 + 1e-9) - eps4 * x[over]
        xs = np.where(np.isfinite(xs) & (xs >= a[over]), xs, a[over])
        xs = np.where(g_slope(xs, idx)[0] <= 0, xs, a[over])
        x[over] = xs
    vp[todo] = x
    return vp


# ----------------------------------------------------------------- unit profiles
@dataclass(frozen=True, slots=True, eq=False)
class UnitProfiles:
    """Phases of every unit (rise, cruise, fall), each of shape ``(n, 7)``.

    Attributes
    ----------
    v_in, v_out, v_peak : numpy.ndarray, shape (n,)
        Entry, exit and peak speed, mm/s.
    duration, a0, jerk : numpy.ndarray, shape (n, 7)
        Phase durations (s), acceleration at each phase start (mm/s^2) and jerk
        (mm/s^3, 0 in phases of zero duration).
    dist_rise, dist_cruise, dist_fall : numpy.ndarray, shape (n,)
        Distance of the rise, the cruise and the fall, mm.
    case : numpy.ndarray of int, shape (n,)
        Case bits (:func:`case_name`).
    """

    v_in: np.ndarray
    v_out: np.ndarray
    v_peak: np.ndarray
    duration: np.ndarray
    a0: np.ndarray
    jerk: np.ndarray
    dist_rise: np.ndarray
    dist_cruise: np.ndarray
    dist_fall: np.ndarray
    case: np.ndarray

    @property
    def time(self) -> np.ndarray:
        """Total time of each unit, s, shape (n,)."""
        return row_sums(self.duration)

    @property
    def rise_time(self) -> np.ndarray:
        """Duration of the rise process of each unit, s."""
        return row_sums(self.duration[:, :3])

    @property
    def fall_time(self) -> np.ndarray:
        """Duration of the fall process of each unit, s."""
        return row_sums(self.duration[:, 4:])


def _ramp_phases(dv, acc, jerk):
    """(T1, T2, a_peak) of a ramp of size dv: phases T1 (jerk), T2 (const a), T1 (jerk)."""
    thr = acc * acc / jerk
    jf = _finite_j(jerk)
    acc_lim = dv >= thr
    fin = np.isfinite(jerk)
    t1 = np.where(acc_lim, acc / jerk, np.sqrt(np.maximum(dv, 0.0) / jf))
    t1 = np.where(fin, t1, 0.0)
    t2 = np.where(acc_lim, np.maximum(dv / acc - acc / jerk, 0.0), 0.0)
    ap = np.where(acc_lim, acc, np.sqrt(np.maximum(dv, 0.0) * jf))
    ap = np.where(dv > 0, ap, 0.0)
    return t1, t2, ap, acc_lim


def unit_profiles(v_in, v_out, length, cap, acc_up, jerk_up, acc_dn, jerk_dn, knee=None,
                  ratio=None) -> UnitProfiles:
    """Time-optimal profiles of all units (see the module docstring).

    Parameters
    ----------
    v_in, v_out : numpy.ndarray, shape (n,)
        Entry and exit speeds, mm/s; must be mutually reachable within ``length``.
    length, cap : numpy.ndarray, shape (n,)
        Unit length (mm) and speed cap (mm/s).
    acc_up, jerk_up, acc_dn, jerk_dn : numpy.ndarray, shape (n,)
        Limits for the rise and for the fall (jerk ``inf`` for BRISK).
    knee, ratio : numpy.ndarray, shape (n,), optional
        DRIVE units (BRISK): the knee speed, mm/s (``inf``: none), and the share of the
        acceleration above it.

    Returns
    -------
    UnitProfiles

    Raises
    ------
    InfeasibleError
        Entry and exit speeds that no profile can join within the length (an internal
        error of the LookAhead), naming the unit.
    """
    args = [np.asarray(x, dtype=np.float64) for x in
            (v_in, v_out, length, cap, acc_up, jerk_up, acc_dn, jerk_dn)]
    v0, v1, L, C, au, ju, ad, jd = args
    has_knee = knee is not None and bool(np.any(np.isfinite(knee)))
    vp = solve_peak(v0, v1, L, C, au, ju, ad, jd, *((knee, ratio) if has_knee else ()))
    du, dd = vp - v0, vp - v1
    t1u, t2u, apu, accu = _ramp_phases(du, au, ju)
    t1d, t2d, apd, accd = _ramp_phases(dd, ad, jd)
    dist_u = 0.5 * (v0 + vp) * (2 * t1u + t2u)
    dist_d = 0.5 * (v1 + vp) * (2 * t1d + t2d)
    rest = L - dist_u - dist_d
    with np.errstate(divide="ignore", invalid="ignore"):
        t4 = np.where(vp > 0, np.maximum(rest, 0.0) / np.where(vp > 0, vp, 1.0), 0.0)
    dur = np.stack([t1u, t2u, t1u, t4, t1d, t2d, t1d], axis=1)
    a0 = np.stack([np.zeros_like(vp), apu, apu, np.zeros_like(vp),
                   np.zeros_like(vp), -apd, -apd], axis=1)
    juf = np.where(np.isfinite(ju), ju, 0.0)
    jdf = np.where(np.isfinite(jd), jd, 0.0)
    jerk = np.stack([juf, np.zeros_like(vp), -juf, np.zeros_like(vp),
                     -jdf, np.zeros_like(vp), jdf], axis=1)
    jerk = np.where(dur > 0, jerk, 0.0)
    if has_knee:
        i = np.flatnonzero(np.isfinite(knee))
        dist_u[i], dist_d[i] = _knee_phases(i, np.asarray(knee, dtype=np.float64),
                                            np.asarray(ratio, dtype=np.float64), v0, v1,
                                            vp, L, au, ad, dur, a0, jerk)
        rest = L - dist_u - dist_d
    case = ((du > 0) * CASE_RISE + (accu & (du > 0)) * CASE_RISE_ACC
            + (vp >= C * (1 - CAUSE_REL_TOL)) * CASE_CRUISE + (dd > 0) * CASE_FALL
            + (accd & (dd > 0)) * CASE_FALL_ACC).astype(np.int64)
    units = UnitProfiles(v_in=v0, v_out=v1, v_peak=vp, duration=dur, a0=a0, jerk=jerk,
                         dist_rise=dist_u, dist_cruise=np.maximum(rest, 0.0),
                         dist_fall=dist_d, case=case)
    verify_units(units, L, C, au, ju, ad, jd)
    return units


def _knee_phases(i, knee, ratio, v0, v1, vp, L, au, ad, dur, a0, jerk):
    """Overwrite the phases of the DRIVE units ``i`` in place: rise with ``A`` below the
    knee (phase 0) and ``ratio * A`` above it (phase 1), cruise, fall with ``ratio * A``
    above the knee (phase 4) and ``A`` below it (phase 5); no jerk phases. Returns the
    rise and fall distances of those units (``E(vp) - E(v)``), mm."""
    k, r = knee[i], ratio[i]
    w0, w1, p, a_u, a_d = v0[i], v1[i], vp[i], au[i], ad[i]
    t_lo_u = np.maximum(np.minimum(p, k) - w0, 0.0) / a_u
    t_hi_u = np.maximum(p - np.maximum(w0, k), 0.0) / (r * a_u)
    t_hi_d = np.maximum(p - np.maximum(w1, k), 0.0) / (r * a_d)
    t_lo_d = np.maximum(np.minimum(p, k) - w1, 0.0) / a_d
    d_u = knee_effort(p, a_u, k, r) - knee_effort(w0, a_u, k, r)
    d_d = knee_effort(p, a_d, k, r) - knee_effort(w1, a_d, k, r)
    with np.errstate(divide="ignore", invalid="ignore"):
        t4 = np.where(p > 0, np.maximum(L[i] - d_u - d_d, 0.0) / np.where(p > 0, p, 1.0),
                      0.0)
    zero = np.zeros_like(p)
    dur[i] = np.stack([t_lo_u, t_hi_u, zero, t4, t_hi_d, t_lo_d, zero], axis=1)
    a0[i] = np.stack([a_u, r * a_u, zero, zero, -r * a_d, -a_d, zero], axis=1)
    jerk[i] = 0.0
    return d_u, d_d


def verify_units(units: UnitProfiles, length, cap, acc_up, jerk_up, acc_dn, jerk_dn) -> None:
    """The one feasibility check of unit profiles (guideline G9).

    Checks per unit: durations >= 0, distance = length, end speeds reached, peak <= cap,
    |a| <= A and |j| <= J of the rise and the fall.

    Raises
    ------
    InfeasibleError
        Naming the first failing unit and the rule.
    """
    L = np.asarray(length, dtype=np.float64)
    tol = DISTANCE_REL_TOL
    dist = units.dist_rise + units.dist_cruise + units.dist_fall
    checks = (
        ("negative phase duration", row_any(units.duration < 0)),
        ("distance differs from the unit length",
         np.abs(dist - L) > tol * np.maximum(L, 1.0)
         + 8 * np.finfo(float).eps * (units.v_in + units.v_peak + units.v_out) * units.time),
        ("cruise distance not covered (zero peak speed)",
         np.abs(units.dist_cruise - units.v_peak * units.duration[:, 3])
         > tol * np.maximum(L, 1.0)),
        ("peak above the speed cap", units.v_peak > cap * (1 + tol) + 1e-12),
        ("peak below an end speed",
         units.v_peak < np.maximum(units.v_in, units.v_out) * (1 - tol) - 1e-12),
        ("rise acceleration above its limit",
         np.abs(units.a0[:, 1]) > acc_up * (1 + tol)),
        ("fall acceleration above its limit",
         np.abs(units.a0[:, 5]) > acc_dn * (1 + tol)),
        ("jerk above its limit",
         (row_max(np.abs(units.jerk[:, :3])) > np.where(np.isfinite(jerk_up), jerk_up,
                                                           np.inf) * (1 + tol))
         | (row_max(np.abs(units.jerk[:, 4:])) > np.where(np.isfinite(jerk_dn), jerk_dn,
                                                             np.inf) * (1 + tol))),
    )
    for rule, bad in checks:
        if np.any(bad):
            k = int(np.flatnonzero(bad)[0])
            raise InfeasibleError(
                f"planning unit {k}: {rule} (v_in {units.v_in[k]:.9g}, v_out "
                f"{units.v_out[k]:.9g}, peak {units.v_peak[k]:.9g} mm/s, length "
                f"{L[k]:.9g} mm, distance {dist[k]:.9g} mm, case "
                f"{case_name(int(units.case[k]))})")


def unit_distance_to_peak(units: UnitProfiles) -> tuple[np.ndarray, np.ndarray]:
    """Local positions (from the unit start) where the cruise at the peak starts and ends."""
    return units.dist_rise, units.dist_rise + units.dist_cruise
