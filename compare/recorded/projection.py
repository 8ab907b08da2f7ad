"""Projection of recorded samples onto the program's path: the second stage.

Each sample goes to the nearest point of the path (over the geometry axes; over all axes
where some segment moves other axes alone, such as a TLIFT block or a positioning axis,
whose progress the geometry axes cannot show), tracked monotonically in ``s`` (a
sample may only look a few chords ahead of the previous one, so a path that crosses
itself is not short-cut; where the path passes a sample twice, the pass that keeps the
advance per sample smoothest wins), then refined by Newton steps on the exact geometry
(vectorised ``path.evaluate``). The distance to the path is the *deviation*; its
maximum and where it happens are reported by the check.

Inputs
    a :class:`~reference.core.geometry.Path`; positions in its axis order, mm / degrees,
    shape ``(N, n_axes)`` (from :func:`compare.recorded.reading.align_axes`); sample
    times, s, shape ``(N,)`` (for the noise level that widens the search window).
Outputs
    :class:`Projection`: path position of each sample, mm, non-decreasing, and its
    distance from the path (geometry axes), mm, both shape ``(N,)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.core.geometry import Path
from reference.core.tolerances import MOVING_AXIS_TOL, POS_TOL_MM

from .smoothing import estimate_noise

#: Dense sampling of the path for the coarse projection: at most this step, mm, and
#: this angle on arcs, rad; at least MIN_DENSE_STEP_MM.
MAX_DENSE_STEP_MM = 0.05
MAX_DENSE_ANGLE_RAD = 0.02
MIN_DENSE_STEP_MM = 0.002
MAX_DENSE_POINTS = 400_000

#: Newton iterations of the exact projection.
NEWTON_STEPS = 6


@dataclass(frozen=True, slots=True)
class Projection:
    """Samples projected onto a path.

    Attributes
    ----------
    s : numpy.ndarray, shape (N,)
        Path position of each sample, mm (non-decreasing).
    deviation : numpy.ndarray, shape (N,)
        Distance of each sample from the path (geometry axes), mm.
    """

    s: np.ndarray
    deviation: np.ndarray

    @property
    def worst(self) -> int:
        """Index of the sample farthest from the path."""
        return int(np.argmax(self.deviation)) if self.deviation.size else 0


def _dense(path: Path) -> tuple[np.ndarray, np.ndarray]:
    L = path.total_length
    step = min(MAX_DENSE_STEP_MM, max(MIN_DENSE_STEP_MM, L / (MAX_DENSE_POINTS / 2)))
    n = np.maximum(2, np.maximum(np.ceil(path.length / step),
                                 np.ceil(np.abs(path.omega) * path.length / MAX_DENSE_ANGLE_RAD))
                   ).astype(np.int64)
    seg = np.repeat(np.arange(path.n_segments), n)
    first = np.concatenate(([0], np.cumsum(n)[:-1]))
    frac = (np.arange(seg.size) - first[seg]) / (n[seg] - 1)
    s = path.s_breaks[seg] + frac * path.length[seg]
    return s, path.evaluate(s, segment=seg)[0]


def project(path: Path, q: np.ndarray, t: np.ndarray | None = None) -> Projection:
    """Project samples onto the path, monotone in ``s``.

    Parameters
    ----------
    path : Path
    q : numpy.ndarray, shape (N, n)
        Samples in the path's axis order.
    t : numpy.ndarray, shape (N,), optional
        Sample times, s (for the noise estimate; default uniform).

    Returns
    -------
    Projection
    """
    N = q.shape[0]
    if path.n_segments == 0:
        return Projection(np.zeros(N), np.zeros(N))
    geo = path.geometry.copy()
    moves_geo = (path.radius > 0) | (np.abs(path.d[:, geo]).max(axis=1, initial=0.0)
                                     > MOVING_AXIS_TOL)
    # the geometry axes find a sample's place on the path, unless some segment moves
    # other axes alone (a TLIFT block, a positioning axis): there the geometry rests and
    # only all axes tell how far the motion got; the deviation stays the geometry's
    measure = geo if moves_geo.any() and geo.any() else np.ones(path.n_axes, bool)
    use = measure if moves_geo.all() else np.ones(path.n_axes, bool)
    sd, qd = _dense(path)
    qd, qu = qd[:, use], q[:, use]
    step = float(np.max(np.diff(sd))) if sd.size > 1 else 0.0
    noise = max((estimate_noise(qu[:, i], t) for i in range(qu.shape[1])), default=0.0)
    tie = step + 3 * noise
    back = 2 * step + 4 * noise
    chord = np.concatenate(([np.linalg.norm(qu[0] - qd[0]) + 1.0],
                            np.linalg.norm(np.diff(qu, axis=0), axis=1)))
    # coarse: windowed nearest dense point, the window moving forward with the samples
    idx = np.empty(N, dtype=np.int64)
    ambiguous: dict[int, np.ndarray] = {}
    j = 0
    for i in range(N):
        s0 = sd[j]
        lo = int(np.searchsorted(sd, s0 - back, "left"))
        hi = int(np.searchsorted(sd, s0 + 3 * chord[i] + 2 * step + back, "right"))
        d = np.sqrt(np.einsum("ij,ij->i", qd[lo:hi] - qu[i], qd[lo:hi] - qu[i]))
        # local minima of the distance about as near as the nearest: more than one
        # where the path passes the sample twice (a plunge and retract, a reversal)
        dp = np.concatenate(([np.inf], d, [np.inf]))
        reps = np.flatnonzero((dp[1:-1] <= dp[:-2]) & (dp[1:-1] <= dp[2:]) &
                              (d <= d.min() + tie))
        reps = reps[np.concatenate(([True], np.diff(reps) > 1))] + lo
        if reps.size > 1:
            # first guess: the advance along the path that matches the chord
            j = int(reps[np.argmin(np.abs(sd[reps] - s0 - chord[i]))]) if i else int(reps[0])
            ambiguous[i] = reps
        else:
            j = int(reps[0])
        idx[i] = j
    # second look at the ambiguous samples: the pass that keeps the advance per sample
    # smoothest (the sample nearest a reversal is on either side of it by position)
    s_c = sd[idx]
    for i, reps in ambiguous.items():
        if 2 <= i < N - 1:
            adv = s_c[i - 1] - s_c[i - 2]
            cand = sd[reps]
            cost = np.abs(cand - s_c[i - 1] - adv) + np.abs((s_c[i + 1] - cand) -
                                                            (cand - s_c[i - 1]))
            idx[i] = int(reps[np.argmin(cost)])
            s_c[i] = sd[idx[i]]
    s = np.maximum.accumulate(sd[idx])
    # exact: Newton on (q(s) - p) . q'(s) = 0 within +-2 dense steps, on the segment of
    # the coarse point and on its neighbours (a sample near a corner may belong to
    # either side); the nearest result wins
    lo_b = np.clip(s - 2 * step - tie, 0, path.total_length)
    hi_b = np.clip(s + 2 * step, 0, path.total_length)
    seg0 = path.segment_index(s)
    best_s, best_d = s.copy(), np.full(N, np.inf)
    for off in (-1, 0, 1):
        seg = np.clip(seg0 + off, 0, path.n_segments - 1)
        a = np.maximum(path.s_breaks[seg], lo_b)
        b = np.minimum(path.s_breaks[seg + 1], hi_b)
        ok = a <= b
        x = np.clip(s, a, np.maximum(a, b))
        for _ in range(NEWTON_STEPS):
            qq, dq, ddq, _ = path.evaluate(x, segment=seg)
            r = qq[:, use] - qu
            f = np.einsum("ij,ij->i", r, dq[:, use])
            fp = np.einsum("ij,ij->i", dq[:, use], dq[:, use]) + \
                np.einsum("ij,ij->i", r, ddq[:, use])
            with np.errstate(divide="ignore", invalid="ignore"):
                dx = np.where(fp > 1e-12, -f / fp, 0.0)
            x = np.clip(x + dx, a, np.maximum(a, b))
        dist = np.linalg.norm(path.evaluate(x, segment=seg)[0][:, use] - qu, axis=1)
        # equally near on two segments (the two sides of a reversal): the one nearer
        # the coarse point, which the pass over the samples chose
        better = ok & ((dist < best_d - POS_TOL_MM) | ((dist <= best_d + POS_TOL_MM) &
                                                       (np.abs(x - s) < np.abs(best_s - s))))
        best_s, best_d = np.where(better, x, best_s), np.where(better, dist, best_d)
    s = np.maximum.accumulate(best_s)
    dev = np.linalg.norm(path.evaluate(s)[0][:, measure] - q[:, measure], axis=1)
    return Projection(s=s, deviation=dev)
