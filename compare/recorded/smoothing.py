"""Smoothing of noisy path positions: the third stage (only when the samples are noisy).

:func:`estimate_noise` measures the noise level from fourth divided differences (robust
MAD: constant-jerk motion leaves none). :func:`smooth` smooths the positions along the
path by penalised least squares on third differences (a Whittaker smoother; it keeps
constant-acceleration phases exact and only rounds the transitions), with the strength
chosen so the residual matches the noise level. Whether to smooth at all is decided by
:func:`compare.recorded.check.recorded_profile`.

Inputs
    sample times, s, and path positions, mm, both shape ``(N,)``; for :func:`smooth`
    the noise level, mm.
Outputs
    the noise level, mm (:func:`estimate_noise`); smoothed positions, mm, shape
    ``(N,)`` (:func:`smooth`).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import solveh_banded

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
