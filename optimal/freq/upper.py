"""Verified upper bounds for the frequency bound sets ``acc+freq`` and ``jerk+freq``.

Two candidate motions, each judged by ``check_profile`` and slowed down uniformly until it
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

A time-domain NLP over phase durations (CasADi) could be tighter but would need its own
verification anyway; the two candidates are exact constructions whose only certificate
is the checker, as for the other bound sets.

Units: mm, s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.core.constraints import (BOUND_SETS, ConstraintReport, check_profile,
                                        scale_time, time_scale_factor,
                                        time_scale_factors_by_block)
from reference.core.geometry import Path
from reference.core.limits import MachineLimits
from reference.core.phases import acceleration_phases, moving_axes_by_segment
from reference.core.profile import Profile

from .lower import rest_pieces, segment_periods

__all__ = ["Candidate", "fir_filtered", "scaled", "verified"]



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
             bounds: str = "jerk+freq") -> Candidate | None:
    """Check ``prof`` and slow it down until ``bounds`` holds; ``None`` if it cannot.

    Each rest-to-rest piece is first slowed down by its own factor (the largest
    :func:`~reference.core.constraints.time_scale_factors_by_block` of its blocks):
    pieces start and end at rest, so stretching one leaves the others as they are. If
    that motion is not accepted (a violation the per-block ratios do not place, round-off
    at a stop), the whole motion is stretched by the single factor instead.
    """
    cons = BOUND_SETS[bounds]
    rep = check_profile(path, limits, prof)
    lam = time_scale_factor(rep, cons)
    if not np.isfinite(lam):
        return None
    if lam <= 1.0:
        return Candidate(name, prof, 1.0, rep)
    per_block = time_scale_factors_by_block(rep, cons)
    pieces = rest_pieces(path)
    if per_block.size and pieces.shape[0] > 1:
        lam_k = np.array([float(np.max(per_block[path.block[lo:hi]], initial=1.0))
                          for lo, hi in pieces])
        if np.all(np.isfinite(lam_k)):
            out = _scale_pieces(path, prof, pieces, lam_k)
            if check_profile(path, limits, out).ok(cons):
                return Candidate(name, out, float(np.max(lam_k)), rep)
    out = scale_time(prof, lam)
    # the scaling argument is exact, but round-off at ratio 1 is judged once more
    if not check_profile(path, limits, out).ok(cons):
        out = scale_time(out, 1.0 + 1e-9)
        if not check_profile(path, limits, out).ok(cons):
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


def scaled(path: Path, limits: MachineLimits, base_profile: Profile,
           bounds: str = "jerk+freq") -> Candidate | None:
    """Candidate 1: the base set's optimum (without holds), slowed down."""
    return verified(f"{bounds.split('+')[0]} scaled", path, limits, base_profile, bounds)


def fir_filtered(path: Path, limits: MachineLimits, acc_profile: Profile,
                 jerk_limited: bool = True) -> Profile:
    """Candidate 2 before verification: the acc optimum (without holds; piecewise
    constant acceleration) filtered per rest-to-rest piece by a moving average of window
    ``W_k = max(T_k - r_k, a_k / J_k)``: ``T_k`` the largest ``1/f`` of the segments of
    piece ``k``, ``r_k`` the shortest acceleration phase of the acc profile there
    (:func:`reference.core.phases.acceleration_phases`; a phase of length ``r`` followed
    by a cruise of at least ``W`` becomes one of ``r + W >= T_k``), ``a_k`` its largest
    ``|s''|`` and ``J_k`` the smallest jerk limit of its moving axes (a step ``a_k``
    spread over ``W`` has the jerk ``a_k / W``). On a rest-to-rest line whose acc profile
    is a trapezoid with ramps ``r`` this is the closed form ``L/v + T`` plus ``r``, and
    the dispatcher tries acc profiles with raised accelerations (shorter ``r``).

    Parameters
    ----------
    path : Path
    limits : MachineLimits
    acc_profile : Profile
        Constant acceleration on every interval (``j = 0``), at rest at every stop break.
    jerk_limited : bool
        Widen the window to ``a_k / J_k`` for the jerk limit (``jerk+freq``); ``False``
        for ``acc+freq``, where the filtered motion's jerk is not bounded.

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
    pieces = rest_pieces(path)
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
        r = float(np.min(ph.duration[mine])) if np.any(mine) else 0.0
        sel = (tk[:-1] >= t0) & (tk[:-1] < t1)
        a_k = float(np.max(np.abs(acc_profile.a[sel]), initial=0.0))
        J = float(np.min(seg_j[lo:hi]))
        spread = a_k / J if (jerk_limited and np.isfinite(J)) else 0.0
        W = max(T - r, spread) if T > 0 else 0.0
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


#: Intervals of the grid on which :func:`eroded_plan` samples the speed caps: one per
#: this fraction of the erosion distance (finer changes nothing the FIR window can use),
#: between the two bounds below (memory grows linearly, some 20 arrays of N floats).
ERODED_GRID_PER_DISTANCE = 8
ERODED_GRID_MIN, ERODED_GRID_MAX = 2_000, 200_000
#: Smallest tangential acceleration the passes of :func:`eroded_plan` use, as a fraction
#: of the smallest axis acceleration: where the caps leave none (a speed at the curvature
#: limit), the motion still moves, and the checker's time scaling pays for it.
ERODED_MIN_ACCEL_SHARE = 0.05


def _window_min(x: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """``min(x[lo[i]:hi[i]])`` for every ``i`` (non-empty windows), by a sparse table:
    ``log2 N`` halvings, O(N log N) work and memory, vectorised."""
    levels = [x]
    span = 1
    while 2 * span <= x.size:
        prev = levels[-1]
        levels.append(np.minimum(prev[:-span], prev[span:]))
        span *= 2
    n = hi - lo
    k = np.floor(np.log2(np.maximum(n, 1))).astype(np.int64)
    out = np.empty(lo.size)
    for lev in np.unique(k):
        sel = k == lev
        tab = levels[int(lev)]
        w = 1 << int(lev)
        out[sel] = np.minimum(tab[lo[sel]], tab[hi[sel] - w])
    return out


def eroded_plan(path: Path, limits: MachineLimits, window_s: float) -> Profile:
    """A motion whose moving average over ``window_s`` keeps every speed cap *where it
    arrives*: the input of the FIR candidate on paths with corners and curves.

    A moving average ``v_out(t) = (1/W) int_{t-W}^t u`` reaches position ``s_out(t)``, an
    average of the positions ``s_u`` of the window, so ``|s_u(tau) - s_out(t)| <= V W``
    for every ``tau`` in it (``V`` the largest speed). If every ``u(tau)`` is at most the
    speed cap everywhere within ``delta = V W`` of ``s_u(tau)``, then ``v_out(t)`` is at
    most the cap at ``s_out(t)``: the filtered motion keeps the feed, the axis speeds, the
    corner (junction) caps and the curvature limit (:func:`optimal.problem.pair_mvc`)
    where a plain filtered optimum overshoots them. So ``u`` follows the caps *eroded* by
    ``delta`` (the smallest cap within ``delta``; stops excluded, the filter is applied
    per rest-to-rest piece), with forward and backward passes of the tangential
    acceleration the axes have left at that speed.

    Parameters
    ----------
    path : Path
    limits : MachineLimits
    window_s : float
        The largest FIR window the caller will use, s.

    Returns
    -------
    Profile
        Constant acceleration per interval (``j = 0``), at rest at every stop break;
        unverified.
    """
    from dataclasses import replace as dc_replace

    from ..grid import initial_grid
    from ..problem import common_node_caps, interval_geometry, pair_mvc

    moving = path.moving_axes()
    work = path.restricted(moving) if 0 < moving.size < path.n_axes else path
    lim = limits.for_axes(work.axes)
    free = dc_replace(work, stop=np.zeros_like(work.stop))
    # the erosion distance needs the largest speed: bounded by feed and axis speeds
    vcap = float(np.max(np.minimum(work.feed, np.sqrt(work.n_axes) * np.max(lim.v_max))))
    delta = vcap * window_s
    L = float(work.total_length)
    n = int(np.clip(ERODED_GRID_PER_DISTANCE * L / max(delta, 1e-9), ERODED_GRID_MIN,
                    ERODED_GRID_MAX))
    grid = initial_grid(free, n)
    dq0, ddq0, dq1, ddq1 = interval_geometry(free, grid)
    caps = common_node_caps(free, lim, grid, dq0, dq1, permissive=False).cap.copy()
    caps[:-1] = np.minimum(caps[:-1], pair_mvc(dq0, ddq0, lim.a_max))
    caps[1:] = np.minimum(caps[1:], pair_mvc(dq1, ddq1, lim.a_max))
    s = grid.s
    lo = np.searchsorted(s, s - delta, side="left")
    hi = np.searchsorted(s, s + delta, side="right")
    b = _window_min(caps, lo, hi)
    b[grid.break_node[work.stop]] = 0.0
    # tangential acceleration left at the eroded speed, per interval (both ends)
    with np.errstate(divide="ignore", invalid="ignore"):
        rem0 = (lim.a_max[None, :] - np.abs(ddq0) * b[:-1, None]) / np.abs(dq0)
        rem1 = (lim.a_max[None, :] - np.abs(ddq1) * b[1:, None]) / np.abs(dq1)
    rem0 = np.where(np.abs(dq0) > 0, rem0, np.inf).min(axis=1)
    rem1 = np.where(np.abs(dq1) > 0, rem1, np.inf).min(axis=1)
    a_t = np.maximum(np.minimum(rem0, rem1), ERODED_MIN_ACCEL_SHARE * float(np.min(lim.a_max)))
    step = 2.0 * a_t * np.diff(s)
    # b[i+1] <= b[i] + step[i] forwards and b[i] <= b[i+1] + step[i] backwards: min-plus
    # scans, b_k = D_k + min_{i<=k} (b_i - D_i) with D the cumulative steps
    D = np.concatenate(([0.0], np.cumsum(step)))
    b = np.minimum(b, D + np.minimum.accumulate(b - D))
    Dr = np.concatenate(([0.0], np.cumsum(step[::-1])))
    br = b[::-1]
    b = np.minimum(b, (Dr + np.minimum.accumulate(br - Dr))[::-1])
    return Profile.from_path_velocity(s, np.sqrt(np.maximum(b, 0.0)),
                                      work.block[grid.segment])
