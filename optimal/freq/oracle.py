"""``optimal.solve(..., bounds="acc+freq" | "jerk+freq")``: the frequency-bounded oracle.

Pipeline (``base`` is ``acc`` or ``jerk``):

1. the ``base`` oracle and the ``acc`` oracle on the same path; the candidates are
   motions without the imposed holds (the holds are a constant added to both bounds and
   inserted at the end, as the other bound sets do; a motion with its holds cannot be
   time-scaled), each judged with the holds inserted
   (:func:`optimal.freq.upper.verified`): a hold rests at zero acceleration, which a
   motion crossing the stop decelerating on one side and accelerating the other way on
   the other breaks. So the ``jerk`` oracle runs with the holds (its NLP arrives at and
   leaves each one as at the path ends; its motion is taken out of its profile by
   :func:`reference.core.holds.without_holds`), and so does the jerk-adapted NLP;
2. lower bound: ``max`` of the base oracle's certified bound (``base`` is a relaxation
   of ``base+freq``: fewer constraints) and :func:`optimal.freq.lower.freq_lower_bound`
   (proof there), plus the holds; where the candidates of step 3 leave the bracket open,
   for ``jerk+freq`` the jerk relaxation again with rows of the rule on three segments
   at a time (:mod:`optimal.freq.windows`), and then the turn programme over the whole
   path (:mod:`optimal.freq.humps`; for ``jerk+freq`` its envelope lowered by the jerk
   set's reach out of every break, :func:`optimal.jerk.lower.reach_speed_caps`);
3. upper bound: the fastest of the verified candidates of :mod:`optimal.freq.upper`
   (the base optimum slowed down, the filtered acc optimum, for ``acc+freq`` the acc
   optimum with its rises and falls capped per hump (:mod:`optimal.freq.capped`), the
   motion under the caps
   adapted to the rule: unfiltered for ``acc+freq``, and filtered with the windows of
   :func:`~optimal.freq.upper.candidate_windows`, its caps eroded for each; for
   ``jerk+freq`` where these leave the bracket open, the jerk optimum re-solved under caps
   adapted to its own short phases, :mod:`optimal.freq.jerk_adapted`), and the fastest
   candidate per rest-to-rest piece, joined, the ramp plan of every piece among them
   (:mod:`optimal.freq.ramps`: humps of ramps of at least ``1/f`` per segment, S-curves
   for ``jerk+freq``, budgets that leave curves their centripetal part);
4. where the bracket is still open, the jerk NLP (for ``acc+freq`` without its jerk
   rows) with the rule's own rows on the fastest candidate's phases
   (:mod:`optimal.freq.phase_nlp`), and the fastest per piece again (the lower bound of
   step 2 holds for every motion no slower than the fastest candidate it was built for,
   so for the faster optimum too); for ``acc+freq``, where it is open still, the rule's
   rows in path position with the phases' ends free between the breaks, and a search
   over where they lie, from the fastest motion (:mod:`optimal.freq.free_phases`; its
   motion of each piece counts where the checker accepts it in that motion). Tried as a
   second seed of the ``jerk+freq`` NLP it did not help (lcnc_sam_tolerance_issue
   2.4375 -> 2.4430 s, the oracle 3.5 times slower), so it is not run there;
5. status ``optimal`` when ``(upper - lower) / lower <= tol``, else ``gap_not_met`` with
   both valid bounds; ``solver_error`` when no candidate could be verified.

Units: mm, s.
"""

from __future__ import annotations

import math
import time
from typing import Callable

import numpy as np

from reference.core.constraints import BOUND_SETS, check_profile, time_scale_factors_by_block
from reference.core.errors import ProfileError
from reference.core.geometry import Path
from reference.core.holds import NO_HOLDS, Holds, dwell_holds, with_holds, without_holds
from reference.core.limits import MachineLimits
from reference.core.tolerances import MIN_SEGMENT_LENGTH_MM
from reference.core.profile import Profile
from reference.core.rows import block_motion, block_rows

from ..solution import IterationRecord, OptimalSolution
from ..status import SolveStatus
from ..grid import grid_on, with_nodes
from ..jerk.oracle import jerk_grid
from ..jerk.lower import reach_nodes, reach_speed_caps, segment_envelope, speed_bounds
from ..jerk.relaxation import RunFloors
from .capped import capped_optimum
from .humps import humps_piece_bounds
from .jerk_adapted import ACC_ADAPT_INTERVALS, ACC_ADAPT_MAX_INTERVALS, jerk_adapted
from .phase_nlp import phase_nlp
from .free_phases import FREE_ACCEPT_SCALE, free_phase_motions
from .lower import freq_lower_bound, rest_pieces, segment_periods
from .ramps import ramp_plan
from .chains import chain_rows
from .windows import rule_envelope, window_lower_bound, window_rows
from .upper import (ERODED_REST_SHARE, Candidate, candidate_windows, eroded_plans,
                    fir_filtered, piece_times, pieced, scaled, verified)

ProgressFn = Callable[..., object]

#: Default requested gap (DESIGN/issue: 2 % where achievable).
DEFAULT_FREQ_GAP_TOL = 2e-2


def _reach_grid(work: Path, lim, t_ipo: float, acc_grid: np.ndarray, t_upper: float):
    """The ``acc`` grid (its nodes, mm) with the nodes of
    :func:`optimal.jerk.lower.reach_nodes`, and the reach caps
    (:func:`optimal.jerk.lower.reach_speed_caps`) at its nodes, mm/s: the ``jerk+freq``
    turn programme's envelope (:func:`optimal.freq.humps.humps_piece_bounds`,
    ``node_caps``)."""
    acc_s = np.asarray(acc_grid, dtype=np.float64)
    _, b_break, b_seg = speed_bounds(work, lim, t_ipo, acc_s)
    env = segment_envelope(work, lim, t_ipo, b_break, b_seg)
    # none within the segment-length floor of another node (no vanishing intervals)
    grid = grid_on(work, with_nodes(acc_s, reach_nodes(work, env), MIN_SEGMENT_LENGTH_MM))
    return grid, reach_speed_caps(work, env, grid.s, t_upper)


def _fastest_per_piece(path: Path, limits: MachineLimits, cands: list, local: dict,
                       name: str, holds: Holds = NO_HOLDS):
    """The fastest motion on each rest-to-rest piece, joined (:func:`pieced`) and judged
    (:func:`verified`); where the checker needs it slowed down, the pieces beside each
    piece that breaks a limit are joined from one motion instead (the faster pair of a
    candidate on both, or the ramp plans on both), and judged again, at most once per
    piece. Two motions meet at a stop at rest, but not always at the same acceleration:
    under ``jerk+freq`` the NLP's motions reach rest with some deceleration that their
    own next piece takes up in one IPO cycle, where a ramp plan starts at zero
    acceleration (examples/slot.ngc's zig-zag after a rapid move, cut out: an
    acceleration step of twice the jerk limit at the stop, the joined motion then
    slowed by 1.48). A motion joins its own
    pieces within the limits, and the ramp plans start and end at zero acceleration.
    Returns the fastest accepted join (``None`` if none is new)."""
    times = piece_times(path, cands, local)
    choice = np.argmin(times, axis=0)
    pieces = rest_pieces(path)
    best = None
    for _ in range(pieces.shape[0]):
        joined = pieced(path, cands, local, choice)
        if joined is None:
            break
        c = verified("fastest per piece", path, limits, joined, name, holds=holds)
        if c is not None and (best is None or c.duration < best.duration):
            best = c
        if c is not None and c.time_scale <= 1.0:
            break
        # the pieces whose blocks break a limit, and their joins to a piece of another
        # motion
        rep = c.report if c is not None else check_profile(
            path, limits, with_holds(joined, path, holds))
        per_block = time_scale_factors_by_block(rep, BOUND_SETS[name])
        bad = [k for k, (lo, hi) in enumerate(pieces)
               if np.max(per_block[path.block[lo:hi]], initial=1.0) > 1.0]
        new = choice.copy()
        for k in bad:
            for p in (k - 1, k):
                if 0 <= p < pieces.shape[0] - 1 and new[p] != new[p + 1]:
                    row = int(np.argmin(times[:, p] + times[:, p + 1]))
                    new[p] = new[p + 1] = row
        if np.array_equal(new, choice):
            break
        choice = new
    return best


def _free_phase_candidate(path: Path, limits: MachineLimits, seed: Candidate,
                          holds: Holds, enough: float,
                          progress: Callable[[str], object] | None = None
                          ) -> Candidate | None:
    """``seed`` (a verified candidate) with each rest-to-rest piece replaced by the
    fastest motion of :func:`optimal.freq.free_phases.free_phase_motions` that the
    checker accepts in it (judged with ``seed``'s other pieces and the holds, not slowed
    down by more than round-off); ``None`` where none is faster. ``enough``: s, holds
    excluded, where the search may stop."""
    pieces = rest_pieces(path)

    def joined(k: int, prof: Profile):
        choice = np.zeros(pieces.shape[0], np.int64)
        choice[k] = 1
        return pieced(path, [seed], {k: prof}, choice)

    def accept(k: int, prof: Profile) -> bool:
        p = joined(k, prof)
        c = verified("free phase ends", path, limits, p, "acc+freq", holds=holds) \
            if p is not None else None
        return c is not None and c.time_scale <= 1.0 + FREE_ACCEPT_SCALE

    found = free_phase_motions(path, limits.for_axes(path.axes), seed.profile,
                               accept=accept, enough=enough, progress=progress)
    if not found:
        return None
    choice = np.array([1 if k in found else 0 for k in range(pieces.shape[0])], np.int64)
    prof = pieced(path, [seed], found, choice)
    return (verified("free phase ends", path, limits, prof, "acc+freq", holds=holds)
            if prof is not None else None)


def _acc_nlp_grid(path: Path, limits: MachineLimits, acc: OptimalSolution) -> np.ndarray:
    """The grid of the NLP candidates under acc+freq, mm: one graded as the jerk oracle's
    first from the acc optimum, with the acc oracle's nodes (the acc grid alone is as
    coarse as straight lines allow)."""
    return np.unique(np.concatenate((jerk_grid(path, ACC_ADAPT_INTERVALS, limits, acc.profile,
                                               ACC_ADAPT_MAX_INTERVALS).s, acc.grid)))


def _acc_freq_seed(path: Path, limits: MachineLimits, acc: OptimalSolution, T_max: float,
                   holds: Holds) -> Profile | None:
    """The fastest of the acc+freq motion under the caps adapted to the rule
    (:func:`optimal.freq.upper.eroded_plans`, unfiltered) and the rounds of the NLP with
    the rule's rows under acc+freq from it, on the grid the acc+freq oracle gives that
    NLP; ``None`` where none passes the checker."""
    try:
        u = eroded_plans(path, limits, T_max, 0.0, False, False, 0.0)
    except ProfileError:
        return None
    c = verified("adapted caps", path, limits, u.profile, "acc+freq", u.rest_breaks, holds)
    if c is None:
        return None
    out = [c] + phase_nlp(path, limits, _acc_nlp_grid(path, limits, acc), c.profile,
                          holds=holds, bounds="acc+freq")
    return min(out, key=lambda x: x.duration).profile


def solve_freq(path: Path, limits: MachineLimits, *, solve: Callable[..., object],
               base: str = "jerk", tol: float = DEFAULT_FREQ_GAP_TOL, holds: Holds | None = None,
               progress: ProgressFn | None = None, jerk_tol: float | None = None
               ) -> OptimalSolution:
    """Minimum-time motion under ``base+freq``, with a certified bracket.

    Parameters
    ----------
    path : Path
    limits : MachineLimits
    solve : callable
        :func:`optimal.solve` (passed in by the dispatcher), for the inner ``base`` and
        ``acc`` solves.
    base : {"acc", "jerk"}
        The bound set the frequency rule is added to.
    tol : float
        Requested relative gap.
    holds : Holds, optional
        Imposed holds (default: the dwells of ``path.blocks``).
    progress : callable, optional
        ``progress(message, fraction)``.
    jerk_tol : float, optional
        Gap requested from the inner jerk solve (default ``tol / 2``: half the bracket
        for the base set, the other half for the frequency rule).

    Returns
    -------
    OptimalSolution
        ``bounds = base + "+freq"``; ``active`` names ``frequency`` on every interval
        when the frequency rule decided the upper bound, else the base solve's labels.
    """
    t_start = time.perf_counter()
    if holds is None:
        holds = dwell_holds(path)
    hold_t = holds.total_s
    name = f"{base}+freq"
    if base not in ("acc", "jerk"):
        raise ValueError(f"base bound set {base!r}: must be 'acc' or 'jerk'")
    sub = (lambda msg, f=-1.0: progress(f"{base}: {msg}", 0.8 * max(f, 0.0))) if progress \
        else None
    if path.n_segments == 0:
        from dataclasses import replace
        return replace(solve(path, limits, "acc", holds=holds), bounds=name)
    if base == "jerk":
        jt = jerk_tol if jerk_tol else tol / 2
        # with the holds: the jerk NLP then rests at zero acceleration at each of them
        # (a stop crossed decelerating on one side and accelerating the other way on the
        # other is no motion once the hold is in); its bound and motion without them
        base_sol = solve(path, limits, "jerk", tol=jt, holds=holds, progress=sub)
        base_lb = base_sol.lower_bound_s - hold_t
        base_prof = (None if base_sol.profile is None
                     else without_holds(base_sol.profile, path, holds))
        acc = solve(path, limits, "acc", holds=NO_HOLDS)
    else:
        base_sol = acc = solve(path, limits, "acc", holds=NO_HOLDS, progress=sub)
        base_lb, base_prof = base_sol.lower_bound_s, base_sol.profile
    moving = path.moving_axes()
    work = path.restricted(moving) if 0 < moving.size < path.n_axes else path
    tb = time.perf_counter()
    lb_freq = freq_lower_bound(work, limits.for_axes(work.axes))
    lb = max(base_lb, lb_freq) + hold_t
    t_bound = base_sol.bound_time_s + (acc.bound_time_s if acc is not base_sol else 0.0) \
        + time.perf_counter() - tb
    tc = time.perf_counter()
    if progress:
        progress("frequency rule: candidate motions", 0.8)
    cands = []
    if base_prof is not None:
        c = scaled(path, limits, base_prof, name, holds)
        if c is not None:
            cands.append(c)
    if acc.profile is not None:
        prof = acc.profile
        if np.any(prof.j != 0.0):
            # the acc optimum's pieces with jerk (on curves) as constant-acceleration
            # pieces through the same knots (v^2 linear in s between them): the filter's
            # exact integration needs that form; the checker judges the result anyway
            prof = Profile.from_path_velocity(prof.s, prof.v, prof.block)
        c = verified("fir (acc)", path, limits,
                     fir_filtered(path, limits, prof, base == "jerk"), name, holds=holds)
        if c is not None:
            cands.append(c)
        if base == "acc":
            # the acc optimum with each hump's rise and fall rates capped until its phases
            # pass the rule (optimal.freq.capped): on curves it keeps the axes' budget
            # where the ramps of one constant cannot
            capped = capped_optimum(path, limits, prof)
            c = verified("capped acc optimum", path, limits, capped, name, holds=holds) \
                if capped is not None else None
            if c is not None:
                cands.append(c)
    # motions under the caps, adapted to the rule (optimal.freq.upper.eroded_plans):
    # unfiltered for acc+freq, and through moving averages of a few windows (caps eroded
    # for each, so that the filtered motion keeps them where it arrives)
    sub_lim = limits.for_axes(work.axes)
    T_max = float(np.max(segment_periods(work, sub_lim), initial=0.0))
    jerk = base == "jerk"
    for W in (candidate_windows(work, sub_lim, T_max, jerk) if T_max > 0 else ()):
        # (jerk reach, rest share): the variants of optimal.freq.upper.eroded_plans,
        # none always faster
        variants = ((False, 0.0), (False, ERODED_REST_SHARE)) if W == 0 else (
            ((False, 0.0), (True, 0.0), (True, ERODED_REST_SHARE)) if jerk
            else ((False, 0.0), (False, ERODED_REST_SHARE)))
        for reach, rest_share in variants:
            try:
                u = eroded_plans(path, limits, T_max, W, jerk, reach, rest_share)
            except ProfileError:
                # the eroded caps leave an interval at zero speed at both ends (cannot
                # be crossed): no candidate from this construction
                continue
            prof = fir_filtered(path, limits, u.profile, jerk, u.rest_breaks,
                                window_s=W) if W > 0 else u.profile
            label = (f"fir {W * 1e3:.3g} ms (eroded caps{', jerk reach' if reach else ''}"
                     f"{', slow corners at rest' if rest_share else ''})" if W > 0
                     else f"adapted caps{' (slow corners at rest)' if rest_share else ''}")
            c = verified(label, path, limits, prof, name, u.rest_breaks, holds)
            if c is not None:
                cands.append(c)
    grids: list[np.ndarray] = []

    def nlp_grid() -> np.ndarray:
        # the NLP candidates' grid (built once): the jerk oracle's final one, or
        # _acc_nlp_grid's
        if not grids:
            grids.append(base_sol.grid if base == "jerk" else _acc_nlp_grid(path, limits, acc))
        return grids[0]

    if (base_prof is not None and cands
            and min(c.duration for c in cands) + hold_t - lb > tol * lb):
        # the base optimum re-solved by the NLP where it breaks the rule
        # (optimal.freq.jerk_adapted)
        grid_s = nlp_grid()
        # (widen, asymmetric): the variants of optimal.freq.jerk_adapted, none always
        # faster; without a jerk limit the NLP also needs the widened bounds
        variants = ((False, True), (False, False)) if base == "jerk" else (
            (False, True), (False, False), (True, True), (True, False))
        for widen, asym in variants:
            if min(c.duration for c in cands) + hold_t - lb <= tol * lb:
                break      # the bracket is met: the next variants cannot matter
            cands += jerk_adapted(path, limits, grid_s, base_prof, bounds=name,
                                  widen=widen, asymmetric=asym, holds=holds,
                                  progress=(lambda msg: progress(msg, 0.85))
                                  if progress else None)
    # pieces start and end at rest: the fastest candidate on each, joined, the ramp plan
    # of every piece among them (optimal.freq.ramps: S-curve ramps for jerk+freq)
    local = ramp_plan(path, limits, jerk=base == "jerk")
    c = _fastest_per_piece(path, limits, cands, local, name, holds) if cands else None
    if c is not None:
        cands.append(c)
    t_check = time.perf_counter() - tc
    win_rows = None
    if (base == "jerk" and cands and base_sol.segment_lower_bounds_s is not None
            and min(c.duration for c in cands) + hold_t - lb > tol * lb):
        # the jerk relaxation again, with rows of the frequency rule on the segments
        # whose rise and fall it lengthens (optimal.freq.windows: a slow segment between
        # low corner caps), for the motions no slower than the fastest candidate
        if progress:
            progress("frequency lower bound: the jerk relaxation with the rule's rows", 0.88)
        tb = time.perf_counter()
        t_fast = min(c.duration for c in cands)
        # the rule's bounds once for both kinds of rows (an acc relaxation on its grid)
        args = (work, sub_lim, limits.t_ipo_s, acc.grid, base_sol.segment_lower_bounds_s,
                t_fast, holds.break_index)
        rule = rule_envelope(work, sub_lim, limits.t_ipo_s, acc.grid, t_fast,
                             holds.break_index)
        win_rows = window_rows(*args, rule=rule).joined(chain_rows(*args, rule=rule))
        lb_win = window_lower_bound(work, sub_lim, limits.t_ipo_s, base_sol.grid,
                                    base_sol.segment_lower_bounds_s, win_rows, t_fast,
                                    holds.break_index)
        t_bound += time.perf_counter() - tb
        if lb_win + hold_t > lb:
            lb, lb_freq = lb_win + hold_t, max(lb_freq, lb_win)
    if cands and (min(c.duration for c in cands) + hold_t - lb) > tol * lb:
        # the frequency rule over the whole path (optimal.freq.humps), from the acc
        # relaxation's speed envelope; a verified upper bound limits the motions it must
        # hold for (slower ones are not the minimum), which bounds the drift of the
        # phases' threshold
        if progress:
            progress("frequency lower bound: where the motion turns", 0.9)
        tb = time.perf_counter()
        # the programme holds for the motions no slower than t_up, so min(bound, t_up)
        # for every motion, whatever t_up is: under jerk+freq the acc+freq motion of
        # ramps (optimal.freq.ramps), where it covers the path, may stand in for the
        # slower jerk+freq candidates (less drift in step 2, and the same as the acc+freq
        # oracle takes where that motion is its upper bound, so that the jerk set's
        # bound, with its segment floors, is not below it)
        t_best = min(c.duration for c in cands)
        t_up = t_best
        if base == "jerk":
            plan = ramp_plan(path, limits)
            if plan and len(plan) == rest_pieces(work).shape[0]:
                t_up = min(t_up, sum(p.duration for p in plan.values()))
        # the bound that meets the bracket (holds excluded): where the programme comes
        # near it, it cuts its cells finer where its motion turns (the turn run)
        enough = (t_best + hold_t) / (1.0 + tol) - hold_t
        env_grid, caps = grid_on(work, acc.grid), None
        if base == "jerk":
            # the jerk set's reach out of every break (optimal.jerk.lower step 7) as
            # node caps of the programme's envelope, on nodes added where it bends;
            # valid for every motion lasting at most t_best (>= t_up): both runs below
            env_grid, caps = _reach_grid(work, sub_lim, limits.t_ipo_s, acc.grid, t_best)
        per_piece = humps_piece_bounds(work, sub_lim, env_grid, t_up, lb - hold_t,
                                       base_sol.segment_lower_bounds_s, enough=enough,
                                       node_caps=caps)
        raw, t_valid = float(np.sum(per_piece)), t_up
        lb_humps = min(raw, t_up)
        if raw >= t_up and t_up < t_best:
            # the stand-in motion capped the bound (every motion no slower than it is
            # slower than the bound, so none is faster than it): the programme again
            # for the motions no slower than the verified one, min(bound, t) being a
            # bound for any t (examples/slot.ngc's zig-zag after a rapid move, cut out:
            # the programme reached the acc+freq ramps' 1.374 s; for the motions up to the
            # verified 1.467 s it shows 1.414 s, the zig-zag's own ramps)
            per_piece = humps_piece_bounds(work, sub_lim, env_grid, t_best,
                                           max(lb - hold_t, lb_humps),
                                           base_sol.segment_lower_bounds_s, enough=enough,
                                           node_caps=caps)
            raw, t_valid = float(np.sum(per_piece)), t_best
            lb_humps = max(lb_humps, min(raw, t_best))
        if (win_rows is not None and raw < t_valid
                and t_best + hold_t - max(lb, lb_humps + hold_t)
                > tol * max(lb, lb_humps + hold_t)):
            # the programme's bound of each piece as a row of the jerk relaxation, with
            # the window rows: the relaxation then keeps its segment floors and coupling
            # where the programme bounds only the piece's total (examples/slot.ngc: the
            # zig-zag's rises and falls of 1/f beside the jerk floors of the lines after
            # it, in one piece); the window rows hold for the motions no slower than the
            # fastest candidate, so for those no slower than t_valid too
            if progress:
                progress("frequency lower bound: the jerk relaxation with the programme's "
                         "rows", 0.95)
            pieces = rest_pieces(work)
            lb_humps = max(lb_humps, window_lower_bound(
                work, sub_lim, limits.t_ipo_s, base_sol.grid, base_sol.segment_lower_bounds_s,
                win_rows.joined(RunFloors(pieces[:, 0], pieces[:, 1], per_piece)), t_valid,
                holds.break_index))
        t_bound += time.perf_counter() - tb
        if lb_humps + hold_t > lb:
            lb, lb_freq = lb_humps + hold_t, max(lb_freq, lb_humps)
    if ((base == "jerk" or base_prof is not None) and cands
            and min(x.duration for x in cands) + hold_t - lb > tol * lb):
        # the bracket is still open: the jerk NLP (for acc+freq without its jerk rows)
        # with the rule's own rows on the fastest motion's phases (optimal.freq.
        # phase_nlp), then the fastest per piece again. The lower bound stands: its rows
        # hold for the motions no slower than the fastest candidate before, so for the
        # optimum, which is faster still
        if progress:
            progress("NLP with the rule's rows", 0.96)
        tp = time.perf_counter()
        seed = min(cands, key=lambda x: x.duration)
        say = (lambda msg: progress(msg, 0.97)) if progress else None
        # a round whose motion meets the bracket ends the rounds (holds excluded)
        met_by = lb * (1.0 + tol) - hold_t
        more = phase_nlp(path, limits, nlp_grid(), seed.profile, holds=holds, progress=say,
                         bounds=name, enough=met_by)
        if (base == "jerk" and acc.profile is not None and T_max > 0
                and min(x.duration for x in cands + more) + hold_t - lb > tol * lb):
            # the phases of the acc+freq set's fastest motion of this kind (the adapted
            # caps, then the NLP with the rule's rows under acc+freq) as a second seed:
            # the jerk NLP then follows its phases, which the jerk set's own motions do
            # not find (lcnc_sam_tolerance_issue 2.48 -> 2.44 s)
            seed2 = _acc_freq_seed(path, limits, acc, T_max, holds)
            if seed2 is not None:
                more += phase_nlp(path, limits, base_sol.grid, seed2, holds=holds,
                                  progress=say, bounds=name, enough=met_by)
        if more:
            cands += more
            c = _fastest_per_piece(path, limits, cands, local, name, holds)
            if c is not None:
                cands.append(c)
        if base == "acc" and min(x.duration for x in cands) + hold_t - lb > tol * lb:
            # still open: the rule's rows in path position with the phases' ends free
            # between the breaks, and a search over where they lie (optimal.freq.
            # free_phases), from the fastest motion; the same lower bound stands
            c = _free_phase_candidate(path, limits, min(cands, key=lambda x: x.duration),
                                      holds, met_by,
                                      (lambda msg: progress(msg, 0.98)) if progress else None)
            if c is not None:
                cands.append(c)
        t_check += time.perf_counter() - tp
    inner = (base_sol,) if acc is base_sol else (base_sol, acc)
    common = dict(grid=base_sol.grid, grid_points=base_sol.grid_points, iterations=base_sol.iterations,
                  backend=base_sol.backend, build_time_s=sum(x.build_time_s for x in inner),
                  solve_time_s=sum(x.solve_time_s for x in inner),
                  check_time_s=sum(x.check_time_s for x in inner) + t_check,
                  bound_time_s=t_bound, dwell_s=base_sol.dwell_s if holds is NO_HOLDS else
                  float(sum(d for d, c_ in zip(holds.duration_s, holds.cause)
                            if c_ == "dwell")),
                  holds=holds, bounds=name)
    if not cands:
        return OptimalSolution(
            status=SolveStatus.SOLVER_ERROR, profile=None, lower_bound_s=lb,
            upper_bound_s=math.inf, objective_s=math.inf, gap=math.inf, time_scale=1.0,
            segment_times_s=np.full(path.n_segments, np.nan), block_times_s=np.zeros(0),
            blocks=(), active=(), total_time_s=time.perf_counter() - t_start,
            history=(IterationRecord(base_sol.grid_points, lb, math.inf, math.inf, 1.0),),
            message=f"no candidate motion passed the checker under {name}", **common)
    best = min(cands, key=lambda c: c.duration)
    ub = best.duration + hold_t
    gap = (ub - lb) / lb if lb > 0 else math.inf
    status = SolveStatus.OPTIMAL if gap <= tol else SolveStatus.GAP_NOT_MET
    prof_h = with_holds(best.profile, path, holds)
    # the frequency rule decided unless the winner is the base optimum as it is
    freq_decides = best.name != f"{base} scaled" or best.time_scale > 1.0
    active = (("frequency",) * len(base_sol.active)) if freq_decides else base_sol.active
    base_cause = [r.cause for r in base_sol.blocks] if len(base_sol.blocks) == len(path.blocks) \
        else ["none" if b.n_segments > 0 else b.stop_reason for b in path.blocks]
    causes = [("frequency" if freq_decides and b.n_segments > 0 else c_)
              for b, c_ in zip(path.blocks, base_cause)]
    hold = None
    if path.blocks:
        idx = np.array([b.block for b in path.blocks], dtype=np.int64)
        hold = holds.per_block(int(idx.max()) + 1)[idx]
    rows = block_rows(path, block_motion(path, prof_h), causes, hold) if path.blocks else ()
    names = ", ".join(f"{c.name} {c.duration + hold_t:.6g} s (x{c.time_scale:.4g})"
                      for c in cands)
    lb_src = "frequency rule" if lb_freq > base_lb else f"{base} oracle"
    message = (f"gap {gap:.4%} {'<=' if status == SolveStatus.OPTIMAL else '>'} {tol:.4%}; "
               f"bracket [{lb:.6g}, {ub:.6g}] s, lower bound from the {lb_src}, "
               f"candidates: {names}")
    if progress:
        progress("done", 1.0)
    return OptimalSolution(
        status=status, profile=prof_h, lower_bound_s=lb, upper_bound_s=ub,
        objective_s=best.duration + hold_t, gap=gap, time_scale=best.time_scale,
        segment_times_s=prof_h.segment_times(path), block_times_s=prof_h.block_times(path),
        blocks=rows, active=active, total_time_s=time.perf_counter() - t_start,
        report=best.report, history=(IterationRecord(base_sol.grid_points, lb, ub,
                                                      best.duration + hold_t,
                                                      best.time_scale),),
        message=message, **common)
