"""Inserted blocks on their own comparison rows.

The corner-rounding stage (:mod:`reference.rounding`) attributes each rounding to the
program block whose end is its corner, so every program
block keeps exactly one :class:`~reference.core.geometry.BlockSpan` and both planners'
per-block numbers stay keyed by program block. For people, the comparison shows an
inserted segment on a row of its own, named by its corner: this module finds those
segments and measures a profile on any stretch of the path exactly (the same knots and
stationary points :func:`reference.core.rows.block_motion` uses), so the corner block's
row and its inserted rows split the block's time without loss.
"""

from __future__ import annotations

import numpy as np

from reference.core.geometry import KIND_CODES, Path
from reference.core.profile import Profile
from reference.core.rows import BlockMotion

from .result import INSERTED_KINDS

#: Inserted segments shown on rows of their own: corner roundings (issue 13). The
#: segments tool radius compensation and tangential control insert (``trc``, ``tlift``)
#: stay in the row of the block they belong to, as those stages define.
_ROW_KINDS = ("rounding",)
_INSERTED_CODES = np.array([KIND_CODES.index(k) for k in _ROW_KINDS], dtype=np.int8)


def inserted_pieces(path: Path) -> dict[int, np.ndarray]:
    """Inserted blocks inside program-block spans: runs of consecutive inserted segments
    (a clothoid pair's two pieces are one rounding, one row).

    Returns
    -------
    dict
        Span index (into ``path.blocks``) -> ``(first, last)`` segment of each run,
        shape (r, 2), ascending; spans that are themselves of an inserted kind are not
        split.
    """
    segs = np.flatnonzero(np.isin(path.kind, _INSERTED_CODES))
    if segs.size == 0:
        return {}
    first, nseg = path.blocks.first_segment, path.blocks.n_segments
    # the span holding each segment: the last span starting at or before it with segments
    has = np.flatnonzero(nseg > 0)
    owner = has[np.searchsorted(first[has], segs, side="right") - 1]
    out: dict[int, list[int]] = {}
    for i, k in zip(owner.tolist(), segs.tolist()):
        if path.blocks.kind[i] not in INSERTED_KINDS:
            out.setdefault(i, []).append(k)
    runs = {}
    for i, v in out.items():
        ks = np.array(v, dtype=np.int64)
        cut = np.flatnonzero(np.diff(ks) != 1) + 1
        starts = np.concatenate(([0], cut))
        ends = np.concatenate((cut, [ks.size])) - 1
        runs[i] = np.column_stack((ks[starts], ks[ends]))
    return runs


def stretch_motion(profile: Profile, s0: np.ndarray, s1: np.ndarray) -> BlockMotion:
    """Time, entry, exit and peak speed of a profile on disjoint path stretches.

    Parameters
    ----------
    profile : Profile
    s0, s1 : numpy.ndarray, shape (p,)
        Stretch ends, mm, ascending and disjoint (``s0 < s1``).

    Returns
    -------
    BlockMotion
        Time from leaving ``s0`` to arriving at ``s1`` (a hold at either end is not in
        it: inserted segments never carry a stop), the speeds there, and the largest
        speed in between (knots and the stationary points of the cubic pieces).
    """
    s0 = np.asarray(s0, dtype=np.float64)
    s1 = np.asarray(s1, dtype=np.float64)
    t0 = profile.time_at(s0, which="last")
    t1 = profile.time_at(s1, which="first")
    v0 = profile.state(t0)[1]
    v1 = profile.state(t1)[1]
    prof = profile.split_at(np.concatenate((s0, s1)))
    h = np.diff(prof.t)
    with np.errstate(divide="ignore", invalid="ignore"):
        ts = np.where(prof.j != 0, -prof.a / np.where(prof.j != 0, prof.j, 1.0), -1.0)
    inside = (ts > 0) & (ts < h)
    ts = np.where(inside, ts, 0.0)
    v_in = np.where(inside, prof.v[:-1] + prof.a * ts + prof.j * ts ** 2 / 2, 0.0)
    v_int = np.maximum(np.maximum(prof.v[:-1], prof.v[1:]), v_in)
    mid = 0.5 * (prof.s[:-1] + prof.s[1:])
    piece = np.searchsorted(s0, mid, side="right") - 1
    ok = (piece >= 0) & (prof.s[1:] > prof.s[:-1])
    ok[ok] &= mid[ok] < s1[piece[ok]]
    peak = np.maximum(v0, v1)
    np.maximum.at(peak, piece[ok], v_int[ok])
    return BlockMotion(time_s=t1 - t0, v_entry=v0, v_exit=v1, v_peak=peak)


__all__ = ["inserted_pieces", "stretch_motion"]
