"""The work behind ``feedoracle plan``, ``optimize``, ``compare`` and ``check`` as plain
functions: a program and a machine in, typed results out.

Nothing here parses arguments, prints, writes files or picks an exit code; that is the
CLI's part (:mod:`compare.commands`). A program is given as a parsed
:class:`~reference.nc.program.Program` (from :func:`reference.parse_text` for program
text) or as a file path; a machine as a :class:`~reference.machine.Machine`, a
``machine.toml`` path, a bundled machine's name, or ``None`` for the default machine.

Every function that runs the oracle takes its path from :func:`reference.build_path`,
the one function the heuristic uses too, so both sides run on the same path::

    program + machine --build_path--> path --plan(path=path)--> heuristic plan
                                          \\--optimal.solve-----> oracle solution
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any, Callable, Union

import numpy as np

from reference.core.budget import DEFAULT_MAX_GRID_POINTS, grid_points, ipo_points
from reference.core.errors import BudgetError, PathError
from reference.core.geometry import Path
from reference.core.limits import MachineLimits
from reference.machine import Machine, load_machine
from reference.nc import parse_file
from reference.nc.program import Program, ProgramWarning
from reference.holds import imposed_holds
from reference.prepare import build_path, prepare, unmodelled_features
from reference.tools import load_linuxcnc_tool_table

from . import engines
from .comparison import Comparison, compare
from .recorded import CheckResult, check_recorded

if TYPE_CHECKING:  # annotations only: importing these costs the planner and the oracle
    from optimal import OptimalSolution
    from reference.planner import ReferencePlan

#: A program: parsed, or the path of an NC file (dialect from its extension).
ProgramLike = Union[Program, str, "os.PathLike[str]"]
#: A machine: loaded, a ``machine.toml`` path or bundled name, or ``None`` (the default).
MachineLike = Union[Machine, str, "os.PathLike[str]", None]
#: ``progress(message, fraction)``, fraction in [0, 1] or -1 when unknown.
ProgressFn = Callable[[str, float], None]


@dataclass(frozen=True, slots=True, eq=False)
class Inputs:
    """A parsed program and loaded machine data.

    Attributes
    ----------
    program : Program
    machine : Machine
    """

    program: Program
    machine: Machine

    @property
    def warnings(self) -> tuple[ProgramWarning, ...]:
        """The parser's warnings and the features the path does not apply (TRC, TANG)."""
        return tuple(self.program.warnings) + unmodelled_features(self.program)


def load_inputs(program: ProgramLike, machine: MachineLike = None, *,
                dialect: str | None = None,
                tool_table: Union[str, "os.PathLike[str]", None] = None,
                tool_table_units: str = "mm") -> Inputs:
    """Parse a program and load machine data; objects pass through unchanged.

    Parameters
    ----------
    program : Program or path
        A parsed program, or an NC file (dialect from the extension unless ``dialect``).
    machine : Machine, path, str or None
        Machine data, a ``machine.toml`` file or bundled name; ``None``: the default.
    dialect : {"sinumerik", "ngc"}, optional
        Dialect of a program file.
    tool_table : path, optional
        A LinuxCNC tool table file (:func:`reference.tools.load_linuxcnc_tool_table`);
        its radii are added to the machine's tool table (``[tools]``), winning where
        both name a tool.
    tool_table_units : {"mm", "inch"}
        Units of that file.

    Returns
    -------
    Inputs

    Raises
    ------
    FeedOracleError
        Bad machine data (checked first) or a bad program, naming key or file and line.
    OSError
        The program file cannot be read.
    """
    m = machine if isinstance(machine, Machine) else load_machine(machine)
    if tool_table is not None:
        m = replace(m, tools=m.tools.merged(load_linuxcnc_tool_table(tool_table,
                                                                     tool_table_units)))
    p = program if isinstance(program, Program) else parse_file(program, dialect=dialect)
    return Inputs(program=p, machine=m)


# --------------------------------------------------------------------- plan
def plan_program(program: ProgramLike, machine: MachineLike = None, *,
                 dialect: str | None = None, progress: ProgressFn | None = None,
                 max_grid_points: float = DEFAULT_MAX_GRID_POINTS) -> "ReferencePlan":
    """The heuristic alone (``feedoracle plan``).

    Parameters
    ----------
    program, machine, dialect
        See :func:`load_inputs`.
    progress : callable, optional
        ``progress(message, fraction)``.
    max_grid_points : float
        Size budget, see :func:`require_budget`.

    Returns
    -------
    reference.planner.ReferencePlan
        Profile, per-block rows (``to_json_dict`` gives the JSON), the own check.
    """
    inp = load_inputs(program, machine, dialect=dialect)
    path = build_path(inp.program, inp.machine)
    require_motion(inp.program, path)
    require_budget(inp.program, path, max_grid_points)
    return engines.run_heuristic(inp.program, inp.machine, path=path, progress=progress)


def require_motion(program: Program, path: Path) -> None:
    """A program whose path has no segment is rejected (exit 2) before any result.

    An empty file, comments only or settings only (``G90`` alone) move nothing: the time
    is 0 s for every planner and the gap ``t_ref/LB - 1`` is 0/0. A CI gate that passed it
    with "0 s, ok" would hide the usual cause, a wrong or truncated file; so it is bad
    input, naming the file, like any other program nothing can be said about. (The
    library's :func:`optimal.solve` and :func:`reference.planner.plan` still answer such a
    path with zero times.)

    Raises
    ------
    PathError
        The path has no segment.
    """
    if path.n_segments == 0:
        n = len(program.blocks)
        raise PathError(f"{program.file}: the program has no motion ({n} block"
                        f"{'' if n == 1 else 's'}, none moves an axis): nothing to plan, "
                        "optimize or compare")


#: Checker points one interval of the oracle's grid costs against the size budget: an
#: interval carries LP rows, bounds and certificates of some kilobytes (10^5 mixed blocks,
#: 5e5 intervals: about 1.1 GB), a checker point some 20 bytes of one bounded chunk. With
#: the default budget the oracle starts on at most 10^6 intervals (about 2 GB).
ORACLE_GRID_WEIGHT = 100


def oracle_intervals(max_grid_points: float) -> int:
    """The oracle's interval budget under the size budget ``max_grid_points``: the
    refinement may grow its grid to ``max_grid_points / ORACLE_GRID_WEIGHT`` intervals
    (10^6 by default), the same weight :func:`require_budget` charges for its first grid.
    """
    return int(min(max_grid_points / ORACLE_GRID_WEIGHT, 2 ** 62))


def require_budget(program: Program, path: Path,
                   max_grid_points: float = DEFAULT_MAX_GRID_POINTS, *,
                   oracle: bool = False) -> None:
    """A path whose sampling would exceed the size budget is rejected before any sample.

    The points are those of :func:`reference.core.budget.grid_points` (the checker's
    samples on arcs and helices, the densest sampling of any stage) and, with
    ``oracle``, the intervals of the oracle's first grid
    (:func:`optimal.grid.initial_counts`) at :data:`ORACLE_GRID_WEIGHT` points each.
    The message names the line contributing most, and what to change there.

    Raises
    ------
    BudgetError
        More than ``max_grid_points`` points; names file, line and the option.
    """
    pts = grid_points(path)
    total = float(pts.sum()) if pts.size else 0.0
    what = "grid points"
    if total <= max_grid_points and oracle and path.n_segments:
        from optimal.grid import initial_counts
        pts = initial_counts(path)
        total = float(pts.sum())
        if total * ORACLE_GRID_WEIGHT <= max_grid_points:
            return
        what = (f"oracle grid intervals (at most --max-grid-points / "
                f"{ORACLE_GRID_WEIGHT} = {max_grid_points / ORACLE_GRID_WEIGHT:.2g})")
    elif total <= max_grid_points:
        return
    worst = int(np.argmax(pts))
    span = _span_of_block(path, int(path.block[worst]))
    line = max(1, span.line) if span is not None else 1
    blk = program.blocks[int(path.block[worst])] if span is not None else None
    turns = int(getattr(blk, "turns", 0) or 0) if blk is not None else 0
    word = "P" if program.dialect == "ngc" else "TURN"
    if turns > 0:
        cause = f"P{turns + 1}" if word == "P" else f"TURN={turns}"
        fix = f"reduce {word}"
    else:
        cause, fix = "the program's arcs and helices", "split the program"
    raise BudgetError(f"{program.file}:{line}: {cause} gives {total:.2g} {what} at "
                      f"line {line} (budget {max_grid_points:.2g}); raise "
                      f"--max-grid-points or {fix}")


def require_ipo_budget(duration_s: float, t_ipo_s: float, what: str,
                       max_grid_points: float = DEFAULT_MAX_GRID_POINTS) -> None:
    """A CSV sampled at the IPO cycle must fit the size budget (checked before sampling).

    Raises
    ------
    BudgetError
        More rows than ``max_grid_points``; names the duration, the cycle and the option.
    """
    n = ipo_points(duration_s, t_ipo_s)
    if n > max_grid_points:
        raise BudgetError(f"{what}: the motion lasts {duration_s:.6g} s, {n:.2g} rows at the "
                          f"IPO cycle of {t_ipo_s * 1e3:.6g} ms (budget {max_grid_points:.2g}"
                          "); raise --max-grid-points or omit the CSV")


def _span_of_block(path: Path, block: int):
    for sp in path.blocks:
        if sp.block == block:
            return sp
    return None


# --------------------------------------------------------------------- optimize
@dataclass(frozen=True, slots=True, eq=False)
class OptimizeResult:
    """The oracle alone on a program's path (``feedoracle optimize``).

    Attributes
    ----------
    program : str
        Program file.
    machine : str
        Machine name.
    bounds : str
        Bound set solved.
    path : Path
        The path solved on (:func:`reference.build_path`).
    limits : MachineLimits
        Machine limits.
    solution : optimal.OptimalSolution
        The oracle's result.
    """

    program: str
    machine: str
    bounds: str
    path: Path
    limits: MachineLimits
    solution: "OptimalSolution"

    @property
    def certified(self) -> bool:
        """True when both bounds are valid (status ``optimal`` or ``gap_not_met``)."""
        return str(self.solution.status) in ("optimal", "gap_not_met")

    def oracle_dict(self) -> dict[str, Any]:
        """The ``"oracle"`` part of the JSON contract (``None`` for a missing bound)."""
        d = engines.oracle_json(self.solution)
        return d.get("oracle", d)

    def rows(self) -> list[dict[str, Any]]:
        """Per-block rows: the oracle's fields with line, label, kind and length added."""
        spans = {b.block: b for b in self.path.blocks}
        out = []
        for r in engines.oracle_json(self.solution).get("blocks", []):
            sp = spans.get(int(r.get("block", -1)))
            out.append({"block": sp.block, "line": max(1, sp.line), "label": sp.label,
                        "kind": sp.kind, "length_mm": sp.length, **r} if sp else dict(r))
        return out

    def to_dict(self) -> dict[str, Any]:
        """The JSON of ``feedoracle optimize --json`` (``schema/result.schema.json``)."""
        oracle = {k: (0.0 if v is None else v) for k, v in self.oracle_dict().items()}
        return {"program": self.program, "machine": self.machine, "bounds": self.bounds,
                "oracle": oracle,
                "blocks": [{k: v for k, v in r.items() if v is not None}
                           for r in self.rows()]}


def optimize_program(program: ProgramLike, machine: MachineLike = None, *,
                     bounds: str = "acc", tol: float | None = None,
                     dialect: str | None = None, progress: ProgressFn | None = None,
                     max_grid_points: float = DEFAULT_MAX_GRID_POINTS) -> OptimizeResult:
    """The oracle alone on the program's path; the heuristic does not run.

    Parameters
    ----------
    program, machine, dialect
        See :func:`load_inputs`.
    bounds : str
        Bound set (``"acc"``; an unavailable set is an input error).
    tol : float, optional
        Requested relative gap between the oracle's bounds (default: the oracle's).
    progress : callable, optional
        ``progress(message, fraction)``.

    Returns
    -------
    OptimizeResult

    Raises
    ------
    FeedOracleError
        Bad input, or a bound set the oracle cannot solve.
    """
    bounds, _ = engines.resolve_bounds(bounds, None)
    inp = load_inputs(program, machine, dialect=dialect)
    path = build_path(inp.program, inp.machine)
    require_motion(inp.program, path)
    require_budget(inp.program, path, max_grid_points, oracle=True)
    # the waits the program and machine impose (dwell, exact-stop settle): the same the
    # heuristic would contain, computed without it
    holds = imposed_holds(inp.program, path, inp.machine)
    sol = engines.run_oracle(path, inp.machine.limits, bounds,
                             progress=engines.prefixed(progress, "oracle: "), tol=tol,
                             holds=holds,
                             max_grid=oracle_intervals(max_grid_points))
    return OptimizeResult(program=inp.program.file, machine=inp.machine.name, bounds=bounds,
                          path=path, limits=inp.machine.limits, solution=sol)


# --------------------------------------------------------------------- compare
def compare_program(program: ProgramLike, machine: MachineLike = None, *,
                    bounds: str = "auto", tol: float | None = None,
                    dialect: str | None = None, progress: ProgressFn | None = None,
                    max_grid_points: float = DEFAULT_MAX_GRID_POINTS) -> Comparison:
    """Heuristic and oracle on one path, compared block by block (``feedoracle compare``).

    Parameters
    ----------
    program, machine, dialect
        See :func:`load_inputs`.
    bounds : {"auto", "acc", "jerk", "acc+freq", "jerk+freq"}
        Oracle bound set; ``"auto"`` takes the heuristic's own where the oracle solves
        it, else ``"acc"`` with a note in :attr:`Comparison.notes`.
    tol : float, optional
        Requested relative gap between the oracle's bounds (default: the oracle's).
    progress : callable, optional
        ``progress(message, fraction)``; messages start with ``heuristic:`` or
        ``oracle:``.

    Returns
    -------
    Comparison
        Per-block rows, totals, the gap interval and ``verdict(max_gap)``.

    Raises
    ------
    FeedOracleError
        Bad input, or an explicit bound set the oracle cannot solve.
    """
    inp = load_inputs(program, machine, dialect=dialect)
    path = build_path(inp.program, inp.machine)
    require_motion(inp.program, path)
    require_budget(inp.program, path, max_grid_points, oracle=True)
    plan = engines.run_heuristic(inp.program, inp.machine, path=path,
                                 progress=engines.prefixed(progress, "heuristic: "))
    bounds, notes = engines.resolve_bounds(bounds, plan.bound_set)
    sol = engines.run_oracle(path, inp.machine.limits, bounds,
                             progress=engines.prefixed(progress, "oracle: "), tol=tol,
                             holds=plan.holds,
                             max_grid=oracle_intervals(max_grid_points))
    c = compare(plan, sol, limits=inp.machine.limits, program=inp.program,
                machine=inp.machine.name)
    if notes:
        c = replace(c, notes=tuple(notes) + c.notes)
    return c


# --------------------------------------------------------------------- check
def check_trajectory(trajectory: str | os.PathLike[str], program: ProgramLike,
                     machine: MachineLike = None, *, bounds: str | None = None,
                     path_kind: str = "reference", smoothing: float | str = "auto",
                     max_deviation: float | None = None, dialect: str | None = None,
                     progress: ProgressFn | None = None,
                     max_grid_points: float = DEFAULT_MAX_GRID_POINTS) -> "CheckResult":
    """A recorded trajectory against the limits and the oracle (``feedoracle check``).

    Parameters
    ----------
    trajectory : path
        CSV file with header ``t,X,Y,Z[,A,...]`` (see :mod:`compare.recorded`).
    program, machine, dialect
        See :func:`load_inputs`; the program the recording ran.
    bounds : str, optional
        Bound set the recording is judged against (default ``"acc"``).
    path_kind : {"reference", "programmed"}
        Project onto :func:`reference.build_path` or onto the programmed contour.
    smoothing : float or "auto"
        Position noise to smooth away, mm (0: none; ``"auto"``: estimated).
    max_deviation : float, optional
        Largest accepted distance from the path, mm (default ``max(0.1, 5 * noise)``).
    progress : callable, optional
        ``progress(message, fraction)``.

    Returns
    -------
    compare.recorded.CheckResult
        ``ok``, ``print(out)``, ``to_dict()`` and the :class:`Comparison`.

    Raises
    ------
    FeedOracleError
        Bad program, machine data or recording (naming file and line or row).
    """
    if isinstance(smoothing, str) and smoothing != "auto":
        raise ValueError(f"smoothing {smoothing!r}: 'auto' or a noise level in mm")
    if not isinstance(smoothing, str) and not (math.isfinite(smoothing) and smoothing >= 0):
        raise ValueError(f"smoothing {smoothing!r}: must be >= 0 mm")
    inp = load_inputs(program, machine, dialect=dialect)
    contour = prepare(inp.program)
    require_motion(inp.program, contour)
    require_budget(inp.program, contour, max_grid_points, oracle=True)
    return check_recorded(trajectory, inp.program, inp.machine, bounds=bounds,
                          path_kind=path_kind, smoothing=smoothing,
                          max_deviation=max_deviation, progress=progress)


__all__ = ["Inputs", "MachineLike", "OptimizeResult", "ProgramLike", "ProgressFn",
           "check_trajectory", "compare_program", "load_inputs", "optimize_program",
           "plan_program", "require_budget", "require_ipo_budget", "require_motion"]
