"""Solvers of the frequency oracle's NLPs; solver packages are imported here only.

=========  ============================================================  =======
module     solves                                                        needs
=========  ============================================================  =======
ipopt      the free phase ends (:class:`optimal.freq.free_phases.         casadi
           FreePhaseNLP`), interior point with CasADi's derivatives
=========  ============================================================  =======

The other NLPs of :mod:`optimal.freq` are the jerk NLP's (:mod:`optimal.jerk.backends`).
"""
