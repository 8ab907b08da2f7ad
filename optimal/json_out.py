"""JSON view of an :class:`~optimal.solution.OptimalSolution` (DESIGN section 7, "oracle").

Velocities in mm/s, times in s. Non-finite numbers (an upper bound that does not exist
after a solver error) become ``null``.
"""

from __future__ import annotations

import math

from .solution import OptimalSolution


def _num(x: float) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None


def to_json_dict(solution: OptimalSolution) -> dict:
    """The ``"oracle"`` part of the result JSON plus the oracle's per-block fields.

    Parameters
    ----------
    solution : OptimalSolution
        Result of :func:`optimal.solve`.

    Returns
    -------
    dict
        ``{"oracle": {"lower_bound_s", "upper_bound_s", "status", "solve_time_s",
        "grid_points"}, "blocks": [{"block", "t_oracle_s", "v_exit_oracle",
        "limit_oracle"}, ...]}``; plain Python types only (``json.dumps`` ready).
    """
    return {
        "oracle": {
            "lower_bound_s": _num(solution.lower_bound_s),
            "upper_bound_s": _num(solution.upper_bound_s),
            "status": str(solution.status.value),
            "solve_time_s": float(solution.total_time_s),
            "grid_points": int(solution.grid_points),
        },
        "blocks": [
            {"block": int(b.block), "t_oracle_s": _num(b.t_oracle_s),
             "v_exit_oracle": _num(b.v_exit_oracle), "limit_oracle": str(b.limit_oracle)}
            for b in solution.blocks
        ],
    }
