"""JSON view of an :class:`~optimal.solution.OptimalSolution` (DESIGN section 7, "oracle").

Velocities in mm/s, times in s. Non-finite numbers (an upper bound that does not exist
after a solver error is ``inf``) stay as they are: the one JSON writer,
:func:`reference.core.jsonio.write_json`, encodes them for every part alike.
"""

from __future__ import annotations

from .solution import OptimalSolution


def _num(x: float) -> float:
    return float(x)


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
            {"block": int(b.block), "t_oracle_s": _num(b.time_s),
             "v_exit_oracle": _num(b.v_exit), "limit_oracle": str(b.cause)}
            for b in solution.blocks
        ],
    }
