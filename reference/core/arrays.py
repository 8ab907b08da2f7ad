"""Read-only array storage for the frozen result records of every package.

A frozen dataclass freezes its attributes, not the numpy arrays they hold: each record
stores its arrays through :func:`readonly`, so a result cannot be changed in place after
it was checked.
"""

from __future__ import annotations

import numpy as np


def readonly(a, dtype=None) -> np.ndarray:
    """A contiguous, write-protected array of ``a`` (converted to ``dtype`` if given).

    Parameters
    ----------
    a : array_like
    dtype : numpy dtype, optional
        Default: keep ``a``'s own (float64 for Python floats).

    Returns
    -------
    numpy.ndarray
        Not writeable; a copy only where ``a`` was not contiguous or of another dtype.
    """
    out = np.ascontiguousarray(a, dtype=dtype)
    out.setflags(write=False)
    return out


# Row-wise reductions over the few axis columns of a (k, n) array. numpy reduces the
# short last axis row by row (some 25..75 ns per row, whatever n); these work column by
# column over whole rows at a time and give the same numbers: ``min``/``max`` are exact
# in any order, and for n < 8 numpy sums a row in column order, as done here (from 8
# columns on it sums pairwise, so the functions hand those to numpy).
_SEQUENTIAL_SUM_COLUMNS = 8


def row_norms(x: np.ndarray) -> np.ndarray:
    """``numpy.linalg.norm(x, axis=-1)`` of a 2-D array, shape (k, n) -> (k,).

    The same numbers (bit for bit): squares summed in column order, as numpy does for
    fewer than 8 columns; 8 or more columns are handed to numpy.
    """
    x = np.asarray(x)
    if x.ndim != 2 or x.shape[1] >= _SEQUENTIAL_SUM_COLUMNS or x.shape[1] == 0 \
            or x.dtype != np.float64:
        return np.linalg.norm(x, axis=-1)
    acc = x[:, 0] * x[:, 0]
    for j in range(1, x.shape[1]):
        col = x[:, j]
        acc += col * col
    return np.sqrt(acc, out=acc)


def row_sums(x: np.ndarray) -> np.ndarray:
    """``x.sum(axis=1)`` of a 2-D float array, shape (k, n) -> (k,).

    The same numbers (bit for bit): columns summed in order, as numpy does for fewer
    than 8 columns; 8 or more columns are handed to numpy.
    """
    x = np.asarray(x)
    if x.ndim != 2 or x.shape[1] >= _SEQUENTIAL_SUM_COLUMNS or x.shape[1] == 0 \
            or x.dtype != np.float64:
        return x.sum(axis=1)
    acc = x[:, 0].copy()
    for j in range(1, x.shape[1]):
        acc += x[:, j]
    return acc


def row_dots(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``numpy.sum(x * y, axis=1)`` of two 2-D arrays of one shape, (k, n) -> (k,).

    The same numbers (bit for bit): products summed in column order, as numpy does for
    fewer than 8 columns; 8 or more columns are handed to numpy.
    """
    x, y = np.asarray(x), np.asarray(y)
    if x.ndim != 2 or x.shape != y.shape or x.shape[1] >= _SEQUENTIAL_SUM_COLUMNS \
            or x.shape[1] == 0 or x.dtype != np.float64 or y.dtype != np.float64:
        return np.sum(x * y, axis=1)
    acc = x[:, 0] * y[:, 0]
    for j in range(1, x.shape[1]):
        acc += x[:, j] * y[:, j]
    return acc


def row_min(x: np.ndarray) -> np.ndarray:
    """``x.min(axis=1)`` of a 2-D array with at least one column, shape (k, n) -> (k,)."""
    x = np.asarray(x)
    out = x[:, 0].copy()
    for j in range(1, x.shape[1]):
        np.minimum(out, x[:, j], out=out)
    return out


def row_max(x: np.ndarray) -> np.ndarray:
    """``x.max(axis=1)`` of a 2-D array with at least one column, shape (k, n) -> (k,)."""
    x = np.asarray(x)
    out = x[:, 0].copy()
    for j in range(1, x.shape[1]):
        np.maximum(out, x[:, j], out=out)
    return out


def row_argmin(x: np.ndarray) -> np.ndarray:
    """``x.argmin(axis=1)`` of a 2-D array without NaN, at least one column: the first
    column holding each row's minimum, shape (k, n) -> (k,) of int64."""
    x = np.asarray(x)
    best = x[:, 0].copy()
    idx = np.zeros(x.shape[0], dtype=np.int64)
    for j in range(1, x.shape[1]):
        col = x[:, j]
        better = col < best
        idx[better] = j
        np.minimum(best, col, out=best)
    return idx


def row_any(x: np.ndarray) -> np.ndarray:
    """``x.any(axis=1)`` of a 2-D boolean array, shape (k, n) -> (k,) (False for n = 0)."""
    x = np.asarray(x, dtype=bool)
    out = np.zeros(x.shape[0], dtype=bool)
    for j in range(x.shape[1]):
        out |= x[:, j]
    return out


def rows_where(mask: np.ndarray):
    """Index of the rows where ``mask`` holds, for gathering only those: a full slice
    when it holds everywhere and None when nowhere (no gathering copies then).

    Parameters
    ----------
    mask : numpy.ndarray of bool, shape (k,)

    Returns
    -------
    slice, numpy.ndarray of int or None
    """
    if mask.all():
        return slice(None)
    return np.flatnonzero(mask) if mask.any() else None


def concat_ranges(starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Concatenation of ``arange(a, b)`` for all pairs ``(a, b)``, vectorised.

    Parameters
    ----------
    starts, ends : numpy.ndarray of int, shape (k,)
        ``ends >= starts``.

    Returns
    -------
    numpy.ndarray of int, shape (sum(ends - starts),)
    """
    n = ends - starts
    off = np.repeat(starts - np.concatenate(([0], np.cumsum(n)[:-1])), n)
    return np.arange(n.sum()) + off
