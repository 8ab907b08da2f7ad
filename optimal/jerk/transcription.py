"""The jerk-limited grid NLP, transcribed to arrays (numpy only; solved in ``backends``).

Variables on a :class:`~optimal.grid.Grid` with nodes ``s_0 < ... < s_N``: the path speed
``c_k`` and acceleration ``a_k`` at every node and the duration ``dt_k`` of every
interval; at every interior segment break a second acceleration, the value on arriving
there (the path acceleration may step at breaks, within the step rule below), so that
interval ``k`` runs from ``a_k`` to ``e_k`` (``e_k = a_{k+1}`` except at breaks). The path
jerk is constant on each interval, ``j_k = (e_k - a_k) / dt_k``,
so the motion is exactly a :class:`~reference.core.profile.Profile` (piecewise cubic
``s(t)``); the exact integration of the triple integrator over each interval gives the
two equalities

* ``c_{k+1} = c_k + (a_k + e_k) dt_k / 2``,
* ``s_{k+1} - s_k = c_k dt_k + (2 a_k + e_k) dt_k^2 / 6``.

Inequalities (formulation note 1.7, with the rulebook's kinematics,
:func:`reference.core.rules.axis_acceleration` / :func:`~reference.core.rules.axis_jerk`):

* speed caps ``c_k <= sqrt(cap_k)``: feed, axis velocity, the velocity-jump rule at
  corners and rest at stops, from :func:`optimal.problem.common_node_caps` (the grid
  problem's feasible flavour); inside an interval that starts accelerating and ends
  decelerating the speed peaks between the nodes, at most ``c_k + a_k dt_k / 2``, so
  ``c_k + a_k dt_k / 2 <= vcap_k`` (feed and axis velocity at both ends of the interval;
  implied by the node caps in every other case);
* axis acceleration ``|q'_i a + q''_i c^2| <= A_i`` at every node, with the geometry of
  both neighbouring segments at breaks;
* axis jerk ``|q'_i j_k + 3 q''_i c a + q'''_i c^3| <= J_i`` at the start of every
  interval and, on arcs, also at its end (multiplied by ``dt_k`` so that it stays
  smooth);
* acceleration steps at segment breaks: ``|(q'_i a + q''_i c^2)(after) -
  (q'_i e + q''_i c^2)(before)| <= Jstep_i T_ipo`` with
  ``Jstep`` from :func:`reference.core.rules.step_jerk_limit` (PATH_TRANS_JERK_LIM where
  :func:`reference.core.rules.curvature_jumps` says the curvature jumps, MAX_AX_JERK
  elsewhere); at the path start and end the surroundings are at rest, so
  ``|q'_i a + q''_i c^2| <= J_i T_ipo`` there, and so at the breaks where a hold (a
  dwell, an exact-stop settle) keeps the path at rest with zero acceleration between
  the arriving and the leaving motion: a step row from each side to rest replaces the
  row across the break (without it the motion may cross such a stop with a continuous
  axis acceleration, arriving decelerating and leaving the other way, which the hold
  inserted afterwards breaks into two steps of the full acceleration).

The checker (:func:`reference.core.constraints.check_profile`) judges the same rules
inside every interval; what the nodes miss is repaired by time scaling.

Everything is made dimensionless (:func:`problem_units`), so that IPOPT sees numbers
near 1.

Units (before scaling): mm, s. Shapes: ``N`` intervals, ``n`` axes, ``R`` rows.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.core.geometry import Path
from reference.core.limits import AxisArrays
from reference.core.rules import curvature_jumps, step_jerk_limit

from ..grid import Grid
from ..problem import common_node_caps
from .lower import rest_to_rest_time


@dataclass(frozen=True, slots=True, eq=False)
class Units:
    """Scales of the dimensionless NLP.

    Attributes
    ----------
    time_s : float
        Time unit, s.
    length_mm : float
        Length unit, mm.
    """

    time_s: float
    length_mm: float

    @property
    def speed(self) -> float:
        """Speed unit, mm/s."""
        return self.length_mm / self.time_s

    @property
    def accel(self) -> float:
        """Acceleration unit, mm/s^2."""
        return self.length_mm / self.time_s ** 2

    @property
    def jerk(self) -> float:
        """Jerk unit, mm/s^3."""
        return self.length_mm / self.time_s ** 3


@dataclass(frozen=True, slots=True, eq=False)
class Rows:
    """Rows ``lo <= p c_node^2 + q a_node + r (...) <= hi`` of one kind, flattened.

    Attributes
    ----------
    node : numpy.ndarray of int, shape (R,)
        Node whose ``c`` and ``a`` the row uses (the interval's start or end node for
        jerk rows).
    interval : numpy.ndarray of int, shape (R,)
        Interval of the row (jerk rows; -1 otherwise).
    dq, ddq, dddq : numpy.ndarray, shape (R,)
        Scaled ``q'``, ``q''``, ``q'''`` of the row's axis at the row's place (for step
        rows: their jumps across the break).
    limit : numpy.ndarray, shape (R,)
        Scaled limit (``A_i``, ``J_i`` or ``Jstep_i T_ipo``).
    axis : numpy.ndarray of int, shape (R,)
        Axis index.
    """

    node: np.ndarray
    interval: np.ndarray
    dq: np.ndarray
    ddq: np.ndarray
    dddq: np.ndarray
    limit: np.ndarray
    axis: np.ndarray

    @property
    def n(self) -> int:
        """Number of rows."""
        return int(self.node.size)


@dataclass(frozen=True, slots=True, eq=False)
class StepRows:
    """Rows ``|(dq_out a_out + ddq_out c^2) - (dq_in a_in + ddq_in c^2)| <= limit``.

    Attributes
    ----------
    node : numpy.ndarray of int, shape (R,)
        Node (for ``c``).
    ia_in, ia_out : numpy.ndarray of int, shape (R,)
        Index of ``a_in`` / ``a_out`` in the acceleration vector ``[a, extra]``
        (-1: the surroundings of the path, at rest).
    dq_in, ddq_in, dq_out, ddq_out : numpy.ndarray, shape (R,)
        Scaled geometry on both sides (0 outside the path).
    limit : numpy.ndarray, shape (R,)
        Scaled ``Jstep_i T_ipo``.
    axis : numpy.ndarray of int, shape (R,)
    """

    node: np.ndarray
    ia_in: np.ndarray
    ia_out: np.ndarray
    dq_in: np.ndarray
    ddq_in: np.ndarray
    dq_out: np.ndarray
    ddq_out: np.ndarray
    limit: np.ndarray
    axis: np.ndarray

    @property
    def n(self) -> int:
        """Number of rows."""
        return int(self.node.size)


@dataclass(frozen=True, slots=True, eq=False)
class PhaseRows:
    """Runs of intervals that are to be phases of the frequency rule with at least a
    given effective duration (:mod:`reference.core.phases`).

    Run ``p`` covers intervals ``first[p] .. stop[p] - 1``, its path acceleration of
    sign ``sign[p]`` there (the caller bounds it so through ``a_lo``, ``a_hi``). With
    ``dv = v_1 - v_0`` its change, ``T`` its duration and ``ds`` its length, the rows are
    ``sign (T v_1 - ds - g dv / 2) >= 0`` and ``sign (ds - T v_0 - g dv / 2) >= 0``: by
    parts ``int (t - t_0) s'' dt = T v_1 - ds`` and ``int (t_1 - t) s'' dt = ds - T v_0``,
    so the acceleration-weighted mean time lies at least ``g / 2`` from either end, which
    is ``D_eff >= g`` (the lost time against either end speed of
    :mod:`reference.core.phases`).

    Attributes
    ----------
    first, stop : numpy.ndarray of int, shape (P,)
        Interval ranges ``[first, stop)``.
    sign : numpy.ndarray of int, shape (P,)
        +1 for a rise, -1 for a fall.
    g : numpy.ndarray, shape (P,)
        Least effective duration (scaled time).
    """

    first: np.ndarray
    stop: np.ndarray
    sign: np.ndarray
    g: np.ndarray


@dataclass(frozen=True, slots=True, eq=False)
class JerkProblem:
    """The dimensionless grid NLP (see the module docstring).

    Attributes
    ----------
    units : Units
        Scales.
    ds : numpy.ndarray, shape (N,)
        Interval lengths (scaled).
    c_max : numpy.ndarray, shape (N + 1,)
        Speed caps (scaled), 0 at stops.
    acc, jerk : Rows
        Axis acceleration rows at nodes and axis jerk rows on intervals; their ``node``
        indexes ``c`` and, for acceleration, ``[a, extra]`` through ``acc_index``.
    acc_index : numpy.ndarray of int, shape (R_acc,)
        Index into ``[a, extra]`` of the acceleration each ``acc`` row uses.
    step : StepRows
        Acceleration-step rows at interior breaks and path ends.
    end_index : numpy.ndarray of int, shape (N,)
        Index into ``[a, extra]`` of each interval's end acceleration ``e_k``.
    n_extra : int
        Number of extra accelerations (one per interior break node).
    grid : Grid
        The grid (mm).
    v_interval : numpy.ndarray, shape (N,)
        Scaled speed cap inside each interval (feed and axis velocity; ``inf`` where
        none).
    cap_code, cap_axis : numpy.ndarray of int, shape (N + 1,)
        The constraint behind each speed cap (``optimal.problem.CAP_*``) and its axis.
    axes : tuple[str, ...]
        Axis names.
    a_lo, a_hi : numpy.ndarray, shape (N + 1 + n_extra,), optional
        Bounds on the path accelerations ``[a, extra]`` (scaled: at the nodes, on leaving
        a break node, then on arriving at each interior break node); ``None``: none.
        Only the IPOPT backend reads them (the SCP cross-check solves the problem as
        transcribed). The transcription sets none; :mod:`optimal.freq.jerk_adapted`
        sets them to lengthen phases the frequency rule finds short.
    phases : PhaseRows, optional
        Rows that make given runs of intervals phases of the frequency rule (only the
        IPOPT backend reads them; :mod:`optimal.freq.phase_nlp` sets them).
    """

    units: Units
    ds: np.ndarray
    c_max: np.ndarray
    acc: Rows
    acc_index: np.ndarray
    jerk: Rows
    step: StepRows
    end_index: np.ndarray
    n_extra: int
    grid: Grid
    v_interval: np.ndarray
    cap_code: np.ndarray
    cap_axis: np.ndarray
    axes: tuple[str, ...]
    a_lo: np.ndarray | None = None
    a_hi: np.ndarray | None = None
    phases: PhaseRows | None = None

    @property
    def n_intervals(self) -> int:
        """Number of intervals ``N``."""
        return int(self.ds.size)


def problem_units(path: Path, lim: AxisArrays) -> Units:
    """Length unit: the median segment length; time unit: a quarter of the jerk-limited
    rest-to-rest time over it (:func:`optimal.jerk.lower.rest_to_rest_time` with the
    largest axis limits). Speeds, accelerations and jerks of the motion are then near 1
    whether the velocity, the acceleration or the jerk limit shapes it (a time unit of
    ``A/J`` alone is 1e-9 s for an absurdly large jerk limit and 1000 s for a tiny one)."""
    L = float(np.median(path.length))
    feed = path.feed[np.isfinite(path.feed)]
    V = float(np.max(lim.v_max)) if feed.size == 0 else min(float(np.max(lim.v_max)),
                                                           float(np.max(feed)))
    T = rest_to_rest_time(L, V, float(np.max(lim.a_max)), float(np.max(lim.j_max)))
    return Units(time_s=T / 4.0, length_mm=L)


def _rows(node, interval, dq, ddq, dddq, limit, axis) -> Rows:
    """Rows of one kind, dropping those whose coefficients are all zero (never binding)."""
    keep = (dq != 0) | (ddq != 0) | (dddq != 0)
    return Rows(node=node[keep], interval=interval[keep], dq=dq[keep], ddq=ddq[keep],
                dddq=dddq[keep], limit=limit[keep], axis=axis[keep])


def _stack(parts: list[tuple]) -> tuple[np.ndarray, ...]:
    if not parts:
        z = np.zeros(0)
        zi = np.zeros(0, dtype=np.int64)
        return zi, zi, z, z, z, z, zi
    return tuple(np.concatenate([p[i] for p in parts]) for i in range(7))


def build_jerk_problem(path: Path, lim: AxisArrays, grid: Grid, t_ipo: float,
                       hold_breaks: np.ndarray | None = None) -> JerkProblem:
    """Transcribe the jerk-limited problem on ``grid``.

    Parameters
    ----------
    path : Path
        Path with positive feeds.
    lim : AxisArrays
        Limits in the path's axis order.
    grid : Grid
        Nodes (every segment break is a node).
    t_ipo : float
        IPO cycle, s (acceleration steps are spread over it).
    hold_breaks : numpy.ndarray of int, optional
        Path breaks (``0..m``) where a hold rests the motion
        (:attr:`reference.core.holds.Holds.break_index`; repeats allowed): the motion
        arrives there and leaves there as at the path ends.

    Returns
    -------
    JerkProblem
    """
    units = problem_units(path, lim)
    L, Au, Ju = units.length_mm, units.accel, units.jerk
    N = grid.n_intervals
    seg = grid.segment
    _, dq0, ddq0, dddq0 = path.evaluate(grid.s[:-1], segment=seg)
    _, dq1, ddq1, dddq1 = path.evaluate(grid.s[1:], segment=seg)
    caps = common_node_caps(path, lim, grid, dq0, dq1, permissive=False)
    c_max = np.sqrt(caps.cap) / units.speed
    with np.errstate(divide="ignore"):
        v_ax = np.minimum(np.min(lim.v_max / np.abs(dq0), axis=1),
                          np.min(lim.v_max / np.abs(dq1), axis=1))
    v_interval = np.minimum(path.feed[seg], v_ax) / units.speed
    n = len(path.axes)
    k_all = np.arange(N)
    a_lim = lim.a_max / Au
    j_lim = lim.j_max / Ju
    # interior break nodes get a second acceleration (the value on arriving there)
    m = path.n_segments
    inner = grid.break_node[1:m]
    n_extra = int(inner.size)
    end_index = k_all + 1
    end_index[inner - 1] = N + 1 + np.arange(n_extra)
    # acceleration rows: every interval's start node; its end node where the segment
    # ends (the next interval's start has the other segment's geometry there); the
    # ``interval`` field carries the index of the acceleration used, [a, extra]
    seg_end = np.ones(N, bool)
    seg_end[:-1] = seg[1:] != seg[:-1]
    acc_parts, jerk_parts = [], []
    arc = path.radius[seg] > 0
    # on lines the rows of all axes are one row, scaled (q' constant, no curvature):
    # keep the tightest axis only (smallest limit / |q'_i|)
    with np.errstate(divide="ignore"):
        inv = np.where(dq0 != 0, 1.0 / np.where(dq0 != 0, np.abs(dq0), 1.0), np.inf)
    tight_a = np.argmin(lim.a_max[None, :] * inv, axis=1)
    tight_j = np.argmin(lim.j_max[None, :] * inv, axis=1)
    for i in range(n):
        use_a = arc | (tight_a == i)
        use_j = arc | (tight_j == i)
        for nodes, ia, dq, ddq, sel in ((k_all, k_all, dq0, ddq0, use_a),
                                        (k_all + 1, end_index, dq1, ddq1, seg_end & use_a)):
            cnt = int(sel.sum())
            acc_parts.append((nodes[sel], ia[sel], dq[sel, i], ddq[sel, i] * L,
                              np.zeros(cnt), np.full(cnt, a_lim[i]), np.full(cnt, i)))
        for nodes, dq, ddq, dddq, sel in ((k_all, dq0, ddq0, dddq0, use_j),
                                          (k_all + 1, dq1, ddq1, dddq1, arc)):
            cnt = int(sel.sum())
            jerk_parts.append((nodes[sel], k_all[sel], dq[sel, i], ddq[sel, i] * L,
                               dddq[sel, i] * L * L, np.full(cnt, j_lim[i]),
                               np.full(cnt, i)))
    acc = _rows(*_stack(acc_parts))
    jerk = _rows(*_stack(jerk_parts))
    step = _step_rows(path, lim, grid, t_ipo, units, dq0, ddq0, dq1, ddq1, end_index,
                      hold_breaks)
    return JerkProblem(units=units, ds=np.diff(grid.s) / L, c_max=c_max, acc=acc,
                       acc_index=acc.interval, jerk=jerk, step=step,
                       end_index=end_index, n_extra=n_extra, grid=grid,
                       v_interval=v_interval,
                       cap_code=caps.code, cap_axis=caps.axis, axes=path.axes)


def _step_rows(path, lim, grid, t_ipo, units, dq0, ddq0, dq1, ddq1,
               end_index, hold_breaks=None) -> StepRows:
    """Acceleration-step rows at interior breaks, at the path ends and at holds."""
    L, Au = units.length_mm, units.accel
    n = len(path.axes)
    N = grid.n_intervals
    m = path.n_segments
    z = np.zeros(n)
    jl = lim.j_max * t_ipo / Au
    parts = []         # node, ia_in, ia_out, dq_in, ddq_in, dq_out, ddq_out, limit, axis
    if m >= 2:
        held = np.zeros(m + 1, bool)
        if hold_breaks is not None and len(hold_breaks):
            held[np.asarray(hold_breaks, dtype=np.int64)] = True
        held = held[1:m]                           # interior breaks with a hold
        bn = grid.break_node[1:m]                  # nodes of the interior breaks
        t_in, t_out = dq1[bn - 1], dq0[bn]
        k_in, k_out = ddq1[bn - 1], ddq0[bn]
        jstep = step_jerk_limit(curvature_jumps(k_in, k_out), lim.j_max, lim.path_trans_jerk)
        go, hb = ~held, bn[held]
        zh = np.zeros(hb.size)
        for i in range(n):
            parts.append((bn[go], end_index[bn[go] - 1], bn[go], t_in[go, i],
                          k_in[go, i] * L, t_out[go, i], k_out[go, i] * L,
                          jstep[go, i] * t_ipo / Au, np.full(int(go.sum()), i)))
            # a hold between: each side meets rest (the hold's zero acceleration)
            parts.append((hb, end_index[hb - 1], np.full(hb.size, -1), t_in[held, i],
                          k_in[held, i] * L, zh, zh, np.full(hb.size, jl[i]),
                          np.full(hb.size, i)))
            parts.append((hb, np.full(hb.size, -1), hb, zh, zh, t_out[held, i],
                          k_out[held, i] * L, np.full(hb.size, jl[i]),
                          np.full(hb.size, i)))
    # path ends: the surroundings rest with zero acceleration
    ax = np.arange(n)
    parts.append((np.zeros(n, np.int64), np.full(n, -1), np.zeros(n, np.int64), z, z,
                  dq0[0], ddq0[0] * L, jl, ax))
    parts.append((np.full(n, N), np.full(n, end_index[-1]), np.full(n, -1), dq1[-1],
                  ddq1[-1] * L, z, z, jl, ax))
    cols = [np.concatenate([p[c] for p in parts]) for c in range(9)]
    # rows with identical geometry on both sides still bound the path-acceleration step
    keep = (cols[3] != 0) | (cols[4] != 0) | (cols[5] != 0) | (cols[6] != 0)
    cols = [c[keep] for c in cols]
    return StepRows(node=cols[0].astype(np.int64), ia_in=cols[1].astype(np.int64),
                    ia_out=cols[2].astype(np.int64), dq_in=cols[3], ddq_in=cols[4],
                    dq_out=cols[5], ddq_out=cols[6], limit=cols[7],
                    axis=cols[8].astype(np.int64))
