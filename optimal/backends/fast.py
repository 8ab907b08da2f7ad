"""Default backend: the exact backward/forward sweep for lattice-form problems (numpy).

For a problem in lattice form (:mod:`optimal.problem`) every row of interval ``k`` is
either a *forward* piece ``b_{k+1} <= p b_k + r`` (``c2 > 0 >= c1``, ``p = -c1/c2 >= 0``)
or a *backward* piece ``b_k <= d b_{k+1} + g`` (``c1 > 0 >= c2``). The greatest feasible
``b`` (which is the time-optimal one) is found by two sweeps (TOPP-RA's controllable
sets, Pham & Pham 2018; Consolini et al. 2017 for the lattice argument):

1. Static consistency of each interval: ``X_k = max b_k`` over the interval's own rows,
   ``X_k = min over pairs (i, l) with d_l p_i < 1 of (g_l + d_l r_i) / (1 - d_l p_i)``.
2. Backward: ``u_N = cap_N``, ``u_k = min(cap_k, X_k, min_l (d_l u_{k+1} + g_l))``
   (the largest ``b_k`` from which the end is reachable).
3. Forward: ``b_0 = u_0``, ``b_{k+1} = min(u_{k+1}, min_i (p_i b_k + r_i))``.

If ``x`` is feasible then ``x_k <= u_k`` (induction backwards) and ``x_{k+1} <= b_{k+1}``
(induction forwards, the pieces increase), and ``b`` itself is feasible, so ``b`` is the
greatest element: exact for the discrete problem, not an approximation.

Both sweeps are recurrences ``x_{k+1} = min(C_{k+1}, min_i (P_ki x_k + R_ki))`` with
increasing concave right-hand sides. They are evaluated without a Python loop per node by
*policy iteration*: fix one piece per step, which makes the step a clipped affine map
``x -> min(c, p x + r)``; such maps are closed under composition, so the whole chain is a
prefix scan (blocked doubling, :data:`SCAN_CHUNK` nodes per block). Then re-select the
minimising piece at the computed values and repeat until nothing changes. Each policy's
values are upper bounds of the true ones and decrease monotonically, so this converges
(typically in 2-4 rounds); after :data:`RECURRENCE_MAX_ROUNDS` or on overflow the plain
sequential sweep (pure Python floats) is used instead.

On large problems (:data:`~optimal.tolerances.COMPILED_MIN_ROWS` rows and more) the
sweep runs as the compiled loops of :mod:`optimal.backends.kernel` (the same arithmetic,
about 25x faster on arc-dense paths); the numpy form serves the small ones, where loading
the compiler would cost more than it saves, and stays an independent implementation the
tests compare the kernel with.

Options: ``method`` (``"auto"``, ``"compiled"``, ``"vectorised"``, ``"sequential"``),
``max_rounds`` (int).
"""

from __future__ import annotations

import time
from typing import Mapping

import numpy as np

from ..problem import DiscreteProblem, DiscreteResult, interval_times
from ..status import SolveStatus
from ..tolerances import (COMPILED_MIN_ROWS, RECURRENCE_MAX_ROUNDS, RECURRENCE_RTOL,
                          SCAN_CHUNK)
from ._common import check_options

NAME = "fast"
INSTALL = "nothing (numpy and numba, both required)"
OPTIONS: dict[str, type] = {"method": str, "max_rounds": int}


def is_available() -> bool:
    """Always True: numpy and numba are required dependencies."""
    return True


# ------------------------------------------------------------------ pieces
def pieces(problem: DiscreteProblem):
    """Forward and backward pieces, the static consistency caps and the node caps.

    Returns
    -------
    cap : numpy.ndarray, shape (N + 1,)
        ``min(cap_k, X_k)``.
    fp, fr : numpy.ndarray, shape (N, F)
        Forward pieces ``b_{k+1} <= fp b_k + fr`` (absent: ``fp = 0, fr = inf``).
    bp, br : numpy.ndarray, shape (N, G)
        Backward pieces ``b_k <= bp b_{k+1} + br`` (absent: ``bp = 0, br = inf``).
    """
    c1, c2, h = problem.c1, problem.c2, problem.h
    cap = problem.cap.copy()
    fwd = (c2 > 0) & (c1 <= 0)
    bwd = (c1 > 0) & (c2 <= 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        fp = np.where(fwd, -c1 / np.where(fwd, c2, 1.0), 0.0)
        fr = np.where(fwd, h / np.where(fwd, c2, 1.0), np.inf)
        bp = np.where(bwd, -c2 / np.where(bwd, c1, 1.0), 0.0)
        br = np.where(bwd, h / np.where(bwd, c1, 1.0), np.inf)
    # exact pruning: a piece whose intercept already exceeds the cap it bounds never binds
    fuse = fwd & (fr < cap[1:, None])
    buse = bwd & (br < cap[:-1, None])
    fp, fr = np.where(fuse, fp, 0.0), np.where(fuse, fr, np.inf)
    bp, br = np.where(buse, bp, 0.0), np.where(buse, br, np.inf)
    # merge forward pieces of slope exactly 1 (all rows on lines) into one column
    fp, fr, fuse = _merge_unit(fp, fr, fuse)
    bp, br, buse = _merge_unit(bp, br, buse)
    # compact: real pieces first in every row, then drop all-absent columns
    fp, fr, fuse = _compact(fp, fr, fuse)
    bp, br, buse = _compact(bp, br, buse)
    # static consistency X_k, only where some slope differs from 1 (curved geometry)
    curved = np.flatnonzero(np.any(fuse & (fp != 1.0), axis=1) | np.any(buse & (bp != 1.0),
                                                                        axis=1))
    if curved.size and fp.shape[1] and bp.shape[1]:
        X = np.full(curved.size, np.inf)
        for i in range(fp.shape[1]):
            pi, ri, ui = fp[curved, i], fr[curved, i], fuse[curved, i]
            for m in range(bp.shape[1]):
                dl, gl, ul = bp[curved, m], br[curved, m], buse[curved, m]
                den = 1.0 - dl * pi
                ok = ui & ul & (den > 0)
                if np.any(ok):
                    val = np.full(curved.size, np.inf)
                    val[ok] = (gl[ok] + dl[ok] * ri[ok]) / den[ok]
                    np.minimum(X, val, out=X)
        cap[curved] = np.minimum(cap[curved], X)
    return cap, fp, fr, bp, br


def _compact(p, r, use):
    """Move each row's real pieces to the front and drop columns that are then empty."""
    if p.shape[1] == 0:
        return p, r, use
    width = int(use.sum(axis=1).max()) if use.size else 0
    order = np.argsort(~use, axis=1, kind="stable")[:, :width]
    ar = np.arange(p.shape[0])[:, None]
    return p[ar, order], r[ar, order], use[ar, order]


def _merge_unit(p, r, use):
    """Replace all unit-slope pieces of a row by one column holding the smallest intercept."""
    unit = use & (p == 1.0)
    if not np.any(unit):
        return p, r, use
    r_unit = np.where(unit, r, np.inf).min(axis=1)
    rest = use & ~unit
    keep = np.flatnonzero(rest.any(axis=0))
    p2 = np.concatenate((np.where(np.isfinite(r_unit), 1.0, 0.0)[:, None], p[:, keep]), axis=1)
    r2 = np.concatenate((r_unit[:, None], np.where(rest, r, np.inf)[:, keep]), axis=1)
    u2 = np.concatenate((np.isfinite(r_unit)[:, None], rest[:, keep]), axis=1)
    p2 = np.where(u2, p2, 0.0)
    return p2, r2, u2


# ------------------------------------------------------------------ recurrences
def _scan_clipped_affine(C: np.ndarray, p: np.ndarray, r: np.ndarray) -> np.ndarray | None:
    """``x_0 = C_0``, ``x_{k+1} = min(C_{k+1}, p_k x_k + r_k)`` by a blocked prefix scan.

    Returns ``None`` when a product of slopes overflows (caller falls back).
    """
    N = p.size
    x = np.empty(N + 1)
    x[0] = C[0]
    if N == 0:
        return x
    B = min(SCAN_CHUNK, N)
    nb = -(-N // B)
    pad = nb * B - N
    P = np.concatenate((p, np.ones(pad))).reshape(nb, B)
    Rr = np.concatenate((r, np.zeros(pad))).reshape(nb, B)
    Cc = np.concatenate((C[1:], np.full(pad, np.inf))).reshape(nb, B)
    d = 1
    while d < B:
        p1, r1, c1 = P[:, :-d], Rr[:, :-d], Cc[:, :-d]
        p2, r2, c2 = P[:, d:], Rr[:, d:], Cc[:, d:]
        nC = np.minimum(c2, p2 * c1 + r2)
        nR = p2 * r1 + r2
        nP = p2 * p1
        P[:, d:], Rr[:, d:], Cc[:, d:] = nP, nR, nC
        d *= 2
    if not (np.all(np.isfinite(P)) and np.all(np.isfinite(Rr))):
        return None
    last_p, last_r, last_c = P[:, -1].tolist(), Rr[:, -1].tolist(), Cc[:, -1].tolist()
    entry = np.empty(nb)
    xv = float(C[0])
    for c in range(nb):
        entry[c] = xv
        t = last_p[c] * xv + last_r[c]
        xv = t if t < last_c[c] else last_c[c]
    with np.errstate(invalid="ignore", over="ignore"):
        X = np.minimum(Cc, P * entry[:, None] + Rr).ravel()[:N]
    if not np.all(np.isfinite(X)):
        return None
    x[1:] = X
    return x


def _recurrence_sequential(C: np.ndarray, P: np.ndarray, R: np.ndarray) -> np.ndarray:
    """Plain sweep ``x_{k+1} = min(C_{k+1}, min_i P_ki x_k + R_ki)`` on Python floats."""
    N = P.shape[0]
    Cl = C.tolist()
    out = [0.0] * (N + 1)
    x = Cl[0]
    out[0] = x
    if P.shape[1] == 1:
        for k, (pk, rk) in enumerate(zip(P[:, 0].tolist(), R[:, 0].tolist())):
            t = pk * x + rk
            c = Cl[k + 1]
            x = t if t < c else c
            out[k + 1] = x
    else:
        Pl, Rl = P.tolist(), R.tolist()
        for k in range(N):
            v = Cl[k + 1]
            for pi, ri in zip(Pl[k], Rl[k]):
                t = pi * x + ri
                if t < v:
                    v = t
            x = v
            out[k + 1] = x
    return np.asarray(out)


def recurrence(C: np.ndarray, P: np.ndarray, R: np.ndarray, *, method: str = "auto",
               max_rounds: int = RECURRENCE_MAX_ROUNDS) -> tuple[np.ndarray, int, str]:
    """Solve ``x_0 = C_0``, ``x_{k+1} = min(C_{k+1}, min_i (P_ki x_k + R_ki))``.

    Parameters
    ----------
    C : numpy.ndarray, shape (N + 1,)
        Finite caps.
    P, R : numpy.ndarray, shape (N, F)
        Slopes (>= 0) and intercepts (``inf`` for absent pieces, then ``P = 0``).
    method : {"auto", "vectorised", "sequential"}
        ``auto``: policy iteration with the sequential sweep as fallback.
    max_rounds : int
        Policy-iteration rounds before the fallback.

    Returns
    -------
    x : numpy.ndarray, shape (N + 1,)
    rounds : int
        Policy-iteration rounds used (0 for the sequential sweep).
    how : str
        ``"vectorised"`` or ``"sequential"``.
    """
    N = P.shape[0]
    if P.shape[1] == 0:
        P = np.zeros((N, 1))
        R = np.full((N, 1), np.inf)
    if method == "sequential":
        return _recurrence_sequential(C, P, R), 0, "sequential"
    # The cap is part of every clipped affine map, so the policy only chooses among the
    # real pieces; a step without any piece becomes x_{k+1} = C_{k+1} (p = 0, r = C).
    has = np.isfinite(R).any(axis=1)
    scale = float(np.max(C)) if C.size else 0.0
    tol = RECURRENCE_RTOL * max(scale, 1e-300)
    ar = np.arange(N)
    with np.errstate(invalid="ignore"):
        pol = np.argmin(P * C[:-1, None] + R, axis=1)
    for rounds in range(1, max_rounds + 1):
        p_sel = np.where(has, P[ar, pol], 0.0)
        r_sel = np.where(has, R[ar, pol], C[1:])
        x = _scan_clipped_affine(C, p_sel, r_sel)
        if x is None:
            break
        vals = P * x[:-1, None] + R
        new_pol = np.argmin(vals, axis=1)
        best = np.minimum(C[1:], vals[ar, new_pol])
        excess = x[1:] - best
        change = excess > tol
        if not np.any(change):
            return np.minimum(x, C), rounds, "vectorised"
        pol = np.where(change, new_pol, pol)
    if method == "vectorised":
        raise RuntimeError("policy iteration did not converge")
    return _recurrence_sequential(C, P, R), 0, "sequential"


def sweep(problem: DiscreteProblem, *, method: str = "auto",
          max_rounds: int = RECURRENCE_MAX_ROUNDS) -> tuple[np.ndarray, int, str]:
    """Greatest feasible ``b`` of a lattice-form problem (backward then forward sweep).

    Returns
    -------
    b : numpy.ndarray, shape (N + 1,)
    rounds : int
        Total policy-iteration rounds of both sweeps.
    how : str
        Method actually used (``"compiled"``, ``"vectorised"``, ``"sequential"`` or
        mixed).
    """
    # "auto" chooses by the problem's size alone, never by what ran before in the
    # process: the kernel agrees with the numpy sweep to round-off, not bit for bit, and
    # the oracle's NLP stages amplify round-off into another local optimum (sam
    # jerk+freq: upper bound 2.4375 s, or 2.4135 s in a process where a large solve had
    # loaded the kernel, when "auto" took the kernel for every size once loaded)
    if method == "compiled" or (method == "auto" and problem.c1.size >= COMPILED_MIN_ROWS):
        # imported here: loading numba and the cached kernel costs about 0.5 s once per
        # process, which small problems never recover
        from .kernel import greatest_element
        b = greatest_element(np.ascontiguousarray(problem.cap),
                             np.ascontiguousarray(problem.c1),
                             np.ascontiguousarray(problem.c2),
                             np.ascontiguousarray(problem.h))
        return b, 0, "compiled"
    cap, fp, fr, bp, br = pieces(problem)
    # backward sweep on reversed arrays: u_N = cap_N, u_k = min(cap_k, bp_k u_{k+1} + br_k)
    u_rev, r1, how1 = recurrence(cap[::-1].copy(), bp[::-1], br[::-1], method=method,
                                 max_rounds=max_rounds)
    u = u_rev[::-1].copy()
    b, r2, how2 = recurrence(u, fp, fr, method=method, max_rounds=max_rounds)
    b = np.maximum(np.minimum(b, u), 0.0)
    how = how1 if how1 == how2 else f"{how1}+{how2}"
    return b, r1 + r2, how


def solve_discrete(problem: DiscreteProblem,
                   options: Mapping[str, object] | None = None) -> DiscreteResult:
    """Solve a lattice-form problem exactly.

    Parameters
    ----------
    problem : DiscreteProblem
        The problem.
    options : Mapping, optional
        ``method`` (``"auto"`` default: the compiled kernel of
        :mod:`optimal.backends.kernel` from :data:`COMPILED_MIN_ROWS` rows on, the numpy
        policy iteration below; ``"compiled"``; ``"vectorised"``; ``"sequential"`` the
        pure-Python sweep), ``max_rounds`` (policy-iteration rounds before the sequential
        fallback).

    Returns
    -------
    DiscreteResult
        ``optimal``; ``infeasible`` when two neighbouring nodes must both be at rest
        (the time would be infinite), with the interval in the message.
    """
    opts = check_options(NAME, options, OPTIONS)
    method = str(opts.get("method", "auto"))
    if method not in ("auto", "compiled", "vectorised", "sequential"):
        raise ValueError(f"backend 'fast' option method={method!r}: must be 'auto', "
                         "'compiled', 'vectorised' or 'sequential'")
    t0 = time.perf_counter()
    b, rounds, how = sweep(problem, method=method,
                           max_rounds=int(opts.get("max_rounds", RECURRENCE_MAX_ROUNDS)))
    t1 = time.perf_counter()
    dt = interval_times(problem.s, b, problem.gamma)
    if not np.all(np.isfinite(dt)):
        k = int(np.flatnonzero(~np.isfinite(dt))[0])
        return DiscreteResult(SolveStatus.INFEASIBLE, b, float("inf"), NAME, 0.0, t1 - t0,
                              rounds, f"interval {k} [{problem.s[k]:.6g}, "
                              f"{problem.s[k + 1]:.6g}] mm must be crossed at zero speed")
    return DiscreteResult(SolveStatus.OPTIMAL, b, float(dt.sum()), NAME, 0.0, t1 - t0, rounds,
                          how)
