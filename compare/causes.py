"""What limits the speed of a profile in each NC block, derived from the motion itself.

Planners that report their own limiting cause per block (the heuristic, the oracle) are
shown with theirs; this module derives one for profiles that do not (recorded
trajectories, or an oracle that reports none), with the same vocabulary
(:data:`CAUSES`).

Rule, per block: sample the motion inside every interval and find, for each limit,
the share of the block's time during which it is *tight* (within :data:`TIGHT_REL` of
its bound). The block's cause is the limit with the largest share; a block that spends
most of its time braking into a required stop or into a corner taken at the
velocity-jump allowance is attributed to that stop or corner instead. A block where no
limit is tight for :data:`MIN_SHARE` of its time is ``"none"``: nothing forced the
motion to be that slow there.
"""

from __future__ import annotations

import numpy as np

from reference.core.causes import (AXIS_ACCELERATION, AXIS_VELOCITY, CAUSES, FEED, JERK,
                                   stop_cause)
from reference.core.geometry import Path
from reference.core.limits import MachineLimits
from reference.core.profile import Profile
from reference.core.rules import (FEASIBLE, axis_acceleration, axis_jerk, is_tangential,
                                  junction_speed_cap)

__all__ = ["CAUSES", "MIN_SHARE", "TIGHT_REL", "derive_causes", "stretch_causes"]

#: A limit is tight where value/limit >= 1 - TIGHT_REL. 2 % covers the oracle's
#: discretisation (constant path acceleration between grid nodes on arcs) and the
#: reconstruction error of recorded trajectories, yet separates real slack.
TIGHT_REL = 0.02

#: A block whose tightest limit is tight for less than this share of its time is "none".
MIN_SHARE = 0.25

#: Samples per profile interval (at 1/6, 1/2 and 5/6 of it; Simpson-like weights).
_TAU = np.array([1.0, 3.0, 5.0]) / 6.0

#: Intervals per chunk (bounds memory on long profiles).
_CHUNK = 50_000

_SHARED = tuple(CAUSES[c] for c in (FEED, AXIS_VELOCITY, AXIS_ACCELERATION, JERK))


def derive_causes(path: Path, limits: MachineLimits, profile: Profile,
                  jerk: bool = True) -> dict[int, str]:
    """Limiting cause of every block of ``path`` for ``profile``.

    Parameters
    ----------
    path : Path
        The path the profile runs on.
    limits : MachineLimits
        Machine limits.
    profile : Profile
        The motion.
    jerk : bool
        Consider the jerk limit (False for acceleration-bounded planners, whose jerk is
        unbounded by design).

    Returns
    -------
    dict[int, str]
        Block index -> one of :data:`CAUSES`, ``"none"`` or ``"-"``.
    """
    if not path.blocks:
        return {}
    n_blocks = max(b.block for b in path.blocks) + 1
    lim = limits.for_axes(path.axes)
    cuts = [b.s_end for b in path.blocks if b.s_end > b.s_start]
    prof = profile.split_at(cuts)
    blk = prof.interval_blocks(path)
    h = np.diff(prof.t)
    moving = np.flatnonzero(np.diff(prof.s) > 0)
    names = _SHARED if jerk else _SHARED[:3]
    tight = {c: np.zeros(n_blocks) for c in names}
    braking = np.zeros(n_blocks)
    time = np.bincount(blk, weights=h, minlength=n_blocks)
    moving_time = np.bincount(blk[moving], weights=h[moving], minlength=n_blocks)
    for lo in range(0, moving.size, _CHUNK):
        k = moving[lo:lo + _CHUNK]
        tau = h[k][:, None] * _TAU[None, :]
        a0, jj = prof.a[k][:, None], prof.j[k][:, None]
        s = prof.s[k][:, None] + prof.v[k][:, None] * tau + a0 * tau ** 2 / 2 + jj * tau ** 3 / 6
        v = np.maximum(prof.v[k][:, None] + a0 * tau + jj * tau ** 2 / 2, 0.0)
        a = a0 + jj * tau
        w = np.repeat(h[k] / _TAU.size, _TAU.size)
        b = np.repeat(blk[k], _TAU.size)
        s, v, a = s.ravel(), v.ravel(), a.ravel()
        j = np.repeat(prof.j[k], _TAU.size)
        ratios = _ratios(path, lim, s, v, a, j, jerk)
        for c in names:
            tight[c] += np.bincount(b, weights=w * (ratios[c] >= 1.0 - TIGHT_REL),
                                    minlength=n_blocks)
        braking += np.bincount(b, weights=w * (a < 0), minlength=n_blocks)
    end_kind = _block_end_kind(path, profile, lim)
    out: dict[int, str] = {}
    for span in path.blocks:
        i = span.block
        T = time[i]
        if T <= 0:
            out[i] = "-"
            continue
        if span.s_end <= span.s_start:          # a hold: dwell or stop without motion
            out[i] = stop_cause(span.stop_reason) if span.stop_reason else "-"
            continue
        # shares of the *motion* time: a wait at rest (exact-stop settle) limits nothing
        T = float(moving_time[i])
        if T <= 0:
            out[i] = "-"
            continue
        shares = {c: tight[c][i] / T for c in names}
        best = max(shares, key=shares.get)
        end = end_kind.get(i, "")
        if end and braking[i] / T >= 0.5:
            out[i] = end
        elif shares[best] >= MIN_SHARE:
            out[i] = best
        else:
            out[i] = end or "none"
    return out


def _ratios(path: Path, lim, s: np.ndarray, v: np.ndarray, a: np.ndarray, j: np.ndarray,
            jerk: bool) -> dict[str, np.ndarray]:
    """value/limit of every shared limit at samples ``(s, v, a, j)``, shape (N,) each."""
    seg = path.segment_index(np.clip(s, 0.0, path.total_length))
    _, dq, ddq, dddq = path.evaluate(np.clip(s, 0.0, path.total_length), segment=seg)
    feed = path.feed[seg]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratios = {
            "feed": np.where(np.isfinite(feed), v / feed, 0.0),
            "axis velocity": np.max(np.abs(dq) * v[:, None] / lim.v_max, axis=1),
            "axis acceleration": np.max(np.abs(axis_acceleration(dq, ddq, v, a))
                                        / lim.a_max, axis=1),
        }
        if jerk:
            jr = axis_jerk(dq, ddq, dddq, v, a, j)
            ratios["jerk"] = np.max(np.abs(jr) / lim.j_max, axis=1)
    return ratios


def stretch_causes(path: Path, limits: MachineLimits, profile: Profile, s0: np.ndarray,
                   s1: np.ndarray, jerk: bool = True, samples: int = 64) -> list[str]:
    """Limiting cause of the motion on path stretches (inserted blocks), by the rule of
    :func:`derive_causes` (the limit tight for the largest share of the time, ``"none"``
    below :data:`MIN_SHARE`), on ``samples`` equal time steps per stretch.

    Parameters
    ----------
    s0, s1 : numpy.ndarray, shape (p,)
        Stretch ends, mm (``s0 < s1``; no stop inside).

    Returns
    -------
    list of str, length p
    """
    if len(s0) == 0:
        return []
    lim = limits.for_axes(path.axes)
    names = _SHARED if jerk else _SHARED[:3]
    t0 = profile.time_at(np.asarray(s0, dtype=np.float64), which="last")
    t1 = profile.time_at(np.asarray(s1, dtype=np.float64), which="first")
    frac = (np.arange(samples) + 0.5) / samples
    t = (t0[:, None] + (t1 - t0)[:, None] * frac[None, :]).ravel()
    s, v, a, j = profile.state(t)
    ratios = _ratios(path, lim, s, np.maximum(v, 0.0), a, j, jerk)
    out = []
    for p in range(len(s0)):
        shares = {c: float(np.mean(ratios[c][p * samples:(p + 1) * samples]
                                   >= 1.0 - TIGHT_REL)) for c in names}
        best = max(shares, key=shares.get)
        out.append(best if shares[best] >= MIN_SHARE else "none")
    return out


def _block_end_kind(path: Path, profile: Profile, lim) -> dict[int, str]:
    """Blocks that end in a required stop or in a corner crossed at the jump allowance."""
    out: dict[int, str] = {}
    if path.n_segments == 0:
        return out
    t_in, t_out = path.junction_tangents()
    tangential = np.concatenate(([True], is_tangential(t_in, t_out), [True]))
    corners: list[tuple[int, int]] = []
    for span in path.blocks:
        if span.n_segments == 0:
            continue
        k = span.first_segment + span.n_segments          # break at the block end
        if path.stop[k]:
            out[span.block] = stop_cause(path.stop_reason[k]) if k < path.n_segments \
                else "forced stop"                        # the program end
        elif not tangential[k]:
            corners.append((span.block, k))
    if corners:
        ks = np.array([k for _, k in corners])
        v_end = profile.state(profile.time_at(path.s_breaks[ks]))[1]
        v_allow = junction_speed_cap(t_in[ks - 1], t_out[ks - 1], lim.jump, FEASIBLE)[0]
        for (b, _), ve, va in zip(corners, v_end, v_allow):
            if ve >= (1.0 - TIGHT_REL) * va:
                out[b] = "corner rule"
    return out
