"""Candidates of ``jerk+freq`` and ``acc+freq``: the base optimum re-solved by the jerk
NLP with the path acceleration bounded where the rule finds its phases short.

The jerk optimum is the fastest motion under every constraint but the frequency rule;
where a few of its phases are short (a dip between two arcs, a speed change along a helix),
slowing the whole motion down (:func:`optimal.freq.upper.scaled`) pays for them on every
block, and the filtered candidates pay the filter's spread at every cap. This one changes
the motion only where it breaks the rule, as the control's dynamic response adaptation
does, and lets the jerk NLP (:mod:`optimal.jerk.backends`) find the rest again:

* a short phase that changes the speed by more than :data:`ADAPT_WIGGLE_REL` of it gets
  a bound on the path acceleration at its nodes (``s'' <= a`` where it accelerates,
  ``s'' >= -a`` where it decelerates), ``a`` the mean acceleration that makes it last its
  ``1/f``, scaled by the phase's own ``D_eff / D`` so that an asymmetric S-ramp is
  slowed by what its effective duration lacks; a phase still short under its bound gets
  the bound lowered by what it lacks (at most halved per round). The bound acts on the
  motion itself: speed caps were tried first and bind only where the motion touches
  them (a phase inside the speed limits, on a helix where the jerk rows decide, never
  saw them), and a motion riding a cap that is only imposed at the nodes leaves a ripple
  of 3-6 ms phases between them;
* a smaller change (a wiggle: the motion following a cap that varies a little along an
  arc) is crossed at constant speed (``s'' = 0`` at its nodes), which costs at most
  that share of the time across it; a wiggle between two phases of the other sign that
  follow within its ``1/f`` (a dip at each kink of a polyline along which the speed
  rises) is crossed with that sign instead (``s'' >= ADAPT_TREND_REL`` times the NLP's
  acceleration unit, or ``<=`` its negative), so that the phases beside it make one
  (examples/demo.mpf's 0.5 mm CAM run: held at 45.7 mm/s by constant-speed wiggles, now
  one rise of 273 ms from 1.6 to 61.6 mm/s; ``jerk+freq`` upper bound 4.8644 ->
  4.8511 s). The share doubles every round: a bounded phase that
  stays short loses speed change rather than length (its ``dv`` shrinks round by round
  while it still lasts about 50 ms against 67 ms on ``lcnc_test_12mmflat``), so later
  rounds flatten what earlier ones could only shrink;
* the NLP runs again on the same grid, warm started from the last motion, in the form
  that solved the round before (:func:`optimal.jerk.backends.ipopt.solve_nlp`'s
  ``attempts``: only the first round tries every form); each round's
  motion is judged by the checker and slowed down per rest-to-rest piece until accepted
  (:func:`optimal.freq.upper.verified`); every accepted round is a candidate, since one
  round can fix one piece and spoil another.

Under ``acc+freq`` the same NLP runs without its jerk and acceleration-step rows
(:func:`without_jerk`) from the ``acc`` optimum: a motion with an acceleration linear in
time between nodes, which the ``acc`` set allows. Without a jerk limit it can move a
bounded phase beside its bounds, so it also runs with the bounds widened (``widen``).

The bounds only remove motions, and the motion at rest keeps all of them, so each
round's NLP is feasible; every result is verified: nothing here is assumed, and a round
that does not help costs time only. Measured (default machine, ``jerk+freq``, bracket
before -> after): ``lcnc_arc_arc_sawtooth`` [7.50, 11.75] -> [7.50, 7.66] s (the jerk
optimum, 7.64 s, had two phases of a dip near the start at 41 and 49 ms against 50 ms),
``lcnc_tangent_helix`` 14.4 -> 0.96 %, ``lcnc_corner_decel`` 5.7 -> 1.99 %,
``lcnc_test_12mmflat`` 23 -> 13 % (174 short phases -> 139, 130, 99, 81, 30, 5, 2, 0 over
8 rounds of about 4 s). On ``lcnc_sam_tolerance_issue`` (tiny segments at low speed) the
rounds settle only once the doubling wiggle share flattens nearly everything, and their
motions (5.2 s at best) lose to the ramp plan (2.70 s, :mod:`optimal.freq.ramps`); there
a last round that IPOPT found locally infeasible took 33 s in all four forms against
1-2 s a round, which trying only the last round's form cuts to 3 s (the brackets of
every example and corpus program, on both machines, the same to the last digit; the
program's whole ``compare`` oracle, medians of two runs in turn: ``jerk+freq`` 88.5 ->
61.7 s, ``acc+freq`` 32.2 -> 15.4 s). ``acc+freq`` (against
the adapted caps of :func:`optimal.freq.upper.eroded_plans`): ``lcnc_corner_decel``
10.4 -> 3.8 %, ``lcnc_arc_arc_sawtooth`` 20.7 -> 5.2 %, ``lcnc_tangent_helix``
3.2 -> 0.92 %; no change on 12mmflat and sam.

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

from ..grid import grid_on
from ..jerk.tolerances import DEFAULT_JERK_MAX_GRID
from ..jerk.transcription import JerkProblem, Rows, StepRows, build_jerk_problem
from ..jerk.upper import resolved
from .upper import ADAPT_MARGIN, ADAPT_WIGGLE_REL, Candidate, verified

__all__ = ["ACC_ADAPT_INTERVALS", "ACC_ADAPT_MAX_INTERVALS", "ADAPT_TREND_REL",
           "JERK_ADAPT_DONE_REL", "JERK_ADAPT_ROUNDS", "jerk_adapted", "without_jerk"]

#: NLP rounds of :func:`jerk_adapted` at most (each costs one jerk NLP on the base
#: solve's final grid; the loop stops as soon as no phase is short). The corpus programs
#: it helps settle in 2-3 rounds, lcnc_test_12mmflat in 8 (about 4 s each).
JERK_ADAPT_ROUNDS = 8
#: The rounds stop once a verified round was slowed down by at most this share: what
#: the phases still short cost is then a tenth of the default 2 % bracket, and the next
#: rounds, which tighten bounds that are nearly met, were the slow ones (on
#: lcnc_arc_arc_sawtooth under acc+freq an eighth round took IPOPT 32 s to fail, after
#: seven of about 1 s).
JERK_ADAPT_DONE_REL = 2e-3
#: ``acc+freq``: target size and largest size of the NLP grid, intervals (the jerk
#: oracle's first grid, :func:`optimal.jerk.oracle.jerk_grid`, graded toward the ends of
#: segments where the acc optimum's speed changes, merged with the acc grid). The acc
#: grid alone has 19 nodes on lcnc_corner_decel: the NLP's motion then took 9.0 s against
#: 7.35 s on 425 nodes.
ACC_ADAPT_INTERVALS = 400
ACC_ADAPT_MAX_INTERVALS = 5_000


def _short_phases(path: Path, lim, prof: Profile):
    """Phases of ``prof`` shorter than their ``1/f`` (less the margin): ``(phases,
    indices, needed durations)``."""
    ph = acceleration_phases(prof)
    seg = path.segment_index(0.5 * (prof.s[:-1] + prof.s[1:]))
    f, _ = phase_frequencies(path, lim, ph, seg)
    need = min_phase_duration(f)
    short = np.flatnonzero(ph.effective_duration < need * (1.0 - ADAPT_MARGIN))
    return ph, short, need


#: The least path acceleration at a wiggle crossed with its neighbours' sign, as a share
#: of the NLP's acceleration unit (the largest axis limit): a thousand times the
#: checker's phase threshold (FREQ_ACCEL_TOL_REL of the largest ``|s''|``), so that the
#: rise stays one phase at IPOPT's tolerance, and too little to cost time (2 mm/s^2 on
#: the default machine: 0.01 mm/s over a 5 ms dip).
ADAPT_TREND_REL = 1e-3


def _trend(ph, p: int, gap_s: float) -> int:
    """Sign of the phases on both sides of phase ``p`` where both have the other sign and
    each follows within ``gap_s`` of it (s); 0 otherwise (a peak, a valley, a wiggle at
    either end of the motion or beside a cruise)."""
    if p == 0 or p + 1 >= ph.sign.size:
        return 0
    if ph.sign[p - 1] != ph.sign[p + 1] or ph.sign[p - 1] == ph.sign[p]:
        return 0
    if ph.start_t[p] - ph.end_t[p - 1] > gap_s or ph.start_t[p + 1] - ph.end_t[p] > gap_s:
        return 0
    return int(ph.sign[p - 1])


def without_jerk(problem: JerkProblem) -> JerkProblem:
    """The NLP of the ``acc`` set: no jerk rows, no acceleration-step rows at breaks
    (the acceleration is still linear in time inside each interval, so it is
    continuous between the nodes of a segment, which only removes motions)."""
    i0 = np.zeros(0, np.int64)
    f0 = np.zeros(0)
    return replace(problem, jerk=Rows(i0, i0, f0, f0, f0, f0, i0),
                   step=StepRows(i0, i0, i0, f0, f0, f0, f0, f0, i0))


def jerk_adapted(path: Path, limits: MachineLimits, grid_s: np.ndarray, start: Profile,
                 rounds: int = JERK_ADAPT_ROUNDS,
                 progress: Callable[[str], object] | None = None,
                 bounds: str = "jerk+freq", widen: bool = False,
                 asymmetric: bool = True, holds: Holds = NO_HOLDS) -> list[Candidate]:
    """The jerk optimum adapted to the frequency rule (see the module docstring).

    Parameters
    ----------
    path : Path
        The path (all axes, as the jerk oracle solved it).
    limits : MachineLimits
    grid_s : numpy.ndarray, shape (N + 1,)
        Nodes of the jerk NLP, mm (the base solve's final grid).
    start : Profile
        The jerk optimum on that grid (holds excluded).
    rounds : int
        NLP rounds at most. None runs on a grid of more than ``DEFAULT_JERK_MAX_GRID``
        intervals (the jerk oracle's largest NLP).
    progress : callable, optional
        ``progress(message)`` after each round.
    bounds : {"jerk+freq", "acc+freq"}
        ``acc+freq``: the NLP without its jerk and acceleration-step rows
        (:func:`without_jerk`), started from the ``acc`` optimum.
    widen : bool
        Bound the acceleration also where the motion goes in ``1/f`` before and after
        each short phase. Without jerk rows the NLP can move a bounded phase beside its
        bounds, one phase length per round (a line-arc-line at F150: two phases of 6 ms
        moved for 8 rounds); the wider bound stops that but also binds ramps that were
        long enough. Neither is faster on every program (default machine, ``acc+freq``:
        ``lcnc_corner_decel`` 7.35 s narrow against 7.26 s wide, ``lcnc_arc_arc_sawtooth``
        5.59 against 5.79 s), so the oracle runs both (``acc+freq`` only).
    asymmetric : bool
        Scale each bound by the phase's ``D_eff / D``: an asymmetric ramp (an S-ramp whose
        jerk differs at its two ends, an acceleration limited by a curvature term that
        changes with the speed) is slowed by what its effective duration lacks, where a
        bound that makes it symmetric would need less. Neither is faster on every program
        (default machine, ``jerk+freq``: ``lcnc_test_12mmflat`` 40.4 s with the factor
        against 41.6 s without, ``lcnc_corner_decel`` 7.35 against 7.29 s; ``acc+freq``
        on ``lcnc_arc_arc_sawtooth`` 5.59 against 5.31 s, but on the line-arc-line of the
        tests 0.742 against 0.750 s), so the oracle runs both, under ``acc+freq`` with and
        without ``widen``.
    holds : Holds
        The holds of the reported motion: the NLP arrives at and leaves their breaks as
        at the path ends (:func:`optimal.jerk.transcription.build_jerk_problem`), and
        each round is judged with them inserted (:func:`optimal.freq.upper.verified`).

    Returns
    -------
    list of Candidate
        Every verified round, named ``"jerk adapted, round k"`` (each is slowed down per
        rest-to-rest piece, and a later round can be better on one piece and worse on
        another: :func:`optimal.freq.upper.pieced` takes the best of each); empty when
        ``start`` already keeps the rule (the scaled base optimum is then that motion).
    """
    lim = limits.for_axes(path.axes)
    prof = start
    ph, short, need = _short_phases(path, lim, prof)
    if short.size == 0:
        return []
    grid = grid_on(path, grid_s)
    if grid.n_intervals > DEFAULT_JERK_MAX_GRID:
        # the jerk oracle's own largest NLP: beyond it a round would cost more than the
        # base solve, and the other candidates stand
        return []
    problem = build_jerk_problem(path, lim, grid, limits.t_ipo_s, holds.break_index)
    jerk_rows = bounds != "acc+freq"
    if not jerk_rows:
        problem = without_jerk(problem)
    a_unit = problem.units.accel
    # bounds on [a, extra]: the accelerations at the nodes (on leaving), then on arriving
    # at each interior break node (a phase ending at a break ends on that one)
    inner = grid.break_node[1:-1]
    a_lo = np.full(grid.s.size + inner.size, -np.inf)
    a_hi = np.full(grid.s.size + inner.size, np.inf)
    out: list[Candidate] = []
    attempts = None          # the first round tries every form of the NLP
    for r in range(rounds):
        for p in short:
            s0, s1 = prof.s[ph.first[p]], prof.s[ph.last[p] + 1]
            if widen:
                # without a jerk limit the NLP can move a bounded phase to the unbounded
                # nodes beside it (it decelerates earlier at the full acceleration):
                # the bound then reaches as far as the motion goes in 1/f on either side
                reach = max(prof.v[ph.first[p]], prof.v[ph.last[p] + 1]) * need[p]
                s0, s1 = s0 - reach, s1 + reach
            i0 = max(int(np.searchsorted(grid.s, s0, side="left")), 0)
            i1 = min(int(np.searchsorted(grid.s, s1, side="right")), grid.s.size)
            if i1 <= i0:
                continue
            nodes = np.concatenate((np.arange(i0, i1), grid.s.size + np.flatnonzero(
                (inner > i0) & (inner < i1))))
            v_hi = max(prof.v[ph.first[p]], prof.v[ph.last[p] + 1])
            if ph.dv[p] <= ADAPT_WIGGLE_REL * 2.0 ** r * v_hi:
                trend = _trend(ph, p, need[p])
                if trend > 0:
                    # a dip inside a rise: crossed rising, so that the rises beside it
                    # make one phase
                    a_lo[nodes] = np.maximum(a_lo[nodes], ADAPT_TREND_REL * a_unit)
                elif trend < 0:
                    a_hi[nodes] = np.minimum(a_hi[nodes], -ADAPT_TREND_REL * a_unit)
                else:
                    # a wiggle: crossed at constant speed (no acceleration at its nodes)
                    a_lo[nodes] = np.maximum(a_lo[nodes], 0.0)
                    a_hi[nodes] = np.minimum(a_hi[nodes], 0.0)
                continue
            aim = need[p] * (1.0 + ADAPT_MARGIN)
            # the mean acceleration that makes the phase last its 1/f, less what an
            # asymmetric ramp's effective duration lacks against its plain one
            a_new = ph.dv[p] / aim * (min(1.0, ph.effective_duration[p] / ph.duration[p])
                                      if asymmetric else 1.0)
            if ph.sign[p] > 0:
                now = a_hi[nodes]
                shrink = float(np.clip(ph.effective_duration[p] / aim, 0.5, 1.0))
                a_hi[nodes] = np.where(now <= a_new * (1.0 + 1e-9), now * shrink, a_new)
            else:
                now = -a_lo[nodes]
                shrink = float(np.clip(ph.effective_duration[p] / aim, 0.5, 1.0))
                a_lo[nodes] = -np.where(now <= a_new * (1.0 + 1e-9), now * shrink, a_new)
        # a node between two trends (a dip in a rise beside a bump in a fall) or a trend
        # against a later round's bound: the upper bound stands, so the NLP's bounds
        # stay consistent (IPOPT rejects lb > ub)
        a_lo = np.minimum(a_lo, a_hi)
        prob_r = replace(problem, a_lo=a_lo / a_unit, a_hi=a_hi / a_unit)
        new, attempt = resolved(path, lim, grid, prob_r, prof, attempts)
        if new is None:
            break      # IPOPT failed, or its answer is no motion: the rounds so far stand
        # a later round is the same NLP with bounds moved, from this round's motion: the
        # form that solved this one is tried alone (lcnc_sam_tolerance_issue.ngc: a last
        # round that IPOPT found locally infeasible in every form took 33 s, against
        # 1-2 s a round, and the rounds before it stood)
        prof, attempts = new, (attempt,)
        tags = ", ".join(t for t, on in (("wide", widen), ("D_eff/D", asymmetric)) if on)
        c = verified(f"{bounds.split('+')[0]} NLP adapted{f' ({tags})' if tags else ''}, "
                     f"round {r + 1}", path, limits, prof, bounds, holds=holds)
        if c is not None:
            out.append(c)
            if c.time_scale <= 1.0 + JERK_ADAPT_DONE_REL:
                break      # what the short phases left still cost is below the mark
        ph, short, need = _short_phases(path, lim, prof)
        if progress:
            progress(f"{bounds.split('+')[0]} NLP adapted to the rule, round {r + 1}: "
                     f"{short.size} short phases left")
        if short.size == 0:
            break
    return out
