"""The oracle: time-optimal path-velocity profiles with certified bounds.

``solve(path, limits, bounds="acc")`` (or ``bounds="jerk"``, :mod:`optimal.jerk`)
returns an :class:`OptimalSolution` with the
verified profile, ``lower_bound_s`` (a relaxation, :mod:`optimal.bounds`) and
``upper_bound_s`` (a profile ``check_profile`` accepts), times per segment and per NC
block, and the active constraint along the path. ``to_json_dict`` gives the JSON part.

Layers (G2): grid (:mod:`optimal.grid`) -> discrete problem (:mod:`optimal.problem`,
numpy only) -> backend (:mod:`optimal.backends`, one file per solver).
Import rule: this package imports ``reference.core`` only; solver packages only inside
``optimal/backends/`` and ``optimal/jerk/backends/``.
"""

from .backends import available_backends, known_backends, solve_discrete
from .grid import Grid, initial_grid
from .json_out import to_json_dict
from .problem import DiscreteProblem, DiscreteResult, build_grid_problem
from .oracle import SUPPORTED_BOUNDS, solve
from .solution import IterationRecord, OptimalSolution
from .status import SolveStatus

__all__ = ["SUPPORTED_BOUNDS", "DiscreteProblem", "DiscreteResult", "Grid",
           "IterationRecord", "OptimalSolution", "SolveStatus", "available_backends",
           "build_grid_problem", "initial_grid", "known_backends", "solve", "solve_discrete",
           "to_json_dict"]
