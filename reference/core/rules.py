"""The rulebook: every rule that more than one side applies, written once.

The heuristic (``reference.planner``), the oracle (its grid problem *and* its lower-bound
relaxation, ``optimal``), the checker (:func:`reference.core.constraints.check_profile`)
and the comparison (``compare``) import these functions; none of them keeps a copy. A
second copy of a rule is how a certificate breaks: the checker accepts a profile that the
oracle's relaxation forbids, and the "lower bound" is no longer below the truth
(tests/test_architecture.py fails when a module outside ``reference/core`` redefines
a name defined here).

Rules
-----
tangency
    A break is *tangential* when the angle between the unit tangents on its two sides is
    at most :data:`~reference.core.tolerances.TANGENT_TOL_RAD`. Tangential breaks have no
    corner rule: the axis velocity jump there is taken as zero.
junction velocity jump (MD32310)
    Crossing a non-tangential break at path speed ``v`` steps axis ``i``'s velocity by
    ``v |t_out_i - t_in_i|``. The checker accepts a step up to the allowance
    ``A_i (ovl_i - 1) T_ipo`` (times ``1 + RATIO_TOL``) and, as standstill, any step up to
    :data:`~reference.core.tolerances.VEL_TOL_MM_S`.
    :func:`junction_speed_cap` turns that into a path-speed cap in two flavours: the
    *feasible* cap (every speed at or below it passes the checker, with a round-off
    margin) and the *relaxed* cap (no speed above it passes the checker). A lower bound
    uses the relaxed one, a planner that must pass the checker the feasible one.
acceleration steps (jerk)
    A jerk-limited motion planned along the path (:data:`STEPS_AT_BREAKS`) may step its
    axis accelerations only where the geometry forces it: at a segment break (the
    tangent or the curvature vector jumps) and at the path ends (the surroundings rest
    with zero acceleration), each step spread over one IPO cycle and held to
    ``Jstep_i T_ipo`` (:func:`step_jerk_limit`); inside a segment its acceleration is
    continuous up to round-off (:data:`~reference.core.tolerances.ACCEL_CONTINUITY_TOL_REL`).
    The jerk lower bound (:mod:`optimal.jerk.lower`) is proved for exactly this class,
    and the checker judges planned profiles by it. A trajectory *sampled* at the IPO cycle
    (a recording, :data:`STEPS_SPREAD`) steps at every sample; there each step counts as
    the jerk ``|delta A_i| / T_ipo``.
curvature jump
    A break has a curvature jump when some component of ``q''`` differs by more than
    :data:`~reference.core.tolerances.CURVATURE_JUMP_TOL_PER_MM` across it; then the
    axis acceleration step, spread over one IPO cycle, is held to PATH_TRANS_JERK_LIM
    instead of MAX_AX_JERK (SOFT).
axis kinematics
    Along a path ``q(s)`` moved with ``s(t)``: ``dq/dt = q' v``,
    ``d2q/dt2 = q' a + q'' v^2``, ``d3q/dt3 = q' j + 3 q'' v a + q''' v^3``.
"""

from __future__ import annotations

import numpy as np

from .arrays import row_any, row_argmin, row_min, row_norms
from .tolerances import (CURVATURE_JUMP_TOL_PER_MM, RATIO_TOL, ROUNDOFF_MARGIN_REL,
                         TANGENT_TOL_RAD, VEL_TOL_MM_S)

#: The two flavours of a cap derived from a checker rule (see :func:`junction_speed_cap`).
FEASIBLE = "feasible"
RELAXED = "relaxed"

#: Where a planned motion's acceleration may step: segment breaks and path ends only
#: (module docstring, "acceleration steps").
STEPS_AT_BREAKS = "breaks"
#: A trajectory sampled at the IPO cycle: every sample's step is a jerk spread over it.
STEPS_SPREAD = "spread"


# ============================================================================ tangency
def junction_angle(t_in: np.ndarray, t_out: np.ndarray) -> np.ndarray:
    """Angle between the tangents before and after each break, rad.

    Uses ``2 atan(|u1 - u2| / |u1 + u2|)`` of the unit tangents, accurate to round-off
    for tiny angles (``arccos`` of the dot product loses half the digits there: its
    resolution near 0 is about 2e-8 rad, the size of the tangency threshold itself).

    Parameters
    ----------
    t_in, t_out : numpy.ndarray, shape (k, n)
        Tangents ``q'`` at the end of the segment before and the start of the one after
        each break (any non-zero length).

    Returns
    -------
    numpy.ndarray, shape (k,)
        Angles in [0, pi].
    """
    t_in = np.asarray(t_in, dtype=np.float64)
    t_out = np.asarray(t_out, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        u1 = t_in / _norms(t_in)[..., None]
        u2 = t_out / _norms(t_out)[..., None]
    u1 = np.nan_to_num(u1, copy=False)
    u2 = np.nan_to_num(u2, copy=False)
    return 2.0 * np.arctan2(_norms(u1 - u2), _norms(u1 + u2))


def _norms(x: np.ndarray) -> np.ndarray:
    """``numpy.linalg.norm(x, axis=-1)`` (the same numbers; faster on (k, n) arrays)."""
    return row_norms(x) if x.ndim == 2 else np.linalg.norm(x, axis=-1)


def is_tangential(t_in: np.ndarray, t_out: np.ndarray, flavour: str = FEASIBLE) -> np.ndarray:
    """Whether each break counts as tangential (no corner rule there).

    Parameters
    ----------
    t_in, t_out : numpy.ndarray, shape (k, n)
        Tangents on both sides of the breaks.
    flavour : {"feasible", "relaxed"}
        The checker's own classification is ``angle <= TANGENT_TOL_RAD``. A planner that
        must pass the checker uses ``"feasible"`` (the threshold shrunk by
        :data:`ROUNDOFF_MARGIN_REL`, so a break the planner calls tangential is
        tangential to the checker even if both evaluate the angle with different
        round-off); a lower bound uses ``"relaxed"`` (the threshold grown by the same
        margin: every break the checker might call tangential is free).

    Returns
    -------
    numpy.ndarray of bool, shape (k,)
    """
    scale = 1.0 - ROUNDOFF_MARGIN_REL if flavour == FEASIBLE else 1.0 + ROUNDOFF_MARGIN_REL
    _flavour(flavour)
    return junction_angle(t_in, t_out) <= TANGENT_TOL_RAD * scale


# ================================================================ junction velocity jumps
def axis_velocity_jumps(t_in: np.ndarray, t_out: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Axis velocity steps ``v |t_out_i - t_in_i|`` when crossing breaks at speed ``v``.

    Zero at tangential breaks (:func:`is_tangential`, the checker's threshold).

    Parameters
    ----------
    t_in, t_out : numpy.ndarray, shape (k, n)
    v : numpy.ndarray, shape (k,)
        Path speed at each break, mm/s.

    Returns
    -------
    numpy.ndarray, shape (k, n)
        mm/s (deg/s for rotary axes).
    """
    dv = np.abs(np.asarray(t_out) - np.asarray(t_in)) * np.abs(np.asarray(v))[:, None]
    tangential = junction_angle(t_in, t_out) <= TANGENT_TOL_RAD
    return np.where(tangential[:, None], 0.0, dv)


def jump_ratio(dv: np.ndarray, allowance: np.ndarray) -> np.ndarray:
    """The checker's ratio of an axis velocity step to its allowance.

    A step of at most :data:`VEL_TOL_MM_S` is standstill-level (ratio 0); a larger one
    against a zero allowance (overload factor 1.0) has ratio ``inf``.

    Parameters
    ----------
    dv : numpy.ndarray, shape (k, n)
        Axis velocity steps, mm/s.
    allowance : numpy.ndarray, shape (n,) or (k, n)
        ``A_i (ovl_i - 1) T_ipo``, mm/s.

    Returns
    -------
    numpy.ndarray, shape (k, n)
    """
    allowance = np.broadcast_to(allowance, np.shape(dv))
    with np.errstate(divide="ignore", invalid="ignore"):
        r = dv / np.where(allowance > 0, allowance, 1.0)
    return np.where(dv <= VEL_TOL_MM_S, 0.0, np.where(allowance > 0, r, np.inf))


def junction_speed_cap(t_in: np.ndarray, t_out: np.ndarray, allowance: np.ndarray,
                       flavour: str, tangential: np.ndarray | None = None
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Path-speed cap at each break from the axis velocity-jump rule.

    The checker accepts crossing at ``v`` when, for every axis,
    ``v |dt_i| <= max(allowance_i (1 + RATIO_TOL), VEL_TOL_MM_S)``, or when the break is
    tangential. Hence

    * ``"relaxed"``: ``inf`` where the break may be tangential, else
      ``min_i max(allowance_i (1 + RATIO_TOL), VEL_TOL) / |dt_i|`` grown by
      :data:`ROUNDOFF_MARGIN_REL`: no speed above it passes the checker;
    * ``"feasible"``: ``inf`` only where the break is surely tangential, else
      ``min_i max(allowance_i, VEL_TOL (1 - margin)) / |dt_i|``: every speed at or below
      it passes, also when the checker re-evaluates the step with different round-off
      (observed: 1e-14 relative; the allowance is judged with RATIO_TOL to spare, the
      standstill floor exactly, hence the margin on the floor only). Caps at or below
      :data:`VEL_TOL_MM_S` become 0 (a stop).

    With an overload factor of 1.0 (allowance 0) the feasible cap is the standstill floor
    ``VEL_TOL / |dt|``: a near-tangent kink of 1e-6 rad may be crossed at a few mm/s,
    exactly as the checker allows and the relaxation assumes, so the two stay equal.

    Parameters
    ----------
    t_in, t_out : numpy.ndarray, shape (k, n)
        Tangents on both sides.
    allowance : numpy.ndarray, shape (n,)
        ``A_i (ovl_i - 1) T_ipo``, mm/s (``AxisArrays.jump``).
    flavour : {"feasible", "relaxed"}
    tangential : numpy.ndarray of bool, shape (k,), optional
        ``is_tangential(t_in, t_out, flavour)`` where the caller has it already (the
        same test, not repeated); computed when omitted.

    Returns
    -------
    v_cap : numpy.ndarray, shape (k,)
        mm/s, ``inf`` where no axis limits.
    axis : numpy.ndarray of int, shape (k,)
        Axis that sets the cap, -1 where none.
    """
    _flavour(flavour)
    t_in = np.asarray(t_in, dtype=np.float64)
    t_out = np.asarray(t_out, dtype=np.float64)
    k = t_in.shape[0]
    if k == 0:
        return np.zeros(0), np.zeros(0, dtype=np.int64)
    dt = np.abs(t_out - t_in)
    allowance = np.asarray(allowance, dtype=np.float64)
    if flavour == RELAXED:
        allow = np.maximum(allowance * (1.0 + RATIO_TOL), VEL_TOL_MM_S) * (1.0 + ROUNDOFF_MARGIN_REL)
    else:
        # the allowance itself is judged with RATIO_TOL to spare; the standstill floor
        # is judged exactly (dv <= VEL_TOL), so only the floor needs the margin
        allow = np.maximum(allowance, VEL_TOL_MM_S * (1.0 - ROUNDOFF_MARGIN_REL))
    with np.errstate(divide="ignore"):
        per_axis = np.where(dt > 0, allow[None, :] / np.where(dt > 0, dt, 1.0), np.inf)
    v = row_min(per_axis) if per_axis.shape[1] else np.full(k, np.inf)
    ax = np.where(np.isfinite(v), row_argmin(per_axis) if per_axis.shape[1] else -1, -1)
    if flavour == FEASIBLE:
        # a crossing at standstill speed is a stop: say so, rather than plan a corner
        # at 1e-7 mm/s that takes a second per nanometre
        v = np.where(v <= VEL_TOL_MM_S, 0.0, v)
    free = is_tangential(t_in, t_out, flavour) if tangential is None else tangential
    return np.where(free, np.inf, v), np.where(free, -1, ax).astype(np.int64)


# ====================================================================== curvature jumps
def curvature_jumps(k_in: np.ndarray, k_out: np.ndarray) -> np.ndarray:
    """Whether the curvature vector ``q''`` jumps across each break.

    Parameters
    ----------
    k_in, k_out : numpy.ndarray, shape (k, n)
        ``q''`` on both sides, 1/mm (deg/mm^2 for rotary axes).

    Returns
    -------
    numpy.ndarray of bool, shape (k,)
    """
    dk = np.abs(np.asarray(k_out) - np.asarray(k_in))
    jumps = dk > CURVATURE_JUMP_TOL_PER_MM
    return row_any(jumps) if jumps.ndim == 2 else np.any(jumps, axis=-1)


def step_jerk_limit(curvature_jump: np.ndarray, j_max: np.ndarray,
                    path_trans_jerk: np.ndarray) -> np.ndarray:
    """Jerk an axis acceleration step spread over one IPO cycle is held to, per break.

    PATH_TRANS_JERK_LIM where the curvature jumps, MAX_AX_JERK elsewhere.

    Parameters
    ----------
    curvature_jump : numpy.ndarray of bool, shape (k,)
    j_max, path_trans_jerk : numpy.ndarray, shape (n,)
        mm/s^3.

    Returns
    -------
    numpy.ndarray, shape (k, n)
    """
    return np.where(np.asarray(curvature_jump)[:, None], np.asarray(path_trans_jerk)[None, :],
                    np.asarray(j_max)[None, :])


def curvature_jump_speed_cap(k_in: np.ndarray, k_out: np.ndarray, path_trans_jerk: np.ndarray,
                             t_ipo: float) -> np.ndarray:
    """Path speed at which the centripetal step ``|dq''_i| v^2`` fits one IPO cycle.

    ``v <= min_i sqrt(PATH_TRANS_JERK_LIM_i T_ipo / |dq''_i|)`` over the axes whose
    curvature jumps (``inf`` where none does).

    Parameters
    ----------
    k_in, k_out : numpy.ndarray, shape (k, n)
    path_trans_jerk : numpy.ndarray, shape (n,)
        mm/s^3.
    t_ipo : float
        IPO cycle, s.

    Returns
    -------
    numpy.ndarray, shape (k,)
        mm/s.
    """
    dk = np.abs(np.asarray(k_out) - np.asarray(k_in))
    if dk.shape[0] == 0:
        return np.zeros(0)
    jumps = dk > CURVATURE_JUMP_TOL_PER_MM
    with np.errstate(divide="ignore", invalid="ignore"):
        v2 = np.where(jumps, np.asarray(path_trans_jerk)[None, :] * t_ipo
                      / np.where(jumps, dk, 1.0), np.inf)
    # one root per row: the root is monotone and correctly rounded, so the root of the
    # smallest square is the smallest root, bit for bit
    return np.sqrt(row_min(v2)) if v2.shape[1] else np.full(dk.shape[0], np.inf)


# ===================================================================== axis kinematics
def axis_velocity(dq: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``dq/dt = q' v``, shape (N, n), from ``dq`` (N, n) and ``v`` (N,), mm/s."""
    return dq * np.asarray(v)[:, None]


def axis_acceleration(dq: np.ndarray, ddq: np.ndarray, v: np.ndarray,
                      a: np.ndarray) -> np.ndarray:
    """``d2q/dt2 = q' a + q'' v^2``, shape (N, n), mm/s^2.

    Parameters
    ----------
    dq, ddq : numpy.ndarray, shape (N, n)
        ``q'`` (1) and ``q''`` (1/mm) at the samples.
    v, a : numpy.ndarray, shape (N,)
        Path speed (mm/s) and acceleration (mm/s^2).
    """
    v = np.asarray(v)
    return dq * np.asarray(a)[:, None] + ddq * (v * v)[:, None]


def axis_jerk(dq: np.ndarray, ddq: np.ndarray, dddq: np.ndarray, v: np.ndarray,
              a: np.ndarray, j: np.ndarray) -> np.ndarray:
    """``d3q/dt3 = q' j + 3 q'' v a + q''' v^3``, shape (N, n), mm/s^3.

    Parameters
    ----------
    dq, ddq, dddq : numpy.ndarray, shape (N, n)
        ``q'`` (1), ``q''`` (1/mm), ``q'''`` (1/mm^2).
    v, a, j : numpy.ndarray, shape (N,)
        Path speed, acceleration and jerk (mm/s, mm/s^2, mm/s^3).
    """
    v = np.asarray(v)
    return (dq * np.asarray(j)[:, None] + ddq * (3.0 * v * np.asarray(a))[:, None]
            + dddq * (v ** 3)[:, None])


def speed_caps(dq: np.ndarray, ddq: np.ndarray, v_max: np.ndarray,
               a_max: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Path-speed caps of a motion at constant path speed (``a = 0``) at sample points.

    ``v <= min_i V_i / |q'_i|`` (axis velocity) and ``v <= min_i sqrt(A_i / |q''_i|)``
    (centripetal axis acceleration); ``inf`` where no axis component is non-zero. These
    are the checker's velocity and acceleration rules with ``a = 0`` solved for ``v``.

    Parameters
    ----------
    dq, ddq : numpy.ndarray, shape (N, n)
        ``q'`` (1) and ``q''`` (1/mm).
    v_max, a_max : numpy.ndarray, shape (n,)
        mm/s and mm/s^2.

    Returns
    -------
    v_axis, v_centripetal : numpy.ndarray, shape (N,)
        mm/s.
    """
    adq, addq = np.abs(dq), np.abs(ddq)
    with np.errstate(divide="ignore", invalid="ignore"):
        v_axis = np.where(adq > 0, np.asarray(v_max)[None, :] / np.where(adq > 0, adq, 1.0),
                          np.inf)
        v_cen = np.where(addq > 0, np.sqrt(np.asarray(a_max)[None, :]
                                           / np.where(addq > 0, addq, 1.0)), np.inf)
    n = adq.shape[0]
    if adq.shape[1] == 0:
        return np.full(n, np.inf), np.full(n, np.inf)
    return v_axis.min(axis=1), v_cen.min(axis=1)


def _flavour(flavour: str) -> None:
    if flavour not in (FEASIBLE, RELAXED):
        raise ValueError(f"flavour must be {FEASIBLE!r} or {RELAXED!r}, got {flavour!r}")
