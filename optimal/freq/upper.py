"""Verified upper bounds for the ``jerk+freq`` bound set.

Two candidate motions, each judged by ``check_profile`` and slowed down uniformly until it
passes every constraint of ``jerk+freq`` (:func:`reference.core.constraints.time_scale_factor`:
stretching time by ``lam`` divides velocity by ``lam``, acceleration by ``lam^2``, jerk by
``lam^3`` and multiplies every phase duration by ``lam``, so the scaled motion is accepted
whatever the candidate was). The faster accepted one is the upper bound.

1. **The jerk optimum, slowed down** (:func:`scaled`): exact and cheap; tight where the
   jerk optimum's phases already last ``1/f`` (long moves, low frequencies), poor where a
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
                                        scale_time, time_scale_factor)
from reference.core.geometry import Path
from reference.core.limits import MachineLimits
from reference.core.phases import acceleration_phases, moving_axes_by_segment
from reference.core.profile import Profile

from .lower import rest_pieces, segment_periods

__all__ = ["Candidate", "fir_filtered", "scaled", "verified"]

FREQ_SET = BOUND_SETS["jerk+freq"]


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


def verified(name: str, path: Path, limits: MachineLimits, prof: Profile) -> Candidate | None:
    """Check ``prof`` and slow it down until ``jerk+freq`` holds; ``None`` if it cannot."""
    rep = check_profile(path, limits, prof)
    lam = time_scale_factor(rep, FREQ_SET)
    if not np.isfinite(lam):
        return None
    out = scale_time(prof, lam) if lam > 1.0 else prof
    # the scaling argument is exact, but round-off at ratio 1 is judged once more
    if not check_profile(path, limits, out).ok(FREQ_SET):
        out = scale_time(out, 1.0 + 1e-9)
        if not check_profile(path, limits, out).ok(FREQ_SET):
            return None
    return Candidate(name, out, lam, rep)


def scaled(path: Path, limits: MachineLimits, jerk_profile: Profile) -> Candidate | None:
    """Candidate 1: the jerk optimum (without holds), slowed down."""
    return verified("jerk scaled", path, limits, jerk_profile)


def fir_filtered(path: Path, limits: MachineLimits, acc_profile: Profile) -> Profile:
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
        W = max(T - r, a_k / J if np.isfinite(J) else 0.0) if T > 0 else 0.0
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
