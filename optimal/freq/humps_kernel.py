"""Compiled kernel of the turn programme (numba): the shortest path of
:func:`optimal.freq.humps.hump_plan`, written as the plain loops it is.

The states, edges and costs are those of steps 3 and 4 (4b to 4d) of :mod:`optimal.freq.humps`
(its module docstring has the proof); this module only runs them. Why compiled: every
cell pulls the rises that end in it from the cells within reach and pushes the falls
that start in it, a few dozen small array operations per cell in numpy, about a
millisecond per cell whatever the reach (measured: 2,133 cells of a two-line program in
2.3 s); the loops here do the same arithmetic, ``O(cells x reach x levels)`` flops and
no temporaries. Compiled once per installation (``cache=True``), like
:mod:`optimal.backends.kernel`.

Units: mm, s, mm/s. Shapes: ``N`` cells, ``NQ`` slack levels.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: State kinds (the first index of ``pred``), as in :mod:`optimal.freq.humps`.
VALLEY, PEAK, RISE_CUT, FALL_CUT = 0, 1, 2, 3


#: Most steps of the lost-time weight of one stretch (:func:`_push`): one per strict drop
#: of the shortest phase along it, so at most one per distinct LOOKAH_FREQUENCY of the
#: axes; beyond it the two lowest steps merge at the lower weight (only less lost time).
MAX_WEIGHT_STEPS = 8


@njit(cache=True, nogil=True, error_model="numpy")
def _push(W: np.ndarray, G: np.ndarray, Q: np.ndarray, n: int, w_k: float,
          g_k: float) -> int:  # pragma: no cover - compiled
    """Add a cell to the lost-time weight of a stretch (step 3 of
    :mod:`optimal.freq.humps`), returning the new number of steps.

    ``w_k`` bounds the speed in the cell (at or below every bound already in: the cells
    come in from the turn cell the stretch starts from), ``g_k`` is its shortest phase.
    The weight of a speed level ``x`` is the least ``g`` of the cells whose bound is at
    least ``x``, a step function kept from the top: step ``j`` covers the levels
    ``(W[j + 1], W[j]]`` (step 0 also those above, the last down to 0) at weight
    ``G[j]``, ``G`` falling with ``j``. ``Q[j] = (P(low_j) - G[j] low_j) / 2`` with
    ``P`` the weight's integral from 0 and ``low_j`` the step's lower end, so that
    ``P(x) / 2 = Q[j] + G[j] x / 2`` on step ``j``."""
    if n > 0 and g_k >= G[n - 1]:
        return n                          # the levels below w_k already weigh no more
    if n == MAX_WEIGHT_STEPS:
        G[n - 1] = g_k                    # merged: the lower weight over both
    else:
        W[n] = w_k
        G[n] = g_k
        n += 1
    p_low = 0.0                           # P at the lower end of step j
    for j in range(n - 1, -1, -1):
        low = W[j + 1] if j + 1 < n else 0.0
        Q[j] = 0.5 * (p_low - G[j] * low)
        p_low += G[j] * (W[j] - low)
    return n


@njit(cache=True, nogil=True, error_model="numpy")
def _lost_base(d: float, u: float, W: np.ndarray, G: np.ndarray, Q: np.ndarray,
               n: int) -> float:  # pragma: no cover - compiled
    """``d - P(u) / 2`` (:func:`_push`), mm: on step ``j`` of the weight the lost-time
    term of :func:`_stretch_floor` is ``(base + Q[j]) / V + G[j] / 2``."""
    j = n - 1
    while j > 0 and u > W[j]:
        j -= 1
    return d - Q[j] - 0.5 * G[j] * u


@njit(cache=True, nogil=True, error_model="numpy")
def _stretch_floor(d: float, u: float, base: float, vlo: float, vhi: float, gm: float,
                   W: np.ndarray, G: np.ndarray, Q: np.ndarray,
                   n: int) -> float:  # pragma: no cover - compiled
    """Least time of a stretch from its phases (step 3 of :mod:`optimal.freq.humps`), its
    top speed ``V`` in ``[vlo, vhi]``, s.

    ``gm`` (it holds a whole phase), and the least over ``V`` of the larger of the weight
    just below ``V`` (the phase that carries the top levels lasts that long) and the
    lost-time term ``(d + int_u^V weight / 2) / V``; where ``V <= u`` (the valley's
    bound: the valley's true speed is at most ``V``) ``d / V``. On each step of the
    weight (:func:`_push`) the first is constant and the second ``C / V + G[j] / 2``,
    monotone, so each step is judged at its ends. ``base`` from :func:`_lost_base`."""
    best = np.inf
    if vlo <= u:
        best = d / min(u, vhi)
    a0 = max(u, vlo)
    for j in range(n):
        top = W[j] if j > 0 else np.inf
        a = max(a0, W[j + 1] if j + 1 < n else 0.0)
        b = min(vhi, top)
        if not a < b:
            continue
        C = base + Q[j]
        val = 0.5 * G[j] + (C / b if C >= 0.0 else C / a)
        best = min(best, max(G[j], val))
    return max(gm, best)


@njit(cache=True, nogil=True, error_model="numpy")
def _frontier(cost: np.ndarray, out: np.ndarray) -> int:  # pragma: no cover - compiled
    """The slack levels of one turn state worth going on from, most slack first, into
    ``out``; returns their number. ``cost`` (shape (NQ,), s) per slack level: a level
    with more slack and no higher cost is charged less on every later stretch and passes
    on at least as much slack (step 4b), so it makes the other one redundant."""
    n = 0
    best = np.inf
    for f in range(cost.size - 1, -1, -1):
        if cost[f] < best:
            best = cost[f]
            out[n] = f
            n += 1
    return n


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _relax(src: np.ndarray, s_lvl: int, s_cell: int, fs: np.ndarray, n: int, G: float,
           R: float, turn_src: float, turn_dst: float, charge: np.ndarray,
           levels: np.ndarray, dst: np.ndarray, d_pred: np.ndarray, d_lvl: int,
           d_cell: int, kind: int, K: int) -> None:  # pragma: no cover - compiled
    """One stretch from a turn state to the next (steps 4 and 4b): from each slack level
    ``fs[:n]`` of the source ``src[:, s_lvl, s_cell]`` (costs, s; a valley's speed
    level or a peak's) the stretch costs ``max(G, R + charge turn_src)``, and the slack
    it leaves sets the slack level of the target ``dst[:, d_lvl, d_cell]`` (its
    predecessor in ``d_pred``, packed from ``kind``, the source's levels and cell).
    Whole arrays and indices, inlined: with views and a call each the programme took
    twice as long (12mmflat's fine cells, measured)."""
    NQ = levels.size
    for m in range(n):
        f = fs[m]
        Rt = R + charge[f] * turn_src
        tot = src[f, s_lvl, s_cell] + max(G, Rt)
        q = _level(G - Rt, turn_dst, levels)
        if tot < dst[q, d_lvl, d_cell]:
            dst[q, d_lvl, d_cell] = tot
            d_pred[q, d_lvl, d_cell] = pack(kind, f, s_lvl, s_cell, NQ, K)


@njit(cache=True, nogil=True, error_model="numpy")
def _level(slack: float, cell_t: float, levels: np.ndarray) -> int:  # pragma: no cover
    """Least index of ``levels`` at or above ``slack / cell_t`` (0 for no slack, the last
    beyond the cell's time)."""
    share = slack / cell_t if slack > 0.0 else 0.0
    if not np.isfinite(share):
        return levels.size - 1
    q = 0
    while q < levels.size - 1 and levels[q] < share:
        q += 1
    return q


@njit(cache=True, nogil=True, error_model="numpy")
def ds_over(s: np.ndarray, k: int, v: float) -> float:  # pragma: no cover - compiled
    """Time of cell ``k`` at speed ``v``, s."""
    return (s[k + 1] - s[k]) / v


@njit(cache=True, nogil=True)
def pack(kind: int, level: int, speed: int, cell: int, NQ: int, K: int) -> int:  # pragma: no cover
    """One int64 for a predecessor ``(kind, slack level, speed level, cell)``."""
    return ((cell * 4 + kind) * NQ + level) * K + speed


def unpack(x: int, NQ: int, K: int) -> tuple[int, int, int, int]:
    """``(kind, slack level, speed level, cell)`` of :func:`pack`; ``-1``s for ``-1``."""
    if x < 0:
        return -1, -1, -1, -1
    x, speed = divmod(int(x), K)
    x, level = divmod(x, NQ)
    cell, kind = divmod(x, 4)
    return kind, level, speed, cell


@njit(cache=True, nogil=True, error_model="numpy")
def programme(s: np.ndarray, hi: np.ndarray, hi_m: np.ndarray, lo: np.ndarray,
              g: np.ndarray,
              turn_t: np.ndarray, first: np.ndarray, last: np.ndarray, chain: float,
              levels: np.ndarray, ratio: float, n_speed: int, peak_ratio: float,
              n_peak: int, peak_slack: float):  # pragma: no cover - compiled
    """Costs and predecessors of every state of the turn programme.

    Parameters
    ----------
    s : numpy.ndarray, shape (N + 1,)
        Cell ends, mm.
    hi : numpy.ndarray, shape (N,)
        Speed bound everywhere in each cell, the checker's standstill tolerance
        included, mm/s (``> 0``): a cell's own bound on ``v``.
    hi_m, lo : numpy.ndarray, shape (N,)
        The same and the bound at some point of each cell, with step 2's drift added
        too: the bounds a stretch carries from cell to cell through the monotonicity of
        ``w`` (``lo <= hi_m``).
    g : numpy.ndarray, shape (N,)
        Shortest phase per cell, s.
    turn_t : numpy.ndarray, shape (N,)
        Time of each cell at its top speed, ``ds / hi``, s (a turn cell's time, step 4b).
    first, last : numpy.ndarray of int64, shape (N,)
        Reach of the edges: rises into cell ``c`` start in cells ``first[c] .. c - 1``,
        falls from cell ``c`` end in cells ``c + 1 .. last[c]``.
    chain : float
        A stretch may be cut once its piece holds this many periods (step 4).
    levels : numpy.ndarray, shape (NQ,)
        Slack levels of step 4b, increasing from 0 to 1.
    ratio : float
        Ratio of the valley speed levels of step 4c (``0 < ratio < 1``).
    n_speed : int
        Number of valley speed levels ``K``: level ``k`` holds speeds in
        ``(lo ratio^(k+1), lo ratio^k]`` of the valley cell's ``lo``, the last down to 0.
    peak_ratio : float
        Ratio of the peak speed levels of step 4d (``0 < peak_ratio < 1``).
    n_peak : int
        Number of peak speed levels ``KV``: level ``m`` holds the rise's top speeds in
        ``[hi peak_ratio^(m+1), hi peak_ratio^m]`` of the peak cell's ``hi``, the last
        down to 0.
    peak_slack : float
        How far the fall's top speed may lie outside the rise's level (``2 delta``),
        mm/s.

    Returns
    -------
    valley : numpy.ndarray, shape (NQ, K, N)
        Least cost of a valley per slack level, speed level and cell, s.
    peak : numpy.ndarray, shape (NQ, KV, N)
        Least cost of a peak per slack level, peak speed level and cell, s.
    cut : numpy.ndarray, shape (2, N)
        Least cost of a rising (row 0) and a falling (row 1) cut per cell, s.
    pred_valley : numpy.ndarray of int64, shape (NQ, K, N)
    pred_peak : numpy.ndarray of int64, shape (NQ, KV, N)
    pred_cut : numpy.ndarray of int64, shape (2, N)
        Predecessor of every state, packed by :func:`pack` with ``K = max(K, KV)``
        (``-1`` where none); a valley's predecessor peak carries its peak level in the
        speed field, cuts have speed and slack level 0.
    """
    N = hi.size
    NQ = levels.size
    K = n_speed
    inf = np.inf
    valley = np.full((NQ, K, N), inf)
    KV = n_peak
    # predecessors pack a valley level or a peak level in one field (pack): its base
    KP = max(K, KV)
    peak = np.full((NQ, KV, N), inf)
    cut = np.full((2, N), inf)
    pv = np.full((NQ, K, N), -1, np.int64)
    pp = np.full((NQ, KV, N), -1, np.int64)
    pc = np.full((2, N), -1, np.int64)
    charge = 1.0 - levels
    # the lost-time weight of the stretch in hand (_push)
    stW = np.empty(MAX_WEIGHT_STEPS)
    stG = np.empty(MAX_WEIGHT_STEPS)
    stQ = np.empty(MAX_WEIGHT_STEPS)
    # upper and lower ends of the speed levels, in shares of a valley cell's lo
    top = ratio ** np.arange(K)
    bottom = ratio * top
    bottom[K - 1] = 0.0
    # the peak's speed levels, in shares of the peak cell's hi
    ptop = peak_ratio ** np.arange(KV)
    pbot = peak_ratio * ptop
    pbot[KV - 1] = 0.0
    # the first valley (the piece's start, at rest: its cell's lo bounds its speed, in
    # whichever level) passes nothing on
    for k in range(K):
        valley[NQ - 1, k, 0] = 0.0
    # the slack levels worth going on from (_frontier), per valley speed level and cell,
    # and per peak level of the cell in hand
    v_f = np.zeros((N, K, NQ), np.int64)
    v_n = np.zeros((N, K), np.int64)
    p_f = np.zeros((KV, NQ), np.int64)
    p_n = np.zeros(KV, np.int64)
    for c in range(N):
        if c > 0:
            # the valleys in cell c - 1 are final (falls into it start before it)
            for k in range(K):
                v_n[c - 1, k] = _frontier(valley[:, k, c - 1], v_f[c - 1, k])
            # rises ending in cell c, from valleys and cuts in cells i = c-1 .. first[c]
            R = 0.0               # cells i+1 .. c-1, at the monotone bounds
            suf = hi_m[c]         # least bound over hi_c and lo of cells i+1 .. c-1
            gmin = g[c]
            n_w = _push(stW, stG, stQ, 0, hi_m[c], g[c])
            lo_i = min(first[c], c - 1)
            for i in range(c - 1, lo_i - 1, -1):
                gm = min(gmin, g[i])
                d = s[c] - s[i + 1]
                # w in cell i is at most its own bound and every later one (w rises)
                n_w = _push(stW, stG, stQ, n_w, min(hi_m[i], suf), g[i])
                # the valley's speed: in its level, at most lo of its cell (where the
                # fall and the rise pass its ends) and every speed of the rise
                ucap = min(lo[i], suf)
                for k in range(K):
                    if bottom[k] * lo[i] > ucap or v_n[i, k] == 0:
                        continue
                    u = min(top[k] * lo[i], ucap)
                    base_u = _lost_base(d, u, stW, stG, stQ, n_w)
                    for kv in range(KV):
                        G = _stretch_floor(d, u, base_u, pbot[kv] * hi[c], ptop[kv] * hi[c],
                                           gm, stW, stG, stQ, n_w)
                        _relax(valley, k, i, v_f[i, k], v_n[i, k], G, R, turn_t[i],
                               turn_t[c], charge, levels, peak, pp, kv, c, VALLEY, KP)
                    # a cut at the start of cell c, once the piece holds `chain` periods
                    if R >= chain * gm:
                        for m in range(v_n[i, k]):
                            f = v_f[i, k, m]
                            x = valley[f, k, i] + R + charge[f] * turn_t[i]
                            if x < cut[0, c]:
                                cut[0, c] = x
                                pc[0, c] = pack(VALLEY, f, k, i, NQ, KP)
                # from a rising cut at cell i's start: cells i .. c-1, an R-only piece
                Rc = R + ds_over(s, i, min(hi[i], suf))
                if cut[0, i] < inf:
                    x = cut[0, i] + Rc
                    for kv in range(KV):
                        if x < peak[0, kv, c]:
                            peak[0, kv, c] = x
                            pp[0, kv, c] = pack(RISE_CUT, 0, 0, i, NQ, KP)
                    if Rc >= chain * gm and x < cut[0, c]:
                        cut[0, c] = x
                        pc[0, c] = pack(RISE_CUT, 0, 0, i, NQ, KP)
                R = Rc
                suf = min(suf, lo[i])
                gmin = gm
        if c + 1 < N:
            # the peaks in cell c are final (rises into it start before it); the slack
            # levels worth going on from, per peak level, as for the valleys
            live = cut[1, c] < inf
            for kv in range(KV):
                p_n[kv] = _frontier(peak[:, kv, c], p_f[kv])
                live = live or p_n[kv] > 0
            if not live:
                continue
            # falls starting in cell c, to valleys and cuts in cells j = c+1 .. last[c]
            hi_j = max(last[c], c + 1)
            F = 0.0               # cells c+1 .. j-1
            pre = hi_m[c]         # least bound over hi_c and lo of cells c+1 .. j-1
            F2 = 0.0              # cells c .. j-1, from a cut at cell c's start
            pre2 = hi_m[c]
            gmin = g[c]
            n_w = _push(stW, stG, stQ, 0, hi_m[c], g[c])
            for j in range(c + 1, hi_j + 1):
                gmin = min(gmin, g[j])
                # w in cell j is at most its own bound and every earlier one (w falls)
                n_w = _push(stW, stG, stQ, n_w, min(hi_m[j], pre), g[j])
                F2 += ds_over(s, j - 1, min(hi[j - 1], pre2))
                pre2 = min(pre2, lo[j - 1])
                d = s[j] - s[c + 1]
                ucap = min(lo[j], pre)
                for k in range(K):
                    if bottom[k] * lo[j] > ucap:
                        continue
                    u = min(top[k] * lo[j], ucap)
                    base_u = _lost_base(d, u, stW, stG, stQ, n_w)
                    for kv in range(KV):
                        # the fall's top speed is within peak_slack of the rise's
                        G = _stretch_floor(d, u, base_u, pbot[kv] * hi[c] - peak_slack,
                                           ptop[kv] * hi[c] + peak_slack, gmin,
                                           stW, stG, stQ, n_w)
                        _relax(peak, kv, c, p_f[kv], p_n[kv], G, F, turn_t[c],
                               turn_t[j], charge, levels, valley, pv, k, j, PEAK, KP)
                if F >= chain * gmin:
                    for kv in range(KV):
                        for m in range(p_n[kv]):
                            f = p_f[kv, m]
                            x = peak[f, kv, c] + F + charge[f] * turn_t[c]
                            if x < cut[1, j]:
                                cut[1, j] = x
                                pc[1, j] = pack(PEAK, f, kv, c, NQ, KP)
                if cut[1, c] < inf:
                    x = cut[1, c] + F2
                    # an R-only piece: tight; the valley's speed in any level its bound
                    # allows
                    ucap2 = min(lo[j], pre2)
                    for k in range(K):
                        if bottom[k] * lo[j] > ucap2:
                            continue
                        if x < valley[0, k, j]:
                            valley[0, k, j] = x
                            pv[0, k, j] = pack(FALL_CUT, 0, 0, c, NQ, KP)
                    if F2 >= chain * gmin and x < cut[1, j]:
                        cut[1, j] = x
                        pc[1, j] = pack(FALL_CUT, 0, 0, c, NQ, KP)
                # cell j is between the peak and the next valleys
                F += ds_over(s, j, min(hi[j], pre))
                pre = min(pre, lo[j])
    return valley, peak, cut, pv, pp, pc
