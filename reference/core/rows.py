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

from .geometry import Path
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
    h = np.diff(prof.t)
    with np.errstate(divide="ignore", invalid="ignore"):
        ts = np.where(prof.j != 0, -prof.a / np.where(prof.j != 0, prof.j, 1.0), -1.0)
    inside = (ts > 0) & (ts < h)
    ts = np.where(inside, ts, 0.0)
    v_in = np.where(inside, prof.v[:-1] + prof.a * ts + prof.j * ts ** 2 / 2, 0.0)
    v_int = np.maximum(np.maximum(prof.v[:-1], prof.v[1:]), v_in) if K else np.zeros(0)
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
