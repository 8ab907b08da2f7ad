"""Solvers of the jerk grid NLP (:mod:`optimal.jerk.transcription`); solver packages are
imported here only.

=========  =====================================================  ===========
name       method                                                 needs
=========  =====================================================  ===========
ipopt      interior point on the exact NLP, CasADi AD (default)   casadi
scp        sequential convex programming, feasible iterates       clarabel or
           (:mod:`.scp`; a cross-check of ``ipopt``)              osqp
=========  =====================================================  ===========

The relaxation's conic solve (:mod:`optimal.jerk.relaxation`) is :mod:`.socp` (Clarabel).
"""

from __future__ import annotations

from typing import Callable

from .ipopt import NlpResult, solve_nlp

#: Names accepted by ``optimal.solve(..., bounds="jerk", nlp_backend=...)``.
NLP_BACKENDS = ("ipopt", "scp")


def get_nlp_backend(name: str) -> Callable[..., NlpResult]:
    """The ``solve_nlp`` function of the backend called ``name`` (see the table above).

    Raises
    ------
    ValueError
        An unknown name (the message lists the known ones).
    """
    if name == "ipopt":
        return solve_nlp
    if name == "scp":
        from .scp import solve_nlp as scp_solve
        return scp_solve
    raise ValueError(f"nlp_backend = {name!r}: unknown (known: {', '.join(NLP_BACKENDS)})")


__all__ = ["NLP_BACKENDS", "NlpResult", "get_nlp_backend", "solve_nlp"]
