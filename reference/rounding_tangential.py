"""Corner rounding, part: G645 at tangential line-arc transitions with a curvature jump.

sinumerik-model 5.7: "At tangential transitions with a curvature jump (e.g. line to arc),
G645 also inserts rounding, using MD33120 PATH_TRANS_POS_TOL. That MD is used only at
tangential transitions"; "[M] At tangential transitions, G645 inserts a rounding block
only if the curvature jump would otherwise force the axis acceleration beyond its limit
(i.e. a velocity reduction)"; 5.8: "Insert only if this beats the non-rounded limit of
6.3". :func:`tangential_transitions` decides, per such transition, with the reasons
named as the corner rounding names its own (:data:`reference.core.rounding.
ROUNDING_REASONS`), and sizes the transition (:mod:`reference.core.transition`):

1. only a line into a circular arc or an arc into a line (both in the geometry axes,
   the arc a circle: no helix, no spiral); arc into arc is a model limit, named;
2. under BRISK no rounding: "Under BRISK only the acceleration limits apply (an
   acceleration step is allowed)" (6.3), so the curvature jump costs no speed;
3. ``v_g64`` = the curvature-jump rule at the transition (6.3, the shared
   :func:`reference.core.rules.curvature_jump_speed_cap`); if it is not below the
   programmed speed and the arc's own limits (centripetal, path jerk on the arc: what
   the heuristic grants a curved segment, :data:`reference.rounding.CENTRIPETAL_SHARE`
   and ``JERK_VELOCITY_SHARE``), G64 passes it without reduction: none;
4. the ramp length ``L`` from the tolerance: the deviation (in the arc's plane) may be
   at most ``min_i PATH_TRANS_POS_TOL_i / rho_i`` (``rho_i`` the axis' weight in the
   plane: an in-plane deviation ``p`` moves axis ``i`` by at most ``rho_i p``), G0 blocks
   times MD20560 G0_TOLERANCE_FACTOR (5.7); CTOL is not applied (5.7 names MD33120 as
   the tolerance of tangential transitions);
5. the block-length clamp (5.3, the G644 excerpt; ``c = rounding_length_clamp``): the
   rounding replaces at most ``c`` times each block (the line by ``line_trim ~ 1.6 L``,
   the arc by ``L/2``), so ``L`` is reduced until both fit; pieces at or below
   MIN_SEGMENT_LENGTH_MM: "rounding distance too small";
6. ``v_round`` = the speed the rounding allows (centripetal at ``1/R``, the path jerk
   ``rho_i |q'''| v^3`` with ``|q'''| <= hypot(c, 1/R^2)`` on the ramp, one IPO cycle per
   piece); inserted only if ``v_round > v_g64``, else "rounding would be slower than G64".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .core.arrays import row_min
from .core.geometry import KIND_CODES, Path
from .core.limits import AxisArrays
from .core.rounding import REASON_CODE
from .core.rules import curvature_jump_speed_cap
from .core.tolerances import MIN_SEGMENT_LENGTH_MM, MOVING_AXIS_TOL
from .core.transition import (PIECES, TransitionShape, ramp_for_deviation,
                              transition_rows, transition_shape)
from .machine import Machine

_LINE = KIND_CODES.index("line")
_ARC = KIND_CODES.index("arc")
_ROUNDING = KIND_CODES.index("rounding")

#: The line-length clamp is met by scaling ``L`` with ``cap / line_trim`` (the trim is
#: nearly proportional to ``L``); this many rounds, each scaled by :data:`CLAMP_MARGIN`
#: so the last lands inside. The trim's relative change from ``L`` to ``0.9 L`` is below
#: 1e-3 for ``L / R < 0.5``, so two rounds suffice; the rest are a guard.
CLAMP_ROUNDS = 6
#: Relative margin below the clamp each scaling aims at.
CLAMP_MARGIN = 1e-9


@dataclass(frozen=True, slots=True, eq=False)
class Transitions:
    """Decisions at the G645 tangential transitions given to :func:`tangential_transitions`,
    shape (k,) each (rows: :data:`reference.core.transition.PIECES` per inserted one).

    Attributes
    ----------
    reason : numpy.ndarray of int
        Code of :data:`reference.core.rounding.ROUNDING_REASONS` (0 = rounded).
    trim_in, trim_out : numpy.ndarray
        Length the rounding replaces of the segment before and after, mm (0 where none).
    shape : TransitionShape
        Sizes (meaningful where rounded).
    clamped : numpy.ndarray of bool
        ``L`` was cut by the block-length clamp.
    v_g64, v_round : numpy.ndarray
        Speed at the transition under G64 (curvature-jump rule) and through the
        rounding, mm/s (``nan`` where not evaluated).
    rows : dict
        Packed rows of the inserted transitions, in the order of ``reason == 0``.
    """

    reason: np.ndarray
    trim_in: np.ndarray
    trim_out: np.ndarray
    shape: TransitionShape
    clamped: np.ndarray
    v_g64: np.ndarray
    v_round: np.ndarray
    rows: dict



def line_arc_pairs(path: Path, a: np.ndarray):
    """The two segments at breaks ``a``/``a + 1`` as a line and an arc, when they are.

    Parameters
    ----------
    path : Path
    a : numpy.ndarray of int, shape (k,)
        Segment before each break.

    Returns
    -------
    b : numpy.ndarray of int, shape (k,)
        ``a + 1``.
    line_arc, arc_line : numpy.ndarray of bool, shape (k,)
        A line into an arc, an arc into a line.
    arc, line : numpy.ndarray of int, shape (k,)
        Which of the two is the arc and which the line (meaningful where either flag is
        set).
    """
    b = a + 1
    kind_a, kind_b = path.kind[a], path.kind[b]
    line_arc = (kind_a == _LINE) & (kind_b == _ARC)
    arc_line = (kind_a == _ARC) & (kind_b == _LINE)
    return b, line_arc, arc_line, np.where(line_arc, b, a), np.where(line_arc, a, b)

def tangential_transitions(path: Path, machine: Machine, a: np.ndarray, ka: np.ndarray,
                           accel: np.ndarray, centripetal_share: float,
                           jerk_share: float, time_loss) -> Transitions:
    """Decide and size G645's rounding at tangential transitions after segments ``a``.

    Parameters
    ----------
    path : Path
    machine : Machine
    a : numpy.ndarray of int, shape (k,)
        Segment before each transition (``a + 1`` after it); at least one is an arc.
    ka : numpy.ndarray of int, shape (k,)
        Block of segment ``a`` (the rounding is attributed to it).
    accel : numpy.ndarray of str, shape (k,)
        Acceleration mode of the blocks (both agree here).
    centripetal_share, jerk_share : float
        Shares of the axis acceleration and jerk granted to the curvature terms (the
        corner rounding's estimate, so both parts decide alike).
    time_loss : callable
        :func:`reference.rounding.corner_time_loss`, the corner rounding's estimate of
        the time a transition costs (passed in: that module imports this one).

    Returns
    -------
    Transitions
    """
    k = a.size
    b, line_arc, arc_line, arc, line = line_arc_pairs(path, a)
    reason = np.full(k, -1, dtype=np.int64)

    def decide(mask: np.ndarray, why: str) -> None:
        reason[(reason < 0) & mask] = REASON_CODE[why]

    decide(~(line_arc | arc_line),
           "tangential transition between arcs: rounding not modelled yet")
    circle = ((path.dradius[arc] == 0) & (path.sharpness[arc] == 0)
              & ~(np.abs(path.d.take(arc, axis=0)) > MOVING_AXIS_TOL).any(axis=1))
    decide(~circle, "tangential transition into a helix or spiral: rounding not "
           "modelled yet")
    decide(accel != "SOFT", "curvature jump allowed under BRISK (acceleration step)")

    lim = machine.limits.for_axes(path.axes)
    t_ipo = machine.limits.t_ipo_s
    # the canonical frame at the arc's end at the line (reference.core.transition)
    R = path.radius[arc]
    w = path.omega[arc]
    at = np.where(line_arc, 0.0, path.length[arc])
    phi = path.theta0[arc] + w * at
    E1, E2 = path.e1.take(arc, axis=0), path.e2.take(arc, axis=0)
    radial = E1 * np.cos(phi)[:, None] + E2 * np.sin(phi)[:, None]
    junction = path.origin.take(arc, axis=0) + R[:, None] * radial
    tangent = np.sign(w)[:, None] * (E2 * np.cos(phi)[:, None] - E1 * np.sin(phi)[:, None])
    along = np.where(line_arc[:, None], tangent, -tangent)
    inward = -radial
    rho = np.sqrt(along ** 2 + inward ** 2)          # each axis' weight in the arc's plane
    moving = rho > 0
    wr = np.where(moving, rho, 1.0)

    v_g64 = np.full(k, np.nan)
    v_round = np.full(k, np.nan)
    shape = _zero_shape(k)
    clamped = np.zeros(k, bool)
    o = np.flatnonzero(reason < 0)
    v_prog = v_c = np.zeros(0)
    if o.size:
        Ro = R[o]
        kappa = inward[o] / Ro[:, None]
        v_g64[o] = curvature_jump_speed_cap(np.zeros_like(kappa), kappa,
                                            lim.path_trans_jerk, t_ipo)
        v_prog = _programmed_speed(path, lim, a[o], b[o], along[o])
        v_c = _centripetal_speed(lim, Ro, moving[o], wr[o], centripetal_share)
        # the arc's own path-jerk limit rho_i v^3 / R^2 <= share J_i
        v_j = _jerk_speed(lim, 1.0 / (Ro * Ro), moving[o], wr[o], jerk_share)
        sub = np.zeros(k, bool)
        v_arc = np.minimum(v_prog, np.minimum(v_c, v_j))
        sub[o] = ~(v_g64[o] < v_arc)
        decide(sub, "G64 passes the curvature jump without reduction")
        keep = reason[o] < 0
        o, v_prog, v_c, v_arc = o[keep], v_prog[keep], v_c[keep], v_arc[keep]
    if o.size:
        Ro = R[o]
        tol = np.array([machine.settings_of(ax).path_trans_pos_tol_mm for ax in path.axes])
        with np.errstate(divide="ignore"):
            dev = row_min(np.where(moving[o], tol[None, :] / wr[o], np.inf))
        g0 = path.rapid[a[o]] & path.rapid[b[o]]
        dev = dev * np.where(g0, machine.channel.g0_tolerance_factor, 1.0)
        ramp = ramp_for_deviation(Ro, dev)
        c = machine.channel.rounding_length_clamp
        cap_arc = 2.0 * c * path.length[arc[o]]
        cap_line = c * path.length[line[o]]
        cut = ramp > cap_arc
        ramp = np.minimum(ramp, cap_arc)
        sh = transition_shape(Ro, ramp)
        for _ in range(CLAMP_ROUNDS):
            over = sh.line_trim > cap_line
            if not over.any():
                break
            cut |= over
            ramp = np.where(over, ramp * (1.0 - CLAMP_MARGIN) * cap_line / sh.line_trim,
                            ramp)
            sh = transition_shape(Ro, ramp)
        clamped[o] = cut
        sub = np.zeros(k, bool)
        sub[o] = ((sh.line_trim > cap_line) | ~(sh.piece > MIN_SEGMENT_LENGTH_MM)
                  | ~(sh.ramp > MIN_SEGMENT_LENGTH_MM))
        decide(sub, "rounding distance too small")
        # the rounding's speed: centripetal at 1/R (the S curves less), path jerk with
        # |q'''| <= hypot(c, 1/R^2) (the S pieces have the same rate c and less
        # curvature), one IPO cycle per piece (5.3), the programmed speed
        v_j = _jerk_speed(lim, np.hypot(sh.rate, 1.0 / (Ro * Ro)), moving[o], wr[o],
                          jerk_share)
        v_round[o] = np.minimum(np.minimum(v_prog, np.minimum(v_c, v_j)),
                                np.minimum(sh.piece, sh.ramp) / t_ipo)
        # 5.2 group 2 "rounding would slow the program down", 5.8 "insert only if this
        # beats the non-rounded limit": the corner rounding's time estimate, each side
        # ramping to its own speed (the line to the programmed one, the arc to its own
        # limit) from the transition speed; the rounding is passed at v_round over its
        # length and replaces line_trim of the line and L/2 of the arc
        la = line_arc[o]
        v_line, acc, jerk = v_prog, *_path_dynamics(lim, along[o])
        v_in, v_out = np.where(la, v_line, v_arc), np.where(la, v_arc, v_line)
        cut_in = np.where(la, sh.line_trim, sh.arc_trim)
        cut_out = np.where(la, sh.arc_trim, sh.line_trim)
        loss_round = time_loss(v_in, v_out, v_round[o], acc, acc, jerk, jerk, sh.length,
                               cut_in, cut_out)
        loss_g64 = time_loss(v_in, v_out, v_g64[o], acc, acc, jerk, jerk, 0.0, 0.0)
        sub[:] = False
        sub[o] = ~((v_round[o] > v_g64[o]) & (loss_round < loss_g64))
        decide(sub, "rounding would be slower than G64")
        shape = _scatter_shape(sh, o, k)
    reason[reason < 0] = REASON_CODE["rounded"]
    ins = reason == 0
    trim_line = np.where(ins, shape.line_trim, 0.0)
    trim_arc = np.where(ins, shape.arc_trim, 0.0)
    trim_in = np.where(line_arc, trim_line, trim_arc)
    trim_out = np.where(line_arc, trim_arc, trim_line)
    i = np.flatnonzero(ins)
    rows = transition_rows(junction[i], along[i], inward[i], _take_shape(shape, i),
                           arc_line[i], ka[i], _ROUNDING)
    return Transitions(reason, trim_in, trim_out, shape, clamped & ins, v_g64, v_round,
                       rows)


def _programmed_speed(path: Path, lim: AxisArrays, a: np.ndarray, b: np.ndarray,
                      along: np.ndarray) -> np.ndarray:
    """Programmed speed at the transitions: the lower feed and the axis velocities along
    the common tangent, mm/s, shape (k,)."""
    with np.errstate(divide="ignore"):
        v_axis = row_min(np.where(np.abs(along) > 0, lim.v_max[None, :] / np.abs(along),
                                  np.inf))
    return np.minimum(np.minimum(path.feed[a], path.feed[b]), v_axis)


def _centripetal_speed(lim: AxisArrays, radius: np.ndarray, moving: np.ndarray,
                       w: np.ndarray, share: float) -> np.ndarray:
    """``min_i sqrt(share A_i R / rho_i)``: centripetal limit at curvature ``1/R`` in a
    plane of axis weights ``rho`` (``w`` = ``rho`` where moving), mm/s, shape (k,)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return row_min(np.where(moving, np.sqrt(share * lim.a_max[None, :]
                                                * radius[:, None] / w), np.inf))


def _jerk_speed(lim: AxisArrays, q3: np.ndarray, moving: np.ndarray, w: np.ndarray,
                share: float) -> np.ndarray:
    """``min_i (share J_i / (rho_i |q'''|))^(1/3)``: the path-jerk limit ``rho_i |q'''|
    v^3 <= share J_i`` on a piece whose third path derivative is at most ``q3``, mm/s."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return row_min(np.where(moving, np.cbrt(share * lim.j_max[None, :]
                                                / (w * q3[:, None])), np.inf))


def _path_dynamics(lim: AxisArrays, along: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Path acceleration and jerk along the common tangent ``min_i A_i / |t_i|``,
    ``min_i J_i / |t_i|``, mm/s^2 and mm/s^3, shape (k,) each (the transitions are SOFT)."""
    t = np.abs(along)
    with np.errstate(divide="ignore"):
        return (row_min(np.where(t > 0, lim.a_max[None, :] / t, np.inf)),
                row_min(np.where(t > 0, lim.j_max[None, :] / t, np.inf)))


def _zero_shape(k: int) -> TransitionShape:
    return TransitionShape(*(np.zeros(k) for _ in TransitionShape.__slots__))


def _take_shape(shape: TransitionShape, i: np.ndarray) -> TransitionShape:
    return TransitionShape(*(getattr(shape, f)[i] for f in TransitionShape.__slots__))


def _scatter_shape(part: TransitionShape, o: np.ndarray, k: int) -> TransitionShape:
    out = []
    for f in TransitionShape.__slots__:
        arr = np.zeros(k)
        arr[o] = getattr(part, f)
        out.append(arr)
    return TransitionShape(*out)


__all__ = ["PIECES", "Transitions", "tangential_transitions"]
