"""feedoracle's heuristic side: NC programs, machine data, path preparation and the
SINUMERIK-style reference planner.

The public API, importable from here::

    program = reference.parse_text(text)            # or parse_file(path)
    machine = reference.load_machine()              # the bundled default mill
    path = reference.build_path(program, machine)   # the one path both planners run on
    plan = reference.plan(program, machine, path=path)

Kept light: ``reference.core`` imports run this file, so the names below are imported
on first use (PEP 562), and this package never imports ``optimal`` or ``compare``.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

#: Public name -> module that defines it.
_EXPORTS = {
    # NC programs
    "Program": "reference.nc", "ProgramWarning": "reference.nc",
    "parse_file": "reference.nc", "parse_text": "reference.nc",
    # machine data
    "BUNDLED_MACHINES": "reference.machine", "Machine": "reference.machine",
    "load_machine": "reference.machine",
    # the path
    "build_path": "reference.prepare", "unmodelled_features": "reference.prepare",
    # the heuristic
    "PlannerParameters": "reference.planner", "ReferencePlan": "reference.planner",
    "plan": "reference.planner",
    # shared vocabulary
    "BOUND_SETS": "reference.core.constraints", "check_profile": "reference.core.constraints",
    "FeedOracleError": "reference.core.errors", "MachineDataError": "reference.core.errors",
    "NCSyntaxError": "reference.core.errors", "PathError": "reference.core.errors",
    "MachineLimits": "reference.core.limits", "Path": "reference.core.geometry",
    "Profile": "reference.core.profile",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    try:
        module = _EXPORTS[name]
    except KeyError:
        raise AttributeError(f"module 'reference' has no attribute {name!r}") from None
    return getattr(importlib.import_module(module), name)


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


if TYPE_CHECKING:  # for type checkers and editors; at run time names load on first use
    from .core.constraints import BOUND_SETS, check_profile
    from .core.errors import FeedOracleError, MachineDataError, NCSyntaxError, PathError
    from .core.geometry import Path
    from .core.limits import MachineLimits
    from .core.profile import Profile
    from .machine import BUNDLED_MACHINES, Machine, load_machine
    from .nc import Program, ProgramWarning, parse_file, parse_text
    from .planner import PlannerParameters, ReferencePlan, plan
    from .prepare import build_path, unmodelled_features
