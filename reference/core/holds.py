"""Imposed holds: waits at rest that the program or the machine impose, not the planner.

A *hold* is an interval during which the path position does not change and the path
speed is 0: a dwell (G4) or the exact-stop settle (G601/G602, the following error
decaying into the stop window before the next block may start). No velocity profile
can avoid or shorten them, so every side of a comparison (the heuristic, the oracle,
a recorded trajectory's reference) carries the *same* holds at the *same* breaks, and
the comparison counts them under their own cause, never as a planning gap.

The durations are computed once, by :func:`reference.holds.imposed_holds` (program +
path + machine data); this module holds the data type and the one function that puts
the holds into a motion profile, :func:`with_holds`, used by the heuristic and the
oracle alike. It imports only numpy (``reference.core`` rule), so the oracle can use it.

Units: s, mm.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .arrays import readonly
from .causes import HOLD_CAUSES
from .errors import ProfileError
from .profile import Profile
from .tolerances import POS_TOL_MM, VEL_TOL_MM_S

#: Cause words of the holds (of the shared vocabulary, :mod:`reference.core.causes`).
DWELL_CAUSE, SETTLE_CAUSE = HOLD_CAUSES




@dataclass(frozen=True, slots=True, eq=False)
class Holds:
    """The imposed holds of a program on its path, in the order they happen.

    Attributes
    ----------
    break_index : numpy.ndarray of int, shape (h,)
        Path break ``k`` (``0..m``) where the motion rests during the hold.
        Non-decreasing; holds at one break run in array order (the settle of the block
        arriving there first, then the dwell blocks in program order).
    block : numpy.ndarray of int, shape (h,)
        NC block the hold belongs to (the exact-stop block, the dwell block).
    duration_s : numpy.ndarray, shape (h,)
        Hold time, s, > 0 (zero holds are not listed).
    cause : tuple[str, ...]
        Length ``h``: :data:`DWELL_CAUSE` or :data:`SETTLE_CAUSE`.
    """

    break_index: np.ndarray
    block: np.ndarray
    duration_s: np.ndarray
    cause: tuple[str, ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "break_index", readonly(self.break_index, np.int64))
        object.__setattr__(self, "block", readonly(self.block, np.int64))
        object.__setattr__(self, "duration_s", readonly(self.duration_s, np.float64))
        object.__setattr__(self, "cause", tuple(self.cause))
        h = self.duration_s.size
        if not (self.break_index.shape == self.block.shape == (h,) and len(self.cause) == h):
            raise ValueError("holds: break_index, block, duration_s and cause must have "
                             "one entry per hold")
        if h and (np.any(np.diff(self.break_index) < 0)
                  or not np.all(np.isfinite(self.duration_s))
                  or np.any(self.duration_s <= 0)):
            raise ValueError("holds: breaks must be non-decreasing and durations finite "
                             "and > 0")
        bad = sorted(set(self.cause) - set(HOLD_CAUSES))
        if bad:
            raise ValueError(f"holds: unknown cause {bad[0]!r}; known: {HOLD_CAUSES}")

    @property
    def n(self) -> int:
        """Number of holds ``h``."""
        return int(self.duration_s.size)

    @property
    def total_s(self) -> float:
        """Sum of all hold times, s."""
        return float(self.duration_s.sum())

    def per_block(self, n_blocks: int) -> np.ndarray:
        """Hold time of every block, shape ``(n_blocks,)`` indexed by block index, s."""
        return np.bincount(self.block, weights=self.duration_s, minlength=n_blocks)

    def cause_of(self, block: int) -> str:
        """The cause of a block's (longest) hold, ``""`` if the block has none."""
        sel = np.flatnonzero(self.block == block)
        if sel.size == 0:
            return ""
        return self.cause[int(sel[np.argmax(self.duration_s[sel])])]

    def causes_by_block(self) -> dict[int, str]:
        """``{block: cause of its longest hold}`` for every block with a hold (one pass,
        the same choice as :meth:`cause_of`: the first of equally long holds)."""
        out: dict[int, tuple[float, str]] = {}
        for b, d, c in zip(self.block.tolist(), self.duration_s.tolist(), self.cause):
            if b not in out or d > out[b][0]:
                out[b] = (d, c)
        return {b: c for b, (_, c) in out.items()}

    def subset(self, keep: np.ndarray) -> "Holds":
        """The holds where ``keep`` (bool, shape ``(h,)``) is True, in the same order."""
        keep = np.asarray(keep, dtype=bool)
        return Holds(break_index=self.break_index[keep], block=self.block[keep],
                     duration_s=self.duration_s[keep],
                     cause=tuple(c for c, k in zip(self.cause, keep) if k))

    def same_as(self, other: "Holds") -> bool:
        """True when both list the same holds (breaks, blocks, causes, bitwise times)."""
        return (self.cause == other.cause
                and np.array_equal(self.break_index, other.break_index)
                and np.array_equal(self.block, other.block)
                and np.array_equal(self.duration_s, other.duration_s))


#: No holds.
NO_HOLDS = Holds(break_index=np.zeros(0), block=np.zeros(0), duration_s=np.zeros(0),
                 cause=())


def dwell_holds(path) -> Holds:
    """The dwell (G4) holds a path carries in its block table (no machine data needed).

    Parameters
    ----------
    path : reference.core.geometry.Path

    Returns
    -------
    Holds
        One :data:`DWELL_CAUSE` hold per block with ``dwell_s > 0``, at the break where the
        block sits, in program order.
    """
    spans = path.blocks
    sel = np.flatnonzero(spans.dwell_s > 0)
    if not sel.size:
        return NO_HOLDS
    k, b, d = spans.first_segment[sel], spans.block[sel], spans.dwell_s[sel]
    order = np.argsort(k, kind="stable")
    return Holds(break_index=k[order], block=b[order], duration_s=d[order],
                 cause=(DWELL_CAUSE,) * sel.size)


def with_holds(profile: Profile, path, holds: Holds) -> Profile:
    """Insert the holds into a motion profile at their breaks.

    Each hold becomes one interval with ``s`` constant, ``v = a = j = 0``, labelled with
    its block, placed right after the knot where the profile arrives at the break (all
    holds at one break in the order of ``holds``); every later knot is shifted by the
    hold times before it. The heuristic and the oracle both build their profiles this
    way, so their holds are identical interval by interval.

    Parameters
    ----------
    profile : Profile
        Motion without the holds; at rest (``v <= VEL_TOL_MM_S``) at every hold break.
    path : reference.core.geometry.Path
        The path (for the break positions).
    holds : Holds

    Returns
    -------
    Profile

    Raises
    ------
    ProfileError
        The profile does not rest at a hold's break (a planner bug: holds sit at stops).
    """
    if holds.n == 0:
        return profile
    pos = path.s_breaks[holds.break_index]
    n_knots = profile.s.size
    # arrival knot: the first knot at rest at the break (knots of the final approach
    # may lie within POS_TOL_MM of it while still moving)
    rest = profile.v <= VEL_TOL_MM_S
    nxt = np.minimum.accumulate(np.where(rest, np.arange(n_knots), n_knots)[::-1])[::-1]
    i0 = np.clip(np.searchsorted(profile.s, pos - POS_TOL_MM, side="left"), 0, n_knots - 1)
    i = nxt[i0]
    ok = i < n_knots
    ok[ok] = np.abs(profile.s[i[ok]] - pos[ok]) <= POS_TOL_MM
    if not np.all(ok):
        bad = int(np.flatnonzero(~ok)[0])
        raise ProfileError(f"hold of block {int(holds.block[bad])} at s = {pos[bad]:.6g} mm: "
                           "the profile does not rest there")
    d = holds.duration_s
    # holds are sorted by break, hence by arrival knot: hold n ends at t[i_n] plus every
    # hold up to and including n; an original knot j moves by the holds with i_n < j
    cum = np.cumsum(d)
    add = np.zeros(n_knots + 1)
    np.add.at(add, i + 1, d)
    shift = np.cumsum(add)[:n_knots]
    v = profile.v.copy()
    v[i] = 0.0
    t = np.insert(profile.t + shift, i + 1, profile.t[i] + cum)
    s = np.insert(profile.s, i + 1, profile.s[i])
    v = np.insert(v, i + 1, 0.0)
    a = np.insert(profile.a, i, 0.0)
    j = np.insert(profile.j, i, 0.0)
    blk = np.insert(profile.block, i, holds.block)
    return Profile(t=t, s=s, v=v, a=a, j=j, block=blk)


def without_holds(profile: Profile, path, holds: Holds) -> Profile:
    """The motion of a profile built by :func:`with_holds`, its holds taken out.

    Each hold is the interval :func:`with_holds` put right after the knot where the
    motion arrives at the hold's break: ``s`` constant, ``v = a = j = 0``, the hold's
    block and duration. That interval is removed and every later knot moved back by its
    duration, so ``without_holds(with_holds(p, path, h), path, h)`` is ``p`` (times to
    round-off of the sums).

    Parameters
    ----------
    profile : Profile
        A motion with ``holds`` in it (the oracle's reported profile).
    path : reference.core.geometry.Path
    holds : Holds

    Returns
    -------
    Profile

    Raises
    ------
    ProfileError
        A hold is not found where :func:`with_holds` puts it.
    """
    if holds.n == 0:
        return profile
    pos = path.s_breaks[holds.break_index]
    h = np.diff(profile.t)
    still = ((np.abs(np.diff(profile.s)) == 0.0) & (profile.v[:-1] == 0.0)
             & (profile.v[1:] == 0.0) & (profile.a == 0.0) & (profile.j == 0.0))
    drop = np.zeros(profile.n_intervals, bool)
    start = 0
    for n in range(holds.n):
        # the first interval at rest at the break with the hold's block and duration,
        # after the previous hold's (holds at one break run in array order)
        cand = np.flatnonzero(still[start:] & ~drop[start:]
                              & (profile.block[start:] == holds.block[n])
                              & (np.abs(profile.s[start:-1] - pos[n]) <= POS_TOL_MM)
                              & np.isclose(h[start:], holds.duration_s[n], rtol=1e-12,
                                           atol=0.0))
        if cand.size == 0:
            raise ProfileError(f"hold of block {int(holds.block[n])} at s = {pos[n]:.6g} mm: "
                               "not in the profile")
        k = start + int(cand[0])
        drop[k] = True
        start = k + 1
    keep_knot = np.ones(profile.s.size, bool)
    keep_knot[np.flatnonzero(drop) + 1] = False
    shift = np.concatenate(([0.0], np.cumsum(np.where(drop, h, 0.0))))
    return Profile(t=(profile.t - shift)[keep_knot], s=profile.s[keep_knot],
                   v=profile.v[keep_knot], a=profile.a[~drop], j=profile.j[~drop],
                   block=profile.block[~drop])


__all__ = ["DWELL_CAUSE", "SETTLE_CAUSE", "HOLD_CAUSES", "Holds", "NO_HOLDS", "dwell_holds",
           "with_holds", "without_holds"]
