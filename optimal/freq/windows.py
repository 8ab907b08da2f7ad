"""Rows of the frequency rule for the jerk relaxation: the time on a segment and its two
neighbours (bound set ``jerk+freq``).

The jerk oracle's relaxation (:mod:`optimal.jerk.relaxation`) knows nothing of the rule,
and :mod:`optimal.freq.humps` knows nothing of the jerk: on a slow segment between two low
corner caps (examples/demo.mpf's plunge at F1200 between a reversal and a 90 degree
corner) the rule makes the rise and the fall last ``1/f`` each, where the jerk lets them
last a third of that, and neither bound sees it. A row per such segment ``k`` bounds the
time on segments ``k - 1, k, k + 1`` from below, for every motion the checker accepts
under ``jerk+freq`` that is no slower than ``T_up``; the relaxation with these rows is then
a lower bound of the minimum under ``jerk+freq`` (``min(bound, T_up)``, as in
:mod:`optimal.freq.humps`).

Proof
=====
Notation (:mod:`optimal.freq.lower`): ``g_k = (1/f_k) / (1 + RATIO_TOL)``, ``f_k`` the
smallest LOOKAH_FREQUENCY of the axes moving on segment ``k``; every phase that overlaps
the segment moves those axes, so it lasts an effective duration of at least ``g_k``;
``eta = FREQ_ACCEL_TOL_REL``; ``abar`` bounds ``|s''|``
(:func:`~optimal.freq.lower.path_accel_bound`) and ``dr = eta abar T_up`` what the
accelerations outside phases change the speed by. ``u_j`` bounds the speed at break ``j``
(``sqrt(b)`` of the ``acc`` relaxation's node bound, :func:`optimal.jerk.lower.speed_bounds`,
with the checker's tolerances) and ``Vc_k`` the speed on segment ``k``
(:func:`~optimal.freq.lower.segment_speed_caps` and the relaxation's segment bound).

1. *One segment.* Let ``[t_a, t_b]`` be the time on segment ``k`` (length ``L``), ``V``
   the largest speed in it, at ``t*``, and ``u0 = u_k``, ``u1 = u_{k+1}``. Then
   ``T_k = (L + int (V - v) dt) / V``. If ``V <= max(u0, u1)``, ``T_k >= L / V``. Else
   ``t*`` lies strictly inside and the speed rises by ``V - v(t_a) >= V - u0`` before it;
   the rise phases in ``[t_a, t*]`` carry at least ``V - u0 - dr`` of it. A rise phase
   ``P`` inside loses ``int_P (V - v) >= int_P (v(p_1) - v) = dv_P (t_c - p_0) >=
   dv_P g_k / 2`` (integration by parts). One phase ``Q`` may have started before
   ``t_a``, ``c0`` earlier: inside it still loses ``dv_Q g_k / 2 - c0 V`` (what it lost
   before ``t_a`` is at most ``c0 v(q_1)``). With the fall alike (``u1``, ``c1``: a fall
   phase that ends after ``t_b``), ``T_k >= F(V) = (L + X0 + X1) / V`` with
   ``Xi = max(0, (V - ui - dr) g_k / 2 - ci V)``. Where ``L > (u0 + u1 + 2 dr) g_k / 2``
   every piece of ``F`` falls with ``V``, so
   ``T_k >= G(c0, c1) = min(L / max(u0, u1), F(Vc_k))``.
2. *The neighbours.* The ``c0`` before ``t_a`` belong to a rise ending at ``v(t_a)``: the
   motion creeps there at most at ``u0``. If the creep stays on segment ``k - 1`` (length
   ``L'``), that segment takes ``c0`` plus the time on its first ``L' - delta`` with
   ``delta <= u0 c0``, entered as the segment is and left at most at ``u0`` with
   ``|s''| <= eta abar + eps`` (the phase starts there; ``eps`` the segment's budget of
   acceleration steps): at least its jerk bound ``E(L' - delta)``
   (:func:`optimal.jerk.lower.peak_times` with those ends and a fixed ``t_cap``, which
   is nondecreasing in the length). The neighbour's own fall to the valley before the
   creep also lies on that part if the neighbour peaks there (above ``W'``, its larger
   corner bound plus ``dr``; a fall phase does not start before the peak): it loses
   ``(V' - u0 - dr) g' / 2`` at the neighbour's top speed ``V'``, so the part takes at
   least ``min(F'(W'), F'(Vc'))``, ``F'(V) = (L' - delta + X'(V)) / V``, monotone on
   each piece; without a peak at least ``(L' - delta) / W'``; the larger of this and
   ``E`` counts. If the creep covers the whole segment it takes at
   least ``L' / u0``. Mirrored after ``t_b``. At the path ends and at holds (zero
   acceleration for the hold's duration) no phase runs through: ``c = 0``.
3. *The row.* ``T_{k-1} + T_k + T_{k+1} >= min over c0, c1 >= 0`` of
   ``P0(c0) + G(c0, c1) + P1(c1)``. ``G`` is ``L / Vc + X0(c0) / Vc + X1(c1) / Vc`` or a
   constant, so the minimum splits into one over ``c0`` and one over ``c1``; each runs
   over cells ``[c_a, c_b]`` (:data:`WINDOW_LINEAR_CELLS` up to where ``X`` is zero, then
   cells growing by :data:`WINDOW_CELL_GROWTH` up to ``L' / u0``, then the rest), on
   which ``P >= min(c_a + E(max(L' - u0 c_b, 0)), L' / u0)`` (the second only where
   ``u0 c_b >= L'``) and ``X(c) >= X(c_b)``: the smallest cell value bounds the minimum.
   A cell of width ``h`` gives away at most about ``h`` (the creep's cost and its saving
   are both about ``c``).

Only segments where ``G(0, 0)`` exceeds the relaxation's own floor of the segment by
:data:`WINDOW_MIN_GAIN_REL` get a row (elsewhere the row cannot bind).

Units: mm, s, mm/s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.core.geometry import Path
from reference.core.limits import AxisArrays
from reference.core.phases import FREQ_ACCEL_TOL_REL
from reference.core.tolerances import RATIO_TOL, VEL_TOL_MM_S

from ..bounds import lower_bound
from ..grid import grid_on
from ..jerk.lower import SegmentEnvelope, segment_envelope, speed_bounds
from ..jerk.relaxation import RunFloors, jerk_relaxation
from ..tolerances import LB_ROUNDOFF_REL
from .lower import path_accel_bound, segment_periods, segment_speed_caps

__all__ = ["WINDOW_CELL_GROWTH", "WINDOW_LINEAR_CELLS", "WINDOW_MIN_GAIN_REL", "CreepCells", "RuleEnvelope",
           "creep_cells", "own_phase", "rule_envelope", "window_lower_bound", "window_rows"]

#: Cells of the creep time ``c`` from 0 to where the phase's lost time is used up
#: (step 3): each gives away at most its width, ``g / 2`` over this (0.5 ms at 15 Hz).
WINDOW_LINEAR_CELLS = 64
#: Growth of the cells beyond that, up to the creep that covers the whole neighbour (the
#: creep costs at least its own time there, so coarse cells lose little).
WINDOW_CELL_GROWTH = 1.25
#: Cells beyond the linear ones at most (then the rest as one).
WINDOW_MAX_GROWN_CELLS = 48
#: A row only where the frequency bound of the segment exceeds its floor by this share.
WINDOW_MIN_GAIN_REL = 1e-3


@dataclass(frozen=True, slots=True, eq=False)
class RuleEnvelope:
    """What the rows of the rule know of a path (module docstring, notation).

    Attributes
    ----------
    env : optimal.jerk.lower.SegmentEnvelope
        The jerk bounds' inputs per segment (step 2).
    u : numpy.ndarray, shape (m + 1,)
        Bound on the speed at each break, mm/s.
    vc : numpy.ndarray, shape (m,)
        Bound on the speed on each segment, mm/s.
    g : numpy.ndarray, shape (m,)
        ``g_k``: the shortest duration the checker accepts of a phase that moves the axes
        of segment ``k``, s (0 where no axis moving on it has a frequency).
    a_bar : float
        Bound on ``|s''|``, mm/s^2.
    dr : float
        What the accelerations outside phases change the speed by at most, mm/s.
    cut : numpy.ndarray of bool, shape (m + 1,)
        Breaks no phase runs through: the path ends and the holds.
    length : numpy.ndarray, shape (m,)
        Segment lengths, mm.
    moving : numpy.ndarray of bool, shape (m,)
        The segments on which an axis moves.
    """

    env: SegmentEnvelope
    u: np.ndarray
    vc: np.ndarray
    g: np.ndarray
    a_bar: float
    dr: float
    cut: np.ndarray
    length: np.ndarray
    moving: np.ndarray


def rule_envelope(path: Path, lim: AxisArrays, t_ipo: float, acc_grid_s: np.ndarray,
                  t_upper: float, hold_breaks: np.ndarray | None = None) -> RuleEnvelope:
    """The bounds of the module docstring's notation, for the motions no slower than
    ``t_upper`` (s); arguments as :func:`window_rows`."""
    m = path.n_segments
    _, b_break, b_seg = speed_bounds(path, lim, t_ipo, acc_grid_s)
    env = segment_envelope(path, lim, t_ipo, b_break, b_seg)
    slack = 1.0 + RATIO_TOL
    u = np.sqrt(np.maximum(b_break, 0.0)) * slack + VEL_TOL_MM_S
    vc = np.minimum(segment_speed_caps(path, lim),
                    np.sqrt(np.maximum(b_seg, 0.0)) * slack + VEL_TOL_MM_S)
    g = segment_periods(path, lim) / slack
    a_bar = path_accel_bound(path, lim)
    cut = np.zeros(m + 1, bool)
    cut[[0, m]] = True
    if hold_breaks is not None and np.size(hold_breaks):
        cut[np.asarray(hold_breaks, dtype=np.int64)] = True
    moving = np.zeros(m, bool)
    moving[env.used] = True
    return RuleEnvelope(env, u, vc, g, a_bar, FREQ_ACCEL_TOL_REL * a_bar * t_upper, cut,
                        path.length, moving)


def window_rows(path: Path, lim: AxisArrays, t_ipo: float, acc_grid_s: np.ndarray,
                floors: np.ndarray, t_upper: float,
                hold_breaks: np.ndarray | None = None,
                rule: RuleEnvelope | None = None) -> RunFloors:
    """The rows of the module docstring.

    Parameters
    ----------
    path : Path
        Restricted to its moving axes.
    lim : AxisArrays
        Limits of ``path.axes``.
    t_ipo : float
        IPO cycle, s.
    acc_grid_s : numpy.ndarray, shape (N + 1,)
        Nodes of an ``acc`` relaxation grid (every break a node), mm.
    floors : numpy.ndarray, shape (m,)
        The relaxation's own floor per segment, s (rows only where they can bind).
    t_upper : float
        The rows hold for every motion no slower than this, s (holds excluded).
    hold_breaks : numpy.ndarray of int, optional
        Breaks where a hold rests the motion.
    rule : RuleEnvelope, optional
        :func:`rule_envelope` of the same arguments, where the caller has it (else made
        here).

    Returns
    -------
    RunFloors
        Runs ``k - 1 .. k + 1`` (clipped where a side has no neighbour) and their bounds.
    """
    m = path.n_segments
    none = RunFloors(np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0))
    if m == 0 or not np.isfinite(t_upper):
        return none
    if rule is None:
        rule = rule_envelope(path, lim, t_ipo, acc_grid_s, t_upper, hold_breaks)
    env, u, vc, g, dr = rule.env, rule.u, rule.vc, rule.g, rule.dr
    L = path.length
    u0, u1 = u[:-1], u[1:]
    lo_v = np.maximum(u0, u1)
    with np.errstate(divide="ignore", invalid="ignore"):
        x0 = np.maximum((vc - u0 - dr) * g / 2.0, 0.0)
        x1 = np.maximum((vc - u1 - dr) * g / 2.0, 0.0)
        g00 = np.minimum(L / lo_v, (L + x0 + x1) / vc)
    ok = (np.isfinite(g) & (g > 0) & np.isfinite(vc) & (vc > lo_v)
          & (L > (u0 + u1 + 2.0 * dr) * g / 2.0)
          & (g00 * (1.0 - LB_ROUNDOFF_REL) > floors * (1.0 + WINDOW_MIN_GAIN_REL)))
    sel = np.flatnonzero(ok)
    if sel.size == 0:
        return none
    cut = rule.cut
    # the creep before segment k (on k - 1, at most u_k) and after it (on k + 1, at most
    # u_{k+1}): the smallest of P + X / Vc over the cells, per side
    before, after = ~cut[sel], ~cut[sel + 1]
    side0 = _side(rule, sel - 1, sel, x0[sel], vc[sel], leaving=True, present=before)
    side1 = _side(rule, sel + 1, sel + 1, x1[sel], vc[sel], leaving=False, present=after)
    with np.errstate(divide="ignore"):
        far = L[sel] / lo_v[sel] + side0[1] + side1[1]
    near = L[sel] / vc[sel] + side0[0] + side1[0]
    value = np.minimum(far, near) * (1.0 - LB_ROUNDOFF_REL)
    lo = np.where(before, sel - 1, sel)
    hi = np.where(after, sel + 2, sel + 1)
    return RunFloors(lo.astype(np.int64), hi.astype(np.int64), value)


def _side(rule: RuleEnvelope, nb: np.ndarray, j: np.ndarray, x: np.ndarray, vc: np.ndarray,
          leaving: bool, present: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Step 3 for one side of K segments: ``(min_c P(c) + X(c) / Vc, min_c P(c))`` per
    segment, s, shape (K,) each. ``nb`` the neighbour on that side, ``j`` the common
    break, ``x`` the lost time at ``c = 0`` (mm), ``vc`` the segments' speed bounds,
    ``leaving``: the neighbour is left at that break (the creep is at its end)."""
    with_x = np.zeros(nb.size)
    alone = np.zeros(nb.size)
    idx = np.flatnonzero(present)
    if idx.size == 0:
        return x / vc, alone                 # no neighbour: c = 0
    # X(c) = x - c Vc reaches 0 at c = x / Vc
    cells = creep_cells(rule, nb[idx], j[idx], x[idx] / vc[idx], leaving)
    X = np.maximum(x[idx, None] - cells.cb * vc[idx, None], 0.0) / vc[idx, None]
    with_x[idx] = np.minimum(np.min(cells.P + X, axis=1), cells.tail)
    alone[idx] = cells.least
    return np.where(present, with_x, x / vc), alone


@dataclass(frozen=True, slots=True, eq=False)
class CreepCells:
    """What a creep of ``c`` on a neighbour costs it (step 3), per cell of ``c``.

    Attributes
    ----------
    cb : numpy.ndarray, shape (K, n)
        Each cell's upper edge, s (the lower edges are 0 and the upper ones before).
    P : numpy.ndarray, shape (K, n)
        A bound on the neighbour's time with a creep in the cell, s.
    tail : numpy.ndarray, shape (K,)
        The same beyond the last cell, s.
    least : numpy.ndarray, shape (K,)
        The smallest of them: a bound on the neighbour's time whatever the creep, s.
    """

    cb: np.ndarray
    P: np.ndarray
    tail: np.ndarray
    least: np.ndarray


def creep_cells(rule: RuleEnvelope, k_nb: np.ndarray, j: np.ndarray, c_lin: np.ndarray,
                leaving: bool) -> CreepCells:
    """The cells of step 3 on neighbours ``k_nb`` of a creep through breaks ``j`` (shape
    (K,) each), the creep at most at ``u_j``: :data:`WINDOW_LINEAR_CELLS` up to ``c_lin``
    (s), then growing by :data:`WINDOW_CELL_GROWTH` up to the creep over the whole
    neighbour. ``leaving``: the neighbour is left at the break (the creep is at its end).
    Each cell takes the larger of the neighbour's jerk bound and step 2's bound from its
    own phase beside the creep (:func:`own_phase`) on what the creep leaves of it."""
    env, moving, a_bar = rule.env, rule.moving, rule.a_bar
    un = rule.u[j]
    Ln = rule.length[k_nb]
    c_all = Ln / un                          # the creep covers the whole neighbour
    # cell edges: linear to c_lin, growing to c_all, then the rest
    lin = np.linspace(0.0, 1.0, WINDOW_LINEAR_CELLS + 1)[None, :] * c_lin[:, None]
    start = np.maximum(c_lin, 1e-12 * np.maximum(c_all, 1.0))
    grown = start[:, None] * WINDOW_CELL_GROWTH ** np.arange(1, WINDOW_MAX_GROWN_CELLS + 1)
    grown = np.minimum(grown, c_all[:, None])
    edges = np.concatenate((lin, grown), axis=1)          # (k, n_edges), nondecreasing
    ca, cb = edges[:, :-1], edges[:, 1:]
    # the neighbour's jerk bound on what the creep leaves of it (t_cap fixed at twice
    # its whole length's bound, so that the bound grows with the length)
    rows = np.repeat(k_nb, cb.shape[1])
    L_left = np.maximum(Ln[:, None] - un[:, None] * cb, 0.0).ravel()
    eps_end = np.full(rows.size, FREQ_ACCEL_TOL_REL * a_bar + env.eps)
    u_end = np.repeat(un, cb.shape[1])
    with np.errstate(all="ignore"):     # non-moving neighbours: masked below
        t_cap = np.repeat(2.0 * env.peak_time(k_nb, Ln), cb.shape[1])
        if leaving:    # the creep is at the neighbour's end: it leaves at most at u
            E = env.peak_time(rows, L_left, vb1=u_end,
                              as1=np.maximum(env.a_in[rows + 1], eps_end), t_cap=t_cap)
        else:          # at its start: entered at most at u
            E = env.peak_time(rows, L_left, vb0=u_end,
                              as0=np.maximum(env.a_out[rows], eps_end), t_cap=t_cap)
    E = np.where((L_left > 0) & moving[rows], np.nan_to_num(E, nan=0.0, posinf=0.0), 0.0)
    E = np.maximum(E, 0.0).reshape(cb.shape)
    # the neighbour's own phase beside the creep lies on what the creep leaves of it
    W, Vc, X = (v[:, None] for v in own_phase(rule, k_nb, j))
    Lr = L_left.reshape(cb.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        F = np.minimum(Lr / W, (Lr + X) / Vc)
    E = np.maximum(E, np.where(np.isfinite(F) & moving[k_nb][:, None], F, 0.0))
    P = np.where(un[:, None] * cb >= Ln[:, None], np.minimum(ca + E, c_all[:, None]), ca + E)
    # the rest: c beyond the last edge (at least c_all, or the creep covers the neighbour)
    tail = np.minimum(edges[:, -1], c_all)
    return CreepCells(cb, P, tail, np.minimum(np.min(P, axis=1), tail))


def own_phase(rule: RuleEnvelope, nb: np.ndarray, j: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(W, Vc, X)`` (mm/s, mm/s, mm) for neighbours ``nb`` of a creep through break
    ``j`` (shape (K,) each): a neighbour that peaks (above ``W``, its larger corner
    bound plus ``dr``) falls to the creep (or rises from it) in a phase of its own, all
    on it, which loses ``X = (Vc - u_j - dr) g / 2`` at its largest speed ``Vc`` (step 1);
    one that does not peak takes ``L'' / W``."""
    w = np.maximum(rule.u[nb], rule.u[nb + 1]) + rule.dr
    x = np.maximum((rule.vc[nb] - rule.u[j] - rule.dr) * rule.g[nb] / 2.0, 0.0)
    return w, rule.vc[nb], x


def window_lower_bound(path: Path, lim: AxisArrays, t_ipo: float, grid_s: np.ndarray,
                       floors: np.ndarray, rows: RunFloors, t_upper: float,
                       hold_breaks: np.ndarray | None = None) -> float:
    """The jerk relaxation with ``rows``: a lower bound of the motion time under
    ``jerk+freq`` (holds excluded), s.

    Parameters
    ----------
    path, lim, t_ipo, floors, hold_breaks
        As :func:`window_rows`; ``floors`` are the relaxation's segment floors.
    grid_s : numpy.ndarray, shape (N + 1,)
        Nodes of the relaxation (the jerk oracle's final grid), mm.
    rows : RunFloors
        Rows that hold for every motion no slower than ``t_upper``: those of
        :func:`window_rows`, and the turn programme's bound of each rest-to-rest piece
        (:func:`optimal.freq.humps.humps_piece_bounds`).
    t_upper : float
        s, holds excluded.

    Returns
    -------
    float
        ``min(relaxation, t_upper)``, s; 0 where there is no row or the relaxation
        failed.
    """
    if rows.value.size == 0:
        return 0.0
    grid = grid_on(path, np.asarray(grid_s, dtype=np.float64))
    _, t_acc, _, b_hat = lower_bound(path, lim, grid)
    rel = jerk_relaxation(path, lim, t_ipo, grid, b_hat, t_acc, floors, hold_breaks, rows)
    return min(rel.lower_bound_s, t_upper) if rel.ok else 0.0
