"""Stage: speed caps and tangential limits of every segment (model note 6.4).

Every segment is a helical piece (line, arc, helix) whose curvature is constant, so its
limit curve is one number per segment. Per axis ``i`` the tangent ``q'_i``, curvature
``q''_i`` and ``q'''_i`` are a constant part ``d_i`` plus a part rotating with amplitude

``P_i = rho_i |r w|``,  ``Q_i = rho_i r w^2``,  ``R_i = rho_i |r w^3|``
(``rho_i = sqrt(e1_i^2 + e2_i^2)``, the axis' share of the arc plane).

The bounds below take the worst phase of the rotation (a safe model: the checker's
per-axis constraints hold wherever the arc is):

``|q'_i v| <= v_max_i``            -> ``v <= v_max_i / (P_i + |d_i|)``   (axis velocity)
``|q'_i a + q''_i v^2| <= A_i``    -> ``|d_i||a| + sqrt((P_i a)^2 + (Q_i v^2)^2) <= A_i``
``|q'_i j + 3 q''_i v a + q'''_i v^3| <= J_i``
                                   -> ``|d_i||j| + sqrt((P_i|j| + R_i v^3)^2 + (3 Q_i v a)^2) <= J_i``

Caps, each with its cause (:mod:`reference.planner.causes`):

* programmed feed F (none for G0): ``feed``;
* axis velocity: ``axis velocity``;
* centripetal: ``Q_i v^2 <= share * A_i`` (``arc_centripetal_share``): ``axis acceleration``;
* SOFT, path jerk on arcs: ``R_i v^3 <= share * J_i`` (``arc_jerk_velocity_share``): ``jerk``;
* at least one IPO cycle per block: ``v <= L / T_ipo``: ``IPO-cycle cap`` (``L`` the
  segment's length; a rounding inside the blocks, G643, is part of its block: ``L`` the
  block's, :func:`reference.core.rows.interpolation_lengths`).

Then, at the cap speed ``C`` (the worst case, as speeds never exceed it), the tangential
acceleration ``a_t`` is the largest that satisfies the acceleration inequality for all
axes, and under SOFT (after keeping ``3 Q_i C a_t <= share * J_i``,
``arc_jerk_accel_share``) the tangential jerk ``j_t`` the largest that satisfies the jerk
inequality. On lines these are exactly ``min_i A_i/|d_i|`` and ``min_i J_i/|d_i|``.

Axis limits: MAX_AX_ACCEL times SOFT_ACCEL_FACTOR (SOFT) and G00_ACCEL_FACTOR (G0),
MAX_AX_JERK times G00_JERK_FACTOR (G0); factors above 1 are clipped to 1 so that the
plan never exceeds the limits the checker judges against.

DRIVE segments (:mod:`reference.planner.drive`): above the segment's knee every axis
acceleration ``A_i`` is its knee-shaped characteristic's share of it at the axis speed
at the cap. The centripetal cap is taken again with these reduced ``A_i`` (no lower than
the knee, below which the full ``A_i`` hold), and the tangential acceleration above the
knee is ``knee_ratio`` times the one below it (both at the cap, as above).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.arrays import row_argmin, row_min, rows_where
from ..core.geometry import Path, axis_tangent_amplitudes, moving_axes, plane_amplitudes
from ..core.rows import interpolation_lengths
from ..machine import Machine
from . import causes as C
from .parameters import PlannerParameters
from .drive import drive_reduction
from .stops import ACCEL_MODES, MODE_CODE, SegmentModes


@dataclass(frozen=True, slots=True, eq=False)
class SegmentLimits:
    """Per-segment speed cap and tangential limits, arrays of shape (m,).

    Attributes
    ----------
    cap : numpy.ndarray
        Largest path speed anywhere in the segment, mm/s.
    cap_cause : numpy.ndarray of int
        Cause code of the cap.
    accel : numpy.ndarray
        Tangential acceleration available at every speed up to ``cap``, mm/s^2.
    jerk : numpy.ndarray
        Tangential jerk (``inf`` for BRISK segments), mm/s^3.
    frequency : numpy.ndarray
        Smallest LOOKAH_FREQUENCY of the axes moving in the segment, Hz.
    moving : numpy.ndarray of bool, shape (m, n)
        Axes that move in the segment.
    knee : numpy.ndarray
        DRIVE: path speed above which the acceleration is reduced, mm/s (``inf``: none
        below the cap).
    knee_ratio : numpy.ndarray
        DRIVE: tangential acceleration above the knee as a share of ``accel`` (1 without
        a knee).
    """

    cap: np.ndarray
    cap_cause: np.ndarray
    accel: np.ndarray
    jerk: np.ndarray
    frequency: np.ndarray
    moving: np.ndarray
    knee: np.ndarray
    knee_ratio: np.ndarray


def axis_amplitudes(path: Path) -> tuple[np.ndarray, ...]:
    """(D, P, Q, R, Rn), each shape (m, n): constant tangent part and rotating amplitudes.

    ``P``, ``Q``: in-plane tangent and curvature; ``R``, ``Rn``: tangential and normal
    parts of the third derivative. On circles they are constant (``Rn = 0``); on spirals
    and clothoids the curvature varies along the segment and these are its worst values
    over the segment (:func:`~reference.core.geometry.plane_amplitudes`), so every cap
    derived from them holds on the whole segment.
    """
    rho = np.sqrt(path.e1 ** 2 + path.e2 ** 2)
    w = np.abs(path.omega)[:, None]
    amp = plane_amplitudes(path)
    D, P = axis_tangent_amplitudes(path, amp)
    Q = P * w
    R = Q * w
    Rn = np.zeros_like(R)
    sp = np.flatnonzero((path.dradius != 0) | (path.sharpness != 0))
    if sp.size:
        Q[sp] = rho[sp] * amp.curvature[sp, None]
        R[sp] = rho[sp] * amp.jerk_t[sp, None]
        Rn[sp] = rho[sp] * amp.jerk_n[sp, None]
    return D, P, Q, R, Rn


def _axis_factors(path: Path, machine: Machine, modes: SegmentModes):
    """Per segment and axis: acceleration and jerk limits after the mode factors."""
    lim = machine.limits.for_axes(path.axes)
    st = [machine.settings_of(a) for a in path.axes]
    soft_f = np.minimum(1.0, np.array([s.soft_accel_factor for s in st]))
    g0a = np.minimum(1.0, np.array([s.g00_accel_factor for s in st]))
    g0j = np.minimum(1.0, np.array([s.g00_jerk_factor for s in st]))
    uses_soft = np.array([m.uses_soft_accel_factor for m in ACCEL_MODES])[modes.mode]
    acc = lim.a_max[None, :] * np.where(uses_soft[:, None], soft_f[None, :], 1.0)
    acc = acc * np.where(path.rapid[:, None], g0a[None, :], 1.0)
    jerk = lim.j_max[None, :] * np.where(path.rapid[:, None], g0j[None, :], 1.0)
    return lim, acc, jerk


def _min_with_cause(candidates: list[tuple[np.ndarray, int]]) -> tuple[np.ndarray, np.ndarray]:
    """Smallest candidate per segment and its cause (the first of equal ones)."""
    vals = np.stack([c[0] for c in candidates], axis=1)
    arg = row_argmin(vals)
    codes = np.array([c[1] for c in candidates])
    return vals[np.arange(vals.shape[0]), arg], codes[arg]


def _accel_at(cap, A, D, P, Q, moving):
    """Largest a with D a + sqrt((P a)^2 + (Q cap^2)^2) <= A for every moving axis."""
    K = Q * (cap * cap)[:, None]
    A2K2 = np.maximum(A * A - K * K, 0.0)
    den = A * D + np.sqrt(P * P * A2K2 + D * D * K * K)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = np.where(den > 0, A2K2 / np.where(den > 0, den, 1.0), np.inf)
    a = np.where(moving, a, np.inf)
    return row_min(a)


def _jerk_at(cap, acc, J, D, P, Q, R, Rn, moving):
    """Largest j with D j + sqrt((P j + M)^2 + N^2) <= J, M = R cap^3,
    N = 3 Q cap acc + Rn cap^3 (``Rn``: normal jerk from a spiral's varying curvature)."""
    M = R * (cap ** 3)[:, None]
    N = 3.0 * Q * (cap * acc)[:, None] + Rn * (cap ** 3)[:, None]
    rest = np.maximum(J * J - M * M - N * N, 0.0)
    b = P * M + J * D
    disc = np.maximum(b * b + (P * P - D * D) * rest, 0.0)
    den = b + np.sqrt(disc)
    with np.errstate(divide="ignore", invalid="ignore"):
        j = np.where(den > 0, rest / np.where(den > 0, den, 1.0), np.inf)
    j = np.where(moving, j, np.inf)
    return row_min(j)


def segment_limits(path: Path, machine: Machine, modes: SegmentModes,
                   params: PlannerParameters) -> SegmentLimits:
    """Speed cap, tangential acceleration and jerk of every segment.

    Parameters
    ----------
    path : Path
    machine : Machine
    modes : SegmentModes
        Acceleration mode per segment (BRISK or SOFT).
    params : PlannerParameters
        The arc budget shares.

    Returns
    -------
    SegmentLimits
    """
    m = path.n_segments
    lim, A, J = _axis_factors(path, machine, modes)
    D, P, Q, R, Rn = axis_amplitudes(path)
    moving = moving_axes(D, P)
    inf = np.full(m, np.inf)
    soft = modes.jerk_limited
    with np.errstate(divide="ignore", invalid="ignore"):
        v_axis = row_min(np.where(moving, lim.v_max[None, :] / (D + P), np.inf))
        v_cent = row_min(np.where(Q > 0, np.sqrt(params.arc_centripetal_share * A / np.where(
            Q > 0, Q, 1.0)), np.inf))
    # the jerk terms bind SOFT segments only: worked out for those rows alone (row by
    # row the same numbers; a BRISK program skips them)
    sr = rows_where(soft)
    v_jerk = inf.copy()
    if sr is not None:
        with np.errstate(divide="ignore", invalid="ignore"):
            R3 = np.hypot(R[sr], Rn[sr])    # third-derivative amplitude (= R on circles)
            v_jerk[sr] = row_min(np.where(R3 > 0, np.cbrt(
                params.arc_jerk_velocity_share * J[sr] / np.where(R3 > 0, R3, 1.0)), np.inf))
    # one IPO cycle per interpolation block: per segment, except that a rounding inside
    # the blocks (G643) is part of its block (reference.core.rows.interpolation_lengths)
    v_ipo = interpolation_lengths(path) / machine.limits.t_ipo_s
    cap, cause = _min_with_cause([(path.feed, C.FEED), (v_axis, C.AXIS_VELOCITY),
                                  (v_cent, C.AXIS_ACCELERATION), (v_jerk, C.JERK),
                                  (v_ipo, C.IPO_CAP)])
    knee, share, cap, cause = _drive(path, machine, modes, lim, A, D, P, Q, moving, cap,
                                     cause, params)
    acc = _accel_at(cap, A, D, P, Q, moving)
    # SOFT: leave the jerk budget share for 3 |q''| v a
    jerk = inf.copy()
    if sr is not None:
        Qs, mv, cs = Q[sr], moving[sr], cap[sr]
        with np.errstate(divide="ignore", invalid="ignore"):
            a_j = row_min(np.where(mv & (Qs > 0), params.arc_jerk_accel_share * J[sr] / (
                3.0 * np.where(Qs > 0, Qs, 1.0) * np.maximum(cs, 1e-300)[:, None]), np.inf))
        acc[sr] = np.minimum(acc[sr], a_j)
        jerk[sr] = _jerk_at(cs, acc[sr], J[sr], D[sr], P[sr], Qs, R[sr], Rn[sr], mv)
    freq = row_min(np.where(moving, lim.frequency_hz[None, :], np.inf))
    if np.isfinite(knee).any():
        d = np.flatnonzero(np.isfinite(knee))
        acc_hi = _accel_at(cap[d], A[d] * share[d], D[d], P[d], Q[d], moving[d])
        knee_ratio = np.ones(m)
        with np.errstate(divide="ignore", invalid="ignore"):
            knee_ratio[d] = np.clip(acc_hi / acc[d], 0.0, 1.0)
    else:
        knee_ratio = np.ones(m)
    return SegmentLimits(cap=cap, cap_cause=cause, accel=acc, jerk=jerk, frequency=freq,
                         moving=moving, knee=knee, knee_ratio=knee_ratio)


def _drive(path: Path, machine: Machine, modes: SegmentModes, lim, A, D, P, Q, moving,
           cap: np.ndarray, cause: np.ndarray, params: PlannerParameters):
    """DRIVE: knee per segment (m,), the per-axis acceleration shares above it (m, n),
    and the caps and their causes with the centripetal limit at the reduced ``A_i``."""
    m, n = A.shape
    knee = np.full(m, np.inf)
    drive = modes.mode == MODE_CODE["DRIVE"]
    if not drive.any():
        return knee, np.ones((m, n)), cap, cause
    st = [machine.settings_of(a) for a in path.axes]
    sp = np.array([x.accel_reduction_speed_point for x in st])
    fac = np.array([x.accel_reduction_factor for x in st])
    kind = np.array([x.accel_type_drive for x in st])
    knee, share = drive_reduction(drive, moving, D + P, cap, lim.v_max, sp, fac, kind)
    # centripetal above the knee with the reduced accelerations, not below the knee
    with np.errstate(divide="ignore", invalid="ignore"):
        v_cent = row_min(np.where(Q > 0, np.sqrt(params.arc_centripetal_share * A * share
                                                 / np.where(Q > 0, Q, 1.0)), np.inf))
    lower = np.isfinite(knee) & (v_cent < cap)
    new_cap = np.where(lower, np.maximum(v_cent, knee), cap)
    cause = np.where(new_cap < cap, C.AXIS_ACCELERATION, cause)
    knee = np.where(knee < new_cap, knee, np.inf)
    share = np.where(np.isfinite(knee)[:, None], share, 1.0)
    return knee, share, new_cap, cause
