"""Compiled kernel of the LookAhead passes (numba): the backward and the forward pass of
:func:`reference.planner.lookahead.lookahead_passes`, written as the plain loops they are.

The steps are those of :mod:`reference.planner.lookahead` (its module docstring has the
model): each node's speed is its own limit unless the step from its neighbour binds, the
step taken with the cheap sufficient test ``_fits`` first and the closed-form reachable
speed (``_reach_brisk``, ``_reach_soft``, ``_reach_drive``) where that fails. The Python
pass decides most nodes for all units at once (``_keeps_own``) and walks the chains where
that fails one step at a time; here every node is stepped in order, which is the same
sequence of decisions (a node the Python pass does not walk keeps its own limit from a
neighbour at its own limit, the test the loop makes there) with the same floating-point
operations in the same order, so the speeds are bitwise those of the Python pass
(``tests/reference/test_lookahead_kernel.py`` compares both on the seeded bench programs
and on random units of every mode).

Why compiled: the chains are sequential (each step starts from the speed the step before
reached) and long where a rounding inserts short segments, and each step in Python costs
about 1.5 us of interpreter work for a few flops; so does each candidate of the greedy
merges (measured, CPU time per plan, on the SOFT G645 rows of
``tests/bench/bench_rounding.py --quick``: line-arc, 4,812 segments, 3,374 reachable
speeds per pass, passes 8.2 -> 0.5 ms and planning units 3.4 -> 1.7 ms of a 48 ms plan;
S-bends, 10,442 segments, passes 5.1 -> 0.4 ms and units 7.1 -> 3.5 ms). Compiled once per
installation (``cache=True``); loading numba and the cached kernel costs about 0.5 s
once per process, so :func:`reference.planner.lookahead.lookahead_passes` uses it from
:data:`reference.planner.lookahead.PASSES_COMPILED_MIN_UNITS` units on, or once it is
loaded (as :mod:`optimal.backends.fast` does with its sweep).

``error_model="numpy"``: a division by zero gives ``inf``/``nan`` as in the vectorised
tests, where Python floats would raise (the limits are positive: it does not occur).
``math.sqrt``, ``**``, ``asinh`` and ``sinh`` call the same C library as CPython.

Units: mm, mm/s, mm/s^2, mm/s^3. Shapes: ``u`` units, ``u + 1`` nodes.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True, error_model="numpy")
def _fits(v_lo: float, v_hi: float, dist: float, acc: float,
          jerk: float) -> bool:  # pragma: no cover - compiled
    """``lookahead._fits``: a ramp between the speeds surely fits into ``dist``."""
    return (v_hi * v_hi - v_lo * v_lo) / (2.0 * acc) + (v_hi + v_lo) * acc / (2.0 * jerk) \
        <= dist


@njit(cache=True, nogil=True, error_model="numpy")
def _reach(mode: int, v: float, dist: float, acc: float, jerk: float, knee: float,
           ratio: float) -> float:  # pragma: no cover - compiled
    """``lookahead._REACH[mode](v, dist, acc, jerk, knee, ratio)``: the reachable speed,
    mm/s (mode 0 BRISK, 1 SOFT, 2 DRIVE with a knee). ``0.0 if x < 0.0 else x`` is
    Python's ``max(x, 0.0)`` (the first argument unless the second is greater)."""
    if mode == 0:
        return math.sqrt(v * v + 2.0 * acc * dist)
    if mode == 2:
        e_k = knee * knee / (2.0 * acc)
        over = v * v - knee * knee
        over = 0.0 if over < 0.0 else over
        x = (v * v + over * (1.0 / ratio - 1.0)) / (2.0 * acc) + dist
        if x <= e_k:
            return math.sqrt(2.0 * acc * x)
        return math.sqrt(knee * knee + 2.0 * ratio * acc * (x - e_k))
    thr = acc * acc / jerk
    # jerk-limited: x^3 + p x + q = 0, dv = x^2
    p = 2.0 * v
    q = -dist * math.sqrt(jerk)
    q2 = 0.25 * q * q
    p3 = p * p * p / 27.0
    if q2 >= p3:
        u = (-0.5 * q + math.sqrt(q2 + p3)) ** (1.0 / 3.0)
        x = u - p / (3.0 * u) if u > 0 else 0.0
    else:
        x = 2.0 * math.sqrt(p / 3.0) * math.sinh(math.asinh(math.sqrt(q2 / p3)) / 3.0)
    df = 3.0 * x * x + p
    if df > 0:
        x -= (x * x * x + p * x + q) / df
    dv = x * x
    if dv <= thr:
        return v + (0.0 if dv < 0.0 else dv)
    b = 2.0 * v + thr
    c = 2.0 * v * thr - 2.0 * acc * dist
    disc = b * b - 4.0 * c
    dv = -2.0 * c / (b + math.sqrt(0.0 if disc < 0.0 else disc))
    return v + (0.0 if dv < 0.0 else dv)


@njit(cache=True, nogil=True, error_model="numpy")
def passes(cap: np.ndarray, length: np.ndarray, mode: np.ndarray, acc_dn: np.ndarray,
           jerk_dn: np.ndarray, acc_up: np.ndarray, jerk_up: np.ndarray, knee: np.ndarray,
           ratio: np.ndarray, acc_dn_fit: np.ndarray, acc_up_fit: np.ndarray,
           cause: np.ndarray):  # pragma: no cover - compiled
    """Backward then forward pass over the units.

    Parameters
    ----------
    cap : numpy.ndarray, shape (u + 1,)
        Node caps, mm/s.
    length : numpy.ndarray, shape (u,)
        Unit lengths, mm.
    mode : numpy.ndarray of int64, shape (u,)
        0 BRISK, 1 SOFT, 2 DRIVE with a knee.
    acc_dn, jerk_dn, acc_up, jerk_up : numpy.ndarray, shape (u,)
        Limits of the falling and rising ramps (jerk ``inf`` for BRISK and DRIVE).
    knee, ratio : numpy.ndarray, shape (u,)
        DRIVE knee speed (mm/s) and the share of the acceleration above it.
    acc_dn_fit, acc_up_fit : numpy.ndarray, shape (u,)
        The accelerations of the cheap test (DRIVE: the one above the knee).
    cause : numpy.ndarray of int64, shape (u + 1,)
        Cause of each node's own limit.

    Returns
    -------
    w : numpy.ndarray, shape (u + 1,)
        Node speeds after both passes, mm/s.
    b : numpy.ndarray, shape (u + 1,)
        After the backward pass alone, mm/s.
    origin : numpy.ndarray of int64, shape (u + 1,)
        Cause of the limit the backward pass propagated to each node.
    acc_lim : numpy.ndarray of bool, shape (u + 1,)
        Nodes the forward ramp kept below their backward speed.
    """
    n = length.size
    b = cap.copy()
    origin = cause.copy()
    for k in range(n - 1, -1, -1):
        be, c, dist = b[k + 1], cap[k], length[k]
        if c <= be or _fits(be, c, dist, acc_dn_fit[k], jerk_dn[k]):
            continue
        r = _reach(mode[k], be, dist, acc_dn[k], jerk_dn[k], knee[k], ratio[k])
        if c <= r:
            continue
        b[k] = r
        origin[k] = origin[k + 1]
    w = b.copy()
    acc_lim = np.zeros(n + 1, dtype=np.bool_)
    for k in range(n):
        ws, bn, dist = w[k], b[k + 1], length[k]
        if bn <= ws or _fits(ws, bn, dist, acc_up_fit[k], jerk_up[k]):
            continue
        f = _reach(mode[k], ws, dist, acc_up[k], jerk_up[k], knee[k], ratio[k])
        if bn <= f:
            continue
        w[k + 1] = f
        acc_lim[k + 1] = True
    return w, b, origin, acc_lim


@njit(cache=True, nogil=True, error_model="numpy")
def greedy_merges(idx: np.ndarray, cap: np.ndarray, eff: np.ndarray, own: np.ndarray,
                  ratio: float) -> np.ndarray:  # pragma: no cover - compiled
    """The greedy runs of ``lookahead._merge_flags``: True where candidate ``idx[i]``
    joins the run before it.

    Parameters
    ----------
    idx : numpy.ndarray of int64, shape (c,)
        Candidate breaks, increasing.
    cap, eff : numpy.ndarray, shape (m,)
        Segment caps and effective caps, mm/s.
    own : numpy.ndarray, shape (m + 1,)
        Each break's own limit, mm/s.
    ratio : float
        ``soft_merge_cap_ratio``.

    Returns
    -------
    numpy.ndarray of bool, shape (c,)
    """
    out = np.zeros(idx.size, dtype=np.bool_)
    lo = elo = ehi = 0.0
    prev = -2
    for i in range(idx.size):
        k = idx[i]
        if k != prev + 1:
            lo, elo, ehi = cap[k - 1], eff[k - 1], eff[k - 1]
        c_k, e_k = cap[k], eff[k]
        new_lo = c_k if c_k < lo else lo
        new_elo = e_k if e_k < elo else elo
        new_ehi = e_k if e_k > ehi else ehi
        if own[k] >= new_lo and new_elo >= ratio * new_ehi:
            out[i] = True
            lo, elo, ehi = new_lo, new_elo, new_ehi
        else:
            lo, elo, ehi = c_k, e_k, e_k
        prev = k
    return out
