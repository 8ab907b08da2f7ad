"""Solvers of the jerk grid NLP (:mod:`optimal.jerk.transcription`); solver packages are
imported here only.

=========  =====================================================  ===========
name       method                                                 needs
=========  =====================================================  ===========
ipopt      interior point on the exact NLP, CasADi AD (default)   casadi
=========  =====================================================  ===========
"""

from __future__ import annotations

from .ipopt import NlpResult, solve_nlp

__all__ = ["NlpResult", "solve_nlp"]
