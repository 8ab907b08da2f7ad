"""Candidate of ``jerk+freq``: the jerk NLP with the frequency rule itself as rows, on the
phases of a verified motion.

The other candidates keep the rule by construction (ramps of at least ``1/f``,
:mod:`optimal.freq.ramps`; filters, :mod:`optimal.freq.upper`) or by bounding the
acceleration where a phase is short (:mod:`optimal.freq.jerk_adapted`); each is a
motion the rule accepts, none the fastest it accepts. The rule (:mod:`reference.core.
phases`) asks of a phase only that its acceleration-weighted mean time lie ``1/(2f)``
from either end, and on a grid of the jerk NLP (:mod:`optimal.jerk.transcription`) that
is two rows per phase, exact in the NLP's variables (:class:`~optimal.jerk.transcription.
PhaseRows`). So, given where the phases of a verified motion are:

* each interval inside a phase keeps the phase's sign (``s'' >= 0`` at its nodes for a
  rise, with :data:`~optimal.freq.jerk_adapted.ADAPT_TREND_REL` of the NLP's acceleration
  unit at the nodes inside it, so that the checker finds one phase there and not two),
  each interval
  between phases runs at constant speed (``s'' = 0`` at its nodes);
* each phase gets the two rows with ``g = 1/f``, ``f`` the smallest LOOKAH_FREQUENCY of
  the axes moving in it (as the checker takes it);
* the NLP (every other row of the jerk set as in the jerk oracle) finds the fastest motion
  with these phases, warm started from the motion; its motion is judged by the checker
  and slowed down per rest-to-rest piece until accepted
  (:func:`optimal.freq.upper.verified`), and its phases seed the next round.

The phases' places are those of the motion rounded to the grid's nodes; the NLP moves
the speed and the acceleration inside them (a phase may take its change early or late,
so long as its mean time stays central), not where they begin and end, which the next
round takes from the new motion. Every constraint the NLP adds only removes motions and
the result is verified: nothing is assumed, and a round that does not help costs time
only.

Units: mm, s.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Callable

import numpy as np

from reference.core.geometry import Path
from reference.core.holds import NO_HOLDS, Holds
from reference.core.limits import MachineLimits
from reference.core.phases import acceleration_phases, min_phase_duration, phase_frequencies
from reference.core.profile import Profile

from ..grid import Grid, grid_on
from ..jerk.tolerances import DEFAULT_JERK_MAX_GRID
from ..jerk.transcription import JerkProblem, PhaseRows, build_jerk_problem
from ..jerk.upper import resolved
from .jerk_adapted import ADAPT_TREND_REL
from .upper import Candidate, verified

__all__ = ["PHASE_NLP_ROUNDS", "phase_nlp"]

#: NLP rounds at most (each from the phases of the last; they end where a round's
#: motion has the phases of the one before, whose NLP it would solve again).
PHASE_NLP_ROUNDS = 3


def phase_nlp(path: Path, limits: MachineLimits, grid_s: np.ndarray, start: Profile, *,
              holds: Holds = NO_HOLDS, rounds: int = PHASE_NLP_ROUNDS,
              progress: Callable[[str], object] | None = None) -> list[Candidate]:
    """The rounds of the module docstring under ``jerk+freq``.

    Parameters
    ----------
    path : Path
    limits : MachineLimits
    grid_s : numpy.ndarray, shape (N + 1,)
        NLP grid nodes (the jerk oracle's final grid), mm.
    start : Profile
        A verified motion on ``path`` (holds excluded): its phases seed the first round.
    holds : Holds
        As for :func:`optimal.freq.jerk_adapted.jerk_adapted`.
    rounds : int
        NLP rounds at most.
    progress : callable, optional
        ``progress(message)`` after each round.

    Returns
    -------
    list of Candidate
        Every verified round, named ``"phase NLP, round k"``.
    """
    lim = limits.for_axes(path.axes)
    grid = grid_on(path, grid_s)
    if grid.n_intervals > DEFAULT_JERK_MAX_GRID:
        return []
    problem = build_jerk_problem(path, lim, grid, limits.t_ipo_s, holds.break_index)
    out: list[Candidate] = []
    prof, attempts = start, None
    last = None
    for r in range(rounds):
        prob_r = _with_phases(path, lim, grid, problem, prof)
        if prob_r is None or (last is not None and _same_phases(prob_r.phases, last)):
            break      # no phase, or the last round's phases again: the same NLP
        last = prob_r.phases
        new, attempt = resolved(path, lim, grid, prob_r, prof, attempts)
        if new is None:
            break
        prof, attempts = new, (attempt,)       # as in optimal.freq.jerk_adapted
        c = verified(f"phase NLP, round {r + 1}", path, limits, prof, "jerk+freq",
                     holds=holds)
        if progress:
            progress(f"jerk NLP with the rule's rows, round {r + 1}"
                     + (f": {c.duration:.4f} s" if c is not None else ": not accepted"))
        if c is None:
            break
        out.append(c)
        prof = c.profile
    return out


def _same_phases(a: PhaseRows, b: PhaseRows) -> bool:
    """Whether two sets of phase rows cover the same intervals with the same signs."""
    return (a.first.size == b.first.size and bool(np.all(a.first == b.first))
            and bool(np.all(a.stop == b.stop)) and bool(np.all(a.sign == b.sign)))


def _with_phases(path: Path, lim, grid: Grid, problem: JerkProblem,
                 prof: Profile) -> JerkProblem | None:
    """``problem`` with the phases of ``prof`` (module docstring): the bounds on the
    accelerations and the rows; ``None`` where ``prof`` has no phase."""
    ph = acceleration_phases(prof)
    if ph.n == 0:
        return None
    f, _ = phase_frequencies(path, lim, ph,
                             path.segment_index(0.5 * (prof.s[:-1] + prof.s[1:])))
    need = min_phase_duration(f)
    N = grid.n_intervals
    # each phase's nodes: where the motion's phase begins and ends, rounded to the grid
    k0 = np.clip(np.rint(np.interp(prof.s[ph.first], grid.s, np.arange(N + 1))), 0, N)
    k1 = np.clip(np.rint(np.interp(prof.s[ph.last + 1], grid.s, np.arange(N + 1))), 0, N)
    k0, k1 = k0.astype(np.int64), k1.astype(np.int64)
    sign = np.zeros(N, np.int64)              # per interval: +1, -1, 0 (constant speed)
    keep = []
    last_stop = 0
    for p in np.argsort(k0, kind="stable"):
        a, b = max(int(k0[p]), last_stop), int(k1[p])
        if b <= a or not np.isfinite(need[p]):
            continue
        sign[a:b] = int(ph.sign[p])
        keep.append((a, b, int(ph.sign[p]), float(need[p])))
        last_stop = b
    if not keep:
        return None
    u = problem.units
    margin = ADAPT_TREND_REL             # in the NLP's acceleration unit
    # bounds on the node accelerations on leaving (interval k) and on arriving (k - 1;
    # the same variable except at interior break nodes, which have their own)
    n_extra = problem.n_extra
    lo = np.full(N + 1 + n_extra, -np.inf)
    hi = np.full(N + 1 + n_extra, np.inf)

    def bound(idx: np.ndarray, sg: np.ndarray, inner: np.ndarray) -> None:
        m = np.where(inner, margin, 0.0)
        for s_, sel in ((1, sg > 0), (-1, sg < 0)):
            i = idx[sel]
            if s_ > 0:
                lo[i] = np.maximum(lo[i], m[sel])
            else:
                hi[i] = np.minimum(hi[i], -m[sel])
        i = idx[sg == 0]
        lo[i] = np.maximum(lo[i], 0.0)
        hi[i] = np.minimum(hi[i], 0.0)

    k = np.arange(N)
    prev = np.concatenate(([0], sign[:-1]))
    nxt = np.concatenate((sign[1:], [0]))
    # leaving node k on interval k; inside a phase where interval k - 1 is of its sign
    bound(k, sign, (prev == sign) & (sign != 0))
    # arriving at node k + 1 from interval k (end_index: the node's a, or its extra)
    bound(problem.end_index, sign, (nxt == sign) & (sign != 0))
    lo = np.minimum(lo, hi)
    rows = PhaseRows(np.array([x[0] for x in keep], np.int64),
                     np.array([x[1] for x in keep], np.int64),
                     np.array([x[2] for x in keep], np.int64),
                     np.array([x[3] for x in keep]) / u.time_s)
    return replace(problem, a_lo=lo, a_hi=hi, phases=rows)
