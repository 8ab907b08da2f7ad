"""SOCP: ``min T`` in the Lipp-Boyd cone form, modelled with cvxpy, solved by Clarabel.

Variables (scaled): ``x = b / (L a_ref)``, ``c`` with ``c_k^2 <= x_k`` and ``d`` with
``d_k (c_k + c_{k+1}) >= 1``; objective ``sum_k 2 (ds_k / L) d_k`` in units of
``sqrt(L / a_ref)`` (length unit = path length ``L``, time unit ``sqrt(L / a_ref)``,
``a_ref`` the largest axis acceleration; formulation note section 0, pitfall 3). Both
cone families are written as vectorised second-order cones:

* ``||(2 c_k, x_k - 1)|| <= x_k + 1``  (``c_k^2 <= x_k``),
* ``||(2, d_k - c_k - c_{k+1})|| <= d_k + c_k + c_{k+1}``  (``d_k (c_k + c_{k+1}) >= 1``).

At the optimum ``c = sqrt(x)`` and ``d = 1 / (c_k + c_{k+1})``, so the objective is the
exact time ``sum 2 ds / (sqrt(b_k) + sqrt(b_{k+1}))``. The reported time is recomputed from
``b`` with that formula.

Options: ``max_iter`` (int), ``verbose`` (bool).
"""

from __future__ import annotations

import importlib.util
import time
import warnings
from typing import Mapping

import numpy as np

from reference.core.errors import SolverError

from ..problem import DiscreteProblem, DiscreteResult, interval_times
from ..status import SolveStatus
from ._common import check_options, sparse_rows
from .tolerances import BACKEND_TOL

NAME = "clarabel"
INSTALL = "pip install cvxpy clarabel"
OPTIONS: dict[str, type] = {"max_iter": int, "verbose": bool}


def is_available() -> bool:
    """True when cvxpy and clarabel are importable."""
    return (importlib.util.find_spec("cvxpy") is not None
            and importlib.util.find_spec("clarabel") is not None)


def solve_discrete(problem: DiscreteProblem,
                   options: Mapping[str, object] | None = None) -> DiscreteResult:
    """Solve the scaled SOCP (see the module docstring).

    Returns
    -------
    DiscreteResult
        Status mapped from cvxpy/Clarabel: ``optimal``, ``optimal_inaccurate``,
        ``infeasible``, else ``solver_error``.
    """
    opts = check_options(NAME, options, OPTIONS)
    try:
        import cvxpy as cp
        import scipy.sparse as sp
    except ImportError as exc:  # pragma: no cover - guarded by is_available
        raise SolverError(f"backend 'clarabel' could not import cvxpy: {exc}") from exc
    t0 = time.perf_counter()
    N = problem.n_intervals
    L = float(problem.s[-1] - problem.s[0])
    a_ref = float(problem.accel_scale)
    b_unit = L * a_ref
    x = cp.Variable(N + 1)
    c = cp.Variable(N + 1)
    d = cp.Variable(N)
    cons = [x >= 0, x <= problem.cap / b_unit, c >= 0]
    rows, cols, vals, rhs = sparse_rows(problem)
    if rhs.size:
        A = sp.csr_matrix((vals * b_unit, (rows, cols)), shape=(rhs.size, N + 1))
        # rows were normalised by their largest coefficient; renormalise after scaling
        rn = np.asarray(abs(A).max(axis=1).todense()).ravel()
        rn[rn == 0] = 1.0
        A = sp.diags(1.0 / rn) @ A
        cons.append(A @ x <= rhs / rn)
    cons.append(cp.SOC(x + 1, cp.vstack([2 * c, x - 1]), axis=0))
    csum = c[:-1] + c[1:]
    cons.append(cp.SOC(d + csum, cp.vstack([2 * np.ones(N), d - csum]), axis=0))
    w = 2.0 * problem.ds / L
    prob = cp.Problem(cp.Minimize(w @ d), cons)
    tol = BACKEND_TOL[NAME]
    kw = dict(tol_gap_abs=tol, tol_gap_rel=tol, tol_feas=tol, tol_ktratio=1e-8,
              max_iter=int(opts.get("max_iter", 200)))
    t1 = time.perf_counter()
    try:
        with warnings.catch_warnings():
            # "Solution may be inaccurate": reported as status optimal_inaccurate instead
            warnings.simplefilter("ignore", UserWarning)
            prob.solve(solver=cp.CLARABEL, verbose=bool(opts.get("verbose", False)), **kw)
    except cp.error.SolverError as exc:
        return DiscreteResult(SolveStatus.SOLVER_ERROR, None, float("inf"), NAME, t1 - t0,
                              time.perf_counter() - t1, 0, f"Clarabel failed: {exc}")
    except Exception as exc:
        raise SolverError(f"cvxpy/Clarabel failed: {exc}") from exc
    t2 = time.perf_counter()
    stats = prob.solver_stats
    setup = float(getattr(stats, "setup_time", 0.0) or 0.0)
    solve_t = float(getattr(stats, "solve_time", 0.0) or 0.0) or (t2 - t1)
    build = (t1 - t0) + max(0.0, (t2 - t1) - solve_t - setup) + setup
    iters = int(getattr(stats, "num_iters", 0) or 0)
    status = {cp.OPTIMAL: SolveStatus.OPTIMAL,
              cp.OPTIMAL_INACCURATE: SolveStatus.OPTIMAL_INACCURATE,
              cp.INFEASIBLE: SolveStatus.INFEASIBLE,
              cp.INFEASIBLE_INACCURATE: SolveStatus.INFEASIBLE}.get(prob.status,
                                                                    SolveStatus.SOLVER_ERROR)
    if x.value is None or status not in (SolveStatus.OPTIMAL, SolveStatus.OPTIMAL_INACCURATE):
        return DiscreteResult(status, None, float("inf"), NAME, build, solve_t, iters,
                              f"cvxpy status {prob.status}")
    b = np.minimum(np.clip(np.asarray(x.value), 0.0, None) * b_unit, problem.cap)
    T = float(interval_times(problem.s, b, problem.gamma).sum())
    return DiscreteResult(status, b, T, NAME, build, solve_t, iters,
                          f"cvxpy status {prob.status}")
