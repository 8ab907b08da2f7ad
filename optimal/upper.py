"""The upper bound: the continuous motion behind a grid solution, verified by the checker.

A solution ``b`` of the grid problem (:mod:`optimal.problem`) fixes ``v^2`` at the nodes.
Between them this module chooses the motion whose time is the upper bound:

* **Lines** (constant tangent ``u``): the fastest motion between the two node speeds,
  ``b(s) = min(cap, b_k + M t, b_{k+1} + M (D - t))``, with the segment's own speed cap
  ``cap = min(F^2, min_j (V_j / |u_j|)^2)`` and ``M = 2 min_j A_j / |u_j|`` (accelerate at
  the limit, cruise at the cap, brake at the limit). On a line the axis constraints are
  exactly ``|v| <= sqrt(cap)`` and ``|s''| <= M / 2``, so this *tent* is feasible and no
  motion with those end values is faster: a line interval is exact at any size, however
  short the real acceleration phase is against the interval (at a feed change or a stop
  the linear ``b`` of the grid problem spreads a phase of micrometres over the whole
  interval, a first-order error that only halving after halving would remove). The
  grid problem's rows on a line are the exact ``|u_j| |b_{k+1} - b_k| / (2 D) <= A_j``,
  so its node values are reachable by the tents. Up to three pieces of constant
  acceleration per interval (:func:`grid_profile`).
* **Circles, helices and spirals**: ``b`` linear in ``s`` (constant acceleration), or
  quadratic where the grid problem carries a slope ``gamma`` (:mod:`optimal.problem`;
  then the interval becomes the constant-jerk motion with the same duration, end speeds
  and length).

``check_profile`` judges the result inside every interval; if any ratio of the bound set
exceeds 1 the profile is slowed down in time by ``time_scale_factor`` and the upper bound
is the duration of that accepted profile.

Units: mm, s. Shapes: ``N`` intervals, ``n`` axes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.core.constraints import (BOUND_SETS, ConstraintReport, check_profile,
                                        scale_time, time_scale_factor)
from reference.core.errors import InternalError
from reference.core.geometry import Path
from reference.core.limits import AxisArrays, MachineLimits
from reference.core.profile import Profile

from .bounds import tent_times
from .grid import Grid
from .problem import interval_times


@dataclass(frozen=True, slots=True, eq=False)
class LineTents:
    """Speed cap and acceleration bound of every line interval (the tents' shape).

    Attributes
    ----------
    cap : numpy.ndarray, shape (N,)
        ``v^2`` cap inside the interval, mm^2/s^2 (``nan`` off lines).
    slope : numpy.ndarray, shape (N,)
        ``M = 2 A_path``, the largest ``|db/ds|``, mm/s^2 (``nan`` off lines).
    """

    cap: np.ndarray
    slope: np.ndarray

    @property
    def on(self) -> np.ndarray:
        """Intervals that get a tent (lines with a finite cap and slope)."""
        return np.isfinite(self.cap) & np.isfinite(self.slope) & (self.slope > 0)


def line_tents(path: Path, lim: AxisArrays, grid: Grid) -> LineTents:
    """:class:`LineTents` of ``grid``: the exact limits of its line intervals.

    Parameters
    ----------
    path : Path
        The path.
    lim : AxisArrays
        Limits in the path's axis order.
    grid : Grid
        Nodes.

    Returns
    -------
    LineTents
    """
    seg = grid.segment
    N = seg.size
    cap = np.full(N, np.nan)
    slope = np.full(N, np.nan)
    line = np.flatnonzero((path.radius[seg] == 0) & np.any(path.d[seg] != 0, axis=1))
    if line.size:
        u = np.abs(path.d[seg[line]])
        with np.errstate(divide="ignore"):
            inv = np.where(u > 0, 1.0 / np.where(u > 0, u, 1.0), np.inf)
        v = np.min(lim.v_max[None, :] * inv, axis=1)
        cap[line] = np.minimum(path.feed[seg[line]], v) ** 2
        slope[line] = 2.0 * np.min(lim.a_max[None, :] * inv, axis=1)
    return LineTents(cap, slope)


def upper_interval_times(s: np.ndarray, b: np.ndarray, gamma: np.ndarray | None,
                         tents: LineTents | None) -> np.ndarray:
    """Time of every interval of the motion :func:`grid_profile` builds, s.

    The tent time (:func:`optimal.bounds.tent_times`, exact here: the tent *is* the
    motion) on lines, :func:`optimal.problem.interval_times` elsewhere.
    """
    t = interval_times(s, b, gamma)
    if tents is None:
        return t
    on = tents.on
    if np.any(on):
        tt = tent_times(s, b, np.where(on, tents.cap, np.inf), np.where(on, tents.slope,
                                                                        np.inf))
        t = np.where(on, tt, t)
    return t


def _tent_pieces(Dl: np.ndarray, b0: np.ndarray, b1: np.ndarray, v0: np.ndarray,
                 v1: np.ndarray, cap: np.ndarray, M: np.ndarray):
    """The tent of every line interval as three pieces (accelerate, cruise, brake).

    Parameters
    ----------
    Dl, b0, b1, v0, v1, cap, M : numpy.ndarray, shape (L,)
        Interval lengths (mm), end values of ``b`` (mm^2/s^2) and ``v`` (mm/s), the
        ``b`` cap and the slope ``M`` (:class:`LineTents`).

    Returns
    -------
    P, dur, V1, acc : numpy.ndarray, shape (L, 3)
        Piece lengths (mm, 0 for absent pieces), durations (s), end speeds (mm/s) and
        accelerations (mm/s^2).
    """
    cap = np.maximum(cap, np.maximum(b0, b1))
    l1 = np.clip((cap - b0) / M, 0.0, Dl)
    l3 = np.clip((cap - b1) / M, 0.0, Dl)
    meet = l1 + l3 > Dl                      # no cruise: the two ramps meet at a peak
    lp = np.clip((b1 - b0 + M * Dl) / (2.0 * M), 0.0, Dl)
    l1 = np.where(meet, lp, l1)
    l3 = np.where(meet, Dl - lp, l3)
    # pieces shorter than round-off of the interval are none (a ramp of 1e-17 mm would
    # carry an acceleration made of round-off): their length goes to the neighbour;
    # but only where the speed they change is round-off too: at 1 mm/min a real ramp to
    # the next block's 1.5 mm/min at 2 m/s^2 is 9e-8 mm long, 1e-9 of its 87 mm interval,
    # and dropping it left a speed jump the next interval's integration missed by 29 mm
    tiny = 1e-9 * Dl
    l1 = np.where((l1 < tiny) & (M * l1 <= 1e-9 * cap), 0.0, l1)
    l3 = np.where((l3 < tiny) & (M * l3 <= 1e-9 * cap), 0.0, l3)
    l2 = Dl - l1 - l3
    l2 = np.where(l2 < tiny, 0.0, l2)
    l1 = np.where((l2 == 0.0) & (l1 > 0), Dl - l3, l1)
    l3 = np.where((l2 == 0.0) & (l1 == 0), Dl, l3)
    vp = np.sqrt(np.minimum(cap, b0 + M * l1))     # speed at the peak or while cruising
    P = np.stack([l1, l2, l3], 1)                  # (L, 3) piece lengths
    V0 = np.stack([v0, vp, vp], 1)
    V1 = np.stack([vp, vp, v1], 1)
    keep = P > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        dur = np.where(keep, 2.0 * P / (V0 + V1), 0.0)
    # a ramp's acceleration from its end speeds (consistent with the knots), never above
    # the tent's own M / 2 in size (round-off); cruising: 0
    half = (M / 2.0)[:, None]
    acc = np.where(keep, np.clip((V1 - V0) / np.where(dur > 0, dur, 1.0), -half, half), 0.0)
    acc[:, 1] = 0.0
    return P, dur, V1, acc


def line_phase_times(s: np.ndarray, b: np.ndarray, tents: LineTents
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Time of the motion :func:`grid_profile` builds in each phase of every line
    interval.

    Returns
    -------
    line : numpy.ndarray of int, shape (L,)
        The line intervals (those with a tent).
    dur : numpy.ndarray, shape (L, 3)
        Seconds accelerating, cruising at the cap and braking.
    """
    s = np.asarray(s, dtype=np.float64)
    b = np.maximum(np.asarray(b, dtype=np.float64), 0.0)
    v = np.sqrt(b)
    line = np.flatnonzero(tents.on)
    _, dur, _, _ = _tent_pieces(np.diff(s)[line], b[line], b[line + 1], v[line],
                                v[line + 1], tents.cap[line], tents.slope[line])
    return line, dur


def grid_profile(s: np.ndarray, b: np.ndarray, block: np.ndarray,
                 gamma: np.ndarray | None = None, tents: LineTents | None = None
                 ) -> Profile:
    """The continuous motion behind a grid solution (module docstring).

    Parameters
    ----------
    s, b : numpy.ndarray, shape (N + 1,)
        Nodes (mm) and squared speeds (mm^2/s^2).
    block : numpy.ndarray of int, shape (N,)
        NC block of each interval.
    gamma : numpy.ndarray, shape (N,), optional
        Slopes of the path acceleration the grid problem was solved with, 1/s^2.
    tents : LineTents, optional
        Caps and slopes of the line intervals (none: ``b`` linear there too).

    Returns
    -------
    Profile
        With up to three knots per line interval (accelerate, cruise, brake).
    """
    s = np.asarray(s, dtype=np.float64)
    b = np.maximum(np.asarray(b, dtype=np.float64), 0.0)
    v = np.sqrt(b)
    N = s.size - 1
    D = np.diff(s)
    g = np.zeros(N) if gamma is None else np.asarray(gamma, dtype=np.float64)
    # ---- one piece per interval: b linear (gamma = 0) or quadratic in s
    h = interval_times(s, b, g)
    if not np.all(np.isfinite(h)):
        k = int(np.flatnonzero(~np.isfinite(h))[0])
        raise InternalError(f"grid profile: interval {k} is never traversed "
                            f"(b = {b[k]:.6g}, {b[k + 1]:.6g} mm^2/s^2)")
    X = v[1:] - v[:-1]
    Y = D - v[:-1] * h
    a = np.where(g == 0, X / h, (6.0 * Y - 2.0 * X * h) / (h * h))
    j = np.where(g == 0, 0.0, 2.0 * (X - a * h) / (h * h))
    del X, Y
    line = np.flatnonzero(tents.on) if tents is not None else np.zeros(0, np.int64)
    if line.size == 0:
        t = np.concatenate(([0.0], np.cumsum(h)))
        return Profile(t=t, s=s, v=v, a=a, j=j, block=block)
    # ---- line intervals: three pieces (accelerate, cruise, brake)
    P, dur, V1, acc = _tent_pieces(D[line], b[line], b[line + 1], v[line], v[line + 1],
                                   tents.cap[line], tents.slope[line])
    keep = P > 0
    if not np.all(np.isfinite(dur)):
        k = int(line[np.flatnonzero(~np.all(np.isfinite(dur), axis=1))[0]])
        raise InternalError(f"grid profile: interval {k} is never traversed "
                            f"(b = {b[k]:.6g}, {b[k + 1]:.6g} mm^2/s^2)")
    # ---- assemble: every interval's pieces in order (1 off lines, 1 to 3 on lines)
    count = np.ones(N, dtype=np.int64)
    count[line] = keep.sum(axis=1)
    first = np.concatenate(([0], np.cumsum(count)[:-1]))
    K = int(count.sum())
    pl = np.empty(K)                  # piece lengths
    pd = np.empty(K)                  # durations
    pa = np.empty(K)
    pj = np.zeros(K)
    pv = np.empty(K)                  # speed at each piece's end
    other = np.ones(N, bool)
    other[line] = False
    io = first[other]
    pl[io], pd[io], pa[io], pj[io], pv[io] = D[other], h[other], a[other], j[other], v[1:][other]
    rank = np.cumsum(keep, axis=1) - 1             # position of a kept piece in its interval
    idx = (first[line][:, None] + rank)[keep]
    pl[idx], pd[idx], pa[idx], pv[idx] = P[keep], dur[keep], acc[keep], V1[keep]
    knots_s = np.concatenate(([s[0]], s[0] + np.cumsum(pl)))
    knots_s[first + count] = s[1:]                 # each interval ends at its node exactly
    t = np.concatenate(([0.0], np.cumsum(pd)))
    return Profile(t=t, s=knots_s, v=np.concatenate(([v[0]], pv)), a=pa, j=pj,
                   block=np.repeat(np.asarray(block), count))


def verified_profile(path: Path, limits: MachineLimits, s: np.ndarray, b: np.ndarray,
                     block: np.ndarray, bounds: str = "acc",
                     gamma: np.ndarray | None = None, tents: LineTents | None = None
                     ) -> tuple[Profile, float, ConstraintReport]:
    """The grid profile, judged by ``check_profile`` and time-scaled until accepted.

    Parameters
    ----------
    path : Path
        The path.
    limits : MachineLimits
        Machine limits.
    s, b : numpy.ndarray, shape (N + 1,)
        Nodes (mm) and squared speeds (mm^2/s^2).
    block : numpy.ndarray of int, shape (N,)
        NC block of each interval.
    bounds : str
        Bound set of :data:`BOUND_SETS`.
    gamma : numpy.ndarray, shape (N,), optional
        Slopes of the path acceleration the grid problem was solved with.
    tents : LineTents, optional
        Line intervals' caps and slopes (:func:`line_tents`).

    Returns
    -------
    profile : Profile
        The accepted (possibly slowed-down) profile.
    lam : float
        Time-scale factor applied (>= 1).
    report : ConstraintReport
        The checker's report on the *unscaled* grid profile.
    """
    prof = grid_profile(s, b, block, gamma, tents)
    report = check_profile(path, limits, prof)
    lam = time_scale_factor(report, BOUND_SETS[bounds])
    if not np.isfinite(lam):
        # the grid problem obeys the rulebook's feasible caps, which the checker accepts
        # by construction; a profile no time scaling can repair is a bug, not bad input
        bad = [r for r in report.results if not np.isfinite(r.ratio)]
        where = (f"{bad[0].constraint} at s = {bad[0].s:.6g} mm, block {bad[0].block}"
                 if bad else "unknown constraint")
        raise InternalError(f"the oracle's grid profile breaks {where} by an infinite "
                            f"ratio; no time scaling repairs it")
    if lam > 1.0:
        prof = scale_time(prof, lam)
    return prof, lam, report
