"""Compiled kernel of the exact sweep (numba): one pass backward, one forward.

The same algorithm as :mod:`optimal.backends.fast` (its module docstring has the
argument), written as the plain loops it is: for a problem in lattice form every row of
interval ``k`` is a *forward* piece (``c2 > 0 >= c1``: ``b_{k+1} <= (h - c1 b_k) / c2``)
or a *backward* piece (``c1 > 0 >= c2``: ``b_k <= (h - c2 b_{k+1}) / c1``), and

1. static consistency: ``X_k = min`` over pairs of a forward piece ``i`` and a backward
   piece ``l`` with ``d_l p_i < 1`` of ``(g_l + d_l r_i) / (1 - d_l p_i)``
   (``p_i = -c1_i / c2_i``, ``r_i = h_i / c2_i``, ``d_l = -c2_l / c1_l``,
   ``g_l = h_l / c1_l``);
2. backward: ``u_N = cap_N``, ``u_k = min(cap_k, X_k, min_l (h_l - c2_l u_{k+1}) / c1_l)``;
3. forward: ``b_0 = u_0``, ``b_{k+1} = min(u_{k+1}, min_i (h_i - c1_i b_k) / c2_i)``.

Why compiled: the profile of the oracle on arc-dense paths (``tests/bench/bench_arcs.py
--profile``) had the numpy sweep at 30 % of the run (263 of 876 ms on 200 S-bends),
most of it building and pruning pieces and the pairs of step 1, which are ``O(R^2)``
small array operations per round; the loops here do the same arithmetic once per row.
The cost is ``O(N R^2)`` flops with no temporaries. Compiled once per installation
(``cache=True`` keeps the machine code beside the module).

Units as :mod:`optimal.problem` (``b`` in mm^2/s^2). Shapes: ``N`` intervals, ``R`` rows.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def greatest_element(cap: np.ndarray, c1: np.ndarray, c2: np.ndarray,
                     h: np.ndarray) -> np.ndarray:  # pragma: no cover - compiled
    """Greatest ``b`` with ``0 <= b <= cap`` and every row ``c1 b_k + c2 b_{k+1} <= h``.

    Parameters
    ----------
    cap : numpy.ndarray, shape (N + 1,)
        Node caps, finite, >= 0.
    c1, c2, h : numpy.ndarray, shape (N, R)
        Rows in lattice form (``c1 * c2 <= 0``, ``h >= 0``; a row with both
        coefficients <= 0 never binds).

    Returns
    -------
    numpy.ndarray, shape (N + 1,)
    """
    N, R = c1.shape
    u = np.empty(N + 1)
    u[N] = cap[N]
    for k in range(N - 1, -1, -1):
        v = cap[k]
        un = u[k + 1]
        for l in range(R):
            a1 = c1[k, l]
            a2 = c2[k, l]
            if a1 > 0.0 and a2 <= 0.0:
                t = (h[k, l] - a2 * un) / a1
                if t < v:
                    v = t
                # static consistency with every forward piece of the interval
                d = -a2 / a1
                g = h[k, l] / a1
                for i in range(R):
                    f1 = c1[k, i]
                    f2 = c2[k, i]
                    if f2 > 0.0 and f1 <= 0.0:
                        p = -f1 / f2
                        den = 1.0 - d * p
                        if den > 0.0:
                            t = (g + d * (h[k, i] / f2)) / den
                            if t < v:
                                v = t
        u[k] = v if v > 0.0 else 0.0
    b = np.empty(N + 1)
    x = u[0]
    b[0] = x
    for k in range(N):
        v = u[k + 1]
        for i in range(R):
            f1 = c1[k, i]
            f2 = c2[k, i]
            if f2 > 0.0 and f1 <= 0.0:
                t = (h[k, i] - f1 * x) / f2
                if t < v:
                    v = t
        x = v if v > 0.0 else 0.0
        b[k + 1] = x
    return b
