"""Solvers of the jerk grid NLP (:mod:`optimal.jerk.transcription`); solver packages are
imported here only.

=========  =====================================================  ===========
name       method                                                 needs
=========  =====================================================  ===========
ipopt      interior point on the exact NLP, CasADi AD (default)   casadi
scp        sequential convex programming, feasible iterates       clarabel or
           (:mod:`.scp`; a cross-check of ``ipopt``)              osqp
=========  =====================================================  ===========
"""

from __future__ import annotations

from .ipopt import NlpResult, solve_nlp

__all__ = ["NlpResult", "solve_nlp"]
