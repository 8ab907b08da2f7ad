"""Reconstruction of a profile from projected positions: the fourth stage.

Constant path acceleration between the mid-points of sample intervals, with the average
speed of each interval at its mid-point. The acceleration of each cell is then the
second difference of the positions: a weighted *average* of the true acceleration, so a
motion that keeps its limits never appears to break them (a cubic spline through BRISK
samples would overshoot by up to 50 %), and a motion that breaks them shows it.

Where the path requires rest (exact stops, dwells, the ends) and the recording is slow
enough to have stopped there (below ``STOP_SNAP_FACTOR * A * h``), a knot with zero
speed sits exactly at the stop. At every other corner a knot carries the speed the
samples allow there (:func:`_corner_speed`: cells average over the speed dip of a
corner, so the recording is given the benefit of the doubt within what the samples
resolve). Positions between these anchors are scaled (by a factor within ``1 +- 1e-3``
for a good recording) so every anchor sits exactly where it belongs. Rest before the
first and after the last motion is trimmed: time counts from leaving the start point to
arriving at the end point. Rest at a block end is split between the dwell blocks there
(their programmed time) and the block that moved there (the rest,
:func:`_label_holds`).

:func:`measurement_tolerance` gives the ratio tolerance the reconstructed profile is
judged with: 1 %, more for noisy recordings or a large anchor rescaling.

Inputs
    the :class:`~reference.core.geometry.Path`, the machine's
    :class:`~reference.core.limits.MachineLimits`, sample times, s, and path
    positions, mm (non-decreasing, from 0 to the path length), both shape ``(N,)``.
Outputs
    a :class:`~reference.core.profile.Profile` starting at t = 0, s = 0 and ending at
    rest at the path end, with a dict of reconstruction details (see
    :func:`reconstruct`); the measurement tolerance, a fraction.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from reference.core.geometry import Path
from reference.core.limits import MachineLimits
from reference.core.profile import Profile
from reference.core.tolerances import POS_TOL_MM

#: Speed below which a stop is considered reached at the sample resolution, as a
#: multiple of ``A_max * h`` (the speed one sample at full acceleration changes).
STOP_SNAP_FACTOR = 1.5

#: A recording breaks a limit when value/limit exceeds 1 + tolerance. Its motion is
#: measured, not computed: positions are quantised, and the reconstruction between
#: samples places stops and corners exactly by rescaling positions by up to a few 1e-4.
#: 1 % is above both for a clean recording and far below the excess of a planner that
#: really ignores a limit. Noisy recordings get more (:func:`measurement_tolerance`).
RECORDED_RATIO_TOL = 0.01

#: Multiple of the noise-induced uncertainty added to the tolerance of noisy recordings.
NOISE_TOL_FACTOR = 3.0


def _v_corner(tk: np.ndarray, vk: np.ndarray, c: int) -> tuple[float, float] | None:
    """Speed dip at knot ``c`` rebuilt from the lines through its neighbours.

    The cell whose sample interval holds a corner or a stop averages the braking before
    it and the acceleration after it, so its speed overstates the speed at the corner.
    The lines through knots ``c-2, c-1`` and ``c+1, c+2`` meet where the motion turned
    from braking to accelerating; returns ``(t, v)`` of that point, or ``None`` when
    it is not a dip inside ``(t[c-1], t[c+1])``.
    """
    if c < 3 or c + 3 >= tk.size:
        return None
    sb = (vk[c - 1] - vk[c - 2]) / (tk[c - 1] - tk[c - 2])
    sa = (vk[c + 2] - vk[c + 1]) / (tk[c + 2] - tk[c + 1])
    if not sb < sa:
        return None
    # both sides must be one constant-acceleration phase for three cells, else the
    # lines say nothing about the corner (short blocks, corners a few samples apart)
    tol = 0.1 * max(abs(vk[c - 1] - vk[c - 2]), abs(vk[c + 2] - vk[c + 1]))
    if abs(vk[c - 2] + sb * (tk[c - 3] - tk[c - 2]) - vk[c - 3]) > tol or \
            abs(vk[c + 2] + sa * (tk[c + 3] - tk[c + 2]) - vk[c + 3]) > tol:
        return None
    t = (vk[c + 1] - vk[c - 1] + sb * tk[c - 1] - sa * tk[c + 1]) / (sb - sa)
    if not tk[c - 1] < t < tk[c + 1]:
        return None
    v = vk[c - 1] + sb * (t - tk[c - 1])
    if v > vk[c]:
        return None
    return float(t), max(float(v), 0.0)


def _label_holds(path: Path, tk: np.ndarray, S: np.ndarray, vk: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Attribute rest at a block end: dwells get their programmed time, the rest of the
    wait belongs to the block that moved there (exact-stop window, block change).

    A recording cannot tell settling from dwelling; this rule is what the control does
    (the moving block ends when the axes are in position, then the dwell runs), so a
    heuristic's own trajectory read back keeps its per-block times. Dwells take their
    time from the end of the rest. Rest elsewhere keeps the position rule of
    :meth:`Profile.interval_blocks`.

    Returns
    -------
    tk, S, vk : numpy.ndarray
        Knots with extra zero-speed knots where a rest is split between blocks.
    block : numpy.ndarray of int
        Block of each interval (-1: from the position).
    """
    still = (np.abs(np.diff(S)) <= POS_TOL_MM) & (vk[:-1] == 0.0) & (vk[1:] == 0.0)
    if not still.any():
        return tk, S, vk, np.full(tk.size - 1, -1)
    edges = np.diff(np.concatenate(([0], still.astype(np.int8), [0])))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    T, P, V, B = [tk[:1]], [S[:1]], [vk[:1]], []
    prev = 0                                   # next knot not yet copied
    for i_a, i_b in zip(starts, ends):         # hold over intervals [i_a, i_b)
        pos = float(S[i_a])
        arrive = [b for b in path.blocks if b.n_segments and abs(b.s_end - pos) <= POS_TOL_MM]
        dwells = [b for b in path.blocks if not b.n_segments and b.dwell_s > 0
                  and abs(b.s_start - pos) <= POS_TOL_MM]
        if not arrive and not dwells:
            continue
        # copy the motion before the hold
        T.append(tk[prev + 1:i_a + 1]); P.append(S[prev + 1:i_a + 1]); V.append(vk[prev + 1:i_a + 1])
        B.append(np.full(i_a - prev, -1))
        t_a, t_b = float(tk[i_a]), float(tk[i_b])
        left = t_b - t_a
        pieces = []
        for d in reversed(dwells):
            take = min(d.dwell_s, left)
            pieces.append((d.block, take))
            left -= take
        owner = arrive[-1].block if arrive else dwells[0].block
        pieces.append((owner, left))
        t_cur = t_a
        for b, dur in reversed(pieces):
            if dur <= 0:
                continue
            t_cur = min(t_cur + dur, t_b)
            T.append(np.array([t_cur])); P.append(np.array([pos])); V.append(np.zeros(1))
            B.append(np.array([b]))
        if T[-1][-1] < t_b:                    # round-off: close the hold exactly
            T[-1] = np.array([t_b])
        prev = i_b
    T.append(tk[prev + 1:]); P.append(S[prev + 1:]); V.append(vk[prev + 1:])
    B.append(np.full(tk.size - 1 - prev, -1))
    return np.concatenate(T), np.concatenate(P), np.concatenate(V), np.concatenate(B)


def _corner_speed(tk: np.ndarray, vk: np.ndarray, tb: float,
                  dip: tuple[float, float] | None, v_allow: float, a_safe: float) -> float:
    """Path speed at a corner passed at time ``tb`` (between knots ``j`` and ``j + 1``).

    The cells around a corner average over its speed dip, so their speeds overstate the
    speed at the corner. The samples bound it: it is at least ``floor``, the lowest
    speed reachable from the knots next but one (whose cells do not hold the corner) at
    the acceleration observed beside them, with half a cell of slack for the corner
    time, and at most ``est``, the lowest of the linear interpolation, the
    parabola through the three nearest knots corrected for cell averaging (a
    jerk-limited dip) and the V of :func:`_v_corner` (an acceleration-limited dip).
    A recording is judged on what its samples prove: when the allowed corner speed
    ``v_allow`` lies in ``[floor, est]`` the corner gets ``v_allow``; when even ``floor``
    exceeds it, ``floor`` (the excess the samples prove) is kept. The knot never drops
    faster than ``a_safe`` (the smallest axis acceleration limit, mm/s^2) from its
    neighbours.
    """
    j = int(np.clip(np.searchsorted(tk, tb) - 1, 0, tk.size - 2))
    h = tk[j + 1] - tk[j]
    lin = vk[j] + (vk[j + 1] - vk[j]) * (tb - tk[j]) / h
    est = [lin]
    c = int(np.clip(np.argmin(np.abs(tk - tb)), 1, tk.size - 2))
    x, y = tk[c - 1:c + 2] - tb, vk[c - 1:c + 2]
    if np.all(np.diff(x) > 0):
        # knots carry cell averages: the average of a parabola over a cell of width h
        # is its value plus curvature * h^2 / 24, so take that off
        p = np.polyfit(x, y, 2)
        est.append(float(p[2] - p[0] * h * h / 12.0))
    if dip is not None and abs(dip[0] - tb) < h:
        est.append(dip[1])
    # the knots one further out average over cells that do not hold the corner; the
    # corner time itself is known to about half a cell
    b, a = max(j - 1, 0), min(j + 2, tk.size - 1)
    acc = [abs(vk[i + 1] - vk[i]) / (tk[i + 1] - tk[i]) for i in (b - 1, a)
           if 0 <= i < tk.size - 1]
    a_obs = max(acc, default=0.0)
    floor = max(vk[b] - a_obs * (tb - tk[b] + h / 2), vk[a] - a_obs * (tk[a] - tb + h / 2),
                0.0)
    top = max(min(est), floor)
    v = top if top <= v_allow else max(floor, v_allow)
    # never steeper than a_safe towards the neighbouring knots: the knot must not
    # invent an acceleration the recording does not have
    return float(max(v, vk[j] - a_safe * (tb - tk[j]), vk[j + 1] - a_safe * (tk[j + 1] - tb)))


def reconstruct(path: Path, limits: MachineLimits, t: np.ndarray, s: np.ndarray
                ) -> tuple[Profile, dict[str, Any]]:
    """Profile through projected positions (see the module docstring).

    Parameters
    ----------
    path : Path
    limits : MachineLimits
    t : numpy.ndarray, shape (N,)
        Sample times, s (strictly increasing).
    s : numpy.ndarray, shape (N,)
        Path positions, mm, non-decreasing, from 0 to the path length.

    Returns
    -------
    profile : Profile
        Starts at t = 0 and s = 0, ends at rest at the path end.
    info : dict
        ``t_offset_s`` (recording time of profile time 0), ``first_sample`` and
        ``last_sample`` (indices kept after trimming rest at the ends), ``anchors``
        (places pinned exactly: stops and corners), ``scale`` (largest anchor
        scaling ``|f - 1|``), ``unsnapped_stops`` (``(break, s, speed)`` of required
        stops the recording passed too fast to have stopped at).
    """
    L = path.total_length
    eps = 1e-9 * max(1.0, L)
    i0 = max(int(np.searchsorted(s, s[0] + eps, "right")) - 1, 0)
    i1 = max(int(np.searchsorted(s, s[-1] - eps, "left")), i0 + 1)
    tt, ss = t[i0:i1 + 1] - t[i0], s[i0:i1 + 1]
    h = np.diff(tt)
    # knots: the start, the mid-point of every sample interval (with its average
    # speed), the end; speed linear between knots = constant acceleration per cell
    tk = np.concatenate(([0.0], tt[:-1] + h / 2, [tt[-1]]))
    vk = np.concatenate(([0.0], np.diff(ss) / h, [0.0]))
    S = np.concatenate(([0.0], np.cumsum(np.diff(tk) * (vk[:-1] + vk[1:]) / 2)))
    v_snap = STOP_SNAP_FACTOR * float(np.max(limits.for_axes(path.axes).a_max)) * \
        float(np.median(h))
    anchors: dict[int, float] = {0: 0.0, tk.size - 1: L}
    unsnapped: list[tuple[int, float, float]] = []
    corners_at: list[tuple[float, float, float]] = []
    a_safe = float(np.min(limits.for_axes(path.axes).a_max))
    if path.n_segments > 1:
        t_in, t_out = path.junction_tangents()
        d = np.abs(t_out - t_in)
        corner = np.any(d > 1e-9, axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            v_allow = np.min(np.where(d > 1e-9, limits.for_axes(path.axes).jump / d,
                                      np.inf), axis=1)
    for k in range(1, path.n_segments):
        stop = bool(path.stop[k])
        if not (stop or corner[k - 1]):
            continue
        sb = float(path.s_breaks[k])
        tb = float(np.interp(sb, S, tk))
        c = int(np.clip(np.argmin(np.abs(tk - tb)), 1, tk.size - 2))
        if c in anchors:
            continue
        near = np.arange(max(c - 1, 1), min(c + 2, tk.size - 1))
        zero = near[vk[near] == 0.0]
        if zero.size:                       # at rest around the break: a hold
            z = int(zero[np.argmin(np.abs(S[zero] - sb))])
            if z not in anchors:
                anchors[z] = sb
            continue
        dip = _v_corner(tk, vk, c)
        if stop:
            v_pass = dip[1] if dip is not None else float(vk[c])
            if v_pass > v_snap:
                unsnapped.append((k, sb, v_pass))
                continue
            if dip is not None:
                tk[c] = dip[0]
            vk[c] = 0.0
            anchors[c] = sb
        else:
            corners_at.append((tb, sb, _corner_speed(tk, vk, tb, dip, float(v_allow[k - 1]),
                                                     a_safe)))
    # a knot at every corner, at the speed estimated there (cells average over it)
    if corners_at:
        tb = np.array([x[0] for x in corners_at])
        pos = np.searchsorted(tk, tb)
        fresh = (tb - tk[np.clip(pos - 1, 0, tk.size - 1)] > 1e-9) & \
            (tk[np.clip(pos, 0, tk.size - 1)] - tb > 1e-9) & (pos > 0) & (pos < tk.size)
        pos, tb = pos[fresh], tb[fresh]
        vb = np.array([x[2] for x in corners_at])[fresh]
        sbs = np.array([x[1] for x in corners_at])[fresh]
        shift = lambda i: i + int(np.searchsorted(pos, i, "right"))  # noqa: E731
        anchors = {shift(i): v for i, v in anchors.items()}
        tk, vk = np.insert(tk, pos, tb), np.insert(vk, pos, vb)
        for n, (i, sb) in enumerate(zip(pos, sbs)):
            anchors.setdefault(int(i + n), float(sb))
    # scale the speeds between anchors so every anchor lands exactly on its place
    order = sorted(anchors.items())
    dt = np.diff(tk)
    S = np.concatenate(([0.0], np.cumsum(dt * (vk[:-1] + vk[1:]) / 2)))
    worst = 0.0
    kept = [order[0]]
    for a1, s1 in order[1:]:
        a0, s0 = kept[-1]
        fixed = vk[a0] * dt[a0] / 2 + vk[a1] * dt[a1 - 1] / 2
        inner = (S[a1] - S[a0]) - fixed
        f = (s1 - s0 - fixed) / inner if inner > 0 else math.nan
        if not (0.5 < f < 2.0):
            if a1 == tk.size - 1:           # the end must stay: rescale what we can
                f = (s1 - s0) / (S[a1] - S[a0]) if S[a1] > S[a0] else 1.0
                vk[a0 + 1:a1] *= f
                kept.append((a1, s1))
            continue                        # an inconsistent anchor is dropped
        worst = max(worst, abs(f - 1.0))
        vk[a0 + 1:a1] *= f
        kept.append((a1, s1))
    S = np.concatenate(([0.0], np.cumsum(dt * (vk[:-1] + vk[1:]) / 2)))
    for a_i, target in kept:
        S[a_i] = target
    S = np.minimum(np.maximum.accumulate(S), L)
    tk, S, vk, blk = _label_holds(path, tk, S, vk)
    dt = np.diff(tk)
    prof = Profile(t=tk, s=S, v=vk, a=np.diff(vk) / dt, j=np.zeros(dt.size), block=blk)
    info = {"t_offset_s": float(t[i0]), "first_sample": i0, "last_sample": i1,
            "anchors": len(kept), "scale": worst, "unsnapped_stops": unsnapped}
    return prof, info


def measurement_tolerance(path: Path, limits: MachineLimits, t: np.ndarray, sigma: float,
                          scale: float) -> float:
    """Ratio tolerance for judging a recording (see :data:`RECORDED_RATIO_TOL`).

    ``max(1 %, 2 * scale, 3 * noise effect)``: ``scale`` is the largest anchor rescaling
    of :func:`reconstruct`; the noise effect is what position noise ``sigma`` does to a
    speed over one sample (``sqrt(2) sigma / h``) relative to the slowest programmed feed,
    and to an acceleration (``sqrt(6) sigma / h^2``) relative to the smallest axis limit.
    Smoothing reduces both, so this errs towards not reporting what the samples cannot
    prove.
    """
    tol = max(RECORDED_RATIO_TOL, 2.0 * scale)
    if sigma > 0:
        h = float(np.median(np.diff(t)))
        lim = limits.for_axes(path.axes)
        feeds = path.feed[np.isfinite(path.feed)]
        v_ref = float(np.min(feeds)) if feeds.size else float(np.min(lim.v_max))
        noise = max(math.sqrt(2.0) * sigma / h / v_ref,
                    math.sqrt(6.0) * sigma / h ** 2 / float(np.min(lim.a_max)))
        tol = max(tol, NOISE_TOL_FACTOR * noise)
    return tol
