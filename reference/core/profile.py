"""Time-parameterised motion along a path: the one profile type of every planner.

A :class:`Profile` is piecewise cubic in time: on interval ``k`` (``t_k <= t <= t_{k+1}``)
the path position is

``s(t) = s_k + v_k tau + a_k tau^2 / 2 + j_k tau^3 / 6``,  ``tau = t - t_k``,

with constant jerk ``j_k``. Path velocity is continuous (``v`` lives on the knots);
acceleration may step at knots (BRISK profiles, curvature jumps). This represents
exactly the constant-acceleration profiles of the convex oracle (``b = v^2`` linear in
``s`` means ``s''`` constant), trapezoids, 7-phase S-curves, jerk-NLP solutions and
resampled recordings, so :func:`reference.core.constraints.check_profile` can judge
all of them analytically inside every interval.

Intervals with ``s_{k+1} = s_k`` are *holds* (dwell, exact-stop settling). Each interval
is attributed to one NC block (``block``) so that block times sum to the total.

Units: s, mm, mm/s, mm/s^2, mm/s^3. Shapes: ``K`` intervals, ``K + 1`` knots.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .arrays import readonly
from .errors import ProfileError
from .tolerances import POS_TOL_MM, VEL_TOL_MM_S

#: Intervals checked at a time by :class:`Profile` (bounds the checks' temporaries to a
#: few MB whatever the profile's length).
_CHECK_CHUNK = 1 << 16



@dataclass(frozen=True, slots=True, eq=False)
class Profile:
    """Path motion ``s(t)`` as a piecewise-constant-jerk spline.

    Attributes
    ----------
    t : numpy.ndarray, shape (K + 1,)
        Knot times, s, non-decreasing, ``t[0] = 0``.
    s : numpy.ndarray, shape (K + 1,)
        Path position at the knots, mm, non-decreasing.
    v : numpy.ndarray, shape (K + 1,)
        Path velocity at the knots, mm/s, >= 0.
    a : numpy.ndarray, shape (K,)
        Path acceleration at the *start* of each interval, mm/s^2.
    j : numpy.ndarray, shape (K,)
        Path jerk, constant inside each interval, mm/s^3.
    block : numpy.ndarray of int, shape (K,)
        NC block each interval belongs to; -1 = derive it from the path position.
    """

    t: np.ndarray
    s: np.ndarray
    v: np.ndarray
    a: np.ndarray
    j: np.ndarray
    block: np.ndarray

    def __post_init__(self) -> None:
        for name in ("t", "s", "v", "a", "j"):
            object.__setattr__(self, name, readonly(getattr(self, name), np.float64))
        object.__setattr__(self, "block", readonly(self.block, np.int64))
        K = self.a.size
        if self.t.shape != (K + 1,) or self.s.shape != (K + 1,) or self.v.shape != (K + 1,):
            raise ProfileError(f"knot arrays must have {K + 1} entries for {K} intervals "
                               f"(t {self.t.shape}, s {self.s.shape}, v {self.v.shape})")
        if self.j.shape != (K,) or self.block.shape != (K,):
            raise ProfileError("a, j and block need one entry per interval")
        for name in ("t", "s", "v", "a", "j"):
            arr = getattr(self, name)
            if not np.all(np.isfinite(arr)):
                k = int(np.flatnonzero(~np.isfinite(arr))[0])
                raise ProfileError(f"profile {name}[{k}] is not finite ({arr[k]})")
        # In chunks: a plan of 10^6 blocks has some 4e6 intervals, and the whole-array
        # formulas would hold half a dozen temporaries of 35 MB each at once.
        K1 = self.t.size
        for lo in range(0, max(K, 0), _CHECK_CHUNK):
            hi = min(K, lo + _CHECK_CHUNK)
            h = self.t[lo + 1:hi + 1] - self.t[lo:hi]
            if np.any(h < 0):
                k = lo + int(np.flatnonzero(h < 0)[0])
                raise ProfileError(f"time runs backwards at knot {k + 1}")
        if np.any(self.v < -VEL_TOL_MM_S):
            k = int(np.argmin(self.v))
            raise ProfileError(f"negative path velocity {self.v[k]:.6g} mm/s at knot {k}")
        if K1:
            scale = max(1.0, abs(float(self.s.max())), abs(float(self.s.min())))
            vscale = max(1.0, abs(float(self.v.max())), abs(float(self.v.min())))
        else:
            scale = vscale = 1.0
        ds_max, dv_max = (-1.0, -1), (-1.0, -1)      # (largest mismatch, its interval)
        for lo in range(0, K, _CHECK_CHUNK):
            hi = min(K, lo + _CHECK_CHUNK)
            s_end, v_end = self._integrate_end(self.t[lo + 1:hi + 1] - self.t[lo:hi], lo, hi)
            ds = np.abs(s_end - self.s[lo + 1:hi + 1])
            dv = np.abs(v_end - self.v[lo + 1:hi + 1])
            k, q = int(np.argmax(ds)), int(np.argmax(dv))
            if ds[k] > ds_max[0]:
                ds_max = (float(ds[k]), lo + k)
            if dv[q] > dv_max[0]:
                dv_max = (float(dv[q]), lo + q)
        if ds_max[0] > POS_TOL_MM * scale:
            k = ds_max[1]
            s_k = self._integrate_end(self.t[k + 1:k + 2] - self.t[k:k + 1], k, k + 1)[0][0]
            raise ProfileError(f"interval {k}: integrated position {s_k:.9g} mm does "
                               f"not meet the next knot {self.s[k + 1]:.9g} mm")
        if dv_max[0] > 1e-6 * vscale:
            k = dv_max[1]
            v_k = self._integrate_end(self.t[k + 1:k + 2] - self.t[k:k + 1], k, k + 1)[1][0]
            raise ProfileError(f"interval {k}: integrated velocity {v_k:.9g} mm/s does "
                               f"not meet the next knot {self.v[k + 1]:.9g} mm/s")

    def _integrate_end(self, h: np.ndarray, lo: int, hi: int
                       ) -> tuple[np.ndarray, np.ndarray]:
        """Position and velocity at the end of intervals ``lo:hi`` of durations ``h``."""
        s0, v0, a, j = self.s[lo:hi], self.v[lo:hi], self.a[lo:hi], self.j[lo:hi]
        s_end = s0 + v0 * h + a * h * h / 2 + j * h ** 3 / 6
        v_end = v0 + a * h + j * h * h / 2
        return s_end, v_end

    # ------------------------------------------------------------ constructors
    @classmethod
    def from_phases(cls, durations, a0, jerk, *, s0: float = 0.0, v0: float = 0.0,
                    block=None) -> "Profile":
        """Integrate phases of constant jerk exactly.

        Parameters
        ----------
        durations : array_like, shape (K,)
            Phase durations, s (>= 0).
        a0 : array_like, shape (K,)
            Acceleration at the start of each phase, mm/s^2.
        jerk : array_like, shape (K,)
            Jerk in each phase, mm/s^3.
        s0, v0 : float
            Initial position (mm) and velocity (mm/s).
        block : array_like of int, shape (K,), optional
            Block of each phase (-1 = unknown).

        Returns
        -------
        Profile
        """
        h = np.asarray(durations, dtype=np.float64)
        a = np.asarray(a0, dtype=np.float64)
        j = np.asarray(jerk, dtype=np.float64)
        dv = a * h + j * h * h / 2
        v = np.concatenate(([v0], v0 + np.cumsum(dv)))
        ds = v[:-1] * h + a * h * h / 2 + j * h ** 3 / 6
        s = np.concatenate(([s0], s0 + np.cumsum(ds)))
        t = np.concatenate(([0.0], np.cumsum(h)))
        # Clip round-off below zero velocity (a stop reached exactly by a ramp).
        v = np.where(np.abs(v) <= VEL_TOL_MM_S, np.maximum(v, 0.0), v)
        blk = np.full(h.size, -1) if block is None else np.asarray(block)
        return cls(t=t, s=s, v=v, a=a, j=j, block=blk)

    @classmethod
    def from_path_velocity(cls, s, v, block=None) -> "Profile":
        """Profile with ``v^2`` linear in ``s`` between nodes (constant acceleration).

        This is the exact continuous profile behind the discretised convex problem
        (``b = v^2`` piecewise linear in ``s``): ``a_k = (v_{k+1}^2 - v_k^2) / (2 ds_k)``
        and ``dt_k = 2 ds_k / (v_k + v_{k+1})``.

        Parameters
        ----------
        s : array_like, shape (N,)
            Increasing path nodes, mm (repeated nodes are dropped).
        v : array_like, shape (N,)
            Path velocity at the nodes, mm/s (>= 0).
        block : array_like of int, shape (N - 1,), optional
            Block of each interval.

        Returns
        -------
        Profile

        Raises
        ------
        ProfileError
            An interval of positive length with zero velocity at both ends.
        """
        s = np.asarray(s, dtype=np.float64)
        v = np.maximum(np.asarray(v, dtype=np.float64), 0.0)
        blk = np.full(s.size - 1, -1) if block is None else np.asarray(block)
        ds = np.diff(s)
        keep = ds > 0
        if not np.all(keep):
            node_keep = np.concatenate(([True], keep))
            s, v, blk, ds = s[node_keep], v[node_keep], blk[keep], ds[keep]
        vs = v[:-1] + v[1:]
        if np.any(vs <= 0):
            k = int(np.flatnonzero(vs <= 0)[0])
            raise ProfileError(f"path velocity is zero at both ends of [{s[k]:.6g}, "
                               f"{s[k + 1]:.6g}] mm: the motion never gets there")
        h = 2 * ds / vs
        a = (v[1:] - v[:-1]) / h      # = (v1^2 - v0^2) / (2 ds), better conditioned
        t = np.concatenate(([0.0], np.cumsum(h)))
        return cls(t=t, s=s, v=v, a=a, j=np.zeros(h.size), block=blk)

    # ------------------------------------------------------------ evaluation
    @property
    def duration(self) -> float:
        """Total time, s."""
        return float(self.t[-1] - self.t[0])

    @property
    def n_intervals(self) -> int:
        """Number of intervals ``K``."""
        return int(self.a.size)

    def state(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Exact ``s, v, a, j`` at times ``t`` (clamped to the profile's span).

        Parameters
        ----------
        t : array_like, shape (N,)
            Times, s.

        Returns
        -------
        s, v, a, j : numpy.ndarray, shape (N,)
            mm, mm/s, mm/s^2, mm/s^3.
        """
        t = np.clip(np.atleast_1d(np.asarray(t, dtype=np.float64)), self.t[0], self.t[-1])
        if self.n_intervals == 0:
            z = np.zeros_like(t)
            return z + self.s[0], z + self.v[0], z, z
        k = np.clip(np.searchsorted(self.t, t, side="right") - 1, 0, self.n_intervals - 1)
        tau = t - self.t[k]
        a0, j = self.a[k], self.j[k]
        s = self.s[k] + self.v[k] * tau + a0 * tau ** 2 / 2 + j * tau ** 3 / 6
        v = self.v[k] + a0 * tau + j * tau ** 2 / 2
        return s, v, a0 + j * tau, j

    def time_at(self, s_query, which: str = "first") -> np.ndarray:
        """Time at which the motion reaches path positions ``s_query``.

        Parameters
        ----------
        s_query : array_like, shape (N,)
            Path positions within ``[s[0], s[-1]]``, mm.
        which : {"first", "last"}
            At a hold, the time of arrival (``"first"``) or of departure (``"last"``).

        Returns
        -------
        numpy.ndarray, shape (N,)
            Times, s. Found by safeguarded Newton steps on the monotone cubic of the
            interval (a bisection step wherever Newton would leave the bracket), to
            round-off of the interval length.
        """
        q = np.atleast_1d(np.asarray(s_query, dtype=np.float64))
        if self.n_intervals == 0:
            return np.zeros_like(q)
        if which == "first":
            k = np.searchsorted(self.s, q, side="left") - 1
        else:
            k = np.searchsorted(self.s, q, side="right") - 1
        k = np.clip(k, 0, self.n_intervals - 1)
        h = self.t[k + 1] - self.t[k]
        s0, s1 = self.s[k], self.s[k + 1]
        # exact hits on knots
        at_start = q <= s0
        at_end = q >= s1
        tau = np.where(at_start, 0.0, h)
        act = np.flatnonzero(~at_start & ~at_end)
        if act.size:
            tau[act] = _cubic_time(q[act], h[act], s0[act], s1[act], self.v[k[act]],
                                   self.a[k[act]], self.j[k[act]])
        return self.t[k] + tau

    def sample(self, dt: float) -> tuple[np.ndarray, ...]:
        """Sample at a fixed period (the IPO cycle), ending exactly at the end.

        Parameters
        ----------
        dt : float
            Sampling period, s (> 0).

        Returns
        -------
        t, s, v, a, j : numpy.ndarray, shape (N,)
            Sample times and states.
        """
        if not dt > 0:
            raise ProfileError(f"sampling period must be > 0 s, got {dt}")
        n = int(np.floor(self.duration / dt + 1e-9))
        t = np.arange(n + 1) * dt + self.t[0]
        if t[-1] < self.t[-1] - 1e-12:
            t = np.append(t, self.t[-1])
        return (t, *self.state(t))

    # ------------------------------------------------------------ accounting
    def _cut_positions(self, s_cuts) -> np.ndarray:
        """The positions of ``s_cuts`` where :meth:`split_at` adds knots, sorted, unique."""
        cuts = np.unique(np.asarray(s_cuts, dtype=np.float64))
        cuts = cuts[(cuts > self.s[0]) & (cuts < self.s[-1])]
        # drop the cuts on a knot: the knots are non-decreasing, so the knot at or after
        # each cut is found by bisection (the same set as ``np.isin(cuts, self.s)``,
        # without sorting the knots again)
        at = np.minimum(np.searchsorted(self.s, cuts), self.s.size - 1)
        off = self.s[at] != cuts
        cuts, at = cuts[off], at[off]
        # and the cuts within POS_TOL_MM of a knot where the motion rests: it has
        # reached the cut there (a motion coming to rest approaches its stop as a cubic,
        # so a cut 1e-14 mm short of it is crossed some microseconds before the knot;
        # the sliver cut off then held the tail of the deceleration, and where pieces
        # of two motions were joined at that stop it became a phase of 5 us)
        near = np.zeros(cuts.size, bool)
        for k in (at - 1, at):
            kk = np.clip(k, 0, self.s.size - 1)
            near |= ((k >= 0) & (np.abs(self.s[kk] - cuts) <= POS_TOL_MM)
                     & (np.abs(self.v[kk]) <= VEL_TOL_MM_S))
        return cuts[~near]

    def _cut_times(self, cuts: np.ndarray) -> np.ndarray:
        """Knot times of :meth:`_cut_positions` ``cuts``, s."""
        if cuts.size == 0 or self.n_intervals == 0:
            return np.zeros(0)
        return self.time_at(cuts)

    def _ordered_cuts(self, cuts: np.ndarray, tc: np.ndarray):
        """``(k, tc, sc)`` of the cuts at positions ``cuts`` reached at times ``tc``, in
        time order (interval, time and position of each), or ``None`` without cuts."""
        if cuts.size == 0 or self.n_intervals == 0:
            return None
        k = np.clip(np.searchsorted(self.t, tc, side="right") - 1, 0, self.n_intervals - 1)
        order = np.argsort(tc, kind="stable")
        return k[order], tc[order], cuts[order]

    def _cuts(self, s_cuts):
        """Where :meth:`split_at` adds knots: ``(k, tc, sc)`` in time order (interval,
        time and position of each cut), or ``None`` when no cut falls inside an
        interval."""
        cuts = self._cut_positions(s_cuts)
        return self._ordered_cuts(cuts, self._cut_times(cuts))

    def split_at(self, s_cuts) -> "Profile":
        """Same motion with extra knots where it first crosses each ``s_cuts`` value.

        Parameters
        ----------
        s_cuts : array_like
            Path positions, mm; values on existing knots, within ``POS_TOL_MM`` of a
            knot where the motion rests (it reaches the cut there), or outside the span
            are ignored.

        Returns
        -------
        Profile
            Equivalent profile whose moving intervals never straddle a cut.
        """
        cut = self._cuts(s_cuts)
        if cut is None:
            return self
        k, tc, sc = cut
        _, vc, ac, _ = self.state(tc)
        t = np.insert(self.t, k + 1, tc)
        s = np.insert(self.s, k + 1, sc)
        v = np.insert(self.v, k + 1, np.maximum(vc, 0.0))
        a = np.insert(self.a, k + 1, ac)
        jj = np.insert(self.j, k + 1, self.j[k])
        blk = np.insert(self.block, k + 1, self.block[k])
        # Re-derive knot positions from the integration so round-off cannot accumulate.
        return Profile(t=t, s=s, v=v, a=a, j=jj, block=blk)

    def interval_blocks(self, path) -> np.ndarray:
        """Block of every interval: given labels, else by position on ``path``.

        Moving intervals without a label take the block at their mid-point; holds
        without a label go to the last block (in program order) ending at their
        position, which is the dwell or stop block when there is one.

        Parameters
        ----------
        path : reference.core.geometry.Path
            The path the profile runs on.

        Returns
        -------
        numpy.ndarray of int, shape (K,)
        """
        return _interval_blocks(self.s, self.block, path)

    def block_times(self, path) -> np.ndarray:
        """Time spent in each NC block; sums to :attr:`duration`.

        The same sums as ``split_at`` at every block end followed by
        :meth:`interval_blocks`, formed from the split knots' times and positions alone
        (a plan of 10^6 blocks would otherwise build a second profile of some 4e6
        intervals to read two of its six arrays).

        Parameters
        ----------
        path : reference.core.geometry.Path
            The path the profile runs on (its ``blocks`` define the block boundaries).

        Returns
        -------
        numpy.ndarray, shape (n_blocks,)
            Indexed by block index (``path.blocks[i].block``), s.
        """
        cuts = self._block_cuts(path)
        return self._block_sums(path, cuts, self._cut_times(cuts))

    def segment_times(self, path, segments: np.ndarray | None = None) -> np.ndarray:
        """Time spent moving through each segment (holds excluded), shape ``(m,)``, s.

        ``segments`` (int array, optional): only these are wanted; the profile is then
        split at their own breaks only and the other entries are 0. A segment's
        intervals are those between its two breaks either way, with the same knots, so
        its time is the same number. Formed from the split knots' times and positions
        alone, as :meth:`block_times`.
        """
        cuts = self._segment_cuts(path, segments)
        return self._segment_sums(path, segments, cuts, self._cut_times(cuts))

    def block_and_segment_times(self, path, segments: np.ndarray
                                ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`block_times` ``(path)`` and :meth:`segment_times` ``(path, segments)``,
        the same numbers, with the time of a knot that both splits add found once
        (:meth:`time_at` solves each position on its own, so a knot's time does not
        depend on which other knots are solved with it).
        """
        cb, cs = self._block_cuts(path), self._segment_cuts(path, segments)
        if cb.size and cs.size and self.n_intervals:
            both = np.union1d(cb, cs)
            t_both = self.time_at(both)
            tb, ts = t_both[np.searchsorted(both, cb)], t_both[np.searchsorted(both, cs)]
        else:
            tb, ts = self._cut_times(cb), self._cut_times(cs)
        return (self._block_sums(path, cb, tb), self._segment_sums(path, segments, cs, ts))

    def _block_cuts(self, path) -> np.ndarray:
        """:meth:`_cut_positions` of the block ends."""
        spans = path.blocks
        return self._cut_positions(spans.s_end[spans.s_end > spans.s_start])

    def _segment_cuts(self, path, segments) -> np.ndarray:
        """:meth:`_cut_positions` of the breaks of ``segments`` (all breaks: None)."""
        if segments is None:
            return self._cut_positions(path.s_breaks)
        segments = np.asarray(segments, dtype=np.int64)
        ends = np.zeros(path.n_segments + 1, dtype=bool)     # their breaks, sorted
        ends[segments] = True
        ends[segments + 1] = True
        return self._cut_positions(path.s_breaks[ends])

    def _block_sums(self, path, cuts: np.ndarray, tc: np.ndarray) -> np.ndarray:
        """:meth:`block_times` from the block-end cuts and their times."""
        spans = path.blocks
        n_blocks = int(spans.block.max()) + 1 if len(spans) else 0
        cut = self._ordered_cuts(cuts, tc)
        if cut is None:
            t, s, blk = self.t, self.s, self.block
        else:
            k, tc, sc = cut
            t = np.insert(self.t, k + 1, tc)
            s = np.insert(self.s, k + 1, sc)
            blk = np.insert(self.block, k + 1, self.block[k])
        iv = _interval_blocks(s, blk, path)
        del s, blk
        return np.bincount(iv, weights=np.diff(t), minlength=n_blocks)

    def _segment_sums(self, path, segments, cuts: np.ndarray, tc: np.ndarray
                      ) -> np.ndarray:
        """:meth:`segment_times` from the segment-break cuts and their times."""
        cut = self._ordered_cuts(cuts, tc)
        if cut is None:
            t, s = self.t, self.s
        else:
            k, tc, sc = cut
            t = np.insert(self.t, k + 1, tc)
            s = np.insert(self.s, k + 1, sc)
        n_iv = s.size - 1
        if segments is not None:
            segments = np.asarray(segments, dtype=np.int64)
            wanted = np.zeros(path.n_segments, dtype=bool)
            wanted[segments] = True
        if segments is None or n_iv <= 0 or segments.size > _FEW_SEGMENTS_SHARE * path.n_segments:
            moving = s[1:] > s[:-1]
            seg = path.segment_index(0.5 * (s[:-1] + s[1:]))
            if segments is not None:
                moving &= wanted[seg]
            return np.bincount(seg[moving], weights=np.diff(t)[moving],
                               minlength=path.n_segments)
        # few segments: only the intervals that can have their mid-point in one of them
        # (the knots are non-decreasing): from the one ending at or after the segment's
        # start to the one starting before its end, one more on each side; the same
        # intervals in the same order as over the whole profile, so the same sums (the
        # block rows of a rounded path ask for its multi-segment blocks only)
        sb = path.s_breaks
        lo = np.searchsorted(s, sb[segments], side="left") - 2
        hi = np.searchsorted(s, sb[segments + 1], side="left") + 1
        lo[segments == 0] = 0                       # segment_index clamps the path ends
        hi[segments == path.n_segments - 1] = n_iv
        lo, hi = np.clip(lo, 0, n_iv), np.clip(hi, 0, n_iv)
        mark = np.bincount(lo, minlength=n_iv + 1) - np.bincount(hi, minlength=n_iv + 1)
        iv = np.flatnonzero(np.cumsum(mark[:-1]) > 0)
        s0, s1 = s[iv], s[iv + 1]
        seg = path.segment_index(0.5 * (s0 + s1))
        moving = (s1 > s0) & wanted[seg]
        return np.bincount(seg[moving], weights=(t[iv + 1] - t[iv])[moving],
                           minlength=path.n_segments)


#: :meth:`Profile.segment_times` of at most this share of the segments works on the
#: intervals near them only (the same sums; measured on the rounded rows of
#: tests/bench/bench_rounding.py: 935 of 10,623 segments 2.9 -> 2.4 ms, while 11,400 of
#: 19,119 were slower so than over the whole profile).
_FEW_SEGMENTS_SHARE = 0.25


#: Iterations of :func:`_cubic_time`: Newton converges in a few steps; the bisection
#: fallback alone would shrink the bracket to 2^-64 of the interval.
_TIME_AT_ITERATIONS = 64


def _cubic_time(q, h, s0, s1, v0, a0, j) -> np.ndarray:
    """Time ``tau`` in ``(0, h)`` where ``s0 + v0 tau + a0 tau^2/2 + j tau^3/6 = q``.

    The cubic is non-decreasing on ``[0, h]`` (a profile interval) and ``s0 < q < s1``
    its values at the ends, so the root is bracketed. Safeguarded Newton: start from the
    chord (exact at constant speed), keep the bracket ``[lo, hi]`` from the sign of the
    residual, and bisect wherever the Newton step would leave it (zero speed at an end,
    round-off). Stops where the step is within round-off of the interval length.

    Parameters
    ----------
    q, h, s0, s1, v0, a0, j : numpy.ndarray, shape (N,)
        Positions (mm), interval lengths (s), knot positions, speed, acceleration and
        jerk at the interval starts.

    Returns
    -------
    numpy.ndarray, shape (N,)
        s.
    """
    tau = h * np.clip((q - s0) / (s1 - s0), 0.0, 1.0)
    lo = np.zeros_like(h)
    hi = h.copy()
    eps4 = 4.0 * np.finfo(float).eps
    act = np.arange(q.size)
    for _ in range(_TIME_AT_ITERATIONS):
        t_, l_, u_ = tau[act], lo[act], hi[act]
        vv, aa, jj = v0[act], a0[act], j[act]
        f = s0[act] + vv * t_ + aa * t_ ** 2 / 2 + jj * t_ ** 3 / 6 - q[act]
        below = f < 0
        l_ = np.where(below, t_, l_)
        u_ = np.where(below, u_, t_)
        vel = vv + aa * t_ + jj * t_ ** 2 / 2
        with np.errstate(divide="ignore", invalid="ignore"):
            tn = t_ - f / vel
        bad = ~np.isfinite(tn) | (tn <= l_) | (tn >= u_)
        tn = np.where(bad, 0.5 * (l_ + u_), tn)
        tn = np.where(f == 0, t_, tn)
        tol = eps4 * h[act]
        done = (np.abs(tn - t_) <= tol) | (u_ - l_ <= tol)
        tau[act], lo[act], hi[act] = tn, l_, u_
        act = act[~done]
        if act.size == 0:
            break
    return tau


#: Intervals labelled at a time by :func:`_interval_blocks` (bounded temporaries).
_LABEL_CHUNK = 1 << 18


def _interval_blocks(s: np.ndarray, block: np.ndarray, path) -> np.ndarray:
    """:meth:`Profile.interval_blocks` of knots ``s`` (shape (K + 1,)) and labels
    ``block`` (shape (K,)), worked in chunks of intervals."""
    blk = np.array(block, dtype=np.int64)
    if not np.any(blk < 0) or not path.blocks:
        return blk
    ends = path.blocks.s_end
    ids = path.blocks.block
    last = int(ids[-1])
    for lo in range(0, blk.size, _LABEL_CHUNK):
        hi = min(blk.size, lo + _LABEL_CHUNK)
        part = blk[lo:hi]                       # a view: written in place
        todo = part < 0
        if not np.any(todo):
            continue
        s0, s1 = s[lo:hi], s[lo + 1:hi + 1]
        moving = s1 > s0
        # moving intervals: the block at the mid-point (looked up for those only, and the
        # holds, usually a few, on their own)
        mv = np.flatnonzero(todo & moving)
        mid = 0.5 * (s0[mv] + s1[mv])
        part[mv] = path.block_of(mid) if path.n_segments else last
        # holds: the last block (program order) whose end is at or before the position
        hd = np.flatnonzero(todo & ~moving)
        if hd.size:
            last_end = np.searchsorted(ends, s0[hd], side="right") - 1
            part[hd] = ids[np.clip(last_end, 0, len(ids) - 1)]
    return blk
