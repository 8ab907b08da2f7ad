"""Compiled parts of the two-arc transitions' sizing (numba): the deviation search of
:func:`reference.core.transition_sbend._deviation_where`, the same-way landing's Newton
iteration (:func:`reference.core.transition_samedir._newton`) and the same-way pieces
the search measures (:func:`reference.core.transition_samedir._canonical_pieces`),
written as the plain loops they are.

The search is that of :func:`reference.core.transition_sbend.pieces_deviation` (its
docstring has the argument): samples along the rounding, scan rounds around the largest
(with scan rounds, once on each side of the normal at ``J``, the larger taken),
the last window cut where the rounding crosses the normal at ``J`` and the largest
distance on each part by safeguarded Newton steps on its slope; or, with ``near``, the
refinement alone around a place found before. Each transition's numbers are the
vectorised search's: the same floating-point operations in the same order, point by
point (``numpy.clip``, ``maximum`` and ``minimum`` with their NaN rules, ``argmax``
taking the first largest), and the iterations of the crossing and of the Newton steps
run, as there, each until its own step is below the tolerance (so each transition's
numbers are its own, whatever the batch: with the batch stepping until its last part
had converged, the final searches of the same-way row's sizing stepped 1.4 times as
often as their parts needed). The Fresnel integrals are scipy's own (the
``cython_special`` export of the function ``scipy.special.fresnel`` evaluates), ``sqrt``,
``sin`` and ``cos`` the C library's, which numpy's float64 loops match bit for bit
(``|q|^3`` is two products in both, not a power: numpy's vectorised ``power`` differs
from the C library's in the last bit). ``tests/reference/test_transition_kernel.py``
compares both on random S-bends and same-way transitions and on every search of the
seeded bench programs' sizing. The rare transitions whose Newton steps do not converge
are refined by the vectorised fallback (:func:`reference.core.transition_sbend.
_refine_sampled`), as there.

Why compiled: the search works on a few dozen points per transition at a time through
some forty numpy operations per round, each a pass over a (transitions x points) array
and its temporaries, and the sizing runs it five to ten times per transition (measured,
CPU time per ``build_path`` of the quick rows of ``tests/bench/bench_rounding.py``:
SOFT G645 S-bends, 1,976 transitions, 44 ms of a 84 ms build in the searches; same-way
arcs, 1,586 transitions, 29 of 90 ms; the same searches compiled: 37.2 -> 14.6 ms and
26.9 -> 11.4 ms, what is left mostly the Fresnel integrals, one per point, as many as
before). Loaded like :mod:`reference.planner.
lookahead_kernel`: from :data:`reference.rounding_tangential.SEARCH_COMPILED_MIN`
transitions on, or once loaded, else the vectorised search runs (the core modules take
it as an argument, ``search``: they import only numpy and scipy).

The same-way landing (:func:`samedir_newton`): the whole iteration of ``_newton`` is
one compiled loop (:func:`_newton_loop`: per step and transition still iterating
:func:`_step`, the landing's miss and Jacobian, the step and its halvings, with
``_landing``'s and ``_halved``'s operations; the compaction and the verdicts those of
``_newton``). Only ``tan(h/2)`` is taken from numpy, called back from the loop once per
step over the transitions still iterating (:func:`_half_turn_tan`): numpy's float64
``tan`` is vectorised (SVML on AVX-512) and differs from the C library's in the last
bit. Why: the transitions beyond the flatter arc's fold (radius ratio about 16) wander
for all ``NEWTON_MAX_ITER`` steps there, each step some 170 numpy operations on a few
hundred transitions (measured: the 22 landings of the same-way quick row's sizing,
63 -> 12 ms CPU with each step compiled). With only the steps compiled, every step
still went through Python (the call of the step's loop with its thirteen arrays, the
compaction of nine arrays, the verdicts' writes), some 280 times per ``build_path`` of
the same-way row of 10^4 arcs: its landings 41 -> 36 ms wall with the loop compiled
(the call back for ``tan`` costs some 2 us a step); what is left is the landings'
own arithmetic, a Fresnel integral and some ten sines and cosines per step.

Units: mm. Shapes: ``k`` transitions, ``p`` pieces each.
"""

from __future__ import annotations

import math

import llvmlite.binding as llvm
import numpy as np
from numba import njit, objmode, types
from numba.extending import get_cython_function_address

from .core.transition_samedir import NEWTON_MAX_ITER as NEWTON_MAX_ITER_SAMEDIR
from .core.transition_samedir import STEP_HALVINGS, _start
from .core.transition_sbend import (DEV_SAMPLES, LANDING_TOL_MM, NEWTON_MAX_ITER,
                                    NEWTON_STEP_TOL, REFINE_POINTS, REFINE_SHRINK,
                                    SCAN_ROUNDS, THETA_MAX, finished, larger_side)

# scipy's Fresnel integrals for one double (S, C by pointer), the C function behind
# scipy.special.fresnel, called by its symbol name (a ctypes pointer would be a constant
# address, which numba cannot cache: the kernel would compile in every process, ~9 s)
_FRESNEL_SYMBOL = "feedoracle_scipy_fresnel"
llvm.add_symbol(_FRESNEL_SYMBOL, get_cython_function_address(
    "scipy.special.cython_special", "__pyx_fuse_1fresnel"))
_FRESNEL = types.ExternalFunction(_FRESNEL_SYMBOL, types.void(
    types.float64, types.CPointer(types.float64), types.CPointer(types.float64)))


@njit(cache=True, nogil=True, error_model="numpy")
def _max(a: float, b: float) -> float:  # pragma: no cover - compiled
    """``numpy.maximum`` of two floats (NaN propagates)."""
    return a if (a >= b or a != a) else b


@njit(cache=True, nogil=True, error_model="numpy")
def _min(a: float, b: float) -> float:  # pragma: no cover - compiled
    """``numpy.minimum`` of two floats (NaN propagates)."""
    return a if (a <= b or a != a) else b


@njit(cache=True, nogil=True, error_model="numpy")
def _clip(x: float, lo: float, hi: float) -> float:  # pragma: no cover - compiled
    """``numpy.clip(x, lo, hi)`` (its float rule: NaN kept, ``>``/``<`` otherwise)."""
    if not x != x:
        x = x if x > lo else lo
    if not x != x:
        x = x if x < hi else hi
    return x


@njit(cache=True, nogil=True, error_model="numpy")
def _point(packed: np.ndarray, t: int, s: float, sc: np.ndarray,
           out: np.ndarray, derivatives: bool) -> None:  # pragma: no cover - compiled
    """``_on_pieces`` at one distance ``s`` of transition ``t``: ``out[0:2]`` the point,
    ``out[2:4]`` the unit tangent, ``out[4:6]`` the second derivative (the last two only
    with ``derivatives``); ``sc`` (2,) scratch for the Fresnel integrals."""
    p = packed.shape[1]
    idx = 0
    for j in range(p - 1):
        if s >= packed[t, j, 7] + packed[t, j, 8]:
            idx += 1
    rate, length = packed[t, idx, 6], packed[t, idx, 7]
    s_local = s - packed[t, idx, 8]
    c = abs(rate)
    sigma = _min(_max(length - s_local if rate < 0 else s_local, 0.0), length)
    scale = math.sqrt(np.pi / c)
    _FRESNEL(sigma / scale, sc[0:].ctypes, sc[1:].ctypes)
    a, b = scale * sc[1], scale * sc[0]
    g2, g3 = packed[t, idx, 2], packed[t, idx, 3]
    g4, g5 = packed[t, idx, 4], packed[t, idx, 5]
    out[0] = packed[t, idx, 0] + a * g2 + b * g4
    out[1] = packed[t, idx, 1] + a * g3 + b * g5
    if derivatives:
        phi = 0.5 * c * sigma * sigma
        cs, sn = math.cos(phi), math.sin(phi)
        sign = -1.0 if rate < 0 else 1.0
        out[2] = sign * (cs * g2 + sn * g4)
        out[3] = sign * (cs * g3 + sn * g5)
        kappa = c * sigma
        out[4] = kappa * (cs * g4 - sn * g2)
        out[5] = kappa * (cs * g5 - sn * g3)


@njit(cache=True, nogil=True, error_model="numpy")
def _distance(x: float, y: float, first: bool, r_in: float, r_out: float,
              centre_out: float) -> float:  # pragma: no cover - compiled
    """``_distance`` of one canonical point from the circle ``first`` selects."""
    yc = r_in if first else centre_out
    r = r_in if first else r_out
    qy = y - yc
    return abs(x * x + y * (y - 2.0 * yc)) / (math.sqrt(x * x + qy * qy) + r)


@njit(cache=True, nogil=True, error_model="numpy")
def _on_side(d: float, x: float, side: int) -> float:  # pragma: no cover - compiled
    """``transition_sbend._on_side`` of one point."""
    if side == 0:
        return d
    keep = (x <= 0) if side == 1 else (x > 0)
    return d if keep else -np.inf


@njit(cache=True, nogil=True, error_model="numpy")
def _slopes_at(buf, first, r_in, r_out, centre_out):  # pragma: no cover - compiled
    """``_distance_slopes`` of the point ``buf`` (``_point`` with its derivatives): the
    distance, its slope and its bend."""
    x, y = buf[0], buf[1]
    yc = r_in if first else centre_out
    r = r_in if first else r_out
    qy = y - yc
    norm = math.sqrt(x * x + qy * qy)
    num = x * x + y * (y - 2.0 * yc)
    sign = 1.0 if num > 0 else (-1.0 if num < 0 else (0.0 if num == 0 else num))
    qt = x * buf[2] + qy * buf[3]
    qa = x * buf[4] + qy * buf[5]
    slope = sign * qt / norm
    bend = sign * ((1.0 + qa) / norm - qt * qt / (norm * norm * norm))
    return abs(num) / (norm + r), slope, bend


@njit(cache=True, nogil=True, error_model="numpy")
def _slopes(packed, t, s, first, r_in, r_out, centre_out, sc, buf):  # pragma: no cover
    """``_distance_slopes`` at one distance: the distance, its slope and its bend."""
    _point(packed, t, s, sc, buf, True)
    return _slopes_at(buf, first, r_in, r_out, centre_out)


@njit(cache=True, nogil=True, error_model="numpy")
def _argmax(d: np.ndarray) -> int:  # pragma: no cover - compiled
    """``numpy.argmax`` of a 1-d float array: the first largest, a NaN first of all."""
    best, k = d[0], 0
    if best != best:
        return 0
    for i in range(1, d.size):
        v = d[i]
        if v > best:
            best, k = v, i
        elif v != v:
            return i
    return k


@njit(cache=True, nogil=True, error_model="numpy")
def _bracket_max(packed, rows, a, b, first, start, r_in, r_out, centre_out,
                 d_a, g_a, d_b, g_b):  # pragma: no cover - compiled
    """``_bracket_max`` over the parts ``[a, b]`` of transitions ``rows`` (shape (m,)
    each), the distance and its slope at both ends of each given (``d_a, g_a, d_b,
    g_b``, shape (m,): the search has the points already): value, converged, where; the
    Newton steps of each inner part run until its own step is below the tolerance (or
    NEWTON_MAX_ITER)."""
    m = rows.size
    sc = np.empty(2)
    buf = np.empty(6)
    value = np.empty(m)
    where = np.empty(m)
    done = np.ones(m, dtype=np.bool_)
    inner = np.zeros(m, dtype=np.bool_)
    for i in range(m):
        at_a = g_a[i] <= 0
        at_b = (not at_a) and g_b[i] >= 0
        value[i] = d_a[i] if at_a else (d_b[i] if at_b else -np.inf)
        where[i] = a[i] if at_a else b[i]
        inner[i] = not (at_a or at_b)
    idx = np.flatnonzero(inner)
    if idx.size == 0:
        return value, done, where
    lo = a[idx].copy()
    hi = b[idx].copy()
    x = start[idx].copy()
    for n in range(idx.size):
        if not (x[n] > lo[n] and x[n] < hi[n]):
            x[n] = 0.5 * (lo[n] + hi[n])
    conv = np.zeros(idx.size, dtype=np.bool_)
    for _ in range(NEWTON_MAX_ITER):
        every = True
        for n in range(idx.size):
            if conv[n]:
                continue
            i = idx[n]
            t = rows[i]
            _, slope, bend = _slopes(packed, t, x[n], first[i], r_in[t], r_out[t],
                                     centre_out[t], sc, buf)
            if slope > 0:
                lo[n] = x[n]
            else:
                hi[n] = x[n]
            nxt = x[n] - slope / bend
            if not (bend < 0 and nxt >= lo[n] and nxt <= hi[n]):
                nxt = 0.5 * (lo[n] + hi[n])
            conv[n] = abs(nxt - x[n]) <= NEWTON_STEP_TOL * b[i]
            every = every and conv[n]
            x[n] = nxt
        if every:
            break
    for n in range(idx.size):
        i = idx[n]
        t = rows[i]
        value[i] = _slopes(packed, t, x[n], first[i], r_in[t], r_out[t], centre_out[t],
                           sc, buf)[0]
        done[i] = conv[n]
        where[i] = x[n]
    return value, done, where


@njit(cache=True, nogil=True, error_model="numpy")
def _crossing(packed, rows, a, b, xa, xb):  # pragma: no cover - compiled
    """``_crossing`` of transitions ``rows`` between ``a`` and ``b`` (shape (m,) each):
    Newton steps on ``x(s)`` from the secant's root, each until its own step is below
    the tolerance."""
    m = rows.size
    sc = np.empty(2)
    buf = np.empty(6)
    t = np.empty(m)
    for i in range(m):
        v = a[i] - xa[i] * (b[i] - a[i]) / (xb[i] - xa[i])
        t[i] = v if (v >= a[i] and v <= b[i]) else 0.5 * (a[i] + b[i])
    stopped = np.zeros(m, dtype=np.bool_)
    for _ in range(NEWTON_MAX_ITER):
        stop = True
        for i in range(m):
            if stopped[i]:
                continue
            _point(packed, rows[i], t[i], sc, buf, True)
            nxt = _clip(t[i] - buf[0] / buf[2], a[i], b[i])
            stopped[i] = abs(nxt - t[i]) <= NEWTON_STEP_TOL * b[i]
            stop = stop and stopped[i]
            t[i] = nxt
        if stop:
            break
    return t


@njit(cache=True, nogil=True, error_model="numpy")
def _sampled(packed: np.ndarray, r_in: np.ndarray, r_out: np.ndarray,
             centre_out: np.ndarray, lin: np.ndarray):  # pragma: no cover - compiled
    """The samples of the full search (``transition_sbend._samples`` and their
    ``_distance``), once for both sides: distances, places (from the rounding's start)
    and canonical ``x``, shape (k, p (n + 1)) each, ``lin`` =
    ``numpy.linspace(0, 1, n + 1)``."""
    k, p, n1 = packed.shape[0], packed.shape[1], lin.size
    dev = np.empty((k, p * n1))
    at = np.empty((k, p * n1))
    xv = np.empty((k, p * n1))
    sc = np.empty(2)
    # every piece has a sample at its zero-curvature end (sigma 0): the integrals
    # there, of +0 and of -0, evaluated once (the same numbers as at each sample)
    zero = np.empty(4)
    _FRESNEL(0.0, zero[0:].ctypes, zero[1:].ctypes)
    _FRESNEL(-0.0, zero[2:].ctypes, zero[3:].ctypes)
    for t in range(k):
        for j in range(p):
            rate, length, st = packed[t, j, 6], packed[t, j, 7], packed[t, j, 8]
            scale = math.sqrt(np.pi / abs(rate))
            for i in range(n1):
                s_local = length * lin[i]
                sigma = length - s_local if rate < 0 else s_local
                z = sigma / scale
                if z == 0.0:
                    zi = 0 if math.copysign(1.0, z) > 0 else 2
                    sc[0], sc[1] = zero[zi], zero[zi + 1]
                else:
                    _FRESNEL(z, sc[0:].ctypes, sc[1:].ctypes)
                fc, fs = scale * sc[1], scale * sc[0]
                x = packed[t, j, 0] + fc * packed[t, j, 2] + fs * packed[t, j, 4]
                y = packed[t, j, 1] + fc * packed[t, j, 3] + fs * packed[t, j, 5]
                dev[t, j * n1 + i] = _distance(x, y, x <= 0, r_in[t], r_out[t],
                                               centre_out[t])
                at[t, j * n1 + i] = st + s_local
                xv[t, j * n1 + i] = x
    return dev, at, xv


@njit(cache=True, nogil=True, error_model="numpy")
def search(packed: np.ndarray, total: np.ndarray, r_in: np.ndarray, r_out: np.ndarray,
           centre_out: np.ndarray, near: np.ndarray, use_near: bool, samples: int,
           scan: int, off: np.ndarray, side: int, s_dev: np.ndarray, s_at: np.ndarray,
           s_x: np.ndarray):  # pragma: no cover - compiled
    """The search of ``_deviation_where`` up to its fallback refinement.

    Parameters
    ----------
    packed : numpy.ndarray, shape (k, p, 9)
        ``_packed`` pieces.
    total : numpy.ndarray, shape (k,)
        Rounding lengths (``lengths.sum(axis=1)``), mm.
    r_in, r_out, centre_out : numpy.ndarray, shape (k,)
        mm.
    near : numpy.ndarray, shape (k,)
        Where to refine (with ``use_near``), mm.
    samples, scan : int
        Samples per piece and scan rounds (without ``use_near``).
    off : numpy.ndarray, shape (REFINE_POINTS,)
        The scan's offsets, in units of its half width.
    side : int
        The samples and scan points taken: 1 those with ``x <= 0``, 2 ``x > 0``, 0 all
        (``transition_sbend._on_side``).
    s_dev, s_at, s_x : numpy.ndarray, shape (k, p (samples + 1))
        The samples' distances, places and ``x`` (:func:`_sampled`; unused with
        ``use_near``).

    Returns
    -------
    best, where, at, h0, win_lo, win_hi : numpy.ndarray, shape (k,)
        The deviation, where it was found, the scan's last centre and the sample spacing
        (both for the fallback), the last window, mm.
    ok : numpy.ndarray of bool, shape (k,)
        The Newton steps converged on every part of the window.
    """
    k, p = packed.shape[0], packed.shape[1]
    sc = np.empty(2)
    buf = np.empty(6)
    best = np.empty(k)
    at = np.empty(k)
    h = np.empty(k)
    h0 = np.empty(k)
    if not use_near:
        n1 = samples + 1
        dev = np.empty(p * n1)
        d = np.empty(off.size)
        xs = np.empty(off.size)
        for t in range(k):
            for m in range(p * n1):
                dev[m] = _on_side(s_dev[t, m], s_x[t, m], side)
            i = _argmax(dev)
            best[t], at[t] = dev[i], s_at[t, i]
            h0[t] = packed[t, min(i // n1, p - 1), 7] / samples
            h[t] = h0[t]
            for _ in range(scan):
                for q in range(off.size):
                    xq = _clip(at[t] + h[t] * off[q], 0.0, total[t])
                    _point(packed, t, xq, sc, buf, False)
                    xs[q] = xq
                    d[q] = _on_side(_distance(buf[0], buf[1], buf[0] <= 0, r_in[t],
                                              r_out[t], centre_out[t]), buf[0], side)
                j = _argmax(d)
                if d[j] > best[t]:
                    best[t], at[t] = d[j], xs[j]
                h[t] = h[t] / REFINE_SHRINK
    else:
        for t in range(k):
            at[t] = _clip(near[t], 0.0, total[t])
            piece, run = 0, 0.0
            for j in range(p - 1):
                run = packed[t, j, 7] if j == 0 else run + packed[t, j, 7]
                if at[t] >= run:
                    piece += 1
            h0[t] = packed[t, piece, 7] / DEV_SAMPLES
            h[t] = h0[t] / REFINE_SHRINK
            best[t] = -np.inf
    where = at.copy()
    lo = np.empty(k)
    hi = np.empty(k)
    x_lo = np.empty(k)
    x_hi = np.empty(k)
    # the window's ends once, with the distance and its slope on the part each ends
    # (the part from lo takes lo's circle; the part to hi the same unless the window
    # crosses x = 0, where the second part takes the outgoing circle)
    d_lo, g_lo = np.empty(k), np.empty(k)
    d_hi, g_hi = np.empty(k), np.empty(k)
    for t in range(k):
        lo[t] = _max(at[t] - h[t], 0.0)
        hi[t] = _min(at[t] + h[t], total[t])
        _point(packed, t, lo[t], sc, buf, True)
        x_lo[t] = buf[0]
        d_lo[t], g_lo[t], _ = _slopes_at(buf, x_lo[t] <= 0, r_in[t], r_out[t],
                                         centre_out[t])
        _point(packed, t, hi[t], sc, buf, True)
        x_hi[t] = buf[0]
        d_hi[t], g_hi[t], _ = _slopes_at(buf, x_lo[t] <= 0 and not x_hi[t] > 0, r_in[t],
                                         r_out[t], centre_out[t])
    split = np.flatnonzero((x_lo <= 0) & (x_hi > 0))
    cross = _crossing(packed, split, lo[split], hi[split], x_lo[split], x_hi[split])
    # the crossing once, for the end of the first part and the start of the second
    d_c1, g_c1 = np.empty(split.size), np.empty(split.size)
    d_c2, g_c2 = np.empty(split.size), np.empty(split.size)
    for n in range(split.size):
        t = split[n]
        _point(packed, t, cross[n], sc, buf, True)
        d_c1[n], g_c1[n], _ = _slopes_at(buf, True, r_in[t], r_out[t], centre_out[t])
        d_c2[n], g_c2[n], _ = _slopes_at(buf, False, r_in[t], r_out[t], centre_out[t])
    mid = hi.copy()
    mid[split] = cross
    d_mid, g_mid = d_hi.copy(), g_hi.copy()
    d_mid[split] = d_c1
    g_mid[split] = g_c1
    rows = np.concatenate((np.arange(k), split))
    a = np.concatenate((lo, cross))
    b = np.concatenate((mid, hi[split]))
    first = np.concatenate((x_lo <= 0, np.zeros(split.size, dtype=np.bool_)))
    value, done, at_value = _bracket_max(
        packed, rows, a, b, first, at[rows], r_in, r_out, centre_out,
        np.concatenate((d_lo, d_c2)), np.concatenate((g_lo, g_c2)),
        np.concatenate((d_mid, d_hi[split])), np.concatenate((g_mid, g_hi[split])))
    # the window's part with the larger value (the first part where they tie)
    for i in range(rows.size):
        t = rows[i]
        if value[i] > best[t]:
            where[t] = at_value[i]
            best[t] = value[i]
    ok = np.ones(k, dtype=np.bool_)
    for i in range(rows.size):
        ok[rows[i]] = ok[rows[i]] and done[i]
    return best, where, at, h0, lo, hi, ok


@njit(cache=True, nogil=True, error_model="numpy")
def _fill_starts(out: np.ndarray, t: int) -> None:  # pragma: no cover - compiled
    """Column 8 of transition ``t`` of a packed array: each piece's start, the running
    sum of the lengths (column 7), piece by piece as ``numpy.cumsum``, less the piece's
    own length (as ``transition_sbend._packed``)."""
    run = 0.0
    for j in range(out.shape[1]):
        length = out[t, j, 7]
        run = length if j == 0 else run + length
        out[t, j, 8] = run - length


@njit(cache=True, nogil=True, error_model="numpy")
def _pack(origin, e1, e2, rates, lengths):  # pragma: no cover - compiled
    """``transition_sbend._packed`` of the pieces (the starts as there: the running sum
    of the lengths, piece by piece as ``numpy.cumsum``, less the piece's own length)."""
    k, p = lengths.shape
    out = np.empty((k, p, 9))
    for t in range(k):
        for j in range(p):
            out[t, j, 0], out[t, j, 1] = origin[t, j, 0], origin[t, j, 1]
            out[t, j, 2], out[t, j, 3] = e1[t, j, 0], e1[t, j, 1]
            out[t, j, 4], out[t, j, 5] = e2[t, j, 0], e2[t, j, 1]
            out[t, j, 6] = rates[t, j]
            out[t, j, 7] = lengths[t, j]
        _fill_starts(out, t)
    return out


def deviation_where(pieces, r_in, r_out, centre_out, near=None, samples=DEV_SAMPLES,
                    scan=SCAN_ROUNDS):
    """:func:`reference.core.transition_sbend._deviation_where` by the compiled
    :func:`search` (the same arguments and results, bit for bit; the full search with
    scan rounds once on each side from the same samples, combined by the same
    :func:`~reference.core.transition_sbend.larger_side`)."""
    lengths = pieces[4]
    k = lengths.shape[0]
    f64 = np.float64
    total = np.ascontiguousarray(lengths.sum(axis=1), f64)
    # packed by one compiled loop: numpy's concatenation of the (k, p, 2) strided parts
    # took about as long as a near search (1.1 ms of 8,000 transitions); the same-way
    # pieces come packed already (samedir_pieces)
    packed = _packed_of(pieces)
    if packed is None:
        packed = _pack(*(np.asarray(v, f64) for v in pieces))
    r_in, r_out, centre_out = (np.ascontiguousarray(v, f64) for v in (r_in, r_out,
                                                                        centre_out))
    use_near = near is not None
    near_arr = np.ascontiguousarray(near, f64) if use_near else np.zeros(k)
    off = (np.arange(REFINE_POINTS) - REFINE_POINTS // 2) / (REFINE_POINTS // 2)
    sampled = ((np.zeros((k, 0)),) * 3 if use_near else
               _sampled(packed, r_in, r_out, centre_out,
                        np.linspace(0.0, 1.0, int(samples) + 1)))

    def on_side(side):
        return finished(packed, *search(packed, total, r_in, r_out, centre_out, near_arr,
                                        use_near, int(samples), int(scan), off, side,
                                        *sampled), r_in, r_out, centre_out)

    if not use_near and scan > 0:
        return larger_side(on_side(1), on_side(2))
    return on_side(0)


# ----------------------------------------------------------------- same-way landing
@njit(cache=True, nogil=True, error_model="numpy")
def _landing(t1, p2, r_in, r_out, rate, xq1, yq1, xq2, yq2, th, sc,
             out):  # pragma: no cover - compiled
    """``transition_samedir._landing`` of one transition: ``out[0:2]`` the miss,
    ``out[2:6]`` the Jacobian ``j00, j01, j10, j11``; ``th = tan(h / 2)`` computed by
    numpy (:func:`samedir_newton`)."""
    b = -t1
    uax, uay = math.cos(b), math.sin(b)
    nax, nay = -uay, uax
    ubx, uby = math.cos(p2), math.sin(p2)
    nbx, nby = -uby, ubx
    s1 = math.sin(0.5 * t1)
    p1x, p1y = -r_in * math.sin(t1), 2.0 * r_in * (s1 * s1)
    s2 = math.sin(0.5 * p2)
    p2x, p2y = r_out * math.sin(p2), 2.0 * r_out * (s2 * s2)
    q1x, q1y = p1x - xq1 * uax + yq1 * nax, p1y - xq1 * uay + yq1 * nay
    q2x, q2y = p2x + xq2 * ubx + yq2 * nbx, p2y + xq2 * uby + yq2 * nby
    d1x, d1y = (yq1 - r_in) * uax + xq1 * nax, (yq1 - r_in) * uay + xq1 * nay
    d2x, d2y = (r_out - yq2) * ubx + xq2 * nbx, (r_out - yq2) * uby + xq2 * nby
    h = t1 + p2
    l_p = np.sqrt(h / rate)
    # clothoid_pair_shape(h), its tan(h/2) = th
    scale = np.sqrt(np.pi / h)
    _FRESNEL(1.0 / scale, sc[0:].ctypes, sc[1:].ctypes)
    big_x, big_y = scale * sc[1], scale * sc[0]
    d_1 = big_x + big_y * th
    # clothoid_pair_shape's cos(h / 2) is the Jacobian's cos(0.5 h): halving is exact,
    # so one cosine serves both
    ch, sh = math.cos(0.5 * h), math.sin(0.5 * h)
    e_1 = big_y / ch
    d_p = l_p * d_1
    wx, wy = uax + ubx, uay + uby
    out[0] = q2x - q1x - d_p * wx
    out[1] = q2y - q1y - d_p * wy
    y = e_1 * ch
    x = d_1 - y * th
    dd1 = (ch - x) / (2.0 * h) + (sh - y) / (2.0 * h) * th + 0.5 * y / (ch * ch)
    dd = 0.5 * d_p / h + l_p * dd1
    out[2] = -d1x - dd * wx + d_p * nax
    out[3] = d2x - dd * wx - d_p * nbx
    out[4] = -d1y - dd * wy + d_p * nay
    out[5] = d2y - dd * wy - d_p * nby


@njit(cache=True, nogil=True, error_model="numpy")
def _step(a1, a2, r1, r2, c, xq1, yq1, xq2, yq2, th, tol, theta_max, halvings, sc,
          out):  # pragma: no cover - compiled
    """One step of ``transition_samedir._newton`` for one transition at ``(a1, a2)``:
    whether it lands there, whether it steps, and the iterate after the step
    (``_halved`` included); ``sc``, ``out`` scratch of :func:`_landing`."""
    _landing(a1, a2, r1, r2, c, xq1, yq1, xq2, yq2, th, sc, out)
    g0, g1 = out[0], out[1]
    ok = abs(g0) <= tol and abs(g1) <= tol
    j00, j01, j10, j11 = out[2], out[3], out[4], out[5]
    det = j00 * j11 - j01 * j10
    dt = -(j11 * g0 - j01 * g1) / det
    dp = -(j00 * g1 - j10 * g0) / det
    a, b = a1 + dt, a2 + dp
    if not (a + a2 + dp > 0 and abs(a) < theta_max and abs(b) < theta_max):
        # the halvings dt 2^-k, the first allowed, else the last
        ct, cp = dt, dp
        for k in range(halvings + 1):
            if k > 0:
                ct, cp = ct * 0.5, cp * 0.5
            a, b = a1 + ct, a2 + cp
            if k == halvings or (a + a2 + cp > 0 and abs(a) < theta_max
                                 and abs(b) < theta_max):
                break
        dt, dp = ct, cp
    step = (not ok) and np.isfinite(dt) and np.isfinite(dp)
    if step:
        return ok, step, a1 + dt, a2 + dp
    return ok, step, a1, a2


def _numpy_tan(x: np.ndarray) -> np.ndarray:
    """``numpy.tan(x)`` (float64) as the vectorised landing takes it (see
    :func:`samedir_newton`)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.tan(x)


@njit(cache=True, error_model="numpy")
def _half_turn_tan(t1, p2, act, m):  # pragma: no cover - compiled
    """``numpy.tan(0.5 * (t1 + p2))`` of the transitions ``act[:m]``, shape (m,): the
    sum and the half in this loop (the same operations as numpy's), the tangent by
    numpy itself, called back from the compiled loop (numpy's float64 ``tan`` differs
    from the C library's in the last bit where it is vectorised). Without ``nogil``:
    the call back holds the interpreter."""
    half = np.empty(m)
    for n in range(m):
        i = act[n]
        half[n] = 0.5 * (t1[i] + p2[i])
    with objmode(th="float64[:]"):
        th = _numpy_tan(half)
    return th


@njit(cache=True, error_model="numpy")
def _newton_loop(t1, p2, r1, r2, c, xq1, yq1, xq2, yq2, tol, theta_max, halvings,
                 max_iter):  # pragma: no cover - compiled
    """The iteration of ``transition_samedir._newton`` from the start ``(t1, p2)``
    (shape (k,) each, updated in place to each transition's last iterate): whether each
    lands, before the final ``h > 0`` test. The transitions still iterating are the
    first ``m`` of ``act`` (a transition leaves it when it lands or its step is not
    finite, keeping the order), so each one's iterates are those it has alone."""
    k = t1.size
    lands = np.zeros(k, dtype=np.bool_)
    act = np.arange(k)
    m = k
    sc = np.empty(2)
    out = np.empty(6)
    for _ in range(max_iter):
        if m == 0:
            break
        th = _half_turn_tan(t1, p2, act, m)
        keep = 0
        for n in range(m):
            i = act[n]
            ok, step, t1[i], p2[i] = _step(t1[i], p2[i], r1[i], r2[i], c[i], xq1[i],
                                           yq1[i], xq2[i], yq2[i], th[n], tol, theta_max,
                                           halvings, sc, out)
            if ok:
                lands[i] = True
            if step:
                act[keep] = i
                keep += 1
        m = keep
    if m:                                     # still iterating: the miss after the last step
        th = _half_turn_tan(t1, p2, act, m)
        for n in range(m):
            i = act[n]
            _landing(t1[i], p2[i], r1[i], r2[i], c[i], xq1[i], yq1[i], xq2[i], yq2[i],
                     th[n], sc, out)
            lands[i] = abs(out[0]) <= tol and abs(out[1]) <= tol
    return lands


@njit(cache=True, nogil=True, error_model="numpy")
def _ramp_starts(r_in, r_out, ramp):  # pragma: no cover - compiled
    """``transition_samedir._ramp_starts`` of ``k`` transitions (:func:`_ramp_start`
    per ramp), four arrays of shape (k,)."""
    k = ramp.size
    xq1, yq1, xq2, yq2 = np.empty(k), np.empty(k), np.empty(k), np.empty(k)
    sc = np.empty(2)
    for t in range(k):
        xq1[t], yq1[t] = _ramp_start(r_in[t], ramp[t], sc)
        xq2[t], yq2[t] = _ramp_start(r_out[t], ramp[t], sc)
    return xq1, yq1, xq2, yq2


def samedir_newton(r_in, r_out, ramp, rate, off, flat_out):
    """:func:`reference.core.transition_samedir._newton` compiled (:func:`_newton_loop`;
    the same arguments and results, bit for bit). ``tan(h/2)`` is numpy's, called back
    from the loop over the transitions still iterating as ``_landing`` computes it
    (numpy's float64 ``tan`` is vectorised, SVML on AVX-512, and differs from the C
    library's in the last bit); every other operation the C library's, which numpy's
    float64 loops match. ``off`` None: the ramps' starts by the compiled
    :func:`_ramp_starts` (measured on the same-way row of ``tests/bench/
    bench_rounding.py``: numpy's two ``ramp_offset`` per shape built took 2 ms of its
    80 ms rounding)."""
    f64 = np.float64
    if off is None:
        off = _ramp_starts(*(np.ascontiguousarray(v, f64) for v in (r_in, r_out, ramp)))
    t1, p2 = _start(r_in, r_out, ramp, rate, flat_out)
    t1, p2 = np.array(t1, f64), np.array(p2, f64)
    args = (np.ascontiguousarray(v, f64) for v in (r_in, r_out, rate, *off))
    lands = _newton_loop(t1, p2, *args, LANDING_TOL_MM, THETA_MAX, STEP_HALVINGS,
                         NEWTON_MAX_ITER_SAMEDIR)
    lands &= t1 + p2 > 0
    return np.where(lands, t1, np.nan), np.where(lands, p2, np.nan)


# ----------------------------------------------------------------- same-way pieces
@njit(cache=True, nogil=True, error_model="numpy")
def _ramp_start(radius: float, length: float, sc: np.ndarray):  # pragma: no cover
    """:func:`reference.core.transition.ramp_offset`'s start ``(x_q, y_q)`` of one ramp:
    its operations in its order (``2 R sin^2(psi/2)`` as ``(2 R) (s s)``, as numpy's
    ``2.0 * radius * s ** 2``); ``sc`` (2,) scratch for the Fresnel integrals."""
    c = 1.0 / (radius * length)
    scale = math.sqrt(np.pi / c)
    _FRESNEL(length / scale, sc[0:].ctypes, sc[1:].ctypes)
    x_r, y_r = scale * sc[1], scale * sc[0]
    psi = length / (2.0 * radius)
    s = math.sin(psi / 2.0)
    return radius * math.sin(psi) - x_r, 2.0 * radius * (s * s) - y_r


@njit(cache=True, nogil=True, error_model="numpy")
def _samedir_packed(theta, phi, r_in, r_out, ramp_in, ramp_out, piece,
                    rate):  # pragma: no cover - compiled
    """``transition_samedir._canonical_pieces`` (with ``_ends`` and the ramps' starts,
    :func:`_ramp_start`) of ``k`` transitions, written as :func:`_pack` lays them out,
    shape (k, 4, 9): its operations, per transition, in its order (``2 sin^2(b/2)`` as
    two products, as numpy's ``** 2``; the pieces' starts by :func:`_fill_starts`, as
    :func:`_pack`)."""
    k = theta.size
    out = np.empty((k, 4, 9))
    sc = np.empty(2)
    for t in range(k):
        t1, p2 = theta[t], phi[t]
        r1, r2 = r_in[t], r_out[t]
        xq1, yq1 = _ramp_start(r1, ramp_in[t], sc)
        xq2, yq2 = _ramp_start(r2, ramp_out[t], sc)
        b = -t1
        uax, uay = math.cos(b), math.sin(b)
        nax, nay = -uay, uax
        ubx, uby = math.cos(p2), math.sin(p2)
        nbx, nby = -uby, ubx
        s1 = math.sin(0.5 * t1)
        p1x, p1y = -r1 * math.sin(t1), 2.0 * r1 * (s1 * s1)
        s2 = math.sin(0.5 * p2)
        p2x, p2y = r2 * math.sin(p2), 2.0 * r2 * (s2 * s2)
        q1x, q1y = p1x - xq1 * uax + yq1 * nax, p1y - xq1 * uay + yq1 * nay
        q2x, q2y = p2x + xq2 * ubx + yq2 * nbx, p2y + xq2 * uby + yq2 * nby
        c = rate[t]
        for j, qx, qy, ux, uy, nx, ny, rj, lj in (
                (0, q1x, q1y, -uax, -uay, nax, nay, -1.0 / (r1 * ramp_in[t]), ramp_in[t]),
                (1, q1x, q1y, uax, uay, nax, nay, c, piece[t]),
                (2, q2x, q2y, -ubx, -uby, nbx, nby, -c, piece[t]),
                (3, q2x, q2y, ubx, uby, nbx, nby, 1.0 / (r2 * ramp_out[t]), ramp_out[t])):
            out[t, j, 0], out[t, j, 1] = qx, qy
            out[t, j, 2], out[t, j, 3] = ux, uy
            out[t, j, 4], out[t, j, 5] = nx, ny
            out[t, j, 6], out[t, j, 7] = rj, lj
        _fill_starts(out, t)
    return out


def _views(packed: np.ndarray) -> tuple:
    """The pieces tuple (:func:`reference.core.transition_sbend.pieces_deviation`) as
    views of a packed array (k, p, 9): origins, ``e1``, ``e2`` (k, p, 2), rates and
    lengths (k, p)."""
    return (packed[:, :, 0:2], packed[:, :, 2:4], packed[:, :, 4:6], packed[:, :, 6],
            packed[:, :, 7])


def _packed_of(pieces) -> np.ndarray | None:
    """The array ``pieces`` are views of (:func:`_views`) where it is packed as
    :func:`_pack` packs them (its starts column the running sum of the lengths, as
    there: :func:`samedir_pieces` returns such views), else None (then packed anew)."""
    base = pieces[0].base
    if not (isinstance(base, np.ndarray) and base.ndim == 3 and base.shape[2] == 9
            and base.dtype == np.float64 and base.flags.c_contiguous):
        return None
    for v, w in zip(pieces, _views(base)):
        if not (v.base is base and v.shape == w.shape and v.strides == w.strides
                and v.ctypes.data == w.ctypes.data):
            return None
    lengths = base[:, :, 7]
    if not np.array_equal(base[:, :, 8], np.cumsum(lengths, axis=1) - lengths):
        return None
    return base


def samedir_pieces(sh):
    """:func:`reference.core.transition_samedir._canonical_pieces` by the compiled
    :func:`_samedir_packed` (the same argument and results, bit for bit), as views of
    the packed array the compiled search measures (:func:`deviation_where` takes it as
    it is). Why: it builds the pieces of every shape the sizing measures, some thirty
    numpy operations on (k, 2) rows, five stacks and the two ramps' starts
    (``ramp_offset``) each time (measured on 8,000 same-way transitions: 2.4 ms a call,
    0.7 ms compiled, most of it the two ``ramp_offset``); built packed, the search's
    packing of the five arrays (:func:`_pack`, 0.35 ms a call of 8,000 transitions) and
    numpy's two ``ramp_offset`` (0.3 ms) are not needed either."""
    f64 = np.float64
    return _views(_samedir_packed(*(np.ascontiguousarray(v, f64) for v in (
        sh.theta, sh.phi, sh.r_in, sh.r_out, sh.ramp_in, sh.ramp_out, sh.piece,
        sh.rate))))
