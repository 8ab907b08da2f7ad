"""Stage: corner rounding (G641..G645), between the path geometry and velocity planning.

sinumerik-model 5.1: "the neighbouring blocks are shortened and one or two intermediate
blocks are inserted". :func:`round_corners` does this on the :class:`Path` that both
planners share (DESIGN section 1): at every corner it rounds, it inserts segments of
kind ``"rounding"`` and shortens the two lines by the tangent distance ``d``: under
BRISK and for RND/RNDM one circular arc tangent to both lines
(:mod:`reference.core.rounding`); under SOFT (G641..G645) a symmetric pair of clothoid
pieces (:func:`reference.core.geometry.clothoid_pieces`) whose curvature rises linearly
from zero to ``theta / L_s`` and falls back to zero, so the path stays curvature
continuous and the axis motion in the rounding area can be jerk-limited (spec 5.9,
MD20480 ten-thousands digit 0: "jerk-limited under SOFT"; 5.8 "curvature-continuous";
6.3: a curvature jump would cap the speed). The segments are attributed to the block whose end is the corner ("synchronisation
events are referred to the end of the shortened first block", 5.1), so every program
block keeps exactly one :class:`BlockSpan`: that block's span now covers its shortened
line and the rounding; the next block's span starts where the rounding ends.

Per corner (break between two consecutive segments), in this order (5.2, 8):

1. the block before the corner programs RND (non-modal) or RNDM (modal radius > 0) or is
   in G641..G645, else nothing is recorded;
2. no rounding where the axes stop anyway (5.2 group 1): geometry axes moving in one
   block only (named first: it is a path stop too), a stop at the break (exact stop,
   auxiliary output before motion, M0, a positioning axis, ...), a block without path
   motion between, a change of acceleration mode (BRISK/SOFT);
3. transitions next to an arc: a tangential one (line into arc, arc into line, two
   arcs in one plane: an S-bend, or curving the same way with another radius) is
   rounded by G645 only ("G645 also inserts rounding" at "tangential transitions with a
   curvature jump", 5.7), decided and sized apart
   (:func:`reference.rounding_tangential.tangential_transitions`: an S of two clothoid
   pairs that takes up the classical shift and a curvature ramp onto the arc,
   :mod:`reference.core.transition`; between arcs :mod:`reference.core.
   transition_sbend` and :mod:`reference.core.transition_samedir`); other modes name it
   "tangential transition".
   A corner between a line and a circular arc, or between two circular arcs in one
   plane, is rounded by a tangent fillet (:func:`reference.rounding_arcs.arc_corners`,
   sized by the same mode parameters). Model limits of this version: corners next to
   helices, between arcs in different planes, and corners where non-geometry axes move
   are passed as under G64, named;
4. the rounding distance ``d`` by mode (5.3 .. 5.7):

   * G641: ``d = ADIS`` (G1/G2/G3), ``ADISPOS`` (G0), the smaller if one block is G0;
     0 means not parameterised;
   * G642/G645 (tens digit of MD20480 SMOOTHING_MODE), G643 (units digit): the largest
     ``d`` whose deviation keeps every axis within MD33100 COMPRESS_POS_TOL (digit 0, 2)
     or the contour within SD42465 SMOOTH_CONTUR_TOL (digit 1, 3); a programmed CTOL
     replaces both for the geometry axes (5.7); digit 4: ``d`` as G641. Both blocks G0:
     tolerances times MD20560 G0_TOLERANCE_FACTOR (5.7);
   * G644 (thousands digit, 5.6): 4xxx MD33100 per axis and 5xxx ADIS/ADISPOS "fully
     used"; 0xxx and 1xxx the same as a maximum, "not fully used" where the rounding of
     3xxx at the path velocity is smaller (``d = min(d_tol, d_3xxx)``, ``min(ADIS,
     d_3xxx)``; CTOL ignored); 2xxx the rounding lasts one period of the lowest
     LOOKAH_FREQUENCY at the programmed speed, 3xxx the smallest rounding the axes pass
     at the programmed speed (:func:`_dynamic_distance`); other digits named;
   * RND/RNDM: the programmed radius ``R``, ``d = R tan(theta/2)`` (a tangent arc of
     radius ``R`` is what RND defines; no speed check: it is contour, not smoothing);
   * a tolerance gives ``d = e / tan(theta/4)`` for the arc and ``d = e d_1(theta) /
     e_1(theta)`` for the clothoid pair (both shapes deviate from the corner by ``e``
     exactly; :func:`reference.core.geometry.clothoid_pair_shape`);
   * clamp: ``d <= c min(L1, L2)`` with ``c = rounding_length_clamp`` (0.5: "the
     rounding distance cannot exceed half the length of the original participating
     blocks", the G644 excerpt; 5.3); ``d`` at or below MIN_SEGMENT_LENGTH_MM: too small;
     with G642/G645 the window may reach across short blocks that continue the same
     straight line, ``L1``, ``L2`` then being those straight chains
     (:func:`_across_blocks`; the blocks it covers whole are no longer interpolated);
5. speeds (4.3, 5.2 group 2, 5.8): ``v_g64`` is the G64 corner speed (the shared
   junction rule); G641/G642/G645 round only when ``v_g64`` is below the speed of the
   lines (the overload-factor check; G643 and G644 never make it); G641/G642/G645 with
   MD20490 IGNORE_OVL_FACTOR_FOR_ADIS = TRUE and G643 "always round" (4.3, 5.5, 5.8,
   :func:`reference.core.rounding.always_rounds`): neither check is made, only the
   documented short-block case keeps an inserted block out ("between two very short
   blocks", 5.2 group 2; :func:`reference.core.rounding.very_short_blocks`; G643
   inserts none); every other mode but RND/RNDM rounds only
   when the rounding is estimated to pass the corner in less time than G64
   (:func:`corner_time_loss`: ramps on each line to the speed it runs at, its
   programmed speed and one IPO cycle per block (:func:`_line_speeds`), BRISK or
   jerk-limited, a stop costing its ramps; the part a window leaves of a block it cuts
   is counted with the rounding where its own IPO cycle caps it), with ``v_round``
   (:func:`_rounding_speed`) = min of the centripetal limit at the largest curvature,
   the one-IPO-cycle limit per inserted block (5.3: "about ADIS/T_ipo"), under SOFT the
   in-rounding jerk limit and, on the arc only, the curvature-jump limit of the shared
   rule (6.3), and the feed.

Model limits, stated: under BRISK the rounding is a tangent arc (G1 continuous,
curvature jump ``1/R`` at both ends: BRISK allows the acceleration step), under SOFT a
clothoid pair (G2), where the control inserts a polynomial of its own;
G643 rounds inside the original blocks (5.5, documented: "no separate rounding block
is inserted"; :func:`_inside_the_blocks`): the rounding's halves belong to the blocks on
either side, it has no row and no one-IPO-cycle cap of its own (its block's,
:func:`reference.core.rows.interpolation_lengths`); its shape is G642's, the per-axis
windows of the model note (5.5 "Model [I]", 5.8 "per-axis T_i") are not modelled (no
segment kind of the shared path traces an axis-wise blend; the common shape keeps every
axis within its tolerance, the documented limit); G644 inserts G642's segments (its
per-axis T_i not modelled either);
G645's rounding of tangential transitions is modelled between a line and a circle and
between two circles in one plane (curving opposite ways, S-bends, or the same way with
another radius), the rounding of corners next to arcs between a line and a circle and
between two circles in one plane (tangential arcs in different planes, helices and
spirals are named and passed as G64; a corner next to an arc gets a tangent arc, G1,
also under SOFT); a window
reaches across short blocks only along a straight chain (several corners closer than
their windows are rounded one by one, each clamped), and tangential transitions between
short blocks are never rounded (no documented mode does; the compressors COMPON/COMPCAD,
which would merge them, are not modelled), so each such block keeps its own IPO cycle.
"""

from __future__ import annotations

from dataclasses import dataclass
from operator import is_not

import numpy as np

from .core.arrays import row_dots, row_max, row_min, row_norms
from .core.geometry import KIND_CODES, Path, clothoid_pair_shape, clothoid_pieces
from .core.limits import AxisArrays
from .core.rounding import (INTERNAL_MODES, OVERLOAD_CHECKED_MODES, REASON_CODE,
                            RoundingTable, always_rounds, axis_deviation_limit,
                            break_windows, deflection_angle, distance_for_deviation,
                            fillet_pieces, very_short_blocks)
from .core.rules import FEASIBLE, curvature_jump_speed_cap, is_tangential, junction_speed_cap
from .core.tolerances import MIN_SEGMENT_LENGTH_MM, MOVING_AXIS_TOL
from .machine import Machine
from .nc.program import Program
from .rounding_arcs import arc_corners
from .rounding_tangential import tangential_transitions

#: Group-10 modes that round corners.
ROUNDING_MODES = ("G641", "G642", "G643", "G644", "G645")
#: Modes that round only where G64 would have to reduce the speed (4.3).
_OVERLOAD_CHECKED = OVERLOAD_CHECKED_MODES
_INTERNAL = INTERNAL_MODES

#: Modes whose tolerance-based rounding window may reach across several short blocks
#: (:func:`_across_blocks`). G641 and the ADIS digit (4) are limited by the block lengths
#: (5.3: "the rounding area is also limited by the block lengths"); G643 rounds inside
#: the original blocks (5.5); G644's distance "cannot exceed half the length of the
#: original participating blocks" (excerpt) -- all three keep the one-block clamp.
_ACROSS_BLOCKS = ("G642", "G645")

#: A rounding window reaches across short blocks only where the lines it covers are so
#: nearly parallel that the rounding's start ``C - d t1`` and the path point ``d`` before
#: the corner differ by at most this, mm: a tenth of the 1e-9 mm to which consecutive
#: segments meet, so the rounded path stays continuous to that.
CHAIN_MEET_MM = 1e-10

#: Share of the axis jerk the rounding-speed estimate grants the path jerk on the
#: rounding (``v^3 |q'''_i|``): the heuristic's default
#: ``PlannerParameters.arc_jerk_velocity_share`` (a test keeps the two equal), for the
#: same reason as :data:`CENTRIPETAL_SHARE`.
JERK_VELOCITY_SHARE = 0.5

#: G644 with SMOOTHING_MODE 2xxx: the rounding motion lasts at least this many periods of
#: the lowest LOOKAH_FREQUENCY of the axes with a velocity jump at the corner. The B1
#: excerpt: "the rounding area is defined so that no frequencies in excess of the
#: specified maximum can occur while the rounding motion is in progress"; spec 5.8:
#: "T_i >= 1/f_i ... Whether Siemens uses 1/f or 1/(2f) is unknown; make it a parameter"
#: (a module constant: the path must not depend on a plan's parameters, see
#: :data:`CENTRIPETAL_SHARE`). One period: an axis velocity change over ``T`` excites
#: frequencies up to about ``1/T``.
G644_FREQUENCY_PERIODS = 1.0

#: Programmed rounding radii (RND non-modal, RNDM modal): a tangent arc of that radius.
_RADIUS_MODES = ("RND", "RNDM")
_ALL_MODES = ROUNDING_MODES + _RADIUS_MODES

#: Share of the axis acceleration the rounding-speed estimate grants the centripetal part:
#: the heuristic's default ``PlannerParameters.arc_centripetal_share`` (a test keeps the two
#: equal). The path must not depend on planner parameters (the oracle runs on it too), so
#: the decision uses the default, not the parameter of a particular plan.
CENTRIPETAL_SHARE = 0.75

#: Group-10 and acceleration modes as fixed-width strings (the longest is 5 characters).
_MODE_DTYPE = "U8"

_LINE = KIND_CODES.index("line")
_ROUNDING = KIND_CODES.index("rounding")
#: Reason placeholder of G645 tangential transitions while the corners are decided.
_PENDING = 10 ** 6


def _digit(value: int, place: int) -> int:
    """Decimal digit ``place`` (0 = units) of a machine-data digit map."""
    return (int(value) // 10 ** place) % 10


def _block_attributes(program: Program, default_accel: str) -> dict[str, np.ndarray]:
    """Per program block, shape (nb,): the mode governing the corner at its end (RND,
    RNDM, else the group-10 mode), acceleration mode, ADIS, ADISPOS, CTOL (``nan`` if
    unset) and programmed rounding radius (mm); and ``mode_id``, ``accel_id`` (int, shape
    (nb,)) indexing the tuples ``mode_names``, ``accel_names`` (the distinct values), so
    that membership and equality tests compare integers (numpy compares fixed-width
    strings a character at a time, and :func:`numpy.isin` sorts them).

    Consecutive blocks share one :class:`~reference.nc.program.Modal` object while
    nothing modal changes (and blocks without extras one ``BlockExtra``), so the values
    are read once per run of blocks with the same object (:func:`_runs`).
    """
    blocks = program.blocks
    modals = [blk.modal for blk in blocks]
    uniq, code = _runs(modals)
    extras, e_code = _runs([blk.extra for blk in blocks])
    rnd = np.array([e.rnd_mm for e in extras], dtype=np.float64)[e_code]
    rndm = np.array([md.rndm_mm for md in uniq], dtype=np.float64)[code]
    # per run: group-10 mode, then RND / RNDM per block where programmed
    run_mode = [md.continuous_mode for md in uniq]
    run_accel = [md.accel_mode or default_accel for md in uniq]
    mode_names = tuple(sorted(set(run_mode) | {"RND", "RNDM"}))
    accel_names = tuple(sorted(set(run_accel)))
    mode_id = np.array([mode_names.index(v) for v in run_mode], dtype=np.int64)[code]
    mode_id = np.where(rnd > 0, mode_names.index("RND"),
                       np.where(rndm > 0, mode_names.index("RNDM"), mode_id))
    accel_id = np.array([accel_names.index(v) for v in run_accel], dtype=np.int64)[code]
    return {
        "mode": np.array(mode_names, dtype=_MODE_DTYPE)[mode_id],
        "accel": np.array(accel_names, dtype=_MODE_DTYPE)[accel_id],
        "mode_id": mode_id,
        "accel_id": accel_id,
        "mode_names": mode_names,
        "accel_names": accel_names,
        "adis": np.array([md.adis_mm for md in uniq], dtype=np.float64)[code],
        "adispos": np.array([md.adispos_mm for md in uniq], dtype=np.float64)[code],
        "ctol": np.array([np.nan if md.contour_tol_mm is None else md.contour_tol_mm
                          for md in uniq], dtype=np.float64)[code],
        "radius": np.where(rnd > 0, rnd, rndm),
    }


def _runs(items: list) -> tuple[list, np.ndarray]:
    """The first item of every run of one object (``is``) in ``items``, and the run
    index of each item, int, shape (len(items),)."""
    if not items:
        return [], np.zeros(0, dtype=np.int64)
    new = np.fromiter(map(is_not, items[1:], items[:-1]), dtype=bool, count=len(items) - 1)
    first = [items[0]] + [items[i] for i in (np.flatnonzero(new) + 1).tolist()]
    return first, np.concatenate(([0], np.cumsum(new)))


def _is_in(ids: np.ndarray, names: tuple[str, ...], chosen: tuple[str, ...]) -> np.ndarray:
    """``names[ids]`` is one of ``chosen``, bool, shape of ``ids`` (by a lookup table)."""
    return np.array([v in chosen for v in names], dtype=bool)[ids]


def round_corners(path: Path, program: Program, machine: Machine) -> Path:
    """Insert rounding segments at the corners of blocks in G641..G645.

    Parameters
    ----------
    path : Path
        The programmed contour over the machine's axes
        (:func:`reference.prepare.restrict_to_machine`).
    program : Program
        Its program (modes, ADIS/ADISPOS, CTOL, acceleration modes).
    machine : Machine
        Tolerances (MD33100, SD42465, MD20480, MD20560, MD20490), limits.

    Returns
    -------
    Path
        ``path`` itself when no block is in a rounding mode; otherwise the rounded path
        with ``rounding`` set to the per-corner :class:`RoundingTable`.
    """
    m = path.n_segments
    if m < 2:
        return path
    ch = machine.channel
    attrs = _block_attributes(program, ch.acceleration_mode)
    names = attrs["mode_names"]
    cand = np.flatnonzero(_is_in(attrs["mode_id"][path.block[:-1]], names, _ALL_MODES))
    if cand.size == 0:
        return path
    a, b = cand, cand + 1                 # segments before and after each corner
    brk = cand + 1                        # break index of each corner
    ka, kb = path.block[a], path.block[b]
    mode_arr = attrs["mode"][ka]
    mode_id = attrs["mode_id"][ka]
    accel_id = attrs["accel_id"]
    soft_id = attrs["accel_names"].index("SOFT") if "SOFT" in attrs["accel_names"] else -1
    mode = tuple(map(names.__getitem__, mode_id.tolist()))    # the names, not new strings
    reason = np.full(a.size, -1, dtype=np.int64)

    def decide(mask: np.ndarray, why: str) -> None:
        reason[(reason < 0) & mask] = REASON_CODE[why]

    geo = path.geometry
    # --- 5.2 group 1: the axes stop between the blocks anyway -----------------------
    # the documented causes first, then any other stop at the break (exact stop,
    # auxiliary output before motion, positioning axes...): a geometry-axis change is a
    # path stop as well (reference.prepare), and the trace should name it as such
    is_line = (path.kind[a] == _LINE) & (path.kind[b] == _LINE)
    da, db = path.d.take(a, axis=0), path.d.take(b, axis=0)     # rows, as d[a], faster
    geo_a = np.where(path.kind[a] == _LINE, row_norms(da[:, geo]) > MOVING_AXIS_TOL, True)
    geo_b = np.where(path.kind[b] == _LINE, row_norms(db[:, geo]) > MOVING_AXIS_TOL, True)
    decide((geo_a != geo_b) & (kb - ka <= 1), "geometry axes move in one block only")
    decide(path.stop[brk], "stop between the blocks")
    decide(kb - ka > 1, "block without path motion between")
    decide(accel_id[ka] != accel_id[kb], "acceleration mode change (BRISK/SOFT)")
    # --- transitions next to an arc: a tangential one is G645's to round (5.7,
    # :mod:`reference.rounding_tangential`), any other mode passes it as G64 does; a
    # corner next to an arc is a model limit of this version
    tang_arc = np.zeros(a.size, bool)
    near_arc = np.flatnonzero(~is_line & (reason < 0))
    if near_arc.size:
        # the arcs' tangents at the corners: evaluated once, used for both tests below
        # at the global break position, as the arcs' rows evaluate it (not
        # Path.junction_tangents, which takes the segment's own length: the two
        # differ by round-off)
        # (both sides in one call: the same elementwise numbers, half the dispatch)
        s_c = path.s_breaks[a[near_arc] + 1]
        t12 = path.tangents(np.concatenate((s_c, s_c)),
                            segment=np.concatenate((a[near_arc], a[near_arc] + 1)))
        t1_arc, t2_arc = t12[:near_arc.size], t12[near_arc.size:]
        tang_arc[near_arc] = is_tangential(t1_arc, t2_arc, FEASIBLE)
    other = np.zeros(a.size, bool)
    if not geo.all():
        other = (row_max(np.abs(da[:, ~geo])) > MOVING_AXIS_TOL) | (
            row_max(np.abs(db[:, ~geo])) > MOVING_AXIS_TOL)
    decide(other, "non-geometry axes move: rounding not modelled yet")
    decide(tang_arc & ~_is_in(mode_id, names, ("G645",)), "tangential transition")
    trans = np.flatnonzero(tang_arc & (reason < 0))
    reason[trans] = _PENDING              # decided below, apart from the corners
    arc_corner = ~is_line & ~tang_arc
    t1, t2 = da, db                       # unit tangents of lines (geometry axes only here)
    if near_arc.size:                     # at corners next to arcs: the arcs' tangents
        t1, t2 = t1.copy(), t2.copy()
        t1[near_arc], t2[near_arc] = t1_arc, t2_arc
    if near_arc.size:                     # the arcs' corners were tested above
        tangential = tang_arc.copy()
        rest = np.ones(a.size, bool)
        rest[near_arc] = False
        tangential[rest] = is_tangential(t1[rest], t2[rest], FEASIBLE)
    else:
        tangential = is_tangential(t1, t2, FEASIBLE)
    decide(tangential, "tangential transition")
    # the same test between two lines, per break (-1: not computed), for the chains
    known = np.full(m - 1, -1, dtype=np.int8)
    known[a[is_line]] = tangential[is_line]

    # --- the rounding's shape (5.8, 5.9): under SOFT the axis motion in the rounding
    # area is jerk-limited (MD20480 ten-thousands digit 0), which a curvature jump at its
    # ends would break: a clothoid pair (G2); under BRISK and for RND/RNDM (a programmed
    # radius) the tangent arc
    theta = deflection_angle(t1, t2)
    g2 = (accel_id[ka] == soft_id) & _is_in(mode_id, names, ROUNDING_MODES)
    # the clothoid pair's shape factors of the SOFT corners between lines, found once
    # for the sizing and the shape
    pair = g2 & is_line
    d_1, e_1 = _pair_factors(theta, pair)
    d, multi, targets = _distances(path, attrs, machine, a, b, ka, mode_id, t1, t2, theta,
                                   g2, pair, d_1, e_1, decide)
    # corners next to arcs: decided and sized apart (reference.rounding_arcs), after the
    # mode's parameters were checked above
    arcc = np.flatnonzero(arc_corner & (reason < 0))
    reason[arcc] = _PENDING
    # clamp (5.3, the G644 excerpt): c times the shorter participating block; where the
    # mode rounds across short blocks, the participating "block" on each side is the
    # straight chain of blocks the window may cover (:func:`_straight_chains`)
    c = ch.rounding_length_clamp
    cap = c * np.minimum(path.length[a], path.length[b])
    first, last = a.copy(), b.copy()
    if multi.any():
        cap, first, last = _across_blocks(path, attrs, a, b, d, cap, c, multi & (reason < 0),
                                          known)
    clamped = d > cap
    d = np.minimum(d, cap)
    decide(~(d > MIN_SEGMENT_LENGTH_MM), "rounding distance too small")
    shape = _shape(theta, d, g2, reason < 0, d_1, e_1, pair)
    decide(~(shape.piece > MIN_SEGMENT_LENGTH_MM), "rounding distance too small")

    # --- speeds: G64 against rounding (4.3, 5.2 group 2, 5.8) -------------------------
    lim = machine.limits.for_axes(path.axes)
    open_ = reason < 0
    v64 = np.full(a.size, np.nan)
    v_round = np.full(a.size, np.nan)
    if open_.any():
        o = np.flatnonzero(open_)
        # the open corners' rows, gathered once (usually every corner: then the arrays
        # themselves)
        if o.size == a.size:
            ao, bo, t1o, t2o, do_, mo = a, b, t1, t2, d, mode_id
        else:
            ao, bo, t1o, t2o, do_, mo = a[o], b[o], t1[o], t2[o], d[o], mode_id[o]
        # open corners are not tangential (decided above): the test is not repeated
        v64[o] = junction_speed_cap(t1o, t2o, lim.jump, FEASIBLE, tangential[o])[0]
        soft = accel_id[ka[o]] == soft_id
        # per line: programmed speed (feed, axis velocities), acceleration, jerk
        a1, a2 = np.abs(t1o), np.abs(t2o)
        # the rounding runs at most at the programmed speed; beside it each line at
        # most at its own one-IPO-cycle cap too (:func:`_line_speeds`)
        p_in, p_out = _programmed_speeds(path, lim, ao, bo, t1o, t2o)
        v_prog = np.minimum(p_in, p_out)
        v_in, v_out = _line_speeds(path, ao, bo, p_in, p_out, machine.limits.t_ipo_s)
        with np.errstate(divide="ignore"):
            acc_in = row_min(lim.a_max[None, :] / a1)
            acc_out = row_min(lim.a_max[None, :] / a2)
            j_in = np.where(soft, row_min(lim.j_max[None, :] / a1), np.inf)
            j_out = np.where(soft, row_min(lim.j_max[None, :] / a2), np.inf)
        v_round[o] = np.minimum(v_prog, _rounding_speed(t1o, t2o, theta[o], shape, o,
                                                        lim, machine.limits.t_ipo_s, soft))
        ovl = _is_in(mo, names, _OVERLOAD_CHECKED) & (not ch.ignore_ovl_factor_for_adis)
        always = always_rounds(np.array(names, dtype=_MODE_DTYPE)[mo],
                               ch.ignore_ovl_factor_for_adis)
        radius_mode = _is_in(mo, names, _RADIUS_MODES)
        sub = np.zeros(a.size, bool)
        sub[o] = ovl & (v64[o] >= np.minimum(v_in, v_out))
        decide(sub, "G64 passes the corner without reduction (overload factor)")
        # where the overload check is waived, the documented short-block case still
        # holds: an inserted block between two blocks of one IPO cycle each (G643
        # inserts none, a window across short blocks replaces several by one)
        sub[:] = False
        sub[o] = always & ~_is_in(mo, names, _INTERNAL) & (first[o] == ao) & (
            last[o] == bo) & very_short_blocks(path.length[ao], path.length[bo], v_prog,
                                               machine.limits.t_ipo_s)
        decide(sub, "rounding would slow the program down (between two very short blocks)")
        sub[:] = False
        # what the window leaves of the blocks it cuts (the corner's own two, or the
        # first and last block it touches across short blocks), with every open corner
        # counted as rounded: a block rounded at both ends keeps one IPO cycle for what
        # is left between the two roundings (5.3), so each is judged with that cap
        # (errs toward a short leftover, as the tangential transitions' estimate)
        sb = path.s_breaks
        s_c = sb[ao + 1]
        w_lo, w_hi = break_windows(sb, ao + 1, do_, do_)
        left_in = np.maximum((s_c - do_) - w_hi[first[o]], 0.0)
        left_out = np.maximum(w_lo[last[o] + 1] - (s_c + do_), 0.0)
        sub[o] = ~(corner_time_loss(v_in, v_out, v_round[o], acc_in, acc_out, j_in, j_out,
                                    shape.length[o], do_, None, left_in, left_out,
                                    machine.limits.t_ipo_s)
                   < corner_time_loss(v_in, v_out, v64[o], acc_in, acc_out, j_in, j_out,
                                      0.0, 0.0)
                   ) & ~radius_mode & ~always
        decide(sub, "rounding would be slower than G64")
    reason[reason < 0] = REASON_CODE["rounded"]
    ins = reason == 0                     # corners rounded (transitions are still pending)
    zero = np.where(ins, 1.0, 0.0)
    dist, length, dev, rad = d * zero, shape.length * zero, shape.deviation * zero, \
        shape.radius * zero
    clamped, g2_out = clamped & ins, g2 & ins
    tr = None
    if trans.size:
        # with where the corner roundings decided so far start and end, per break
        tr = tangential_transitions(path, machine, a[trans], ka[trans],
                                    attrs["accel"][ka[trans]], CENTRIPETAL_SHARE,
                                    JERK_VELOCITY_SHARE, corner_time_loss,
                                    windows=break_windows(path.s_breaks, a + 1, dist, dist))
        reason[trans] = tr.reason
        dist[trans] = np.maximum(tr.trim_in, tr.trim_out)
        length[trans], dev[trans], rad[trans] = tr.length, tr.deviation, tr.radius
        clamped[trans] = tr.clamped
        g2_out[trans] = tr.reason == 0
        v64[trans], v_round[trans] = tr.v_g64, tr.v_round
    ac = None
    if arcc.size:
        ac = arc_corners(path, machine, a[arcc], ka[arcc], mode_arr[arcc], t1[arcc],
                         t2[arcc], targets if arcc.size == a.size else
                         {key: val[arcc] for key, val in targets.items()},
                         attrs["accel"][ka[arcc]], CENTRIPETAL_SHARE, JERK_VELOCITY_SHARE,
                         corner_time_loss)
        reason[arcc] = ac.reason
        dist[arcc] = np.maximum(ac.trim_in, ac.trim_out)
        length[arcc], dev[arcc], rad[arcc] = ac.length, ac.deviation, ac.radius
        clamped[arcc] = ac.clamped
        g2_out[arcc] = False
        v64[arcc], v_round[arcc] = ac.v_g64, ac.v_round
    tangential = np.zeros(a.size, bool)
    tangential[trans] = True
    # G643 rounds inside the original blocks (5.5): between two blocks the rounding's
    # halves go to the blocks on either side (:func:`_inside_the_blocks`); a corner
    # between two segments of one block is inside that block anyway
    internal = (reason == 0) & _is_in(mode_id, names, _INTERNAL) & (ka != kb) & ~tangential
    table = RoundingTable(
        block=ka.astype(np.int64), next_block=kb.astype(np.int64), mode=mode, reason=reason,
        distance_mm=dist, length_mm=length, deviation_mm=dev, radius_mm=rad,
        clamped=clamped, v_g64=v64, v_round=v_round, g2=g2_out,
        first_block=np.where(ins, path.block[first], ka).astype(np.int64),
        last_block=np.where(ins, path.block[last], kb).astype(np.int64),
        tangential=tangential, internal=internal)
    if not (reason == 0).any():           # nothing to insert: same path, with the table
        keep = ("axes", "geometry", "rotary", "origin", "e1", "e2", "d", "radius", "omega",
                "theta0", "length", "block", "kind", "feed", "rapid", "stop", "stop_reason",
                "blocks", "source", "dradius", "sharpness")
        return Path(rounding=table, **{f: getattr(path, f) for f in keep})
    extras = []
    for part, at in ((tr, trans), (ac, arcc)):
        if part is not None and (part.reason == 0).any():
            done = part.reason == 0
            n_rows = part.n_rows if part is tr else 1
            extras.append((a[at[done]], part.trim_in[done],
                           part.trim_out[done], part.rows, n_rows, internal[at[done]]))
    return _assemble(path, a[ins], d[ins], t1[ins], t2[ins], g2[ins], shape.piece[ins],
                     table, extras, internal[ins])


def _distances(path: Path, attrs: dict[str, np.ndarray], machine: Machine, a: np.ndarray,
               b: np.ndarray, ka: np.ndarray, mode: np.ndarray, t1: np.ndarray,
               t2: np.ndarray, theta: np.ndarray, g2: np.ndarray, pair: np.ndarray,
               d_1: np.ndarray, e_1: np.ndarray, decide
               ) -> tuple[np.ndarray, np.ndarray, dict]:
    """Tangent distance per corner by mode, before the block-length clamp, mm, shape (k,);
    whether the corner's window may reach across short blocks (G642/G645 with a
    tolerance, :data:`_ACROSS_BLOCKS`), bool, shape (k,); and the limits themselves for
    the corners next to arcs (:func:`reference.rounding_arcs.arc_corners`): ``how``
    (the HOW_ codes there), ``dist`` (ADIS/ADISPOS), ``contour`` and ``axis_tol`` (shape
    (k, n)) tolerances, ``g0`` (their factor), ``deviation`` (the contour deviation the
    tolerances allow between the tangents, times ``g0``; ``nan`` where no corner is of
    the tolerance type), ``radius`` (RND/RNDM), ``dyn_radius``
    and ``dyn_length`` (G644 2xxx/3xxx, and 0xxx/1xxx as their cap,
    :func:`_dynamic_distance`), mm, ``dyn_cap`` (bool: G644 0xxx/1xxx). ``mode``:
    each corner's mode as an index into ``attrs["mode_names"]``, int, shape (k,);
    ``g2`` (bool, shape (k,)): the rounding is a clothoid pair; ``pair`` (bool, shape
    (k,)): it is, between two lines (elsewhere the distance is not used), where
    ``d_1``, ``e_1`` (shape (k,)) hold its shape factors (:func:`_pair_factors`)."""
    ch = machine.channel
    sm = ch.smoothing_mode
    k = a.size
    ra, rb = path.rapid[a], path.rapid[b]
    adis, adispos, ctol = attrs["adis"][ka], attrs["adispos"][ka], attrs["ctol"][ka]
    radius = attrs["radius"][ka]
    # how each corner's distance is found: ADIS, TOL (MD33100 per axis and maybe a
    # contour tolerance), RADIUS (RND/RNDM) or NONE (not modelled)
    NONE, ADIS, TOL, RADIUS, FREQ, DYN = 0, 1, 2, 3, 4, 5
    how = np.full(k, NONE, dtype=np.int8)
    contour = np.full(k, np.inf)
    use_axis_tol = np.ones(k, bool)
    names = attrs["mode_names"]
    how[_is_in(mode, names, _RADIUS_MODES)] = RADIUS
    how[_is_in(mode, names, ("G641",))] = ADIS
    dig644 = _digit(sm, 3)
    is644 = _is_in(mode, names, ("G644",))
    how[is644] = {0: TOL, 1: ADIS, 2: FREQ, 3: DYN, 4: TOL, 5: ADIS}.get(dig644, NONE)
    # G644 0xxx/1xxx (spec 5.6): the tolerance or the distance is a maximum that the
    # rounding "if the dynamics allow" does not fully use: the rounding of 3xxx (the
    # axes' maximum dynamics at the path velocity) where it is smaller; 4xxx/5xxx use
    # them fully ("where possible": the block-length clamp)
    dyn_cap = is644 & (dig644 in (0, 1))
    for md, place in (("G642", 1), ("G645", 1), ("G643", 0)):
        sel = _is_in(mode, names, (md,))
        dig = _digit(sm, place)
        if dig == 4:
            how[sel] = ADIS
            continue
        how[sel] = TOL
        has_ctol = sel & ~np.isnan(ctol)           # CTOL overrides MD/SD values (5.7)
        contour[has_ctol], use_axis_tol[has_ctol] = ctol[has_ctol], False
        if dig in (1, 3):
            rest = sel & np.isnan(ctol)
            contour[rest], use_axis_tol[rest] = ch.smooth_contour_tol_mm, False
    d = np.zeros(k)
    # G641-type: ADIS for G1/G2/G3, ADISPOS for G0, the smaller if one block is G0 (5.3)
    dist = np.where(ra & rb, adispos, np.where(ra | rb, np.minimum(adis, adispos), adis))
    is_adis = how == ADIS
    decide(is_adis & (dist <= 0) & ((ra & rb) | ((ra | rb) & (adispos <= adis))),
           "rounding not parameterised (ADISPOS = 0)")
    decide(is_adis & (dist <= 0), "rounding not parameterised (ADIS = 0)")
    d = np.where(is_adis, dist, d)
    # tolerance type (5.4): per-axis MD33100 on the axes it applies to, contour tolerance
    is_tol = how == TOL
    tol_k = np.full((k, path.n_axes), np.inf)
    g0 = np.where(ra & rb, ch.g0_tolerance_factor, 1.0)
    dev = np.full(k, np.nan)
    if is_tol.any():
        tol = np.array([machine.settings_of(ax).compress_pos_tol_mm for ax in path.axes])
        tol_k = np.where(use_axis_tol[:, None] | ~path.geometry[None, :], tol[None, :], np.inf)
        dev = np.minimum(contour, axis_deviation_limit(t1, t2, tol_k)) * g0
        decide(is_tol & ~(dev > 0), "rounding not parameterised (tolerance 0)")
        dev0 = np.maximum(dev, 0.0)
        d_dev = np.array(distance_for_deviation(theta, dev0), dtype=np.float64)
        c = np.flatnonzero(pair)
        if c.size:
            # both scale with the piece length: d = deviation d_1 / e_1
            with np.errstate(divide="ignore", invalid="ignore"):
                d_dev[c] = dev0[c] * d_1[c] / e_1[c]
        d = np.where(is_tol & (dev > 0), d_dev, d)
    # RND/RNDM: the programmed radius, d = R tan(theta/2)
    d = np.where(how == RADIUS, radius * np.tan(theta / 2.0), d)
    # G644 2xxx (frequency) and 3xxx (maximum dynamics): sized by the path velocity
    dyn = np.flatnonzero((how == FREQ) | (how == DYN) | dyn_cap)
    dyn_radius, dyn_length = np.zeros(k), np.zeros(k)
    if dyn.size:
        d_dyn, dyn_radius[dyn], dyn_length[dyn] = _dynamic_distance(
            path, machine, a[dyn], b[dyn], t1[dyn], t2[dyn], theta[dyn], g2[dyn],
            how[dyn] == FREQ)
        # 0xxx/1xxx: the smaller of the mode's distance and the dynamic one (fmin: a
        # reversal has no plane, and no dynamic size, but its tolerance distance)
        d[dyn] = np.where(dyn_cap[dyn], np.fmin(d[dyn], d_dyn), d_dyn)
    decide(how == NONE, "G644 SMOOTHING_MODE digit not documented")
    multi = _is_in(mode, names, _ACROSS_BLOCKS) & (how == TOL)
    targets = {"how": how, "dist": dist, "contour": contour, "axis_tol": tol_k, "g0": g0,
               "deviation": dev, "radius": radius, "dyn_radius": dyn_radius,
               "dyn_length": dyn_length, "dyn_cap": dyn_cap}
    return np.where(np.isfinite(d), d, 0.0), multi, targets


def _programmed_speeds(path: Path, lim: AxisArrays, a: np.ndarray, b: np.ndarray,
                       t1: np.ndarray, t2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Programmed path speed of the lines before and after corners (feed and the axis
    velocities along each line), mm/s, shape (k,) each."""
    with np.errstate(divide="ignore"):
        v_in = np.minimum(path.feed[a], row_min(lim.v_max[None, :] / np.abs(t1)))
        v_out = np.minimum(path.feed[b], row_min(lim.v_max[None, :] / np.abs(t2)))
    return v_in, v_out


def _line_speeds(path: Path, a: np.ndarray, b: np.ndarray, v_in: np.ndarray,
                 v_out: np.ndarray, t_ipo: float) -> tuple[np.ndarray, np.ndarray]:
    """Speed the segments before and after corners can run at beside the corner, mm/s,
    shape (k,) each: the programmed speed (``v_in``, ``v_out``:
    :func:`_programmed_speeds`) and at most one segment per IPO cycle, ``L / T_ipo``
    (5.3: "every block ... needs at least one interpolation point"; the heuristic caps
    every segment so, :func:`reference.planner.limit_curves.segment_limits`).

    The decision's estimate (:func:`corner_time_loss`) ramps each side between the
    corner speed and this speed and counts the length a rounding replaces at it. With
    the programmed speed alone, a corner between blocks shorter than ``v T_ipo`` (CAM
    chains of short blocks; ``lcnc_short_segments_0.001.ngc``: 0.0254 mm blocks, whose
    cap at 1 ms is 25.4 mm/s, not the 203 mm/s of the axis velocity) was estimated with
    ramps from a speed the lines never reach and with the replaced stretch passed at it:
    on the LinuxCNC machine 0.4 ms slower per corner than G64, where the plan is 1.1 ms
    faster. The overload-factor check compares with the same speed: G64 passes a corner
    "without a reduction" (4.3) where its corner speed is at least what the blocks run
    at.
    """
    return (np.minimum(v_in, path.length[a] / t_ipo),
            np.minimum(v_out, path.length[b] / t_ipo))


def _plane_weights(t1: np.ndarray, t2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit normal of the corner's plane towards ``t2`` and each axis's weight in that
    plane ``rho_i = sqrt(n_i^2 + t1_i^2)`` (a curvature ``kappa`` in the plane moves axis
    ``i`` with at most ``rho_i kappa v^2``), shape (k, n) each."""
    normal = t2 - row_dots(t2, t1)[:, None] * t1
    normal /= row_norms(normal)[:, None]
    return normal, np.sqrt(normal ** 2 + t1 ** 2)


def _dynamic_distance(path: Path, machine: Machine, a: np.ndarray, b: np.ndarray,
                      t1: np.ndarray, t2: np.ndarray, theta: np.ndarray, g2: np.ndarray,
                      freq: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Tangent distance of G644 with SMOOTHING_MODE 3xxx (``freq`` False) or 2xxx
    (``freq`` True), before the block-length clamp, mm, shape (k,); and for a tangent
    arc whose turn is not known in advance (the fillets at arc corners,
    :mod:`reference.rounding_arcs`) the same rules as the smallest radius (3xxx:
    ``1 / K_a``, under SOFT also ``1 / sqrt(K_j)``, the fillet staying an arc; 2xxx: 0)
    and the length the arc must have (3xxx ``v T_ipo``, 2xxx ``v T``), mm, shape (k,)
    each.

    Both are sized by "the current path velocity" (B1 excerpt), here the programmed speed
    ``v`` of the slower line (:func:`_programmed_speeds`):

    * 3xxx, "any axis that has a velocity jump at a corner traverses around the corner
      with the maximum possible dynamic response ... neither the maximum deviations nor
      the rounding distance are checked": the smallest rounding the axes pass at ``v``
      with the dynamics the heuristic grants a curved segment (the rules of
      :func:`_rounding_speed`, so that the rounding is passed at ``v``: centripetal
      ``rho_i kappa v^2 <= CENTRIPETAL_SHARE A_i``; under SOFT also the jerk
      ``rho_i |q3| v^3 <= JERK_VELOCITY_SHARE J_i``, ``q3`` the third path derivative;
      one IPO cycle per piece, ``piece >= v T_ipo``). Tangent arc: ``R = max(1 / K_a,
      v T_ipo / theta)``, ``d = R tan(theta/2)``. Clothoid pair of piece ``L``:
      ``kappa_max = theta / L`` and ``|q3| = theta sqrt(1 + theta^2) / L^2``, so
      ``L = max(theta / K_a, sqrt(theta sqrt(1 + theta^2) / K_j), v T_ipo)``,
      ``d = L d_1(theta)``; ``K_a = min_i share A_i / (rho_i v^2)``, ``K_j = min_i
      share J_i / (rho_i v^3)``.
    * 2xxx, "the rounding distance is limited to a minimum value, which results from the
      maximum permissible excitation frequency and the current path velocity": the
      rounding lasts ``T = G644_FREQUENCY_PERIODS / f`` at ``v`` (``f`` the lowest
      LOOKAH_FREQUENCY of the axes whose velocity jumps, ``|t2_i - t1_i| > 0``), so its
      length is ``v T``: arc ``R = v T / theta``; clothoid pair ``L = v T / 2``.

    Both then take the block-length clamp like every mode ("any further limitations are
    also effective ... the rounding distance cannot exceed half the length of the
    original participating blocks").
    """
    lim = machine.limits.for_axes(path.axes)
    t_ipo = machine.limits.t_ipo_s
    v_in, v_out = _programmed_speeds(path, lim, a, b, t1, t2)
    v = np.minimum(v_in, v_out)
    with np.errstate(divide="ignore", invalid="ignore"):    # a reversal: no plane
        _, rho = _plane_weights(t1, t2)
    moving = rho > 0
    w = np.where(moving, rho, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        k_a = row_min(np.where(moving, CENTRIPETAL_SHARE * lim.a_max[None, :]
                               / (w * (v * v)[:, None]), np.inf))
        k_j = row_min(np.where(moving, JERK_VELOCITY_SHARE * lim.j_max[None, :]
                               / (w * (v * v * v)[:, None]), np.inf))
        # 3xxx: the arc's radius, the clothoid pair's piece length
        r_dyn = np.maximum(1.0 / k_a, v * t_ipo / theta)
        l_dyn = np.maximum(np.maximum(theta / k_a,
                                      np.sqrt(theta * np.sqrt(1.0 + theta * theta) / k_j)),
                           v * t_ipo)
        # 2xxx: the rounding's duration at v
        jump = np.abs(t2 - t1) > 0
        f = row_min(np.where(jump, lim.frequency_hz[None, :], np.inf))
        length = v * G644_FREQUENCY_PERIODS / f
        radius = np.where(freq, length / theta, r_dyn)
        piece = np.where(freq, length / 2.0, l_dyn)
        d_1, _ = clothoid_pair_shape(np.clip(theta, 1e-300, None))
        d = np.where(g2, piece * d_1, radius * np.tan(theta / 2.0))
        r_min = np.where(freq, 0.0, np.where(g2, np.maximum(1.0 / k_a, 1.0 / np.sqrt(k_j)),
                                              1.0 / k_a))
    return (np.where(np.isfinite(d), d, 0.0), r_min,
            np.where(freq, length, v * t_ipo))


def _straight_chains(path: Path, attrs: dict[str, np.ndarray], known: np.ndarray | None = None
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Maximal runs of line segments that one rounding window may cover, and their lengths.

    Two consecutive segments are in one run when both are lines of consecutive program
    blocks (no block between), the break between them is tangential (the shared rule,
    :func:`reference.core.rules.is_tangential`) and carries no stop, and both blocks
    agree in group-10 mode, acceleration mode, feed and G0: the blocks of a run are then
    one straight stretch of the contour that the control can replace in part by a
    rounding block without anything else changing along it.

    Parameters
    ----------
    known : numpy.ndarray of int8, shape (m - 1,), optional
        Per break, the tangency already decided by the same rule (1, 0), or -1: the
        corners' own test (:func:`round_corners`), not repeated here.

    Returns
    -------
    run : numpy.ndarray of int, shape (m,)
        Run index of each segment (non-decreasing).
    run_length : numpy.ndarray, shape (max(run) + 1,)
        Length of each run, mm.
    """
    blk = path.block
    line = path.kind == _LINE
    ok = line[:-1] & line[1:] & ~path.stop[1:-1] & (np.diff(blk) == 1)
    mode, accel = attrs["mode_id"], attrs["accel_id"]
    ok &= mode[blk[:-1]] == mode[blk[1:]]
    ok &= accel[blk[:-1]] == accel[blk[1:]]
    ok &= (path.feed[:-1] == path.feed[1:]) & (path.rapid[:-1] == path.rapid[1:])
    sel = np.flatnonzero(ok)
    tang = known[sel] if known is not None else np.full(sel.size, -1, dtype=np.int8)
    todo = np.flatnonzero(tang < 0)
    tang = tang > 0
    if todo.size:
        j = sel[todo]
        tang[todo] = is_tangential(path.d[j], path.d[j + 1], FEASIBLE)
    ok[sel] = tang
    run = np.concatenate(([0], np.cumsum(~ok)))
    return run, np.bincount(run, weights=path.length)


def _across_blocks(path: Path, attrs: dict[str, np.ndarray], a: np.ndarray, b: np.ndarray,
                   d: np.ndarray, cap: np.ndarray, c: float, sel: np.ndarray,
                   known: np.ndarray | None = None
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Clamp and window ends of corners whose rounding may span several short blocks.

    Model [I] of rounding across short blocks (issue item: "where the documented modes
    allow rounding across several short blocks"): with G642/G645 the tolerance, not the
    block, fixes the rounding distance (5.4: ``d`` from MD33100 / SD42465 / CTOL), and
    the rounding "replaces the area near the original angular transition" (FB1 excerpt,
    5.1) -- so where the blocks beside the corner are shorter than ``d``, the window
    runs on into the blocks before and after as long as they continue the same straight
    line (:func:`_straight_chains`), and those blocks are covered by the rounding block
    (what the control then interpolates is one rounding block instead of several short
    ones, so the one-IPO-cycle-per-block cap applies to the rounding's length, 5.3).
    The clamp "at most half of the participating blocks" (the G644 excerpt) then applies
    to the straight chain on each side: two windows on one chain never overlap. A window
    does not pass a non-tangential break: several corners closer together than their
    windows are rounded one by one, each clamped (a blend over several corners is not
    modelled).

    Parameters
    ----------
    a, b : numpy.ndarray of int, shape (k,)
        Segments before and after each corner (lines).
    d : numpy.ndarray, shape (k,)
        Tangent distance by mode, before any clamp, mm.
    cap : numpy.ndarray, shape (k,)
        The one-block clamp ``c min(L_a, L_b)``, mm.
    c : float
        The clamp factor (``rounding_length_clamp``).
    sel : numpy.ndarray of bool, shape (k,)
        Corners that may reach across blocks.
    known : numpy.ndarray of int8, shape (m - 1,), optional
        Tangency per break where already decided (:func:`_straight_chains`).

    Returns
    -------
    cap : numpy.ndarray, shape (k,)
        The clamp, on ``sel`` ``c`` times the shorter straight chain, mm.
    first, last : numpy.ndarray of int, shape (k,)
        First and last segment the window ``[S - d', S + d']`` touches (``a`` and ``b``
        unless it reaches further; ``d' = min(d, cap)``).
    """
    first, last = a.copy(), b.copy()
    # only a clamped corner can reach further (``wide <= d``): the chains are needed
    # only if there is one
    o = np.flatnonzero(sel & (d > cap))
    if o.size == 0:
        return cap, first, last
    run, run_len = _straight_chains(path, attrs, known)
    wide = np.minimum(c * np.minimum(run_len[run[a[o]]], run_len[run[b[o]]]), d[o])
    reach = wide > np.minimum(cap[o], d[o])
    o, wide = o[reach], wide[reach]
    if o.size == 0:
        return cap, first, last
    sb = path.s_breaks
    corner = sb[a[o] + 1]
    f = np.maximum(np.searchsorted(sb, corner - wide, side="right") - 1, 0)
    g = np.minimum(np.searchsorted(sb, corner + wide, side="left") - 1, path.n_segments - 1)
    # the lines of a chain are tangential (angle <= TANGENT_TOL_RAD), not bit-parallel:
    # the rounding starts at C - d t1 on the corner's own line, the covered part of the
    # chain ends at the path point S - d; they differ by at most d max_j |t_j - t_a|
    # (sum of the covered lengths times their direction errors). Where that could exceed
    # CHAIN_MEET_MM the window stays within the two blocks (the one-block clamp).
    err = np.maximum(_max_dir_error(path, f, a[o], a[o]),
                     _max_dir_error(path, b[o], g, b[o])) * wide
    good = err <= CHAIN_MEET_MM
    o, f, g, wide = o[good], f[good], g[good], wide[good]
    cap = cap.copy()
    cap[o] = wide
    first[o], last[o] = f, g
    return cap, first, last


def _max_dir_error(path: Path, lo: np.ndarray, hi: np.ndarray, ref: np.ndarray
                   ) -> np.ndarray:
    """``max_{lo <= j <= hi} |t_j - t_ref|`` per range (segment directions), shape (k,)."""
    out = np.zeros(lo.size)
    cnt = hi - lo + 1
    owner = np.repeat(np.arange(lo.size), cnt)
    flat = lo[owner] + np.arange(int(cnt.sum())) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    np.maximum.at(out, owner, row_norms(path.d[flat] - path.d[ref[owner]]))
    return out


def corner_time_loss(v_in: np.ndarray, v_out: np.ndarray, v_corner: np.ndarray,
                     a_in: np.ndarray, a_out: np.ndarray, j_in: np.ndarray,
                     j_out: np.ndarray, inserted: np.ndarray | float,
                     replaced: np.ndarray | float,
                     replaced_out: np.ndarray | float | None = None,
                     left_in: np.ndarray | None = None, left_out: np.ndarray | None = None,
                     t_ipo: float = 0.0) -> np.ndarray:
    """Time a corner passed at ``v_corner`` costs against passing it at the programmed
    speeds, s: the decision's estimate of "rounding would slow the program down"
    (5.2 group 2, 4.3). Only the comparison of two such numbers (rounding, G64) is used;
    the heuristic then plans whichever contour results exactly.

    Each side ``i`` (the line before, with speed ``v_in``, and the one after,
    ``v_out``) ramps between the corner speed ``v`` and its own speed ``v_i``: ``v =
    min(v_corner, v_in, v_out)`` at a G64 corner (one point), ``min(v_corner, v_i)``
    beside a rounding (which may be faster than a side that its IPO cycle caps: it
    replaces such blocks by one of its own). The ramp lasts ``T_i = dv_i / a_i`` (BRISK), ``dv_i / a_i +
    a_i / j_i`` (SOFT, where it reaches ``a_i``: ``dv_i >= a_i^2 / j_i``) or ``2 sqrt(dv_i
    / j_i)``, and is symmetric in time, so it covers ``(v + v_i) T_i / 2`` and costs
    ``T_i dv_i / (2 v_i)`` more than that distance at ``v_i``. A rounding of length ``l``
    adds ``l / v_x`` (it is passed at about its own speed: a SOFT profile crosses its
    ends at zero path acceleration; ``v_x = min(v_corner, sqrt(v^2 + a l))``, what a
    BRISK ramp from the slower side reaches by its middle) and removes ``replaced`` of each line, which would have been
    passed at ``v_i``. Per side because the two lines may have other programmed speeds
    (a G0 into a G1 at a low feed: the rounding runs at the lower, the replaced stretch
    of the G0 at rapid speed).

    The part of a shortened block left beside the rounding (``left_in``, ``left_out``)
    is still one block and needs one IPO cycle (5.3): its cap ``r / T_ipo`` may bind
    where the block itself did not (a 0.0254 mm block cut to half, at 4 ms: 3.2 mm/s,
    below a rounding passed at 4.4 mm/s). Where that cap is below the side's speed and
    below the speed a ramp from the rounding reaches at the far end of the piece
    (``sqrt(v^2 + 2 a_i r)``, the BRISK ramp: under SOFT the ramp reaches less, so the
    test errs toward the cap binding), the piece is counted with the rounding: passed at
    ``v = min(v_corner, r / T_ipo)``, its length added to ``l`` and to the side's
    ``replaced``.

    Parameters
    ----------
    v_in, v_out : numpy.ndarray, shape (k,)
        Speed of the line before and after (programmed: feed, axis velocities; and one
        IPO cycle per block), mm/s.
    v_corner : numpy.ndarray, shape (k,)
        Speed at the corner (G64: the corner rule; rounding: the rounding's speed), mm/s.
    a_in, a_out : numpy.ndarray, shape (k,)
        Path acceleration of each line, mm/s^2.
    j_in, j_out : numpy.ndarray, shape (k,)
        Path jerk of each line, mm/s^3 (``inf``: BRISK).
    inserted : numpy.ndarray or float
        Rounding length ``l``, mm (0 for G64).
    replaced : numpy.ndarray or float
        Length cut from each line, mm (the tangent distance ``d``; 0 for G64).
    replaced_out : numpy.ndarray or float, optional
        Length cut from the segment after, where it differs from ``replaced`` (then cut
        from the segment before only): G645's tangential transitions replace more of
        the line than of the arc.
    left_in, left_out : numpy.ndarray, shape (k,), optional
        Length left of the shortened block before and after the rounding, mm (none
        given: not counted).
    t_ipo : float
        IPO cycle, s (used with ``left_in``, ``left_out``).

    Returns
    -------
    numpy.ndarray, shape (k,)
        s; ``inf`` for a rounding that would be passed at no speed.
    """
    inserted = np.asarray(inserted, dtype=np.float64)
    cut_in = np.asarray(replaced, dtype=np.float64)
    cut_out = cut_in if replaced_out is None else np.asarray(replaced_out, dtype=np.float64)
    # the speed each side's ramp ends at: a G64 corner is one point, passed at most at
    # the slower side's speed; a rounding may be faster than a side capped by its IPO
    # cycle (it replaces such blocks by one block of its own, 5.3), so each side ramps
    # to the rounding's speed or its own, whichever is lower
    point = np.minimum(v_corner, np.minimum(v_in, v_out))
    curve = inserted > 0
    v_s = [np.where(curve, np.minimum(v_corner, v_p), point) for v_p in (v_in, v_out)]
    left = [np.zeros(np.shape(point)), np.zeros(np.shape(point))]
    if left_in is not None and t_ipo > 0:
        for i, (r, v_p, a) in enumerate(((left_in, v_in, a_in), (left_out, v_out, a_out))):
            with np.errstate(invalid="ignore"):
                cap = r / t_ipo
                binds = ((r > MIN_SEGMENT_LENGTH_MM) & (cap < v_p)
                         & (cap < np.sqrt(v_s[i] * v_s[i] + 2.0 * a * r)))
            left[i] = np.where(binds, r, 0.0)
            v_s[i] = np.where(binds, np.minimum(v_s[i], cap), v_s[i])
        cut_in, cut_out = cut_in + left[0], cut_out + left[1]
    # the rounding itself: at its own speed, as far as a ramp from the slower side
    # reaches by its middle (BRISK)
    v_lo = np.minimum(v_s[0], v_s[1])
    v_x = np.minimum(v_corner, np.sqrt(v_lo * v_lo + np.minimum(a_in, a_out) * inserted))
    total = np.zeros(np.shape(point))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for v_p, v, a, j, cut, r in ((v_in, v_s[0], a_in, j_in, cut_in, left[0]),
                                     (v_out, v_s[1], a_out, j_out, cut_out, left[1])):
            dv = np.maximum(v_p - v, 0.0)
            reach = dv * j >= a * a
            T = np.where(reach, dv / a + a / j, 2.0 * np.sqrt(dv / j))
            T = np.where(dv > 0, T, 0.0)
            total = total + np.where(np.isfinite(v_p) & (v_p > 0),
                                     T * dv / (2.0 * v_p) - cut / v_p, 0.0)
            total = total + np.where(r > 0, r / v, 0.0)
        total = total + np.where(curve, inserted / v_x, 0.0)
    # a stop costs its ramps; only a rounding passed at no speed would never end
    return np.where((v_x > 0) | ~curve, total, np.inf)


@dataclass(frozen=True, slots=True, eq=False)
class _Shape:
    """Per corner, the rounding's size (0 where none): ``piece`` the length of each
    inserted segment, ``length`` of the whole rounding, ``deviation`` from the corner,
    ``radius`` the smallest radius of curvature, ``kappa`` the largest curvature and
    ``sharp`` the clothoid's curvature rate (0 on arcs), all shape (k,), mm, 1/mm,
    1/mm^2."""

    piece: np.ndarray
    length: np.ndarray
    deviation: np.ndarray
    radius: np.ndarray
    kappa: np.ndarray
    sharp: np.ndarray


def _shape(theta: np.ndarray, d: np.ndarray, g2: np.ndarray, open_: np.ndarray,
           d_1: np.ndarray, e_1: np.ndarray, known: np.ndarray) -> _Shape:
    """Size of the rounding of tangent distance ``d`` at each open corner; ``d_1``,
    ``e_1`` the clothoid pair's shape factors where ``known`` (:func:`_pair_factors`),
    found here for the other clothoid pairs.

    Tangent arc (``reference.core.rounding``): ``R = d / tan(theta/2)``, length
    ``R theta``, deviation ``d tan(theta/4)``. Clothoid pair
    (:func:`reference.core.geometry.clothoid_pair_shape`, both pieces of length ``L_s``):
    ``L_s = d / d_1(theta)``, length ``2 L_s``, deviation ``L_s e_1(theta)``, largest
    curvature ``theta / L_s`` in the middle, curvature rate ``theta / L_s^2``.
    """
    z = np.zeros_like(d)
    ok = open_ & (d > 0)
    if not ok.any():                      # no corner to size (e.g. all next to arcs)
        return _Shape(z, z.copy(), z.copy(), z.copy(), z.copy(), z.copy())
    # the pair's shape where it is one and not known yet (elementwise: the same numbers
    # as on all rows; the open corners are not tangential, theta > 0)
    c = np.flatnonzero(g2 & ok & ~known)  # the other rows read neither
    if c.size:
        d_1, e_1 = d_1.copy(), e_1.copy()
        d_1[c], e_1[c] = clothoid_pair_shape(theta[c])
    with np.errstate(divide="ignore", invalid="ignore"):
        r_arc = d / np.tan(theta / 2.0)
        piece_c = d / d_1
        piece = np.where(ok, np.where(g2, piece_c, r_arc * theta), z)
        length = np.where(g2, 2.0 * piece, piece)
        deviation = np.where(ok, np.where(g2, piece_c * e_1, d * np.tan(theta / 4.0)), z)
        kappa = np.where(ok, np.where(g2, theta / piece_c, 1.0 / r_arc), z)
        radius = np.where(ok, 1.0 / kappa, z)
        sharp = np.where(ok & g2, theta / (piece_c * piece_c), z)
    return _Shape(piece, length, deviation, radius, kappa, sharp)


def _pair_factors(theta: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The clothoid pair's tangent distance and deviation per unit piece length
    (:func:`reference.core.geometry.clothoid_pair_shape`) at the corners ``rows`` (bool,
    shape (k,)), 1 elsewhere, shape (k,) each; ``theta`` clipped above 0 (a tangential
    corner is sized, then decided as such)."""
    d_1, e_1 = np.ones_like(theta), np.ones_like(theta)
    c = np.flatnonzero(rows)
    if c.size:
        d_1[c], e_1[c] = clothoid_pair_shape(np.clip(theta[c], 1e-300, None))
    return d_1, e_1


def _rounding_speed(t1: np.ndarray, t2: np.ndarray, theta: np.ndarray, shape: _Shape,
                    o: np.ndarray, lim: AxisArrays, t_ipo: float,
                    soft: np.ndarray) -> np.ndarray:
    """Model speed through the roundings of corners ``o`` (5.8, 6.3, 6.4), mm/s,
    shape (k,).

    Centripetal ``sqrt(CENTRIPETAL_SHARE A_i / (rho_i kappa_max))``; one IPO cycle per
    inserted block (5.3: a piece of length ``l`` is passed at most at ``l / T_ipo``);
    under SOFT the in-rounding jerk ``rho_i |q3| v^3 <= J_i`` (``q3`` the third path derivative: ``|q3| = kappa^2`` on
    the arc, at most ``hypot(kappa_max^2, c)`` on a clothoid) and, on the arc only, the
    curvature-jump rule at both ends (6.3; a clothoid pair starts and ends with zero
    curvature, as the lines do).
    """
    kappa, sharp, piece = shape.kappa, shape.sharp, shape.piece
    if o.size < kappa.size:                         # (every corner: the arrays themselves)
        kappa, sharp, piece = kappa[o], sharp[o], piece[o]
    clo = sharp > 0
    normal, rho = _plane_weights(t1, t2)            # plane weight of each axis
    with np.errstate(divide="ignore", invalid="ignore"):
        a_c = CENTRIPETAL_SHARE * lim.a_max[None, :]
        w = np.where(rho > 0, rho, 1.0)
        v_c = row_min(np.where(rho > 0, np.sqrt(a_c / (w * kappa[:, None])), np.inf))
    out = np.minimum(v_c, piece / t_ipo)
    sel = np.flatnonzero(soft)                      # the SOFT rules, on those corners only
    if sel.size == 0:
        return out
    if sel.size < out.size:                         # (all SOFT: the arrays themselves)
        kappa, sharp, clo, rho, w = kappa[sel], sharp[sel], clo[sel], rho[sel], w[sel]
    q3 = np.where(clo, np.hypot(kappa * kappa, sharp), kappa * kappa)
    with np.errstate(divide="ignore", invalid="ignore"):
        v_j = row_min(np.where(rho > 0, np.cbrt(JERK_VELOCITY_SHARE * lim.j_max[None, :]
                                                / (w * q3[:, None])), np.inf))
    # the arc's curvature vector jumps from 0 to kappa n at the start and from the
    # rotated normal to 0 at the end (same magnitude per axis bounded by rho kappa); a
    # clothoid pair has none
    v_k = np.full(sel.size, np.inf)
    arc = np.flatnonzero(~clo)
    if arc.size:
        i = sel[arc]
        nrm, ka, th = normal[i], kappa[arc][:, None], theta[i]
        k_end = (nrm * np.cos(th)[:, None] - t1[i] * np.sin(th)[:, None]) * ka
        zero = np.zeros_like(nrm)
        v_k[arc] = np.minimum(
            curvature_jump_speed_cap(zero, nrm * ka, lim.path_trans_jerk, t_ipo),
            curvature_jump_speed_cap(k_end, zero, lim.path_trans_jerk, t_ipo))
    out[sel] = np.minimum(out[sel], np.minimum(v_j, v_k))
    return out


def _inserted_rows(corner: np.ndarray, t1: np.ndarray, t2: np.ndarray, d: np.ndarray,
                   g2: np.ndarray, piece: np.ndarray, block: np.ndarray
                   ) -> dict[str, np.ndarray]:
    """Packed rows of the inserted roundings in corner order: one tangent arc
    (:func:`reference.core.rounding.fillet_pieces`) or the two pieces of a clothoid
    pair (:func:`reference.core.geometry.clothoid_pieces`) per corner."""
    arcs = fillet_pieces(corner, t1, t2, d, block, _ROUNDING)
    arcs["sharpness"] = np.zeros(d.size)
    if not g2.any():
        return arcs
    c = np.flatnonzero(g2)
    pairs = clothoid_pieces(corner[c] - d[c, None] * t1[c], t1[c], t2[c], piece[c],
                            block[c], _ROUNDING)
    # interleave: corner order, one row per arc, two per pair
    n_rows = np.where(g2, 2, 1)
    start = np.concatenate(([0], np.cumsum(n_rows)[:-1]))
    arc_rows = start[~g2]
    pair_rows = np.concatenate((start[c], start[c] + 1))
    pair_src = np.concatenate((np.arange(0, 2 * c.size, 2), np.arange(1, 2 * c.size, 2)))
    out = {}
    total = int(n_rows.sum())
    for key, val in arcs.items():
        arr = np.zeros((total,) + val.shape[1:], dtype=val.dtype)
        arr[arc_rows] = val[~g2]
        arr[pair_rows] = pairs[key][pair_src]
        out[key] = arr
    return out


def _inside_the_blocks(path: Path, a: np.ndarray, cnt: np.ndarray, inside: np.ndarray,
                       rows: dict[str, np.ndarray]
                       ) -> tuple[dict[str, np.ndarray], np.ndarray]:
    """Roundings carried out inside the original blocks (G643, spec 5.5: "No separate
    rounding block is inserted; the rounding is carried out inside the original
    blocks"): the part up to the middle of the rounding stays with the block before the
    corner, the rest goes to the block after it, so the block boundary moves from the
    corner to the rounding's middle (the point nearest to it; both shapes are
    symmetric). A clothoid pair splits there already (its second piece is attributed to
    the next block); a tangent arc (at line corners; the fillet at an arc corner) is cut
    into two arcs of half its length (the second's start angle moved by ``omega L / 2``).

    Parameters
    ----------
    a : numpy.ndarray of int, shape (r,)
        Segment before each insertion, ascending.
    cnt : numpy.ndarray of int, shape (r,)
        Rows of each insertion (in ``rows``, in that order).
    inside : numpy.ndarray of bool, shape (r,)
        The insertion is block-internal (one arc row or a clothoid pair).
    rows : dict
        Packed rows of all insertions.

    Returns
    -------
    rows : dict
        The rows with every block-internal arc in two halves.
    cnt : numpy.ndarray of int, shape (r,)
        Rows per insertion.
    """
    split = inside & (cnt == 1)
    reps = np.repeat(np.where(split, 2, 1), cnt)            # per row: 1, or 2 (split)
    src = np.repeat(np.arange(reps.size), reps)
    out = {key: val[src] for key, val in rows.items()}
    cnt = cnt + split
    last = np.cumsum(cnt) - 1                                # each insertion's last row
    half = np.zeros(src.size, bool)
    half[np.repeat(split, cnt)] = True
    second = np.zeros(src.size, bool)
    second[last[split]] = True
    out["length"] = np.where(half, 0.5 * out["length"], out["length"])
    out["theta0"] = np.where(second, out["theta0"] + out["omega"] * out["length"],
                             out["theta0"])
    nxt = np.zeros(src.size, bool)
    nxt[last[inside]] = True
    out["block"] = np.where(nxt, np.repeat(path.block[a + 1], cnt), out["block"])
    return out, cnt


def _window_trims(path: Path, a: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Length cut from the start and from the end of every segment by the windows
    ``[S_c - d, S_c + d]`` around the corners at the ends of segments ``a``, mm, shape (m,)
    each (at most the segment's length each; a covered segment gets its whole length).

    Windows are disjoint (each is at most half of the straight chain on either side) and
    contain their corner, so a segment is cut at its start only by the window of the
    corner before it and at its end only by the window of the corner after it. The cut is
    ``d - (distance from the corner)``, which is exactly ``d`` at the corner's own two
    segments (the one-block case keeps its exact trims).
    """
    trim_start = np.zeros(path.n_segments)
    trim_end = np.zeros(path.n_segments)
    if a.size == 0:
        return trim_start, trim_end
    sb = path.s_breaks
    if (np.all(d < sb[a + 1] - sb[a]) and np.all(d < sb[a + 2] - sb[a + 1])
            and np.all(d <= path.length[a]) and np.all(d <= path.length[a + 1])):
        # every window within its corner's two segments (the one-block clamp): the
        # general rule below then cuts exactly ``d`` from those two and nothing elsewhere
        # (the distance to any other corner is at least a whole segment, more than its d)
        trim_end[a] = d
        trim_start[a + 1] = d
        return trim_start, trim_end
    s0, s1 = sb[:-1], sb[1:]
    corner = sb[a + 1]
    # window whose corner is at or before the segment's start, and whose reach covers it
    i = np.searchsorted(corner, s0, side="right") - 1
    hit = i >= 0
    reach = np.where(hit, d[np.maximum(i, 0)] - (s0 - corner[np.maximum(i, 0)]), 0.0)
    trim_start = np.where(hit & (reach > 0), np.minimum(reach, path.length), 0.0)
    # window whose corner is at or after the segment's end
    i = np.searchsorted(corner, s1, side="left")
    hit = i < corner.size
    ic = np.minimum(i, corner.size - 1)
    reach = np.where(hit, d[ic] - (corner[ic] - s1), 0.0)
    trim_end = np.where(hit & (reach > 0), np.minimum(reach, path.length), 0.0)
    return trim_start, trim_end


def _assemble(path: Path, a: np.ndarray, d: np.ndarray, t1: np.ndarray, t2: np.ndarray,
              g2: np.ndarray, piece: np.ndarray, table: RoundingTable,
              extras: list | None = None, internal: np.ndarray | None = None) -> Path:
    """The rounded path: lines shortened, roundings inserted after segments ``a``
    (a tangent arc, or the two pieces of a clothoid pair), spans moved.

    Parameters
    ----------
    a : numpy.ndarray of int, shape (r,)
        Segment before each inserted rounding (the corner is at its end).
    d : numpy.ndarray, shape (r,)
        Tangent distances, mm.
    t1, t2 : numpy.ndarray, shape (r, n)
        Unit directions of the lines before and after.
    g2 : numpy.ndarray of bool, shape (r,)
        Clothoid pair (else tangent arc).
    piece : numpy.ndarray, shape (r,)
        Length of each clothoid piece, mm (used where ``g2``).
    extras : list of tuple, optional
        Other insertions ``(a_x, trim_in, trim_out, rows, n_rows)``: after segments
        ``a_x``, the segment before shortened at its end by ``trim_in`` and the one after
        at its start by ``trim_out`` (an arc's start angle moves, so it stays the exact
        arc), ``n_rows`` packed ``rows`` each (G645's tangential transitions,
        :mod:`reference.rounding_tangential`; fillets at corners next to arcs,
        :mod:`reference.rounding_arcs`), and a 6th item: which of them are inside the
        blocks (bool, shape of ``a_x``; as ``internal``).
    internal : numpy.ndarray of bool, shape (r,), optional
        The rounding is carried out inside the original blocks (G643, between two
        blocks): :func:`_inside_the_blocks`.
    """
    m = path.n_segments
    trim_start, trim_end = _window_trims(path, a, d)
    n_ins = np.zeros(m, dtype=np.int64)
    n_ins[a] = np.where(g2, 2, 1)
    corner = path.origin.take(a, axis=0) + path.d.take(a, axis=0) * path.length[a][:, None]
    arcs = _inserted_rows(corner, t1, t2, d, g2, piece, path.block[a])
    inside = np.zeros(a.size, bool) if internal is None else internal
    cnt = np.where(g2, 2, 1)
    if extras:
        a_all, cnt, inside = [a], [cnt], [inside]
        for at, t_in, t_out, rows, n_rows, x_inside in extras:
            trim_end[at] += t_in
            trim_start[at + 1] += t_out
            n_ins[at] = n_rows
            a_all.append(at)
            cnt.append(np.full(at.size, n_rows))
            inside.append(x_inside)
            arcs = {key: np.concatenate((val, rows[key])) for key, val in arcs.items()}
        # rows in path order: every insertion's rows sorted by its segment
        a_all, cnt, inside = np.concatenate(a_all), np.concatenate(cnt), \
            np.concatenate(inside)
        rank = np.empty(a_all.size, dtype=np.int64)
        rank[np.argsort(a_all, kind="stable")] = np.arange(a_all.size)
        order = np.argsort(np.repeat(rank, cnt), kind="stable")
        arcs = {key: val[order] for key, val in arcs.items()}
        srt = np.argsort(a_all, kind="stable")
        a, cnt, inside = a_all[srt], cnt[srt], inside[srt]
    span_shift = np.zeros(m + 1, dtype=np.int64)
    if inside.any():
        arcs, cnt = _inside_the_blocks(path, a, cnt, inside, arcs)
        n_ins[a] = cnt
        # the last row of each such rounding starts the next block's span
        span_shift[a[inside] + 1] = 1
    length = path.length - trim_start - trim_end
    # with c = 0.5 on both ends a line can shrink to nothing: the two roundings then
    # meet tangentially and the line is dropped; a line inside a window that reaches
    # across short blocks (:func:`_across_blocks`) is covered whole and dropped too
    keep = length > MIN_SEGMENT_LENGTH_MM
    count = keep.astype(np.int64) + n_ins
    first = np.concatenate(([0], np.cumsum(count)))          # new index of old seg's pieces
    total = int(first[-1])
    n = path.n_axes
    # rows of the inserted segments: after the kept part of segment a, n_ins[a] each
    base = first[:-1][a] + keep[a]
    k_ins = n_ins[a]
    arc_pos = np.repeat(base, k_ins) + (np.arange(int(k_ins.sum()))
                                        - np.repeat(np.cumsum(k_ins) - k_ins, k_ins))
    kept = np.flatnonzero(keep)
    line_pos = first[:-1][kept]
    # every new row is one old row (kept) or one inserted row: gather them at once
    # (one take per column set, instead of zeros and two scatters each)
    src_row = np.empty(total, dtype=np.int64)
    src_row[line_pos] = kept
    src_row[arc_pos] = m + np.arange(arc_pos.size)
    new = {}
    # shortened segments: lines, and arcs at G645 transitions (circles: the start angle
    # moves by omega times the trim, the radius, centre and plane stay)
    origin = path.origin + path.d * trim_start[:, None]
    theta0 = path.theta0 + path.omega * trim_start
    for key in ("origin", "e1", "e2", "d"):
        src = origin if key == "origin" else getattr(path, key)
        new[key] = np.concatenate((src, arcs[key])).take(src_row, axis=0)
    for key, dtype in (("radius", np.float64), ("omega", np.float64),
                       ("theta0", np.float64), ("length", np.float64),
                       ("block", np.int64), ("kind", np.int8), ("dradius", np.float64),
                       ("sharpness", np.float64)):
        src = {"length": length, "theta0": theta0}.get(key)
        src = getattr(path, key) if src is None else src
        new[key] = np.concatenate((src.astype(dtype, copy=False),
                                   arcs[key].astype(dtype, copy=False))).take(src_row)
    per = np.repeat(np.arange(a.size), k_ins)               # corner of each inserted row
    feed = np.zeros(total)
    feed[line_pos] = path.feed[keep]
    feed[arc_pos] = np.minimum(path.feed[a], path.feed[a + 1])[per]
    rapid = np.zeros(total, bool)
    rapid[line_pos] = path.rapid[keep]
    rapid[arc_pos] = (path.rapid[a] & path.rapid[a + 1])[per]
    # breaks: old break k (k = 0..m) is new break first[k]; the new interior breaks
    # (line -> rounding -> line) carry no stop (a corner with a stop is never rounded)
    reasons = [""] * (total + 1)
    stop = np.zeros(total + 1, dtype=bool)
    for k in np.flatnonzero(path.stop):
        reasons[int(first[k])] = path.stop_reason[k]
        stop[int(first[k])] = True
    sb = np.concatenate(([0.0], np.cumsum(new["length"])))
    # a span's segments [j0, j0 + n) become [first[j0], first[j0 + n)) (n = 0 included)
    spans = path.blocks
    j0 = spans.first_segment
    at = first - span_shift               # a block-internal rounding's second half
    f, e = at[j0], at[j0 + spans.n_segments]
    spans = spans.moved(sb[f], sb[e], f, e - f)
    return Path(axes=path.axes, geometry=path.geometry, rotary=path.rotary, feed=feed,
                rapid=rapid, stop=stop, stop_reason=tuple(reasons), blocks=spans,
                source=path.source, rounding=table, **new)


__all__ = ["ROUNDING_MODES", "corner_time_loss", "round_corners"]
