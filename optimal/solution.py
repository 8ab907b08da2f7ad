"""Result types of :func:`optimal.solve`: the solution, its per-block rows and the
refinement history.

Kept apart from the algorithm (:mod:`optimal.oracle`) so that readers of a result (the
JSON writer, :mod:`compare`) need not read the solver. Units: mm, s.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from reference.core.constraints import ConstraintReport
from reference.core.holds import NO_HOLDS, Holds
from reference.core.profile import Profile
from reference.core.rows import BlockRow

from .status import SolveStatus

__all__ = ["IterationRecord", "OptimalSolution"]


@dataclass(frozen=True, slots=True)
class IterationRecord:
    """One refinement round: grid size and the bounds found on it (s).

    ``upper_bound_s`` is ``inf`` in rounds where the checker was not run (the grid
    optimum was still farther than the requested gap from the lower bound).
    """

    grid_points: int
    lower_bound_s: float
    upper_bound_s: float
    objective_s: float
    time_scale: float


@dataclass(frozen=True, slots=True, eq=False)
class OptimalSolution:
    """Result of :func:`solve`; ``status`` is never ``None``.

    Attributes
    ----------
    status : SolveStatus
        ``optimal`` (gap met), ``gap_not_met``, ``infeasible`` or ``solver_error``.
    profile : Profile or None
        The verified profile whose duration is ``upper_bound_s`` (``None`` only on
        ``solver_error``).
    lower_bound_s, upper_bound_s : float
        Certified lower bound and verified upper bound of the minimum time, s (the
        imposed holds, dwell and exact-stop settle, included in both: they are the same
        constant in every feasible motion).
    objective_s : float
        Time of the grid optimum before time scaling, s.
    gap : float
        ``(upper - lower) / lower`` (0 for an empty path).
    time_scale : float
        Factor ``lam >= 1`` the grid profile was slowed down by to pass the checker.
    segment_times_s : numpy.ndarray, shape (m,)
        Time spent moving through each segment, s.
    block_times_s : numpy.ndarray, shape (max block index + 1,)
        Time spent in each NC block (by block index), s.
    blocks : tuple[BlockRow, ...]
        One row per block of ``path.blocks``.
    grid : numpy.ndarray, shape (N + 1,)
        Final grid nodes, mm.
    active : tuple[str, ...]
        Active constraint on each final grid interval (labels as in
        :class:`~reference.core.rows.BlockRow` ``cause``).
    grid_points : int
        ``N + 1``.
    iterations : int
        Refinement rounds.
    backend : str
        Backend of the grid problem.
    build_time_s, solve_time_s, check_time_s, bound_time_s, total_time_s : float
        Problem construction, discrete solves, checker, lower-bound relaxation, and the
        whole call, s (sums over rounds).
    dwell_s : float
        Total dwell (G4) time of the program, s (part of ``holds``).
    report : ConstraintReport or None
        The checker's report on the final grid profile before time scaling.
    history : tuple[IterationRecord, ...]
        Bounds per round.
    message : str
        Human-readable summary.
    holds : Holds
        The imposed holds in ``profile`` and in both bounds (as given to :func:`solve`).
    bounds : str
        The bound set solved (``"acc"`` or ``"jerk"``, :data:`BOUND_SETS` keys).
    segment_lower_bounds_s : numpy.ndarray, shape (m,), optional
        Certified per-segment lower bounds, s: every motion of the bound set spends at
        least this long moving through each segment (holds excluded), so their sums
        over any set of segments bound that part of the program. ``None`` when the
        method gives none (``acc``: its bound is global).
    """

    status: SolveStatus
    profile: Profile | None
    lower_bound_s: float
    upper_bound_s: float
    objective_s: float
    gap: float
    time_scale: float
    segment_times_s: np.ndarray
    block_times_s: np.ndarray
    blocks: tuple[BlockRow, ...]
    grid: np.ndarray
    active: tuple[str, ...]
    grid_points: int
    iterations: int
    backend: str
    build_time_s: float
    solve_time_s: float
    check_time_s: float
    bound_time_s: float
    total_time_s: float
    dwell_s: float
    report: ConstraintReport | None = None
    history: tuple[IterationRecord, ...] = field(default=())
    message: str = ""
    holds: Holds = NO_HOLDS
    bounds: str = "acc"
    segment_lower_bounds_s: np.ndarray | None = None

    @property
    def hold_s(self) -> float:
        """Total imposed hold time (dwell and exact-stop settle), s."""
        return self.holds.total_s
