"""Rebuild a :class:`~reference.core.geometry.Path` whose segments were replaced, inserted
or dropped, keeping every block's span and every stop.

The stages that change geometry before the velocity planners (tool radius compensation,
tangential control) describe their output as new packed segment rows in path order, each
owned by one old segment: the rows that replace old segment ``j`` (an offset line, a
trimmed arc) and the rows inserted in front of it (a G450 transition circle, a TLIFT
block, both belonging to the block of ``j``). :func:`splice` then moves the block spans
and the stop flags: old break ``k`` (``k = 0..m``) becomes the break in front of the
first row owned by old segment ``k``, so a stop at the start of a block stays in front
of everything that block now holds, and a block without motion stays where it was.
"""

from __future__ import annotations

import numpy as np

from .core.geometry import Path

#: The packed row arrays of a path (keys of :func:`reference.core.geometry.line_segments`).
ROW_KEYS = ("origin", "e1", "e2", "d", "radius", "omega", "theta0", "length", "block",
            "kind", "dradius")


def copy_rows(path: Path, rows: np.ndarray) -> dict[str, np.ndarray]:
    """Packed arrays of the given rows of ``path`` (copies)."""
    return {k: np.array(getattr(path, k)[rows]) for k in ROW_KEYS}


def splice(path: Path, packed: dict[str, np.ndarray], owner: np.ndarray,
           feed: np.ndarray, rapid: np.ndarray, *,
           inner_stops: dict[int, str] | None = None,
           break_stops: dict[int, str] | None = None) -> Path:
    """The path with its segments replaced by ``packed``.

    Parameters
    ----------
    path : Path
        The path before the stage (``m`` segments).
    packed : dict of numpy.ndarray
        The new rows (``M`` of them, keys :data:`ROW_KEYS`), in path order.
    owner : numpy.ndarray of int, shape (M,)
        Old segment each new row belongs to; non-decreasing. An old segment that owns
        no row is dropped (its breaks merge).
    feed, rapid : numpy.ndarray, shape (M,)
        Path-speed cap (mm/s) and G0 flag of each new row.
    inner_stops : dict, optional
        ``{new row r: reason}``: the motion rests at the break in front of row ``r``.
    break_stops : dict, optional
        ``{old break k: reason}``: a rest added at old break ``k`` where it had none.

    Returns
    -------
    Path
        With the same block table (spans moved), ``rounding`` kept.
    """
    m = path.n_segments
    owner = np.asarray(owner, dtype=np.int64)
    total = owner.size
    if total and np.any(np.diff(owner) < 0):
        raise ValueError("splice: rows must be in path order (owner non-decreasing)")
    # first[k]: new index of the first row owned by old segment k (k = m: the end)
    first = np.searchsorted(owner, np.arange(m + 1), side="left")
    reasons = [""] * (total + 1)
    old = list(path.stop_reason)
    for k, why in (break_stops or {}).items():
        old[k] = old[k] or why
    for k in range(m + 1):
        if old[k] and not reasons[int(first[k])]:
            reasons[int(first[k])] = old[k]
    for r, why in (inner_stops or {}).items():
        reasons[r] = reasons[r] or why
    reasons[0] = reasons[0] or "start"
    reasons[total] = reasons[total] or "end"
    length = np.asarray(packed["length"], dtype=np.float64)
    sb = np.concatenate(([0.0], np.cumsum(length)))
    spans = path.blocks
    f = first[spans.first_segment]
    e = first[spans.first_segment + spans.n_segments]
    spans = spans.moved(sb[f], sb[e], f, e - f)
    return Path(axes=path.axes, geometry=path.geometry, rotary=path.rotary,
                feed=np.asarray(feed, dtype=np.float64), rapid=np.asarray(rapid, bool),
                stop=np.array([bool(r) for r in reasons]), stop_reason=tuple(reasons),
                blocks=spans, source=path.source, rounding=path.rounding,
                **{k: packed[k] for k in ROW_KEYS})


__all__ = ["ROW_KEYS", "copy_rows", "splice"]
