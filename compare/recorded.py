"""Trajectories recorded from other controllers or simulators (``feedoracle check``).

A recording is a CSV file with a header ``t,X,Y,Z[,A,...]`` (time in s, linear axes in
mm, rotary axes in degrees; a unit may be given in brackets: ``t[ms]``, ``X[in]``,
``A[deg]``), one row per sample, at a constant or varying period. It is turned into a
:class:`~reference.core.profile.Profile` on the program's path so that the one checker
(:func:`~reference.core.constraints.check_profile`) judges it and the comparison with
the oracle works block by block, exactly as for the heuristic:

1. **Read and validate** (:func:`read_trajectory`): header, units, numbers, strictly
   increasing time; every problem is a :class:`TrajectoryError` naming file and row.
2. **Project** (:func:`project`): each sample goes to the nearest point of the path,
   tracked monotonically in ``s`` (a sample may only look a few chords ahead of the
   previous one, so a path that crosses itself is not short-cut), then refined by
   Newton steps on the exact geometry (vectorised ``path.evaluate``). The distance to
   the path is the *deviation*; its maximum and where it happens are reported.
3. **Smooth** (:func:`smooth`, only when the samples are noisy): positions along the
   path are smoothed by penalised least squares on third differences (a Whittaker
   smoother; it keeps constant-acceleration phases exact and only rounds the
   transitions), with the strength chosen so the residual matches the noise level.
   The noise level is estimated from fourth differences (robust MAD) unless given.
4. **Reconstruct** (:func:`reconstruct`): constant path acceleration between the
   mid-points of sample intervals, with the average speed of each interval at its
   mid-point. The acceleration of each cell is then the second difference of the
   positions: a weighted *average* of the true acceleration, so a motion that keeps its
   limits never appears to break them (a cubic spline through BRISK samples would
   overshoot by up to 50 %), and a motion that breaks them shows it.
   Where the path requires rest (exact stops, dwells, the ends) and the recording is
   slow enough to have stopped there (below ``1.5 * A * h``), a knot with zero speed
   sits exactly at the stop. At every other corner a knot carries the speed the samples
   allow there (:func:`_corner_speed`: cells average over the speed dip of a corner, so
   the recording is given the benefit of the doubt within what the samples resolve).
   Positions between these anchors are scaled (by a factor within ``1 +- 1e-3`` for a
   good recording) so every anchor sits exactly where it belongs. Rest before the first
   and after the last motion is trimmed: time counts from leaving the start point to
   arriving at the end point, and the holds the program imposes there (dwell, the last
   block's exact-stop settle) are put back as :func:`reference.holds.imposed_holds`
   gives them, as the oracle has them; rest at a block end is split between the dwell
   blocks there (their programmed time) and the block that moved there (the rest).
5. **Judge** (:func:`check_recorded`): ``check_profile`` on the reconstructed profile
   with a measurement tolerance (:func:`measurement_tolerance`: 1 %, more for noisy
   recordings), the deviation against ``--max-deviation``, and the comparison with the
   oracle block by block.

Jerk of a recording is estimated from acceleration steps spread over one IPO cycle,
meaningful when the recording is sampled at the IPO cycle; by default recordings are
judged on the ``acc`` bound set (velocity, acceleration, feed, corner jumps, stops) and
jerk is shown for information (``--bounds jerk`` makes it binding).
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path as FsPath
from typing import Any, Callable, TextIO

import numpy as np
from scipy.linalg import solveh_banded

from reference.core.constraints import BOUND_SETS
from reference.core.errors import TrajectoryError
from reference.core.geometry import Path
from reference.core.holds import with_holds
from reference.core.limits import MachineLimits
from reference.core.profile import Profile
from reference.core.tolerances import POS_TOL_MM

from .comparison import Comparison, Side, block_span, compare_profiles, oracle_result

#: Unit suffixes accepted in the header and their factor to s / mm / degrees.
TIME_UNITS = {"s": 1.0, "ms": 1e-3}
LINEAR_UNITS = {"mm": 1.0, "in": 25.4, "inch": 25.4}
ROTARY_UNITS = {"deg": 1.0, "°": 1.0}

#: Columns that are not axes: the path position and speed that ``feedoracle plan --csv``
#: writes beside the axes. They are ignored; ``s`` is always recomputed by projection.
IGNORED_COLUMNS = ("s", "v")

#: Default largest accepted deviation from the path, mm (also >= 5x the noise level).
DEFAULT_MAX_DEVIATION_MM = 0.1

#: Smooth only when the noise would move second-difference accelerations by more than
#: this fraction of the smallest axis acceleration limit (below it, smoothing changes
#: nothing that matters and exact data stay exact).
ACCEL_NOISE_REL = 0.005

#: Speed below which a stop is considered reached at the sample resolution, as a
#: multiple of ``A_max * h`` (the speed one sample at full acceleration changes).
STOP_SNAP_FACTOR = 1.5

#: Dense sampling of the path for the coarse projection: at most this step, mm, and
#: this angle on arcs, rad; at least MIN_DENSE_STEP_MM.
MAX_DENSE_STEP_MM = 0.05
MAX_DENSE_ANGLE_RAD = 0.02
MIN_DENSE_STEP_MM = 0.002
MAX_DENSE_POINTS = 400_000

#: A recording breaks a limit when value/limit exceeds 1 + tolerance. Its motion is
#: measured, not computed: positions are quantised, and the reconstruction between
#: samples places stops and corners exactly by rescaling positions by up to a few 1e-4.
#: 1 % is above both for a clean recording and far below the excess of a planner that
#: really ignores a limit. Noisy recordings get more (:func:`measurement_tolerance`).
RECORDED_RATIO_TOL = 0.01

#: Multiple of the noise-induced uncertainty added to the tolerance of noisy recordings.
NOISE_TOL_FACTOR = 3.0

#: Newton iterations of the exact projection.
NEWTON_STEPS = 6


@dataclass(frozen=True, slots=True)
class Recording:
    """A recorded trajectory as read from CSV.

    Attributes
    ----------
    file : str
        File name as given.
    axes : tuple[str, ...]
        Axis names of the columns after ``t``.
    t : numpy.ndarray, shape (N,)
        Sample times, s, strictly increasing.
    q : numpy.ndarray, shape (N, n)
        Axis positions, mm / degrees.
    rows : numpy.ndarray of int, shape (N,)
        1-based line of each sample in the file.
    """

    file: str
    axes: tuple[str, ...]
    t: np.ndarray
    q: np.ndarray
    rows: np.ndarray


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


# --------------------------------------------------------------------- reading
def _header_name(raw: str, file: str) -> tuple[str, str | None]:
    name = raw.strip()
    unit = None
    if "[" in name and name.endswith("]"):
        name, unit = name[:-1].split("[", 1)
        name, unit = name.strip(), unit.strip()
    elif "(" in name and name.endswith(")"):
        name, unit = name[:-1].split("(", 1)
        name, unit = name.strip(), unit.strip()
    return name, unit


def read_trajectory(file: str | FsPath, path_axes: tuple[str, ...] = (),
                    rotary: tuple[bool, ...] = ()) -> Recording:
    """Read and validate a recorded trajectory.

    Parameters
    ----------
    file : path
        CSV file with header ``t,X,Y,Z[,...]``.
    path_axes : tuple[str, ...]
        Axes of the program's path (to name what is missing or extra).
    rotary : tuple[bool, ...]
        Rotary flag per path axis (for unit checks).

    Returns
    -------
    Recording

    Raises
    ------
    TrajectoryError
        Naming file and row: no header, unknown unit, wrong column count, a value that
        is not a finite number, time not strictly increasing, fewer than 3 samples.
    """
    name = str(file)
    text = FsPath(file).read_text(encoding="utf-8-sig", errors="replace")
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    header_row = next((i for i, ln in enumerate(lines) if ln.strip()
                       and not ln.lstrip().startswith("#")), None)
    if header_row is None:
        raise TrajectoryError(f"{name}: empty file (expected a header t,X,Y,Z)")
    delim = ";" if lines[header_row].count(";") > lines[header_row].count(",") else ","
    cols = next(csv.reader([lines[header_row]], delimiter=delim))
    parsed = [_header_name(c, name) for c in cols]
    tname, tunit = parsed[0]
    if tname.lower() not in ("t", "time", "t_s"):
        raise TrajectoryError(f"{name}:{header_row + 1}: first column is {cols[0]!r}, expected "
                              f"'t' (time in s), then one column per axis (X,Y,Z,...)")
    tfac = 1.0 if tunit is None else TIME_UNITS.get(tunit.lower())
    if tfac is None:
        raise TrajectoryError(f"{name}:{header_row + 1}: time unit {tunit!r} not supported "
                              f"(use s or ms)")
    rot = dict(zip(path_axes, rotary))
    axes, facs, used = [], [], [0]
    for ci, (raw, (ax, unit)) in enumerate(zip(cols[1:], parsed[1:]), start=1):
        if ax in IGNORED_COLUMNS:
            continue
        used.append(ci)
        ax = ax.upper()
        if not ax or not ax.replace("_", "").isalnum():
            raise TrajectoryError(f"{name}:{header_row + 1}: column {raw!r} is not an axis name")
        if ax in axes:
            raise TrajectoryError(f"{name}:{header_row + 1}: axis {ax} appears twice")
        is_rot = rot.get(ax, ax in ("A", "B", "C"))
        table = ROTARY_UNITS if is_rot else LINEAR_UNITS
        f = 1.0 if unit is None else table.get(unit.lower())
        if f is None:
            raise TrajectoryError(
                f"{name}:{header_row + 1}: column {raw!r}: unit {unit!r} not supported "
                f"(use {' or '.join(table)})")
        axes.append(ax)
        facs.append(f)
    if not axes:
        raise TrajectoryError(f"{name}:{header_row + 1}: no axis columns after 't'")
    data, rows = [], []
    for i in range(header_row + 1, len(lines)):
        ln = lines[i]
        if not ln.strip() or ln.lstrip().startswith("#"):
            continue
        cells = next(csv.reader([ln], delimiter=delim))
        if len(cells) != len(cols):
            raise TrajectoryError(f"{name}:{i + 1}: {len(cells)} values, the header has "
                                  f"{len(cols)} columns")
        vals = []
        for c, cell in zip(cols, cells):
            try:
                x = float(cell)
            except ValueError:
                raise TrajectoryError(f"{name}:{i + 1}: column {c.strip()!r}: "
                                      f"{cell.strip()!r} is not a number") from None
            if not math.isfinite(x):
                raise TrajectoryError(f"{name}:{i + 1}: column {c.strip()!r}: "
                                      f"{cell.strip()!r} is not a finite number")
            vals.append(x)
        data.append(vals)
        rows.append(i + 1)
    if len(data) < 3:
        raise TrajectoryError(f"{name}: {len(data)} sample(s); at least 3 are needed")
    arr = np.array(data, dtype=np.float64)[:, used]
    t = arr[:, 0] * tfac
    q = arr[:, 1:] * np.array(facs)
    dt = np.diff(t)
    if np.any(dt <= 0):
        k = int(np.flatnonzero(dt <= 0)[0])
        raise TrajectoryError(f"{name}:{rows[k + 1]}: time {float(arr[k + 1, 0])!r} is not "
                              f"after the previous row's {float(arr[k, 0])!r} (time must "
                              f"increase)")
    return Recording(file=name, axes=tuple(axes), t=t, q=q, rows=np.array(rows))


def align_axes(rec: Recording, path: Path) -> np.ndarray:
    """The recording's positions in the path's axis order, shape ``(N, n)``.

    Axes the path has but the recording lacks must not move on the path (they are
    filled with the path's constant value); recorded axes the path lacks must stay
    constant.

    Raises
    ------
    TrajectoryError
        A moving axis missing on either side.
    """
    N = rec.t.size
    out = np.empty((N, path.n_axes))
    q0 = path.evaluate(0.0)[0][0] if path.n_segments else np.zeros(path.n_axes)
    probe = path.evaluate(np.linspace(0, path.total_length, 200))[0] if path.n_segments \
        else np.zeros((1, path.n_axes))
    for i, ax in enumerate(path.axes):
        if ax in rec.axes:
            out[:, i] = rec.q[:, rec.axes.index(ax)]
        elif np.ptp(probe[:, i]) > 1e-9:
            raise TrajectoryError(f"{rec.file}: no column for axis {ax}, which the program "
                                  f"moves (columns: {', '.join(rec.axes)})")
        else:
            out[:, i] = q0[i]
    for j, ax in enumerate(rec.axes):
        if ax not in path.axes and np.ptp(rec.q[:, j]) > 1e-9:
            k = int(np.argmax(np.abs(rec.q[:, j] - rec.q[0, j]) > 1e-9))
            raise TrajectoryError(f"{rec.file}:{rec.rows[k]}: axis {ax} moves, but the "
                                  f"program's path has no axis {ax} "
                                  f"(path axes: {', '.join(path.axes)})")
    return out


# --------------------------------------------------------------------- projection
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
    use = geo if np.any(np.abs(path.d[:, geo]).sum() + path.radius.sum() > 0) and geo.any() \
        else np.ones(path.n_axes, bool)
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
    dev = np.linalg.norm(path.evaluate(s)[0][:, use] - qu, axis=1)
    return Projection(s=s, deviation=dev)


# --------------------------------------------------------------------- smoothing
def estimate_noise(s: np.ndarray, t: np.ndarray | None = None) -> float:
    """Noise level of sampled positions, mm (robust; exact cubic motion gives 0).

    Over every 5 consecutive samples, the component of the positions orthogonal to all
    cubics in time (the normalised fourth divided difference) is noise only: constant
    jerk leaves none. Its robust spread (1.4826 MAD) estimates the noise; the few
    windows where the jerk changes are outliers the median ignores. Works for a
    varying sampling period.

    Parameters
    ----------
    s : numpy.ndarray, shape (N,)
        Positions, mm.
    t : numpy.ndarray, shape (N,), optional
        Sample times, s (default: uniform).
    """
    if s.size < 6:
        return 0.0
    if t is None:
        t = np.arange(s.size, dtype=np.float64)
    idx = np.arange(s.size - 4)[:, None] + np.arange(5)[None, :]
    T = t[idx]
    T = (T - T[:, :1]) / np.maximum(T[:, -1:] - T[:, :1], 1e-300)     # scale-free
    D = T[:, :, None] - T[:, None, :]
    D[:, np.arange(5), np.arange(5)] = 1.0
    w = 1.0 / np.prod(D, axis=2)
    w /= np.linalg.norm(w, axis=1, keepdims=True)
    e = np.einsum("ij,ij->i", w, s[idx])
    return 1.4826 * float(np.median(np.abs(e - np.median(e))))


def smooth(t: np.ndarray, s: np.ndarray, sigma: float) -> np.ndarray:
    """Whittaker smoother with a third-difference penalty, residual RMS ~ ``sigma``.

    Parameters
    ----------
    t, s : numpy.ndarray, shape (N,)
        Sample times (s) and positions (mm).
    sigma : float
        Noise level, mm (> 0).

    Returns
    -------
    numpy.ndarray, shape (N,)
        Smoothed positions.
    """
    n = s.size
    if n < 8 or sigma <= 0:
        return s.copy()
    h = np.diff(t)
    hm = float(np.mean(h))
    # third divided differences scaled by hm^3 (dimensionless for uniform sampling)
    rows = n - 3
    D = np.zeros((rows, 4))
    for r in range(rows):
        tt = t[r:r + 4]
        # divided-difference weights: w_i = 1 / prod_{k != i} (t_i - t_k), times 3! hm^3
        w = np.array([1.0 / np.prod([tt[i] - tt[k] for k in range(4) if k != i])
                      for i in range(4)])
        D[r] = w * 6.0 * hm ** 3
    # banded (upper form) storage of D^T D
    DtD = np.zeros((4, n))
    for off in range(4):
        for a in range(4 - off):
            # contributions D[r, a] * D[r, a + off] to entry (r + a, r + a + off)
            vals = D[:, a] * D[:, a + off]
            np.add.at(DtD[3 - off], np.arange(rows) + a + off, vals)

    def solve(lam: float) -> np.ndarray:
        ab = lam * DtD
        ab[3] += 1.0
        return solveh_banded(ab, s)

    target = sigma * math.sqrt(n)
    lo, hi = -6.0, 16.0
    z = s
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        z = solve(10.0 ** mid)
        if np.linalg.norm(z - s) > target:
            hi = mid
        else:
            lo = mid
        if hi - lo < 0.05:
            break
    return solve(10.0 ** lo)


# --------------------------------------------------------------------- reconstruction
def _v_corner(tk: np.ndarray, vk: np.ndarray, c: int) -> tuple[float, float] | None:
    """Speed dip at knot ``c`` rebuilt from the lines through its neighbours.

    The cell whose sample interval holds a corner or a stop averages the braking before
    it and the acceleration after it, so its speed overstates the speed at the corner.
    The lines through knots ``c-2, c-1`` and ``c+1, c+2`` meet where the motion turned
    from braking to accelerating; returns ``(t, v)`` of that point, or ``None`` when
    it is not a dip inside ``(t[c-1], t[c+1])``.
    """
    if c < 3 or c + 3 >= tk.size:
        return None
    sb = (vk[c - 1] - vk[c - 2]) / (tk[c - 1] - tk[c - 2])
    sa = (vk[c + 2] - vk[c + 1]) / (tk[c + 2] - tk[c + 1])
    if not sb < sa:
        return None
    # both sides must be one constant-acceleration phase for three cells, else the
    # lines say nothing about the corner (short blocks, corners a few samples apart)
    tol = 0.1 * max(abs(vk[c - 1] - vk[c - 2]), abs(vk[c + 2] - vk[c + 1]))
    if abs(vk[c - 2] + sb * (tk[c - 3] - tk[c - 2]) - vk[c - 3]) > tol or \
            abs(vk[c + 2] + sa * (tk[c + 3] - tk[c + 2]) - vk[c + 3]) > tol:
        return None
    t = (vk[c + 1] - vk[c - 1] + sb * tk[c - 1] - sa * tk[c + 1]) / (sb - sa)
    if not tk[c - 1] < t < tk[c + 1]:
        return None
    v = vk[c - 1] + sb * (t - tk[c - 1])
    if v > vk[c]:
        return None
    return float(t), max(float(v), 0.0)


def _label_holds(path: Path, tk: np.ndarray, S: np.ndarray, vk: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Attribute rest at a block end: dwells get their programmed time, the rest of the
    wait belongs to the block that moved there (exact-stop window, block change).

    A recording cannot tell settling from dwelling; this rule is what the control does
    (the moving block ends when the axes are in position, then the dwell runs), so a
    heuristic's own trajectory read back keeps its per-block times. Dwells take their
    time from the end of the rest. Rest elsewhere keeps the position rule of
    :meth:`Profile.interval_blocks`.

    Returns
    -------
    tk, S, vk : numpy.ndarray
        Knots with extra zero-speed knots where a rest is split between blocks.
    block : numpy.ndarray of int
        Block of each interval (-1: from the position).
    """
    still = (np.abs(np.diff(S)) <= POS_TOL_MM) & (vk[:-1] == 0.0) & (vk[1:] == 0.0)
    if not still.any():
        return tk, S, vk, np.full(tk.size - 1, -1)
    edges = np.diff(np.concatenate(([0], still.astype(np.int8), [0])))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    T, P, V, B = [tk[:1]], [S[:1]], [vk[:1]], []
    prev = 0                                   # next knot not yet copied
    for i_a, i_b in zip(starts, ends):         # hold over intervals [i_a, i_b)
        pos = float(S[i_a])
        arrive = [b for b in path.blocks if b.n_segments and abs(b.s_end - pos) <= POS_TOL_MM]
        dwells = [b for b in path.blocks if not b.n_segments and b.dwell_s > 0
                  and abs(b.s_start - pos) <= POS_TOL_MM]
        if not arrive and not dwells:
            continue
        # copy the motion before the hold
        T.append(tk[prev + 1:i_a + 1]); P.append(S[prev + 1:i_a + 1]); V.append(vk[prev + 1:i_a + 1])
        B.append(np.full(i_a - prev, -1))
        t_a, t_b = float(tk[i_a]), float(tk[i_b])
        left = t_b - t_a
        pieces = []
        for d in reversed(dwells):
            take = min(d.dwell_s, left)
            pieces.append((d.block, take))
            left -= take
        owner = arrive[-1].block if arrive else dwells[0].block
        pieces.append((owner, left))
        t_cur = t_a
        for b, dur in reversed(pieces):
            if dur <= 0:
                continue
            t_cur = min(t_cur + dur, t_b)
            T.append(np.array([t_cur])); P.append(np.array([pos])); V.append(np.zeros(1))
            B.append(np.array([b]))
        if T[-1][-1] < t_b:                    # round-off: close the hold exactly
            T[-1] = np.array([t_b])
        prev = i_b
    T.append(tk[prev + 1:]); P.append(S[prev + 1:]); V.append(vk[prev + 1:])
    B.append(np.full(tk.size - 1 - prev, -1))
    return np.concatenate(T), np.concatenate(P), np.concatenate(V), np.concatenate(B)


def _corner_speed(tk: np.ndarray, vk: np.ndarray, tb: float,
                  dip: tuple[float, float] | None, v_allow: float, a_safe: float) -> float:
    """Path speed at a corner passed at time ``tb`` (between knots ``j`` and ``j + 1``).

    The cells around a corner average over its speed dip, so their speeds overstate the
    speed at the corner. The samples bound it: it is at least ``floor``, the lowest
    speed reachable from the knots next but one (whose cells do not hold the corner) at
    the acceleration observed beside them, with half a cell of slack for the corner
    time, and at most ``est``, the lowest of the linear interpolation, the
    parabola through the three nearest knots corrected for cell averaging (a
    jerk-limited dip) and the V of :func:`_v_corner` (an acceleration-limited dip).
    A recording is judged on what its samples prove: when the allowed corner speed
    ``v_allow`` lies in ``[floor, est]`` the corner gets ``v_allow``; when even ``floor``
    exceeds it, ``floor`` (the excess the samples prove) is kept. The knot never drops
    faster than ``a_safe`` (the smallest axis acceleration limit, mm/s^2) from its
    neighbours.
    """
    j = int(np.clip(np.searchsorted(tk, tb) - 1, 0, tk.size - 2))
    h = tk[j + 1] - tk[j]
    lin = vk[j] + (vk[j + 1] - vk[j]) * (tb - tk[j]) / h
    est = [lin]
    c = int(np.clip(np.argmin(np.abs(tk - tb)), 1, tk.size - 2))
    x, y = tk[c - 1:c + 2] - tb, vk[c - 1:c + 2]
    if np.all(np.diff(x) > 0):
        # knots carry cell averages: the average of a parabola over a cell of width h
        # is its value plus curvature * h^2 / 24, so take that off
        p = np.polyfit(x, y, 2)
        est.append(float(p[2] - p[0] * h * h / 12.0))
    if dip is not None and abs(dip[0] - tb) < h:
        est.append(dip[1])
    # the knots one further out average over cells that do not hold the corner; the
    # corner time itself is known to about half a cell
    b, a = max(j - 1, 0), min(j + 2, tk.size - 1)
    acc = [abs(vk[i + 1] - vk[i]) / (tk[i + 1] - tk[i]) for i in (b - 1, a)
           if 0 <= i < tk.size - 1]
    a_obs = max(acc, default=0.0)
    floor = max(vk[b] - a_obs * (tb - tk[b] + h / 2), vk[a] - a_obs * (tk[a] - tb + h / 2),
                0.0)
    top = max(min(est), floor)
    v = top if top <= v_allow else max(floor, v_allow)
    # never steeper than a_safe towards the neighbouring knots: the knot must not
    # invent an acceleration the recording does not have
    return float(max(v, vk[j] - a_safe * (tb - tk[j]), vk[j + 1] - a_safe * (tk[j + 1] - tb)))


def reconstruct(path: Path, limits: MachineLimits, t: np.ndarray, s: np.ndarray
                ) -> tuple[Profile, dict[str, Any]]:
    """Profile through projected positions (see the module docstring, step 4).

    Parameters
    ----------
    path : Path
    limits : MachineLimits
    t : numpy.ndarray, shape (N,)
        Sample times, s (strictly increasing).
    s : numpy.ndarray, shape (N,)
        Path positions, mm, non-decreasing, from 0 to the path length.

    Returns
    -------
    profile : Profile
        Starts at t = 0 and s = 0, ends at rest at the path end.
    info : dict
        ``t_offset_s`` (recording time of profile time 0), ``first_sample`` and
        ``last_sample`` (indices kept after trimming rest at the ends), ``anchors``
        (places pinned exactly: stops and corners), ``scale`` (largest anchor
        scaling ``|f - 1|``), ``unsnapped_stops`` (``(break, s, speed)`` of required
        stops the recording passed too fast to have stopped at).
    """
    L = path.total_length
    eps = 1e-9 * max(1.0, L)
    i0 = max(int(np.searchsorted(s, s[0] + eps, "right")) - 1, 0)
    i1 = max(int(np.searchsorted(s, s[-1] - eps, "left")), i0 + 1)
    tt, ss = t[i0:i1 + 1] - t[i0], s[i0:i1 + 1]
    h = np.diff(tt)
    # knots: the start, the mid-point of every sample interval (with its average
    # speed), the end; speed linear between knots = constant acceleration per cell
    tk = np.concatenate(([0.0], tt[:-1] + h / 2, [tt[-1]]))
    vk = np.concatenate(([0.0], np.diff(ss) / h, [0.0]))
    S = np.concatenate(([0.0], np.cumsum(np.diff(tk) * (vk[:-1] + vk[1:]) / 2)))
    v_snap = STOP_SNAP_FACTOR * float(np.max(limits.for_axes(path.axes).a_max)) * \
        float(np.median(h))
    anchors: dict[int, float] = {0: 0.0, tk.size - 1: L}
    unsnapped: list[tuple[int, float, float]] = []
    corners_at: list[tuple[float, float, float]] = []
    a_safe = float(np.min(limits.for_axes(path.axes).a_max))
    if path.n_segments > 1:
        t_in, t_out = path.junction_tangents()
        d = np.abs(t_out - t_in)
        corner = np.any(d > 1e-9, axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            v_allow = np.min(np.where(d > 1e-9, limits.for_axes(path.axes).jump / d,
                                      np.inf), axis=1)
    for k in range(1, path.n_segments):
        stop = bool(path.stop[k])
        if not (stop or corner[k - 1]):
            continue
        sb = float(path.s_breaks[k])
        tb = float(np.interp(sb, S, tk))
        c = int(np.clip(np.argmin(np.abs(tk - tb)), 1, tk.size - 2))
        if c in anchors:
            continue
        near = np.arange(max(c - 1, 1), min(c + 2, tk.size - 1))
        zero = near[vk[near] == 0.0]
        if zero.size:                       # at rest around the break: a hold
            z = int(zero[np.argmin(np.abs(S[zero] - sb))])
            if z not in anchors:
                anchors[z] = sb
            continue
        dip = _v_corner(tk, vk, c)
        if stop:
            v_pass = dip[1] if dip is not None else float(vk[c])
            if v_pass > v_snap:
                unsnapped.append((k, sb, v_pass))
                continue
            if dip is not None:
                tk[c] = dip[0]
            vk[c] = 0.0
            anchors[c] = sb
        else:
            corners_at.append((tb, sb, _corner_speed(tk, vk, tb, dip, float(v_allow[k - 1]),
                                                     a_safe)))
    # a knot at every corner, at the speed estimated there (cells average over it)
    if corners_at:
        tb = np.array([x[0] for x in corners_at])
        pos = np.searchsorted(tk, tb)
        fresh = (tb - tk[np.clip(pos - 1, 0, tk.size - 1)] > 1e-9) & \
            (tk[np.clip(pos, 0, tk.size - 1)] - tb > 1e-9) & (pos > 0) & (pos < tk.size)
        pos, tb = pos[fresh], tb[fresh]
        vb = np.array([x[2] for x in corners_at])[fresh]
        sbs = np.array([x[1] for x in corners_at])[fresh]
        shift = lambda i: i + int(np.searchsorted(pos, i, "right"))  # noqa: E731
        anchors = {shift(i): v for i, v in anchors.items()}
        tk, vk = np.insert(tk, pos, tb), np.insert(vk, pos, vb)
        for n, (i, sb) in enumerate(zip(pos, sbs)):
            anchors.setdefault(int(i + n), float(sb))
    # scale the speeds between anchors so every anchor lands exactly on its place
    order = sorted(anchors.items())
    dt = np.diff(tk)
    S = np.concatenate(([0.0], np.cumsum(dt * (vk[:-1] + vk[1:]) / 2)))
    worst = 0.0
    kept = [order[0]]
    for a1, s1 in order[1:]:
        a0, s0 = kept[-1]
        fixed = vk[a0] * dt[a0] / 2 + vk[a1] * dt[a1 - 1] / 2
        inner = (S[a1] - S[a0]) - fixed
        f = (s1 - s0 - fixed) / inner if inner > 0 else math.nan
        if not (0.5 < f < 2.0):
            if a1 == tk.size - 1:           # the end must stay: rescale what we can
                f = (s1 - s0) / (S[a1] - S[a0]) if S[a1] > S[a0] else 1.0
                vk[a0 + 1:a1] *= f
                kept.append((a1, s1))
            continue                        # an inconsistent anchor is dropped
        worst = max(worst, abs(f - 1.0))
        vk[a0 + 1:a1] *= f
        kept.append((a1, s1))
    S = np.concatenate(([0.0], np.cumsum(dt * (vk[:-1] + vk[1:]) / 2)))
    for a_i, target in kept:
        S[a_i] = target
    S = np.minimum(np.maximum.accumulate(S), L)
    tk, S, vk, blk = _label_holds(path, tk, S, vk)
    dt = np.diff(tk)
    prof = Profile(t=tk, s=S, v=vk, a=np.diff(vk) / dt, j=np.zeros(dt.size), block=blk)
    info = {"t_offset_s": float(t[i0]), "first_sample": i0, "last_sample": i1,
            "anchors": len(kept), "scale": worst, "unsnapped_stops": unsnapped}
    return prof, info


def measurement_tolerance(path: Path, limits: MachineLimits, t: np.ndarray, sigma: float,
                          scale: float) -> float:
    """Ratio tolerance for judging a recording (see :data:`RECORDED_RATIO_TOL`).

    ``max(1 %, 2 * scale, 3 * noise effect)``: ``scale`` is the largest anchor rescaling
    of :func:`reconstruct`; the noise effect is what position noise ``sigma`` does to a
    speed over one sample (``sqrt(2) sigma / h``) relative to the slowest programmed feed,
    and to an acceleration (``sqrt(6) sigma / h^2``) relative to the smallest axis limit.
    Smoothing reduces both, so this errs towards not reporting what the samples cannot
    prove.
    """
    tol = max(RECORDED_RATIO_TOL, 2.0 * scale)
    if sigma > 0:
        h = float(np.median(np.diff(t)))
        lim = limits.for_axes(path.axes)
        feeds = path.feed[np.isfinite(path.feed)]
        v_ref = float(np.min(feeds)) if feeds.size else float(np.min(lim.v_max))
        noise = max(math.sqrt(2.0) * sigma / h / v_ref,
                    math.sqrt(6.0) * sigma / h ** 2 / float(np.min(lim.a_max)))
        tol = max(tol, NOISE_TOL_FACTOR * noise)
    return tol


# --------------------------------------------------------------------- the check
@dataclass(frozen=True, slots=True)
class CheckResult:
    """Outcome of ``feedoracle check``.

    Attributes
    ----------
    recording : Recording
        The samples as read.
    projection : Projection
        Their projection onto the path.
    noise_mm : float
        Noise level used for smoothing, mm (0: none).
    max_deviation_mm : float
        The deviation accepted (the gate of the deviation check), mm.
    info : dict
        Reconstruction details (see :func:`reconstruct`).
    comparison : Comparison
        The recorded profile against the oracle (``reference_name == "recorded"``).
    path_kind : str
        ``"reference"`` (the heuristic's path with its rounding) or ``"programmed"``.
    """

    recording: Recording
    projection: Projection
    noise_mm: float
    max_deviation_mm: float
    info: dict
    comparison: Comparison
    path_kind: str = "reference"

    @property
    def deviation_ok(self) -> bool:
        """True when no sample is farther from the path than the accepted deviation."""
        return float(np.max(self.projection.deviation)) <= self.max_deviation_mm

    @property
    def ok(self) -> bool:
        """True when the deviation and every declared limit hold and bounds exist."""
        return self.deviation_ok and self.comparison.verdict(None).ok

    def _where(self, i: int) -> str:
        rec, c = self.recording, self.comparison
        s = float(self.projection.s[i])
        blk = int(c.path.block_of(min(s, c.path.total_length))[0]) if c.path.n_segments else -1
        span = block_span(c.path, blk)
        line = f", line {span.line}{(' ' + span.label) if span and span.label else ''}" \
            if span else ""
        return f"row {rec.rows[i]} (t = {rec.t[i]:.4f} s, s = {s:.3f} mm{line})"

    def deviation_text(self) -> str:
        """Largest deviation and where."""
        i = self.projection.worst
        return f"{float(self.projection.deviation[i]):.4g} mm at {self._where(i)}"

    def print(self, out: TextIO) -> None:
        """Text summary (deviation, limits, gap, stops, worst blocks)."""
        from .text import print_comparison
        rec = self.recording
        out.write(f"{rec.file}: {rec.t.size} samples over {rec.t[-1] - rec.t[0]:.4f} s, "
                  f"projected onto the {self.path_kind} path of {self.comparison.program}\n")
        dev_state = "ok" if self.deviation_ok else "FAIL"
        out.write(f"  deviation  {dev_state}: largest {self.deviation_text()} "
                  f"(accepted {self.max_deviation_mm:.4g} mm)\n")
        smooth_txt = f"smoothed for noise {self.noise_mm:.3g} mm" if self.noise_mm > 0 \
            else "no smoothing (noise below the accuracy that matters)"
        out.write(f"  samples    {smooth_txt}; motion from t = {self.info['t_offset_s']:.4f} s "
                  f"in the recording\n")
        for k, sb, v in self.info["unsnapped_stops"]:
            reason = self.comparison.path.stop_reason[k]
            out.write(f"  stop       the recording does not stop at s = {sb:.3f} mm "
                      f"({reason}): it passes at about {v:.3g} mm/s\n")
        print_comparison(self.comparison, None, out)

    def to_dict(self) -> dict:
        """JSON result: the comparison contract plus a ``recorded`` part."""
        from .export import comparison_dict
        d = comparison_dict(self.comparison)
        i = self.projection.worst
        d["recorded"] = {
            "file": self.recording.file, "samples": int(self.recording.t.size),
            "path": self.path_kind, "noise_mm": self.noise_mm,
            "max_deviation_mm": float(self.projection.deviation[i]),
            "max_deviation_at": {"row": int(self.recording.rows[i]),
                                 "t": float(self.recording.t[i]),
                                 "s": float(self.projection.s[i])},
            "accepted_deviation_mm": self.max_deviation_mm,
            "deviation_ok": self.deviation_ok,
            "t_offset_s": self.info["t_offset_s"],
            "unsnapped_stops": [{"s": sb, "reason": self.comparison.path.stop_reason[k],
                                 "speed": v} for k, sb, v in self.info["unsnapped_stops"]]}
        d["verdict"]["ok"] = self.ok
        if not self.deviation_ok and d["verdict"]["status"] == "ok":
            d["verdict"]["status"] = "leaves the path"
            d["verdict"]["text"] = f"the trajectory leaves the path: {self.deviation_text()}"
        return d


def recorded_profile(path: Path, limits: MachineLimits, rec: Recording,
                     smoothing: float | str = "auto"
                     ) -> tuple[Profile, Projection, float, dict]:
    """Project, smooth and reconstruct a recording on ``path``.

    Parameters
    ----------
    path : Path
    limits : MachineLimits
    rec : Recording
    smoothing : float or "auto"
        Noise level in mm (0 = none) or ``"auto"`` (estimated).

    Returns
    -------
    profile, projection, noise_mm, info
        See :func:`reconstruct` for ``info``.

    Raises
    ------
    TrajectoryError
        The recording does not start at the path start or does not reach its end.
    """
    q = align_axes(rec, path)
    proj = project(path, q, rec.t)
    L = path.total_length
    h = float(np.median(np.diff(rec.t)))
    if smoothing == "auto":
        sigma = estimate_noise(proj.s, rec.t)
        a_min = float(np.min(limits.for_axes(path.axes).a_max))
        if math.sqrt(6.0) * sigma / h ** 2 <= ACCEL_NOISE_REL * a_min:
            sigma = 0.0
    else:
        sigma = float(smoothing)
    s = smooth(rec.t, proj.s, sigma) if sigma > 0 else proj.s
    s = np.clip(np.maximum.accumulate(s), 0.0, L)
    tol = max(DEFAULT_MAX_DEVIATION_MM, 5 * sigma)
    start_gap = float(np.linalg.norm(q[0] - path.evaluate(0.0)[0][0])) if path.n_segments else 0.0
    if s[0] > tol or start_gap > 10 * tol + 1.0:
        raise TrajectoryError(f"{rec.file}:{rec.rows[0]}: the recording starts "
                              f"{max(s[0], start_gap):.4g} mm from the start of the path "
                              f"(it must cover the whole program)")
    if L - s[-1] > tol:
        i = int(np.argmax(s))
        raise TrajectoryError(f"{rec.file}:{rec.rows[-1]}: the recording ends {L - s[-1]:.4g} mm "
                              f"before the end of the path (s = {s[i]:.3f} of {L:.3f} mm)")
    s = s.copy()
    s[0] = 0.0 if s[0] <= tol else s[0]
    s[-1] = L
    s = np.clip(np.maximum.accumulate(s), 0.0, L)
    prof, info = reconstruct(path, limits, rec.t, s)
    return prof, proj, sigma, info


def check_recorded(file: str | FsPath, program, machine, *, bounds: str | None = None,
                   path_kind: str = "reference", smoothing: float | str = "auto",
                   max_deviation: float | None = None,
                   progress: Callable[[str, float], None] | None = None) -> CheckResult:
    """Read, project, check and compare a recorded trajectory (``feedoracle check``).

    Parameters
    ----------
    file : path
        CSV file (see the module docstring).
    program : reference.nc.Program
        The program the recording ran.
    machine : reference.machine.Machine
        Machine data (limits).
    bounds : str, optional
        Bound set the recording is judged against (default ``"acc"``).
    path_kind : {"reference", "programmed"}
        Project onto the heuristic's path (with its rounding) or the programmed contour.
    smoothing : float or "auto"
        Noise level in mm, 0 for none, ``"auto"`` to estimate.
    max_deviation : float, optional
        Largest accepted distance from the path, mm (default ``max(0.1, 5 * noise)``).
    progress : callable, optional
        ``progress(message, fraction)``.

    Returns
    -------
    CheckResult
    """
    from . import engines
    from reference.prepare import build_path, prepare, restrict_to_machine
    limits = machine.limits
    from reference.holds import imposed_holds
    if path_kind == "reference":
        path, holds = build_path(program, machine), None
    else:
        path, holds = restrict_to_machine(prepare(program), limits), None
    if holds is None:
        holds = imposed_holds(program, path, machine)
    rec = read_trajectory(file, path.axes, tuple(bool(r) for r in path.rotary))
    if progress is not None:
        progress("projecting the recording", -1.0)
    prof, proj, sigma, info = recorded_profile(path, limits, rec, smoothing)
    # rest before the first and after the last motion is trimmed from the recording, so
    # the holds the program imposes there (a dwell before any motion, the settle of the
    # last block, dwells at the end) cannot be measured: they are put back as imposed
    at_ends = (holds.break_index == 0) | (holds.break_index == path.n_segments)
    prof = with_holds(prof, path, holds.subset(at_ends))
    bound_set = bounds or "acc"
    sol = engines.run_oracle(path, limits, "acc", progress=_pre(progress, "oracle: "),
                             holds=holds)
    i = proj.worst
    tol = measurement_tolerance(path, limits, rec.t, sigma, info["scale"])
    notes = [f"Recorded trajectory {rec.file} ({rec.t.size} samples): judged on the "
             f"{bound_set!r} bound set ({', '.join(BOUND_SETS[bound_set])}) with a "
             f"measurement tolerance of {100 * tol:.3g} %; largest distance "
             f"from the {path_kind} path {float(proj.deviation[i]):.4g} mm at row "
             f"{rec.rows[i]} (t = {rec.t[i]:.4f} s)."]
    if sigma > 0:
        notes.append(f"Positions were smoothed for a noise level of {sigma:.3g} mm.")
    if info["scale"] > 5e-3:
        notes.append(f"Positions between stops and corners were rescaled by up to "
                     f"{100 * info['scale']:.2f} % to put each of them in place; the "
                     f"recording may not follow this path closely.")
    c = compare_profiles(path, limits, Side("recorded", prof, bound_set,
                                            ratio_tol=tol),
                         oracle_result(sol), program=program.file, machine=machine.name,
                         program_lines=tuple(program.lines), notes=notes)
    max_dev = max_deviation if max_deviation is not None else max(
        DEFAULT_MAX_DEVIATION_MM, 5 * sigma)
    return CheckResult(recording=rec, projection=proj, noise_mm=sigma,
                       max_deviation_mm=max_dev, info=info, comparison=c,
                       path_kind=path_kind)


def _pre(progress, prefix: str):
    if progress is None:
        return None
    return lambda m, f=-1.0: progress(prefix + m, f)
