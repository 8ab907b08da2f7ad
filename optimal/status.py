"""Status values of oracle results (strings, so they serialise to JSON unchanged)."""

from __future__ import annotations

from enum import Enum


class SolveStatus(str, Enum):
    """Outcome of a discrete solve or of the whole refinement.

    ``OPTIMAL``
        Discrete solve: the global optimum of the discrete problem. Refinement: the
        requested gap ``(upper - lower) / lower`` was met.
    ``OPTIMAL_INACCURATE``
        Discrete solve only: the backend stopped at reduced accuracy (Clarabel's
        ``optimal_inaccurate``); the values are usable but not to full precision.
    ``GAP_NOT_MET``
        Refinement stopped at the grid-size or iteration limit before the gap was met;
        both bounds are still valid.
    ``INFEASIBLE``
        No motion exists (for example a block with zero feed).
    ``SOLVER_ERROR``
        A backend failed for reasons that are not a property of the problem.
    """

    OPTIMAL = "optimal"
    OPTIMAL_INACCURATE = "optimal_inaccurate"
    GAP_NOT_MET = "gap_not_met"
    INFEASIBLE = "infeasible"
    SOLVER_ERROR = "solver_error"

    def __str__(self) -> str:  # "optimal", not "SolveStatus.OPTIMAL"
        return self.value
