"""The two planners as the CLI runs them: the heuristic and the oracle, on one path.

The only module of ``compare`` that calls into ``reference.planner`` and ``optimal``
(the comparison itself reads their results through :mod:`compare.comparison`).
"""

from __future__ import annotations

from typing import Callable

from reference.core.errors import FeedOracleError, InternalError, ProfileError
from reference.core.geometry import Path
from reference.core.limits import MachineLimits
from reference.machine import Machine
from reference.nc.program import Program

ProgressFn = Callable[[str, float], None]


def prefixed(progress: ProgressFn | None, prefix: str) -> ProgressFn | None:
    """A progress callback that prefixes messages (``None``-safe).

    Parameters
    ----------
    progress : callable or None
        ``progress(message, fraction)``.
    prefix : str
        Put before every message (``"oracle: "``).

    Returns
    -------
    callable or None
        ``None`` when ``progress`` is ``None``.
    """
    if progress is None:
        return None
    return lambda message, fraction=-1.0: progress(f"{prefix}{message}", fraction)


#: Bound sets the ``--bounds`` option names (``auto`` picks one, see :func:`resolve_bounds`).
BOUND_CHOICES = ("auto", "acc", "jerk", "acc+freq", "jerk+freq")


#: Bound sets ``--bounds auto`` may pick: the planner's own (``acc`` for BRISK, ``jerk``
#: for SOFT, each ``+freq`` where the dynamic response adaptation is active and the plan
#: meets the frequency rule), so the gap compares like with like and both of its ends
#: mean something.
AUTO_BOUND_SETS = ("acc", "jerk", "acc+freq", "jerk+freq")


class BoundsNotAvailable(FeedOracleError, ValueError):
    """A bound set the oracle cannot solve yet (exit 2)."""


def oracle_bound_sets() -> tuple[str, ...]:
    """Bound sets the installed oracle solves."""
    from optimal import SUPPORTED_BOUNDS
    return tuple(SUPPORTED_BOUNDS)


def resolve_bounds(requested: str, planner_bounds: str | None) -> tuple[str, tuple[str, ...]]:
    """The oracle bound set for ``--bounds``, and notes for the report.

    ``auto`` asks for the planner's own bound set (``jerk`` for a SOFT heuristic) and
    falls back to ``acc`` while the oracle cannot solve it, with a note saying what that
    means for the gap interval. An explicit unavailable set is an input error.

    Raises
    ------
    BoundsNotAvailable
        ``jerk`` or ``jerk+freq`` requested explicitly but not available.
    """
    available = oracle_bound_sets()
    if requested != "auto":
        if requested not in available:
            raise BoundsNotAvailable(f"bound set {requested!r} is not available yet; "
                                     f"use --bounds {' or '.join(available)}")
        return requested, ()
    want = planner_bounds or "acc"
    if want in available and want in AUTO_BOUND_SETS:
        return want, ()
    if want in available:
        return "acc", (f"--bounds auto: the heuristic keeps the {want!r} bound set (SOFT); "
                       f"the oracle's {want!r} bounds are not yet certified to the gap "
                       f"tolerance on every program, so auto solved 'acc' "
                       f"(use --bounds {want} for them).",)
    return "acc", (f"--bounds auto: the heuristic keeps the {want!r} bound set (SOFT); "
                   f"the oracle cannot solve that yet and solved 'acc' instead.",)


def run_heuristic(program: Program, machine: Machine, progress: ProgressFn | None = None,
                  *, path: Path | None = None):
    """``reference.planner.plan`` (the SINUMERIK-style heuristic) on ``path``, the
    program's :func:`reference.build_path` (built by the planner when ``None``)."""
    from reference.planner import plan
    try:
        return plan(program, machine, path=path, progress=progress)
    except ProfileError as exc:
        # the planner's profile comes from the validated program and path: one that is
        # no motion is its own bug (exit 3), as in run_oracle
        raise InternalError(f"the heuristic built an invalid motion: {exc}") from exc


def run_oracle(path: Path, limits: MachineLimits, bounds: str,
               progress: ProgressFn | None = None, *, tol: float | None = None,
               holds=None, max_grid: int | None = None):
    """``optimal.solve`` on ``path`` under ``bounds`` with the imposed ``holds``
    (``reference.holds.imposed_holds``, the heuristic's ``plan.holds``); ``tol``: the
    requested relative gap between its bounds (``None`` for the oracle's default);
    ``max_grid``: its interval budget (``None`` for the oracle's default; the pipeline
    derives it from ``--max-grid-points``)."""
    import optimal
    options = {} if tol is None else {"tol": tol}
    if max_grid is not None:
        options["max_grid"] = max(int(max_grid), 2)
    try:
        return optimal.solve(path, limits, bounds=bounds, progress=progress, holds=holds,
                             **options)
    except ProfileError as exc:
        # the oracle builds every profile it judges from the validated path and limits:
        # one that is no motion is its own bug (exit 3), not bad input (exit 2)
        raise InternalError(f"the {bounds} oracle built an invalid motion: {exc}") from exc


def oracle_json(solution) -> dict:
    """``optimal.to_json_dict``: the ``"oracle"`` part and the oracle's block fields."""
    import optimal
    return optimal.to_json_dict(solution)
