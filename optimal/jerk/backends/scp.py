"""The jerk grid NLP by sequential convex programming with feasible iterates.

A cross-check of :mod:`optimal.jerk.backends.ipopt` on the same transcription
(:class:`~optimal.jerk.transcription.JerkProblem`), after Debrouwere et al. 2013
("Time-optimal path following for robots with convex-concave constraints using sequential
convex programming", IEEE TRO 29(6)): every iterate is a feasible point of the grid NLP,
so the objective of every iterate is the duration of a motion that satisfies every row,
and the sequence of objectives decreases.

Variables
---------
``x = [c (N + 1), a (N + 1), dt (N), e (n_extra)]``, dimensionless as in the problem
(``e``: the accelerations on arriving at interior breaks; ``[a, e]`` is the acceleration
vector the rows index). Minimise ``T(x) = sum(dt)``.

One iteration
-------------
1. *Trust box*: ``|d_i| <= delta_i`` with ``delta = rho * (|x| + floor)`` (speeds and
   accelerations relative to themselves with a floor of :data:`C_FLOOR` of the largest
   speed and :data:`A_FLOOR` of the rms acceleration; durations relative to
   themselves), stop speeds fixed at 0, speeds may drop by at most :data:`C_DROP` of
   themselves (a speed reaching 0 off a stop would make the motion stand still).
2. *Convex model*: the integration equalities are linearised. Every inequality row
   ``F(x) <= 0`` (speed peak ``c + a dt / 2``, axis acceleration ``q' a + q'' c^2``,
   acceleration steps, axis jerk times ``dt``: ``q' (e - a) + (3 q'' c a + q''' c^3) dt``,
   each one-sided) is replaced by a convex majorant on the box,
   ``F(x + d) <= F(x) + grad F . d + sum_i w_i d_i^2``, ``w >= 0``: the bilinear and
   trilinear terms are bounded with ``|u v| <= (u^2 / s + s v^2) / 2`` (``s`` the ratio
   of the box half-widths, tight at the box corner), the cubic by its remainder on the
   box. This is the convex-concave decomposition of Debrouwere et al. with the concave
   part linearised (a linearised concave part is an upper bound of it) and the
   indefinite parts split into convex pieces.

   * ``subproblem="clarabel"`` (default, chosen by measurement, see below): the SOCP
     ``min T + (theta / n_x) |z|^2`` with the majorant rows exactly (one epigraph
     variable ``y_i >= z_i^2`` per variable with curvature, a 3-cone each), solved by
     Clarabel (interior point). Its steps satisfy the rows up to the linearisation of
     the equalities.
   * ``subproblem="osqp"``: the QP with the rows linearised (``F + grad F . d <= 0``) and
     the row curvature moved into the objective, weighted by the row multipliers of the
     previous subproblem (``P = theta / n_x + sum_r y_r 2 w_r``, diagonal, positive
     semidefinite: a convexified SQP step), solved by OSQP (ADMM, warm started, one
     factorisation pattern for all iterations). Rows that cannot reach their limit on
     the box (by the majorant) are dropped. An ADMM answer is only approximately
     optimal (:data:`OSQP_EPS`); that only affects progress, never feasibility (3.).

   Both scale the variables by the box half-widths (``z = d / delta``) and the rows by
   their natural size, so the solvers see numbers near 1.
3. *Restoration and acceptance* (which is what keeps iterates feasible): for
   ``tau`` in :data:`STEP_FRACTIONS`, project ``x + tau d`` onto the equalities (Newton,
   minimum weighted norm, residual below :data:`PROJECTION_TOL`), then stretch time by
   the smallest factor ``lam`` after which every inequality row and bound holds
   (``lam < 1``: the point had room everywhere and is sped up). Accept the first
   candidate whose total time ``lam * T(projected)`` is below ``T(x)``. Trust-region
   update: the ratio of actual to predicted decrease (``rho`` doubled up to
   :data:`RHO_MAX` above 0.75, halved below 0.25 or after a partial step, quartered on a
   rejection).
4. *Stop*: predicted decrease ``<= SCP_TOL * T`` (converged), or ``rho`` below
   :data:`RHO_MIN` with no accepted step (stalled: no step of the convex model improves
   the time; the iterate is feasible, reported as success with that message), or
   :data:`SCP_MAX_ITER`.

The start is the caller's warm start projected onto the equalities and stretched the
same way (the time-scaled acc profile of :func:`optimal.jerk.upper.warm_start`).

Proof that every iterate is feasible
------------------------------------
*Lemma (time scaling).* If ``x = (c, a, e, dt)`` satisfies the two integration
equalities of every interval, so does ``x_lam = (c / lam, a / lam^2, e / lam^2,
lam dt)`` for every ``lam > 0``, and every inequality row value is multiplied by
``lam^-d`` with ``d`` its degree: speed caps and the speed peak ``c + a dt / 2``:
``d = 1``; axis acceleration ``q' a + q'' c^2`` and acceleration steps: ``d = 2``; axis
jerk ``q' (e - a) / dt + 3 q'' c a + q''' c^3``: ``d = 3``.

*Proof.* ``c_{k+1} - c_k - (a_k + e_k) dt_k / 2`` becomes ``1 / lam`` times itself;
``ds_k - c_k dt_k - (2 a_k + e_k) dt_k^2 / 6`` is unchanged (``c dt`` and ``a dt^2``
are invariant). Each term of each row has the stated degree (``dt`` counts ``-1``,
``c`` ``1``, ``a`` and ``e`` ``2``). The path is the same (the ``q`` are functions of
``s``), so the same motion is run ``lam`` times slower. ∎

*Feasibility.* Let ``x`` satisfy the equalities and let ``rho_r(x) = |F_r(x)| / limit_r``
for each row ``r`` of degree ``d_r``, ``rho_v = max c_k / c_max_k`` over the
non-stop nodes. With ``lam = max(max_r rho_r^(1 / d_r), rho_v, MIN_dt / min(dt))``, the
stretched point ``x_lam`` satisfies every row (``rho_r(x_lam) = rho_r(x) / lam^d_r <=
1``), every speed cap, and ``dt >= MIN_dt``; speeds stay ``>= 0`` and the stop speeds
stay 0 (the projection weights them 0, candidates with a negative speed are rejected).
Every iterate (the start included) is of this form, so every iterate is feasible: the
inequalities to round-off (the ratio is computed in float64, relative error ~1e-15),
the equalities to the projection residual :data:`PROJECTION_TOL` (scaled speed and
relative position units; IPOPT's answers hold them to 1e-9). The convex model and the
trust region decide only how fast ``T`` decreases; a poor subproblem answer costs a
rejected step, never feasibility. ∎

Measured (``tests/bench/bench_jerk.py``, stadium of 2 laps, default machine, one run on a
shared 2-core machine): with Clarabel subproblems SCP reaches IPOPT's objective within
3e-9 relative in 22-25 iterations, at 3.3 times IPOPT's wall time on 1,000 intervals and
6.6 times on 5,000 (each interior-point subproblem costs about an IPOPT solve's
factorisations); with OSQP subproblems it needs thousands of ADMM iterations per
subproblem on these LP-like QPs, 31 times IPOPT's time on 1,000 intervals, and stalls
7.5e-6 above IPOPT's objective there. IPOPT stays the default backend; Clarabel is the
default subproblem solver here, OSQP the alternative.

Units: dimensionless (the problem's :class:`~optimal.jerk.transcription.Units`).
Shapes: ``N`` intervals, ``n_x = 3 N + 2 + n_extra`` variables.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from ..tolerances import MIN_INTERVAL_TIME_REL
from ..transcription import JerkProblem
from .ipopt import NlpResult

NAME = "scp"

#: Subproblem solvers (:func:`solve_nlp`'s ``subproblem``).
SUBPROBLEMS = ("clarabel", "osqp")

#: Stop when the subproblem's predicted decrease of the total time is at most this
#: fraction of it (the same relative level as IPOPT's tolerance, ``IPOPT_TOL``).
SCP_TOL = 1e-9

#: Most SCP iterations (the warm-started solves here take 10-45).
SCP_MAX_ITER = 300

#: Proximal weight: ``theta / n_x |z|^2`` in the scaled step ``z = d / delta``; keeps the
#: subproblem strictly convex (unique step) while the linear term ``sum dt`` (normalised
#: to 1) dominates.
THETA = 0.1

#: Trust-region size: initial, largest and smallest relative half-width ``rho``.
RHO0, RHO_MAX, RHO_MIN = 0.25, 0.5, 1e-8

#: Floors of the box half-widths: a fraction of the largest speed for speeds and of the
#: rms acceleration for accelerations (a speed or acceleration near 0 may still move).
C_FLOOR, A_FLOOR = 0.01, 0.1

#: A speed off the stops may drop by at most this fraction of itself in one step.
C_DROP = 0.5

#: Fractions of the subproblem step tried, in turn, before a rejection.
STEP_FRACTIONS = (1.0, 0.5, 0.25)

#: Residual of the Newton projection onto the equalities (scaled speed for the speed
#: equality, relative to the interval length for the position equality), and its most
#: iterations (it converges quadratically; 2-4 are used).
PROJECTION_TOL = 1e-13
PROJECTION_MAX_ITER = 10

#: Clarabel's gap and feasibility tolerances of the SOCP subproblem (the model is exact
#: on the box; loose answers would end the iteration early by a wrong predicted
#: decrease).
CLARABEL_TOL = 1e-8
CLARABEL_MAX_ITER = 200

#: OSQP's absolute and relative tolerance of the QP subproblem. Feasibility does not
#: depend on it; 1e-4 needed fewest ADMM iterations in total (1e-6: 3-4 times more
#: for the same SCP iterations; 1e-3: the predicted decrease too noisy and the iteration
#: stalled on one setting), measured on a line-arc-line path.
OSQP_EPS = 1e-4
OSQP_MAX_ITER = 20_000

#: OSQP's ``status_val`` of "solved" and "solved inaccurate" (the same in 0.6 and 1.x);
#: an inaccurate step is still only a proposal, judged by the acceptance test.
_OSQP_SOLVED = (1, 2)

IterateFn = Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray], None]


@dataclass(frozen=True, slots=True, eq=False)
class _Layout:
    """Columns of ``x = [c (N + 1), a (N + 1), dt (N), e (ne)]``."""

    N: int
    ne: int

    @property
    def nx(self) -> int:
        return 3 * self.N + 2 + self.ne

    def a(self, j):
        """Column of ``[a, e][j]``."""
        j = np.asarray(j)
        return np.where(j <= self.N, self.N + 1 + j, 2 * self.N + 1 + j)

    def t(self, k):
        """Column of ``dt[k]``."""
        return 2 * self.N + 2 + np.asarray(k)

    @property
    def dt_slice(self) -> slice:
        return slice(2 * self.N + 2, 3 * self.N + 2)

    def split(self, x):
        """``(c, a, dt, [a, e])``."""
        N = self.N
        return (x[:N + 1], x[N + 1:2 * N + 2], x[2 * N + 2:3 * N + 2],
                np.concatenate((x[N + 1:2 * N + 2], x[3 * N + 2:])))

    def from_parts(self, c, a, dt, a_all):
        return np.concatenate((c, a, dt, a_all[self.N + 1:]))


def _objective(lay: _Layout, x: np.ndarray) -> float:
    return float(np.sum(x[lay.dt_slice]))


def equalities(problem: JerkProblem, lay: _Layout, x: np.ndarray):
    """Residuals of the exact integration and their Jacobian.

    Returns
    -------
    h : numpy.ndarray, shape (2 N,)
        ``c_{k+1} - c_k - (a_k + e_k) dt_k / 2``, then
        ``c_k dt_k + (2 a_k + e_k) dt_k^2 / 6 - ds_k``.
    rows, cols, vals : numpy.ndarray
        The Jacobian ``dh / dx`` in COO form.
    """
    N = lay.N
    c, a, dt, a_all = lay.split(x)
    e = a_all[problem.end_index]
    k = np.arange(N)
    h1 = c[1:] - c[:-1] - (a[:-1] + e) * dt / 2
    h2 = c[:-1] * dt + (2 * a[:-1] + e) * dt * dt / 6 - problem.ds
    ea = lay.a(problem.end_index)
    r1 = np.repeat(k, 5)
    c1 = np.column_stack((k + 1, k, lay.a(k), ea, lay.t(k))).ravel()
    v1 = np.column_stack((np.ones(N), -np.ones(N), -dt / 2, -dt / 2,
                          -(a[:-1] + e) / 2)).ravel()
    r2 = np.repeat(N + k, 4)
    c2 = np.column_stack((k, lay.a(k), ea, lay.t(k))).ravel()
    v2 = np.column_stack((dt, dt * dt / 3, dt * dt / 6,
                          c[:-1] + (2 * a[:-1] + e) * dt / 3)).ravel()
    return (np.concatenate((h1, h2)), np.concatenate((r1, r2)), np.concatenate((c1, c2)),
            np.concatenate((v1, v2)))


def equality_residual(problem: JerkProblem, lay: _Layout, h: np.ndarray) -> float:
    """Largest residual, the position equality relative to the interval length."""
    return float(np.max(np.abs(np.concatenate((h[:lay.N], h[lay.N:] / problem.ds)))))


def project(problem: JerkProblem, lay: _Layout, x: np.ndarray, w: np.ndarray
            ) -> np.ndarray | None:
    """Newton projection onto the equalities, minimum ``sum d_i^2 / w_i`` per step
    (``w_i = 0`` keeps variable ``i`` fixed); ``None`` when it does not converge."""
    x = x.copy()
    for _ in range(PROJECTION_MAX_ITER):
        h, r, col, v = equalities(problem, lay, x)
        if equality_residual(problem, lay, h) <= PROJECTION_TOL:
            return x
        J = sp.csr_matrix((v, (r, col)), shape=(2 * lay.N, lay.nx))
        JW = J @ sp.diags(w)
        try:
            y = splu((JW @ J.T).tocsc()).solve(h)
        except RuntimeError:            # singular: a fixed variable blocks the projection
            return None
        x = x - JW.T @ y
        if not np.all(np.isfinite(x)):
            return None
    h, *_ = equalities(problem, lay, x)
    return x if equality_residual(problem, lay, h) <= PROJECTION_TOL else None


def stretch_factor(problem: JerkProblem, lay: _Layout, x: np.ndarray) -> float:
    """The time stretch ``lam`` after which every row and bound holds exactly at its
    limit or inside (module docstring, *Feasibility*); ``inf`` when no stretch helps
    (a stop speed not 0, a negative speed or duration)."""
    c, a, dt, a_all = lay.split(x)
    if np.any(c[problem.c_max == 0] != 0) or np.any(c < 0) or np.any(dt <= 0):
        return np.inf
    ratios = [float(MIN_INTERVAL_TIME_REL / np.min(dt))]
    pos = problem.c_max > 0
    ratios.append(float(np.max(c[pos] / problem.c_max[pos], initial=0.0)))
    fin = np.isfinite(problem.v_interval)
    if fin.any():
        pk = c[:-1][fin] + a[:-1][fin] * dt[fin] / 2
        ratios.append(float(np.max(pk / problem.v_interval[fin])))
    for val, limit, degree in row_values(problem, lay, x):
        if val.size:
            ratios.append(float(np.max(np.abs(val) / limit)) ** (1.0 / degree))
    lam = max(ratios)
    return lam if lam > 0 and np.isfinite(lam) else np.inf


def row_values(problem: JerkProblem, lay: _Layout, x: np.ndarray
               ) -> list[tuple[np.ndarray, np.ndarray, int]]:
    """``(value, limit, degree)`` of the acceleration, step and jerk rows at ``x`` (the
    rows hold when ``|value| <= limit``; the degree is the one of the time-scaling
    lemma)."""
    c, a, dt, a_all = lay.split(x)
    out = []
    ar = problem.acc
    out.append((ar.dq * a_all[problem.acc_index] + ar.ddq * c[ar.node] ** 2, ar.limit, 2))
    st = problem.step
    z = np.concatenate((a_all, [0.0]))
    ai = z[np.where(st.ia_in < 0, z.size - 1, st.ia_in)]
    ao = z[np.where(st.ia_out < 0, z.size - 1, st.ia_out)]
    c2 = c[st.node] ** 2
    out.append((st.dq_out * ao + st.ddq_out * c2 - st.dq_in * ai - st.ddq_in * c2,
                st.limit, 2))
    jr = problem.jerk
    k = jr.interval
    e = a_all[problem.end_index]
    ah = np.where(jr.node != k, e[k], a[k])
    cn = c[jr.node]
    out.append((jr.dq * (e[k] - a[k]) / dt[k] + 3 * jr.ddq * cn * ah + jr.dddq * cn ** 3,
                jr.limit, 3))
    return out


def stretch(lay: _Layout, x: np.ndarray, lam: float) -> np.ndarray:
    """The same motion ``lam`` times slower (the time-scaling lemma)."""
    c, a, dt, a_all = lay.split(x)
    return lay.from_parts(c / lam, a / lam ** 2, dt * lam, a_all / lam ** 2)


@dataclass(frozen=True, slots=True, eq=False)
class Block:
    """One-sided rows with a convex majorant on the box,
    ``F(x + d) <= F + grad . d[cols] + sum w d[wcols]^2``.

    Attributes
    ----------
    cols : numpy.ndarray of int, shape (R, k)
        Columns of the linear part.
    grad : numpy.ndarray, shape (R, k)
        Gradient entries.
    F : numpy.ndarray, shape (R,)
        Row value at ``x`` (``<= 0`` when the row holds).
    wcols : numpy.ndarray of int, shape (R, m)
        Columns of the curvature.
    w : numpy.ndarray, shape (R, m)
        Curvature weights, ``>= 0``.
    scale : numpy.ndarray, shape (R,)
        The row's natural size (its limit).
    """

    cols: np.ndarray
    grad: np.ndarray
    F: np.ndarray
    wcols: np.ndarray
    w: np.ndarray
    scale: np.ndarray

    def scaled(self, cs: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(grad_z, F_z, w_z, reach)`` in ``z = d / cs`` and row units; ``reach > 0``
        where the row may reach its limit on the unit box."""
        s = self.scale
        gz = self.grad * cs[self.cols] / s[:, None]
        Fz = self.F / s
        wz = self.w * cs[self.wcols] ** 2 / s[:, None]
        return gz, Fz, wz, Fz + np.sum(np.abs(gz), axis=1) + np.sum(wz, axis=1)


def _pair(K, dx, dy):
    """Weights of ``K |u v| <= K (u^2 / s + s v^2) / 2`` with ``s = dx / dy`` (tight at
    the box corner), zero where either side is fixed."""
    ok = (dx > 0) & (dy > 0)
    s = np.where(ok, dx / np.where(dy > 0, dy, 1.0), 1.0)
    K = np.where(ok, K, 0.0)
    return K / (2 * s), K * s / 2


def blocks(problem: JerkProblem, lay: _Layout, x: np.ndarray, delta: np.ndarray
           ) -> list[Block]:
    """The inequality rows at ``x`` as one-sided blocks with their majorants on the box
    ``|d| <= delta``."""
    p = problem
    c, a, dt, a_all = lay.split(x)
    dc, da, dtt, da_all = lay.split(delta)
    e = a_all[p.end_index]
    out = []
    f = np.flatnonzero(np.isfinite(p.v_interval))
    if f.size:                                   # c + a dt / 2 <= v (one-sided)
        wa, wt = _pair(np.full(f.size, 0.5), da[f], dtt[f])
        out.append(Block(np.column_stack((f, lay.a(f), lay.t(f))),
                         np.column_stack((np.ones(f.size), dt[f] / 2, a[f] / 2)),
                         c[f] + a[f] * dt[f] / 2 - p.v_interval[f],
                         np.column_stack((lay.a(f), lay.t(f))), np.column_stack((wa, wt)),
                         p.v_interval[f]))
    ar = p.acc
    if ar.n:                                     # +-(q' a + q'' c^2) <= A
        cn = c[ar.node]
        g = ar.dq * a_all[p.acc_index] + ar.ddq * cn ** 2
        cols = np.column_stack((lay.a(p.acc_index), ar.node))
        grad = np.column_stack((ar.dq, 2 * ar.ddq * cn))
        for sgn in (1.0, -1.0):
            out.append(Block(cols, sgn * grad, sgn * g - ar.limit, ar.node[:, None],
                             np.maximum(sgn * ar.ddq, 0.0)[:, None], ar.limit))
    st = p.step
    if st.n:                                     # +-(step) <= Jstep T_ipo
        z = np.concatenate((a_all, [0.0]))
        ai = z[np.where(st.ia_in < 0, z.size - 1, st.ia_in)]
        ao = z[np.where(st.ia_out < 0, z.size - 1, st.ia_out)]
        cn = c[st.node]
        kap = st.ddq_out - st.ddq_in
        g = st.dq_out * ao - st.dq_in * ai + kap * cn ** 2
        # outside the path the acceleration is 0: a zero coefficient on the node's c
        cols = np.column_stack((np.where(st.ia_out < 0, st.node, lay.a(st.ia_out)),
                                np.where(st.ia_in < 0, st.node, lay.a(st.ia_in)), st.node))
        grad = np.column_stack((np.where(st.ia_out < 0, 0.0, st.dq_out),
                                np.where(st.ia_in < 0, 0.0, -st.dq_in), 2 * kap * cn))
        for sgn in (1.0, -1.0):
            out.append(Block(cols, sgn * grad, sgn * g - st.limit, st.node[:, None],
                             np.maximum(sgn * kap, 0.0)[:, None], st.limit))
    jr = p.jerk
    if jr.n:                                     # +-G <= J dt, G = jerk row times dt
        k = jr.interval
        hidx = np.where(jr.node != k, p.end_index[k], k)
        ah = a_all[hidx]
        cn = c[jr.node]
        t = dt[k]
        G = jr.dq * (e[k] - a[k]) + 3 * jr.ddq * cn * ah * t + jr.dddq * cn ** 3 * t
        cols = np.column_stack((lay.a(p.end_index[k]), lay.a(k), lay.a(hidx), jr.node,
                                lay.t(k)))
        gc = 3 * jr.ddq * ah * t + 3 * jr.dddq * cn ** 2 * t
        gt = 3 * jr.ddq * cn * ah + jr.dddq * cn ** 3
        grad = np.column_stack((jr.dq, -jr.dq, 3 * jr.ddq * cn * t, gc, gt))
        xc, xa, xt = dc[jr.node], da_all[hidx], dtt[k]
        C3, D = np.abs(3 * jr.ddq), np.abs(jr.dddq)
        # remainder of q''' c^3 t on the box, all in the c direction (t's part bounded
        # through |dc| <= xc, |dt| <= xt)
        wc = D * (3 * cn * t + t * xc + 3 * cn * xt + xc * xt)
        wa = np.zeros(jr.n)
        wt = np.zeros(jr.n)
        # cross terms of 3 q'' c a t (c-a, c-t, a-t; the c-t also of q''' c^3 t),
        # each split into two squares
        dx = (xc, xa, xt)
        for K, (i, j) in ((C3 * (t + xt), (0, 1)), (C3 * np.abs(ah) + 3 * D * cn ** 2, (0, 2)),
                          (C3 * cn, (1, 2))):
            u, v = _pair(K, dx[i], dx[j])
            for idx, val in ((i, u), (j, v)):
                if idx == 0:
                    wc = wc + val
                elif idx == 1:
                    wa = wa + val
                else:
                    wt = wt + val
        wcols = np.column_stack((jr.node, lay.a(hidx), lay.t(k)))
        w = np.column_stack((wc, wa, wt))
        Jt = jr.limit * t
        for sgn in (1.0, -1.0):
            gr = sgn * grad
            gr[:, 4] -= jr.limit
            out.append(Block(cols, gr, sgn * G - Jt, wcols, w, Jt))
    return out


@dataclass(frozen=True, slots=True, eq=False)
class _Sub:
    """A subproblem's answer: the step ``d`` (unscaled) and the solver's account."""

    ok: bool
    d: np.ndarray
    iterations: int
    status: str


def _box(problem: JerkProblem, lay: _Layout, x: np.ndarray, delta: np.ndarray,
         cs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bounds of the scaled step ``z``: the trust box intersected with the variable
    bounds (``0 <= c <= c_max``, ``dt >= MIN``) and the relative speed drop."""
    N = lay.N
    lbx = np.concatenate((np.zeros(N + 1), np.full(N + 1, -np.inf),
                          np.full(N, MIN_INTERVAL_TIME_REL), np.full(lay.ne, -np.inf)))
    ubx = np.concatenate((problem.c_max, np.full(N + 1, np.inf), np.full(N, np.inf),
                          np.full(lay.ne, np.inf)))
    lo = np.maximum(-delta, lbx - x)
    lo[:N + 1] = np.maximum(lo[:N + 1], -C_DROP * x[:N + 1])
    hi = np.minimum(delta, ubx - x)
    return lo / cs, np.maximum(lo, hi) / cs


def _linear_objective(lay: _Layout, cs: np.ndarray) -> np.ndarray:
    """``sum dt`` in ``z``, normalised to sum 1."""
    q = np.zeros(lay.nx)
    q[lay.dt_slice] = cs[lay.dt_slice]
    return q / float(np.sum(q))


def _equality_rows(problem, lay, x, cs):
    """Linearised equalities in ``z``, each row divided by its natural size."""
    h, r, col, v = equalities(problem, lay, x)
    size = np.concatenate((np.ones(lay.N), problem.ds))
    return r, col, v * cs[col] / size[r], -h / size


class _ClarabelSub:
    """The SOCP subproblem (module docstring, 2.): variables ``[z (n_x), y (n_y)]``,
    ``y_i >= z_i^2`` for every variable with curvature, rows ``g . z + w . y <= -F``."""

    def __init__(self, problem: JerkProblem, lay: _Layout):
        self.p, self.lay = problem, lay

    def solve(self, x: np.ndarray, delta: np.ndarray, cs: np.ndarray) -> _Sub:
        import clarabel

        p, lay = self.p, self.lay
        nx = lay.nx
        r, col, v, b_eq = _equality_rows(p, lay, x, cs)
        scaled = [(b, *b.scaled(cs)) for b in blocks(p, lay, x, delta)]
        used = np.zeros(nx, bool)
        for b, _, _, wz, _ in scaled:
            used[b.wcols[wz > 0]] = True
        ny = int(used.sum())
        ycol = np.full(nx, -1)
        ycol[used] = nx + np.arange(ny)
        rr, cc, vv, bb = [r], [col], [v], [b_eq]
        n_eq = n = 2 * lay.N
        for b, gz, Fz, wz, reach in scaled:
            keep = reach > 0
            nk = int(keep.sum())
            if not nk:
                continue
            rows = n + np.arange(nk)
            rr.append(np.repeat(rows, b.cols.shape[1]))
            cc.append(b.cols[keep].ravel())
            vv.append(gz[keep].ravel())
            wk = wz[keep]
            pos = wk > 0
            rr.append(np.repeat(rows, b.wcols.shape[1])[pos.ravel()])
            cc.append(ycol[b.wcols[keep]][pos])
            vv.append(wk[pos])
            bb.append(-Fz[keep])
            n += nk
        zl, zu = _box(p, lay, x, delta, cs)
        iu = np.flatnonzero(np.isfinite(zu))
        il = np.flatnonzero(np.isfinite(zl))
        rr += [n + np.arange(iu.size), n + iu.size + np.arange(il.size)]
        cc += [iu, il]
        vv += [np.ones(iu.size), -np.ones(il.size)]
        bb += [zu[iu], -zl[il]]
        n += iu.size + il.size
        n_lin = n - n_eq
        # y_i >= z_i^2  <=>  (y + 1, y - 1, 2 z) in SOC(3)
        iz = np.flatnonzero(used)
        base = n + 3 * np.arange(ny)
        rr += [base, base + 1, base + 2]
        cc += [ycol[iz], ycol[iz], iz]
        vv += [-np.ones(ny), -np.ones(ny), -2 * np.ones(ny)]
        b_soc = np.zeros(3 * ny)
        b_soc[0::3] = 1.0
        b_soc[1::3] = -1.0
        n += 3 * ny
        A = sp.csc_matrix((np.concatenate(vv), (np.concatenate(rr), np.concatenate(cc))),
                          shape=(n, nx + ny))
        cones = [clarabel.ZeroConeT(n_eq), clarabel.NonnegativeConeT(n_lin)]
        cones += [clarabel.SecondOrderConeT(3)] * ny
        q = np.concatenate((_linear_objective(lay, cs), np.zeros(ny)))
        P = sp.diags(np.concatenate((np.full(nx, THETA / nx), np.zeros(ny))), format="csc")
        st = clarabel.DefaultSettings()
        st.verbose = False
        st.max_iter = CLARABEL_MAX_ITER
        st.tol_gap_abs = st.tol_gap_rel = st.tol_feas = CLARABEL_TOL
        res = clarabel.DefaultSolver(P, q, A, np.concatenate(bb + [b_soc]), cones,
                                     st).solve()
        status = str(res.status)
        ok = status in ("Solved", "AlmostSolved")
        z = np.asarray(res.x)[:nx] if ok else np.zeros(nx)
        return _Sub(ok, z * cs, int(res.iterations), status)


class _OsqpSub:
    """The QP subproblem (module docstring, 2.): linearised rows, row curvature in the
    objective weighted by the last multipliers; one OSQP instance for all iterations
    (the sparsity of ``A`` and ``P`` is the same every time), warm started."""

    def __init__(self, problem: JerkProblem, lay: _Layout):
        self.p, self.lay = problem, lay
        self.solver = None
        self.pattern = None
        self.y = None

    def solve(self, x: np.ndarray, delta: np.ndarray, cs: np.ndarray) -> _Sub:
        import osqp

        p, lay = self.p, self.lay
        nx = lay.nx
        r, col, v, b_eq = _equality_rows(p, lay, x, cs)
        rows, cols, vals, lo, hi = [r], [col], [v], [b_eq], [b_eq]
        n = 2 * lay.N
        curv = []
        for b in blocks(p, lay, x, delta):
            gz, Fz, wz, reach = b.scaled(cs)
            R, k = b.cols.shape
            rows.append(np.repeat(n + np.arange(R), k))
            cols.append(b.cols.ravel())
            vals.append(gz.ravel())
            lo.append(np.full(R, -np.inf))
            hi.append(np.where(reach > 0, -Fz, np.inf))
            curv.append((n, b.wcols, wz))
            n += R
        zl, zu = _box(p, lay, x, delta, cs)
        rows.append(n + np.arange(nx))
        cols.append(np.arange(nx))
        vals.append(np.ones(nx))
        lo.append(zl)
        hi.append(zu)
        n += nx
        rows, cols, vals = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
        lo, hi = np.concatenate(lo), np.concatenate(hi)
        if self.pattern is None:
            self.pattern = _csc_pattern(rows, cols, n, nx)
        indices, indptr, slot, nslot = self.pattern
        data = np.bincount(slot, weights=vals, minlength=nslot)
        A = sp.csc_matrix((data, indices, indptr), shape=(n, nx))
        q = _linear_objective(lay, cs)
        diag = np.full(nx, THETA / nx)
        if self.y is not None:
            for r0, wc, wz in curv:
                yr = np.maximum(self.y[r0:r0 + wz.shape[0]], 0.0)
                np.add.at(diag, wc.ravel(), (yr[:, None] * 2 * wz).ravel())
        P = sp.diags(diag, format="csc")
        # osqp 1.x renamed ``polish`` and warns unless ``raise_error`` is given
        v1 = hasattr(osqp, "SolverStatus")
        if self.solver is None:
            self.solver = osqp.OSQP()
            self.solver.setup(P, q, A, lo, hi, eps_abs=OSQP_EPS, eps_rel=OSQP_EPS,
                              warm_starting=True, verbose=False, max_iter=OSQP_MAX_ITER,
                              **{"polishing" if v1 else "polish": True})
        else:
            self.solver.update(q=q, l=lo, u=hi, Ax=data, Px=P.data)
        res = self.solver.solve(raise_error=False) if v1 else self.solver.solve()
        ok = res.info.status_val in _OSQP_SOLVED
        if ok:
            self.y = np.asarray(res.y).copy()
        z = np.asarray(res.x) if ok else np.zeros(nx)
        return _Sub(ok, z * cs, int(res.info.iter), str(res.info.status))


def _csc_pattern(rows, cols, n_rows, n_cols):
    """CSC structure of the entries ``(rows, cols)`` (duplicates summed) and the slot of
    every entry, so that later values fill the same structure by ``bincount``."""
    key = cols.astype(np.int64) * n_rows + rows
    uniq, inv = np.unique(key, return_inverse=True)
    indptr = np.zeros(n_cols + 1, np.int64)
    np.add.at(indptr, uniq // n_rows + 1, 1)
    return (uniq % n_rows).astype(np.int64), np.cumsum(indptr), inv, int(uniq.size)


def _trust_scales(lay: _Layout, x: np.ndarray, rho: float, fixed: np.ndarray) -> np.ndarray:
    """Half-widths of the trust box (module docstring, 1.)."""
    c, a, dt, a_all = lay.split(x)
    sc = rho * (c + C_FLOOR * np.max(c))
    sa = rho * (np.abs(a_all) + A_FLOOR * np.sqrt(np.mean(a_all ** 2)))
    d = lay.from_parts(sc, sa[:lay.N + 1], rho * dt, sa)
    d[fixed] = 0.0
    return d


def feasible_start(problem: JerkProblem, lay: _Layout, x0: np.ndarray, fixed: np.ndarray
                   ) -> np.ndarray | None:
    """A feasible point near ``x0``: projected onto the equalities and stretched.

    Four projection metrics are tried (durations kept or free; speeds weighted by the
    trust scales or relative to themselves, so that a node near a small cap stays near
    it); the fastest feasible result is returned, ``None`` when none projects."""
    N = lay.N
    w = _trust_scales(lay, x0, 1.0, fixed) ** 2
    w_rel = w.copy()
    w_rel[:N + 1] = np.where(fixed[:N + 1], 0.0, x0[:N + 1] ** 2)
    best, best_T = None, np.inf
    for wk in (w, w_rel):
        wk_dt = wk.copy()
        wk_dt[lay.dt_slice] = 0.0
        for wm in (wk_dt, wk):
            xp = project(problem, lay, x0, wm)
            if xp is None:
                continue
            lam = stretch_factor(problem, lay, xp)
            if np.isfinite(lam) and lam * _objective(lay, xp) < best_T:
                best, best_T = stretch(lay, xp, lam), lam * _objective(lay, xp)
    return best


def _result(problem: JerkProblem, lay: _Layout, x: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    c, a, dt, a_all = lay.split(x)
    return c, a, a_all[problem.end_index], dt


def solve_nlp(problem: JerkProblem, c0: np.ndarray, a0: np.ndarray, dt0: np.ndarray,
              *, print_level: int = 0, subproblem: str = "clarabel",
              max_iter: int = SCP_MAX_ITER, callback: IterateFn | None = None
              ) -> NlpResult:
    """Minimise the total time of the jerk grid NLP by SCP with feasible iterates.

    Same contract as :func:`optimal.jerk.backends.ipopt.solve_nlp`; unlike IPOPT's,
    the returned point is feasible (module docstring) even when ``success`` is false.

    Parameters
    ----------
    problem : JerkProblem
        The transcribed problem.
    c0, a0 : numpy.ndarray, shape (N + 1,)
        Initial speed and acceleration (dimensionless).
    dt0 : numpy.ndarray, shape (N,)
        Initial interval durations (dimensionless, > 0).
    print_level : int
        0: silent; 1 or more: one line per iteration on stdout.
    subproblem : {"clarabel", "osqp"}
        Solver of the convex subproblems (module docstring, 2.).
    max_iter : int
        Most SCP iterations.
    callback : callable, optional
        ``callback(c, a, a_end, dt)`` with every accepted iterate, the start included
        (arrays of the shapes of the result's; for tests of feasibility).

    Returns
    -------
    NlpResult
        ``success``: converged, or stalled (no step of the convex model improves the
        time); ``iterations``: SCP iterations (subproblems solved); ``message``: the
        stop reason, the subproblem solver and its total inner iterations.

    Raises
    ------
    ValueError
        Unknown ``subproblem``.
    """
    if subproblem not in SUBPROBLEMS:
        raise ValueError(f"subproblem {subproblem!r}: expected one of {SUBPROBLEMS}")
    tb = time.perf_counter()
    lay = _Layout(problem.n_intervals, problem.n_extra)
    N = lay.N
    fixed = np.zeros(lay.nx, bool)
    fixed[:N + 1] = problem.c_max == 0
    x = np.concatenate((np.clip(c0, 0.0, problem.c_max), a0,
                        np.maximum(dt0, MIN_INTERVAL_TIME_REL),
                        a0[problem.grid.break_node[1:-1]]))
    x[fixed] = 0.0
    x = feasible_start(problem, lay, x, fixed)
    build = time.perf_counter() - tb
    ts = time.perf_counter()
    if x is None:
        n0 = np.zeros(N + 1)
        return NlpResult(False, n0, n0, np.zeros(N), np.zeros(N), 0,
                         "the start does not project onto the integration equalities",
                         build, time.perf_counter() - ts)
    T = _objective(lay, x)
    if callback:
        callback(*_result(problem, lay, x))
    sub_solver = (_ClarabelSub if subproblem == "clarabel" else _OsqpSub)(problem, lay)
    rho = RHO0
    n_sub = n_inner = 0
    status = "iteration limit"
    for it in range(max_iter):
        delta = _trust_scales(lay, x, rho, fixed)
        cs = np.where(fixed, 1.0, delta)
        sub = sub_solver.solve(x, delta, cs)
        n_sub += 1
        n_inner += sub.iterations
        accepted = None
        if sub.ok:
            d = np.where(fixed, 0.0, sub.d)
            pred = -float(np.sum(d[lay.dt_slice]))
            if pred <= SCP_TOL * T:
                status = "converged"
                break
            # projection metric: the trust box's, speeds at most relative to themselves
            # (a node at a small cap is not pushed over it by the correction)
            wproj = np.where(fixed, 0.0, delta ** 2)
            wproj[:N + 1] = np.minimum(wproj[:N + 1], (rho * x[:N + 1]) ** 2)
            for tau in STEP_FRACTIONS:
                xp = project(problem, lay, x + tau * d, wproj)
                if xp is None:
                    continue
                lam = stretch_factor(problem, lay, xp)
                if not np.isfinite(lam):
                    continue
                xn = stretch(lay, xp, lam)
                Tn = _objective(lay, xn)
                if Tn < T:
                    accepted = (tau, xn, Tn)
                    break
        if accepted is None:
            rho /= 4
            if print_level:
                print(f"{it:4d} rejected ({sub.status}), rho {rho:.3g}")
            if rho < RHO_MIN:
                status = "stalled" if sub.ok else f"subproblem failed ({sub.status})"
                break
            continue
        tau, xn, Tn = accepted
        ratio = (T - Tn) / (tau * pred)
        if print_level:
            print(f"{it:4d} T {Tn:.12g} dT {T - Tn:.2e} ratio {ratio:.3f} tau {tau} "
                  f"rho {rho:.3g} {sub.status} {sub.iterations}")
        x, T = xn, Tn
        if callback:
            callback(*_result(problem, lay, x))
        if tau == 1.0 and ratio > 0.75:
            rho = min(2 * rho, RHO_MAX)
        elif tau < 1.0 or ratio < 0.25:
            rho /= 2
    c, a, a_end, dt = _result(problem, lay, x)
    return NlpResult(success=status in ("converged", "stalled"), c=c, a=a, a_end=a_end,
                     dt=dt, iterations=n_sub,
                     message=f"SCP {status} ({subproblem}, {n_inner} inner iterations)",
                     build_time_s=build, solve_time_s=time.perf_counter() - ts)
