"""Candidate of ``jerk+freq`` and ``acc+freq``: the jerk NLP with the frequency rule itself
as rows, on the phases of a verified motion.

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
so long as its mean time stays central), not where they begin and end. Its motion then
has the same phases, so from the second round on each phase first grows into the
constant-speed intervals beside it (:data:`PHASE_GROW` of its ``1/f`` at each end,
:func:`_grown`): a relaxation of the rows, which lets the next NLP start the change
earlier or end it later, and the rounds stop when the phases come back unchanged.

Before growing, two neighbouring phases of one sign a short constant-speed stretch apart
(:data:`PHASE_MERGE_GAP` of their ``1/f``) become one phase (:func:`_merged`), crossed
with its sign between them: a relaxation of the rows too (the joined phase's mean time
lies between the two phases' own). A fall to a cap, a short stretch at it and a fall
further need ``1/f`` for each change; as one phase both changes may be done at full
acceleration with the cap passed in its slow middle, the motion the rule accepts in the
second case of :mod:`reference.core.phases` (there a hand-built motion of this kind on
lcnc_test_12mmflat's first pass was faster than every motion of the oracle). Measured
on that pass (lines 8-14 cut out, ``acc+freq``, lower bound 3.3360 s): the upper bound
3.3994 -> 3.3749 s (bracket 1.90 -> 1.17 %), below the hand-built motion's 3.3766 s;
on a line falling through a feed cap to rest (tests/optimal/test_freq.py) 0.5132 ->
0.4694 s, against 0.46875 s of the hand motion.

Where the rounds leave the bracket open, one trial follows (:func:`_flattened`): from the
fastest motion, every *wiggle* (a phase between two of the other sign, with at most
:data:`PHASE_WIGGLE_REL` of their speed change) joined with its neighbours into one
phase, and the rounds from there. A short curve between two low caps (a curvature jump's
cap and a corner's) lets the ramps rise a little and fall again, two phases of ``1/f``
for a bump of a few mm/s; one fall through the curve passes it in the creep. The joined
phase forbids the bump, so the trial is no relaxation: its motions are judged like every
other and kept where faster. Measured (``acc+freq``, default machine):
lcnc_test_12mmflat's pass at Y43.87 (lines 118-124 cut out) 3.8142 -> 3.7871 s (bracket
3.25 -> 2.51 %), the whole program 38.1831 -> 38.1272 s; five blocks of a line with a
wiggle between two point caps (tests/optimal/test_freq.py) 0.8909 -> 0.8437 s, against a
hand motion's 0.84197 s.

Under ``acc+freq`` the same NLP runs without its jerk and acceleration-step rows
(:func:`optimal.freq.jerk_adapted.without_jerk`), as the jerk-adapted rounds do there:
its motions (acceleration linear in time between nodes) are motions of the ``acc`` set,
and the checker judges them under ``acc+freq``. The grid there gets nodes at the seed's
phase ends and one IPO cycle beside them (:func:`_with_step_nodes`), where a ramp of the
``acc`` set steps its acceleration.

The NLP keeps the axis acceleration at its nodes; on an arc it peaks between them, and
the checker would slow the whole rest-to-rest piece down for it (lcnc_test_12mmflat,
``acc+freq``: by 1.024). Such a round runs again with the acceleration rows of the blocks
it breaks lowered by the checker's ratio (:func:`_eased`, at most
:data:`PHASE_REFINE_MAX` times). Every constraint the NLP adds only removes motions, and
every result is verified in full: nothing is assumed, and a round that does not help
costs time only.

Measured (``compare``, default machine, bracket before -> after): ``jerk+freq``
lcnc_sam_tolerance_issue 30.9 -> 23.8 % (the NLP on the seed's phases) -> 20.0 % (the
phases grown) -> 18.0 % (with the oracle's second seed, :mod:`optimal.freq.oracle`),
lcnc_test_12mmflat 2.64 -> 2.51 -> 1.84 %; ``acc+freq`` (the NLP added there) sam
20.2 -> 12.6 %, 12mmflat 3.27 -> 3.00 % -> 2.90 % (phases joined; sam has no two
phases of one sign to join, its motion rising and falling between corners) -> 2.75 %
(wiggles flattened; 2.26 % with the turn programme's cell ceiling raised,
:data:`optimal.freq.humps.HUMP_MAX_CELLS`).

Units: mm, s.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Callable

import numpy as np

from reference.core.constraints import BOUND_SETS, time_scale_factors_by_block
from reference.core.geometry import Path
from reference.core.holds import NO_HOLDS, Holds
from reference.core.limits import MachineLimits
from reference.core.phases import acceleration_phases, min_phase_duration, phase_frequencies
from reference.core.profile import Profile
from reference.core.tolerances import VEL_TOL_MM_S

from ..grid import Grid, grid_on, with_nodes
from ..jerk.tolerances import DEFAULT_JERK_MAX_GRID
from ..jerk.transcription import JerkProblem, PhaseRows, build_jerk_problem
from ..jerk.upper import resolved
from .jerk_adapted import ADAPT_TREND_REL, without_jerk
from .lower import segment_periods
from .upper import Candidate, verified

__all__ = ["PHASE_NLP_ROUNDS", "phase_nlp"]

#: NLP rounds at most (each from the phases of the last; they end where a round's
#: motion has the phases of the one before, whose NLP it would solve again).
PHASE_NLP_ROUNDS = 3
#: From the second round on, each phase grows into the constant-speed intervals beside it
#: by up to this share of its ``1/f`` at each end (:func:`_grown`): the first round keeps
#: the seed's phases and its motion has them again, so without growing the rounds stop
#: there.
PHASE_GROW = 0.5
#: From the second round on, two neighbouring phases of one sign are joined into one
#: (:func:`_merged`) where the constant-speed stretch between them lasts at most this
#: many times their ``1/f``: a fall to a cap, a short stretch at it and a fall further
#: take two phases of ``1/f`` each, and one phase through the cap may do both changes at
#: full acceleration.
PHASE_MERGE_GAP = 1.0
#: After the rounds, one trial (:func:`_flattened`): a phase between two of the other sign
#: whose speed change is at most this share of the smaller of theirs is joined with them
#: into one phase of their sign. Not a relaxation (the joined phase forbids the bump), so
#: its rounds are kept only where they are faster. Measured on lcnc_test_12mmflat
#: (``acc+freq``): 0.25 and 0.5 flatten the same 2 wiggles (38.1831 -> 38.1272 s); at 1
#: and 3, 49 and 65, and the first round's motion is not accepted.
PHASE_WIGGLE_REL = 0.5
#: A round whose motion the checker slows down by more than this share (s/s) is solved
#: again with the acceleration rows lowered in the blocks where it breaks the axis
#: acceleration (:func:`_eased`), at most :data:`PHASE_REFINE_MAX` times.
PHASE_REFINE_SCALE = 1e-3
PHASE_REFINE_MAX = 2
#: The rounds stop when one is not faster than the fastest before it by this share
#: (s/s): the next would start from nearly the same phases. Measured on
#: lcnc_test_12mmflat (``jerk+freq``): round 2 38.9363 s, round 3 38.9368 s.
PHASE_MIN_GAIN = 1e-3
#: What :func:`_eased` lowers the rows by beyond the checker's ratio, relative: the
#: peak between the nodes moves a little with the motion.
PHASE_EASE_MARGIN = 1e-3


def phase_nlp(path: Path, limits: MachineLimits, grid_s: np.ndarray, start: Profile, *,
              holds: Holds = NO_HOLDS, rounds: int = PHASE_NLP_ROUNDS,
              progress: Callable[[str], object] | None = None,
              bounds: str = "jerk+freq", grow: float = PHASE_GROW,
              merge: float = PHASE_MERGE_GAP, wiggle: float = PHASE_WIGGLE_REL,
              enough: float = 0.0) -> list[Candidate]:
    """The rounds of the module docstring.

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
    bounds : {"jerk+freq", "acc+freq"}
        The bound set the motions are judged under; ``acc+freq``: the NLP without its
        jerk and acceleration-step rows.
    grow : float
        :data:`PHASE_GROW`: share of a phase's ``1/f`` it grows by at each end from the
        second round on.
    merge : float
        :data:`PHASE_MERGE_GAP`: from the second round on, two neighbouring phases of
        one sign are joined where the stretch between them lasts at most this many
        times their ``1/f`` (:func:`_merged`); 0 or less: none is joined.
    wiggle : float
        :data:`PHASE_WIGGLE_REL`: after the rounds, the trial from the fastest motion
        with every phase whose change is at most this share of its two neighbours'
        joined with them (:func:`_flattened`); 0 or less: no trial.
    enough : float
        s. The rounds stop once one's motion (holds excluded) takes at most this long:
        the caller's bracket is met and a further round would cost time only. 0: run
        until :data:`PHASE_MIN_GAIN` or ``rounds`` stops them.

    Returns
    -------
    list of Candidate
        Every verified round, named ``"phase NLP, round k"`` (the trial's
        ``"phase NLP, wiggles flattened, round k"``).
    """
    if bounds not in ("jerk+freq", "acc+freq"):
        raise ValueError(f"bound set {bounds!r}: must be 'jerk+freq' or 'acc+freq'")
    lim = limits.for_axes(path.axes)
    if bounds == "acc+freq":
        grid_s = _with_step_nodes(grid_s, start, limits.t_ipo_s)
    grid = grid_on(path, grid_s)
    if grid.n_intervals > DEFAULT_JERK_MAX_GRID:
        return []

    def problem_on(grid: Grid) -> JerkProblem:
        problem = build_jerk_problem(path, lim, grid, limits.t_ipo_s, holds.break_index)
        return without_jerk(problem) if bounds == "acc+freq" else problem

    problem = problem_on(grid)
    attempts = None

    def run(prof: Profile, name: str, first_grow: float, flatten: float) -> list[Candidate]:
        """The rounds from ``prof``; the first with ``first_grow`` and ``flatten``."""
        nonlocal problem, attempts
        out: list[Candidate] = []
        last = None
        for r in range(rounds):
            seed = prof
            prob_r = _with_phases(path, lim, grid, problem, seed,
                                  first_grow if r == 0 else grow, merge,
                                  flatten if r == 0 else 0.0)
            if prob_r is None or (last is not None and _same_phases(prob_r.phases, last)):
                break      # no phase, or the last round's phases again: the same NLP
            last = prob_r.phases
            for refined in range(PHASE_REFINE_MAX + 1):
                new, attempt = resolved(path, lim, grid, prob_r, seed, attempts)
                if new is None:
                    break
                attempts = (attempt,)              # as in optimal.freq.jerk_adapted
                c = verified(f"{name}, round {r + 1}", path, limits, new, bounds,
                             holds=holds)
                if c is None or c.time_scale <= 1.0 + PHASE_REFINE_SCALE or \
                        refined == PHASE_REFINE_MAX:
                    break
                # the motion breaks the axis acceleration between the nodes (on an
                # arc): the same round again with the rows of those blocks lowered
                eased = _eased(path, grid, problem, c)
                if eased is problem:
                    break
                out.append(c)
                problem = eased
                prob_r = replace(prob_r, acc=problem.acc)
            if new is None:
                break
            if progress:
                progress(f"NLP with the rule's rows ({name}), round {r + 1}"
                         + (f": {c.duration:.4f} s" if c is not None else ": not accepted"))
            if c is None:
                break
            best = min((o.duration for o in out), default=np.inf)
            out.append(c)
            prof = c.profile
            if c.duration <= enough or c.duration > best * (1.0 - PHASE_MIN_GAIN):
                break      # the bracket is met, or the rounds no longer gain
        return out

    out = run(start, "phase NLP", 0.0, 0.0)
    best = min(out, key=lambda c: c.duration, default=None)
    if wiggle > 0 and best is not None and best.duration > enough:
        # the trial: the fastest motion's wiggles flattened, and the rounds from there
        out += run(best.profile, "phase NLP, wiggles flattened", grow, wiggle)
    return out


def _eased(path: Path, grid: Grid, problem: JerkProblem, c: Candidate) -> JerkProblem:
    """``problem`` with the axis-acceleration rows of every block where the checker
    found ``c``'s acceleration above its limit lowered by that block's ratio (and
    :data:`PHASE_EASE_MARGIN`): the NLP keeps the limit at its nodes, and on an arc the
    axis acceleration peaks between them."""
    ratio = np.asarray(c.report.block_ratios.get("acceleration", np.zeros(0)))
    if ratio.size == 0 or not np.any(ratio > 1.0):
        return problem
    acc, N = problem.acc, grid.n_intervals
    # each row's interval: its node's, or the one before where the row is the arriving
    # one at a break (its acceleration one of the extras) or at the path's end
    iv = np.where((problem.acc_index > N) | (acc.node >= N), acc.node - 1, acc.node)
    blk = path.block[grid.segment[np.clip(iv, 0, N - 1)]]
    r = np.where(blk < ratio.size, ratio[np.minimum(blk, ratio.size - 1)], 0.0)
    scale = np.where(r > 1.0, 1.0 / (r * (1.0 + PHASE_EASE_MARGIN)), 1.0)
    return replace(problem, acc=replace(acc, limit=acc.limit * scale))


def _with_step_nodes(grid_s: np.ndarray, prof: Profile, t_ipo: float) -> np.ndarray:
    """``grid_s`` (mm, shape (N + 1,)) with nodes at the phase ends of ``prof`` and one
    IPO cycle of its speed on either side of each, mm, sorted.

    Without jerk rows the motion's acceleration may step where a phase begins or ends
    (as a ramp of the ``acc`` set does), but the NLP's acceleration is continuous at a
    node and linear in time across an interval, so a step costs the time of the
    interval it is spread over; the nodes make that interval one IPO cycle long and put
    the phase's end on a node (they are rounded to the nodes)."""
    ph = acceleration_phases(prof)
    if ph.n == 0:
        return grid_s
    s_b = np.concatenate((prof.s[ph.first], prof.s[ph.last + 1]))
    d = np.interp(s_b, prof.s, prof.v) * t_ipo
    new = np.concatenate((s_b, s_b - d, s_b + d))
    # none within the round-off of the positions (1e-9 of the path) of another node
    return with_nodes(grid_s, new, 1e-9 * max(grid_s[-1] - grid_s[0], 1.0))


def _same_phases(a: PhaseRows, b: PhaseRows) -> bool:
    """Whether two sets of phase rows cover the same intervals with the same signs."""
    return (a.first.size == b.first.size and bool(np.all(a.first == b.first))
            and bool(np.all(a.stop == b.stop)) and bool(np.all(a.sign == b.sign)))


def _grown(keep: list, grow: float, grid: Grid, prof: Profile,
           period: np.ndarray) -> list:
    """The phases ``keep`` (``(first interval, stop, sign, 1/f)``, in order) each grown
    at both ends into the constant-speed intervals beside it, by up to ``grow`` times
    its ``1/f`` of ``prof``'s time (whole intervals), s; never into an interval where
    ``prof`` is at rest at a node, at most to the middle of the intervals between two
    phases, and leaving one constant-speed interval between two phases of one sign
    (else the checker sees one phase). A grown phase takes the largest ``period``
    (``1/f`` per grid interval, s, shape (N,)) of its intervals.

    Where the grown intervals keep the phase's ``1/f``, growing only relaxes the NLP:
    the first extra interval of a rise at the speed ``v0`` it starts with adds ``tau``
    to ``T`` and ``v0 tau`` to ``ds``, so ``T v1 - ds`` grows by ``tau (v1 - v0) >= 0``
    and ``ds - T v0`` stays (alike at the end and for a fall), and the intervals'
    accelerations may stay as small as the trend margin. Where they move an axis of a
    smaller frequency the phase must last longer; the motion is judged either way."""
    t = np.interp(grid.s, prof.s, prof.t)
    v = np.interp(grid.s, prof.s, prof.v)
    moving = (v[:-1] > VEL_TOL_MM_S) & (v[1:] > VEL_TOL_MM_S)
    n = len(keep)
    # how far each phase may reach: to the middle of the gap to its neighbour
    lo_lim, hi_lim = [0] * n, [grid.n_intervals] * n
    for i in range(n - 1):
        b, a_next = keep[i][1], keep[i + 1][0]
        free = max(a_next - b - (keep[i][2] == keep[i + 1][2]), 0)
        hi_lim[i], lo_lim[i + 1] = b + free // 2, a_next - (free - free // 2)
    out = []
    for (a0, b0, sg, need), lo, hi in zip(keep, lo_lim, hi_lim):
        a, b = a0, b0
        while a > lo and moving[a - 1] and t[a0] - t[a - 1] <= grow * need:
            a -= 1
        while b < hi and moving[b] and t[b + 1] - t[b0] <= grow * need:
            b += 1
        out.append((a, b, sg, max(need, float(np.max(period[a:b])))))
    return out


def _merged(keep: list, grid: Grid, prof: Profile, period: np.ndarray,
            gap: float) -> list:
    """The phases ``keep`` (``(first interval, stop, sign, 1/f)``, in order) with every
    two neighbours of one sign joined into one phase where the intervals between them
    take at most ``gap`` times the larger ``1/f`` of ``prof``'s time and ``prof`` is in
    motion at each of their nodes. The joined phase spans both and the intervals
    between (crossed with the phase's sign at the trend margin) and takes the largest
    ``1/f`` of the three and of ``period`` (``1/f`` per grid interval, s, shape (N,))
    over the intervals between.

    Joining only relaxes the rows: the joined phase's acceleration-weighted mean time
    lies between the two phases' own, so where each lay ``1/(2f)`` from its ends it lies
    that far from the joined phase's ends too (``prof``'s crossing at constant speed
    misses the trend margin only, a tenth of a percent of the NLP's acceleration unit).
    What it frees: the change may be done at full acceleration on both sides of a cap
    and the cap passed in the slow middle of one phase (the second case of
    :mod:`reference.core.phases`), where two phases need ``1/f`` each."""
    t = np.interp(grid.s, prof.s, prof.t)
    v = np.interp(grid.s, prof.s, prof.v)
    out = [keep[0]] if keep else []
    for a, b, sg, need in keep[1:]:
        a0, b0, sg0, need0 = out[-1]
        if (sg == sg0 and t[a] - t[b0] <= gap * max(need, need0)
                and bool(np.all(v[b0:a + 1] > VEL_TOL_MM_S))):
            out[-1] = (a0, b, sg, max(need, need0, float(np.max(period[b0:a], initial=0.0))))
        else:
            out.append((a, b, sg, need))
    return out


def _flattened(keep: list, grid: Grid, prof: Profile, period: np.ndarray,
               rel: float) -> list:
    """The phases ``keep`` (``(first interval, stop, sign, 1/f)``, in order) with every
    *wiggle* joined with its neighbours: a phase between two of the other sign whose
    speed change (``prof``'s, from node to node) is at most ``rel`` times the smaller of
    theirs, ``prof`` in motion throughout; the three become one phase of the outer sign
    with the largest ``1/f`` of the three and of ``period`` (``1/f`` per grid interval, s,
    shape (N,)) over them. Taken from the left, none twice.

    Where a short curve between two low caps lets the speed rise a little (the first
    fall to the curve's cap, the bump, the fall to the corner after it), the bump costs
    two phases of ``1/f``, and the phases' places are fixed from round to round; joined,
    the fall may pass the curve in its creep. The joined phase forbids the bump, so this
    is not a relaxation: :func:`phase_nlp` runs it as a trial."""
    v = np.interp(grid.s, prof.s, prof.v)
    dv = [abs(v[b] - v[a]) for a, b, _, _ in keep]
    out, i = [], 0
    while i < len(keep):
        if (i + 2 < len(keep) and keep[i][2] == keep[i + 2][2] == -keep[i + 1][2]
                and dv[i + 1] <= rel * min(dv[i], dv[i + 2])
                and bool(np.all(v[keep[i][1]:keep[i + 2][0] + 1] > VEL_TOL_MM_S))):
            a, b = keep[i][0], keep[i + 2][1]
            need = max(keep[i][3], keep[i + 1][3], keep[i + 2][3], float(np.max(period[a:b])))
            out.append((a, b, keep[i][2], need))
            i += 3
        else:
            out.append(keep[i])
            i += 1
    return out


def _with_phases(path: Path, lim, grid: Grid, problem: JerkProblem,
                 prof: Profile, grow: float = 0.0, merge: float = PHASE_MERGE_GAP,
                 flatten: float = 0.0) -> JerkProblem | None:
    """``problem`` with the phases of ``prof`` (module docstring), where ``grow > 0``
    joined by ``merge`` (:func:`_merged`), flattened by ``flatten`` (:func:`_flattened`)
    and grown by ``grow`` (:func:`_grown`): the bounds on the accelerations and the rows;
    ``None`` where ``prof`` has no phase, or with ``flatten > 0`` no wiggle."""
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
    if grow > 0:
        period = segment_periods(path, lim)[grid.segment]
        if merge > 0:
            keep = _merged(keep, grid, prof, period, merge)
        if flatten > 0:
            n = len(keep)
            keep = _flattened(keep, grid, prof, period, flatten)
            if len(keep) == n:
                return None                # no wiggle: nothing to try
        keep = _grown(keep, grow, grid, prof, period)
        sign[:] = 0
        for a, b, sg, _ in keep:
            sign[a:b] = sg
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
