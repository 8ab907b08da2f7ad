"""Backends for discrete problems: one file each, one signature, a try-import registry.

Every backend module defines ``NAME``, ``INSTALL`` (what to install), ``OPTIONS`` (its
known option keys and types), ``is_available()`` and

``solve_discrete(problem: DiscreteProblem, options: Mapping | None) -> DiscreteResult``.

Solver packages are imported inside the backend modules only, and only when used.

=========  =============================================  ==========================
name       method                                         needs
=========  =============================================  ==========================
fast       exact backward/forward sweep (default)         numpy
highs      LP ``max sum b`` (lattice property), HiGHS     scipy (HiGHS inside)
clarabel   SOCP ``min T`` (Lipp-Boyd cones), Clarabel     cvxpy, clarabel
=========  =============================================  ==========================
"""

from __future__ import annotations

import importlib
from typing import Callable, Mapping

from reference.core.errors import BackendNotFoundError

from ..problem import DiscreteProblem, DiscreteResult

DEFAULT_BACKEND = "fast"

_MODULES: dict[str, str] = {
    "fast": "optimal.backends.fast",
    "highs": "optimal.backends.highs",
    "clarabel": "optimal.backends.clarabel",
}


def _module(name: str):
    if name not in _MODULES:
        raise ValueError(f"unknown backend {name!r}; known backends: {', '.join(_MODULES)}")
    return importlib.import_module(_MODULES[name])


def known_backends() -> tuple[str, ...]:
    """All backend names, installed or not."""
    return tuple(_MODULES)


def available_backends() -> tuple[str, ...]:
    """Names of the backends whose packages are installed, default first."""
    return tuple(n for n in _MODULES if _module(n).is_available())


def get_backend(name: str) -> Callable[[DiscreteProblem, Mapping | None], DiscreteResult]:
    """The ``solve_discrete`` function of a backend.

    Raises
    ------
    ValueError
        Unknown backend name.
    BackendNotFoundError
        The backend's packages are missing (the message says what to install).
    """
    mod = _module(name)
    if not mod.is_available():
        raise BackendNotFoundError(
            f"backend {name!r} is not installed: {mod.INSTALL}; "
            f"available backends: {', '.join(available_backends())}")
    return mod.solve_discrete


def solve_discrete(problem: DiscreteProblem, backend: str = DEFAULT_BACKEND,
                   options: Mapping[str, object] | None = None) -> DiscreteResult:
    """Solve a discrete problem with the named backend.

    Parameters
    ----------
    problem : DiscreteProblem
        The problem (lattice form).
    backend : str
        One of :func:`known_backends`.
    options : Mapping, optional
        Backend-specific options (checked against the backend's known keys).

    Returns
    -------
    DiscreteResult
    """
    return get_backend(backend)(problem, options)


__all__ = ["DEFAULT_BACKEND", "available_backends", "get_backend", "known_backends",
           "solve_discrete"]
