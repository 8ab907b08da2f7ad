"""DRIVE: the knee-shaped acceleration characteristic (model note 6.1; B2 2.18).

Per axis, above a velocity threshold the acceleration is reduced (B2 2.18, key data):

``v_red = ACCEL_REDUCTION_SPEED_POINT (MD35220) * MAX_AX_VELO``,
``a_red = (1 - ACCEL_REDUCTION_FACTOR (MD35230)) * MAX_AX_ACCEL``,

with ``a(v) = a_max`` up to ``v_red`` and, above it, by the type MD35240
ACCEL_TYPE_DRIVE (the name is the model note's, tagged [M]):

* 0 constant: ``a(v) = a_red``;
* 1 hyperbolic: ``a(v) = c0 + c1/v`` through ``(v_red, a_max)`` and ``(v_max, a_red)``;
* 2 linear: ``a(v) = a_max - (a_max - a_red) (v - v_red)/(v_max - v_red)``.

The note's hyperbolic formula ``a_max v_red / v`` does not pass through ``a_red`` at
``v_max`` and would reduce even with ACCEL_REDUCTION_FACTOR = 0, against "no reduction is
applied if SPEED_POINT = 1 or FACTOR = 0" (6.1, from B2); the two-point hyperbola keeps
both. "If axes with different types of characteristic curve are interpolated together,
the acceleration profile for the path acceleration will be determined on the basis of
the reduction type that is most restrictive" (constant, then hyperbolic, then linear,
then none): the path's type applies to every moving axis with its own ``v_red``,
``a_red``. At each speed constant <= hyperbolic <= linear, so this order is also the
order of restrictiveness.

Model on the path [I] (:func:`drive_reduction`): a DRIVE segment accelerates with the
full axis limits up to its *knee*, the path speed at which the first moving axis with a
reduction reaches its ``v_red`` (``v_red_i / |q'_i|``, worst phase on arcs), and above
it with every axis at its characteristic's value at the segment's speed cap (the
smallest over the speeds above the knee, as ``a(v)`` never rises). Exact for the
constant type when one axis reduces, or all reducing axes reach ``v_red`` at the same
path speed; otherwise the reduction is assumed a little early and a little deep (a safe
model, never faster than the characteristic allows).

The oracle does not model DRIVE: it accelerates with MAX_AX_ACCEL, so the gap of a
DRIVE program includes the reduction; the planner's trace and the program warnings say
so.
"""

from __future__ import annotations

import numpy as np

#: Types of characteristic (MD35240), in order of priority (most restrictive first).
CONSTANT, HYPERBOLIC, LINEAR = 0, 1, 2
#: No reduction effective (lowest priority).
NONE = 3
TYPE_NAMES = ("constant", "hyperbolic", "linear", "none")


def reduces(speed_point: np.ndarray, factor: np.ndarray) -> np.ndarray:
    """True where the characteristic reduces anything: "no acceleration reduction
    effective ... when MD35220 ACCEL_REDUCTION_SPEED_POINT = 1 and/or MD35230
    ACCEL_REDUCTION_FACTOR = 0" (B2 2.18.1.2)."""
    return (np.asarray(speed_point) < 1.0) & (np.asarray(factor) > 0.0)


def acceleration_share(v: np.ndarray, v_max: np.ndarray, speed_point: np.ndarray,
                       factor: np.ndarray, kind: np.ndarray) -> np.ndarray:
    """``a(v) / a_max`` of the characteristic at axis speed ``v`` (broadcasting).

    Parameters
    ----------
    v : numpy.ndarray
        Axis speed, mm/s (deg/s for rotary axes), >= 0.
    v_max : numpy.ndarray
        MAX_AX_VELO in the same unit.
    speed_point, factor : numpy.ndarray
        MD35220 (share of ``v_max``, in (0, 1]) and MD35230 (in [0, 1)).
    kind : numpy.ndarray of int
        :data:`CONSTANT`, :data:`HYPERBOLIC`, :data:`LINEAR` or :data:`NONE`.

    Returns
    -------
    numpy.ndarray
        Share in ``[1 - factor, 1]``; 1 up to ``v_red`` and for :data:`NONE`.
    """
    v, v_max, sp, f, kind = np.broadcast_arrays(*(np.asarray(x, dtype=np.float64)
                                                  for x in (v, v_max, speed_point, factor,
                                                            kind)))
    v_red = sp * v_max
    x = np.clip(v, v_red, v_max)
    span = v_max - v_red
    with np.errstate(divide="ignore", invalid="ignore"):
        lin = 1.0 - f * np.where(span > 0, (x - v_red) / np.where(span > 0, span, 1.0), 0.0)
        hyp = 1.0 - f * np.where(span > 0, v_max / np.where(span > 0, span, 1.0)
                                 * (1.0 - v_red / np.where(x > 0, x, 1.0)), 0.0)
    share = np.select([kind == CONSTANT, kind == HYPERBOLIC, kind == LINEAR],
                      [1.0 - f, hyp, lin], 1.0)
    above = (v > v_red) & reduces(sp, f)
    return np.where(above, share, 1.0)


def drive_reduction(drive: np.ndarray, moving: np.ndarray, tangent: np.ndarray,
                    cap: np.ndarray, v_max: np.ndarray, speed_point: np.ndarray,
                    factor: np.ndarray, kind: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Knee and reduced acceleration shares of every segment.

    Parameters
    ----------
    drive : numpy.ndarray of bool, shape (m,)
        Segments planned in DRIVE.
    moving : numpy.ndarray of bool, shape (m, n)
        Axes that move in each segment.
    tangent : numpy.ndarray, shape (m, n)
        Largest ``|q'_i|`` over the segment (axis speed per path speed).
    cap : numpy.ndarray, shape (m,)
        Segment speed caps, mm/s.
    v_max, speed_point, factor : numpy.ndarray, shape (n,)
        MAX_AX_VELO (mm/s or deg/s), MD35220, MD35230 per axis.
    kind : numpy.ndarray of int, shape (n,)
        MD35240 per axis.

    Returns
    -------
    knee : numpy.ndarray, shape (m,)
        Path speed above which the reduced shares apply, mm/s (``inf``: no reduction
        below the cap).
    share : numpy.ndarray, shape (m, n)
        ``a(v)/a_max`` of each axis above the knee, at the axis speed at the cap (1 where
        nothing is reduced).
    """
    m, n = moving.shape
    red = reduces(speed_point, factor)[None, :] & moving & drive[:, None]
    # the path's type: the most restrictive among its moving axes with a reduction
    path_kind = np.where(red, np.asarray(kind)[None, :], NONE).min(axis=1, initial=NONE)
    with np.errstate(divide="ignore", invalid="ignore"):
        knee_i = np.where(red & (tangent > 0), speed_point[None, :] * v_max[None, :]
                          / np.where(tangent > 0, tangent, 1.0), np.inf)
    knee = knee_i.min(axis=1, initial=np.inf)
    v_axis = np.minimum(tangent * cap[:, None], v_max[None, :])
    share = acceleration_share(v_axis, v_max[None, :], speed_point[None, :],
                               factor[None, :], np.broadcast_to(path_kind[:, None], (m, n)))
    share = np.where(red, share, 1.0)
    knee = np.where((knee < cap) & (share.min(axis=1, initial=1.0) < 1.0), knee, np.inf)
    share = np.where(np.isfinite(knee)[:, None], share, 1.0)
    return knee, share


__all__ = ["CONSTANT", "HYPERBOLIC", "LINEAR", "NONE", "TYPE_NAMES", "acceleration_share",
           "drive_reduction", "reduces"]
