"""A convex relaxation of the jerk-limited problem on a grid: the jerk oracle's main
lower bound, a second-order cone program solved by Clarabel.

Variables
=========
On a :class:`~optimal.grid.Grid` with nodes ``s_0 < ... < s_N`` (every segment break a
node): ``b_k`` (the squared path speed at node ``k``), ``a0_k`` and ``a1_k`` (the path
acceleration at the start and at the end of interval ``k``) and ``tau_k`` (the time spent
in interval ``k``). Objective: ``min sum tau_k``.

Why every jerk-feasible motion is feasible here
===============================================
Take any motion of the ``jerk`` bound set (:mod:`optimal.jerk.lower`, "The problem": the
``acc`` constraints; the axis jerk ``|q'_i s''' + 3 q''_i v s'' + q'''_i v^3| <= J_i``
inside segments; the axis acceleration ``A_i = q'_i s'' + q''_i v^2`` stepping only at
segment breaks and the path ends, by at most ``Jstep_i T_ipo``, and elsewhere by at most
``eps_i = ACCEL_CONTINUITY_TOL_REL J_i T_ipo`` summed over a segment). Set ``b_k`` to its
``v^2`` at ``s_k``, ``a0_k, a1_k`` to its path acceleration just after ``s_k`` and just
before ``s_{k+1}``, ``tau_k`` to the time between. Then, writing ``A_i^0``, ``A_i^1`` for
the axis accelerations at the two ends of the interval (each affine in the variables,
with the interval's own geometry ``q'_i, q''_i`` at the ends):

1. ``b_k <= bhat_k`` (the ``acc`` relaxation's greatest element dominates every
   ``acc``-feasible, hence every jerk-feasible motion, :mod:`optimal.bounds`), ``b = 0``
   at stops, ``tau_k >= t_acc,k``, the ``acc`` relaxation's lower estimate of the time
   in the interval (same module, step 4), and the time on every segment at least its
   per-segment jerk bound (:func:`optimal.jerk.lower.jerk_lower_bound`).
2. ``|A_i^0|, |A_i^1| <= A_i`` (the axis acceleration limit, point-wise).
3. ``|A_i^1 - A_i^0| <= J_i tau_k + eps_i``: ``A_i`` is absolutely continuous inside a
   segment apart from steps of at most ``eps_i`` in total, with ``|dA_i/dt| <= J_i``
   (the axis jerk) almost everywhere.
4. *Steps*: at a break node the axis accelerations on both sides differ by at most
   ``max(Jstep_i, J_i) T_ipo`` (the rulebook; the larger of the two limits, because the
   relaxation does not know whether the path moves there); at the path ends the outside
   rests (``|A_i| <= J_i T_ipo``), and so on both sides of a break where a hold (a dwell,
   an exact-stop settle) keeps the path at rest: the reported motion has the hold's zero
   acceleration between the arriving and the leaving motion, at speed 0, where the
   rulebook's step limit is ``J_i`` (:func:`reference.core.holds.with_holds`); inside a
   segment ``a1_{k-1} = a0_k``, both set to the motion's acceleration just *before* node
   ``k``: a step there is part of the segment's budget ``eps_i``, which every row of the
   interval after it carries (rows 3, 5 and 6 bound the variation of ``A_i`` from
   ``A_i^0`` by ``J_i t + eps_i``).
5. *Energy rows with jerk*: ``(q'_i^2 b)' = 2 q'_i A_i`` along ``s``, so
   ``q'_i(s_{k+1})^2 b_{k+1} - q'_i(s_k)^2 b_k = 2 int q'_i A_i ds``. Inside the
   interval ``A_i`` stays within ``J_i t + eps_i`` of ``A_i^0`` and within
   ``J_i (tau - t) + eps_i`` of ``A_i^1``, hence within ``r_i = J_i tau / 2 + eps_i`` of
   their mean ``Am_i = (A_i^0 + A_i^1) / 2``: ``int q'_i A_i ds = Am_i dq_i + E`` with
   ``|E| <= r_i int |q'_i| ds``; ``dq_i`` is the exact chord and the travel
   ``int |q'_i|`` is the chord where ``q'_i`` keeps its sign, else ``D sup|q'_i|``
   (:func:`optimal.bounds.derivative_ranges`). Also ``|2 int q'_i A_i| <= 2 A_i travel``.
6. *Time*: on lines, circles and helices ``q' . q'' = 0``, so the path acceleration is
   ``a = sum_i q'_i A_i / |q'|^2`` (``|q'|^2`` constant there). With the bounds of 5 on
   ``A_i`` and ``q'_i`` within ``delta_i`` of its mid-interval value ``m_i``:
   ``a <= u = sum_i (m_i^+ Ahi_i - m_i^- Alo_i + delta_i A_i) / |q'|^2`` and
   ``a >= -w`` likewise (``Ahi, Alo = Am +- r``), both affine in the variables. So
   ``b(s_k + x) <= L1(x) = b_k + 2 u x`` and ``<= L2(x) = b_{k+1} + 2 w (D - x)``, and
   every convex combination ``l = (1 - lam) L1 + lam L2`` is an affine majorant of
   ``b`` on the interval; ``int dx / sqrt(b) >= int dx / sqrt(l) =
   2 D / (sqrt(l(0)) + sqrt(l(D)))``. With ``rho_0^2 <= l(0)``, ``rho_1^2 <= l(D)`` and
   ``tau (rho_0 + rho_1) >= 2 D`` (second-order cones), for ``lam = 0, 1/2, 1``. The
   same holds on spirals and clothoids, which are parameterised by arc length in their
   plane (``|q'|`` constant, ``q' . q'' = 0``, :func:`_unit_speed_curve`); there the
   ranges of ``q'_j`` are the end values widened by ``D sup|q''_j| / 2``
   (:func:`reference.core.geometry.plane_amplitudes`), which steps 5 and 6 use.

So the relaxation's optimum is at most the motion's time, for every jerk-feasible motion:
it is a lower bound of the minimum time. Clarabel returns a primal and a dual objective;
the smaller, less :data:`~optimal.jerk.tolerances.RELAX_SOLVER_MARGIN_REL` (ten times the
solver's relative tolerance) and less their own relative difference, is reported; a run
whose two objectives differ by more than that margin gives no bound.

What it captures that the per-segment bounds do not: the coupling of the accelerations
across breaks and inside segments (an acceleration must ramp through zero when the motion
turns from braking into a junction to accelerating out of it), the curvature-jump steps
at breaks, and jerk on arcs through the axis accelerations rather than norms. What it
loses: the slack ``J_i tau / 2`` of step 5 and the ``J tau`` width of the tents in step
6, first order in the interval time, so the bound converges at first order; the caller
refines where the bracket is.

Units: mm, s (scaled internally: speeds^2 by the largest node bound, accelerations by the
largest axis limit, times by the mean interval time). Shapes: ``N`` intervals, ``n``
axes.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from reference.core.geometry import Path, plane_amplitudes
from reference.core.limits import AxisArrays
from reference.core.rules import curvature_jumps, step_jerk_limit
from reference.core.tolerances import ACCEL_CONTINUITY_TOL_REL

from ..bounds import derivative_ranges
from ..grid import Grid
from ..problem import interval_geometry
from .backends.socp import solve_conic
from .tolerances import RELAX_SOLVER_MARGIN_REL, RELAX_SOLVER_MAX_ITER, RELAX_SOLVER_TOL


@dataclass(frozen=True, slots=True, eq=False)
class RunFloors:
    """Lower bounds of the time on runs of consecutive segments.

    Attributes
    ----------
    lo, hi : numpy.ndarray of int64, shape (R,)
        Each run is the segments ``lo .. hi - 1`` (``lo < hi``).
    value : numpy.ndarray, shape (R,)
        Its bound, s.
    """

    lo: np.ndarray
    hi: np.ndarray
    value: np.ndarray

    def joined(self, other: RunFloors) -> RunFloors:
        """Both sets of rows."""
        return RunFloors(np.concatenate((self.lo, other.lo)),
                         np.concatenate((self.hi, other.hi)),
                         np.concatenate((self.value, other.value)))


@dataclass(frozen=True, slots=True, eq=False)
class RelaxationResult:
    """The relaxation's solution.

    Attributes
    ----------
    ok : bool
        Clarabel solved it: status ``Solved`` or ``AlmostSolved``, with primal and dual
        objectives within :data:`~optimal.jerk.tolerances.RELAX_SOLVER_MARGIN_REL` of
        each other.
    lower_bound_s : float
        The certified bound (the smaller of the primal and dual objective, less the
        margin), s; 0 when not ``ok``.
    tau : numpy.ndarray, shape (N,)
        Time per interval at the relaxation's optimum, s (zeros when not ``ok``): where the
        relaxation sees the motion's time.
    b : numpy.ndarray, shape (N + 1,)
        ``v^2`` at the nodes at the optimum, mm^2/s^2.
    status : str
        Clarabel's status.
    iterations : int
    build_time_s, solve_time_s : float
    """

    ok: bool
    lower_bound_s: float
    tau: np.ndarray
    b: np.ndarray
    status: str
    iterations: int
    build_time_s: float
    solve_time_s: float


#: The convex combinations ``(1 - lam) L1 + lam L2`` of the two tents used as majorants
#: of ``b`` (step 6 of the module docstring): the two tents themselves. Adding
#: ``lam = 1/2`` moved the bound by less than 1e-6 (relative) on the stadium and the demo
#: and cost a third more solver time.
_LAMBDAS = (0.0, 1.0)


class _Rows:
    """Sparse rows ``A x <= b`` (or ``= b``, or cone blocks) collected as triplets."""

    def __init__(self) -> None:
        self.r: list[np.ndarray] = []
        self.c: list[np.ndarray] = []
        self.v: list[np.ndarray] = []
        self.rhs: list[np.ndarray] = []
        self.n = 0

    def add(self, terms: list[tuple[np.ndarray, np.ndarray]], rhs: np.ndarray,
            normalise: bool = True) -> np.ndarray:
        """Rows ``sum_t coef_t x[col_t] (op) rhs``, one per entry of ``rhs``.

        ``terms`` are ``(col, coef)`` pairs of arrays shaped like ``rhs`` (a column
        index and a coefficient per row). Rows are divided by their largest coefficient
        when ``normalise`` (conditioning; the set is the same). Returns the row indices.
        """
        rhs = np.asarray(rhs, dtype=np.float64)
        k = rhs.size
        idx = self.n + np.arange(k)
        cols = [np.broadcast_to(np.asarray(c, np.int64), (k,)) for c, _ in terms]
        vals = [np.broadcast_to(np.asarray(v, np.float64), (k,)).copy() for _, v in terms]
        scale = np.ones(k)
        if normalise and vals:
            scale = np.max(np.abs(np.stack(vals)), axis=0)
            scale = np.where(scale > 0, scale, 1.0)
        for c, v in zip(cols, vals):
            self.r.append(idx)
            self.c.append(c)
            self.v.append(v / scale)
        self.rhs.append(rhs / scale)
        self.n += k
        return idx

    def matrix(self, n_cols: int) -> tuple[sp.csc_matrix, np.ndarray]:
        if not self.r:
            return sp.csc_matrix((0, n_cols)), np.zeros(0)
        A = sp.coo_matrix((np.concatenate(self.v), (np.concatenate(self.r),
                                                    np.concatenate(self.c))),
                          shape=(self.n, n_cols)).tocsc()
        A.eliminate_zeros()      # zero coefficients (a tangent component that vanishes)
        return A, np.concatenate(self.rhs)


@dataclass(frozen=True, slots=True, eq=False)
class RelaxationProblem:
    """The relaxation as Clarabel sees it: ``min q x`` s.t. ``A x + s = b``,
    ``s`` in (zero cone of ``n_eq`` rows, nonnegative cone of ``n_lin`` rows,
    ``n_soc`` second-order cones of dimension 3).

    Attributes
    ----------
    A : scipy.sparse.csc_matrix, shape (n_eq + n_lin + 3 n_soc, n_var)
    b : numpy.ndarray
    n_eq, n_lin, n_soc, n_var : int
    scales : tuple[float, float, float]
        Units of the scaled variables: ``v^2`` (mm^2/s^2), acceleration (mm/s^2), time
        (s).
    b_col, a0_col, a1_col, tau_col : numpy.ndarray of int
        Columns of ``b`` (N + 1), ``a0``, ``a1``, ``tau`` (N each).
    rho_col : numpy.ndarray of int, shape (2 L, K)
        Columns of the cone helpers ``rho`` (per majorant: ``rho_0`` then ``rho_1``) on
        the ``K`` intervals with time cones; the cones come in the same order, three
        blocks of ``K`` per majorant (``rho_0``, ``rho_1``, hyperbolic).
    """

    A: sp.csc_matrix
    b: np.ndarray
    n_eq: int
    n_lin: int
    n_soc: int
    n_var: int
    scales: tuple[float, float, float]
    b_col: np.ndarray
    a0_col: np.ndarray
    a1_col: np.ndarray
    tau_col: np.ndarray
    rho_col: np.ndarray

    def point(self, b: np.ndarray, a0: np.ndarray, a1: np.ndarray, tau: np.ndarray
              ) -> np.ndarray:
        """The variable vector of a motion's node values (``b`` in mm^2/s^2, ``a0, a1``
        in mm/s^2, ``tau`` in s), with every cone helper ``rho`` at its largest value
        (``rho = sqrt(l)``, read from the cones' rows): the point a feasibility test
        evaluates."""
        Bs, As, Ts = self.scales
        x = np.zeros(self.n_var)
        x[self.b_col] = b / Bs
        x[self.a0_col] = a0 / As
        x[self.a1_col] = a1 / As
        x[self.tau_col] = tau / Ts
        # per majorant three blocks of K cones: rho_0^2 <= l(0), rho_1^2 <= l(D) (rows
        # (l + 1, 2 rho, l - 1): with rho = 0 the first row's value is l + 1), then the
        # hyperbolic one
        start = self.n_eq + self.n_lin
        s0 = self.b - self.A @ x
        K = self.rho_col.shape[1]
        for m in range(self.rho_col.shape[0] // 2):
            for part in (0, 1):
                cones = (3 * m + part) * K + np.arange(K)
                ell = s0[start + 3 * cones] - 1.0
                x[self.rho_col[2 * m + part]] = np.sqrt(np.maximum(ell, 0.0))
        return x

    def violation(self, x: np.ndarray) -> dict[str, float]:
        """Largest violation of each kind of row at ``x`` (0 where all hold): equalities
        (absolute), inequalities (scaled units) and cones (``||s_1,2|| - s_0``)."""
        s = self.b - self.A @ x
        e, ln = self.n_eq, self.n_lin
        soc = s[e + ln:].reshape(-1, 3)
        return {"equality": float(np.max(np.abs(s[:e]), initial=0.0)),
                "inequality": float(max(0.0, -np.min(s[e:e + ln], initial=0.0))),
                "cone": float(max(0.0, np.max(np.hypot(soc[:, 1], soc[:, 2]) - soc[:, 0],
                                                 initial=0.0)))}


def build_relaxation_problem(path: Path, lim: AxisArrays, t_ipo: float, grid: Grid,
                             b_hat: np.ndarray, t_acc: np.ndarray,
                             seg_floor: np.ndarray | None = None,
                             hold_breaks: np.ndarray | None = None,
                             run_floor: RunFloors | None = None) -> RelaxationProblem:
    """Assemble the relaxation of the module docstring on ``grid``.

    Parameters
    ----------
    path : Path
        The path (the moving axes only is enough and faster).
    lim : AxisArrays
        Limits in the path's axis order.
    t_ipo : float
        IPO cycle, s.
    grid : Grid
        Nodes; every segment break is a node.
    b_hat : numpy.ndarray, shape (N + 1,)
        Node bounds valid for every ``acc``-feasible motion (the ``acc`` relaxation's
        greatest element on this grid), mm^2/s^2.
    t_acc : numpy.ndarray, shape (N,)
        Lower estimates of the time in each interval valid for every ``acc``-feasible
        motion (the ``acc`` relaxation's), s.
    seg_floor : numpy.ndarray, shape (m,), optional
        Lower bounds of the time every jerk-feasible motion spends on each segment, s
        (:func:`optimal.jerk.lower.jerk_lower_bound`'s per-segment bounds): rows
        ``sum_{k on g} tau_k >= seg_floor_g``.
    hold_breaks : numpy.ndarray of int, optional
        Path breaks (``0..m``, repeats allowed) where a hold rests the motion
        (:attr:`reference.core.holds.Holds.break_index`): rows ``|A_i| <= J_i T_ipo`` on
        both sides, as at the path ends.
    run_floor : RunFloors, optional
        Lower bounds of the time a smaller set of motions (the caller's) spends on runs
        of consecutive segments: rows ``sum_{k on lo..hi-1} tau_k >= value``. The
        relaxation's optimum is then a bound for that set only (the ``jerk+freq``
        oracle's window rows, :mod:`optimal.freq.windows`).

    Returns
    -------
    RelaxationProblem
    """
    N = grid.n_intervals
    n = len(path.axes)
    D = np.diff(grid.s)
    seg = grid.segment
    A = lim.a_max
    J = lim.j_max
    eps = ACCEL_CONTINUITY_TOL_REL * J * t_ipo
    dq0, ddq0, dq1, ddq1 = interval_geometry(path, grid)
    t_lo, t_hi, _, _, exact, t_tol = derivative_ranges(path, grid, dq0, ddq0, dq1, ddq1)
    # spirals and clothoids: derivative_ranges gives the end values only; q'_j moves by
    # at most sup|q''_j| per mm, so on an interval of length D it stays within
    # D sup|q''_j| / 2 of the larger (smaller) end value
    vary = ~exact
    if np.any(vary):
        amp = plane_amplitudes(path)
        plane = np.sqrt(path.e1[seg] ** 2 + path.e2[seg] ** 2)
        widen = (0.5 * D * amp.curvature[seg])[:, None] * plane
        t_lo = np.where(vary[:, None], t_lo - widen, t_lo)
        t_hi = np.where(vary[:, None], t_hi + widen, t_hi)
    q0 = path.evaluate(grid.s[:-1], segment=seg)[0]
    q1 = path.evaluate(grid.s[1:], segment=seg)[0]
    chord = q1 - q0
    one = exact[:, None] & ((t_lo >= -t_tol) | (t_hi <= t_tol))
    travel = np.where(one, np.abs(chord) + t_tol * D[:, None],
                      D[:, None] * np.maximum(np.abs(t_lo), np.abs(t_hi)))
    # scales: v^2 by the largest node bound, accelerations by the largest limit, time by
    # the mean interval estimate
    b_hat = np.maximum(np.asarray(b_hat, dtype=np.float64), 0.0)
    Bs = float(np.max(b_hat)) if np.max(b_hat) > 0 else 1.0
    As = float(np.max(A))
    Ts = float(np.mean(t_acc)) if np.mean(t_acc) > 0 else 1.0
    # variable blocks (scaled): b (N+1), a0 (N), a1 (N), tau (N), then the cone helpers
    ib, ia0, ia1, it = 0, N + 1, 2 * N + 1, 3 * N + 1
    k_all = np.arange(N)
    B0, B1 = ib + k_all, ib + k_all + 1
    C0, C1, CT = ia0 + k_all, ia1 + k_all, it + k_all
    lin = _Rows()      # A x <= b
    eq = _Rows()       # A x = b
    # ---- 1: node bounds, stops, acc interval times
    # rows scaled by sqrt(Bs): between the raw mm^2/s^2 row (Clarabel stalled on a
    # tangential-axis program and on sub-millimetre spirals) and the unit row (153
    # interior-point iterations on 6,000 micrometre segments against 41 here); measured
    # on the corpus, this scaling solved every relaxation of every round
    lin.add([(ib + np.arange(N + 1), np.sqrt(Bs))], b_hat / np.sqrt(Bs), normalise=False)
    stops = grid.break_node[path.stop]
    if stops.size:
        eq.add([(ib + stops, 1.0)], np.zeros(stops.size), normalise=False)
    lin.add([(CT, -Ts)], -np.asarray(t_acc, dtype=np.float64))
    # a segment's floor is a run of one segment: one row per run, -sum tau_k <= -floor,
    # over its intervals (contiguous in the grid's order; rows of varying length: COO)
    runs = [] if run_floor is None else [run_floor]
    if seg_floor is not None:
        fl = np.asarray(seg_floor, dtype=np.float64)
        g_use = np.flatnonzero(fl > 0)
        runs.insert(0, RunFloors(g_use, g_use + 1, fl[g_use]))
    for run in runs:
        if run.value.size == 0:
            continue
        first = grid.break_node[run.lo]
        count = grid.break_node[run.hi] - first
        rows = np.repeat(np.arange(count.size), count)
        cols = np.repeat(first - np.cumsum(count) + count, count) + np.arange(int(count.sum()))
        lin.r.append(lin.n + rows)
        lin.c.append(CT[cols])
        lin.v.append(np.full(cols.size, -1.0))
        lin.rhs.append(-np.asarray(run.value, dtype=np.float64) / Ts)
        lin.n += count.size
    # axis accelerations at the interval ends as (col, coef) terms, physical units
    def acc_start(i):
        return [(C0, dq0[:, i] * As), (B0, ddq0[:, i] * Bs)]

    def acc_end(i):
        return [(C1, dq1[:, i] * As), (B1, ddq1[:, i] * Bs)]

    def neg(terms):
        return [(c, -v) for c, v in terms]

    used = np.flatnonzero(np.any(dq0 != 0, axis=0) | np.any(dq1 != 0, axis=0)
                          | np.any(ddq0 != 0, axis=0) | np.any(ddq1 != 0, axis=0))
    for i in used:
        # ---- 2: point-wise axis acceleration at both ends
        for terms in (acc_start(i), acc_end(i)):
            lin.add(terms, np.full(N, A[i]))
            lin.add(neg(terms), np.full(N, A[i]))
        # ---- 3: jerk over the interval
        diff = acc_end(i) + neg(acc_start(i))
        lin.add(diff + [(CT, -J[i] * Ts)], np.full(N, eps[i]))
        lin.add(neg(diff) + [(CT, -J[i] * Ts)], np.full(N, eps[i]))
        # ---- 5: energy rows with jerk; lhs = q'1^2 b1 - q'0^2 b0
        lhs = [(B1, dq1[:, i] ** 2 * Bs), (B0, -dq0[:, i] ** 2 * Bs)]
        mean = [(c, v * chord[:, i]) for c, v in (acc_start(i) + acc_end(i))]   # 2 Am dq
        half = [(CT, J[i] * Ts * travel[:, i])]                                   # 2 r trav
        rhs_eps = 2.0 * eps[i] * travel[:, i]
        lin.add(lhs + neg(mean) + neg(half), rhs_eps)
        lin.add(neg(lhs) + mean + neg(half), rhs_eps)
        lin.add(lhs, 2.0 * A[i] * travel[:, i])
        lin.add(neg(lhs), 2.0 * A[i] * travel[:, i])
    # ---- 4: breaks, ends, continuity inside segments
    m = path.n_segments
    if m >= 2:
        bn = grid.break_node[1:m]
        kin, kout = ddq1[bn - 1], ddq0[bn]
        jstep = np.maximum(step_jerk_limit(curvature_jumps(kin, kout), J, lim.path_trans_jerk),
                           J[None, :])
        for i in used:
            step = [(ia0 + bn, dq0[bn, i] * As), (ib + bn, ddq0[bn, i] * Bs),
                    (ia1 + bn - 1, -dq1[bn - 1, i] * As), (ib + bn, -ddq1[bn - 1, i] * Bs)]
            lin.add(step, jstep[:, i] * t_ipo)
            lin.add(neg(step), jstep[:, i] * t_ipo)
    for i in used:
        for terms in ([(ia0 + 0, dq0[0, i] * As), (ib + 0, ddq0[0, i] * Bs)],
                      [(ia1 + N - 1, dq1[-1, i] * As), (ib + N, ddq1[-1, i] * Bs)]):
            t1 = [(np.atleast_1d(c), np.atleast_1d(v)) for c, v in terms]
            lin.add(t1, np.array([J[i] * t_ipo]))
            lin.add(neg(t1), np.array([J[i] * t_ipo]))
    held = np.unique(np.asarray([] if hold_breaks is None else hold_breaks, np.int64))
    held = held[(held > 0) & (held < m)]
    if held.size:
        hn = grid.break_node[held]
        for i in used:
            arrive = [(ia1 + hn - 1, dq1[hn - 1, i] * As), (ib + hn, ddq1[hn - 1, i] * Bs)]
            leave = [(ia0 + hn, dq0[hn, i] * As), (ib + hn, ddq0[hn, i] * Bs)]
            for terms in (arrive, leave):
                lin.add(terms, np.full(hn.size, J[i] * t_ipo))
                lin.add(neg(terms), np.full(hn.size, J[i] * t_ipo))
    is_break = np.zeros(N + 1, bool)
    is_break[grid.break_node] = True
    inner = np.flatnonzero(~is_break[1:-1]) + 1
    if inner.size:
        # one acceleration per inner node (its left limit): a step there belongs to the
        # segment's continuity budget, which every interval row already carries (eps)
        eq.add([(ia1 + inner - 1, 1.0), (ia0 + inner, -1.0)], np.zeros(inner.size),
               normalise=False)
    # ---- 6: time cones on lines, circles and helices
    mid = 0.5 * (grid.s[:-1] + grid.s[1:])
    _, dqm, _, _ = path.evaluate(mid, segment=seg)
    nq2 = np.sum(dqm ** 2, axis=1)
    delta = np.maximum(np.abs(t_hi - dqm), np.abs(dqm - t_lo))
    ok = (exact | _unit_speed_curve(path)[seg]) & (nq2 > 0)
    sel = np.flatnonzero(ok)
    K = sel.size
    n_var = 4 * N + 1 + 2 * len(_LAMBDAS) * K
    soc_A: list = []
    soc_b: list = []
    if K:
        # u, w as terms over the interval's variables (physical units), plus constants
        u_terms, w_terms = [], []
        u_const = np.zeros(N)
        w_const = np.zeros(N)
        for i in used:
            cpos = np.maximum(dqm[:, i], 0.0) / np.where(nq2 > 0, nq2, 1.0)
            cneg = np.maximum(-dqm[:, i], 0.0) / np.where(nq2 > 0, nq2, 1.0)
            mean_half = [(c, 0.5 * v) for c, v in (acc_start(i) + acc_end(i))]   # Am
            rad = [(CT, 0.5 * J[i] * Ts)]                                        # r - eps
            # Ahi = Am + r, Alo = Am - r; u += cpos Ahi - cneg Alo, w += cneg Ahi - cpos Alo
            for c, v in mean_half:
                u_terms.append((c, (cpos - cneg) * v))
                w_terms.append((c, (cneg - cpos) * v))
            for c, v in rad:
                u_terms.append((c, (cpos + cneg) * v))
                w_terms.append((c, (cpos + cneg) * v))
            u_const += (cpos + cneg) * eps[i] + delta[:, i] * A[i] / np.where(nq2 > 0, nq2, 1.0)
            w_const += (cpos + cneg) * eps[i] + delta[:, i] * A[i] / np.where(nq2 > 0, nq2, 1.0)
        iR = 4 * N + 1
        Kroot = np.sqrt(4.0 * 2.0 * D[sel] / (np.sqrt(Bs) * Ts))    # 2 sqrt(K_k)
        for lam_i, lam in enumerate(_LAMBDAS):
            r0 = iR + (2 * lam_i) * K + np.arange(K)
            r1 = iR + (2 * lam_i + 1) * K + np.arange(K)
            # l(0) = (1 - lam) b_k + lam (b_k+1 + 2 D w);  l(D) = (1 - lam)(b_k + 2 D u) + lam b_k+1
            l0 = [(B0[sel], (1 - lam) * Bs), (B1[sel], lam * Bs)]
            l0 += [(c[sel], lam * 2 * D[sel] * v[sel]) for c, v in w_terms]
            l0c = lam * 2 * D[sel] * w_const[sel]
            l1 = [(B0[sel], (1 - lam) * Bs), (B1[sel], lam * Bs)]
            l1 += [(c[sel], (1 - lam) * 2 * D[sel] * v[sel]) for c, v in u_terms]
            l1c = (1 - lam) * 2 * D[sel] * u_const[sel]
            for ell, ellc, rr in ((l0, l0c, r0), (l1, l1c, r1)):
                # || (2 rho, l/Bs - 1) || <= l/Bs + 1   <=>   rho^2 <= l / Bs
                soc_A.append(_cone3(K, [(c, v / Bs) for c, v in ell], ellc / Bs,
                                    [(rr, 2.0)], np.zeros(K), n_var))
            # || (2 sqrt(K), tau - rho0 - rho1) || <= tau + rho0 + rho1
            soc_A.append(_hyperbolic(K, CT[sel], r0, r1, Kroot, n_var))
    A_lin, b_lin = lin.matrix(n_var)
    A_eq, b_eq = eq.matrix(n_var)
    blocks_A = [A_eq, A_lin] + [m_ for m_, _ in soc_A]
    blocks_b = [b_eq, b_lin] + [v_ for _, v_ in soc_A]
    rho = (4 * N + 1 + np.arange(2 * len(_LAMBDAS) * K)).reshape(2 * len(_LAMBDAS), K)
    return RelaxationProblem(
        A=sp.vstack(blocks_A).tocsc(), b=np.concatenate(blocks_b), n_eq=A_eq.shape[0],
        n_lin=A_lin.shape[0], n_soc=len(soc_A) * K, n_var=n_var, scales=(Bs, As, Ts),
        b_col=ib + np.arange(N + 1), a0_col=C0, a1_col=C1, tau_col=CT, rho_col=rho)


def jerk_relaxation(path: Path, lim: AxisArrays, t_ipo: float, grid: Grid,
                    b_hat: np.ndarray, t_acc: np.ndarray,
                    seg_floor: np.ndarray | None = None,
                    hold_breaks: np.ndarray | None = None,
                    run_floor: RunFloors | None = None) -> RelaxationResult:
    """Build (:func:`build_relaxation_problem`, same parameters) and solve the relaxation.

    Returns
    -------
    RelaxationResult
    """
    tb = time.perf_counter()
    prob = build_relaxation_problem(path, lim, t_ipo, grid, b_hat, t_acc, seg_floor,
                                    hold_breaks, run_floor)
    N = grid.n_intervals
    _, _, Ts = prob.scales
    Bs = prob.scales[0]
    q = np.zeros(prob.n_var)
    q[prob.tau_col] = 1.0
    ts = time.perf_counter()
    sol = solve_conic(prob.A, prob.b, q, prob.n_eq, prob.n_lin, prob.n_soc,
                      RELAX_SOLVER_TOL, RELAX_SOLVER_MAX_ITER)
    te = time.perf_counter()
    status = sol.status
    x = sol.x
    p_obj, d_obj = sol.primal_objective, sol.dual_objective
    rel_gap = (abs(p_obj - d_obj) / max(abs(p_obj), 1e-300)
               if np.isfinite(p_obj) and np.isfinite(d_obj) else np.inf)
    solved = (status in ("Solved", "AlmostSolved") and rel_gap <= RELAX_SOLVER_MARGIN_REL
              and np.all(np.isfinite(x)))
    if not solved:
        return RelaxationResult(False, 0.0, np.zeros(N), np.zeros(N + 1), status,
                                sol.iterations, ts - tb, te - ts)
    obj = min(p_obj, d_obj) * Ts
    lb = max(obj, 0.0) * (1.0 - RELAX_SOLVER_MARGIN_REL - rel_gap)
    return RelaxationResult(True, lb, x[prob.tau_col] * Ts,
                            np.maximum(x[prob.b_col] * Bs, 0.0), status,
                            sol.iterations, ts - tb, te - ts)


def _unit_speed_curve(path: Path) -> np.ndarray:
    """Segments on which ``|q'|`` is constant and ``q' . q'' = 0`` although the curvature
    varies (step 6 of the module docstring), shape (m,).

    Clothoids: ``q' = +-T``, ``q'' = kappa N`` with ``T``, ``N`` orthonormal in the plane
    (:func:`reference.core.geometry._eval_clothoid`). Spirals: the in-plane part of
    ``q'`` has the constant length ``g`` and ``q''`` lies in the plane, normal to it
    (:class:`reference.core.geometry.PlaneAmplitudes`), so with the linear part ``d``
    normal to the plane ``|q'|^2 = g^2 + |d|^2`` and ``q' . q'' = 0``; a spiral whose
    ``d`` has an in-plane part (none is built today) is left out.
    """
    d_in_plane = np.maximum(np.abs(np.sum(path.d * path.e1, axis=1)),
                            np.abs(np.sum(path.d * path.e2, axis=1)))
    spiral = (path.dradius != 0) & (d_in_plane <= 1e-12)
    return (path.sharpness != 0) | spiral


def _cone3(K, t_terms, t_const, z_terms, z_const, n_var):
    """Rows of ``K`` cones ``|| (z, t - 1) || <= t + 1`` (``z`` and ``t`` affine, given
    as ``(col, coef)`` terms plus constants): ``rho^2 <= t`` when ``z = 2 rho``. Clarabel's
    form ``s = b - A x`` with ``s = (t + 1, z, t - 1)`` interleaved per cone."""
    rows, cols, vals = [], [], []
    b = np.zeros(3 * K)
    base = 3 * np.arange(K)
    for c, v in t_terms:                       # row 0: t + 1, row 2: t - 1
        for off in (0, 2):
            rows.append(base + off)
            cols.append(np.broadcast_to(c, (K,)))
            vals.append(-np.broadcast_to(v, (K,)))
    b[base] = t_const + 1.0
    b[base + 2] = t_const - 1.0
    for c, v in z_terms:                       # row 1: z
        rows.append(base + 1)
        cols.append(np.broadcast_to(c, (K,)))
        vals.append(-np.broadcast_to(v, (K,)))
    b[base + 1] = z_const
    A = sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(3 * K, n_var))
    return A.tocsc(), b


def _hyperbolic(K, ct, r0, r1, two_sqrt_k, n_var):
    """Rows of ``K`` cones ``|| (2 sqrt(K), tau - rho0 - rho1) || <= tau + rho0 + rho1``,
    i.e. ``tau (rho0 + rho1) >= K`` (``tau, rho >= 0``)."""
    base = 3 * np.arange(K)
    rows = np.concatenate([base, base, base, base + 2, base + 2, base + 2])
    cols = np.concatenate([ct, r0, r1, ct, r0, r1])
    vals = np.concatenate([-np.ones(K), -np.ones(K), -np.ones(K),
                           -np.ones(K), np.ones(K), np.ones(K)])
    b = np.zeros(3 * K)
    b[base + 1] = two_sqrt_k
    A = sp.coo_matrix((vals, (rows, cols)), shape=(3 * K, n_var))
    return A.tocsc(), b
