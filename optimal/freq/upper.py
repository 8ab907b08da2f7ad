"""Verified upper bounds for the frequency bound sets ``acc+freq`` and ``jerk+freq``.

Candidate motions, each judged by ``check_profile`` and slowed down until it
passes every constraint of the set (:func:`reference.core.constraints.time_scale_factor`:
stretching time by ``lam`` divides velocity by ``lam``, acceleration by ``lam^2``, jerk by
``lam^3`` and multiplies every phase duration by ``lam``, so the scaled motion is accepted
whatever the candidate was). The faster accepted one is the upper bound.

1. **The base optimum (acc or jerk), slowed down** (:func:`scaled`): exact and cheap;
   tight where its phases already last ``1/f`` (long moves, low frequencies), poor where a
   single short phase forces the whole motion slower.
2. **The acc optimum through a moving-average (FIR) filter of window ``W_k`` per
   rest-to-rest piece** (:func:`fir_filtered`; Biagiotti & Melchiorri 2012,
   spec/oracle-formulations 1.8). Per piece ``u(t) = (1/W) int_{t-W}^{t} v dt``: the
   acceleration becomes ``(v(t) - v(t-W))/W``, continuous, and the jerk ``(a(t) -
   a(t-W))/W``, piecewise constant because the acc optimum's acceleration is
   (representable exactly as a :class:`Profile`). What it preserves, checked rather than
   assumed: on a straight line the filtered speed and acceleration are averages of
   feasible ones (within the limits), the jerk is at most ``2 A / W``, and a rest-to-rest
   move of one rise and one fall gets phases of at least ``W`` and lasts ``W`` longer
   (the closed form of DESIGN 6 with the acc profile's own ramps added). It does **not**
   hold in general: on a path the filtered motion reaches a position later than the
   original and carries its speed there (a corner cap can be exceeded), the jerk bound
   ``2 A / W`` may exceed the machine's, and a speed that rises and falls within ``W``
   leaves shorter phases. Each of these shows in the checker's report and is paid for
   by the time scaling. Pieces are filtered separately so that every stop stays at rest.

3. **A motion under the caps, adapted to the rule, filtered or not**
   (:func:`eroded_plans`, :func:`window_caps`): the speed caps (feed, axis speeds,
   corners, curvature) lowered so that a moving average of window ``W`` keeps them where
   it arrives, dips widened and bumps cut so that the filter leaves no short phase, short
   phases stretched as the control's adaptation does (to ``1/f - W``: the filter adds
   ``W``); then filtered. ``jerk+freq`` tries a few windows
   (:func:`candidate_windows`: the filter also spreads every acceleration step into a
   jerk-limited ramp), with u's acceleration kept to the jerk room the curvature terms
   leave (at each interval, or over the distance the filter lags behind);
   ``acc+freq`` also the motion itself, unfiltered and not eroded, its phases stretched
   to the full ``1/f``, which is the closest to the acc optimum.
   They win on paths with corners and arcs, where the filtered optimum overshoots.

Every candidate is slowed down per rest-to-rest piece (:func:`verified`) until the
checker accepts it. A time-domain NLP over phase durations (CasADi) could be tighter but
would need its own verification anyway; the candidates are exact constructions whose
only certificate is the checker, as for the other bound sets.

Units: mm, s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.core.arrays import concat_ranges
from reference.core.constraints import (BOUND_SETS, ConstraintReport, check_profile,
                                        scale_time, time_scale_factor,
                                        time_scale_factors_by_block)
from reference.core.geometry import Path
from reference.core.errors import ProfileError
from reference.core.holds import NO_HOLDS, Holds, with_holds
from reference.core.limits import MachineLimits
from reference.core.phases import (acceleration_phases, min_phase_duration,
                                   moving_axes_by_segment, phase_frequencies)
from reference.core.profile import Profile
from reference.core.rules import curvature_jump_speed_cap
from reference.core.tolerances import ROUNDOFF_MARGIN_REL

from .lower import path_rate_bounds, rest_pieces, segment_periods

__all__ = ["Candidate", "ErodedPlan", "candidate_windows", "eroded_plans", "fir_filtered",
           "piece_times", "pieced", "scaled", "verified", "window_caps"]



@dataclass(frozen=True, slots=True, eq=False)
class Candidate:
    """A verified motion (holds excluded).

    Attributes
    ----------
    name : str
        ``"jerk scaled"`` or ``"fir"``.
    profile : Profile
        The accepted (time-scaled) motion.
    time_scale : float
        Factor it was slowed down by.
    report : ConstraintReport
        The checker's report before scaling.
    """

    name: str
    profile: Profile
    time_scale: float
    report: ConstraintReport

    @property
    def duration(self) -> float:
        return self.profile.duration


def verified(name: str, path: Path, limits: MachineLimits, prof: Profile,
             bounds: str = "jerk+freq", rest_breaks: np.ndarray | None = None,
             holds: Holds = NO_HOLDS) -> Candidate | None:
    """Check ``prof`` and slow it down until ``bounds`` holds; ``None`` if it cannot.

    ``prof`` is the motion without the holds; it is judged as it will be reported, with
    ``holds`` inserted (:func:`reference.core.holds.with_holds`): a hold's zero
    acceleration between the arriving and the leaving motion is two acceleration steps
    the motion alone does not show (a stop crossed decelerating on one side and
    accelerating the other way on the other). Time scaling applies to the motion; the
    holds keep their durations.

    Each rest-to-rest piece is first slowed down by its own factor (the largest
    :func:`~reference.core.constraints.time_scale_factors_by_block` of its blocks):
    pieces start and end at rest, so stretching one leaves the others as they are. If
    that motion is not accepted (a violation the per-block ratios do not place, round-off
    at a stop), the whole motion is stretched by the single factor instead.
    ``rest_breaks``: further breaks where ``prof`` is at rest (pieces end there too).
    """
    cons = BOUND_SETS[bounds]

    def judge(p: Profile) -> ConstraintReport:
        return check_profile(path, limits, with_holds(p, path, holds))

    rep = judge(prof)
    lam = time_scale_factor(rep, cons)
    if not np.isfinite(lam):
        return None
    if lam <= 1.0:
        return Candidate(name, prof, 1.0, rep)
    per_block = time_scale_factors_by_block(rep, cons)
    pieces = rest_pieces(path, rest_breaks)
    if per_block.size and pieces.shape[0] > 1:
        lam_k = np.array([float(np.max(per_block[path.block[lo:hi]], initial=1.0))
                          for lo, hi in pieces])
        if np.all(np.isfinite(lam_k)):
            out = _scale_pieces(path, prof, pieces, lam_k)
            if judge(out).ok(cons):
                return Candidate(name, out, float(np.max(lam_k)), rep)
    out = scale_time(prof, lam)
    # the scaling argument is exact, but round-off at ratio 1 is judged once more
    if not judge(out).ok(cons):
        out = scale_time(out, 1.0 + 1e-9)
        if not judge(out).ok(cons):
            return None
    return Candidate(name, out, lam, rep)


def _scale_pieces(path: Path, prof: Profile, pieces: np.ndarray, lam_k: np.ndarray) -> Profile:
    """``prof`` with the time of piece ``k`` stretched by ``lam_k[k]`` (>= 1).

    Interval ``i`` belongs to the piece holding its mid position; its duration is
    multiplied by ``lam``, ``a`` divided by ``lam^2``, ``j`` by ``lam^3`` and its start
    speed by ``lam``, as :func:`~reference.core.constraints.scale_time` does for the whole.
    At a stop the speed is at most ``VEL_TOL_MM_S``, so the two pieces meet within it.
    """
    h = np.diff(prof.t)
    mid = 0.5 * (prof.s[:-1] + prof.s[1:])
    starts = path.s_breaks[pieces[:, 0]]
    k = np.clip(np.searchsorted(starts, mid, side="right") - 1, 0, lam_k.size - 1)
    lam = lam_k[k]
    t = np.concatenate(([0.0], np.cumsum(h * lam)))
    v = prof.v / np.concatenate((lam, lam[-1:]))
    return Profile(t=t, s=prof.s, v=v, a=prof.a / lam ** 2, j=prof.j / lam ** 3,
                   block=prof.block)


def piece_times(path: Path, candidates: list[Candidate],
                local: dict[int, Profile] | None = None) -> np.ndarray:
    """Time of each candidate on each rest-to-rest piece, s, shape (C + 1, P): row ``C``
    the ``local`` motion of the piece (``inf`` where it has none)."""
    pieces = rest_pieces(path)
    local = local or {}
    seg_t = np.stack([c.profile.segment_times(path) for c in candidates])
    out = np.full((len(candidates) + 1, pieces.shape[0]), np.inf)
    out[:-1] = np.add.reduceat(seg_t, pieces[:, 0], axis=1)
    for k, prof in local.items():
        out[-1, k] = prof.duration
    return out


def pieced(path: Path, candidates: list[Candidate],
           local: dict[int, Profile] | None = None,
           choice: np.ndarray | None = None) -> Profile | None:
    """The fastest candidate on each rest-to-rest piece, joined at the stops.

    Pieces start and end at rest, so a motion may take each piece from a different
    candidate: the time is the sum of the pieces' best. The joined motion is judged by
    the checker like any other (:func:`verified`); at a stop two candidates meet within
    ``VEL_TOL_MM_S`` of rest and may change acceleration there, which the rules allow
    (the frequency rule's phases end at the stop; the ``jerk`` candidates reach rest at
    zero acceleration).

    Parameters
    ----------
    path : Path
    candidates : list of Candidate
        Verified motions on ``path`` (holds excluded).
    local : dict, optional
        Motions of single pieces (piece index to profile over that piece alone, path
        positions absolute), e.g. :func:`optimal.freq.ramps.ramp_plan`; they take
        part on their piece.
    choice : numpy.ndarray of int, shape (P,), optional
        The motion of each piece instead of the fastest: a candidate's index, or
        ``len(candidates)`` for the piece's ``local`` motion (rows of
        :func:`piece_times`).

    Returns
    -------
    Profile or None
        ``None`` when one candidate is the fastest (or chosen) on every piece.
    """
    pieces = rest_pieces(path)
    local = local or {}
    if not candidates:
        return None
    lo_s = path.s_breaks[pieces[:, 0]]
    if choice is None:
        choice = np.argmin(piece_times(path, candidates, local), axis=0)
    use_local = np.asarray(choice) == len(candidates)
    best = np.where(use_local, 0, choice)
    if not np.any(use_local) and np.all(best == best[0]):
        return None
    cuts = path.s_breaks[pieces[1:, 0]]
    parts = {int(c): candidates[int(c)].profile.split_at(cuts) for c in np.unique(best)}
    t, s, v, a, j, blk = [np.zeros(1)], [np.zeros(1)], [np.zeros(1)], [], [], []
    for k, c in enumerate(best):
        prof = local[k] if use_local[k] else parts[int(c)]
        mid = 0.5 * (prof.s[:-1] + prof.s[1:])
        piece = np.clip(np.searchsorted(lo_s, mid, side="right") - 1, 0, pieces.shape[0] - 1)
        idx = np.flatnonzero(piece == k)
        if idx.size == 0:
            return None
        k0, k1 = int(idx[0]), int(idx[-1]) + 1        # intervals k0 .. k1-1, contiguous
        t.append(t[-1][-1] + prof.t[k0 + 1:k1 + 1] - prof.t[k0])
        s.append(prof.s[k0 + 1:k1 + 1])
        v.append(prof.v[k0 + 1:k1 + 1])
        a.append(prof.a[k0:k1])
        j.append(prof.j[k0:k1])
        blk.append(prof.block[k0:k1])
    try:
        return Profile(t=np.concatenate(t), s=np.concatenate(s), v=np.concatenate(v),
                       a=np.concatenate(a), j=np.concatenate(j), block=np.concatenate(blk))
    except ProfileError:
        return None      # the pieces do not meet within the tolerances: no candidate


def scaled(path: Path, limits: MachineLimits, base_profile: Profile,
           bounds: str = "jerk+freq", holds: Holds = NO_HOLDS) -> Candidate | None:
    """Candidate 1: the base set's optimum (without holds), slowed down."""
    return verified(f"{bounds.split('+')[0]} scaled", path, limits, base_profile, bounds,
                    holds=holds)


#: Windows of :func:`fir_filtered` at most this share of the piece's ``1/f`` are none:
#: the filter's acceleration ``(v(t) - v(t - W)) / W`` carries the round-off of ``v``
#: (1e-16 relative) divided by ``W``, 1e-7 relative at this share for a phase of ``1/f``
#: at the speed it reaches; the phases it would lengthen are that close to ``1/f``
#: (the checker's ``RATIO_TOL`` is 1e-6).
FIR_MIN_WINDOW_REL = ROUNDOFF_MARGIN_REL


def fir_filtered(path: Path, limits: MachineLimits, acc_profile: Profile,
                 jerk_limited: bool = True, rest_breaks: np.ndarray | None = None,
                 window_s: float | None = None) -> Profile:
    """Candidate 2 before verification: the acc optimum (without holds; piecewise
    constant acceleration) filtered per rest-to-rest piece by a moving average of window
    ``W_k = max(T_k - r_k, a_k / J_k)``: ``T_k`` the largest ``1/f`` of the segments of
    piece ``k``, ``r_k`` the shortest acceleration phase of the acc profile there
    (:func:`reference.core.phases.acceleration_phases`; a phase of length ``r`` followed
    by a cruise of at least ``W`` becomes one of ``r + W >= T_k``), ``a_k`` its largest
    ``|s''|`` and ``J_k`` the smallest jerk limit of its moving axes (a step ``a_k``
    spread over ``W`` has the jerk ``a_k / W``). On a rest-to-rest line whose acc profile
    is a trapezoid with ramps ``r`` this is the closed form ``L/v + T`` plus ``r``.

    Parameters
    ----------
    path : Path
    limits : MachineLimits
    acc_profile : Profile
        Constant acceleration on every interval (``j = 0``), at rest at every stop break.
    jerk_limited : bool
        Widen the window to ``a_k / J_k`` for the jerk limit (``jerk+freq``); ``False``
        for ``acc+freq``, where the filtered motion's jerk is not bounded.
    rest_breaks : numpy.ndarray of int, optional
        Further breaks where ``acc_profile`` is at rest: pieces are filtered separately.
    window_s : float, optional
        The window of every piece, s, instead of ``W_k`` (the motions of
        :func:`eroded_plans` were built for a given window).

    Returns
    -------
    Profile
        Unverified; lasts ``sum_k W_k`` longer.
    """
    if np.any(acc_profile.j != 0.0):
        raise ValueError("the FIR candidate needs a piecewise-constant acceleration")
    moving = path.moving_axes()
    work = path.restricted(moving) if 0 < moving.size < path.n_axes else path
    lim = limits.for_axes(work.axes)
    per = segment_periods(work, lim)
    seg_j = np.where(moving_axes_by_segment(work), lim.j_max[None, :], np.inf).min(axis=1)
    pieces = rest_pieces(path, rest_breaks)
    ph = acceleration_phases(acc_profile)
    ph_t = 0.5 * (ph.start_t + ph.end_t)
    sb = path.s_breaks
    t_cut = acc_profile.time_at(sb[np.concatenate((pieces[:, 0], pieces[-1:, 1]))])
    tk = acc_profile.t
    D, A0, JJ = [], [], []
    for k, (lo, hi) in enumerate(pieces):
        t0, t1 = float(t_cut[k]), float(t_cut[k + 1])
        T = float(np.max(per[lo:hi]))
        mine = (ph_t > t0) & (ph_t < t1)
        r = float(np.min(ph.effective_duration[mine])) if np.any(mine) else 0.0
        sel = (tk[:-1] >= t0) & (tk[:-1] < t1)
        a_k = float(np.max(np.abs(acc_profile.a[sel]), initial=0.0))
        J = float(np.min(seg_j[lo:hi]))
        spread = a_k / J if (jerk_limited and np.isfinite(J)) else 0.0
        W = max(T - r, spread) if T > 0 else 0.0
        if window_s is not None:
            W = float(window_s)
        if W <= FIR_MIN_WINDOW_REL * T:
            # the phases already last 1/f up to round-off (T - r = 1.4e-17 s on a line
            # whose acc ramps take exactly 1/f): the moving average's acceleration
            # (v(t) - v(t - W)) / W would be round-off divided by W (it drove the filtered
            # motion 30 mm past the path end)
            W = 0.0
        inner = tk[(tk > t0) & (tk < t1)]
        if W <= 0.0:
            knots = np.concatenate(([t0], inner, [t1]))
        else:
            knots = np.unique(np.concatenate(([t0], inner, [t1], inner + W, [t0 + W, t1 + W])))
        h = np.diff(knots)
        keep = h > 0
        lo_t, h = knots[:-1][keep], h[keep]
        if W <= 0.0:
            _, _, a, _ = _state(acc_profile, lo_t + 0.5 * h, t0, t1)
            D.append(h)
            A0.append(a)
            JJ.append(np.zeros_like(h))
            continue
        _, v_now, _, _ = _state(acc_profile, lo_t, t0, t1)
        _, v_old, _, _ = _state(acc_profile, lo_t - W, t0, t1)
        _, _, a_now, _ = _state(acc_profile, lo_t + 0.5 * h, t0, t1)
        _, _, a_old, _ = _state(acc_profile, lo_t + 0.5 * h - W, t0, t1)
        D.append(h)
        A0.append((v_now - v_old) / W)
        JJ.append((a_now - a_old) / W)
    d, a0, jj = np.concatenate(D), np.concatenate(A0), np.concatenate(JJ)
    prof = Profile.from_phases(d, a0, jj)
    # the integration reaches the path end up to round-off; pin the last knot there
    s = prof.s.copy()
    s[-1] = min(max(s[-1], 0.0), path.total_length) if abs(s[-1] - path.total_length) < \
        1e-9 * max(1.0, path.total_length) else s[-1]
    v = np.where(np.abs(prof.v) < 1e-12 * max(1.0, float(np.max(prof.v))), 0.0, prof.v)
    return Profile(t=prof.t, s=s, v=np.maximum(v, 0.0), a=prof.a, j=prof.j, block=prof.block)


def _state(prof: Profile, t: np.ndarray, t0: float, t1: float):
    """``s, v, a, j`` of one rest-to-rest piece ``[t0, t1]`` of ``prof``, at rest outside."""
    inside = (t >= t0) & (t <= t1)
    s, v, a, j = prof.state(np.clip(t, t0, t1))
    z = np.zeros_like(t)
    return s, np.where(inside, v, z), np.where(inside, a, z), np.where(inside, j, z)


#: Intervals of the base grid of :func:`eroded_plans` per erosion distance ``V W`` (``V``
#: the largest speed cap), between the two bounds below; nodes are added where the caps
#: change (around every corner), so this only sets the resolution of curvature caps.
ERODED_GRID_PER_DISTANCE = 8
ERODED_GRID_MIN, ERODED_GRID_MAX = 2_000, 200_000
#: Smallest tangential acceleration the passes of :func:`eroded_plans` use, as a fraction
#: of the smallest axis acceleration: where the caps leave none (a speed at the curvature
#: limit), the motion still moves, and the checker's time scaling pays for it.
ERODED_MIN_ACCEL_SHARE = 0.05
#: Interior breaks whose speed cap is at most this are rests of :func:`eroded_plans`
#: (piece ends of the filter), mm/s: resting is always allowed, and a corner passed at
#: 1 um/s is a stop for the time (its band of ``cap W`` is some 50 nm long, below what
#: the grid resolves next to it).
ERODED_REST_CAP_MM_S = 1e-3
#: ``rest_share`` of the second eroded candidate of each window (:func:`eroded_plans`):
#: corners slower than the speed a quarter window gains at the smallest axis
#: acceleration are taken at rest. Of 0.25, 0.5 and 1 tried on the corpus, 0.25 and 0.5
#: gave the same brackets and 1 made some worse (a stop costs more than the plateau).
ERODED_REST_SHARE = 0.25
#: Rounds in which :func:`eroded_plans` re-evaluates the tangential acceleration at the
#: speeds its passes reached (the checker judges the result; more rounds change little).
TANGENTIAL_ROUNDS = 2
#: Rounds of dip widening and bump cutting in :func:`eroded_plans` (each followed by the
#: acceleration passes, which can leave new short features behind; two settle the corpus).
REGULARISE_ROUNDS = 2
#: Rounds of stretching u's short phases in :func:`eroded_plans`, and the margin they aim
#: above the rule (so that round-off does not leave a phase a hair short). The loop stops
#: as soon as no phase is short; 12 rounds left a phase at 1/1.39 of 1/f on
#: lcnc_tangent_helix (each round at most halves a phase's acceleration), which the time
#: scaling then paid on the whole motion (acc+freq 1.551 s; with 40 rounds 1.308 s, and
#: 100 rounds change nothing on the corpus).
ADAPT_ROUNDS = 40
ADAPT_MARGIN = 1e-3
#: A short phase of ``u`` whose speed change is at most this share of its higher end
#: speed is flattened rather than stretched (:func:`_adapted`): following a cap that
#: varies along an arc leaves changes of 1e-5 of the speed, which no lower acceleration
#: stretches; flattening one costs at most this share of the time across it (1 %).
ADAPT_WIGGLE_REL = 1e-2


@dataclass(frozen=True, slots=True, eq=False)
class ErodedPlan:
    """Input motion of the FIR candidate (:func:`eroded_plans`).

    Attributes
    ----------
    profile : Profile
        Constant acceleration per interval (``j = 0``), at rest at every stop break and at
        every break in ``rest_breaks``; unverified.
    rest_breaks : numpy.ndarray of int
        Interior breaks whose speed cap is zero (a corner without velocity-jump
        allowance): the motion rests there, and the filter treats them as piece ends.
    window_s : float
        The FIR window the caps were eroded for, s.
    """

    profile: Profile
    rest_breaks: np.ndarray
    window_s: float


def _sparse_table(x: np.ndarray) -> list[np.ndarray]:
    """Minima of ``x`` over windows of 1, 2, 4, ... elements (``log2 N`` arrays)."""
    levels = [x]
    span = 1
    while 2 * span <= x.size:
        prev = levels[-1]
        levels.append(np.minimum(prev[:-span], prev[span:]))
        span *= 2
    return levels


def _query(levels: list[np.ndarray], lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """``min(x[lo[i]:hi[i]])`` from :func:`_sparse_table` (non-empty windows), O(1) each."""
    k = np.floor(np.log2(np.maximum(hi - lo, 1))).astype(np.int64)
    out = np.empty(lo.size)
    for lev in np.unique(k):
        sel = k == lev
        tab = levels[int(lev)]
        out[sel] = np.minimum(tab[lo[sel]], tab[hi[sel] - (1 << int(lev))])
    return out


def _window_min(x: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """``min(x[lo[i]:hi[i]])`` for every ``i`` (non-empty windows), by a sparse table:
    ``log2 N`` halvings, O(N log N) work and memory, vectorised."""
    return _query(_sparse_table(x), lo, hi)


def _passes(b: np.ndarray, step: np.ndarray) -> np.ndarray:
    """Largest ``b' <= b`` with ``|b'[i+1] - b'[i]| <= step[i]``: forward and backward
    min-plus scans, ``b_k = D_k + min_{i<=k} (b_i - D_i)``, ``D`` the cumulative steps."""
    D = np.concatenate(([0.0], np.cumsum(step)))
    b = np.minimum(b, D + np.minimum.accumulate(b - D))
    Dr = np.concatenate(([0.0], np.cumsum(step[::-1])))
    return np.minimum(b, (Dr + np.minimum.accumulate(b[::-1] - Dr))[::-1])


#: Largest number of (node, cap) pairs :func:`window_caps` holds at once (bounds its
#: temporaries to some 100 MB; the result does not depend on it).
WINDOW_CAPS_CHUNK = 4_000_000


def window_caps(s: np.ndarray, cap: np.ndarray, window_s: float) -> np.ndarray:
    """Speed caps for a motion ``u`` that a moving average of window ``W`` turns into
    one keeping every cap where it arrives (:func:`eroded_plans`), at every node:
    ``c(p) = min {cap(q) : p in band(q)}``.

    The band of node ``q`` with the cap ``c = cap(q)`` is ``|s - s_q| <= c W / 2``,
    widened by one node on each side. Why it keeps ``c``: ``u^2`` is linear between
    nodes, so with every node of the widened band at most ``c``, ``u <= c`` on the whole
    band, and crossing it takes at least ``W``; the window ``[t - W, t]`` of the filter
    cannot hold positions on both sides of it. If the filtered motion is at ``q``
    (``s_out(t) = (1/W) int_{t-W}^t s_u = s_q``) and the window held some positions below
    the band, the rest (inside it, at speeds ``<= c``, entered at ``tau``) would average at
    most ``s_q - c W / 2 + c (t - tau)^2 / (2 W) <= s_q``, with equality only if the whole
    window is in the band; above alike. So the window lies in the band and ``v_out(t) =
    (1/W) int u <= c``.

    This replaces the cone envelope ``min_q max(cap(q), |s_p - s_q| / W)`` of the first
    version, which was evaluated at the nodes only: a cone is convex, so ``u^2``
    interpolated linearly between two nodes under it can cross it (a slow corner on a
    coarse grid: tests/optimal/test_freq_upper.py simulates the filter). The band needs
    nodes where it ends: :func:`_eroded_grid` puts them at ``cap W / 2`` and ``cap W``
    around every break whose cap is finite, so that the widening costs little there.

    Parameters
    ----------
    s : numpy.ndarray, shape (N,)
        Increasing nodes, mm.
    cap : numpy.ndarray, shape (N,)
        Speed caps, mm/s (``inf``: none; ``0``: a rest, where the filter's pieces end,
        kept at its node only).
    window_s : float
        ``W``, s (>= 0).

    Returns
    -------
    numpy.ndarray, shape (N,)
    """
    out = np.array(cap, dtype=np.float64)
    q = np.flatnonzero(np.isfinite(cap) & (cap > 0.0))
    if q.size == 0 or window_s <= 0.0:
        return out
    c = cap[q]
    lo = np.maximum(np.searchsorted(s, s[q] - 0.5 * window_s * c, side="left") - 1, 0)
    hi = np.minimum(np.searchsorted(s, s[q] + 0.5 * window_s * c, side="right") + 1, s.size)
    size = np.cumsum(hi - lo)
    start = 0
    while start < q.size:
        base = size[start - 1] if start else 0
        stop = max(int(np.searchsorted(size, base + WINDOW_CAPS_CHUNK, side="right")),
                   start + 1)
        idx = concat_ranges(lo[start:stop], hi[start:stop])
        np.minimum.at(out, idx, np.repeat(cap[q[start:stop]], hi[start:stop] - lo[start:stop]))
        start = stop
    return out


#: Windows of the filtered candidates of ``jerk+freq``, as multiples of the longest
#: ``A_i / J_i`` of the moving axes (a moving average of ``W`` turns an acceleration
#: step ``Delta a`` into the jerk ``Delta a / W``: one axis' full step needs ``A_i / J_i``,
#: a reversal twice that); the longest ``1/f`` is tried too. No window is best on every
#: program (a longer one costs more at each cap, a shorter one more time scaling for
#: the jerk), so each is a candidate.
JERK_WINDOW_MULTIPLES = (1.0, 2.0)


def candidate_windows(work: Path, lim, period_s: float, jerk_limited: bool) -> tuple[float, ...]:
    """Moving-average windows of the eroded-caps candidates, s (``0``: unfiltered).

    ``acc+freq``: the unfiltered adapted motion and the window ``1/f``; ``jerk+freq``:
    :data:`JERK_WINDOW_MULTIPLES` of the longest ``A_i / J_i`` of the moving axes, and
    ``1/f``.

    Parameters
    ----------
    work : Path
        Restricted to its moving axes.
    lim : AxisArrays
        Limits of ``work.axes``.
    period_s : float
        The longest ``1/f`` of the path's segments, s.
    jerk_limited : bool
    """
    if not jerk_limited:
        return (0.0, period_s)
    w_a = float(np.max(lim.a_max / lim.j_max))
    return tuple(sorted({period_s, *(k * w_a for k in JERK_WINDOW_MULTIPLES)}))


def _eroded_grid(path: Path, n: int, v_junction: np.ndarray, window_s: float):
    """The initial grid plus nodes at ``cap W / 2`` and ``cap W`` on both sides of every
    break with a finite cap ``v_junction`` (a corner, a curvature jump, a change of the
    feed or of the axis speed caps), inside the neighbouring segments: where the bands of
    :func:`window_caps` end."""
    from ..grid import Grid, initial_grid
    g = initial_grid(path, n)
    sb = path.s_breaks
    fin = np.flatnonzero(np.isfinite(v_junction) & (v_junction > 0))
    extra = [g.s]
    for f in (0.5, 1.0):
        d = v_junction[fin] * window_s * f
        lo = np.maximum(sb[fin] - d, sb[np.maximum(fin - 1, 0)])
        hi = np.minimum(sb[fin] + d, sb[np.minimum(fin + 1, sb.size - 1)])
        extra += [lo, hi]
    s = np.unique(np.concatenate(extra))
    # drop nodes within round-off of a break (the break itself stays): the distance to
    # the nearest break from the sorted breaks, O(N log m)
    j = np.clip(np.searchsorted(sb, s), 1, sb.size - 1)
    near = np.minimum(np.abs(s - sb[j - 1]), np.abs(sb[j] - s))
    s = s[(near == 0) | (near > 1e-9 * max(1.0, float(sb[-1])))]
    seg = np.clip(np.searchsorted(sb, 0.5 * (s[:-1] + s[1:]), side="right") - 1, 0,
                  path.n_segments - 1)
    return Grid(s=s, segment=seg, break_node=np.searchsorted(s, sb))


def eroded_plans(path: Path, limits: MachineLimits, period_s: float, window_s: float,
                 jerk_limited: bool, jerk_reach: bool = False,
                 rest_share: float = 0.0) -> ErodedPlan:
    """A motion whose moving average keeps every speed cap *where it arrives*: the input
    of the FIR candidate on paths with corners and curves.

    A moving average ``v_out(t) = (1/W) int_{t-W}^t u`` reaches the position ``s_out(t)``,
    an average of the window's positions. Where ``u`` stays at most ``cap(q)`` on a band of
    length ``cap(q) W`` around ``q`` (:func:`window_caps`, which proves it), the window
    lies inside the band when the filtered motion passes ``q``, so ``v_out <= cap(q)``:
    the filtered motion keeps the feed, the axis speeds, the corner (junction) caps, the
    curvature jumps' caps and the curvature limit (:func:`optimal.problem.pair_mvc`)
    where a plain filtered optimum overshoots them. At a corner of cap ``v_c`` the band is
    a plateau that ``u`` crosses in ``W``. Forward and backward passes with the
    tangential acceleration the axes have left at that speed make ``u``. A corner with a
    zero cap is a rest (a plateau of zero length cannot be crossed): the filter takes it
    as a piece end. Without a filter (``W = 0``) the caps are kept as they are.

    Parameters
    ----------
    path : Path
    limits : MachineLimits
    period_s : float
        The largest ``1/f`` of the path's segments, s: sets the grid's resolution.
    window_s : float
        ``W``, the window of the moving average that will filter ``u``
        (:func:`fir_filtered`), s. The caps are eroded for it and ``u``'s phases are
        stretched to ``1/f - W`` (the filter lengthens each by ``W``). ``0``: no filter
        (``acc+freq``): ``u`` is the candidate itself, not eroded, its phases stretched to
        the full ``1/f``.
    jerk_limited : bool
        Cap the speed at curvature jumps as the jerk set does (``jerk+freq``), and keep
        u's tangential acceleration to what leaves every axis its jerk limit after the
        filter (``a / W`` plus the curvature terms of the axis jerk).
    jerk_reach : bool
        Take that jerk room as the least over the intervals the filtered motion may lag
        behind (u's speed times ``W``): needed where u accelerates hard just after a
        curve, costly on long curves; the oracle tries both.
    rest_share : float
        Corners whose cap is at most ``rest_share * A_min * max(W, 1/f)`` are rests (piece
        ends of the filter) instead of plateaus: the filter needs ``W`` to pass a corner at
        its cap on a plateau and a dip costs two phases of ``1/f``, while stopping at a
        slow corner costs about ``v_c / A`` (:data:`ERODED_REST_SHARE`; the oracle tries
        both, neither is always faster; measured on lcnc_test_12mmflat, default machine:
        ``acc+freq`` 46.96 -> 38.86 s, ``jerk+freq`` 46.64 -> 44.01 s).

    Returns
    -------
    ErodedPlan
    """
    from dataclasses import replace as dc_replace

    from ..problem import common_node_caps, interval_geometry, junction_speed_caps, pair_mvc

    moving = path.moving_axes()
    work = path.restricted(moving) if 0 < moving.size < path.n_axes else path
    lim = limits.for_axes(work.axes)
    free = dc_replace(work, stop=np.zeros_like(work.stop))
    v_j, _ = junction_speed_caps(free, lim, permissive=False)
    W = float(window_s)
    vcap = float(np.max(np.minimum(path_rate_bounds(work, lim.v_max), work.feed)))
    L = float(work.total_length)
    n = int(np.clip(ERODED_GRID_PER_DISTANCE * L / max(vcap * max(W, period_s), 1e-9),
                    ERODED_GRID_MIN, ERODED_GRID_MAX))
    m = free.n_segments
    v_point = v_j.copy()
    if jerk_limited and m >= 2:
        # a curvature jump steps the centripetal acceleration at any speed: the jerk set
        # holds that step to PATH_TRANS_JERK_LIM (at least MAX_AX_JERK) over one IPO cycle
        sb = free.s_breaks
        _, _, k_in, _ = free.evaluate(sb[1:m], segment=np.arange(m - 1))
        _, _, k_out, _ = free.evaluate(sb[1:m], segment=np.arange(1, m))
        v_point[1:m] = np.minimum(v_point[1:m], curvature_jump_speed_cap(
            k_in, k_out, np.maximum(lim.path_trans_jerk, lim.j_max), limits.t_ipo_s))
    # where the caps change: the point caps and the lower speed cap of the two segments
    seg_cap = np.minimum(path_rate_bounds(free, lim.v_max), free.feed)
    v_break = v_point.copy()
    v_break[1:] = np.minimum(v_break[1:], seg_cap)
    v_break[:-1] = np.minimum(v_break[:-1], seg_cap)
    # corners the motion passes at rest: a zero cap, or one so low that crossing it is a
    # stop in all but name (and u^2 = 0 at both ends of an interval cannot be crossed)
    # a plateau at a corner lasts W after the filter, and the phases into and out of a
    # dip last at least 1/f, while a stop costs about v_c / A: the longer of the two
    rest_cap = max(ERODED_REST_CAP_MM_S,
                   rest_share * float(np.min(lim.a_max)) * max(W, period_s))
    rest = np.flatnonzero(v_point <= rest_cap)
    rest = rest[(rest > 0) & (rest < m)]
    grid = _eroded_grid(free, n, v_break, W)
    dq0, ddq0, dq1, ddq1 = interval_geometry(free, grid)
    b_cap = common_node_caps(free, lim, grid, dq0, dq1, permissive=False).cap.copy()
    b_cap[:-1] = np.minimum(b_cap[:-1], pair_mvc(dq0, ddq0, lim.a_max))
    b_cap[1:] = np.minimum(b_cap[1:], pair_mvc(dq1, ddq1, lim.a_max))
    b_cap[grid.break_node] = np.minimum(b_cap[grid.break_node], v_point ** 2)
    cap = np.sqrt(b_cap)
    rest_nodes = np.concatenate((grid.break_node[work.stop], grid.break_node[rest]))
    cap[grid.break_node[rest]] = np.inf          # rests are piece ends, not caps
    b = window_caps(grid.s, cap, W) ** 2
    b[rest_nodes] = 0.0
    # tangential acceleration the axes have left beside the curvature term at the speed
    # reached, per interval (both ends): first at the eroded caps (the least), then at
    # the passes' own speeds, which are lower where a ramp has not reached the cap yet
    floor = ERODED_MIN_ACCEL_SHARE * float(np.min(lim.a_max))
    ds_n = np.diff(grid.s)

    if jerk_limited and W > 0:
        # the third derivative of the path at the interval middles, for the jerk room;
        # the filtered motion lags u by up to W times u's speed (at most the eroded cap
        # there): with jerk_reach each interval takes the least room of those that close
        mid = 0.5 * (grid.s[:-1] + grid.s[1:])
        _, _, _, d3 = free.evaluate(mid, segment=grid.segment)
        d1, d2 = 0.5 * (np.abs(dq0) + np.abs(dq1)), 0.5 * (np.abs(ddq0) + np.abs(ddq1))
        reach = W * np.sqrt(np.maximum(np.maximum(b[:-1], b[1:]), 0.0)) if jerk_reach \
            else np.zeros(mid.size)
        near_lo = np.searchsorted(mid, mid - reach, side="left")
        near_hi = np.searchsorted(mid, mid + reach, side="right")

    def steps(b_at: np.ndarray) -> np.ndarray:
        with np.errstate(divide="ignore", invalid="ignore"):
            rem0 = (lim.a_max[None, :] - np.abs(ddq0) * b_at[:-1, None]) / np.abs(dq0)
            rem1 = (lim.a_max[None, :] - np.abs(ddq1) * b_at[1:, None]) / np.abs(dq1)
        rem0 = np.where(np.abs(dq0) > 0, rem0, np.inf).min(axis=1)
        rem1 = np.where(np.abs(dq1) > 0, rem1, np.inf).min(axis=1)
        a_t = np.minimum(rem0, rem1)
        if jerk_limited and W > 0:
            # the filter turns a step of u's acceleration a into the path jerk a / W; on
            # a curve the axis jerk (q' s''' + 3 q'' s' s'' + q''' s'^3) also carries the
            # other two terms: a is kept to what leaves each axis its jerk limit
            v = np.sqrt(np.maximum(np.maximum(b_at[:-1], b_at[1:]), 0.0))[:, None]
            with np.errstate(divide="ignore", invalid="ignore"):
                room = (lim.j_max[None, :] - np.abs(d3) * v ** 3) / (d1 / W + 3.0 * d2 * v)
            room = np.where(d1 + d2 > 0, room, np.inf).min(axis=1)
            a_t = np.minimum(a_t, _window_min(room, near_lo, near_hi))
        return 2.0 * np.maximum(a_t, floor) * ds_n

    b_eroded = b
    step = steps(b_eroded)
    b = _passes(b_eroded, step)
    for _ in range(TANGENTIAL_ROUNDS):
        step = steps(b)
        b = _passes(b_eroded, step)
    blocks = work.block[grid.segment]
    b = _regularised(grid.s, b, step, rest_nodes, vcap, W) if W > 0 else b
    b = _adapted(work, lim, grid, b, step.copy(), blocks, W)
    prof = Profile.from_path_velocity(grid.s, np.sqrt(np.maximum(b, 0.0)), blocks)
    return ErodedPlan(profile=prof, rest_breaks=rest, window_s=W)


def _regularised(s_n: np.ndarray, b: np.ndarray, step: np.ndarray, rest_nodes: np.ndarray,
                 vcap: float, W: float) -> np.ndarray:
    """Dips widened and bumps cut (see :func:`eroded_plans`); returns ``b`` after the
    passes, shape (N,).

    A dip or a bump that u crosses in less than ``W`` leaves phases of its own width after
    the filter (a moving average spreads a step over ``W``, not a pulse): dips become
    plateaus crossed in ``W`` (:func:`window_caps` of u's dips) and narrower bumps are cut
    by a flat opening in time, then the passes run again.
    """
    ds_n = np.diff(s_n)
    for _ in range(REGULARISE_ROUNDS):
        v = np.sqrt(np.maximum(b, 0.0))
        # the sources are u's dips: runs of equal speed with a higher run on both sides
        # (not a flat step on a ramp, nor the ramps from the rests, which are piece ends)
        chg = np.flatnonzero(np.diff(v) != 0) + 1
        starts = np.concatenate(([0], chg))
        rv = v[starts]
        dip = np.zeros(rv.size, bool)
        dip[1:-1] = (rv[:-2] > rv[1:-1]) & (rv[2:] > rv[1:-1])
        # a dip that u already crosses in W or more needs no widening
        ends = np.concatenate((starts[1:], [v.size])) - 1
        dip &= (s_n[ends] - s_n[starts]) < rv * W
        low = np.repeat(dip, np.diff(np.concatenate((starts, [v.size]))))
        v = np.minimum(window_caps(s_n, np.where(low, v, np.inf), W), v)
        # the bumps are cut by a flat opening in *time* (constant width W, at the times u
        # reaches the nodes, so that monotone ramps stay and exactly the narrower peaks
        # go; an opening of constant width in path length was a second candidate and
        # never won by more than 0.3 % on the corpus); the rests are piece ends, not
        # dips, for it
        v[rest_nodes] = vcap
        v_nodes = np.sqrt(np.maximum(b, 0.0))
        vs = v_nodes[:-1] + v_nodes[1:]
        t_n = np.concatenate(([0.0], np.cumsum(np.where(vs > 0, 2.0 * ds_n / np.where(
            vs > 0, vs, 1.0), 0.0))))
        lo = np.searchsorted(t_n, t_n - 0.5 * W, side="left")
        hi = np.searchsorted(t_n, t_n + 0.5 * W, side="right")
        opened = -_window_min(-_window_min(v, lo, hi), lo, hi)
        b = np.minimum(b, np.minimum(opened, v) ** 2)
        b[rest_nodes] = 0.0
        b = _passes(b, step)
    return b


def _adapted(work: Path, lim, grid, b: np.ndarray, step: np.ndarray, blocks: np.ndarray,
             spread: float) -> np.ndarray:
    """The rule on u itself, as the control's adaptation does it (see
    :func:`eroded_plans`): a phase shorter than its ``1/f`` less the filter's jerk
    ``spread`` (which lengthens every phase) gets the constant acceleration that makes it
    last that long; repeated, as a slower ramp can change its neighbours. ``step`` is
    changed in place; returns ``b``, shape (N,)."""
    s_n = grid.s
    ds = np.diff(s_n)
    b_env = b.copy()
    for _ in range(ADAPT_ROUNDS):
        prof = Profile.from_path_velocity(s_n, np.sqrt(np.maximum(b, 0.0)), blocks)
        ph = acceleration_phases(prof)
        f, _ = phase_frequencies(work, lim, ph, grid.segment)
        need = np.maximum(min_phase_duration(f) - spread, 0.0)
        short = np.flatnonzero(ph.effective_duration < need * (1.0 - ADAPT_MARGIN))
        if short.size == 0:
            break
        # a_new: the mean acceleration of a linear ramp of the needed length
        aim = need[short] * (1.0 + ADAPT_MARGIN)      # > 0: the phase is short of it
        a_new = ph.dv[short] / aim
        shrink = np.clip(ph.effective_duration[short] / aim, 0.5, 1.0)
        v_hi = np.sqrt(np.maximum(np.maximum(b[ph.first[short]], b[ph.last[short] + 1]), 0.0))
        for k, p_ in enumerate(short):
            sl = slice(int(ph.first[p_]), int(ph.last[p_]) + 1)
            if ph.dv[p_] <= ADAPT_WIGGLE_REL * v_hi[k]:
                # a wiggle (u following a cap that varies a little along a curve, or
                # round-off): flattened at its lower speed, which costs less than the
                # change's share of the speed, instead of stretched
                nodes = slice(sl.start, sl.stop + 1)
                b_env[nodes] = np.minimum(b_env[nodes], float(np.min(b[nodes])))
                continue
            a_now = step[sl] / (2.0 * ds[sl])
            # the steeper intervals take the ramp's acceleration and the gentler ones
            # stay; only a phase already at it everywhere (cut by the grid into unequal
            # pieces, not quite symmetric) is slowed by the stretch still missing, at
            # most halved per round. (Slowing the gentler intervals of a phase that is
            # not yet the ramp loaded its far end: a deceleration the grid put into one
            # interval grew by an interval a round, 300, 225, 112 mm/s^2 towards its
            # end, its mean time early, and lasted 46 % longer than the ramp of 1/f.)
            a_set = (a_now * shrink[k] if np.all(a_now <= a_new[k] * (1.0 + 1e-9))
                     else np.minimum(a_now, a_new[k]))
            step[sl] = 2.0 * a_set * ds[sl]
        b = _passes(b_env, step)
    return b
