"""The jerk grid NLP with CasADi + IPOPT (MUMPS), warm started.

The problem (:class:`~optimal.jerk.transcription.JerkProblem`) is built as one SX graph
from vector expressions (no per-node Python loop), so building costs a few ms per
thousand nodes; IPOPT exploits the banded sparsity of the KKT system. Exact Hessians
come from CasADi's automatic differentiation.

Variables ``x = [c (N + 1), a (N + 1), dt (N), e (extra)]``, dimensionless (``e``: the
accelerations on arriving at interior breaks). Minimise ``sum dt``. Two forms of the same
problem, tried in turn (:data:`optimal.jerk.tolerances.MU_STRATEGIES`): first one unit for
all variables (:func:`~optimal.jerk.transcription.problem_units`) and the jerk rows with
``(e - a) / dt``; where that fails, every variable in its own unit
(:func:`variable_scales`) and the jerk rows times ``dt``,
``|dq (e - a) + (3 ddq c a + dddq c^3) dt| <= J dt`` (for ``dt > 0`` the same rows, without
the pole at ``dt = 0``). The second solves programs of several time scales that the
first does not: a 10 mm line at F100 on the default machine (a cruise of 6 s between jerk
ramps of milliseconds, tests/optimal/test_jerk.py) ran out of IPOPT's iterations in every
attempt of the first form, and so did sin_cead_loop.mpf on the LinuxCNC machine; two lines
of 100 m at F10 needed the units as well as the rows times ``dt``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..tolerances import IPOPT_TOL, MIN_INTERVAL_TIME_REL, MU_STRATEGIES
from ..transcription import JerkProblem

NAME = "ipopt"

#: Smallest variable unit, relative to the largest of its kind: a zero speed cap (a stop)
#: or a zero warm start gets this unit, not zero.
SCALE_FLOOR_REL = 1e-6


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
    attempt : int
        Index in :data:`~optimal.jerk.tolerances.MU_STRATEGIES` of the last attempt made
        (the one that solved it where ``success``; -1 where none was made).
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
    attempt: int = -1


def solve_nlp(problem: JerkProblem, c0: np.ndarray, a0: np.ndarray, dt0: np.ndarray,
              *, print_level: int = 0, attempts: tuple[int, ...] | None = None) -> NlpResult:
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
    attempts : tuple of int, optional
        Which of :data:`~optimal.jerk.tolerances.MU_STRATEGIES` to try, in that order
        (default: all of them). A caller that re-solves the same problem with other
        bounds from a nearby start (:mod:`optimal.freq.jerk_adapted`) tries the form
        that solved it last.

    Returns
    -------
    NlpResult
    """
    import casadi as ca

    forms: dict[bool, tuple] = {}       # the NLP of each form, built when first tried
    build = solve = 0.0
    iters = 0
    N = problem.n_intervals
    order = tuple(range(len(MU_STRATEGIES))) if attempts is None else tuple(attempts)
    if not order:
        raise ValueError("solve_nlp: attempts is empty")
    # the attempts in turn (MU_STRATEGIES: barrier strategy, iteration cap, graph, form)
    for attempt in order:
        strategy, max_iter, expand, scaled = MU_STRATEGIES[attempt]
        tk = time.perf_counter()
        if scaled not in forms:
            forms[scaled] = _nlp(ca, problem, c0, a0, dt0, scaled)
        nlp, lbx, ubx, x0, lbg, ubg, scale = forms[scaled]
        opts = {"ipopt.print_level": print_level, "print_time": False,
                "ipopt.tol": IPOPT_TOL, "ipopt.constr_viol_tol": IPOPT_TOL,
                "ipopt.max_iter": max_iter, "ipopt.mu_strategy": strategy, "ipopt.sb": "yes",
                "expand": expand}
        solver = ca.nlpsol("jerk", "ipopt", nlp, opts)
        ts = time.perf_counter()
        build += ts - tk
        sol = solver(x0=x0, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg)
        solve += time.perf_counter() - ts
        stats = solver.stats()
        xs = np.asarray(sol["x"]).ravel() * scale
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
                     f"{', SX graph' if expand else ''}{', scaled' if scaled else ''})",
                     build_time_s=build, solve_time_s=solve, attempt=attempt)


def _nlp(ca, problem: JerkProblem, c0, a0, dt0, scaled: bool):
    """The NLP of ``problem`` as CasADi's dict, its variable bounds and start (in the
    variables' units) and its row bounds, and the units (ones unless ``scaled``).

    ``scaled``: every variable in its own unit (:func:`variable_scales`) and the jerk rows
    times ``dt``, ``|dq (e - a) + (3 ddq c a + dddq c^3) dt| <= J dt`` (for ``dt > 0`` the
    same rows, without the pole at ``dt = 0``); else one unit for all and the rows with
    the jerk ``(e - a) / dt``.
    """
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
    scale = variable_scales(problem, c0, a0, dt0) if scaled else np.ones(nx)
    xu = ca.DM(scale) * x                   # the variables in the problem's units
    c = xu[0:N + 1]
    a = xu[N + 1:2 * (N + 1)]
    dt = xu[2 * (N + 1):3 * N + 2]
    a_all = ca.vertcat(a, xu[3 * N + 2:])
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
        # the row's terms 3 q'' v s'' and q''' v^3 (at the row's place)
        mixed, cubic = 3 * ca.DM(jr.ddq) * cn * a_here, ca.DM(jr.dddq) * cn * cn * cn
        if scaled:
            h = dt[iv]
            jerk_dt = ca.DM(jr.dq) * (e[iv] - a[iv]) + (mixed + cubic) * h
            lim_dt = ca.DM(jr.limit) * h
            g += [jerk_dt - lim_dt, jerk_dt + lim_dt]
            lo += [np.full(jr.n, -np.inf), np.zeros(jr.n)]
            hi += [np.zeros(jr.n), np.full(jr.n, np.inf)]
        else:
            g.append(ca.DM(jr.dq) * ((e[iv] - a[iv]) / dt[iv]) + mixed + cubic)
            lo.append(-jr.limit)
            hi.append(jr.limit)
    ph = problem.phases
    if ph is not None and ph.first.size:
        # the frequency rule on given runs of intervals (PhaseRows), by parts:
        # int (t - t_0) s'' dt = T v_1 - ds and int (t_1 - t) s'' dt = ds - T v_0 (ds the
        # run's length, which the integration rows make exact), so each row is linear in
        # the run's speeds at its ends and bilinear with its duration (a sparse Hessian)
        cum = np.concatenate(([0.0], np.cumsum(problem.ds)))
        for k0, k1, sgn, gp in zip(ph.first.tolist(), ph.stop.tolist(), ph.sign.tolist(),
                                   ph.g.tolist()):
            dur = ca.sum1(dt[k0:k1])
            d_s = float(cum[k1] - cum[k0])
            dv = c[k1] - c[k0]
            g += [sgn * (dur * c[k1] - d_s - gp * dv / 2),
                  sgn * (d_s - dur * c[k0] - gp * dv / 2)]
            lo += [np.zeros(1), np.zeros(1)]
            hi += [np.full(1, np.inf), np.full(1, np.inf)]
    nlp = {"x": x, "f": ca.sum1(dt), "g": ca.vertcat(*g)}
    a_lo = problem.a_lo if problem.a_lo is not None else np.full(N + 1 + ne, -np.inf)
    a_hi = problem.a_hi if problem.a_hi is not None else np.full(N + 1 + ne, np.inf)
    lbx = np.concatenate((np.zeros(N + 1), a_lo[:N + 1],
                          np.full(N, MIN_INTERVAL_TIME_REL), a_lo[N + 1:]))
    ubx = np.concatenate((problem.c_max, a_hi[:N + 1], np.full(N, np.inf), a_hi[N + 1:]))
    a_start = np.clip(np.concatenate((a0, a0[problem.grid.break_node[1:-1]])), a_lo, a_hi)
    x0 = np.concatenate((np.clip(c0, 0.0, problem.c_max), a_start[:N + 1],
                         np.maximum(dt0, MIN_INTERVAL_TIME_REL), a_start[N + 1:]))
    return (nlp, lbx / scale, ubx / scale, x0 / scale, np.concatenate(lo),
            np.concatenate(hi), scale)


def variable_scales(problem: JerkProblem, c0: np.ndarray, a0: np.ndarray,
                    dt0: np.ndarray) -> np.ndarray:
    """Unit of every NLP variable, in the problem's units.

    One time and one length unit (:func:`~optimal.jerk.transcription.problem_units`) do
    not make a program of several scales near 1: a line at F10 mm/min beside a rapid
    move has intervals of 1e-4 and 1e2 of the unit, and IPOPT ran out of iterations on
    it. Each variable is therefore measured in its own unit: an interval's duration in
    that of its warm start, a node's speed in its cap (the warm start's speed where the
    cap is infinite), and an acceleration in what that speed gains over the shorter
    neighbouring interval (the scale a ramp there has). A unit only rescales a variable:
    the problem and its solution are the same.

    Returns
    -------
    numpy.ndarray, shape (2 (N + 1) + N + n_extra,)
        In the order of ``x``.
    """
    d = np.maximum(np.asarray(dt0, np.float64), MIN_INTERVAL_TIME_REL)
    cap = np.asarray(problem.c_max, np.float64)
    c = np.where(np.isfinite(cap) & (cap > 0), cap, np.abs(c0))
    c = np.maximum(c, SCALE_FLOOR_REL * max(float(np.max(c)), 1.0))
    shorter = np.minimum(np.concatenate(([d[0]], d)), np.concatenate((d, [d[-1]])))
    acc = np.maximum(c / shorter, np.abs(a0))
    acc = np.maximum(acc, SCALE_FLOOR_REL * float(np.max(acc)))
    # the arriving accelerations at interior breaks: the break node's unit
    return np.concatenate((c, acc, d, acc[problem.grid.break_node[1:-1]]))
