"""The jerk oracle: ``optimal.solve(path, limits, bounds="jerk")``.

One stage per module: :mod:`~optimal.jerk.transcription` (the grid NLP as arrays),
:mod:`~optimal.jerk.backends` (CasADi + IPOPT), :mod:`~optimal.jerk.upper` (warm start,
exact profile, checker, time scaling), :mod:`~optimal.jerk.lower` (the certified lower
bound and its proof), :mod:`~optimal.jerk.oracle` (the refinement loop and the result).
"""

from .lower import rest_to_rest_time
from .oracle import solve_jerk

__all__ = ["rest_to_rest_time", "solve_jerk"]
