"""Solver tolerances per backend, one dict (G7).

``BACKEND_TOL[name]`` is the relative accuracy the backend is asked for (and that its
result is trusted to) on the scaled problem. The agreement demanded between backends on
the same discrete problem is ``reference.core.tolerances.DISCRETE_AGREEMENT_RTOL``
(1e-5), comfortably above all of these.
"""

from __future__ import annotations

BACKEND_TOL: dict[str, float] = {
    # exact sweep: only float64 round-off of the recurrences
    "fast": 1e-12,
    # HiGHS simplex primal/dual feasibility on the scaled LP (b in units of max cap)
    "highs": 1e-10,
    # Clarabel interior point: gap and feasibility tolerances on the scaled SOCP
    "clarabel": 1e-9,
}
