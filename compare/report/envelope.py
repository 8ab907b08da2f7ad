"""Reduce long series to what a screen can show without losing a peak.

A plot is about a thousand pixel columns wide; a program of 10^5 blocks has millions of
samples. Drawing every sample makes the SVG hundreds of MB and the curve a solid blob;
drawing every k-th sample (striding) aliases: a spike between two kept samples vanishes.
The min/max envelope keeps, for every pixel column, the sample with the smallest and the
one with the largest value, so the drawn polyline reaches every peak and every trough of
the data, and its size depends on the plot width only.

Pure numpy, no plotting. Shapes: ``N`` samples, ``C`` columns.
"""

from __future__ import annotations

from typing import Callable, Iterable

import numpy as np

#: Pixel columns of a plot: the figures are 11 in wide and shown at most ~1230 px wide
#: (the page's max-width); 1200 columns give every screen pixel its own min and max.
N_COLUMNS = 1200

#: Samples evaluated per chunk when a series is built from a long profile (bounds the
#: memory of one chunk to a few tens of MB whatever the program size).
CHUNK = 200_000


def _columns(x: np.ndarray, x0: float, x1: float, n_columns: int) -> np.ndarray:
    width = x1 - x0
    if not width > 0:
        return np.zeros(x.shape, dtype=np.int64)
    return np.clip(((x - x0) * (n_columns / width)).astype(np.int64), 0, n_columns - 1)


def envelope_indices(x: np.ndarray, y: np.ndarray, x0: float, x1: float,
                     n_columns: int = N_COLUMNS) -> np.ndarray:
    """Indices of the smallest and largest ``y`` in every column of ``[x0, x1]``.

    Parameters
    ----------
    x, y : numpy.ndarray, shape (N,)
        Abscissa and value; non-finite pairs are ignored.
    x0, x1 : float
        Range of the plot's x axis (samples outside it go to the edge columns).
    n_columns : int
        Number of columns.

    Returns
    -------
    numpy.ndarray of int, shape (M,), M <= 2 C
        Sorted indices into ``x``/``y``: per non-empty column the argmin and argmax
        (one index when they coincide). When there are no more finite samples than
        ``2 * n_columns``, all of them.
    """
    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    ok = np.flatnonzero(np.isfinite(x) & np.isfinite(y))
    if ok.size <= 2 * n_columns:
        return ok
    col = _columns(x[ok], x0, x1, n_columns)
    yk = y[ok]
    if np.all(col[1:] >= col[:-1]):          # sorted x (the usual case): O(N)
        start = np.flatnonzero(np.r_[True, col[1:] != col[:-1]])
        size = np.diff(np.r_[start, col.size])
        g = np.repeat(np.arange(start.size), size)
        lo = np.minimum.reduceat(yk, start)
        hi = np.maximum.reduceat(yk, start)
        # first sample of each column that attains its min (max)
        i_lo = np.flatnonzero(yk == lo[g])
        i_hi = np.flatnonzero(yk == hi[g])
        i_lo = i_lo[np.r_[True, g[i_lo][1:] != g[i_lo][:-1]]]
        i_hi = i_hi[np.r_[True, g[i_hi][1:] != g[i_hi][:-1]]]
        return np.unique(ok[np.concatenate([i_lo, i_hi])])
    order = np.lexsort((yk, col))             # by column, inside a column by value
    cs = col[order]
    first = np.flatnonzero(np.r_[True, cs[1:] != cs[:-1]])
    last = np.r_[first[1:], cs.size] - 1
    return np.unique(ok[np.concatenate([order[first], order[last]])])


def envelope(x, y, x0: float, x1: float, n_columns: int = N_COLUMNS
             ) -> tuple[np.ndarray, np.ndarray]:
    """The min/max envelope of a series as a polyline, in the order of ``x``.

    Parameters
    ----------
    x, y : array_like, shape (N,)
        Samples; ``x`` non-decreasing for a polyline that runs left to right.
    x0, x1 : float
        Range of the plot's x axis.
    n_columns : int
        Pixel columns.

    Returns
    -------
    x, y : numpy.ndarray, shape (M,), M <= max(N, 2 C)
        The kept samples. ``max(y)`` and ``min(y)`` over the finite samples are among
        them, as is the extreme of every column.
    """
    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    keep = envelope_indices(x, y, x0, x1, n_columns)
    return x[keep], y[keep]


def column_extremes(x, y, x0: float, x1: float, n_columns: int = N_COLUMNS
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Smallest and largest value per column, for bar-like (filled) envelopes.

    Parameters
    ----------
    x, y : array_like, shape (N,)
    x0, x1 : float
        Range of the x axis.
    n_columns : int

    Returns
    -------
    centre, lo, hi : numpy.ndarray, shape (C,)
        Column centres (in units of ``x``) and the min and max of ``y`` in each column
        (``nan`` for an empty column).
    """
    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    ok = np.isfinite(x) & np.isfinite(y)
    col = _columns(x[ok], x0, x1, n_columns)
    lo = np.full(n_columns, np.inf)
    hi = np.full(n_columns, -np.inf)
    np.minimum.at(lo, col, y[ok])
    np.maximum.at(hi, col, y[ok])
    empty = ~np.isfinite(lo)
    lo[empty] = np.nan
    hi[empty] = np.nan
    centre = x0 + (np.arange(n_columns) + 0.5) * ((x1 - x0) / n_columns)
    return centre, lo, hi


def chunked_envelopes(times: np.ndarray,
                      series: Callable[[np.ndarray], Iterable[tuple[np.ndarray, np.ndarray]]],
                      x0: float, x1: float, n_columns: int = N_COLUMNS,
                      chunk: int = CHUNK) -> list[tuple[np.ndarray, np.ndarray]]:
    """Envelopes of several series evaluated chunk by chunk at ``times``.

    The envelope of a union is the envelope of the chunks' envelopes (a column's min
    and max survive every reduction), so memory stays bounded by ``chunk`` samples.

    Parameters
    ----------
    times : numpy.ndarray, shape (N,)
        Sorted sample times (or any parameter ``series`` takes).
    series : callable
        ``series(t_chunk)`` yields ``(x, y)`` pairs, the same number for every chunk.
    x0, x1 : float
        Range of the x axis of every series.
    n_columns : int
    chunk : int
        Samples per evaluation.

    Returns
    -------
    list of (x, y)
        One envelope polyline per series.
    """
    parts: list[list[tuple[np.ndarray, np.ndarray]]] = []
    for start in range(0, max(times.size, 1), chunk):
        t = times[start:start + chunk]
        for k, (x, y) in enumerate(series(t)):
            if k == len(parts):
                parts.append([])
            parts[k].append(envelope(x, y, x0, x1, n_columns))
    out = []
    for p in parts:
        x = np.concatenate([a for a, _ in p])
        y = np.concatenate([b for _, b in p])
        out.append(envelope(x, y, x0, x1, n_columns))
    return out
