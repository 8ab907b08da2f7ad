"""Compiled kernel of the turn programme (numba): the shortest path of
:func:`optimal.freq.humps.hump_plan`, written as the plain loops it is.

The states, edges and costs are those of steps 3, 4 and 4b of :mod:`optimal.freq.humps`
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


@njit(cache=True, nogil=True, error_model="numpy")
def _lost(d: float, u: float, w: float, g: float) -> float:  # pragma: no cover - compiled
    """``LT`` of step 3: ``min(d / u, (d - u g / 2) / w + g / 2)``, 0 where not positive."""
    lt = min(d / u, (d - u * g / 2.0) / w + g / 2.0)
    if lt > 0.0:
        return lt
    return 0.0


@njit(cache=True, nogil=True, error_model="numpy")
def _level(slack: float, cell_t: float, levels: np.ndarray) -> int:  # pragma: no cover
    """Least index of ``levels`` at or above ``slack / cell_t`` (0 for no slack, the last
    beyond the cell's time)."""
    share = slack / cell_t if slack > 0.0 else 0.0
    if not np.isfinite(share):
        return levels.size - 1
    q = np.searchsorted(levels, share)
    return min(q, levels.size - 1)


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
              levels: np.ndarray, ratio: float, n_speed: int):  # pragma: no cover - compiled
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

    Returns
    -------
    valley : numpy.ndarray, shape (NQ, K, N)
        Least cost of a valley per slack level, speed level and cell, s.
    peak : numpy.ndarray, shape (NQ, N)
        Least cost of a peak per slack level and cell, s.
    cut : numpy.ndarray, shape (2, N)
        Least cost of a rising (row 0) and a falling (row 1) cut per cell, s.
    pred_valley : numpy.ndarray of int64, shape (NQ, K, N)
    pred_peak : numpy.ndarray of int64, shape (NQ, N)
    pred_cut : numpy.ndarray of int64, shape (2, N)
        Predecessor of every state, packed by :func:`pack` (``-1`` where none); peaks
        and cuts have speed level 0, cuts slack level 0.
    """
    N = hi.size
    NQ = levels.size
    K = n_speed
    inf = np.inf
    valley = np.full((NQ, K, N), inf)
    peak = np.full((NQ, N), inf)
    cut = np.full((2, N), inf)
    pv = np.full((NQ, K, N), -1, np.int64)
    pp = np.full((NQ, N), -1, np.int64)
    pc = np.full((2, N), -1, np.int64)
    charge = 1.0 - levels
    # upper and lower ends of the speed levels, in shares of a valley cell's lo
    top = ratio ** np.arange(K)
    bottom = ratio * top
    bottom[K - 1] = 0.0
    # the first valley (the piece's start, at rest: its cell's lo bounds its speed, in
    # whichever level) passes nothing on
    for k in range(K):
        valley[NQ - 1, k, 0] = 0.0
    for c in range(N):
        if c > 0:
            # rises ending in cell c, from valleys and cuts in cells i = c-1 .. first[c]
            R = 0.0               # cells i+1 .. c-1, at the monotone bounds
            suf = hi_m[c]         # least bound over hi_c and lo of cells i+1 .. c-1
            gmin = g[c]
            lo_i = min(first[c], c - 1)
            for i in range(c - 1, lo_i - 1, -1):
                gm = min(gmin, g[i])
                d = s[c] - s[i + 1]
                # the valley's speed: in its level, at most lo of its cell (where the
                # fall and the rise pass its ends) and every speed of the rise
                ucap = min(lo[i], suf)
                for k in range(K):
                    if bottom[k] * lo[i] > ucap:
                        continue
                    any_ = False
                    for f in range(NQ):
                        if valley[f, k, i] < inf:
                            any_ = True
                    if not any_:
                        continue
                    u = min(top[k] * lo[i], ucap)
                    G = max(gm, _lost(d, u, hi[c], gm))
                    for f in range(NQ):
                        base = valley[f, k, i]
                        if base == inf:
                            continue
                        Rt = R + charge[f] * turn_t[i]
                        tot = base + max(G, Rt)
                        q = _level(G - Rt, turn_t[c], levels)
                        if tot < peak[q, c]:
                            peak[q, c] = tot
                            pp[q, c] = pack(VALLEY, f, k, i, NQ, K)
                        # a cut at the start of cell c, once the piece holds `chain`
                        # periods
                        if R >= chain * gm and base + Rt < cut[0, c]:
                            cut[0, c] = base + Rt
                            pc[0, c] = pack(VALLEY, f, k, i, NQ, K)
                # from a rising cut at cell i's start: cells i .. c-1, an R-only piece
                Rc = R + ds_over(s, i, min(hi[i], suf))
                if cut[0, i] < inf:
                    x = cut[0, i] + Rc
                    if x < peak[0, c]:
                        peak[0, c] = x
                        pp[0, c] = pack(RISE_CUT, 0, 0, i, NQ, K)
                    if Rc >= chain * gm and x < cut[0, c]:
                        cut[0, c] = x
                        pc[0, c] = pack(RISE_CUT, 0, 0, i, NQ, K)
                R = Rc
                suf = min(suf, lo[i])
                gmin = gm
        if c + 1 < N:
            live = cut[1, c] < inf
            for f in range(NQ):
                if peak[f, c] < inf:
                    live = True
            if not live:
                continue
            # falls starting in cell c, to valleys and cuts in cells j = c+1 .. last[c]
            hi_j = max(last[c], c + 1)
            F = 0.0               # cells c+1 .. j-1
            pre = hi_m[c]         # least bound over hi_c and lo of cells c+1 .. j-1
            F2 = 0.0              # cells c .. j-1, from a cut at cell c's start
            pre2 = hi_m[c]
            gmin = g[c]
            for j in range(c + 1, hi_j + 1):
                gmin = min(gmin, g[j])
                F2 += ds_over(s, j - 1, min(hi[j - 1], pre2))
                pre2 = min(pre2, lo[j - 1])
                d = s[j] - s[c + 1]
                ucap = min(lo[j], pre)
                for k in range(K):
                    if bottom[k] * lo[j] > ucap:
                        continue
                    u = min(top[k] * lo[j], ucap)
                    G = max(gmin, _lost(d, u, hi[c], gmin))
                    for f in range(NQ):
                        base = peak[f, c]
                        if base == inf:
                            continue
                        Ft = F + charge[f] * turn_t[c]
                        tot = base + max(G, Ft)
                        q = _level(G - Ft, turn_t[j], levels)
                        if tot < valley[q, k, j]:
                            valley[q, k, j] = tot
                            pv[q, k, j] = pack(PEAK, f, 0, c, NQ, K)
                for f in range(NQ):
                    base = peak[f, c]
                    if base == inf:
                        continue
                    Ft = F + charge[f] * turn_t[c]
                    if F >= chain * gmin and base + Ft < cut[1, j]:
                        cut[1, j] = base + Ft
                        pc[1, j] = pack(PEAK, f, 0, c, NQ, K)
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
                            pv[0, k, j] = pack(FALL_CUT, 0, 0, c, NQ, K)
                    if F2 >= chain * gmin and x < cut[1, j]:
                        cut[1, j] = x
                        pc[1, j] = pack(FALL_CUT, 0, 0, c, NQ, K)
                # cell j is between the peak and the next valleys
                F += ds_over(s, j, min(hi[j], pre))
                pre = min(pre, lo[j])
    return valley, peak, cut, pv, pp, pc
