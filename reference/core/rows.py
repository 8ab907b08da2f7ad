"""The one per-block row model: what a planner did in each NC block of a path.

Every side that reports per-block numbers (the heuristic, the oracle, a recorded
trajectory) reports a :class:`BlockRow` per entry of ``path.blocks``; the comparison
pairs two of them. :func:`block_motion` measures the numbers of any profile on its path
the same way for every side (times, entry, exit and peak speeds).

Units: mm, s, mm/s.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from .geometry import KIND_CODES, Path
from .profile import Profile


@dataclass(frozen=True, slots=True)
class BlockRow:
    """One side's numbers for one NC block (or inserted block) of a path.

    Attributes
    ----------
    block : int
        Block index in the program (``BlockSpan.block``).
    line : int
        1-based source line.
    label : str
        Block number or label as written, ``""`` if none.
    kind : str
        ``"G0"``, ``"G1"``, ``"G2"``, ``"G3"``, ``"none"`` or an inserted kind.
    length_mm : float
        Path length of the block, mm.
    time_s : float
        Time spent in the block, s (its imposed hold included, see ``hold_s``).
    v_entry, v_exit, v_peak : float
        Path speed on leaving the block start, on arriving at its end, and the largest
        in between, mm/s (``nan`` where the side has no motion to measure).
    cause : str
        Limiting cause (a word of :data:`reference.core.causes.CAUSES`, ``"none"`` or
        ``"-"``); the oracle reports its active constraint label (``"acceleration X"``),
        which :func:`reference.core.causes.normalise_cause` maps to a word.
    hold_s : float
        Imposed hold (dwell, exact-stop settle) contained in ``time_s``, s.
    """

    block: int
    line: int
    label: str
    kind: str
    length_mm: float
    time_s: float
    v_entry: float
    v_exit: float
    v_peak: float
    cause: str
    hold_s: float = 0.0


@dataclass(frozen=True, slots=True, eq=False)
class BlockMotion:
    """Per-block numbers of one profile on its path, in ``path.blocks`` order.

    Attributes
    ----------
    time_s, v_entry, v_exit, v_peak : numpy.ndarray, shape (len(path.blocks),)
        As in :class:`BlockRow`.
    """

    time_s: np.ndarray
    v_entry: np.ndarray
    v_exit: np.ndarray
    v_peak: np.ndarray


def interval_peak_speeds(prof: Profile) -> np.ndarray:
    """Largest speed inside each interval of ``prof``: at its knots or where the
    acceleration crosses zero inside it (``v`` is quadratic in time), mm/s, shape (K,)."""
    h = np.diff(prof.t)
    with np.errstate(divide="ignore", invalid="ignore"):
        ts = np.where(prof.j != 0, -prof.a / np.where(prof.j != 0, prof.j, 1.0), -1.0)
    inside = (ts > 0) & (ts < h)
    ts = np.where(inside, ts, 0.0)
    v_in = np.where(inside, prof.v[:-1] + prof.a * ts + prof.j * ts ** 2 / 2, 0.0)
    return np.maximum(np.maximum(prof.v[:-1], prof.v[1:]), v_in)


def block_motion(path: Path, profile: Profile) -> BlockMotion:
    """Time, entry, exit and peak path speed of a profile in every block span.

    Parameters
    ----------
    path : Path
    profile : Profile
        The motion along ``path`` (holds included, if any).

    Returns
    -------
    BlockMotion
        Entry is the speed on leaving the block start (after any hold there), exit the
        speed on arriving at its end, peak the largest speed in between (knots and the
        stationary points of the cubic pieces).
    """
    spans = path.blocks
    if not spans:
        z = np.zeros(0)
        return BlockMotion(z, z, z, z)
    idx = spans.block
    time_s = profile.block_times(path)[idx]
    s0, s1 = spans.s_start, spans.s_end
    prof = profile.split_at(s1[s1 > s0])
    K = prof.n_intervals
    k_dep = np.clip(np.searchsorted(prof.s, s0, side="right") - 1, 0, prof.s.size - 1)
    k_arr = np.clip(np.searchsorted(prof.s, s1, side="left"), 0, prof.s.size - 1)
    v_entry, v_exit = prof.v[k_dep], prof.v[k_arr]
    # peak: knots and stationary points of v inside each interval, per block
    v_int = interval_peak_speeds(prof) if K else np.zeros(0)
    n_blocks = int(idx.max()) + 1
    peak = np.zeros(n_blocks)
    if K:
        np.maximum.at(peak, prof.interval_blocks(path), v_int)
    v_peak = np.maximum(peak[idx], np.maximum(v_entry, v_exit))
    return BlockMotion(time_s=time_s, v_entry=v_entry, v_exit=v_exit, v_peak=v_peak)


def block_rows(path: Path, motion: BlockMotion, causes: Sequence[str],
               hold_s: np.ndarray | None = None) -> tuple[BlockRow, ...]:
    """One :class:`BlockRow` per entry of ``path.blocks``.

    Parameters
    ----------
    path : Path
    motion : BlockMotion
        From :func:`block_motion` (or a planner's own exact numbers, same layout).
    causes : sequence of str, length len(path.blocks)
        Limiting cause of each block.
    hold_s : numpy.ndarray, shape (len(path.blocks),), optional
        Imposed hold in each block, s (default 0).

    Returns
    -------
    tuple[BlockRow, ...]
    """
    spans = path.blocks
    hold = np.zeros(len(spans)) if hold_s is None else np.asarray(hold_s, dtype=np.float64)
    return tuple(
        BlockRow(block=sp.block, line=max(1, sp.line), label=sp.label, kind=sp.kind,
                 length_mm=float(sp.length), time_s=float(motion.time_s[i]),
                 v_entry=float(motion.v_entry[i]), v_exit=float(motion.v_exit[i]),
                 v_peak=float(motion.v_peak[i]), cause=str(causes[i]),
                 hold_s=float(hold[i]))
        for i, sp in enumerate(spans))


# ------------------------------------------------------------------ inserted blocks
#: Kinds of spans and segments a path stage inserts (corner rounding, tool radius
#: compensation, tangential lift): a span of such a kind is never split into rows.
INSERTED_KINDS = ("rounding", "trc", "tlift")
#: Inserted segments shown on rows of their own: corner roundings (issue 13). The
#: segments tool radius compensation and tangential control insert (``trc``, ``tlift``)
#: stay in the row of the block they belong to, as those stages define.
_ROW_KINDS = ("rounding",)
_INSERTED_CODES = np.array([KIND_CODES.index(k) for k in _ROW_KINDS], dtype=np.int8)


def internal_rounding_segments(path: Path) -> np.ndarray:
    """Segments of roundings carried out inside the original blocks (G643, spec 5.5:
    "No separate rounding block is inserted"), bool, shape (m,): per such corner of
    ``path.rounding`` (``internal``), the last segment of the span of the block before
    it and the first of the span of the block after it (its two halves,
    :func:`reference.rounding._inside_the_blocks`). They are part of their blocks: no
    row and no interpolation block of their own."""
    out = np.zeros(path.n_segments, bool)
    table = path.rounding
    if table is None or not np.any(table.internal):
        return out
    spans = path.blocks
    i = np.flatnonzero(table.internal)
    # spans are in program order, one per block: the span index of a block
    before = np.searchsorted(spans.block, table.block[i])
    after = np.searchsorted(spans.block, table.next_block[i])
    out[spans.first_segment[before] + spans.n_segments[before] - 1] = True
    out[spans.first_segment[after]] = True
    return out


def interpolation_lengths(path: Path) -> np.ndarray:
    """Length of the interpolation block each segment belongs to, mm, shape (m,): its
    own length, except where a rounding is carried out inside the blocks (G643,
    :func:`internal_rounding_segments`): that block is its span's own segments with the
    halves of such roundings, less any rounding inserted as a block of its own. "Every
    block, the rounding block included, needs at least one interpolation point" (spec
    5.3): the one-IPO-cycle cap is this length over ``T_ipo``."""
    inner = internal_rounding_segments(path)
    if not inner.any():
        return path.length
    own_block = np.isin(path.kind, _INSERTED_CODES) & ~inner      # inserted as blocks
    same = path.block[:-1] == path.block[1:]
    join = same & (inner[:-1] | inner[1:]) & ~own_block[:-1] & ~own_block[1:]
    unit = np.concatenate(([0], np.cumsum(~join)))
    return np.bincount(unit, weights=path.length)[unit]


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
    # a rounding inside the blocks (G643) is part of them: no row of its own
    segs = np.flatnonzero(np.isin(path.kind, _INSERTED_CODES)
                          & ~internal_rounding_segments(path))
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


@dataclass(frozen=True, slots=True)
class InsertedSplit:
    """How one program block's span splits into its own stretch and its inserted blocks
    (:func:`inserted_splits`).

    Attributes
    ----------
    span : int
        Index into ``path.blocks``.
    runs : numpy.ndarray of int64, shape (r, 2)
        First and last segment of each inserted block (:func:`inserted_pieces`).
    corner_blocks : tuple of int or None
        Program blocks before and after the corner the insertion replaces (the rounding
        table's ``block``, ``next_block``), ``None`` without a rounding table entry.
    tail : bool
        One inserted block that ends the span: it ends the block's own stretch too.
    inserted_length : float
        Length of the inserted blocks, mm.
    """

    span: int
    runs: np.ndarray
    corner_blocks: tuple[int, int] | None
    tail: bool
    inserted_length: float


def inserted_splits(path: Path) -> list[InsertedSplit]:
    """Every span holding inserted blocks and how it splits, in span order: the one
    layout ``feedoracle plan``'s rows and the comparison's rows are both cut by.
    """
    found = inserted_pieces(path)
    if not found:
        return []
    spans, sb = path.blocks, path.s_breaks
    corner: dict[int, tuple[int, int]] = {}
    table = path.rounding
    if table is not None:
        for k in np.flatnonzero(table.inserted).tolist():
            corner[int(table.block[k])] = (int(table.block[k]), int(table.next_block[k]))
    out = []
    for i in sorted(found):
        ks = found[i]
        last = int(spans.first_segment[i] + spans.n_segments[i] - 1)
        out.append(InsertedSplit(
            span=i, runs=ks, corner_blocks=corner.get(int(spans.block[i])),
            tail=bool(ks.shape[0] == 1 and ks[-1, 1] == last),
            inserted_length=float(np.sum(sb[ks[:, 1] + 1] - sb[ks[:, 0]]))))
    return out


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
    v_int = interval_peak_speeds(prof)
    mid = 0.5 * (prof.s[:-1] + prof.s[1:])
    piece = np.searchsorted(s0, mid, side="right") - 1
    ok = (piece >= 0) & (prof.s[1:] > prof.s[:-1])
    ok[ok] &= mid[ok] < s1[piece[ok]]
    peak = np.maximum(v0, v1)
    np.maximum.at(peak, piece[ok], v_int[ok])
    return BlockMotion(time_s=t1 - t0, v_entry=v0, v_exit=v1, v_peak=peak)
