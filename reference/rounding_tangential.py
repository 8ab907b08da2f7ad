"""Corner rounding, part: G645 at tangential line-arc transitions with a curvature jump.

sinumerik-model 5.7: "At tangential transitions with a curvature jump (e.g. line to arc),
G645 also inserts rounding, using MD33120 PATH_TRANS_POS_TOL. That MD is used only at
tangential transitions"; "[M] At tangential transitions, G645 inserts a rounding block
only if the curvature jump would otherwise force the axis acceleration beyond its limit
(i.e. a velocity reduction)"; 5.8: "Insert only if this beats the non-rounded limit of
6.3". :func:`tangential_transitions` decides, per such transition, with the reasons
named as the corner rounding names its own (:data:`reference.core.rounding.
ROUNDING_REASONS`), and sizes the transition (:mod:`reference.core.transition`):

1. a line into a circular arc or an arc into a line (both in the geometry axes, the arc
   a circle: no helix, no spiral), an S-bend: a circle into a tangent circle in the
   same plane curving the other way (:mod:`reference.core.transition_sbend`, six
   clothoid pieces through zero curvature), or a circle into a tangent circle in the
   same plane curving the same way with another radius
   (:mod:`reference.core.transition_samedir`, four pieces through zero curvature);
   arcs in different planes are named, a model limit (the transitions are plane
   curves), and so are helices and spirals;
2. under BRISK no rounding: "Under BRISK only the acceleration limits apply (an
   acceleration step is allowed)" (6.3), so the curvature jump costs no speed;
3. ``v_g64`` = the curvature-jump rule at the transition (6.3, the shared
   :func:`reference.core.rules.curvature_jump_speed_cap`); if it is not below the
   programmed speed and the arc's own limits (centripetal, path jerk on the arc: what
   the heuristic grants a curved segment, :data:`reference.rounding.CENTRIPETAL_SHARE`
   and ``JERK_VELOCITY_SHARE``; between two arcs both arcs'), G64 passes it without
   reduction: none;
4. the ramp length ``L`` from the tolerance: the deviation (in the arc's plane) may be
   at most ``min_i PATH_TRANS_POS_TOL_i / rho_i`` (``rho_i`` the axis' weight in the
   plane: an in-plane deviation ``p`` moves axis ``i`` by at most ``rho_i p``), G0 blocks
   times MD20560 G0_TOLERANCE_FACTOR (5.7); CTOL is not applied (5.7 names MD33120 as
   the tolerance of tangential transitions);
5. the block-length clamp (5.3, the G644 excerpt; ``c = rounding_length_clamp``): the
   rounding replaces at most ``c`` times each block (the line by ``line_trim ~ 1.6 L``,
   the arc by ``L/2``; between two arcs each arc by its trim), so ``L`` is reduced
   (between two arcs the rate raised) until both fit; pieces at or below
   MIN_SEGMENT_LENGTH_MM:
   "rounding distance too small";
6. ``v_round`` = the speed the rounding allows (centripetal at its smallest radius:
   ``R`` at a line-arc transition, the peak ``1/(c L_s)`` of the S or the pair between
   two arcs (or the sharper arc, where that is smaller); the path
   jerk ``rho_i |q'''| v^3`` with ``|q'''| <= hypot(c, 1/r_min^2)``, one IPO cycle per
   piece); inserted only if ``v_round > v_g64`` and the corner rounding's time estimate
   favours it (each side at its speed and one segment per IPO cycle, and what is left of
   a segment cut from both ends judged with its IPO cycle too, :func:`_leftovers`), else
   "rounding would be slower than G64".
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from functools import partial

import numpy as np

from .core.arrays import row_any, row_min
from .core.geometry import KIND_CODES, Path
from .core.limits import AxisArrays
from .core.rounding import REASON_CODE, break_windows, leftovers
from .core.rules import FEASIBLE, curvature_jump_speed_cap, is_tangential
from .core.tolerances import MIN_SEGMENT_LENGTH_MM, MOVING_AXIS_TOL
from .core.transition import (PIECES, TransitionShape, ramp_for_deviation,
                              transition_rows, transition_shape)
from .core.transition_samedir import (SAMEDIR_PIECES, samedir_canonical,
                                      samedir_for_deviation, samedir_measured,
                                      samedir_rows, samedir_shape)
from .core.transition_sbend import (SBEND_PIECES, not_above_aim, sbend_for_deviation,
                                    sbend_measured, sbend_rows, sbend_shape, scatter, take)
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
#: Largest factor one clamp round raises an S-bend's rate by (a transition that found
#: no landing heading has no trims to scale by: it is raised by this much).
RATE_RAISE_MAX = 1e3
#: Two-arc transitions from which the sizing runs the compiled deviation search
#: (:mod:`reference.transition_kernel`) even before it is loaded: loading numba and the
#: cached kernel costs about 0.5 s once per process, what the vectorised searches cost
#: on some 2 10^4 transitions; once it is loaded every size uses it (the same numbers).
SEARCH_COMPILED_MIN = 20_000
_KERNEL = __name__.rsplit(".", 1)[0] + ".transition_kernel"
#: Named where a tangential transition next to an arc is not between a line and an arc
#: or two arcs (an inserted block's segment).
_BETWEEN_ARCS = "tangential transition between arcs: rounding not modelled yet"
#: Named where two tangent circular arcs lie in different planes: the transitions
#: (:mod:`reference.core.transition_sbend`, :mod:`reference.core.transition_samedir`)
#: are plane curves built in the arcs' one plane; a transition between planes would
#: need a space curve (torsion), which the path's pieces do not have.
_OTHER_PLANES = ("tangential transition between arcs in different planes: rounding not "
                 "modelled (model limit)")


@dataclass(frozen=True, slots=True, eq=False)
class Transitions:
    """Decisions at the G645 tangential transitions given to :func:`tangential_transitions`,
    shape (k,) each unless said.

    Attributes
    ----------
    reason : numpy.ndarray of int
        Code of :data:`reference.core.rounding.ROUNDING_REASONS` (0 = rounded).
    trim_in, trim_out : numpy.ndarray
        Length the rounding replaces of the segment before and after, mm (0 where none).
    length, deviation, radius : numpy.ndarray
        Length of the rounding, its largest distance from the programmed contour and its
        smallest radius of curvature, mm (0 where none).
    clamped : numpy.ndarray of bool
        The rounding was cut by the block-length clamp.
    v_g64, v_round : numpy.ndarray
        Speed at the transition under G64 (curvature-jump rule) and through the
        rounding, mm/s (``nan`` where not evaluated).
    n_rows : numpy.ndarray of int, shape (r,)
        Rows per inserted transition (:data:`PIECES` line-arc, :data:`SBEND_PIECES`
        S-bend, :data:`SAMEDIR_PIECES` arcs curving the same way), in the order of
        ``reason == 0``.
    rows : dict
        Packed rows of the inserted transitions, in the order of ``reason == 0``.
    """

    reason: np.ndarray
    trim_in: np.ndarray
    trim_out: np.ndarray
    length: np.ndarray
    deviation: np.ndarray
    radius: np.ndarray
    clamped: np.ndarray
    v_g64: np.ndarray
    v_round: np.ndarray
    n_rows: np.ndarray
    rows: dict



def line_arc_pairs(path: Path, a: np.ndarray):
    """The two segments at breaks ``a``/``a + 1`` as a line and an arc, or two arcs, when
    they are; the one classification of the G645 transitions and of the arc corners.

    Parameters
    ----------
    path : Path
    a : numpy.ndarray of int, shape (k,)
        Segment before each break.

    Returns
    -------
    b : numpy.ndarray of int, shape (k,)
        ``a + 1``.
    line_arc, arc_line, arc_arc : numpy.ndarray of bool, shape (k,)
        A line into an arc, an arc into a line, an arc into an arc.
    arc, line : numpy.ndarray of int, shape (k,)
        Which of the two is the arc and which the line (meaningful where a flag is set;
        two arcs: the first and the second).
    circle : numpy.ndarray of bool, shape (k,)
        Its arc (both, for two arcs) is a circular arc: no spiral, clothoid or helical
        lead.
    """
    b = a + 1
    kind_a, kind_b = path.kind[a], path.kind[b]
    line_arc = (kind_a == _LINE) & (kind_b == _ARC)
    arc_line = (kind_a == _ARC) & (kind_b == _LINE)
    arc_arc = (kind_a == _ARC) & (kind_b == _ARC)
    arc, line = np.where(line_arc, b, a), np.where(line_arc, a, b)

    def is_circle(i: np.ndarray) -> np.ndarray:
        return ((path.dradius[i] == 0) & (path.sharpness[i] == 0)
                & ~row_any(np.abs(path.d.take(i, axis=0)) > MOVING_AXIS_TOL))

    circle = is_circle(arc) & np.where(arc_arc, is_circle(b), True)
    return b, line_arc, arc_line, arc_arc, arc, line, circle

def tangential_transitions(path: Path, machine: Machine, a: np.ndarray, ka: np.ndarray,
                           accel: np.ndarray, centripetal_share: float,
                           jerk_share: float, time_loss,
                           windows: tuple[np.ndarray, np.ndarray] | None = None
                           ) -> Transitions:
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

    windows : tuple of numpy.ndarray, shape (m + 1,) each, optional
        Per segment break, the path positions where the corner rounding already decided
        there starts and ends (both the break's own position where none), mm: what a
        transition leaves of a segment is judged with them (:func:`_leftovers`).

    Returns
    -------
    Transitions
    """
    k = a.size
    b, line_arc, arc_line, arc_arc, arc, line, circle = line_arc_pairs(path, a)
    reason = np.full(k, -1, dtype=np.int64)

    def decide(mask: np.ndarray, why: str) -> None:
        reason[(reason < 0) & mask] = REASON_CODE[why]

    decide(~(line_arc | arc_line | arc_arc), _BETWEEN_ARCS)
    decide(~circle, "tangential transition into a helix or spiral: rounding not "
           "modelled yet")
    decide(accel != "SOFT", "curvature jump allowed under BRISK (acceleration step)")

    lim = machine.limits.for_axes(path.axes)
    t_ipo = machine.limits.t_ipo_s
    # the canonical frame at the arc's end at the line (reference.core.transition);
    # between two arcs at the first arc's end (reference.core.transition_sbend)
    R = path.radius[arc]
    w = path.omega[arc]
    at = np.where(line_arc, 0.0, path.length[arc])
    phi = path.theta0[arc] + w * at
    E1, E2 = path.e1.take(arc, axis=0), path.e2.take(arc, axis=0)
    radial = E1 * np.cos(phi)[:, None] + E2 * np.sin(phi)[:, None]
    junction = path.origin.take(arc, axis=0) + R[:, None] * radial
    tangent = np.sign(w)[:, None] * (E2 * np.cos(phi)[:, None] - E1 * np.sin(phi)[:, None])
    along = np.where(line_arc[:, None] | arc_arc[:, None], tangent, -tangent)
    inward = -radial
    # the second arc's normal at its start (the shared test of two directions): an
    # S-bend curves the other way in the plane (normals opposite), arcs curving the same
    # way have one normal; any other pair lies in two planes (_OTHER_PLANES)
    inward_b = inward.copy()
    sbend, samedir = np.zeros(k, bool), np.zeros(k, bool)
    aa = np.flatnonzero(arc_arc & (reason < 0))
    if aa.size:
        th_b = path.theta0[b[aa]]
        inward_b[aa] = -(path.e1.take(b[aa], axis=0) * np.cos(th_b)[:, None]
                         + path.e2.take(b[aa], axis=0) * np.sin(th_b)[:, None])
        sbend[aa] = is_tangential(inward[aa], -inward_b[aa], FEASIBLE)
        samedir[aa] = is_tangential(inward[aa], inward_b[aa], FEASIBLE)
    decide(arc_arc & ~sbend & ~samedir, _OTHER_PLANES)
    two = sbend | samedir
    R_b = np.where(two, path.radius[b], R)          # the second arc (= R at a line)
    rho = np.sqrt(along ** 2 + inward ** 2)          # each axis' weight in the arc's plane
    moving = rho > 0
    wr = np.where(moving, rho, 1.0)

    v_g64 = np.full(k, np.nan)
    v_round = np.full(k, np.nan)
    trim_in, trim_out = np.zeros(k), np.zeros(k)
    length, deviation, radius = np.zeros(k), np.zeros(k), np.zeros(k)
    clamped = np.zeros(k, bool)
    o = np.flatnonzero(reason < 0)
    # the transitions between two arcs: (which, shape, rows function, rows each) per
    # kind sized
    la_shape, groups = _zero_shape(0), []
    la_at = np.zeros(0, np.int64)
    if o.size:
        Ro = R[o]
        kappa = inward[o] / Ro[:, None]
        k_in = np.where(two[o, None], kappa, 0.0)
        k_out = np.where(two[o, None], inward_b[o] / R_b[o, None], kappa)
        v_g64[o] = curvature_jump_speed_cap(k_in, k_out, lim.path_trans_jerk, t_ipo)
        v_prog = _programmed_speed(path, lim, a[o], b[o], along[o])
        # each arc's own limits: centripetal, and path jerk rho_i v^3 / R^2 <= share J_i
        v_arc_a = np.minimum(v_prog, np.minimum(
            _centripetal_speed(lim, Ro, moving[o], wr[o], centripetal_share),
            _jerk_speed(lim, 1.0 / (Ro * Ro), moving[o], wr[o], jerk_share)))
        Rbo = R_b[o]
        v_arc_b = np.minimum(v_prog, np.minimum(
            _centripetal_speed(lim, Rbo, moving[o], wr[o], centripetal_share),
            _jerk_speed(lim, 1.0 / (Rbo * Rbo), moving[o], wr[o], jerk_share)))
        sub = np.zeros(k, bool)
        sub[o] = ~(v_g64[o] < np.minimum(v_arc_a, v_arc_b))
        decide(sub, "G64 passes the curvature jump without reduction")
        keep = reason[o] < 0
        o, v_prog, v_arc_a, v_arc_b = o[keep], v_prog[keep], v_arc_a[keep], v_arc_b[keep]
    if o.size:
        tol = np.array([machine.settings_of(ax).path_trans_pos_tol_mm for ax in path.axes])
        with np.errstate(divide="ignore"):
            dev = row_min(np.where(moving[o], tol[None, :] / wr[o], np.inf))
        g0 = path.rapid[a[o]] & path.rapid[b[o]]
        dev = dev * np.where(g0, machine.channel.g0_tolerance_factor, 1.0)
        c = machine.channel.rounding_length_clamp
        # per open transition: the rounding's trims, length, smallest radius, curvature
        # rate, shortest piece, deviation (line-arc, S-bend and same-way arcs sized
        # apart, decided alike below)
        cut_in, cut_out, rlen, rmin, rate, piece, devo = (np.zeros(o.size)
                                                          for _ in range(7))
        small, cut = np.zeros(o.size, bool), np.zeros(o.size, bool)
        la = ~two[o]
        la_at = o[la]
        if la_at.size:
            sh, cut_la, small_la = _size_line_arc(path, R, arc, line, la_at, dev[la], c)
            la_shape = sh
            lin = line_arc[la_at]
            cut_in[la] = np.where(lin, sh.line_trim, sh.arc_trim)
            cut_out[la] = np.where(lin, sh.arc_trim, sh.line_trim)
            rlen[la], rmin[la], rate[la] = sh.length, sh.radius, sh.rate
            piece[la] = np.minimum(sh.piece, sh.ramp)
            small[la], cut[la], devo[la] = small_la, cut_la, sh.deviation
        search, newton, pieces = _compiled_parts(int(np.sum(sbend[o] | samedir[o])))
        for kind, sized, shape_of, measured, canon, to_rows, n_p in (
                (sbend, partial(sbend_for_deviation, search=search), sbend_shape,
                 partial(sbend_measured, search=search), None, sbend_rows, SBEND_PIECES),
                (samedir, partial(samedir_for_deviation, search=search, newton=newton,
                                  pieces=pieces),
                 partial(samedir_shape, newton=newton),
                 partial(samedir_measured, search=search, pieces=pieces),
                 partial(samedir_canonical, newton=newton),
                 partial(samedir_rows, pieces=pieces), SAMEDIR_PIECES)):
            sel = kind[o]
            at = o[sel]
            if not at.size:
                continue
            sh, cut_aa, small_aa = _size_arcs(path, R, R_b, a, b, at, dev[sel], c, sized,
                                              shape_of, measured, canon)
            groups.append((at, sh, to_rows, n_p))
            cut_in[sel], cut_out[sel] = sh.trim_in, sh.trim_out
            rlen[sel], rmin[sel], rate[sel] = sh.length, sh.min_radius, sh.rate
            piece[sel] = np.minimum(np.minimum(sh.ramp_in, sh.ramp_out), sh.piece)
            small[sel], cut[sel], devo[sel] = small_aa, cut_aa, sh.deviation
        clamped[o] = cut
        sub = np.zeros(k, bool)
        sub[o] = small
        decide(sub, "rounding distance too small")
        # the rounding's speed: centripetal at its smallest radius (line-arc: the arc's,
        # the S curves less; between arcs: the peak of the S or pair, or the sharper
        # arc), path jerk with |q^(3)| <=
        # hypot(c, 1/r_min^2) (every piece has the rate c), one IPO cycle per piece
        # (5.3), the programmed speed
        v_c = _centripetal_speed(lim, rmin, moving[o], wr[o], centripetal_share)
        v_j = _jerk_speed(lim, np.hypot(rate, 1.0 / (rmin * rmin)), moving[o], wr[o],
                          jerk_share)
        v_round[o] = np.minimum(np.minimum(v_prog, np.minimum(v_c, v_j)), piece / t_ipo)
        # 5.2 group 2 "rounding would slow the program down", 5.8 "insert only if this
        # beats the non-rounded limit": the corner rounding's time estimate, each side
        # ramping to its own speed (a line to the programmed one, an arc to its own
        # limit) from the transition speed; the rounding is passed at v_round over its
        # length and replaces cut_in before and cut_out after the transition
        lin = line_arc[o]
        acc, jerk = _path_dynamics(lim, along[o])
        # each side at most one segment per IPO cycle as well (5.3), as the corner
        # rounding's estimate (reference.rounding._line_speeds)
        v_in = np.minimum(np.where(lin, v_prog, v_arc_a), path.length[a[o]] / t_ipo)
        v_out = np.minimum(np.where(lin, v_arc_a, np.where(two[o], v_arc_b, v_prog)),
                           path.length[b[o]] / t_ipo)
        # what is left of each segment once every rounding beside it is in (the corner
        # roundings decided, the other open transitions as if inserted): a segment cut
        # from both ends keeps one IPO cycle, and its cap may bind
        left_in, left_out = _leftovers(path, a[o], b[o], cut_in, cut_out, windows)
        loss_round = time_loss(v_in, v_out, v_round[o], acc, acc, jerk, jerk, rlen,
                               cut_in, cut_out, left_in, left_out, t_ipo)
        loss_g64 = time_loss(v_in, v_out, v_g64[o], acc, acc, jerk, jerk, 0.0, 0.0)
        sub[:] = False
        sub[o] = ~((v_round[o] > v_g64[o]) & (loss_round < loss_g64))
        decide(sub, "rounding would be slower than G64")
        trim_in[o], trim_out[o] = cut_in, cut_out
        length[o], deviation[o], radius[o] = rlen, devo, rmin
    reason[reason < 0] = REASON_CODE["rounded"]
    ins = reason == 0
    done = np.where(ins, 1.0, 0.0)
    trim_in, trim_out = trim_in * done, trim_out * done
    # rows of the inserted ones, in their order: PIECES per line-arc transition,
    # SBEND_PIECES per S-bend, SAMEDIR_PIECES between arcs curving the same way
    i_la = np.flatnonzero(ins[la_at])
    g_la = la_at[i_la]
    rows = transition_rows(junction[g_la], along[g_la], inward[g_la],
                           _take_shape(la_shape, i_la), arc_line[g_la], ka[g_la], _ROUNDING)
    n_rows = np.zeros(k, np.int64)
    n_rows[g_la] = PIECES
    owner = [np.repeat(g_la, PIECES)]
    more = [rows]
    for at, sh, to_rows, n_p in groups:
        i = np.flatnonzero(ins[at])
        g = at[i]
        if not g.size:
            continue
        more.append(to_rows(junction[g], along[g], inward[g], take(sh, i), ka[g],
                            _ROUNDING))
        owner.append(np.repeat(g, n_p))
        n_rows[g] = n_p
    if len(more) > 1:
        order = np.argsort(np.concatenate(owner), kind="stable")
        rows = {key: np.concatenate([m[key] for m in more])[order] for key in rows}
    return Transitions(reason, trim_in, trim_out, length * done, deviation * done,
                       radius * done, clamped & ins, v_g64, v_round, n_rows[ins], rows)


def _size_line_arc(path: Path, R: np.ndarray, arc: np.ndarray, line: np.ndarray,
                   o: np.ndarray, dev: np.ndarray, c: float):
    """Line-arc transitions ``o``: the shape whose deviation is ``dev`` (mm, shape (j,)),
    the ramp cut by the block-length clamp ``c`` (5.3) until both trims fit; whether it
    was cut, and whether it is too small (bool, shape (j,) each)."""
    Ro = R[o]
    ramp = ramp_for_deviation(Ro, dev)
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
        ramp = np.where(over, ramp * (1.0 - CLAMP_MARGIN) * cap_line / sh.line_trim, ramp)
        sh = transition_shape(Ro, ramp)
    small = ((sh.line_trim > cap_line) | ~(sh.piece > MIN_SEGMENT_LENGTH_MM)
             | ~(sh.ramp > MIN_SEGMENT_LENGTH_MM))
    return sh, cut, small


def _size_arcs(path: Path, R: np.ndarray, R_b: np.ndarray, a: np.ndarray, b: np.ndarray,
               o: np.ndarray, dev: np.ndarray, c: float, for_deviation, shape_of,
               measured, canonical=None, defer: bool = True):
    """Transitions ``o`` between two arcs (an S-bend, :mod:`reference.core.
    transition_sbend`, or arcs curving the same way, :mod:`reference.core.
    transition_samedir`: ``for_deviation`` and ``shape_of`` of that module, and
    ``measured``, a shape built without its deviation -> the same with it): the shape
    whose deviation is ``dev`` (mm, shape (j,)); where a trim exceeds the block-length
    clamp ``c`` (5.3) the rate is raised until both fit; whether it was cut, and whether
    it is too small (bool, shape (j,) each).

    The rounds raise ``log rate`` by secant steps on ``log`` of the larger trim's share
    of its cap (slope -1 at first: every length scales about like ``1/rate``), aiming at
    :data:`CLAMP_MARGIN` below the cap, until the share is within that margin of the aim
    (a step that overshoots is taken back: two roundings clamped at the two ends of one
    block leave it some ``2 CLAMP_MARGIN c`` of its length, below
    :data:`~reference.core.tolerances.MIN_SEGMENT_LENGTH_MM`, where a looser fit leaves
    a sliver of a block that needs an IPO cycle of its own). Measured on the same-way
    row of ``tests/bench/bench_rounding.py`` (1,819 transitions cut): with the slope -1
    at every round and the first fit accepted, the share's excess fell only some
    200-fold a round (the trims scale like ``rate^-0.995`` there), 27 % -> 0.17 % ->
    8e-6 -> 3e-8 -> 1e-9 in five rounds, and where a round overshot the fit stayed up
    to 5e-4 below the cap (two clamped roundings then left slivers of up to 2e-3 mm);
    with the secant, four rounds to within the margin.

    ``canonical`` (the same-way transitions': :func:`reference.core.transition_samedir.
    samedir_canonical`): each round builds the shapes ``like`` the ones before (a pair
    left on the sharper arc is not sought on the flatter one again at every round,
    where Newton's method wanders for all its steps beyond the flatter arc's landing),
    and the answer is made the model's at its rate; where that moves a pair (the
    flatter arc's landing found at the raised rate) and a trim no longer fits, the
    rounds go on from there.

    ``defer``: the sizing leaves the full measure of its answers whose trim exceeds the
    cap to the clamp (``defer`` of :func:`reference.core.transition_sbend.
    size_for_deviation`), which measures them at the raised rate anyway. Where that
    measure is above what the sizing accepts (:func:`reference.core.transition_sbend.
    not_above_aim`: the maximum the sizing followed was not the highest,
    so the tolerance's rate is above the one the rounds started from), those transitions
    are sized again without ``defer``: the answer is the same either way, the largest
    of the tolerance's rate and the clamp's.
    """
    r1, r2 = R[o], R_b[o]
    cap_in, cap_out = c * path.length[a[o]], c * path.length[b[o]]

    def over_cap(part, i, slack=0.0):
        """Whether a trim of the shapes ``part`` (transitions ``i``) exceeds its cap by
        more than the factor ``exp(slack)`` (``slack`` shape (m,) or a float)."""
        return np.maximum(part.trim_in / cap_in[i], part.trim_out / cap_out[i]) \
            > np.exp(slack)

    sh = for_deviation(r1, r2, dev, defer=over_cap if defer else None)
    deferred = (np.isnan(sh.deviation) & over_cap(sh, np.arange(o.size))) if defer \
        else np.zeros(o.size, bool)
    rate, sh0_rate = sh.rate.copy(), sh.rate
    cut = np.zeros(o.size, bool)
    aim = np.log1p(-CLAMP_MARGIN)
    x_old, g_old = np.full(o.size, np.nan), np.full(o.size, np.nan)

    def rounds(sh, like: bool):
        """The clamp's rounds from ``sh`` (updates ``rate``, ``cut`` and the secant's last
        points), each shape built ``like`` the one before where ``like``."""
        for _ in range(CLAMP_ROUNDS):
            over = np.maximum(sh.trim_in / cap_in, sh.trim_out / cap_out)
            # a cut one fits within CLAMP_MARGIN of the aim, or at the tolerance's rate
            # (nan: no landing, raised)
            fits = (over <= 1.0) & (~cut | (over >= 1.0 - 2.0 * CLAMP_MARGIN)
                                    | (rate <= sh0_rate))
            hit = np.flatnonzero(~fits)
            if not hit.size:
                break
            cut[hit] = True
            x, g = np.log(rate[hit]), np.log(over[hit])
            with np.errstate(divide="ignore", invalid="ignore"):
                slope = (g - g_old[hit]) / (x - x_old[hit])
            slope = np.where((slope < -0.5) & (slope > -2.0), slope, -1.0)
            step = np.minimum((g - aim) / -slope, np.log(RATE_RAISE_MAX))
            step = np.where(np.isnan(g), np.log(RATE_RAISE_MAX), step)
            x_old[hit], g_old[hit] = x, g
            # never below the rate of the tolerance (a step back after an overshoot)
            rate[hit] = np.maximum(np.exp(x + step), sh0_rate[hit])
            kw = {"like": take(sh, hit)} if like else {}
            # only the transitions cut are re-sized, their deviation measured once below
            sh = scatter(sh, hit, shape_of(r1[hit], r2[hit], rate[hit], deviation=False,
                                           **kw))
        return sh

    sh = rounds(sh, canonical is not None)
    if canonical is not None and cut.any():
        again = np.flatnonzero(cut)
        sh = scatter(sh, again, canonical(take(sh, again)))
        # a moved pair's trims are another function of the rate: the rounds go on from
        # there with the model's shapes where one no longer fits (none else is hit)
        x_old[again] = g_old[again] = np.nan
        sh = rounds(sh, False)
    again = np.flatnonzero(cut)
    if again.size:
        # each was last shaped at its final rate, without the deviation
        sh = scatter(sh, again, measured(take(sh, again)))
    redo = np.flatnonzero(deferred & ~not_above_aim(sh.deviation, dev))
    if redo.size:
        part, cut_redo, _ = _size_arcs(path, R, R_b, a, b, o[redo], dev[redo], c,
                                       for_deviation, shape_of, measured, canonical,
                                       defer=False)
        sh = scatter(sh, redo, part)
        cut[redo] = cut_redo
    small = (np.isnan(sh.theta) | (sh.trim_in > cap_in) | (sh.trim_out > cap_out)
             | ~(np.minimum(np.minimum(sh.ramp_in, sh.ramp_out), sh.piece)
                 > MIN_SEGMENT_LENGTH_MM))
    return sh, cut, small


def _compiled_parts(n: int) -> tuple:
    """The deviation search, the same-way landing's Newton iteration and the same-way
    pieces for ``n`` two-arc transitions: the compiled ones (:func:`reference.
    transition_kernel.deviation_where`, :func:`~reference.transition_kernel.
    samedir_newton` and :func:`~reference.transition_kernel.samedir_pieces`, bit for
    bit the vectorised ones) from :data:`SEARCH_COMPILED_MIN` transitions on or once
    they are loaded, else ``(None, None, None)`` (the vectorised ones, without loading
    numba)."""
    if n < SEARCH_COMPILED_MIN and _KERNEL not in sys.modules:
        return None, None, None
    from .transition_kernel import deviation_where, samedir_newton, samedir_pieces
    return deviation_where, samedir_newton, samedir_pieces


def _leftovers(path: Path, a: np.ndarray, b: np.ndarray, cut_in: np.ndarray,
               cut_out: np.ndarray, windows: tuple[np.ndarray, np.ndarray] | None
               ) -> tuple[np.ndarray, np.ndarray]:
    """Length left of segments ``a`` and ``b`` (before and after each transition), mm,
    shape (j,) each, once the transitions' own trims ``cut_in``, ``cut_out`` and the
    decided corner roundings (``windows``) are cut from their ends.

    Every open transition counts as inserted: the estimate then errs toward a short
    leftover, so two transitions that each pay alone but together leave a segment too
    short for its IPO cycle (5.3) are both judged with that cap (a seeded line-arc chain
    under G645 SOFT was 0.3 % slower than under G64 where each was judged alone).
    """
    left = leftovers(*break_windows(path.s_breaks, a + 1, cut_in, cut_out, windows))
    return left[a], left[b]


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


__all__ = ["PIECES", "SBEND_PIECES", "Transitions", "tangential_transitions"]
