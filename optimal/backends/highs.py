"""LP cross-check: ``max sum_k w_k b_k`` over the lattice-form constraints, with HiGHS.

By the lattice property (:mod:`optimal.problem`) the feasible set has a greatest element,
and for any positive weights the LP optimum is that element, which is also the
time-optimal ``b`` (Consolini et al.). The LP is scaled: ``b`` in units of the largest
cap, each row divided by its largest coefficient. Solved by scipy's HiGHS interface
(dual simplex) with tight feasibility tolerances (:data:`BACKEND_TOL`).

Options: ``time_limit`` (float, s), ``method`` (``"highs-ds"`` default, ``"highs-ipm"``,
``"highs"``).
"""

from __future__ import annotations

import importlib.util
import time
from typing import Mapping

import numpy as np

from reference.core.errors import SolverError

from ..problem import DiscreteProblem, DiscreteResult, interval_times
from ..status import SolveStatus
from ._common import check_options, sparse_rows
from .tolerances import BACKEND_TOL

NAME = "highs"
INSTALL = "pip install scipy  (HiGHS ships with scipy >= 1.6)"
OPTIONS: dict[str, type] = {"time_limit": float, "method": str}


def is_available() -> bool:
    """True when scipy with HiGHS is importable."""
    return importlib.util.find_spec("scipy") is not None


def solve_discrete(problem: DiscreteProblem,
                   options: Mapping[str, object] | None = None) -> DiscreteResult:
    """Solve the LP ``max sum b`` (see the module docstring).

    Returns
    -------
    DiscreteResult
        Status mapped from HiGHS: success -> ``optimal``, infeasible -> ``infeasible``,
        anything else -> ``solver_error``.
    """
    opts = check_options(NAME, options, OPTIONS)
    try:
        from scipy.optimize import linprog
        from scipy.sparse import csr_matrix
    except ImportError as exc:  # pragma: no cover - guarded by is_available
        raise SolverError(f"backend 'highs' could not import scipy: {exc}") from exc
    t0 = time.perf_counter()
    N1 = problem.n_intervals + 1
    scale = float(np.max(problem.cap)) or 1.0
    rows, cols, vals, rhs = sparse_rows(problem)
    A = csr_matrix((vals * scale, (rows, cols)), shape=(rhs.size, N1))
    # weights: the node's share of path length (any positive weights give the optimum)
    ds = problem.ds
    w = np.zeros(N1)
    w[:-1] += ds
    w[1:] += ds
    w /= w.max()
    bounds = np.column_stack((np.zeros(N1), problem.cap / scale))
    tol = BACKEND_TOL[NAME]
    lp_opts = {"primal_feasibility_tolerance": tol, "dual_feasibility_tolerance": tol,
               "presolve": True}
    if "time_limit" in opts:
        lp_opts["time_limit"] = float(opts["time_limit"])
    t1 = time.perf_counter()
    try:
        res = linprog(-w, A_ub=A if rhs.size else None, b_ub=rhs if rhs.size else None,
                      bounds=bounds, method=str(opts.get("method", "highs-ds")),
                      options=lp_opts)
    except Exception as exc:  # native failure -> our error
        raise SolverError(f"HiGHS failed: {exc}") from exc
    t2 = time.perf_counter()
    if res.status == 0 and res.x is not None:
        b = np.clip(res.x, 0.0, None) * scale
        b = np.minimum(b, problem.cap)
        dt = interval_times(problem.s, b, problem.gamma)
        T = float(dt.sum())
        st = SolveStatus.OPTIMAL if np.isfinite(T) else SolveStatus.INFEASIBLE
        return DiscreteResult(st, b, T, NAME, t1 - t0, t2 - t1, int(res.nit), res.message)
    st = SolveStatus.INFEASIBLE if res.status == 2 else SolveStatus.SOLVER_ERROR
    return DiscreteResult(st, None, float("inf"), NAME, t1 - t0, t2 - t1, int(res.nit or 0),
                          f"HiGHS status {res.status}: {res.message}")
