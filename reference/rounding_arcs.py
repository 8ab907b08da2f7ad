"""Corner rounding, part: corners next to circular arcs (G641..G645, RND/RNDM).

The rounding of a corner next to an arc is a tangent arc of radius ``r``: "RND inserts a
tangent circle" and the rounding "replaces the area near the original angular
transition" (5.1). Two kinds of corner, each with an exact closed form for a given ``r``
(:mod:`reference.core.rounding`):

* a line and an arc (either order): the fillet between the line and the circle
  (:func:`~reference.core.rounding.line_circle_fillet`); the line is shortened by its
  tangent length, the arc by the arc length the fillet replaces;
* two arcs in one plane: the fillet tangent to both circles
  (:func:`~reference.core.rounding.circle_circle_fillet`): on the side the corner turns
  to, inside a circle that turns the same way and outside one that turns the other way,
  the one of the candidate tangent circles that shrinks to the corner with ``r`` and
  turns by the angle the contour turns between its ends; both arcs are shortened by the
  arc lengths it replaces.

A shortened arc only has its start angle or length changed, so it stays the exact arc;
the lengths replaced on the two sides differ, unlike at a line-line corner.

The radius by mode is the largest ``r`` that keeps every limit of the mode (the trims,
the deviation and ``r`` itself grow with ``r`` on the branch that shrinks to the
corner; past that branch the fillet does not exist and the limit counts as broken):

* RND/RNDM: ``r <= R_prog`` (the programmed radius exactly where nothing else limits);
* G641 / ADIS digits: both trims ``<= ADIS`` (ADISPOS for G0, 5.3: "the earliest point
  before the block end where rounding may start, and the latest point after it"; "for
  arcs, measure along the arc"), in closed form;
* tolerance modes (G642, G643, G645 at corners, G644 0xxx/4xxx): per axis
  ``|C_i - M_i| <= tol_i`` and ``|C - M| <=`` the contour tolerance where one applies
  (``M`` the fillet's point nearest the corner ``C``, as at line-line corners), G0
  tolerances times MD20560, by a root search on ``log r``;
* G644 2xxx/3xxx: the dynamic size of :func:`reference.rounding._dynamic_distance`
  for a tangent arc, whose turn here depends on ``r``: 3xxx the smallest fillet the
  axes pass at the programmed speed (centripetal, under SOFT the path jerk on the
  fillet, at least ``v T_ipo`` long), 2xxx the fillet ``v T`` long (``T`` from
  LOOKAH_FREQUENCY), by the same root search on ``log r`` (its length ``r sweep(r)``);
* the block-length clamp on both sides (``c`` times each participating block's length,
  along the arc for an arc, 5.3), in closed form. Between two circles the replaced
  length grows with ``r`` only up to the largest fillet (the two circles may cross a
  second time); a limit beyond what the largest fillet replaces does not bind
  (:func:`~reference.core.rounding.circle_fillet_radius_within`).

Model limits, named: the fillet is G1 (curvature jumps at its ends; under SOFT the
curvature-jump rule of 6.3 caps the speed there, as it does for a BRISK-shaped
rounding), where the line-line corners get a clothoid pair under SOFT; corners next to
a helix or spiral, whose line leaves the arc's plane or whose two arcs lie in different
planes, and corners next to inserted TRC/TLIFT blocks are passed as under G64.

Speeds as at line-line corners (:mod:`reference.rounding`): G641/G642/G645 round only
where G64 must slow down (overload factor, 4.3); every mode but RND/RNDM only where the
corner's time estimate favours the rounding (5.2 group 2), each side ramping to the
speed its own element allows (an arc: what the heuristic grants its curvature).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize.elementwise import find_root

from .core.arrays import row_dots, row_min, row_norms
from .core.geometry import KIND_CODES, Path
from .core.rounding import (INTERNAL_MODES, OVERLOAD_CHECKED_MODES, REASON_CODE,
                            always_rounds, circle_circle_fillet,
                            circle_fillet_deviation, circle_fillet_radius_for_deviation,
                            circle_fillet_radius_within, fillet_deviation,
                            fillet_radius_for_arc_trim, fillet_radius_for_deviation,
                            fillet_radius_for_line_trim, line_circle_fillet,
                            very_short_blocks)
from .core.rules import FEASIBLE, curvature_jump_speed_cap, junction_speed_cap
from .core.tolerances import MIN_SEGMENT_LENGTH_MM
from .machine import Machine
from .rounding_tangential import line_arc_pairs

_ROUNDING = KIND_CODES.index("rounding")

#: A line counts as lying in its arc's plane, and a second arc in the first's, when its
#: direction (its plane vectors) leaves the plane by at most this (the sine of the
#: angle): the fillet is built in the plane and meets the line's projection (the second
#: circle's), at most ``OFF_PLANE_MAX`` times the replaced length (at most half the
#: block) off it, which stays below POS_TOL_MM (1e-6 mm) for blocks up to 2 m.
OFF_PLANE_MAX = 1e-9

#: Fillet radii are searched in ``[R_MIN_MM, R_MAX_MM]`` (log scale): below a nanometre
#: a rounding is "too small" anyway (MIN_SEGMENT_LENGTH_MM), above 10 m no clamp of a
#: real block lets a fillet through.
R_MIN_MM = 1e-9
R_MAX_MM = 1e7
#: Absolute tolerance of the root in ``log r`` (tolerance modes): a relative error in
#: ``r``, so in the deviation used, of 1e-11 (the radius kept lies up to two of these
#: inside the tolerance).
ROOT_XATOL = 1e-11
#: Secant steps in ``log r`` before the bracketed search (tolerance modes).
SECANT_STEPS = 5
#: ``|log ratio|`` at which a secant search in ``log r`` stops: the slope there is about
#: 1 (0.75..1.3 on the seeded corners), so the root is within about ROOT_XATOL / 8 and
#: the final step half ROOT_XATOL inside keeps the radius within ROOT_XATOL of it (each
#: result checked: ``-2 ROOT_XATOL <= ratio <= 0``, else a later stage).
SETTLED = ROOT_XATOL / 8.0
#: A closed-form start is used where it lies at least this far below the clamp in
#: ``log r`` (relative 1e-6): there the clamp does not bind and its ratio is not needed.
#: The fillet at the start is kept without the clamp's closed forms where both its
#: trims lie this far (relative) inside their limits (:func:`_radius_by_mode`).
GUESS_BELOW_CAP = 1e-6
#: ``log`` of the tolerance ratio where the fillet does not exist (larger radii): far
#: above 0, so the root search stays below it.
NO_FILLET_LOG_RATIO = 50.0
#: The closed-form radii of the clamp and of ADIS are shrunk by this (relative), so that
#: round-off cannot put a replaced length above its limit: the closed forms and the
#: fillet they invert agree to 2.6e-12 (relative, 2000 seeded corners down to 0.005
#: degrees, tests/reference/test_rounding_arcs.py); 40 times that.
CLOSED_FORM_MARGIN = 1e-10

#: How each corner's limit is found (the codes of :func:`reference.rounding._distances`).
HOW_NONE, HOW_ADIS, HOW_TOL, HOW_RADIUS, HOW_FREQ, HOW_DYN = 0, 1, 2, 3, 4, 5


@dataclass(frozen=True, slots=True, eq=False)
class ArcCorners:
    """Decisions at corners next to arcs, shape (k,) each.

    Attributes
    ----------
    reason : numpy.ndarray of int
        :data:`reference.core.rounding.ROUNDING_REASONS` code (0 = rounded).
    trim_in, trim_out : numpy.ndarray
        Length replaced of the segment before and after, mm (0 where none).
    radius, length, deviation : numpy.ndarray
        Fillet radius, its length, ``|C - M|``, mm (0 where none).
    clamped : numpy.ndarray of bool
        The block-length clamp decided the radius.
    v_g64, v_round : numpy.ndarray
        Corner speed under G64 and through the fillet, mm/s (``nan``: not evaluated).
    rows : dict
        Packed rows of the inserted fillets (one each), in corner order.
    """

    reason: np.ndarray
    trim_in: np.ndarray
    trim_out: np.ndarray
    radius: np.ndarray
    length: np.ndarray
    deviation: np.ndarray
    clamped: np.ndarray
    v_g64: np.ndarray
    v_round: np.ndarray
    rows: dict


def arc_corners(path: Path, machine: Machine, a: np.ndarray, ka: np.ndarray,
                mode: np.ndarray, t1: np.ndarray, t2: np.ndarray, targets: dict,
                accel: np.ndarray, centripetal_share: float, jerk_share: float,
                time_loss) -> ArcCorners:
    """Decide and size the rounding of corners after segments ``a`` (one or both of
    ``a``, ``a + 1`` an arc, the corner not tangential).

    Parameters
    ----------
    path : Path
    machine : Machine
    a, ka : numpy.ndarray of int, shape (k,)
        Segment before each corner and its block.
    mode : numpy.ndarray of str, shape (k,)
        Mode governing each corner (``"G641"`` .. ``"G645"``, ``"RND"``, ``"RNDM"``).
    t1, t2 : numpy.ndarray, shape (k, n)
        Tangents at the corner.
    targets : dict
        Per corner, from :func:`reference.rounding._distances`: ``how`` (HOW_ codes),
        ``dist`` (ADIS/ADISPOS, mm), ``contour`` (contour tolerance, mm, ``inf``: none),
        ``axis_tol`` (per-axis tolerance, shape (k, n), mm, ``inf``: none), ``g0``
        (tolerance factor), ``radius`` (programmed radius, mm), ``dyn_radius``,
        ``dyn_length`` (G644 2xxx/3xxx, and 0xxx/1xxx as their cap: smallest radius
        and length, mm), ``dyn_cap`` (bool: G644 0xxx/1xxx).
    accel : numpy.ndarray of str, shape (k,)
    centripetal_share, jerk_share : float
        The corner rounding's shares of the axis acceleration and jerk.
    time_loss : callable
        :func:`reference.rounding.corner_time_loss`.

    Returns
    -------
    ArcCorners
    """
    k = a.size
    b, line_arc, arc_line, arc_arc, arc, line, circle = line_arc_pairs(path, a)
    reason = np.full(k, -1, dtype=np.int64)

    def decide(mask: np.ndarray, why: str) -> None:
        reason[(reason < 0) & mask] = REASON_CODE[why]

    decide(~(line_arc | arc_line | arc_arc), "corner next to an inserted block (TRC, "
           "TLIFT): rounding not modelled yet")
    E1, E2 = path.e1.take(arc, axis=0), path.e2.take(arc, axis=0)
    E1b, E2b = path.e1.take(b, axis=0), path.e2.take(b, axis=0)
    # how far out of the arc's plane (OFF_PLANE_MAX), each test only on its own
    # corners (elementwise: the same numbers as on all of them)
    off = np.empty(k)
    la = np.flatnonzero(~arc_arc)
    if la.size:
        # the line in the arc's plane
        t_line = path.d.take(line[la], axis=0)
        e1, e2 = E1[la], E2[la]
        off[la] = row_norms(t_line - row_dots(t_line, e1)[:, None] * e1
                            - row_dots(t_line, e2)[:, None] * e2)
    two = np.flatnonzero(arc_arc)
    if two.size:
        both = _gather(two, k)
        # between two arcs (``arc`` is the first, ``line`` the second): the second's
        # plane vectors in the first's plane
        e1, e2, e1b, e2b = E1[both], E2[both], E1b[both], E2b[both]
        off[both] = np.maximum(
            row_norms(e1b - row_dots(e1b, e1)[:, None] * e1 - row_dots(e1b, e2)[:, None] * e2),
            row_norms(e2b - row_dots(e2b, e1)[:, None] * e1 - row_dots(e2b, e2)[:, None] * e2))
    decide(~circle | ~(off <= OFF_PLANE_MAX),
           "corner next to a helix or spiral, or out of the arc's plane: rounding not "
           "modelled yet")
    how = targets["how"]

    # plane coordinates: the corner at the origin, the construction traversed from the
    # line into the arc (arc into line: backwards), from the first arc into the second
    R = path.radius[arc]
    w = path.omega[arc]
    at = np.where(line_arc, 0.0, path.length[arc])
    phi = path.theta0[arc] + w * at
    radial = np.column_stack((np.cos(phi), np.sin(phi)))      # plane coords
    c = machine.channel.rounding_length_clamp
    # the two elements in the construction's order (line-arc: the line first)
    cap_first = c * path.length[np.where(arc_arc, a, line)]
    cap_second = c * path.length[np.where(arc_arc, b, arc)]

    v_g64 = np.full(k, np.nan)
    v_round = np.full(k, np.nan)
    r = np.zeros(k)
    o = np.flatnonzero(reason < 0)
    fil = None                 # the fillets of the corners o, in their order
    clamped = np.zeros(k, bool)
    # per corner: its family's geometry, as 1-d columns (:class:`_Family`)
    fams = []
    la_o = np.flatnonzero(~arc_arc[o])
    if la_o.size:
        # the line's direction in the arc's plane, the arc's centre and sense
        i = o[la_o]
        t_line = path.d.take(line[i], axis=0)
        t2d = np.column_stack((row_dots(t_line, E1[i]), row_dots(t_line, E2[i])))
        t2d /= np.where(row_norms(t2d) > 0, row_norms(t2d), 1.0)[:, None]
        t2d = np.where(line_arc[i, None], t2d, -t2d)
        centre = -R[i, None] * radial[i]
        sense = np.where(line_arc[i], np.sign(w[i]), -np.sign(w[i]))
        fams.append((la_o, _LINE_CIRCLE, (*t2d.T, *centre.T, R[i], sense)))
    aa_o = np.flatnonzero(arc_arc[o])
    if aa_o.size:
        i = _gather(o[aa_o], k)
        fams.append((aa_o, _CIRCLE_CIRCLE,
                     _circle_pair(path, a[i], b[i], E1[i], E2[i], E1b[i], E2b[i], R[i],
                                  radial[i])))
    for sub_o, fam, cols in fams:
        i = _gather(o[sub_o], k)
        ro, r_cap, tol_ok, (kept, f_kept) = _radius_by_mode(
            fam, cols, how[i], targets["dist"][i], targets["radius"][i],
            targets["axis_tol"][i], targets["contour"][i], targets["g0"][i], E1[i], E2[i],
            cap_first[i], cap_second[i], targets["dyn_radius"][i],
            targets["dyn_length"][i], targets["deviation"][i], targets["dyn_cap"][i])
        clamped[i] = ro >= r_cap
        # the fillet at the radius found: the tolerance search's own where it kept the
        # fillet it judged, else built here
        # (its rows outside ``kept`` are overwritten here: the fillets are new arrays)
        f = f_kept if f_kept is not None else _empty_fillet(ro.size)
        if not kept.all():
            todo = np.flatnonzero(~kept)
            _put(f, todo, fam.fillet(np.where(ro[todo] > 0, ro[todo], 1.0),
                                     *(col[todo] for col in cols)))
        r[i] = ro
        length = ro * f.sweep
        # the closed forms assume the branch that shrinks to the corner: the fillet
        # found must exist and keep both lengths
        keeps = ((f.trim_first <= cap_first[i]) & (f.trim_second <= cap_second[i])
                 & ((how[i] != HOW_ADIS)
                    | (np.maximum(f.trim_first, f.trim_second) <= targets["dist"][i]))
                 & tol_ok)
        sub = np.zeros(k, bool)
        sub[i] = (~keeps | ~f.valid | ~(length > MIN_SEGMENT_LENGTH_MM)
                  | ~(ro > R_MIN_MM * 2))
        decide(sub, "rounding distance too small")
        if sub_o.size == o.size:
            fil = f
        else:
            if fil is None:
                fil = _empty_fillet(o.size)
            _put(fil, sub_o, f)

    o2 = np.flatnonzero(reason < 0)
    lim = machine.limits.for_axes(path.axes)
    t_ipo = machine.limits.t_ipo_s
    sel = np.searchsorted(o, o2) if o.size else np.zeros(0, np.int64)
    if o2.size:
        f = fil if sel.size == o.size else _take(fil, sel)
        # every corner still open (the common case): views, not copies of each column
        at = slice(None) if o2.size == k else o2
        ro = r[at]
        E1o, E2o = E1[at], E2[at]
        rho = np.sqrt(E1o ** 2 + E2o ** 2)             # each axis' weight in the plane
        moving = rho > 0
        wr = np.where(moving, rho, 1.0)
        t1o, t2o = t1[at], t2[at]
        a1, a2 = np.abs(t1o), np.abs(t2o)
        # not tangential: round_corners sent only the corners its test (the same rule,
        # the same tangents) found not tangential
        v64o = junction_speed_cap(t1o, t2o, lim.jump, FEASIBLE,
                                  np.zeros(o2.size, bool))[0]
        v_g64[o2] = v64o
        aa = arc_arc[at]
        soft = accel[at] == "SOFT"
        ao, bo = a[at], b[at]
        # the elements' own radii in the construction's order (inf: the line)
        R_first = np.where(aa, R[at], np.inf)
        R_second = np.where(aa, path.radius[bo], R[at])
        with np.errstate(divide="ignore", invalid="ignore"):
            v_axis = np.minimum(row_min(lim.v_max[None, :] / a1),
                                row_min(lim.v_max[None, :] / a2))
            v_prog = np.minimum(np.minimum(path.feed[ao], path.feed[bo]), v_axis)
            # at most one segment per IPO cycle on either side (5.3), as the heuristic
            # caps them: the speed each side runs at beside the corner
            # (reference.rounding._line_speeds)
            ipo_in, ipo_out = path.length[ao] / t_ipo, path.length[bo] / t_ipo
        terms = _arc_speed_terms(lim, moving, wr, soft, centripetal_share, jerk_share)
        v_arc = _arc_speed(R_second, *terms)
        v_arc_first = np.full(o2.size, np.inf)
        if aa.any():
            v_arc_first[aa] = _arc_speed(R_first[aa], *(x[aa] for x in terms))
        length = ro * f.sweep
        # centripetal and, under SOFT, the path jerk on the fillet (third path
        # derivative 1/r^2), as on any arc; one IPO cycle per inserted block (5.3), the
        # feed; under SOFT the curvature jumps at its ends
        vr = np.minimum(np.minimum(v_prog, length / t_ipo),
                        _arc_speed(ro, *terms))
        if soft.any():
            # 6.3: the fillet's curvature vector jumps from the first element's (the
            # line's 0) at one end and to the second's at the other (q'' = (centre -
            # P) / radius^2)
            def world(v2, j=slice(None)):
                return E1o[j] * v2[:, :1] + E2o[j] * v2[:, 1:]
            k_fs = world((f.centre - f.start) / (ro * ro)[:, None])
            k_fe = world((f.centre - f.end) / (ro * ro)[:, None])
            k_ae = world((f.centre_second - f.end) / (R_second * R_second)[:, None])
            # from the first arc's (a line's: 0), only where the first is an arc
            k_as = np.zeros_like(k_fs)
            if aa.any():
                j = _gather(np.flatnonzero(aa), aa.size)
                k_as[j] = world((f.centre_first[j] - f.start[j])
                                / (R_first[j] * R_first[j])[:, None], j)
            v_k = np.minimum(
                curvature_jump_speed_cap(k_as, k_fs, lim.path_trans_jerk, t_ipo),
                curvature_jump_speed_cap(k_fe, k_ae, lim.path_trans_jerk, t_ipo))
            vr = np.where(soft, np.minimum(vr, v_k), vr)
        v_round[o2] = vr
        sub = np.zeros(k, bool)
        ignore = machine.channel.ignore_ovl_factor_for_adis
        mode_o = mode[at]
        ovl = np.isin(mode_o, OVERLOAD_CHECKED_MODES) & (not ignore)
        sub[o2] = ovl & (v64o >= np.minimum(v_prog, np.minimum(ipo_in, ipo_out)))
        decide(sub, "G64 passes the corner without reduction (overload factor)")
        # G643, and G641/G642/G645 with MD20490 = TRUE, round whatever G64 costs
        # (always_rounds), but not with an inserted block between two very short ones
        always = always_rounds(mode_o, ignore)
        sub[:] = False
        sub[o2] = always & ~np.isin(mode_o, INTERNAL_MODES) & very_short_blocks(
            path.length[ao], path.length[bo], v_prog, t_ipo)
        decide(sub, "rounding would slow the program down (between two very short blocks)")
        # the time estimate of the line-line corners, each side ramping to its own
        # speed (an arc side to its own limit), the fillet passed at v_round
        forward = line_arc[at] | aa
        v_line = v_prog
        v_first = np.minimum(v_line, v_arc_first)
        v_second = np.minimum(v_line, v_arc)
        v_in = np.minimum(np.where(forward, v_first, v_second), ipo_in)
        v_out = np.minimum(np.where(forward, v_second, v_first), ipo_out)
        with np.errstate(divide="ignore"):
            acc_in = row_min(lim.a_max[None, :] / a1)
            acc_out = row_min(lim.a_max[None, :] / a2)
            j_in = np.where(soft, row_min(lim.j_max[None, :] / a1), np.inf)
            j_out = np.where(soft, row_min(lim.j_max[None, :] / a2), np.inf)
        cut_in = np.where(forward, f.trim_first, f.trim_second)
        cut_out = np.where(forward, f.trim_second, f.trim_first)
        radius_mode = np.isin(mode_o, ("RND", "RNDM"))
        sub[:] = False
        # what the fillet leaves of the two elements (one IPO cycle each, 5.3)
        left_in = path.length[ao] - cut_in
        left_out = path.length[bo] - cut_out
        sub[o2] = ~(time_loss(v_in, v_out, vr, acc_in, acc_out, j_in, j_out, length,
                              cut_in, cut_out, left_in, left_out, t_ipo)
                    < time_loss(v_in, v_out, v64o, acc_in, acc_out, j_in, j_out,
                                0.0, 0.0)) & ~radius_mode & ~always
        decide(sub, "rounding would be slower than G64")

    reason[reason < 0] = REASON_CODE["rounded"]
    ins = np.flatnonzero(reason == 0)
    trim_in = np.zeros(k)
    trim_out = np.zeros(k)
    radius_out = np.zeros(k)
    length_out = np.zeros(k)
    dev_out = np.zeros(k)
    rows = {}
    if ins.size:
        f = _take(fil, np.searchsorted(o, ins))
        fw = line_arc[ins] | arc_arc[ins]
        trim_in[ins] = np.where(fw, f.trim_first, f.trim_second)
        trim_out[ins] = np.where(fw, f.trim_second, f.trim_first)
        radius_out[ins] = r[ins]
        length_out[ins] = r[ins] * f.sweep
        dev_out[ins] = row_norms(f.deviation)
        # the corner in the world: the arc's end (line-arc: its start)
        rad = radial[ins]
        corner = path.origin.take(arc[ins], axis=0) + R[ins, None] * (
            E1[ins] * rad[:, :1] + E2[ins] * rad[:, 1:])
        rows = _fillet_rows(corner, E1[ins], E2[ins], f, r[ins], fw, ka[ins])
    return ArcCorners(reason, trim_in, trim_out, radius_out, length_out, dev_out,
                      clamped & (reason == 0), v_g64, v_round, rows)


def _circle_pair(path: Path, a: np.ndarray, b: np.ndarray, E1: np.ndarray, E2: np.ndarray,
                 E1b: np.ndarray, E2b: np.ndarray, R1: np.ndarray, radial1: np.ndarray
                 ) -> tuple:
    """The columns of :data:`_CIRCLE_CIRCLE` at corners between arcs ``a`` and ``b``
    (``E1``, ``E2`` the plane vectors of ``a``, ``E1b``, ``E2b`` those of ``b``):
    both circles in the first arc's plane coordinates with the corner (the first arc's
    end, ``radial1`` its unit radial there) at the origin, ``c_j = -R_j u_j``. The
    second circle is taken through that point with its own radial at its start (the
    two ends meet to the path's continuity tolerance; the fillet then meets the second
    arc's shortened start as the arcs met). Its sense in the first's plane: its own
    (``sign omega``) times the orientation of its plane vectors in the first's."""
    phi2 = path.theta0[b]
    rad2 = E1b * np.cos(phi2)[:, None] + E2b * np.sin(phi2)[:, None]
    u2 = np.column_stack((row_dots(rad2, E1), row_dots(rad2, E2)))
    u2 /= row_norms(u2)[:, None]
    orient = np.sign(row_dots(E1b, E1) * row_dots(E2b, E2)
                     - row_dots(E1b, E2) * row_dots(E2b, E1))
    R2 = path.radius[b]
    c1 = -R1[:, None] * radial1
    c2 = -R2[:, None] * u2
    return (*c1.T, R1, np.sign(path.omega[a]), *c2.T, R2,
            np.sign(path.omega[b]) * orient)


@dataclass(frozen=True, slots=True, eq=False)
class _Fillet:
    """A fillet per corner in the construction's order (line-arc: from the line; two
    arcs: from the first), plane coordinates with the corner at the origin; shapes (k,)
    or (k, 2). ``radial``/``heading``: unit vector from the centre to the start and the
    direction of travel there; ``centre_first``/``centre_second``: the elements' own
    centres (the line's: unused)."""

    valid: np.ndarray
    trim_first: np.ndarray
    trim_second: np.ndarray
    centre: np.ndarray
    start: np.ndarray
    end: np.ndarray
    radial: np.ndarray
    heading: np.ndarray
    sweep: np.ndarray
    deviation: np.ndarray
    centre_first: np.ndarray
    centre_second: np.ndarray


@dataclass(frozen=True, slots=True, eq=False)
class _Family:
    """A kind of arc corner (line-circle, circle-circle): its fillet of radius ``r``
    and the closed-form radii that replace a given length of the first or the second
    element, its deviation ``C - M`` and the closed-form radius of a given contour
    deviation (the tolerance search's start), all from the same 1-d geometry columns
    (as :func:`scipy.optimize.elementwise.find_root` passes them)."""

    fillet: Callable
    r_first: Callable
    r_second: Callable
    deviation: Callable
    r_deviation: Callable


def _lc(cols):
    tx, ty, cx, cy, radius, sense = cols
    return np.column_stack((tx, ty)), np.column_stack((cx, cy)), radius, sense


def _lc_fillet(r, *cols) -> _Fillet:
    t, centre, radius, sense = _lc(cols)
    f = line_circle_fillet(r, t, centre, radius, sense)
    start_dir = f.start / np.where(row_norms(f.start) > 0, row_norms(f.start), 1.0)[:, None]
    # direction of travel at the construction's start: along the line towards the
    # corner, i.e. -start / |start| (the start is at x t with x < 0)
    return _Fillet(f.valid, f.line_trim, f.arc_trim, f.centre, f.start, f.end,
                   (f.start - f.centre) / r[:, None], -start_dir, f.sweep, f.deviation,
                   np.zeros_like(centre), centre)


def _cc(cols):
    c1x, c1y, r1, s1, c2x, c2y, r2, s2 = cols
    return np.column_stack((c1x, c1y)), r1, s1, np.column_stack((c2x, c2y)), r2, s2


def _cc_fillet(r, *cols) -> _Fillet:
    c1, r1, s1, c2, r2, s2 = _cc(cols)
    f = circle_circle_fillet(r, c1, r1, s1, c2, r2, s2)
    return _Fillet(f.valid, f.trim_in, f.trim_out, f.centre, f.start, f.end, f.radial,
                   f.heading, f.sweep, f.deviation, c1, c2)


def _cc_r_second(trim, *cols):
    c1, r1, s1, c2, r2, s2 = _cc(cols)
    # the same fillet on the pair traversed backwards (core.rounding)
    return circle_fillet_radius_within(trim, c2, r2, -s2, c1, r1, -s1)


_LINE_CIRCLE = _Family(
    fillet=_lc_fillet,
    r_first=lambda trim, *cols: fillet_radius_for_line_trim(trim, *_lc(cols)),
    r_second=lambda trim, *cols: fillet_radius_for_arc_trim(trim, *_lc(cols)),
    deviation=lambda r, *cols: fillet_deviation(r, *_lc(cols)),
    r_deviation=lambda e, *cols: fillet_radius_for_deviation(e, *_lc(cols)))
_CIRCLE_CIRCLE = _Family(
    fillet=_cc_fillet,
    r_first=lambda trim, *cols: circle_fillet_radius_within(trim, *_cc(cols)),
    r_second=_cc_r_second,
    deviation=lambda r, *cols: circle_fillet_deviation(r, *_cc(cols)),
    r_deviation=lambda e, *cols: circle_fillet_radius_for_deviation(e, *_cc(cols)))


def _gather(idx: np.ndarray, k: int) -> np.ndarray | slice:
    """``idx`` (sorted, distinct rows of ``k``) as an index that gathers without
    copying where it takes every row: the full slice then, so the columns are passed
    as views (the common case: every corner of one family and one open decision)."""
    return slice(None) if idx.size == k else idx


def _empty_fillet(k: int) -> _Fillet:
    z, z2 = np.zeros(k), np.zeros((k, 2))
    return _Fillet(np.zeros(k, bool), z, z.copy(), z2, z2.copy(), z2.copy(), z2.copy(),
                   z2.copy(), z.copy(), z2.copy(), z2.copy(), z2.copy())


def _put(into: _Fillet, i: np.ndarray, part: _Fillet) -> None:
    """Write ``part`` into rows ``i`` of ``into`` (its arrays, in place)."""
    for name in _Fillet.__slots__:
        getattr(into, name)[i] = getattr(part, name)


def _radius_by_mode(fam: _Family, cols: tuple, how: np.ndarray, dist: np.ndarray,
                    rad: np.ndarray, tol: np.ndarray, cont: np.ndarray, g0: np.ndarray,
                    E1: np.ndarray, E2: np.ndarray, cap_first: np.ndarray,
                    cap_second: np.ndarray, dyn_radius: np.ndarray,
                    dyn_length: np.ndarray, dev: np.ndarray,
                    dyn_cap: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple]:
    """The fillet radius by mode within the block-length clamp, mm, shape (k,) (0: none):
    the largest within the mode's limits, or for G644 2xxx/3xxx the smallest of the
    dynamic size (:func:`reference.rounding._dynamic_distance`: at least ``dyn_radius``
    and at least ``dyn_length`` long, ``r sweep(r)``); the clamp's radius (``inf`` at
    the corners whose fillet was kept at the tolerance search's start: its trims show
    that the clamp does not bind there, see the comment below); and whether
    the tolerance holds at the radius found (True where no tolerance applies); and
    whether the tolerance search built and judged the fillet at that radius (bool,
    shape (k,)), with those fillets as rows of one :class:`_Fillet` of k rows (``None``
    where none was kept; its other rows are not used), so that they are not built
    again.
    ``dev`` (shape (k,), mm): the contour deviation the tolerances allow in the
    direction ``C - M`` of the line-line corner between the tangents
    (:func:`reference.rounding._distances`; the tolerance search's start).
    ``dyn_cap`` (bool, shape (k,)): G644 0xxx/1xxx, the tolerance or ADIS radius
    but at most the 3xxx one (spec 5.6: not fully used "if the dynamics allow")."""
    k = how.size
    tol_ok = np.ones(k, bool)
    n_ax = E1.shape[1]
    n_geo = len(cols)
    ro = np.where(how == HOW_RADIUS, rad, np.inf)
    # tolerances: where the contour tolerance decides, the closed form for the contour
    # deviation (the radius of the deviation the tolerances allow in the direction C - M
    # of the line-line corner between the tangents) is the root itself. The fillet half
    # ROOT_XATOL inside it (in log r) is built and judged once, and kept, with that same
    # fillet as the rounding, where its ratio lies in [-2 ROOT_XATOL, 0] (the acceptance
    # of every result of the search, _secant_root) and both its trims lie clearly
    # within the block-length clamp (GUESS_BELOW_CAP, relative): the trims grow with r
    # on the branch that shrinks to the corner, so the clamp does not bind there and
    # its closed forms are not needed. The other corners search below the clamp.
    tl = np.flatnonzero(how == HOW_TOL)
    r_guess = np.zeros(0)
    kept = np.zeros(k, bool)
    f_kept = None
    if tl.size:
        tl_at = _gather(tl, k)
        r_guess = fam.r_deviation(dev[tl_at], *(col[tl_at] for col in cols))
        g = np.flatnonzero((r_guess > R_MIN_MM) & np.isfinite(r_guess) & ~dyn_cap[tl])
        if g.size:
            tg = tl[g]
            tg_at = _gather(tg, k)
            r_g = np.exp(np.log(r_guess[g]) - ROOT_XATOL / 2.0)
            f_g = fam.fillet(r_g, *(col[tg_at] for col in cols))
            lr = _tol_log_ratio(f_g.deviation, f_g.valid, E1[tg_at], E2[tg_at],
                                tol[tg_at] * g0[tg_at, None], cont[tg_at] * g0[tg_at])
            inside = 1.0 - GUESS_BELOW_CAP
            with np.errstate(invalid="ignore"):
                hit = ((lr <= 0.0) & (lr >= -2.0 * ROOT_XATOL) & f_g.valid
                       & (f_g.trim_first <= inside * cap_first[tg_at])
                       & (f_g.trim_second <= inside * cap_second[tg_at]))
            kept[tg[hit]] = True
            ro[tg[hit]] = r_g[hit]
            # in corner order, without copying where every corner was judged (the
            # common case: one contour tolerance); rows outside ``kept`` are not used
            if tg.size == k:
                f_kept = f_g
            elif hit.any():
                f_kept = _empty_fillet(k)
                _put(f_kept, tg, f_g)
    # the replaced lengths grow with r: the largest r within a length on each side
    # in closed form (the clamp; ADIS), shrunk by CLOSED_FORM_MARGIN so that the
    # round-off of the closed form cannot put a trim above its limit
    # (ADIS only where it applies; both lengths of a side in one call: the same
    # elementwise numbers, half the calls); inf where the guess was kept
    r_cap = np.full(k, np.inf)
    rest = np.flatnonzero(~kept)
    if rest.size:
        adis = rest[how[rest] == HOW_ADIS]
        both = np.concatenate((rest, adis))
        cb = tuple(col[both] for col in cols)
        with np.errstate(invalid="ignore"):
            r_both = np.fmin(
                _positive(fam.r_first(np.concatenate((cap_first[rest], dist[adis])), *cb)),
                _positive(fam.r_second(np.concatenate((cap_second[rest], dist[adis])),
                                       *cb)))
        r_both *= 1.0 - CLOSED_FORM_MARGIN
        r_cap[rest] = r_both[:rest.size]
        ro[adis] = r_both[rest.size:]
        ro[rest] = np.fmin(ro[rest], r_cap[rest])
    search = np.flatnonzero(~kept[tl])
    ts = tl[search]
    if ts.size:
        # the others: the root of log(ratio) in log r below the clamp (the deviation
        # grows with r), from the guess where it lies clearly below the clamp, else
        # bracketed (Chandrupatla's method, scipy)
        def ratio(x, *c):
            return _log_tol_ratio(x, *c, n_axes=n_ax, n_geo=n_geo, dev_fn=fam.deviation)

        tc = (*(col[ts] for col in cols), *E1[ts].T, *E2[ts].T,
              *(tol[ts] * g0[ts, None]).T, cont[ts] * g0[ts])
        ro[ts], f_ro = _tolerance_radius(ratio, tc, r_cap[ts], r_guess[search])
        # where no radius was found (0, or no clamp and the whole family within) the
        # corner is too small anyway
        tol_ok[ts] = f_ro <= 0.0
    # G644 2xxx/3xxx: the radius whose fillet has the dynamic length (the length grows
    # about like r: the same search, the largest r not longer), at least dyn_radius,
    # then clamped (dyn_cap corners were not kept at the guess: their clamp is known)
    dy = np.flatnonzero((how == HOW_FREQ) | (how == HOW_DYN) | dyn_cap)
    if dy.size:
        dc = (*(col[dy] for col in cols), dyn_length[dy])

        def too_long(x, *c):
            return _log_length_ratio(x, *c, n_geo=n_geo, fillet=fam.fillet)

        r_len = _tolerance_radius(too_long, dc, r_cap[dy])[0]
        r_dyn = np.fmin(np.maximum(r_len, dyn_radius[dy]), r_cap[dy])
        ro[dy] = np.where(dyn_cap[dy], np.fmin(ro[dy], r_dyn), r_dyn)
    ro = np.where(np.isfinite(ro), ro, 0.0)
    return ro, r_cap, tol_ok, (kept, f_kept)


def _tolerance_radius(ratio: Callable, cols: tuple, r_cap: np.ndarray,
                      r_guess: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The largest radius at most ``r_cap`` whose ``ratio`` (``log`` of the largest
    tolerance ratio, growing with ``log r``) is not above 0, mm, shape (k,) (0: none),
    and ``ratio`` at the log of that radius (``nan`` where the radius is 0 or not
    finite).

    The deviation grows about like ``r``, so ``ratio`` is nearly linear in ``log r``:
    secant steps (:func:`_secant_root`) reach the root in a few steps; a radius is kept
    where they end inside the tolerance and within ROOT_XATOL of the root. They start
    from ``r_guess`` where it is clearly below the clamp (the closed form for the
    contour deviation: where it decides, the root itself); else from the clamp (whose
    ratio decides whether the clamp binds). Far above the root (no clamp: the search
    starts at R_MAX_MM) the deviation may level off (both arcs curving away from the
    fillet), where the secant crawls: those start again from R_MIN_MM, where every
    fillet is as small as a line-line one and ``ratio`` has slope 1, so the first step
    lands near the root. Any left go to the bracketed search (Chandrupatla's method,
    scipy). Only the corners still moving are evaluated.
    """
    k = r_cap.size
    hi = np.log(np.where(np.isfinite(r_cap), r_cap, R_MAX_MM))
    ro = np.zeros(k)
    f_ro = np.full(k, np.nan)
    done = np.zeros(k, bool)
    # 0. from the guess, where it lies clearly below the clamp (then, the ratio growing
    # with r, the clamp does not bind)
    if r_guess is not None:
        with np.errstate(divide="ignore", invalid="ignore"):
            x_g = np.log(r_guess)
        start = np.flatnonzero((r_guess > R_MIN_MM) & (x_g < hi - GUESS_BELOW_CAP))
        if start.size:
            sc = tuple(c[start] for c in cols)
            r, f = _secant_root(ratio, sc, x_g[start], ratio(x_g[start], *sc), hi[start])
            ok = (f <= 0.0) & (f >= -2.0 * ROOT_XATOL)
            ro[start[ok]], f_ro[start[ok]], done[start[ok]] = r[ok], f[ok], True
    # 1. from the clamp: where it is within the tolerance, it is the radius
    rest = np.flatnonzero(~done)
    f_hi = ratio(hi[rest], *(c[rest] for c in cols)) if rest.size else np.zeros(0)
    top = f_hi <= 0.0
    ro[rest[top]] = r_cap[rest[top]]
    f_ro[rest[top]] = np.where(np.isfinite(r_cap[rest[top]]), f_hi[top], np.nan)
    done[rest[top]] = True
    start = rest[np.isfinite(f_hi) & (f_hi < NO_FILLET_LOG_RATIO) & ~top]
    x0, f0 = hi[start], f_hi[np.isfinite(f_hi) & (f_hi < NO_FILLET_LOG_RATIO) & ~top]
    # 2. the others from R_MIN_MM, where the root is bracketed (ratio below 0 there)
    for stage in (1, 2):
        if stage == 2:
            rest = np.flatnonzero(~done)
            x_lo = np.full(rest.size, np.log(R_MIN_MM))
            f_lo = ratio(x_lo, *(c[rest] for c in cols))
            below = f_lo < 0.0
            start, x0, f0 = rest[below], x_lo[below], f_lo[below]
        if not start.size:
            continue
        r, f = _secant_root(ratio, tuple(c[start] for c in cols), x0, f0, hi[start])
        ok = (f <= 0.0) & (f >= -2.0 * ROOT_XATOL)
        ro[start[ok]], f_ro[start[ok]], done[start[ok]] = r[ok], f[ok], True
    sol = np.flatnonzero(~done)
    if sol.size:
        sc = tuple(c[sol] for c in cols)
        sol = sol[ratio(np.full(sol.size, np.log(R_MIN_MM)), *sc) < 0.0]
    if sol.size:
        sc = tuple(c[sol] for c in cols)
        res = find_root(ratio, (np.full(sol.size, np.log(R_MIN_MM)), hi[sol]), args=sc,
                        tolerances={"xatol": ROOT_XATOL, "xrtol": 0.0})
        # the bracket's lower end keeps f <= 0: within the tolerance (half ROOT_XATOL
        # further inside, as above)
        ro[sol] = np.exp(res.bracket[0] - ROOT_XATOL / 2.0)
        f_ro[sol] = ratio(np.log(ro[sol]), *sc)
    return ro, f_ro


def _secant_root(ratio: Callable, cols: tuple, x0: np.ndarray, f0: np.ndarray,
                 hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Secant steps on ``ratio`` in ``x = log r`` from ``(x0, f0)``, the first with
    slope 1, never above ``hi``, at most SECANT_STEPS more; a corner stops once
    ``|ratio| <= SETTLED`` or when its step is not downhill-finite (0/0: it stopped
    moving); each step evaluates only the corners still moving. Then half ROOT_XATOL
    inside the tolerance (``r = exp(x)`` and ``log r`` differ by round-off, which must
    not carry the kept radius across the limit). Returns ``r`` and ``ratio(log r)``,
    shape (k,) each."""
    x, f_x = x0.copy(), f0.copy()
    xp, fp = x.copy(), f_x.copy()
    act = np.flatnonzero(~(np.abs(f_x) <= SETTLED))
    if act.size:
        x[act] = np.minimum(x[act] - f_x[act], hi[act])
        f_x[act] = ratio(x[act], *(c[act] for c in cols))
        act = act[~(np.abs(f_x[act]) <= SETTLED)]
    for _ in range(SECANT_STEPS):
        if not act.size:
            break
        xa, fa = x[act], f_x[act]
        with np.errstate(divide="ignore", invalid="ignore"):
            slope = (fa - fp[act]) / (xa - xp[act])
        move = np.isfinite(slope) & (slope > 0)
        xp[act], fp[act] = xa, fa
        act = act[move]
        x[act] = np.minimum(xa[move] - fa[move] / slope[move], hi[act])
        f_x[act] = ratio(x[act], *(c[act] for c in cols))
        act = act[~(np.abs(f_x[act]) <= SETTLED)]
    r = np.exp(x - np.maximum(f_x, 0.0) - ROOT_XATOL / 2.0)
    with np.errstate(divide="ignore"):               # r = 0: f = ratio(-inf), not kept
        return r, ratio(np.log(r), *cols)


def _arc_speed_terms(lim, moving: np.ndarray, wr: np.ndarray, soft: np.ndarray,
                     centripetal_share: float, jerk_share: float
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per corner, the radius-free factors of :func:`_arc_speed`: the smallest axis term
    of ``centripetal_share a_i / rho_i`` (1/s^2) and, under SOFT, of ``jerk_share j_i /
    rho_i`` (1/s^3, ``inf`` under BRISK), and ``soft``, each shape (k,). The axis
    minima do not depend on the radius (a positive factor of every term), so they are
    taken once per corner for the fillet and both elements."""
    with np.errstate(divide="ignore", invalid="ignore"):
        k_acc = row_min(np.where(moving, centripetal_share * lim.a_max[None, :] / wr,
                                 np.inf))
        k_jerk = np.full(soft.shape, np.inf)
        if soft.any():
            k_jerk[soft] = row_min(np.where(moving[soft],
                                            jerk_share * lim.j_max[None, :] / wr[soft],
                                            np.inf))
    return k_acc, k_jerk, soft


def _arc_speed(radius: np.ndarray, k_acc: np.ndarray, k_jerk: np.ndarray,
               soft: np.ndarray) -> np.ndarray:
    """What the heuristic grants an arc of ``radius`` (mm, > 0, ``inf``: a line) in the
    fillet's plane: centripetal ``v^2 rho_i / R <= c a_i``, under SOFT also the path jerk
    ``rho_i v^3 / R^2 <= s j_i``, mm/s, shape (k,); the factors from
    :func:`_arc_speed_terms`. The roots grow with their argument, so the root of the
    smallest axis term is the smallest root: one root per corner, not one per axis."""
    with np.errstate(invalid="ignore", over="ignore"):
        v_arc = np.sqrt(k_acc * radius)
        return np.where(soft, np.minimum(v_arc, np.cbrt(k_jerk * (radius * radius))),
                        v_arc)


def _log_length_ratio(x: np.ndarray, *cols, n_geo: int, fillet: Callable) -> np.ndarray:
    """``log(r sweep / L)`` of the fillets of radius ``r = exp(x)`` (their length against
    the target ``L``, the last column), elementwise over 1-d columns;
    :data:`NO_FILLET_LOG_RATIO` where the fillet does not exist."""
    r = np.exp(x)
    f = fillet(r, *cols[:n_geo])
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(f.valid, np.log(np.maximum(r * f.sweep / cols[n_geo], 1e-300)),
                        NO_FILLET_LOG_RATIO)


def _log_tol_ratio(x: np.ndarray, *cols, n_axes: int, n_geo: int,
                   dev_fn: Callable) -> np.ndarray:
    """``log`` of the largest tolerance ratio of the fillets of radius ``exp(x)`` (per
    axis ``|C_i - M_i| / tol_i``, contour ``|C - M| / tol``), elementwise over 1-d
    columns (:func:`scipy.optimize.elementwise.find_root` passes the active ones): the
    ``n_geo`` geometry columns of the family (``dev_fn``), then the plane vectors, the
    per-axis and the contour tolerance; :data:`NO_FILLET_LOG_RATIO` where the fillet
    does not exist."""
    rest = cols[n_geo:]
    dev2, ok = dev_fn(np.exp(x), *cols[:n_geo])
    return _tol_log_ratio(dev2, ok, np.stack(rest[:n_axes], axis=1),
                          np.stack(rest[n_axes:2 * n_axes], axis=1),
                          np.stack(rest[2 * n_axes:3 * n_axes], axis=1), rest[3 * n_axes])


def _tol_log_ratio(dev2: np.ndarray, ok: np.ndarray, e1: np.ndarray, e2: np.ndarray,
                   tol: np.ndarray, cont: np.ndarray) -> np.ndarray:
    """``log`` of the largest tolerance ratio of fillets whose deviation ``C - M`` in
    plane coordinates is ``dev2`` (shape (k, 2)): per axis ``|C_i - M_i| / tol_i`` (plane
    vectors ``e1``, ``e2`` and tolerances ``tol``, shape (k, n)), contour ``|C - M| /
    cont`` (shape (k,)); :data:`NO_FILLET_LOG_RATIO` where the fillet does not exist
    (``ok`` False)."""
    dev = e1 * dev2[:, :1] + e2 * dev2[:, 1:]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.maximum(row_norms(dev) / cont, row_max_safe(np.abs(dev) / tol))
        return np.where(ok, np.log(np.maximum(ratio, 1e-300)), NO_FILLET_LOG_RATIO)


def _positive(r: np.ndarray) -> np.ndarray:
    """Radii from the closed forms, ``inf`` where there is none (not positive, ``nan``:
    that length never limits)."""
    return np.where(r > 0, r, np.inf)


def row_max_safe(x: np.ndarray) -> np.ndarray:
    """Row maxima of (k, n) ratios, ``nan`` (0/0 on a standing axis) counted as 0."""
    return np.max(np.where(np.isnan(x), 0.0, x), axis=1) if x.shape[1] else np.zeros(
        x.shape[0])


def _take(f: _Fillet, i: np.ndarray) -> _Fillet:
    return _Fillet(*(getattr(f, name)[i] for name in _Fillet.__slots__))


def _fillet_rows(corner: np.ndarray, E1: np.ndarray, E2: np.ndarray, f: _Fillet,
                 r: np.ndarray, forward: np.ndarray, block: np.ndarray) -> dict:
    """Packed rows of the fillets (one circle each, ``d = 0``): ``e1`` the unit radial
    at the construction's start, ``e2`` its direction of travel there, ``omega = 1/r``;
    an arc-into-line fillet is that circle traversed backwards (``theta0 = sweep``,
    ``omega = -1/r``)."""
    def world(v2):
        return E1 * v2[:, :1] + E2 * v2[:, 1:]

    k = r.size
    return {
        "origin": corner + world(f.centre),
        "e1": world(f.radial),
        "e2": world(f.heading),
        "d": np.zeros_like(corner),
        "radius": r.copy(),
        "omega": np.where(forward, 1.0, -1.0) / r,
        "theta0": np.where(forward, 0.0, f.sweep),
        "length": r * f.sweep,
        "block": np.asarray(block, np.int64),
        "kind": np.full(k, _ROUNDING, dtype=np.int8),
        "dradius": np.zeros(k),
        "sharpness": np.zeros(k),
    }


__all__ = ["ArcCorners", "arc_corners"]
