"""The jerk grid NLP with CasADi + IPOPT (MUMPS), warm started.

The problem (:class:`~optimal.jerk.transcription.JerkProblem`) is built as one SX graph
from vector expressions (no per-node Python loop), so building costs a few ms per
thousand nodes; IPOPT exploits the banded sparsity of the KKT system. Exact Hessians
come from CasADi's automatic differentiation.

Variables ``x = [c (N + 1), a (N + 1), dt (N), e (extra)]``, dimensionless (``e``: the
accelerations on arriving at interior breaks). Minimise ``sum dt``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..tolerances import IPOPT_TOL, MIN_INTERVAL_TIME_REL, MU_STRATEGIES
from ..transcription import JerkProblem

NAME = "ipopt"


@dataclass(frozen=True, slots=True, eq=False)
class NlpResult:
    """IPOPT's answer (dimensionless, as in the problem).

    Attributes
    ----------
    success : bool
        IPOPT reported ``Solve_Succeeded`` or ``Solved_To_Acceptable_Level``.
    c, a : numpy.ndarray, shape (N + 1,)
        Path speed and acceleration at the nodes (at breaks: on leaving them).
    a_end : numpy.ndarray, shape (N,)
        Path acceleration at the end of every interval.
    dt : numpy.ndarray, shape (N,)
        Interval durations.
    iterations : int
        IPOPT iterations.
    message : str
        IPOPT's return status.
    build_time_s, solve_time_s : float
        Graph construction and solver time, s.
    """

    success: bool
    c: np.ndarray
    a: np.ndarray
    a_end: np.ndarray
    dt: np.ndarray
    iterations: int
    message: str
    build_time_s: float
    solve_time_s: float


def solve_nlp(problem: JerkProblem, c0: np.ndarray, a0: np.ndarray, dt0: np.ndarray,
              *, print_level: int = 0) -> NlpResult:
    """Minimise the total time of the jerk grid NLP from a warm start.

    Parameters
    ----------
    problem : JerkProblem
        The transcribed problem.
    c0, a0 : numpy.ndarray, shape (N + 1,)
        Initial speed and acceleration (dimensionless).
    dt0 : numpy.ndarray, shape (N,)
        Initial interval durations (dimensionless, > 0).
    print_level : int
        IPOPT's verbosity (0: silent).

    Returns
    -------
    NlpResult
    """
    import casadi as ca

    tb = time.perf_counter()
    N = problem.n_intervals
    ne = problem.n_extra
    nx = 2 * (N + 1) + N + ne
    # MX: one graph node per vector operation, so building the NLP and its derivatives
    # costs O(rows) in C++ (stadium, 5,000 intervals: nlpsol 0.21 s against 2.4 s for
    # the scalar SX graph, whose derivatives CasADi forms symbolically). The derivatives
    # are the same to round-off (Jacobian 2e-15, Hessian 1e-13 of 1.7e3 on
    # sin_cead_arc.mpf), but IPOPT's path is sensitive to them on hard problems, so a
    # failed attempt is repeated on the expanded (SX) graph (MU_STRATEGIES)
    x = ca.MX.sym("x", nx)
    c = x[0:N + 1]
    a = x[N + 1:2 * (N + 1)]
    dt = x[2 * (N + 1):3 * N + 2]
    a_all = ca.vertcat(a, x[3 * N + 2:])
    e = a_all[problem.end_index.tolist()]
    ds = ca.DM(problem.ds)
    g, lo, hi = [], [], []
    # exact integration of the triple integrator over each interval
    g.append(c[1:] - c[:-1] - (a[:-1] + e) * dt / 2)
    g.append(ds - c[:-1] * dt - (2 * a[:-1] + e) * dt * dt / 6)
    lo += [np.zeros(N), np.zeros(N)]
    hi += [np.zeros(N), np.zeros(N)]
    # the speed peak inside intervals that accelerate, then decelerate
    fin = np.flatnonzero(np.isfinite(problem.v_interval))
    if fin.size:
        iv = fin.tolist()
        g.append(c[iv] + a[iv] * dt[iv] / 2)
        lo.append(np.full(fin.size, -np.inf))
        hi.append(problem.v_interval[fin])
    ar = problem.acc
    if ar.n:
        cn = c[ar.node.tolist()]
        g.append(ca.DM(ar.dq) * a_all[problem.acc_index.tolist()] + ca.DM(ar.ddq) * cn * cn)
        lo.append(-ar.limit)
        hi.append(ar.limit)
    st = problem.step
    if st.n:
        cn = c[st.node.tolist()]
        zero = ca.MX(1, 1)
        a_in = ca.vertcat(a_all, zero)[np.where(st.ia_in < 0, N + 1 + ne, st.ia_in).tolist()]
        a_out = ca.vertcat(a_all, zero)[np.where(st.ia_out < 0, N + 1 + ne,
                                                 st.ia_out).tolist()]
        g.append(ca.DM(st.dq_out) * a_out + ca.DM(st.ddq_out) * cn * cn
                 - ca.DM(st.dq_in) * a_in - ca.DM(st.ddq_in) * cn * cn)
        lo.append(-st.limit)
        hi.append(st.limit)
    jr = problem.jerk
    if jr.n:
        node = jr.node.tolist()
        iv = jr.interval.tolist()
        cn = c[node]
        # the acceleration at the row's place: interval start, or its end value
        at_end = jr.node != jr.interval
        a_here = a_all[np.where(at_end, problem.end_index[jr.interval], jr.interval).tolist()]
        jerk = (e[iv] - a[iv]) / dt[iv]
        g.append(ca.DM(jr.dq) * jerk
                 + 3 * ca.DM(jr.ddq) * cn * a_here + ca.DM(jr.dddq) * cn * cn * cn)
        lo.append(-jr.limit)
        hi.append(jr.limit)
    nlp = {"x": x, "f": ca.sum1(dt), "g": ca.vertcat(*g)}
    a_lo = problem.a_lo if problem.a_lo is not None else np.full(N + 1 + ne, -np.inf)
    a_hi = problem.a_hi if problem.a_hi is not None else np.full(N + 1 + ne, np.inf)
    lbx = np.concatenate((np.zeros(N + 1), a_lo[:N + 1],
                          np.full(N, MIN_INTERVAL_TIME_REL), a_lo[N + 1:]))
    ubx = np.concatenate((problem.c_max, a_hi[:N + 1], np.full(N, np.inf), a_hi[N + 1:]))
    a_start = np.clip(np.concatenate((a0, a0[problem.grid.break_node[1:-1]])), a_lo, a_hi)
    x0 = np.concatenate((np.clip(c0, 0.0, problem.c_max), a_start[:N + 1],
                         np.maximum(dt0, MIN_INTERVAL_TIME_REL), a_start[N + 1:]))
    build = time.perf_counter() - tb
    solve = 0.0
    iters = 0
    # the attempts in turn (MU_STRATEGIES: barrier strategy, iteration cap, graph)
    for k, (strategy, max_iter, expand) in enumerate(MU_STRATEGIES):
        tk = time.perf_counter()
        opts = {"ipopt.print_level": print_level, "print_time": False,
                "ipopt.tol": IPOPT_TOL, "ipopt.constr_viol_tol": IPOPT_TOL,
                "ipopt.max_iter": max_iter, "ipopt.mu_strategy": strategy, "ipopt.sb": "yes",
                "expand": expand}
        solver = ca.nlpsol("jerk", "ipopt", nlp, opts)
        ts = time.perf_counter()
        build += ts - tk
        sol = solver(x0=x0, lbx=lbx, ubx=ubx, lbg=np.concatenate(lo),
                     ubg=np.concatenate(hi))
        solve += time.perf_counter() - ts
        stats = solver.stats()
        xs = np.asarray(sol["x"]).ravel()
        iters += int(stats.get("iter_count", 0))
        status = str(stats.get("return_status", "unknown"))
        ok = ((bool(stats.get("success", False)) or status == "Solved_To_Acceptable_Level")
              and bool(np.all(np.isfinite(xs))))
        if ok:
            break
    a_all = np.concatenate((xs[N + 1:2 * (N + 1)], xs[3 * N + 2:]))
    return NlpResult(success=ok, c=xs[:N + 1], a=xs[N + 1:2 * (N + 1)],
                     a_end=a_all[problem.end_index], dt=xs[2 * (N + 1):3 * N + 2],
                     iterations=iters, message=f"{status} ({strategy} barrier update"
                     f"{', SX graph' if expand else ''})",
                     build_time_s=build, solve_time_s=solve)
