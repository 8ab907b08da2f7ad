"""Lower bound of the frequency rule over the whole path: a shortest path over humps.

:mod:`optimal.freq.lower` bounds each rest-to-rest piece on its own and knows nothing of
the corners inside it; the ``acc`` bound knows the corners but lets the speed dip at each
of them as fast as the acceleration allows. Where corners are closer than a speed change
lasting ``1/f`` can follow (short zig-zags, small arcs), the true motion cannot dip at every
corner: it holds a speed below the lowest corner cap of a whole stretch. This module
bounds that: a dynamic programme over where the motion turns from falling to rising.

Proof
=====
Notation: ``g`` the shortest phase the checker accepts, ``(1/f)/(1 + RATIO_TOL)``;
``eta = FREQ_ACCEL_TOL_REL``; ``abar`` a bound on ``|s''|`` of every motion of the ``acc``
problem (half the largest slope bound ``M_k`` of ``b = v^2`` of its relaxation,
:mod:`optimal.bounds`); ``T_up`` a verified upper bound of the minimum time. A motion
slower than ``T_up`` is not the minimum, so only motions with ``T <= T_up`` need the bound.

1. *Speed envelope.* The ``acc`` relaxation on a grid gives node bounds ``b_hat`` (its
   greatest element), interval bounds ``Bbar_k`` and slopes ``M_k`` valid for every motion
   of the ``acc`` problem, hence for every motion of ``acc+freq``:
   ``v(s)^2 <= phi(s) = min(Bbar_k, b_hat_k + M_k (s - s_k), b_hat_{k+1} + M_k (s_{k+1} - s))``
   on interval ``k``. On each *cell* (a piece of an interval, :func:`speed_envelope`)
   ``e_hi = sqrt(max phi)`` bounds ``v`` at every point of the cell and
   ``e_lo = sqrt(min phi)`` at *some* point of it (``phi`` is concave, so its least value is
   at an end of the cell).
2. *Phase speed.* Let ``w(t) = v(0) + int_0^t s'' 1[in a phase] dt``: the speed with only
   the phases' accelerations. Outside phases ``|s''| <= eta abar``, so
   ``|v - w| <= delta = eta abar T_up``. ``w`` changes only inside phases, so it is
   piecewise monotone and each of its maximal monotone *stretches* contains at least one
   whole phase (a stretch ends only where a phase of the other sign begins; the motion
   starts and ends at rest), which lasts at least its effective duration ``>= g_P``.
   Every bound below is on ``w``; ``v <= w + delta`` and ``w <= v + delta <= e + delta`` turn
   them into bounds on ``v`` with the cell speeds raised by ``2 delta``
   (``hi = e_hi + 2 delta``, ``lo = e_lo + 2 delta``).
3. *One stretch.* A rising stretch from a valley ``a`` (in cell ``i``) to a peak ``p`` (in
   cell ``c``) has ``w(s) <= w(s') <= e(s') + delta`` for every ``s' in [s, p]``; with
   step 1, in each cell ``k`` strictly between ``i`` and ``c``:
   ``v <= ub_k = min(hi_k, lo_{k+1}, ..., lo_{c-1}, hi_c)``. Its time is at least:

   * ``R = sum_k ds_k / ub_k`` over those cells;
   * ``g`` (it holds a whole phase; ``g`` the smallest over the cells ``i..c``);
   * ``LT``, from lost time: each phase ``P`` of the stretch loses
     ``int_P (V - v) dt >= dv_P g / 2`` against the stretch's largest speed ``V``
     (integration by parts, :mod:`reference.core.phases`), the phases carry the whole
     change of ``w``, at least ``V - u`` with ``u = hi_i`` (step 2), and ``V - v >= 0``
     elsewhere. The distance ``d >= sum_k ds_k`` is ``V D - int (V - v) dt``, so
     ``D >= (d + (V - u) g / 2) / V``; minimised over ``V <= hi_c``:
     ``LT = min(d / u, (d - u g / 2) / hi_c + g / 2)``.

   Falling stretches alike, mirrored.
4. *The programme.* Any motion is a chain of stretches, valley (rest at the start) to
   peak to valley (rest at the end), and its time is the sum of their times. A cell that
   holds a turn is left out of both stretches' sums (the turn can be anywhere in it). A
   long stretch may also be cut at cell starts (*cuts*): the pieces' ``R`` add to at most
   the stretch's ``R`` (each piece's minima run over fewer cells, so they are larger), and
   the pieces carry no ``g`` or ``LT`` term. The shortest path over the states "valley /
   peak / rising cut / falling cut in cell ``k``" with these edge costs is therefore at
   most the time of every motion with ``T <= T_up``, as long as every motion is one of
   its paths. A path may leave out edges for strength and still have that: edges reach
   ``K`` cells, enough for ``2 HUMP_CHAIN_PERIODS + 2`` periods at the speeds ``hi``
   from every start, and a piece ending in a cut must hold ``HUMP_CHAIN_PERIODS`` periods
   of ``R`` (``R >= sum ds / hi``), so every stretch longer than ``K`` cells splits into
   such pieces and a last one within reach. Without that floor on the pieces, a chain of
   cuts could follow every dip of the envelope, as no hump could.

What it does not know: the acceleration inside a stretch beyond the envelope (``acc``
has it, so the oracle keeps the larger of the two bounds), and the time in the cells left
out, which :data:`HUMP_CELL_TIME_REL` keeps to a few per cent of a period per turn.

Units: mm, s, mm/s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from reference.core.geometry import Path
from reference.core.limits import AxisArrays
from reference.core.phases import FREQ_ACCEL_TOL_REL
from reference.core.tolerances import RATIO_TOL

from ..bounds import speed_envelope_bounds
from ..grid import Grid
from .lower import segment_periods

__all__ = ["HUMP_CELL_TIME_REL", "HUMP_MAX_CELLS", "HUMP_CHAIN_PERIODS", "Envelope",
           "hump_lower_bound", "humps_bound", "speed_envelope"]

#: Cells are cut so that each takes at most this fraction of its period at the fastest
#: speed the envelope allows in it. Each turn leaves out its cell's time (step 4 of the
#: module docstring); a hump lasts at least two periods, so this keeps that loss near
#: 3 % of a hump's shortest time on uniform paths, while the programme's work grows as
#: the cells' count times the window's.
HUMP_CELL_TIME_REL = 0.02

#: Ceiling on the number of cells (work and memory of the programme: about
#: ``cells x window`` float64 operations). Above it the cells get longer, which only
#: weakens the bound.
HUMP_MAX_CELLS = 20_000

#: A stretch may be cut into pieces of at least this many periods (step 4). A cut forgets
#: that the speed before it stays below the speeds after it, so a chain of pieces could
#: dip where a motion would need a whole hump; this many periods between such dips keeps
#: that slack small against the two periods a hump costs, while edges need only reach
#: ``2 x HUMP_CHAIN_PERIODS + 2`` periods (the work grows with the reach).
HUMP_CHAIN_PERIODS = 8.0


@dataclass(frozen=True, slots=True)
class Envelope:
    """Speed bounds per cell for :func:`hump_lower_bound`.

    Attributes
    ----------
    s : numpy.ndarray, shape (N + 1,)
        Cell ends, mm.
    hi : numpy.ndarray, shape (N,)
        Upper bound of the speed everywhere in the cell, mm/s.
    lo : numpy.ndarray, shape (N,)
        Upper bound of the speed at some point of the cell, mm/s (``<= hi``).
    period : numpy.ndarray, shape (N,)
        Shortest phase a motion may have in the cell, s.
    accel : float
        Bound on ``|s''|`` of every motion (``abar`` of step 2), mm/s^2.
    """

    s: np.ndarray
    hi: np.ndarray
    lo: np.ndarray
    period: np.ndarray
    accel: float


def _tent(x: np.ndarray, s0, s1, b0, b1, B, M) -> np.ndarray:
    """``phi`` of the module docstring at ``x`` inside the interval ``[s0, s1]``."""
    with np.errstate(invalid="ignore"):
        t = np.minimum(b0 + M * (x - s0), b1 + M * (s1 - x))
    t = np.where(np.isfinite(M), t, np.inf)
    # the node bounds hold at the nodes themselves whatever the slope
    t = np.where(x <= s0, np.minimum(t, b0), t)
    t = np.where(x >= s1, np.minimum(t, b1), t)
    return np.minimum(t, B)


def speed_envelope(path: Path, lim: AxisArrays, grid: Grid, *,
                   cell_time_rel: float = HUMP_CELL_TIME_REL,
                   max_cells: int = HUMP_MAX_CELLS) -> Envelope:
    """Cells and their speed bounds from the ``acc`` relaxation on ``grid``.

    Parameters
    ----------
    path : Path
        Restricted to its moving axes, at least one segment.
    lim : AxisArrays
        Limits of ``path.axes``.
    grid : Grid
        Nodes (the ``acc`` oracle's final grid is a good one: refined where the speed
        bounds change).
    cell_time_rel : float
        Largest cell time at the envelope's speed, as a fraction of the cell's period.
    max_cells : int
        Ceiling on the number of cells.

    Returns
    -------
    Envelope
    """
    b_hat, B, M = speed_envelope_bounds(path, lim, grid)
    b_hat = np.maximum(b_hat, 0.0)
    s = grid.s
    D = np.diff(s)
    b0, b1 = b_hat[:-1], b_hat[1:]
    good = np.isfinite(M) & (M > 0)
    Mg = np.where(good, M, np.inf)
    # the tent's top inside each interval
    with np.errstate(invalid="ignore", divide="ignore"):
        top = np.where(good, np.clip((b1 - b0 + Mg * D) / (2 * np.where(good, Mg, 1.0)),
                                     0.0, D), 0.0)
    peak = np.minimum(_tent(s[:-1] + top, s[:-1], s[1:], b0, b1, B, Mg),
                      np.where(good, np.inf, B))
    peak = np.maximum(peak, np.minimum(np.maximum(b0, b1), B))
    per = segment_periods(path, lim)[grid.segment] / (1.0 + RATIO_TOL)
    fast = D / np.sqrt(np.where(peak > 0, peak, np.inf))
    with np.errstate(divide="ignore", invalid="ignore"):
        want = np.where(per > 0, fast / (cell_time_rel * per), 1.0)
    want = np.where(np.isfinite(want), want, 1.0)
    pieces = np.clip(np.ceil(want), 1, None)
    total = float(pieces.sum())
    if total > max_cells:
        # longer cells only weaken the bound; spread what the ceiling allows
        pieces = np.clip(np.floor(pieces * (max_cells - D.size) / total), 0, None) + 1
    pieces = pieces.astype(np.int64)
    k = np.repeat(np.arange(D.size), pieces)
    first = np.concatenate(([0], np.cumsum(pieces)[:-1]))
    j = np.arange(k.size) - first[k]
    x0 = s[k] + D[k] * (j / pieces[k])
    x1 = np.where(j + 1 == pieces[k], s[k + 1], s[k] + D[k] * ((j + 1) / pieces[k]))
    args = (s[k], s[k + 1], b0[k], b1[k], B[k], Mg[k])
    f0 = _tent(x0, *args)
    f1 = _tent(x1, *args)
    apex = np.clip(s[k] + top[k], x0, x1)
    hi = np.maximum(np.maximum(f0, f1), np.minimum(_tent(apex, *args),
                                                   np.where(good[k], np.inf, B[k])))
    hi = np.where(good[k], hi, np.maximum(np.maximum(f0, f1), B[k]))
    lo = np.minimum(f0, f1)
    cells = np.concatenate((x0, [s[-1]]))
    # the checker's slack on every speed limit
    scale = 1.0 + RATIO_TOL
    a_bar = 0.5 * float(np.max(M[np.isfinite(M)], initial=0.0)) * scale
    if not np.all(np.isfinite(M)):
        a_bar = math.inf
    return Envelope(s=cells, hi=np.sqrt(np.maximum(hi, 0.0)) * scale,
                    lo=np.sqrt(np.maximum(lo, 0.0)) * scale, period=per[k], accel=a_bar)


def hump_lower_bound(env: Envelope, drift: float = 0.0,
                     chain: float = HUMP_CHAIN_PERIODS) -> float:
    """The shortest path of step 4 of the module docstring, s.

    Parameters
    ----------
    env : Envelope
        Cells and speed bounds.
    drift : float
        ``delta`` of step 2, mm/s (``>= 0``).
    chain : float
        A stretch may be cut once its piece holds this many periods (step 4).

    Returns
    -------
    float
        Lower bound on the motion time over the cells, holds excluded, s.
    """
    ds = np.diff(env.s)
    N = ds.size
    if N < 3:
        return 0.0
    hi = env.hi + 2.0 * drift
    lo = np.minimum(env.lo, env.hi) + 2.0 * drift
    g = env.period
    with np.errstate(divide="ignore"):
        fast = ds / hi
    # reach of the edges: from every start, 2 chain + 2 of the largest period at speed hi
    cum = np.concatenate(([0.0], np.cumsum(fast)))
    need = (2.0 * chain + 2.0) * float(np.max(g))
    reach = np.searchsorted(cum, cum[:-1] + need, side="left")
    K = int(min(N - 1, max(2, int(np.max(reach - np.arange(N))) + 2)))
    inf = math.inf
    V = np.full(N, inf)    # valley in cell k
    P = np.full(N, inf)    # peak in cell k
    U = np.full(N, inf)    # rising stretch cut in cell k
    Dn = np.full(N, inf)   # falling stretch cut in cell k
    V[0] = 0.0
    for c in range(N):
        if c > 0:
            # rises ending in cell c, pulled from valleys and cuts in cells i = c-1 .. c-K;
            # a valley's cell is left out, a cut (at its cell's start) leaves nothing out
            lo_i = max(0, c - K)
            kk = np.arange(c - 1, lo_i - 1, -1)      # cells c-1 .. lo_i, nearest first
            suf = np.minimum.accumulate(np.concatenate(([hi[c]], lo[kk])))[:-1]
            Rx, dx = _sums(ds[kk], np.minimum(hi[kk], suf))
            R, d, Rc = Rx[:-1], dx[:-1], Rx[1:]      # valley i = kk: cells i+1 .. c-1
            i = kk
            gm = np.minimum(np.minimum.accumulate(g[i]), g[c])
            full = np.maximum(np.maximum(gm, R), _lost(d, hi[i], hi[c], gm))
            P[c] = min(float(np.min(V[i] + full)), float(np.min(U[i] + Rc)))
            # a cut at the start of cell c: cells i+1 .. c-1 from a valley, cells
            # i .. c-1 from a cut, once they hold `chain` periods
            U[c] = min(float(np.min(np.where(R >= chain * gm, V[i] + R, inf))),
                       float(np.min(np.where(Rc >= chain * gm, U[i] + Rc, inf))))
        if c + 1 < N and (P[c] < inf or Dn[c] < inf):
            # falls starting in cell c, pushed to valleys and cuts j = c+1 .. c+K
            hi_j = min(N - 1, c + K)
            j = np.arange(c + 1, hi_j + 1)
            tail = slice(c + 1, hi_j + 1)
            if P[c] < inf:
                kk = np.arange(c + 1, hi_j)          # peak in cell c: cells c+1 .. j-1
                pre = np.minimum.accumulate(np.concatenate(([hi[c]], lo[kk])))[:-1]
                F, d = _sums(ds[kk], np.minimum(hi[kk], pre))
                gm = np.minimum(np.minimum.accumulate(g[j]), g[c])
                full = np.maximum(np.maximum(gm, F), _lost(d, hi[j], hi[c], gm))
                V[tail] = np.minimum(V[tail], P[c] + full)
                # a cut at the start of cell j: cells c+1 .. j-1
                Dn[tail] = np.minimum(Dn[tail], np.where(F >= chain * gm, P[c] + F, inf))
            if Dn[c] < inf:
                kk = np.arange(c, hi_j)              # cut at cell c's start: c .. j-1
                pre = np.minimum.accumulate(np.concatenate(([hi[c]], lo[kk])))[:-1]
                F, _ = _sums(ds[kk], np.minimum(hi[kk], pre))
                F = F[1:]
                gm = np.minimum(np.minimum.accumulate(g[j]), g[c])
                V[tail] = np.minimum(V[tail], Dn[c] + F)
                Dn[tail] = np.minimum(Dn[tail], np.where(F >= chain * gm, Dn[c] + F, inf))
    return float(V[N - 1])


def _sums(ds: np.ndarray, ub: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Running time ``sum ds / ub`` and distance over the cells between, shape (m + 1,):
    entry ``t`` for the stretch whose far end is ``t`` cells away."""
    with np.errstate(divide="ignore"):
        R = np.concatenate(([0.0], np.cumsum(ds / ub)))
    return R, np.concatenate(([0.0], np.cumsum(ds)))


def _lost(d: np.ndarray, u: np.ndarray, w: float, g: np.ndarray) -> np.ndarray:
    """``LT`` of step 3: ``min(d / u, (d - u g / 2) / w + g / 2)``, s (0 where undefined)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        lt = np.minimum(d / u, (d - u * g / 2.0) / w + g / 2.0)
    return np.where(np.isfinite(lt) & (lt > 0), lt, 0.0)


def humps_bound(path: Path, lim: AxisArrays, grid: Grid, t_upper: float) -> float:
    """Lower bound on the motion time under ``acc+freq`` (holds excluded), s.

    Parameters
    ----------
    path : Path
        Restricted to its moving axes.
    lim : AxisArrays
        Limits of ``path.axes``.
    grid : Grid
        Nodes of the ``acc`` relaxation.
    t_upper : float
        A verified upper bound of the minimum motion time (holds excluded), s.

    Returns
    -------
    float
        s; 0 where the path has no segment or the rule does not apply.
    """
    if path.n_segments == 0 or not math.isfinite(t_upper):
        return 0.0
    env = speed_envelope(path, lim, grid)
    if not np.any(env.period > 0):
        return 0.0
    drift = FREQ_ACCEL_TOL_REL * env.accel * t_upper
    if not math.isfinite(drift):
        return 0.0
    return hump_lower_bound(env, drift)
