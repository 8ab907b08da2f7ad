"""Piece-aware grids on a path: every segment break is a node, arcs get enough nodes.

A :class:`Grid` has nodes ``s_0 < s_1 < ... < s_N`` and assigns every interval
``[s_k, s_{k+1}]`` to exactly one segment. Segment breaks are nodes, so an interval never
straddles a break: the geometry on each interval is that of one piece, and the node at a
break carries the constraints of both sides (the "double node" of the formulation note,
without an artificial epsilon: ``b`` is continuous, only the geometry jumps).

Units: mm. Shapes: ``N`` intervals, ``N + 1`` nodes, ``m`` segments.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.core.arrays import readonly
from reference.core.geometry import Path

from .tolerances import (DEFAULT_INITIAL_INTERVALS, MAX_ARC_STEP_RAD, MIN_ARC_INTERVALS,
                         MIN_SEGMENT_INTERVALS)

#: Intervals shorter than this fraction of their segment are never split again: a
#: guard against splitting down to float64 resolution (1e-12 of a segment).
_MIN_SPLIT_REL = 1e-12




@dataclass(frozen=True, slots=True, eq=False)
class Grid:
    """Nodes on a path and the segment of every interval.

    Attributes
    ----------
    s : numpy.ndarray, shape (N + 1,)
        Strictly increasing nodes, mm; ``s[0] = 0``, ``s[-1]`` = path length.
    segment : numpy.ndarray of int, shape (N,)
        Segment of each interval.
    break_node : numpy.ndarray of int, shape (m + 1,)
        Node index of every segment break (``path.s_breaks``).
    """

    s: np.ndarray
    segment: np.ndarray
    break_node: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "s", readonly(self.s, np.float64))
        object.__setattr__(self, "segment", readonly(self.segment, np.int64))
        object.__setattr__(self, "break_node", readonly(self.break_node, np.int64))

    @property
    def n_intervals(self) -> int:
        """Number of intervals ``N``."""
        return int(self.segment.size)

    @property
    def n_points(self) -> int:
        """Number of nodes ``N + 1``."""
        return int(self.s.size)


def _counts(path: Path, n_target: int, min_arc: int, arc_step: float,
            lines_by_length: bool = True) -> np.ndarray:
    length = path.length
    h0 = path.total_length / max(n_target, 1)
    n = np.maximum(MIN_SEGMENT_INTERVALS, np.ceil(length / h0 * (1 - 1e-12))).astype(np.int64)
    arc = path.radius > 0
    sweep = np.abs(path.omega) * length
    n_arc = np.maximum(min_arc, np.ceil(sweep / arc_step)).astype(np.int64)
    line = n if lines_by_length else np.full_like(n, MIN_SEGMENT_INTERVALS)
    return np.where(arc, np.maximum(n, n_arc), line)


def initial_counts(path: Path, n_intervals: int = DEFAULT_INITIAL_INTERVALS, *,
                   lines_by_length: bool = True) -> np.ndarray:
    """Intervals per segment of :func:`initial_grid` (default settings, the same
    ``lines_by_length``), without building it: the size of a first grid, known before
    anything is allocated. The default (lines spread by length) is the base of the jerk
    NLP's grid and at least the ``acc`` oracle's first grid (``lines_by_length=False``),
    so a size budget on it holds for both.

    Returns
    -------
    numpy.ndarray of float, shape (m,)
        Float, so that a hostile path (10^6 turns) cannot overflow.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        length = path.length
        h0 = path.total_length / max(n_intervals, 1)
        n = np.maximum(MIN_SEGMENT_INTERVALS, np.ceil(length / h0 * (1 - 1e-12)))
        sweep = np.abs(path.omega) * length
        n_arc = np.maximum(MIN_ARC_INTERVALS, np.ceil(sweep / MAX_ARC_STEP_RAD))
        line = n if lines_by_length else np.full_like(n, MIN_SEGMENT_INTERVALS)
        return np.where(path.radius > 0, np.maximum(n, n_arc), line).astype(np.float64)


def grid_from_counts(path: Path, counts: np.ndarray) -> Grid:
    """Grid with ``counts[i]`` equal intervals on segment ``i``.

    Parameters
    ----------
    path : Path
        The path.
    counts : numpy.ndarray of int, shape (m,)
        Intervals per segment (>= 1).

    Returns
    -------
    Grid
    """
    counts = np.asarray(counts, dtype=np.int64)
    seg = np.repeat(np.arange(path.n_segments), counts)
    first = np.concatenate(([0], np.cumsum(counts)[:-1]))
    j = np.arange(seg.size) - first[seg]
    s = path.s_breaks[seg] + path.length[seg] * (j / counts[seg])
    s = np.concatenate((s, [path.total_length]))
    break_node = np.concatenate((first, [seg.size]))
    return Grid(s=s, segment=seg, break_node=break_node)


def initial_grid(path: Path, n_intervals: int = DEFAULT_INITIAL_INTERVALS, *,
                 min_arc_intervals: int = MIN_ARC_INTERVALS,
                 max_arc_step_rad: float = MAX_ARC_STEP_RAD,
                 lines_by_length: bool = True) -> Grid:
    """Piece-aware starting grid.

    Each segment gets ``max(2, ceil(length / h))`` equal intervals with
    ``h = total_length / n_intervals``; arcs and helices at least ``min_arc_intervals`` and
    at most ``max_arc_step_rad`` of sweep per interval. With ``lines_by_length=False``
    straight segments get :data:`MIN_SEGMENT_INTERVALS` only (the ``acc`` oracle: both of
    its bounds are exact on a line interval of any length, see
    :mod:`optimal.upper` and :mod:`optimal.bounds`, so length-spread nodes there only
    cost; where a line still carries part of the bracket, refinement splits it).

    Parameters
    ----------
    path : Path
        A path with at least one segment.
    n_intervals : int
        Target number of intervals spread by length (the result has at least this many
        minus rounding, more when segments are short or arcs need more).
    min_arc_intervals : int
        Fewest intervals per arc.
    max_arc_step_rad : float
        Largest sweep per arc interval, rad.
    lines_by_length : bool
        Spread nodes over straight segments by length too (default), or give them the
        fewest intervals.

    Returns
    -------
    Grid
    """
    return grid_from_counts(path, _counts(path, n_intervals, min_arc_intervals,
                                          max_arc_step_rad, lines_by_length))


def split(grid: Grid, path: Path, mark: np.ndarray) -> Grid:
    """Halve the marked intervals.

    Parameters
    ----------
    grid : Grid
        Current grid.
    path : Path
        Its path (for the guard against splitting to round-off).
    mark : numpy.ndarray of bool, shape (N,)
        Intervals to split at their mid-point.

    Returns
    -------
    Grid
        The refined grid (the same object when nothing can be split).
    """
    ds = np.diff(grid.s)
    ok = np.asarray(mark, bool) & (ds > _MIN_SPLIT_REL * path.length[grid.segment])
    idx = np.flatnonzero(ok)
    if idx.size == 0:
        return grid
    mid = 0.5 * (grid.s[idx] + grid.s[idx + 1])
    s = np.insert(grid.s, idx + 1, mid)
    seg = np.insert(grid.segment, idx + 1, grid.segment[idx])
    break_node = np.searchsorted(s, path.s_breaks)
    return Grid(s=s, segment=seg, break_node=break_node)


def subdivide(grid: Grid, path: Path, mark: np.ndarray, pieces=2) -> Grid:
    """Split the marked intervals into ``pieces`` equal parts (a power of two).

    Parameters
    ----------
    grid : Grid
        Current grid.
    path : Path
        Its path.
    mark : numpy.ndarray of bool, shape (N,)
        Intervals to split.
    pieces : int or numpy.ndarray of int, shape (N,)
        2, 4, 8, ... for every marked interval, or one such number per interval.

    Returns
    -------
    Grid
        The refined grid (the same object when nothing can be split).
    """
    p = np.broadcast_to(np.asarray(pieces, dtype=np.int64), (grid.n_intervals,))
    marks = np.asarray(mark, bool)
    p = np.where(marks, p, 1)
    if np.any(p[marks] < 2) or np.any(p & (p - 1)):
        raise ValueError(f"pieces = {pieces}: must be a power of two >= 2")
    out = grid
    rem = p
    while np.any(rem > 1):
        cut = rem > 1
        new = split(out, path, cut)
        if new is out:
            break
        # the halves of a cut interval carry on with half of its pieces
        mid = 0.5 * (new.s[:-1] + new.s[1:])
        parent = np.clip(np.searchsorted(out.s, mid) - 1, 0, out.n_intervals - 1)
        rem = np.where(cut, rem // 2, rem)[parent]
        out = new
    return out



def grid_on(path: Path, s: np.ndarray) -> Grid:
    """The :class:`Grid` with nodes ``s`` (which contain every segment break): an
    oracle's final grid, kept as an array of nodes, back as a grid.

    Parameters
    ----------
    path : Path
    s : numpy.ndarray, shape (N + 1,)
        Strictly increasing nodes from 0 to the path length, mm.

    Returns
    -------
    Grid
    """
    s = np.asarray(s, dtype=np.float64)
    seg = path.segment_index(0.5 * (s[:-1] + s[1:]))
    return Grid(s=s, segment=seg, break_node=np.searchsorted(s, path.s_breaks))


def with_nodes(s: np.ndarray, new: np.ndarray, min_gap: float) -> np.ndarray:
    """Nodes ``s`` with the positions ``new`` added where each keeps at least ``min_gap``
    from every other node: inside ``(s[0], s[-1])``, the first of new ones closer than
    that to each other, none that close to a node of ``s`` (no vanishing intervals).

    Parameters
    ----------
    s : numpy.ndarray, shape (N + 1,)
        Strictly increasing nodes, mm.
    new : numpy.ndarray, shape (M,)
        Positions to add, mm (any order).
    min_gap : float
        mm (> 0).

    Returns
    -------
    numpy.ndarray, shape (N + 1 + K,)
        Sorted, strictly increasing, mm.
    """
    s = np.asarray(s, dtype=np.float64)
    new = np.asarray(new, dtype=np.float64)
    new = np.unique(new[(new > s[0] + min_gap) & (new < s[-1] - min_gap)])
    if new.size == 0:
        return s
    new = new[np.concatenate(([True], np.diff(new) > min_gap))]
    i = np.searchsorted(s, new)
    near = np.minimum(np.abs(new - s[np.maximum(i - 1, 0)]),
                      np.abs(s[np.minimum(i, s.size - 1)] - new))
    return np.union1d(s, new[near > min_gap])
