"""Corner rounding geometry: the tangent-arc fillet of a corner between two lines (below),
between a line and a circle (:func:`line_circle_fillet`) and between two circles
(:func:`circle_circle_fillet`), and the table that records, per corner, what the
rounding stage decided.

Model (sinumerik-model 5.8 leaves the shape open: "the user must not assume a
particular shape inside the rounding area", 5.1): under BRISK the rounding block is the
circular arc tangent to both lines, exactly representable by the path's helical pieces
(a circle with ``d = 0``; its ``q'``, ``q''``, ``q'''`` are the arc's closed forms). It
is G1 continuous with a curvature jump ``1/R`` at both ends. Under SOFT the stage
inserts a curvature-continuous clothoid pair instead
(:func:`reference.core.geometry.clothoid_pieces`); this module's arc formulas below
describe the arc only.

For a corner ``C`` between unit directions ``t1`` (in) and ``t2`` (out) with deflection
angle ``theta`` (the angle between ``t1`` and ``t2``) and tangent distance ``d`` (how far
before and after ``C`` the rounding starts and ends, along the lines):

* radius ``R = d / tan(theta/2)``, arc length ``R theta``;
* the arc's midpoint ``M`` is the point nearest to ``C``; the contour deviation (the
  Hausdorff distance between the programmed corner and the rounded path) is
  ``|C - M| = R (1/cos(theta/2) - 1) = d tan(theta/4)``;
* ``C - M`` points along ``t1 - t2``, so axis ``i`` deviates by
  ``|C_i - M_i| = |C - M| |t2_i - t1_i| / |t2 - t1|`` (``|t2 - t1| = 2 sin(theta/2)``).

Inverting the last two gives the distance that uses a deviation ``e`` exactly:
``d = e / tan(theta/4)``.

Units: mm, rad. Shapes: ``k`` corners, ``n`` axes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .arrays import row_dots, row_min, row_norms

#: Why a corner in a rounding mode was or was not rounded (codes index this tuple).
#: Documented cases of sinumerik-model 5.2 first, then model limits of this version.
ROUNDING_REASONS: tuple[str, ...] = (
    "rounded",                                                        # 0
    "stop between the blocks",                                        # 1  5.2 group 1
    "block without path motion between",                              # 2  5.2 group 1
    "acceleration mode change (BRISK/SOFT)",                          # 3  5.2 group 1
    "geometry axes move in one block only",                           # 4  5.2 group 1
    "G64 passes the corner without reduction (overload factor)",      # 5  5.2 group 2, 4.3
    "rounding would be slower than G64",                              # 6  5.2 group 2
    "rounding distance too small",                                    # 7  5.2 group 2
    "rounding not parameterised (ADIS = 0)",                          # 8  5.2 group 3
    "rounding not parameterised (ADISPOS = 0)",                       # 9  5.2 group 3
    "rounding not parameterised (tolerance 0)",                       # 10 5.2 group 3
    "tangential transition",                                          # 11
    "corner next to an inserted block (TRC, TLIFT): rounding not modelled yet",  # 12
    "non-geometry axes move: rounding not modelled yet",              # 13 model limit
    "G644 SMOOTHING_MODE digit not documented",                       # 14 6xxx..9xxx
    # G645 at tangential transitions with a curvature jump (5.7, 6.3)
    "curvature jump allowed under BRISK (acceleration step)",         # 15 6.3
    "G64 passes the curvature jump without reduction",                # 16 5.7 [M], 5.8
    "tangential transition between arcs: rounding not modelled yet",  # 17 model limit
    "tangential transition into a helix or spiral: rounding not modelled yet",  # 18
    # corners next to arcs (reference.rounding_arcs): model limits
    "corner next to a helix or spiral, or out of the arc's plane: rounding not modelled "
    "yet",                                                            # 19
    # no longer given (G644 2xxx/3xxx at arc corners are modelled); kept so that the
    # codes of the reasons after it stay
    "G644 dynamic rounding (2xxx, 3xxx) at arc corners: not modelled yet",  # 20
    # G645 between tangent arcs: a model limit (reference.rounding_tangential)
    "tangential transition between arcs in different planes: rounding not modelled "
    "(model limit)",                                                  # 21
    # 5.2 group 2, where the overload check is waived (MD20490, reference.rounding.
    # always_rounds)
    "rounding would slow the program down (between two very short blocks)",  # 22
)
REASON_CODE = {r: i for i, r in enumerate(ROUNDING_REASONS)}


#: Modes that round inside the original blocks, inserting no block of their own
#: (5.5: "No separate rounding block is inserted; the rounding is carried out inside the
#: original blocks").
INTERNAL_MODES = ("G643",)
#: Modes that round only where G64 would have to reduce the speed (4.3).
OVERLOAD_CHECKED_MODES = ("G641", "G642", "G645")


def always_rounds(mode: np.ndarray, ignore_ovl: bool) -> np.ndarray:
    """Corners rounded whatever G64 would cost, bool, shape of ``mode`` (mode names).

    spec 4.3: "G643 ignores the overload factor. Setting MD20490
    IGNORE_OVL_FACTOR_FOR_ADIS = TRUE makes G641/G642 behave like G643 here (always
    round)"; 5.5 (G643): "The overload factor is never taken into account"; 5.8:
    "Insert the rounding only if v_corner_G64 < min(F, v_round), unless MD20490 = TRUE
    or the mode is G643". So for these corners neither the overload check nor the
    model's time comparison (:func:`reference.rounding.corner_time_loss`, which
    generalises that inequality) is made: G643 always, G641/G642/G645 with MD20490 = TRUE (G645 "at
    corners rounds like G642", 5.7). G644 and RND/RNDM are not named there: G644 keeps
    the time comparison, RND/RNDM never make it (a programmed contour).
    """
    out = np.isin(mode, INTERNAL_MODES)
    if ignore_ovl:
        out |= np.isin(mode, OVERLOAD_CHECKED_MODES)
    return out


def very_short_blocks(l_in: np.ndarray, l_out: np.ndarray, v: np.ndarray,
                      t_ipo: float) -> np.ndarray:
    """Both blocks beside a corner are "very short", bool, shape (k,).

    spec 5.2 group 2, "Rounding would slow the program down: between two very short
    blocks (each block costs at least one IPO cycle, so an extra block could double the
    time)"; 5.8: "If the blocks are too short (..., or less than one IPO cycle per
    block), fall back to G64 [S1]". Model [I]: a block is very short where it is
    crossed in at most one IPO cycle at the programmed speed ``v``, ``L <= v T_ipo``
    (its one-IPO-cycle cap binds), mm, mm/s, s.
    """
    return (l_in <= v * t_ipo) & (l_out <= v * t_ipo)


def break_windows(s_breaks: np.ndarray, at: np.ndarray, before: np.ndarray,
                  after: np.ndarray, windows: tuple[np.ndarray, np.ndarray] | None = None
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Per segment break, the path positions where the roundings at it start and end.

    The one record the rounding decisions share of what the roundings cut (the corner
    estimate, the G645 transitions' estimate and the hand-over between them), so that
    what a block keeps between two roundings (:func:`leftovers`) is judged alike.

    Parameters
    ----------
    s_breaks : numpy.ndarray, shape (m + 1,)
        Break positions, mm.
    at : numpy.ndarray of int, shape (k,)
        Breaks with a rounding (a break may repeat: the widest counts).
    before, after : numpy.ndarray, shape (k,)
        Length each rounding replaces before and after its break, mm.
    windows : tuple of numpy.ndarray, shape (m + 1,) each, optional
        Windows known already (of an earlier decision), widened by these.

    Returns
    -------
    lo, hi : numpy.ndarray, shape (m + 1,)
        Start and end of the window at every break (the break itself where none), mm.
    """
    lo = s_breaks.copy() if windows is None else np.minimum(s_breaks, windows[0])
    hi = s_breaks.copy() if windows is None else np.maximum(s_breaks, windows[1])
    np.minimum.at(lo, at, s_breaks[at] - before)
    np.maximum.at(hi, at, s_breaks[at] + after)
    return lo, hi


def leftovers(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Length of every segment left between the windows at its two ends, mm, shape (m,)
    (0 where they meet or overlap; ``lo``, ``hi`` of :func:`break_windows`)."""
    return np.maximum(lo[1:] - hi[:-1], 0.0)


@dataclass(frozen=True, slots=True, eq=False)
class RoundingTable:
    """What the rounding stage decided at every corner whose first block is in a
    rounding mode (G641..G645, RND/RNDM), in path order.

    Attributes
    ----------
    block, next_block : numpy.ndarray of int, shape (k,)
        The blocks before and after the corner (the rounding segment is attributed to
        ``block``, whose end the corner is).
    mode : tuple[str, ...]
        ``"G641"`` .. ``"G645"``, ``"RND"``: the mode that governed the corner.
    reason : numpy.ndarray of int, shape (k,)
        Index into :data:`ROUNDING_REASONS` (0 = rounded).
    distance_mm : numpy.ndarray, shape (k,)
        Tangent distance ``d`` (rounding starts ``d`` before and ends ``d`` after the
        corner), mm; 0 where none was inserted.
    length_mm, deviation_mm, radius_mm : numpy.ndarray, shape (k,)
        Arc length of the rounding, contour deviation ``|C - M|``, radius, mm; 0 where
        none was inserted.
    clamped : numpy.ndarray of bool, shape (k,)
        The distance was cut to ``c`` times the shorter neighbouring block.
    v_g64, v_round : numpy.ndarray, shape (k,)
        The G64 corner speed and the model's rounding speed (centripetal, curvature
        jump, one IPO cycle), mm/s (``nan`` where not evaluated).
    g2 : numpy.ndarray of bool, shape (k,)
        The rounding is a clothoid pair (curvature continuous; ``radius_mm`` is then its
        smallest radius of curvature, in the middle), else a tangent arc.
    first_block, last_block : numpy.ndarray of int, shape (k,)
        First and last program block the rounding window touches: ``block`` and
        ``next_block`` unless the window reaches across short blocks (G642/G645), in
        which case the blocks strictly between ``first_block`` and ``block`` (and
        between ``next_block`` and ``last_block``) are covered by the rounding whole.
    tangential : numpy.ndarray of bool, shape (k,)
        The transition is tangential with a curvature jump (G645 at a line-arc
        transition, :mod:`reference.core.transition`); for these ``distance_mm`` is the
        length replaced of the line, ``deviation_mm`` the largest distance from the
        programmed contour, ``radius_mm`` the arc's radius (the rounding's smallest),
        ``v_g64`` the curvature-jump limit (6.3). Rounded ones have ``g2`` set.
    internal : numpy.ndarray of bool, shape (k,), optional
        The rounding is carried out inside the original blocks (G643, 5.5: "No separate
        rounding block is inserted"): its half up to the corner's bisector belongs to
        ``block`` (the last segment of its span), the other half to ``next_block`` (the
        first of its span), it is no interpolation block of its own (no one-IPO-cycle
        cap of its own, no row of its own; :func:`reference.core.rows.
        internal_rounding_segments`). False where inserted as a block, or not rounded.
    """

    block: np.ndarray
    next_block: np.ndarray
    mode: tuple[str, ...]
    reason: np.ndarray
    distance_mm: np.ndarray
    length_mm: np.ndarray
    deviation_mm: np.ndarray
    radius_mm: np.ndarray
    clamped: np.ndarray
    v_g64: np.ndarray
    v_round: np.ndarray
    g2: np.ndarray
    first_block: np.ndarray
    last_block: np.ndarray
    tangential: np.ndarray
    internal: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.internal is None:
            object.__setattr__(self, "internal", np.zeros(self.block.size, bool))

    @property
    def n(self) -> int:
        """Number of corners recorded."""
        return int(self.block.size)

    @property
    def inserted(self) -> np.ndarray:
        """True per corner where a rounding segment was inserted, shape (k,)."""
        return self.reason == 0

    @property
    def blocks_spanned(self) -> np.ndarray:
        """Program blocks the rounding window touches (2 for a rounding between two
        blocks, more across short blocks; 0 where none was inserted), shape (k,)."""
        return np.where(self.inserted, self.last_block - self.first_block + 1, 0)

    def reason_text(self, i: int) -> str:
        """The reason of corner ``i`` as words."""
        return ROUNDING_REASONS[int(self.reason[i])]

    def decision_by_block(self) -> dict[int, str]:
        """The decision at the corner each block ends in, for the block rows (issue 13:
        every case where no rounding block is inserted is "named in the trace and in
        the block rows").

        Returns
        -------
        dict
            Program block index (the block before the corner) -> ``"rounded"`` or
            ``"none: <reason>"`` (:data:`ROUNDING_REASONS`); blocks whose end is not a
            corner in a rounding mode are absent.
        """
        words = ["rounded"] + [f"none: {r}" for r in ROUNDING_REASONS[1:]]
        return dict(zip(self.block.tolist(), (words[k] for k in self.reason.tolist())))


def deflection_angle(t1: np.ndarray, t2: np.ndarray) -> np.ndarray:
    """Angle between unit directions, rad, shape (k,) from (k, n) each.

    ``2 atan2(|t2 - t1|, |t2 + t1|)`` is accurate at both ends (0 and pi), unlike
    ``arccos`` of the dot product.
    """
    return 2.0 * np.arctan2(_norms(t2 - t1), _norms(t2 + t1))


def _norms(x: np.ndarray) -> np.ndarray:
    """``numpy.linalg.norm(x, axis=-1)`` (the same numbers; faster on (k, n) arrays)."""
    return row_norms(x) if x.ndim == 2 else np.linalg.norm(x, axis=-1)


def distance_for_deviation(theta: np.ndarray, deviation: np.ndarray) -> np.ndarray:
    """Tangent distance whose fillet deviates from the corner by exactly ``deviation``.

    ``d = e / tan(theta/4)`` (module docstring), mm, shape (k,).
    """
    with np.errstate(divide="ignore"):
        return deviation / np.tan(theta / 4.0)


def axis_deviation_limit(t1: np.ndarray, t2: np.ndarray, tol: np.ndarray) -> np.ndarray:
    """Largest contour deviation ``|C - M|`` that keeps every axis within ``tol``.

    ``min_i tol_i |t2 - t1| / |t2_i - t1_i|`` over the axes whose direction changes.

    Parameters
    ----------
    t1, t2 : numpy.ndarray, shape (k, n)
        Unit directions before and after the corners.
    tol : numpy.ndarray, shape (k, n) or (n,)
        Per-axis tolerance, mm (``inf`` = no limit).

    Returns
    -------
    numpy.ndarray, shape (k,)
        mm (``inf`` where no axis limits).
    """
    dt = np.abs(t2 - t1)
    norm = _norms(t2 - t1)
    tol = np.broadcast_to(tol, dt.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        per = np.where(dt > 0, tol * norm[:, None] / np.where(dt > 0, dt, 1.0), np.inf)
    return row_min(per) if per.shape[1] else np.full(dt.shape[0], np.inf)


def fillet_pieces(corner: np.ndarray, t1: np.ndarray, t2: np.ndarray, d: np.ndarray,
                  block: np.ndarray, kind_code: int) -> dict[str, np.ndarray]:
    """Packed helical parameters of the tangent arcs rounding ``k`` corners.

    The arc starts at ``P_s = C - d t1`` with tangent ``t1`` and ends at
    ``P_e = C + d t2`` with tangent ``t2``: ``q(s) = o + R (e1 cos(s/R) + e2 sin(s/R))``
    with centre ``o = P_s + R n`` (``n`` the unit component of ``t2`` normal to ``t1``),
    ``e1 = -n``, ``e2 = t1``, ``0 <= s <= R theta``.

    Parameters
    ----------
    corner, t1, t2 : numpy.ndarray, shape (k, n)
        Corner points and unit directions (zero components on non-geometry axes).
    d : numpy.ndarray, shape (k,)
        Tangent distances, mm (> 0; ``0 < theta < pi``).
    block : numpy.ndarray of int, shape (k,)
        Block each rounding is attributed to.
    kind_code : int
        Segment kind code (index of ``"rounding"`` in the path's kind codes).

    Returns
    -------
    dict
        ``origin, e1, e2, d, radius, omega, theta0, length, block, kind, dradius``.
    """
    theta = deflection_angle(t1, t2)
    radius = d / np.tan(theta / 2.0)
    normal = t2 - row_dots(t2, t1)[:, None] * t1
    normal /= row_norms(normal)[:, None]
    start = corner - d[:, None] * t1
    k = d.size
    return {
        "origin": start + radius[:, None] * normal,
        "e1": -normal,
        "e2": t1.copy(),
        "d": np.zeros_like(t1),
        "radius": radius,
        "omega": 1.0 / radius,
        "theta0": np.zeros(k),
        "length": radius * theta,
        "block": np.asarray(block, dtype=np.int64),
        "kind": np.full(k, kind_code, dtype=np.int8),
        "dradius": np.zeros(k),
    }


@dataclass(frozen=True, slots=True, eq=False)
class ArcFillet:
    """Tangent arcs of radius ``r`` between a line and a circle, in the plane of the
    circle, per corner (shape (k,) or (k, 2)); see :func:`line_circle_fillet`.

    Attributes
    ----------
    valid : numpy.ndarray of bool
        The fillet exists, leaves the line before the corner and meets the circle after
        it, turning by less than pi.
    line_trim, arc_trim : numpy.ndarray
        Length of the line and arc length of the circle it replaces, mm.
    centre, start, end : numpy.ndarray, shape (k, 2)
        Its centre, its start on the line and its end on the circle (plane coordinates,
        the corner at the origin), mm.
    sweep : numpy.ndarray
        Angle it turns, rad.
    deviation : numpy.ndarray, shape (k, 2)
        ``C - M``: the corner minus the fillet's point nearest to it, mm.
    """

    valid: np.ndarray
    line_trim: np.ndarray
    arc_trim: np.ndarray
    centre: np.ndarray
    start: np.ndarray
    end: np.ndarray
    sweep: np.ndarray
    deviation: np.ndarray


def _cross2(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]


def _perp(u: np.ndarray) -> np.ndarray:
    return np.column_stack((-u[:, 1], u[:, 0]))


def line_circle_fillet(r: np.ndarray, t: np.ndarray, centre: np.ndarray,
                       radius: np.ndarray, sense: np.ndarray) -> ArcFillet:
    """The tangent arc of radius ``r`` rounding the corner between a line and a circle.

    Plane coordinates (the circle's plane), the corner ``C`` at the origin: the line
    ends at ``C`` with unit direction ``t``; the circle (centre ``c``, radius ``R``,
    ``sense`` +1 counter-clockwise, -1 clockwise) starts at ``C``. The rounding turns
    towards ``s = sign(t x t_c)`` (``t_c`` the circle's tangent at ``C``), so the fillet's
    centre lies on the line offset by ``r`` to that side, ``O = x t + r n`` (``n = s
    perp(t)``), and on the circle of radius ``rho`` about ``c``: ``R - r`` where the
    fillet turns the way the circle does (inside it), ``R + r`` otherwise. ``|x t + w|
    = rho`` with ``w = r n - c`` is a quadratic in ``x``; of its roots the one that
    tends to 0 with ``r`` (``|c| = R``: the corner is on the circle) is taken, written
    without cancellation as ``(|w|^2 - rho^2) / q`` with ``q = -(t.w) - sign(t.w)
    sqrt(disc)``. The fillet leaves the line at ``x t`` (``x < 0``) and meets the circle
    at ``c + R (O - c) / |O - c|``.

    Parameters
    ----------
    r : numpy.ndarray, shape (k,)
        Fillet radii, mm (> 0).
    t, centre : numpy.ndarray, shape (k, 2)
    radius, sense : numpy.ndarray, shape (k,)

    Returns
    -------
    ArcFillet
    """
    tc = sense[:, None] * _perp(-centre) / radius[:, None]    # circle's tangent at C
    s = np.sign(_cross2(t, tc))
    n, iota = _corner_frame(t, centre, radius, sense)
    rho = radius - iota * r
    x, disc = _line_offset(r, t, n, iota, centre, radius)
    with np.errstate(invalid="ignore", divide="ignore"):
        O = x[:, None] * t + r[:, None] * n
        u = O - centre
        u = u / row_norms(u)[:, None]
        end = centre + radius[:, None] * u
        # arc length from C to the end along the circle's sense
        a0 = -centre
        ang = sense * np.arctan2(_cross2(a0, end - centre), row_dots(a0, end - centre))
        te = sense[:, None] * _perp(end - centre) / radius[:, None]
        sweep = s * np.arctan2(_cross2(t, te), row_dots(t, te))
        dc = -O                                               # C - O
        near = O + r[:, None] * dc / row_norms(dc)[:, None]
    valid = ((disc >= 0) & (x < 0) & (ang > 0) & (sweep > 0) & (rho > 0)
             & np.isfinite(x) & (s != 0))
    return ArcFillet(valid, -x, radius * ang, O, x[:, None] * t, end, sweep, -near)


def _corner_frame(t: np.ndarray, centre: np.ndarray, radius: np.ndarray,
                  sense: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``n`` (unit normal of the line towards the fillet's centre) and ``iota`` (+1 where
    the fillet lies inside the circle, -1 outside) of :func:`line_circle_fillet`."""
    tc = sense[:, None] * _perp(-centre) / radius[:, None]
    s = np.sign(_cross2(t, tc))
    return s[:, None] * _perp(t), np.where(s == sense, 1.0, -1.0)


def _line_offset(r: np.ndarray, t: np.ndarray, n: np.ndarray, iota: np.ndarray,
                 centre: np.ndarray, radius: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Where the fillet of radius ``r`` leaves the line (``x``, the root of
    :func:`line_circle_fillet` that tends to 0 with ``r``) and the discriminant.

    ``|x t + w|^2 = rho^2`` with ``w = r n - c``, ``rho = R - iota r``: ``x^2 + 2 (t.w) x +
    |w|^2 - rho^2 = 0``, where ``|w|^2 - rho^2 = iota r R |iota n + u0|^2`` (``|c| = R``,
    ``u0 = -c / R``: written so, without the cancellation of ``R^2``); the small root is
    ``(|w|^2 - rho^2) / q``, ``q = -(t.w) - sign(t.w) sqrt(disc)``.
    """
    u0 = -centre / radius[:, None]
    half = iota[:, None] * n + u0
    c0 = iota * r * radius * row_dots(half, half)
    tw = r * row_dots(t, n) - row_dots(t, centre)
    disc = tw * tw - c0
    with np.errstate(invalid="ignore", divide="ignore"):
        q = -tw - np.where(tw >= 0, 1.0, -1.0) * np.sqrt(np.maximum(disc, 0.0))
        return c0 / q, disc


def fillet_radius_for_line_trim(trim: np.ndarray, t: np.ndarray, centre: np.ndarray,
                                radius: np.ndarray, sense: np.ndarray) -> np.ndarray:
    """Radius of the fillet of :func:`line_circle_fillet` that replaces ``trim`` of the
    line, closed form, mm, shape (k,).

    Its centre is ``O = P + r n`` with ``P = -trim t`` and ``|O - c| = R - iota r``;
    squared, the ``r^2`` terms cancel: ``r = (R^2 - |P - c|^2) / (2 (n.(P - c) + iota R))``.
    Written without cancellation (``|c| = R``, ``n.t = 0``, ``u0 = -c / R`` the radial
    at ``C``): ``R^2 - |P - c|^2 = -trim (trim - 2 R t.u0)`` and ``n.(P - c) + iota R =
    iota R |iota n + u0|^2 / 2``.
    """
    n, iota = _corner_frame(t, centre, radius, sense)
    u0 = -centre / radius[:, None]
    num = -trim * (trim - 2.0 * radius * row_dots(t, u0))
    half = iota[:, None] * n + u0
    with np.errstate(divide="ignore", invalid="ignore"):
        return num / (iota * radius * row_dots(half, half))


def fillet_radius_for_arc_trim(trim: np.ndarray, t: np.ndarray, centre: np.ndarray,
                               radius: np.ndarray, sense: np.ndarray) -> np.ndarray:
    """Radius of the fillet of :func:`line_circle_fillet` that replaces the arc length
    ``trim`` of the circle, closed form, mm, shape (k,).

    It touches the circle at ``T``, ``trim / R`` along the circle from ``C``, with its
    centre ``O = c + (R - iota r) u`` (``u`` the unit radial at ``T``) at distance ``r``
    from the line: ``n.O = r``, so ``r = n.T / (1 + iota n.u)``; without cancellation
    ``n.T = R n.(u - u0)`` with ``u - u0 = -2 sin^2(a/2) u0 + sin(a) perp(u0)`` (``a``
    the angle turned) and ``1 + iota n.u = |iota n + u|^2 / 2``.
    """
    n, iota = _corner_frame(t, centre, radius, sense)
    a = sense * trim / radius
    u0 = -centre / radius[:, None]                      # radial at C
    du = (-2.0 * np.sin(a / 2.0) ** 2)[:, None] * u0 + np.sin(a)[:, None] * _perp(u0)
    half = iota[:, None] * n + u0 + du
    with np.errstate(divide="ignore", invalid="ignore"):
        return 2.0 * radius * row_dots(n, du) / row_dots(half, half)


def fillet_deviation(r: np.ndarray, t: np.ndarray, centre: np.ndarray,
                     radius: np.ndarray, sense: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``C - M`` of the fillets of radius ``r`` (:attr:`ArcFillet.deviation`), shape
    (k, 2), and whether they exist with their start before the corner, shape (k,): the
    cheap part of :func:`line_circle_fillet` for a search over ``r``."""
    n, iota = _corner_frame(t, centre, radius, sense)
    rho = radius - iota * r
    x, disc = _line_offset(r, t, n, iota, centre, radius)
    with np.errstate(invalid="ignore", divide="ignore"):
        O = x[:, None] * t + r[:, None] * n
        dist = row_norms(O)
        dev = -O * (1.0 - r / dist)[:, None]
    return dev, (disc >= 0) & (x < 0) & (rho > 0) & np.isfinite(x)


def _small_root(a2: np.ndarray, a1: np.ndarray, a0: np.ndarray) -> np.ndarray:
    """The root of ``a2 r^2 + a1 r + a0 = 0`` (``a0 < 0 < -a1``) that tends to
    ``-a0 / -a1`` as ``a2 -> 0``, written without cancellation: ``2 a0 / (-a1 -
    sqrt(a1^2 - 4 a2 a0))``; ``nan`` where the discriminant is negative."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return 2.0 * a0 / (-a1 - np.sqrt(a1 * a1 - 4.0 * a2 * a0))


def fillet_radius_for_deviation(e: np.ndarray, t: np.ndarray, centre: np.ndarray,
                                radius: np.ndarray, sense: np.ndarray) -> np.ndarray:
    """Radius of the fillet of :func:`line_circle_fillet` whose contour deviation
    ``|C - M|`` is ``e``, closed form, mm, shape (k,) (``nan`` or not positive: none).

    ``M`` lies on the fillet's radius towards ``C``, so ``|O| = r + e``; with ``|O - c| =
    R - iota r`` (``c = -R u0``) the difference of the squares is linear:
    ``O.u0 = -iota r - g / R``, ``g = r e + e^2 / 2``, and with ``O = x t + r n``, ``|O|^2
    = x^2 + r^2`` gives ``x^2 = 2 g`` and ``x (t.u0) = -(p r + g / R)`` (``p = iota + n.u0
    = iota |iota n + u0|^2 / 2``, without cancellation). Squared: ``P^2 r^2 + 2 (P Q -
    q^2 e) r + Q^2 - q^2 e^2 = 0`` with ``P = p + e / R``, ``Q = e^2 / (2 R)``, ``q =
    t.u0``; the root that tends to the line-line ``e cos(theta/2) / (1 - cos(theta/2))``
    as ``R`` grows is taken. Exact for the contour deviation (squaring may give the
    mirrored branch's root, ``x > 0``: 1 of 192 seeded corners); a start (checked by
    the full fillet) for the tolerance search.
    """
    n, iota = _corner_frame(t, centre, radius, sense)
    u0 = -centre / radius[:, None]
    half = iota[:, None] * n + u0
    p = iota * row_dots(half, half) / 2.0
    q2 = row_dots(t, u0) ** 2
    big_p = p + e / radius
    big_q = e * e / (2.0 * radius)
    return _small_root(big_p * big_p, 2.0 * (big_p * big_q - q2 * e),
                       big_q * big_q - q2 * e * e)


def circle_fillet_radius_for_deviation(e: np.ndarray, c1: np.ndarray, r1: np.ndarray,
                                       s1: np.ndarray, c2: np.ndarray, r2: np.ndarray,
                                       s2: np.ndarray) -> np.ndarray:
    """Radius of the fillet of :func:`circle_circle_fillet` whose contour deviation
    ``|C - M|`` is ``e`` (``M`` on its radius towards ``C``), closed form, mm, shape (k,)
    (``nan`` or not positive: none).

    ``|O| = r + e`` fixes ``g = (|O|^2 - r^2) / 2 = r e + e^2 / 2`` in the quadratic of
    :func:`_circle_fillet_centre`, ``|V|^2 g^2 - 2 (1 - r K) g + a^2 r^2 = 0`` (``A_t =
    a r``, ``A.V = r K``, ``K = iota_1 / R_1 - 2 iota_2 (c / R_1 - 1 / R_2) / P`` as in
    :func:`circle_fillet_largest_radius`), which becomes a quadratic in ``r``; divided by
    ``e``: ``(|V|^2 e + 2 K + a^2 / e) r^2 + (|V|^2 e^2 + K e - 2) r + |V|^2 e^3 / 4 - e =
    0``, of which the root that tends to the line-line one as the radii grow is taken.
    Exact for the contour deviation; a start (checked by the full fillet) where the
    per-axis deviations decide.
    """
    x, p2, m, kk = _circle_pair_terms(c1, r1, s1, c2, r2, s2)
    with np.errstate(divide="ignore", invalid="ignore"):
        v2 = 1.0 / (r1 * r1) + (m / x) ** 2
        a = 2.0 * x / p2
        return _small_root(v2 * e + 2.0 * kk + a * a / e, v2 * e * e + kk * e - 2.0,
                           v2 * e ** 3 / 4.0 - e)


@dataclass(frozen=True, slots=True, eq=False)
class CircleFillet:
    """Tangent arcs of radius ``r`` between two circles meeting at a corner, in their
    common plane, per corner (shape (k,) or (k, 2)); see :func:`circle_circle_fillet`.

    Attributes
    ----------
    valid : numpy.ndarray of bool
        The fillet exists, leaves the first circle before the corner and meets the
        second after it, turning the way the corner turns by the angle the contour turns
        between its ends.
    trim_in, trim_out : numpy.ndarray
        Arc length of the first and of the second circle it replaces, mm.
    centre, start, end : numpy.ndarray, shape (k, 2)
        Its centre, its start on the first circle and its end on the second (plane
        coordinates, the corner at the origin), mm.
    radial, heading : numpy.ndarray, shape (k, 2)
        Unit vector from its centre to its start, and its unit tangent there (the first
        circle's tangent in the direction of travel).
    sweep : numpy.ndarray
        Angle it turns, rad (in ``(0, 2 pi)``).
    deviation : numpy.ndarray, shape (k, 2)
        ``C - M``: the corner minus the fillet's point nearest to it, mm.
    """

    valid: np.ndarray
    trim_in: np.ndarray
    trim_out: np.ndarray
    centre: np.ndarray
    start: np.ndarray
    end: np.ndarray
    radial: np.ndarray
    heading: np.ndarray
    sweep: np.ndarray
    deviation: np.ndarray


def _circle_pair_terms(c1: np.ndarray, r1: np.ndarray, s1: np.ndarray, c2: np.ndarray,
                       r2: np.ndarray, s2: np.ndarray):
    """The terms of the fillet quadratic of :func:`_circle_fillet_centre` that both closed
    forms (:func:`circle_fillet_radius_for_deviation`, :func:`circle_fillet_largest_radius`)
    use, shape (k,) each: ``X = u_1 x u_2``, ``P = |u_2 + iota_1 iota_2 u_1|^2``,
    ``m = c / R_1 - 1 / R_2`` (``c = u_1 . u_2``) and ``K = iota_1 / R_1 - 2 iota_2 m / P``.
    """
    return _terms_of(_circle_pair_frame(c1, r1, s1, c2, r2, s2), r1, r2)


def _terms_of(frame: tuple, r1: np.ndarray, r2: np.ndarray):
    """:func:`_circle_pair_terms` from the pair's :func:`_circle_pair_frame`."""
    u1, u2, _, iota1, iota2 = frame
    x = _cross2(u1, u2)
    plus = u2 + (iota1 * iota2)[:, None] * u1
    p2 = row_dots(plus, plus)
    m = row_dots(u1, u2) / r1 - 1.0 / r2
    return x, p2, m, iota1 / r1 - 2.0 * iota2 * m / p2


def _circle_pair_frame(c1: np.ndarray, r1: np.ndarray, s1: np.ndarray, c2: np.ndarray,
                       r2: np.ndarray, s2: np.ndarray):
    """Unit radials at the corner ``u_j = -c_j / R_j``, the side ``s`` the corner turns
    to (+1 left) and ``iota_j`` (+1 where the fillet lies inside circle ``j``: it turns
    the way that circle does) of :func:`circle_circle_fillet`."""
    u1 = -c1 / r1[:, None]
    u2 = -c2 / r2[:, None]
    # the sign of t_1 x t_2 (t_j = s_j perp(u_j)): s_1 s_2 (u_1 x u_2), the same number
    # (perp and the senses +-1 only swap and negate the products)
    s = np.sign(s1 * s2 * _cross2(u1, u2))
    return u1, u2, s, np.where(s == s1, 1.0, -1.0), np.where(s == s2, 1.0, -1.0)


def _circle_fillet_centre(r, u1, r1, u2, r2, iota1, iota2):
    """Centre ``O`` of the fillet of radius ``r`` (:func:`circle_circle_fillet`) in each
    circle's frame at the corner, and the discriminant of its equation.

    ``|O - c_j|^2 = rho_j^2`` with ``c_j = -R_j u_j`` and ``rho_j = R_j - iota_j r``,
    divided by ``2 R_j``: ``O.u_j = -iota_j r - g / R_j`` with one unknown ``g = (|O|^2 -
    r^2) / 2``. For a given ``g`` this is linear in ``O``: ``O = A + g V``. In the frame
    ``(u_1, perp(u_1))`` (``c = u_1.u_2``, ``X = u_1 x u_2``, so ``u_2 = c u_1 + X
    perp(u_1)``): ``A = (-iota_1 r, -2 iota_2 r X / |u_2 + i u_1|^2)`` (``i = iota_1
    iota_2``; ``|u_2 + i u_1|^2 = 2 (1 + i c) = 4 cos^2(theta/2)``, ``theta`` the corner's
    deflection: the second component is the line-line ``-/+ r tan(theta/2)``), ``V =
    (-1 / R_1, (c / R_1 - 1 / R_2) / X)``; then ``g`` solves ``|V|^2 g^2 - 2 (1 - A.V) g
    + A_t^2 = 0`` (``|A|^2 - r^2 = A_t^2``), of which the root that tends to 0 with ``r``
    is taken. In the frame ``(u_2, perp(u_2))`` by the same steps ``A = (-iota_2 r, 2
    iota_1 r X / |u_2 + i u_1|^2)``, ``V = (-1 / R_2, (1 / R_1 - c / R_2) / X)``.

    Every term is computed to round-off relative to itself, so the components of ``O``
    along the circles' tangents -- the replaced angles -- are exact near a tangential
    corner (``X -> 0``) as near a cusp; the form through the circles' radical line loses
    digits like ``1 / theta^2`` there.

    Returns
    -------
    on1, ot1, on2, ot2 : numpy.ndarray, shape (k,)
        ``O.u_1``, ``O.perp(u_1)``, ``O.u_2``, ``O.perp(u_2)``, mm.
    disc : numpy.ndarray, shape (k,)
        Discriminant (the fillet exists where it is not negative).
    """
    i = iota1 * iota2
    c = row_dots(u1, u2)
    x = _cross2(u1, u2)
    plus = u2 + i[:, None] * u1
    with np.errstate(invalid="ignore", divide="ignore"):
        p2 = row_dots(plus, plus)
        at1 = -2.0 * iota2 * r * x / p2
        at2 = 2.0 * iota1 * r * x / p2
        vt1 = (c / r1 - 1.0 / r2) / x
        vt2 = (1.0 / r1 - c / r2) / x
        beta = 1.0 - (iota1 * r / r1 + at1 * vt1)
        disc = beta * beta - (1.0 / (r1 * r1) + vt1 * vt1) * at1 * at1
        g = at1 * at1 / (beta + np.where(beta >= 0, 1.0, -1.0)
                         * np.sqrt(np.maximum(disc, 0.0)))
    return -iota1 * r - g / r1, at1 + g * vt1, -iota2 * r - g / r2, at2 + g * vt2, disc


def _first_angle(on1: np.ndarray, ot1: np.ndarray, r1: np.ndarray,
                 s1: np.ndarray) -> np.ndarray:
    """Angle of the first circle the fillet replaces, from the radial at the corner to
    the one through its centre ``O`` (``O - c_1`` has the components ``R_1 + O.u_01``
    and ``O.perp(u_01)``): exact relative to the angle, rad, shape (k,)."""
    return -s1 * np.arctan2(ot1, r1 + on1)


def _rotated(u: np.ndarray, a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``u`` turned by ``a`` (counter-clockwise) and the change ``rot(a) u - u``, written
    without cancellation, shape (k, 2) each."""
    du = (-2.0 * np.sin(a / 2.0) ** 2)[:, None] * u + np.sin(a)[:, None] * _perp(u)
    return u + du, du


def circle_circle_fillet(r: np.ndarray, c1: np.ndarray, r1: np.ndarray, s1: np.ndarray,
                         c2: np.ndarray, r2: np.ndarray, s2: np.ndarray) -> CircleFillet:
    """The tangent arc of radius ``r`` rounding the corner between two circles.

    Plane coordinates (the circles' common plane), the corner ``C`` at the origin: the
    first circle (centre ``c_1``, radius ``R_1``, ``s_1`` +1 counter-clockwise, -1
    clockwise) ends at ``C``, the second (``c_2``, ``R_2``, ``s_2``) starts there
    (``|c_j| = R_j``). The rounding turns to the side ``s`` the corner turns to (the sign
    of ``t_1 x t_2``, the circles' tangents at ``C``), so near ``C`` its centre ``O`` is
    ``r`` from each circle on that side: ``|O - c_j| = R_j - r`` where the fillet turns
    the way circle ``j`` does (inside it), ``R_j + r`` otherwise. Of the two points
    where these two circles about ``c_1``, ``c_2`` cross, the one that tends to ``C``
    with ``r`` is taken (:func:`_circle_fillet_centre`); the fillet touches circle ``j``
    on the radius through ``O``. It is valid where it exists (both offset radii
    positive, the circles cross), its start lies before ``C`` on the first circle and
    its end after ``C`` on the second (each by less than half a turn), and the angle it
    turns in the direction ``s``, ``sweep``, is the angle the programmed contour turns
    between its ends, ``theta + s (s_1 a_1 + s_2 a_2)`` (``theta`` the corner's
    deflection, ``a_j`` the angles replaced; the two agree up to whole turns, and this
    picks the fillet that rounds this corner, not a loop).

    The deviation is ``C - M``, ``M`` the fillet's point nearest ``C`` (on the radius
    towards ``C``, or the nearer end where that radius misses the fillet).

    Parameters
    ----------
    r : numpy.ndarray, shape (k,)
        Fillet radii, mm (> 0).
    c1, c2 : numpy.ndarray, shape (k, 2)
    r1, s1, r2, s2 : numpy.ndarray, shape (k,)

    Returns
    -------
    CircleFillet
    """
    u01, u02, s, iota1, iota2 = _circle_pair_frame(c1, r1, s1, c2, r2, s2)
    on1, ot1, on2, ot2, disc = _circle_fillet_centre(r, u01, r1, u02, r2, iota1, iota2)
    with np.errstate(invalid="ignore", divide="ignore"):
        O = on1[:, None] * u01 + ot1[:, None] * _perp(u01)
        # the angles replaced, from the radials at C to those through O (O - c_j has
        # the components R_j + O.u_0j and O.perp(u_0j)): exact relative to the angle
        ang1 = _first_angle(on1, ot1, r1, s1)
        ang2 = s2 * np.arctan2(ot2, r2 + on2)
        u1, du1 = _rotated(u01, -s1 * ang1)
        u2, du2 = _rotated(u02, s2 * ang2)
        start = r1[:, None] * du1
        end = r2[:, None] * du2
        radial = iota1[:, None] * u1
        e_end = iota2[:, None] * u2
        sweep = np.mod(s * np.arctan2(_cross2(radial, e_end), row_dots(radial, e_end)),
                       2.0 * np.pi)
        # the corner's deflection between t_j = s_j perp(u_0j): |t_2 -+ t_1| = |s_2 u_02
        # -+ s_1 u_01| (perp turns a vector: the same squares, summed in the other order)
        w1, w2 = s1[:, None] * u01, s2[:, None] * u02
        theta = 2.0 * np.arctan2(row_norms(w2 - w1), row_norms(w2 + w1))
        expected = theta + s * (s1 * ang1 + s2 * ang2)
        # nearest point to C: on the radius towards C where it meets the fillet's span
        to_c = -O / row_norms(O)[:, None]
        at = np.mod(s * np.arctan2(_cross2(radial, to_c), row_dots(radial, to_c)),
                    2.0 * np.pi)
        near = np.where((at <= sweep)[:, None], O + r[:, None] * to_c,
                        np.where((row_norms(start) <= row_norms(end))[:, None], start, end))
    valid = ((disc >= 0) & (r1 - iota1 * r > 0) & (r2 - iota2 * r > 0) & (ang1 > 0)
             & (ang2 > 0) & (sweep > 0) & (np.abs(sweep - expected) < np.pi)
             & np.isfinite(sweep) & (s != 0))
    return CircleFillet(valid, r1 * ang1, r2 * ang2, O, start, end, radial,
                        s1[:, None] * _perp(u1), sweep, -near)


def circle_fillet_deviation(r: np.ndarray, c1: np.ndarray, r1: np.ndarray,
                            s1: np.ndarray, c2: np.ndarray, r2: np.ndarray,
                            s2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``C - M`` of the fillets of radius ``r`` of :func:`circle_circle_fillet`, shape
    (k, 2), and whether they are valid, shape (k,) (the signature of
    :func:`fillet_deviation`, for the same search over ``r``)."""
    f = circle_circle_fillet(r, c1, r1, s1, c2, r2, s2)
    return f.deviation, f.valid


def circle_fillet_radius_for_trim(trim: np.ndarray, c1: np.ndarray, r1: np.ndarray,
                                  s1: np.ndarray, c2: np.ndarray, r2: np.ndarray,
                                  s2: np.ndarray) -> np.ndarray:
    """Radius of the fillet of :func:`circle_circle_fillet` that replaces the arc length
    ``trim`` of the first circle, closed form, mm, shape (k,). For the second circle's,
    pass the pair traversed backwards: ``(c2, r2, -s2, c1, r1, -s1)`` (the same fillet;
    the corner then turns the other way and each ``iota`` stays with its circle).

    It touches the first circle at ``T = c_1 + R_1 u`` (``u`` the radial ``trim / R_1``
    back along it from ``C``), with its centre ``O = T - iota_1 r u``; ``|O - c_2| = R_2 -
    iota_2 r`` squared loses its ``r^2`` terms: ``r = (|T - c_2|^2 - R_2^2) / (2 (iota_1
    u.(T - c_2) - iota_2 R_2))``. Without cancellation (``T = R_1 du``, ``du = u - u_01``,
    ``|c_2| = R_2``, ``c_2 = -R_2 u_02``): the numerator is ``R_1 du.(R_1 du + 2 R_2
    u_02)`` and twice the denominator ``iota_1 R_1 |du|^2 - iota_2 R_2 |u_02 - iota_1
    iota_2 u|^2``.
    """
    return _radius_for_trim(trim, _circle_pair_frame(c1, r1, s1, c2, r2, s2), r1, s1, r2)


def _radius_for_trim(trim: np.ndarray, frame: tuple, r1: np.ndarray, s1: np.ndarray,
                     r2: np.ndarray) -> np.ndarray:
    """:func:`circle_fillet_radius_for_trim` from the pair's :func:`_circle_pair_frame`."""
    u01, u02, _, iota1, iota2 = frame
    a = -s1 * trim / r1
    du = (-2.0 * np.sin(a / 2.0) ** 2)[:, None] * u01 + np.sin(a)[:, None] * _perp(u01)
    T = r1[:, None] * du
    u = u01 + du
    num = row_dots(T, T + 2.0 * r2[:, None] * u02)
    w = u02 - (iota1 * iota2)[:, None] * u
    den = iota1 * r1 * row_dots(du, du) - iota2 * r2 * row_dots(w, w)
    with np.errstate(divide="ignore", invalid="ignore"):
        return num / den


def circle_fillet_largest_radius(c1: np.ndarray, r1: np.ndarray, s1: np.ndarray,
                                 c2: np.ndarray, r2: np.ndarray,
                                 s2: np.ndarray) -> np.ndarray:
    """Largest radius of the fillets of :func:`circle_circle_fillet` (where the
    discriminant of :func:`_circle_fillet_centre` reaches 0), mm, shape (k,); ``inf``
    where they exist at every radius (both circles curving away from the fillet).

    ``disc(r) = (1 - r k)^2 - |V|^2 a^2 r^2`` with ``A_t = a r``, ``k = iota_1 / R_1 + a
    V_t``: its first positive root is ``1 / (k + |V| |a|)``, where that is positive.
    With ``a = -2 iota_2 X / P``, ``V_t = (c / R_1 - 1 / R_2) / X`` (``P = |u_2 + i
    u_1|^2``) the ``X`` cancel: ``k = iota_1 / R_1 - 2 iota_2 (c / R_1 - 1 / R_2) / P``,
    ``|V| |a| = 2 sqrt(X^2 / R_1^2 + (c / R_1 - 1 / R_2)^2) / P``.
    """
    return _largest_radius(_circle_pair_terms(c1, r1, s1, c2, r2, s2), r1)


def _largest_radius(terms: tuple, r1: np.ndarray) -> np.ndarray:
    """:func:`circle_fillet_largest_radius` from the pair's :func:`_circle_pair_terms`."""
    x, p2, m, k = terms
    den = k + 2.0 * np.sqrt(x * x / (r1 * r1) + m * m) / p2
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(den > 0, 1.0 / den, np.inf)


def circle_fillet_radius_within(trim: np.ndarray, c1: np.ndarray, r1: np.ndarray,
                                s1: np.ndarray, c2: np.ndarray, r2: np.ndarray,
                                s2: np.ndarray) -> np.ndarray:
    """Largest radius whose fillet (:func:`circle_circle_fillet`) replaces at most the
    arc length ``trim`` of the first circle, mm, shape (k,) (``inf``: every fillet
    does; not positive: none). For the second circle pass the pair backwards, as to
    :func:`circle_fillet_radius_for_trim`.

    On the fillets' branch the replaced length grows with ``r`` up to the largest
    radius (:func:`circle_fillet_largest_radius`); the closed form
    :func:`circle_fillet_radius_for_trim` inverts it there, and beyond it falls back to
    0 where the circles cross a second time. So: the closed form where ``trim`` is
    below the length the largest fillet replaces, that radius where it is not.
    """
    # one frame for the closed form, the largest radius and the length it replaces
    # (the same expressions as the public functions: the same numbers)
    frame = _circle_pair_frame(c1, r1, s1, c2, r2, s2)
    r = _radius_for_trim(trim, frame, r1, s1, r2)
    top = _largest_radius(_terms_of(frame, r1, r2), r1)
    fin = np.flatnonzero(np.isfinite(top))
    reach = np.full(trim.shape, np.inf)
    if fin.size:
        # just inside the largest radius, where the fillet still exists (its replaced
        # length changes like the root of the distance to it: 1e-12 relative moves it
        # by about 1e-6 relative, on the closed form's side of the comparison); only
        # the first circle's replaced length is needed, the trim_in of
        # circle_circle_fillet: its centre and angle, not the whole fillet
        u01, u02, _, iota1, iota2 = frame
        r1f = r1[fin]
        on1, ot1, _, _, _ = _circle_fillet_centre(
            top[fin] * (1.0 - 1e-12), u01[fin], r1f, u02[fin], r2[fin], iota1[fin],
            iota2[fin])
        with np.errstate(invalid="ignore", divide="ignore"):
            reach[fin] = r1f * _first_angle(on1, ot1, r1f, s1[fin])
    return np.where(trim < reach, r, top)


__all__ = ["ArcFillet", "CircleFillet", "INTERNAL_MODES", "OVERLOAD_CHECKED_MODES",
           "REASON_CODE", "ROUNDING_REASONS", "RoundingTable", "always_rounds",
           "axis_deviation_limit", "break_windows", "circle_circle_fillet", "circle_fillet_deviation",
           "circle_fillet_largest_radius", "circle_fillet_radius_for_deviation",
           "fillet_radius_for_deviation", "circle_fillet_radius_for_trim",
           "circle_fillet_radius_within", "deflection_angle", "distance_for_deviation",
           "fillet_deviation", "fillet_pieces", "fillet_radius_for_arc_trim",
           "fillet_radius_for_line_trim", "leftovers", "line_circle_fillet",
           "very_short_blocks"]
