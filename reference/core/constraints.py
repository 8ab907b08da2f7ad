"""The one constraint checker: judges every profile (heuristic, oracle, recorded) alike.

``check_profile(path, limits, profile)`` evaluates the motion analytically or densely
*inside every interval* (never only at knots) and returns, per constraint, the worst
ratio value/limit with its place (s, t, NC block, axis). A ratio <= 1 satisfies it.

Constraints (:data:`CONSTRAINTS`):

``velocity``
    per-axis ``|q'_i v| <= v_max_i``.
``acceleration``
    per-axis ``|q'_i a + q''_i v^2| <= a_max_i`` (tangential plus centripetal part).
``jerk``
    per-axis ``|q'_i j + 3 q''_i v a + q'''_i v^3| <= j_max_i`` inside intervals, and
    every *step* of an axis acceleration (a knot where the path acceleration jumps, a
    tangential segment break with a curvature jump) spread over one IPO cycle, as the
    control does it: ``|delta a_i| / t_ipo`` against ``path_trans_jerk_i`` at breaks with
    a curvature jump and ``j_max_i`` elsewhere. BRISK profiles therefore show large
    jerk ratios by design; their bound set does not contain jerk.
``feed``
    path speed ``v <= F`` of the segment (no limit for G0).
``velocity_jump``
    at a non-tangential break crossed at speed ``v``: per axis
    ``v |q'_i(right) - q'_i(left)| <= a_max_i (ovl_i - 1) t_ipo`` (MD32310 rule); with
    an allowance of 0 (ovl = 1) any jump gives ``inf``.
``stop``
    ``v = 0`` where the path requires rest (start, end, exact stops, forced stops);
    ratio ``v / VEL_TOL_MM_S``.
``frequency``
    no velocity-change process (a maximal span where the path acceleration keeps one
    non-zero sign) may be shorter than ``1 / f``, ``f`` the smallest LOOKAH_FREQUENCY of
    the axes moving during it; ratio ``(1/f) / duration``.

Sampling inside intervals: on lines the axis quantities are polynomials in time and are
evaluated exactly (interval ends and the stationary point of ``v``). On arcs and helices
they are sampled at an angular step of at most :data:`ARC_SAMPLE_STEP_RAD` (and at
least :data:`MIN_ARC_SAMPLES` points per interval, plus the stationary point of ``v``);
a maximum of a ``cos``-type function sampled at step ``dphi`` is missed by at most
``dphi^2 / 8`` relative, 2.4e-6 for 0.25 degrees, below :data:`RATIO_TOL` = 1e-6 only
after the factor-2 oversampling applied here (step 0.125 deg: 6e-7).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterable, Mapping

import numpy as np

from .geometry import Path
from .limits import MachineLimits
from .profile import Profile
from .errors import ProfileError
from .tolerances import POS_TOL_MM, RATIO_TOL, TANGENT_TOL_RAD, VEL_TOL_MM_S

CONSTRAINTS: tuple[str, ...] = ("velocity", "acceleration", "jerk", "feed", "velocity_jump",
                                "stop", "frequency")
BOUND_SETS: dict[str, tuple[str, ...]] = {
    "acc": ("velocity", "acceleration", "feed", "velocity_jump", "stop"),
    "jerk": ("velocity", "acceleration", "feed", "velocity_jump", "stop", "jerk"),
    "jerk+freq": ("velocity", "acceleration", "feed", "velocity_jump", "stop", "jerk",
                  "frequency"),
}
UNITS = {"velocity": "mm/s", "acceleration": "mm/s^2", "jerk": "mm/s^3", "feed": "mm/s",
         "velocity_jump": "mm/s", "stop": "mm/s", "frequency": "s"}

#: Angular sampling step on arcs, rad (0.125 deg: a cos-peak error of 6e-7 relative).
ARC_SAMPLE_STEP_RAD = np.deg2rad(0.125)
#: Fewest samples per interval on an arc.
MIN_ARC_SAMPLES = 8
#: Intervals per chunk: bounds memory to a few MB whatever the profile length.
CHUNK_INTERVALS = 20_000
#: Path accelerations below this fraction of the profile's largest |a| count as zero
#: when cutting the motion into velocity-change processes (round-off of a = 0 phases).
FREQ_ACCEL_TOL_REL = 1e-6


@dataclass(frozen=True, slots=True)
class ConstraintResult:
    """Worst place of one constraint.

    Attributes
    ----------
    constraint : str
        One of :data:`CONSTRAINTS`.
    ratio : float
        value / limit at the worst place (<= 1 satisfied; ``inf`` for a forbidden jump).
    value, limit : float
        In ``unit``.
    unit : str
        Unit of value and limit.
    s : float
        Path position, mm.
    t : float
        Time, s.
    block : int
        NC block index (-1 where not tied to one).
    axis : str or None
        Axis name for per-axis constraints.
    """

    constraint: str
    ratio: float
    value: float
    limit: float
    unit: str
    s: float
    t: float
    block: int
    axis: str | None

    @property
    def violated(self) -> bool:
        """True when the ratio exceeds 1 + RATIO_TOL."""
        return self.ratio > 1.0 + RATIO_TOL


@dataclass(frozen=True, slots=True)
class ConstraintReport:
    """Worst ratio per constraint, plus the worst ratio per NC block.

    Attributes
    ----------
    results : tuple[ConstraintResult, ...]
        One per constraint in :data:`CONSTRAINTS` order.
    block_ratios : Mapping[str, numpy.ndarray]
        Per constraint, shape ``(n_blocks,)`` worst ratio by NC block index.
    """

    results: tuple[ConstraintResult, ...]
    block_ratios: Mapping[str, np.ndarray] = field(default_factory=dict)

    def worst(self, name: str) -> ConstraintResult:
        """The result of one constraint."""
        for r in self.results:
            if r.constraint == name:
                return r
        raise KeyError(f"unknown constraint {name!r}; known: {', '.join(CONSTRAINTS)}")

    def violations(self, constraints: Iterable[str] | None = None,
                   tol: float = RATIO_TOL) -> tuple[ConstraintResult, ...]:
        """Results with ratio > 1 + tol, restricted to ``constraints`` (default all)."""
        names = set(CONSTRAINTS if constraints is None else constraints)
        return tuple(r for r in self.results if r.constraint in names and r.ratio > 1 + tol)

    def ok(self, constraints: Iterable[str] | None = None, tol: float = RATIO_TOL) -> bool:
        """True when no constraint in ``constraints`` is violated."""
        return not self.violations(constraints, tol)

    def max_ratio(self, constraints: Iterable[str] | None = None) -> float:
        """Largest ratio among ``constraints``."""
        names = set(CONSTRAINTS if constraints is None else constraints)
        return max((r.ratio for r in self.results if r.constraint in names), default=0.0)


class _Worst:
    """Running maximum of one constraint over chunks (private accumulator)."""

    __slots__ = ("ratio", "value", "limit", "s", "t", "block", "axis", "per_block")

    def __init__(self, n_blocks: int) -> None:
        self.ratio, self.value, self.limit = 0.0, 0.0, 0.0
        self.s = self.t = 0.0
        self.block, self.axis = -1, None
        self.per_block = np.zeros(n_blocks)

    def update(self, ratio, value, limit, s, t, block, axis_idx, axes) -> None:
        """ratio/value/limit shaped (N, n_axes) or (N,); s, t, block shaped (N,)."""
        if ratio.size == 0:
            return
        r2 = ratio if ratio.ndim == 2 else ratio[:, None]
        per_row = r2.max(axis=1)
        if self.per_block.size:
            np.maximum.at(self.per_block, block, per_row)
        flat = int(np.argmax(r2))
        row, col = divmod(flat, r2.shape[1])
        if r2[row, col] > self.ratio or self.block < 0 and r2[row, col] >= self.ratio:
            self.ratio = float(r2[row, col])
            v2 = value if value.ndim == 2 else value[:, None]
            lim = np.asarray(limit, dtype=np.float64)
            if lim.ndim == 0:
                lval = float(lim)
            elif lim.ndim == 1 and ratio.ndim == 1:
                lval = float(lim[row])               # one limit per sample
            elif lim.ndim == 1:
                lval = float(lim[col])               # one limit per axis
            else:
                lval = float(lim[row, col])
            self.value, self.limit = float(v2[row, col]), lval
            self.s, self.t, self.block = float(s[row]), float(t[row]), int(block[row])
            self.axis = axes[col] if axis_idx else None

    def result(self, name: str) -> ConstraintResult:
        return ConstraintResult(name, self.ratio, self.value, self.limit, UNITS[name],
                                self.s, self.t, self.block, self.axis)


def _safe_div(num: np.ndarray, den: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(den > 0, num / np.where(den > 0, den, 1.0), np.where(num > 0, np.inf, 0.0))
    return r


def check_profile(path: Path, limits: MachineLimits, profile: Profile) -> ConstraintReport:
    """Judge a profile against the machine limits on its path.

    Parameters
    ----------
    path : Path
        The path the profile runs on.
    limits : MachineLimits
        Machine limits; must define every axis of the path.
    profile : Profile
        The motion ``s(t)``; its ``s`` must span ``[0, path.total_length]``.

    Returns
    -------
    ConstraintReport
        Worst ratio per constraint with its place, and per NC block.
    """
    lim = limits.for_axes(path.axes)
    axes = path.axes
    if profile.s.size and (abs(profile.s[0]) > POS_TOL_MM or
                           abs(profile.s[-1] - path.total_length) > POS_TOL_MM * max(
                               1.0, path.total_length)):
        raise ProfileError(f"profile starts at s = {profile.s[0]:.6g} mm and ends at s = "
                           f"{profile.s[-1]:.6g} mm but the path is "
                           f"{path.total_length:.6g} mm long")
    n_blocks = (max(b.block for b in path.blocks) + 1) if path.blocks else 0
    worst = {c: _Worst(n_blocks) for c in CONSTRAINTS}
    if path.n_segments == 0 or profile.n_intervals == 0:
        st = worst["stop"]
        v_max = float(np.max(profile.v)) if profile.v.size else 0.0
        st.ratio, st.value, st.limit = v_max / VEL_TOL_MM_S, v_max, VEL_TOL_MM_S
        return ConstraintReport(tuple(worst[c].result(c) for c in CONSTRAINTS),
                                {c: worst[c].per_block for c in CONSTRAINTS})
    prof = profile.split_at(path.s_breaks)
    h_all = np.diff(prof.t)
    ds_all = np.diff(prof.s)
    moving = np.flatnonzero(ds_all > 0)
    for lo in range(0, moving.size, CHUNK_INTERVALS):
        _check_intervals(path, lim, prof, moving[lo:lo + CHUNK_INTERVALS], h_all, worst, axes)
    _check_knots(path, lim, limits.t_ipo_s, prof, worst, axes)
    _check_frequency(path, lim, prof, worst, axes)
    return ConstraintReport(tuple(worst[c].result(c) for c in CONSTRAINTS),
                            {c: worst[c].per_block for c in CONSTRAINTS})


def _check_intervals(path, lim, prof, k, h_all, worst, axes) -> None:
    """Dense/analytic evaluation inside the moving intervals ``k`` (one chunk)."""
    h = h_all[k]
    s0, v0, a0, jj = prof.s[k], prof.v[k], prof.a[k], prof.j[k]
    seg = path.segment_index(0.5 * (prof.s[k] + prof.s[k + 1]))
    arc = path.radius[seg] > 0
    dphi = np.abs(path.omega[seg]) * (prof.s[k + 1] - prof.s[k])
    n_s = np.where(arc, np.maximum(MIN_ARC_SAMPLES,
                                   np.ceil(dphi / ARC_SAMPLE_STEP_RAD).astype(np.int64) + 1), 2)
    n_s = n_s + 1                                          # + the stationary point of v
    idx = np.repeat(np.arange(k.size), n_s)
    first = np.concatenate(([0], np.cumsum(n_s)[:-1]))
    pos = np.arange(idx.size) - first[idx]
    n_uni = n_s[idx] - 1
    tau = h[idx] * np.minimum(pos, n_uni - 1) / np.maximum(n_uni - 1, 1)
    # the last sample of each interval is the stationary point of v (a + j tau = 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        tstar = np.where(jj != 0, -a0 / np.where(jj != 0, jj, 1.0), -1.0)
    tstar = np.clip(np.where((tstar > 0) & (tstar < h), tstar, 0.0), 0.0, h)
    is_star = pos == n_s[idx] - 1
    tau = np.where(is_star, tstar[idx], tau)
    a_i, j_i = a0[idx], jj[idx]
    s = s0[idx] + v0[idx] * tau + a_i * tau ** 2 / 2 + j_i * tau ** 3 / 6
    v = np.maximum(v0[idx] + a_i * tau + j_i * tau ** 2 / 2, 0.0)
    a = a_i + j_i * tau
    segi = seg[idx]
    # keep s inside the segment (round-off at the interval end)
    s = np.clip(s, path.s_breaks[segi], path.s_breaks[segi + 1])
    _, dq, ddq, dddq = path.evaluate(s, segment=segi)
    t = prof.t[k][idx] + tau
    blk = path.block[segi]
    vel = np.abs(dq * v[:, None])
    acc = np.abs(dq * a[:, None] + ddq * (v * v)[:, None])
    jer = np.abs(dq * j_i[:, None] + 3 * ddq * (v * a)[:, None] + dddq * (v ** 3)[:, None])
    worst["velocity"].update(vel / lim.v_max, vel, lim.v_max, s, t, blk, True, axes)
    worst["acceleration"].update(acc / lim.a_max, acc, lim.a_max, s, t, blk, True, axes)
    worst["jerk"].update(jer / lim.j_max, jer, lim.j_max, s, t, blk, True, axes)
    feed = path.feed[segi]
    finite = np.isfinite(feed)
    if finite.any():
        worst["feed"].update(v[finite] / feed[finite], v[finite], feed[finite], s[finite],
                             t[finite], blk[finite], False, axes)


def _check_knots(path, lim, t_ipo, prof, worst, axes) -> None:
    """Velocity jumps and acceleration steps at knots; rest where the path stops."""
    K = prof.n_intervals
    # knot index of the first arrival at each break (breaks are knots after split_at)
    kb = np.searchsorted(prof.s, path.s_breaks, side="left")
    kb = np.clip(kb, 0, K)
    v_b = prof.v[kb]
    t_b = prof.t[kb]
    m = path.n_segments
    breaks = np.arange(m + 1)
    seg_after = np.minimum(breaks, m - 1)
    blk_b = path.block[seg_after]
    # --- stops (start, end, exact and forced stops)
    stop = np.flatnonzero(path.stop)
    # at a stop the motion must be at rest on arrival and on departure
    kl = np.clip(np.searchsorted(prof.s, path.s_breaks, side="right") - 1, 0, K)
    v_stop = np.maximum(v_b[stop], prof.v[kl[stop]])
    worst["stop"].update(v_stop / VEL_TOL_MM_S, v_stop, VEL_TOL_MM_S,
                         path.s_breaks[stop], t_b[stop], path.block[np.minimum(
                             np.maximum(stop - 1, 0), m - 1)], False, axes)
    if m >= 2:
        t_in, t_out = path.junction_tangents()
        k_in, k_out = path.junction_curvatures()
        vj = v_b[1:m]
        dv = np.abs(t_out - t_in) * vj[:, None]
        ratio = _safe_div(dv, np.broadcast_to(lim.jump, dv.shape))
        ratio = np.where(dv <= VEL_TOL_MM_S, 0.0, ratio)
        worst["velocity_jump"].update(ratio, dv, np.broadcast_to(lim.jump, dv.shape),
                                      path.s_breaks[1:m], t_b[1:m], path.block[:m - 1], True,
                                      axes)
        # acceleration step at tangential breaks (curvature jump and/or s'' jump)
        cosang = np.sum(t_in * t_out, axis=1) / np.maximum(
            np.linalg.norm(t_in, axis=1) * np.linalg.norm(t_out, axis=1), 1e-300)
        tangential = np.arccos(np.clip(cosang, -1, 1)) <= TANGENT_TOL_RAD
        k_left = np.clip(kb[1:m] - 1, 0, K - 1)
        k_right = np.clip(kb[1:m], 0, K - 1)
        h_left = prof.t[k_left + 1] - prof.t[k_left]
        a_left = prof.a[k_left] + prof.j[k_left] * h_left
        a_right = prof.a[k_right]
        # a hold at the break: the acceleration at departure is the one after the hold
        acc_l = t_in * a_left[:, None] + k_in * (vj * vj)[:, None]
        acc_r = t_out * a_right[:, None] + k_out * (vj * vj)[:, None]
        step = np.abs(acc_r - acc_l)
        curv_jump = np.any(np.abs(k_out - k_in) > 1e-12, axis=1)
        jlim = np.where(curv_jump[:, None], lim.path_trans_jerk[None, :], lim.j_max[None, :])
        jstep = step / t_ipo
        rj = np.where(tangential[:, None], jstep / jlim, 0.0)
        worst["jerk"].update(rj, jstep, jlim, path.s_breaks[1:m], t_b[1:m], path.block[1:m],
                             True, axes)
    # --- acceleration steps at knots inside segments (BRISK switching points)
    if K >= 2:
        inner = np.arange(1, K)
        ds_prev = prof.s[inner] - prof.s[inner - 1]
        ds_next = prof.s[inner + 1] - prof.s[inner]
        on_break = np.isin(prof.s[inner], path.s_breaks)
        keep = (ds_prev > 0) & (ds_next > 0) & ~on_break
        kk = inner[keep]
        if kk.size:
            h_prev = prof.t[kk] - prof.t[kk - 1]
            a_left = prof.a[kk - 1] + prof.j[kk - 1] * h_prev
            da = np.abs(prof.a[kk] - a_left)
            seg = path.segment_index(prof.s[kk])
            _, dq, _, _ = path.evaluate(prof.s[kk], segment=seg)
            jstep = np.abs(dq) * (da / t_ipo)[:, None]
            worst["jerk"].update(jstep / lim.j_max, jstep, lim.j_max, prof.s[kk], prof.t[kk],
                                 path.block[seg], True, axes)


def _check_frequency(path, lim, prof, worst, axes) -> None:
    """Shortest velocity-change process against 1/f of the axes moving in it."""
    K = prof.n_intervals
    h = np.diff(prof.t)
    a0, jj = prof.a, prof.j
    a1 = a0 + jj * h
    scale = max(float(np.max(np.abs(a0))), float(np.max(np.abs(a1))), 0.0)
    if scale == 0.0:
        return
    tol = FREQ_ACCEL_TOL_REL * scale
    # split each interval where a(tau) crosses zero (at most once: a is linear in tau)
    with np.errstate(divide="ignore", invalid="ignore"):
        tz = np.where(jj != 0, -a0 / np.where(jj != 0, jj, 1.0), -1.0)
    cross = (tz > 0) & (tz < h) & (np.sign(a0) != np.sign(a1))
    t_start = np.concatenate([prof.t[:-1], prof.t[:-1][cross] + tz[cross]])
    t_end = np.concatenate([np.where(cross, prof.t[:-1] + tz, prof.t[1:]), prof.t[1:][cross]])
    a_mid_first = np.where(cross, a0 / 2, (a0 + a1) / 2)
    a_mid_second = (a1[cross]) / 2
    a_mid = np.concatenate([a_mid_first, a_mid_second])
    src = np.concatenate([np.arange(K), np.flatnonzero(cross)])
    order = np.argsort(t_start, kind="stable")
    t_start, t_end, a_mid, src = t_start[order], t_end[order], a_mid[order], src[order]
    sign = np.where(np.abs(a_mid) <= tol, 0, np.sign(a_mid)).astype(int)
    sign = np.where(np.diff(prof.s)[src] > 0, sign, 0)      # holds separate processes
    if not np.any(sign):
        return
    # runs of equal non-zero sign
    change = np.flatnonzero(np.diff(sign) != 0) + 1
    starts = np.concatenate(([0], change))
    ends = np.concatenate((change, [sign.size]))
    run_sign = sign[starts]
    keep = run_sign != 0
    starts, ends = starts[keep], ends[keep]
    dur = t_end[ends - 1] - t_start[starts]
    # axes moving during each process: sample the tangent at piece mid-points
    s_mid = 0.5 * (prof.s[src] + prof.s[src + 1])
    _, dq, _, _ = path.evaluate(s_mid)
    moving_axes = np.abs(dq) > 1e-9
    run_id = np.repeat(np.arange(starts.size), ends - starts)
    piece = np.concatenate([np.arange(a, b) for a, b in zip(starts, ends)]) if starts.size else \
        np.zeros(0, int)
    mv = np.zeros((starts.size, len(axes)), bool)
    np.logical_or.at(mv, run_id, moving_axes[piece])
    f = np.where(mv, lim.frequency_hz[None, :], np.inf)
    f_min = f.min(axis=1)
    ax_min = f.argmin(axis=1)
    finite = np.isfinite(f_min)
    if not finite.any():
        return
    need = np.where(finite, 1.0 / np.where(finite, f_min, 1.0), 0.0)
    ratio = _safe_div(need, dur)
    i = int(np.argmax(ratio))
    s_at = prof.s[src[starts[i]]]
    blk_all = path.block_of(prof.s[src[starts]])
    w = worst["frequency"]
    if w.per_block.size:
        np.maximum.at(w.per_block, blk_all, ratio)
    w.ratio, w.value, w.limit = float(ratio[i]), float(dur[i]), float(need[i])
    w.s, w.t, w.block = float(s_at), float(t_start[starts[i]]), int(blk_all[i])
    w.axis = axes[int(ax_min[i])]


def time_scale_factor(report: ConstraintReport, constraints: Iterable[str]) -> float:
    """Smallest factor ``lam >= 1`` by which slowing the profile down in time satisfies
    the given constraints (velocity-like ratios scale with ``1/lam``, acceleration with
    ``1/lam^2``, jerk with ``1/lam^3``, frequency ratios with ``1/lam``).

    ``stop`` violations cannot be fixed by time scaling and are ignored here.
    """
    power = {"velocity": 1, "feed": 1, "velocity_jump": 1, "acceleration": 2, "jerk": 3,
             "frequency": 1}
    lam = 1.0
    for name in constraints:
        if name not in power:
            continue
        r = report.worst(name).ratio
        if r > 1.0:
            lam = max(lam, r ** (1.0 / power[name]))
    return lam


def scale_time(profile: Profile, lam: float) -> Profile:
    """The same path motion slowed down by ``lam`` (t * lam, v / lam, a / lam^2, j / lam^3)."""
    return Profile(t=profile.t * lam, s=profile.s, v=profile.v / lam,
                   a=profile.a / lam ** 2, j=profile.j / lam ** 3, block=profile.block)
