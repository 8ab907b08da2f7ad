"""The jerk relaxation's conic solve (:mod:`optimal.jerk.relaxation`) with Clarabel.

The relaxation is built as Clarabel's standard form ``min q x`` s.t. ``A x + s = b``,
``s`` in a product of a zero cone (equalities), a nonnegative cone (inequalities) and
three-dimensional second-order cones; this module is the only place that imports the
solver package (the project's rule: solvers live in ``backends``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp


@dataclass(frozen=True, slots=True, eq=False)
class ConicResult:
    """Clarabel's answer.

    Attributes
    ----------
    status : str
        Clarabel's status (``"Solved"``, ``"AlmostSolved"``, ``"NumericalError"``...).
    x : numpy.ndarray, shape (n_var,)
        Primal point (scaled units of the caller).
    primal_objective, dual_objective : float
        Clarabel's primal and dual objective values.
    iterations : int
        Interior-point iterations.
    """

    status: str
    x: np.ndarray
    primal_objective: float
    dual_objective: float
    iterations: int


def solve_conic(A: sp.csc_matrix, b: np.ndarray, q: np.ndarray, n_eq: int, n_lin: int,
                n_soc3: int, tol: float, max_iter: int) -> ConicResult:
    """Solve ``min q x`` s.t. ``A x + s = b``, ``s`` in ``{0}^n_eq x R+^n_lin x
    (SOC_3)^n_soc3`` (rows in that order).

    Parameters
    ----------
    A : scipy.sparse.csc_matrix, shape (n_eq + n_lin + 3 n_soc3, n_var)
    b : numpy.ndarray, shape (n_eq + n_lin + 3 n_soc3,)
    q : numpy.ndarray, shape (n_var,)
    n_eq, n_lin, n_soc3 : int
        Sizes of the cones.
    tol : float
        Clarabel's absolute and relative gap and feasibility tolerance.
    max_iter : int
        Iteration cap.

    Returns
    -------
    ConicResult
    """
    import clarabel

    cones = []
    if n_eq:
        cones.append(clarabel.ZeroConeT(n_eq))
    cones.append(clarabel.NonnegativeConeT(n_lin))
    cones.extend([clarabel.SecondOrderConeT(3)] * n_soc3)
    st = clarabel.DefaultSettings()
    st.verbose = False
    st.tol_gap_abs = st.tol_gap_rel = st.tol_feas = tol
    st.max_iter = max_iter
    P = sp.csc_matrix((q.size, q.size))
    sol = clarabel.DefaultSolver(P, q, A, b, cones, st).solve()
    return ConicResult(str(sol.status), np.asarray(sol.x, dtype=np.float64),
                       float(sol.obj_val), float(sol.obj_val_dual), int(sol.iterations))
