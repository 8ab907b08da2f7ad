"""Axis motion of a profile on its path, sampled in time or along the path.

Used to *show* and to *explain* motion (plots, limiting causes). Whether a profile
keeps the limits is decided by :func:`reference.core.constraints.check_profile` alone.

Units: s, mm (degrees for rotary axes). Shapes: ``N`` samples, ``n`` axes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.core.geometry import Path
from reference.core.limits import MachineLimits
from reference.core.profile import Profile
from reference.core.rules import axis_acceleration, axis_jerk, axis_velocity, speed_caps


@dataclass(frozen=True, slots=True)
class AxisMotion:
    """Path and axis quantities at sample times.

    Attributes
    ----------
    t, s, v, a, j : numpy.ndarray, shape (N,)
        Time (s), path position (mm), velocity (mm/s), acceleration (mm/s^2), jerk (mm/s^3).
    q, vel, acc, jerk : numpy.ndarray, shape (N, n)
        Axis position, velocity, acceleration and jerk (mm, mm/s, mm/s^2, mm/s^3).
    segment : numpy.ndarray of int, shape (N,)
        Path segment of each sample.
    """

    t: np.ndarray
    s: np.ndarray
    v: np.ndarray
    a: np.ndarray
    j: np.ndarray
    q: np.ndarray
    vel: np.ndarray
    acc: np.ndarray
    jerk: np.ndarray
    segment: np.ndarray


def axis_motion(path: Path, profile: Profile, t: np.ndarray) -> AxisMotion:
    """Evaluate a profile and its axis motion at times ``t`` (clamped to the profile).

    Parameters
    ----------
    path : Path
        The path the profile runs on.
    profile : Profile
        The motion along it.
    t : array_like, shape (N,)
        Sample times, s.

    Returns
    -------
    AxisMotion
    """
    t = np.atleast_1d(np.asarray(t, dtype=np.float64))
    s, v, a, j = profile.state(t)
    s = np.clip(s, 0.0, path.total_length)
    v = np.maximum(v, 0.0)
    seg = path.segment_index(s)
    q, dq, ddq, dddq = path.evaluate(s, segment=seg)
    vel = axis_velocity(dq, v)
    acc = axis_acceleration(dq, ddq, v, a)
    jerk = axis_jerk(dq, ddq, dddq, v, a, j)
    return AxisMotion(t=t, s=s, v=v, a=a, j=j, q=q, vel=vel, acc=acc, jerk=jerk, segment=seg)


def sample_times(profile: Profile, n_max: int = 20000, dt_max: float | None = None) -> np.ndarray:
    """Sample times covering a profile: every knot plus a uniform grid.

    Parameters
    ----------
    profile : Profile
    n_max : int
        Number of uniform samples (the knots are added to them, thinned to ``n_max``
        when there are more).
    dt_max : float, optional
        Largest uniform step, s (refines the grid of short profiles).

    Returns
    -------
    numpy.ndarray
        Sorted unique times, s.
    """
    T = profile.duration
    n = n_max
    if dt_max is not None and T > 0:
        n = max(n, int(np.ceil(T / dt_max)) + 1)
    uni = np.linspace(profile.t[0], profile.t[-1], max(n, 2))
    knots = profile.t
    if knots.size > n_max:
        knots = knots[np.linspace(0, knots.size - 1, n_max).astype(np.int64)]
    return np.unique(np.concatenate([uni, knots]))


def limit_curve(path: Path, limits: MachineLimits, s: np.ndarray) -> dict[str, np.ndarray]:
    """Speed limits along the path for a motion at constant speed (no path acceleration).

    Parameters
    ----------
    path : Path
    limits : MachineLimits
    s : array_like, shape (N,)
        Path positions, mm.

    Returns
    -------
    dict
        ``"feed"`` (programmed feed, ``inf`` for G0), ``"axis velocity"``
        (``min_i V_i / |q'_i|``), ``"axis acceleration"`` (centripetal:
        ``min_i sqrt(A_i / |q''_i|)``) and ``"limit"`` (their minimum), each shape ``(N,)``
        in mm/s.
    """
    s = np.atleast_1d(np.asarray(s, dtype=np.float64))
    lim = limits.for_axes(path.axes)
    seg = path.segment_index(s)
    _, dq, ddq, _ = path.evaluate(s, segment=seg)
    v_ax, v_cen = speed_caps(dq, ddq, lim.v_max, lim.a_max)
    feed = path.feed[seg]
    return {"feed": feed, "axis velocity": v_ax, "axis acceleration": v_cen,
            "limit": np.minimum(np.minimum(feed, v_ax), v_cen)}
