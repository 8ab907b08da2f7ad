"""Stage: tool radius compensation (G41/G42/G40), the first stage after the programmed
contour (DESIGN section 5: TRC -> tangential control -> rounding).

The tool centre path replaces the programmed contour wherever G41 (tool left of the
contour, looking along the motion) or G42 (right) is active. It is built exactly from
the path's helical pieces, in the working plane of the blocks (G17 XY, G18 ZX, G19 YZ;
other axes move as programmed):

* **offsets** (sinumerik-model 9): a line moves by the tool radius ``r`` along its
  normal to the programmed side and stays a line; an arc keeps its centre and becomes an
  arc of radius ``R + r`` or ``R - r`` (a spiral's end radii both move by ``r``). A
  radius that would reach zero or below is the control's collision alarm: an error
  naming the line ("the arc is smaller than the tool on the inside").
* **outside corners, SINUMERIK** (9; modal G450/G451 and DISC of the block after the
  corner, which the transition belongs to: "the transition circle belongs to the next
  traversing block"):

  - G450: a transition circle of radius ``r`` around the programmed corner, inserted as
    segments of kind ``"trc"`` owned by the next block;
  - DISC > 0 (with G450; at most MD20220 CUTCOM_MAX_DISC): the circle is sharpened. The
    model [I] (sinumerik-model 9 gives the apex distance ``r + (DISC/100) r (1/cos(theta/2)
    - 1)`` and suggests "two tangent lines plus a smaller arc"): straight extensions of
    both offset elements along their end tangents, then an arc of radius
    ``rho = r (1 - DISC/100)`` tangent to both, which puts the apex exactly there
    (DISC = 100: the two lines meet at the intersection of the tangents);
  - G451: the intersection of the two offset elements (lines extended as lines, arcs as
    their circles), no inserted block; above MD20210 CUTCOM_CORNER_LIMIT (a corner
    deflection, "very pointed outside corners") G451 switches to G450 with DISC, and
    where the offset elements do not intersect (two circles apart) too;
  - below MD20230 CUTCOM_CURVE_INSERT_LIMIT (deflection) the intersection is taken
    instead of a circle under G450 as well (9, "max. angle for which the intersection
    is calculated instead of inserting circles");
  - the 840C MD6 rule, when ``CUTCOM_840C_MD6`` > 0 (840C excerpt), at outside corners
    with an arc: with ``A``/``C`` the ends of the two offset elements at the corner,
    ``AC < MD6``: the intersection of the two blocks, no intermediate block (G450 and
    G451); where there is none or it lies more than 1.5 r from the contour: for contour
    angles 90..170 degrees the intermediate blocks again, for 170..180 degrees none (the
    next block starts at ``A`` and reaches its compensated end only at its end, the
    excerpt's "contour error"); ``AC < 2 MD6`` under G451: the transition circle (G450);
    otherwise G450 the circle and G451 one or two intermediate lines to the intersection
    of the tangents at ``A`` and ``C``. (The contour angle of the excerpt is the angle
    between the elements, 180 degrees minus the deflection.)

* **outside corners, NGC** (LinuxCNC ``convert_straight_comp2``/``convert_arc_comp2``):
  an arc of radius ``r`` around the corner; a G0 block instead goes straight to the start
  of its offset (no arc traverse exists); below 0.01 rad (``TOLERANCE_CONCAVE_CORNER``)
  no arc: the next block starts where the previous one ended.
* **inside corners** (both): the intersection of the offset elements, trimming both
  (9: "inside corners: always the intersection of the equidistants"). No intersection,
  or an element trimmed to nothing or reversed (a bottleneck, a contour reversal of the
  tool centre path) is the collision alarm: an error naming the line where the tool does
  not fit. A programmed reversal (180 degrees) is an outside corner: the tool goes around
  the end point.
* **approach and retract** (the controls' NORM / LinuxCNC entry move): compensation
  starts with the first block in G41/G42 that moves in the plane; it must be a line
  (G0/G1, else an error). SINUMERIK: it goes straight from the uncompensated start to the
  compensated start of the next element (perpendicular to its start tangent); NGC
  (``convert_straight_comp1``): to the end point moved by ``r`` perpendicular to the move
  itself, longer than ``r`` (else LinuxCNC's error), and the corner to the next element
  is then treated like any other (an inside corner there cuts the entry line at the
  intersection with the next offset; LinuxCNC moves its end back parallel to the
  programmed move instead, a difference of the order of r times the small angle between
  the two). The first moving block after G40 (a line, else an
  error) goes from the compensated end of the last element straight to its programmed
  end, whatever axes it names (so ``G40 G0 Z50`` moves the plane axes back too, as on
  LinuxCNC, whose canonical moves are absolute).
* other axes (Z, rotary axes) move on the block's own element; an inserted transition
  moves none of them (LinuxCNC moves rotary axes on its inserted arc: not modelled).
* blocks in a compensated run that do not move in the plane (a Z infeed) stay at the
  compensated end of the element before them (the intermediate point ``P*`` of 9); the
  transition of the corner around them belongs to the next element in the plane.

Tool radius: from the program (``Modal.tool_radius_mm``: ``$TC_DP6``, ``G10 L1``,
``G41.1 D``), else the machine's tool table for ``Modal.trc_tool``; missing: an error
naming the line. A negative radius changes the side. Model limits (each an error naming
the line, never a silently wrong path): G41 <-> G42 without G40 between, a radius change
during compensation, a change of plane, an arc in a rotated (tilted) plane; NGC also G19
(LinuxCNC compensates in XY and XZ only). Not modelled: KONT/KONTC approach (read as
NORM), look-ahead collision detection beyond neighbouring elements (CDON), LinuxCNC
entry arcs (an error).

Units: mm, rad. ``m`` segments, ``n`` axes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .core.errors import PathError
from .core.geometry import KIND_CODES, Path, arc_segments, line_segments
from .core.tolerances import POS_TOL_MM
from .machine import Machine
from .nc.program import Block, Program
from .splice import ROW_KEYS, copy_rows, splice

_PLANES = {"G17": ("X", "Y"), "G18": ("Z", "X"), "G19": ("Y", "Z")}
_LINE = KIND_CODES.index("line")
_ARC = KIND_CODES.index("arc")
_TRC = KIND_CODES.index("trc")
#: LinuxCNC's TOLERANCE_CONCAVE_CORNER (rs274ngc): below this deflection, rad, an outside
#: corner gets no arc (the next move starts where the previous one ended).
NGC_CORNER_TOL_RAD = 0.01
#: 840C excerpt: the intersection is not used when it lies farther than this many tool
#: radii from the contour.
MD6_INTERSECTION_REACH = 1.5
#: A corner whose deflection has a sine below this (and a cosine below 0) is a reversal,
#: whose turn direction the tangents cannot tell: float64 round-off of unit tangents is
#: about 1e-16, a real corner of 1e-12 rad moves the offset by 5e-12 mm at r = 5 mm.
REVERSAL_SIN = 1e-12


# ------------------------------------------------------------------ results
@dataclass(frozen=True, slots=True)
class TrcCorner:
    """What the stage did at one corner of a compensated run.

    Attributes
    ----------
    block, next_block : int
        Program blocks before and after the corner (inserted segments belong to
        ``next_block``).
    side : {"outside", "inside", "tangential"}
        Corner type seen from the tool.
    action : str
        ``"circle"``, ``"DISC 30"``, ``"intersection"``, ``"joined"``, ``"chord"``,
        ``"tangent lines"`` or ``"none"``, with the rule that chose it.
    deflection_deg : float
        Change of direction of the programmed contour, degrees.
    inserted_mm : float
        Length of the inserted ``trc`` segments, mm (0 if none).
    """

    block: int
    next_block: int
    side: str
    action: str
    deflection_deg: float
    inserted_mm: float


@dataclass(frozen=True, slots=True)
class TrcBlock:
    """One block of a compensated run.

    Attributes
    ----------
    block : int
        Program block.
    role : {"approach", "contour", "retract", "infeed"}
        Approach line, offset contour element, retract line, or a block without plane
        motion at the compensated point.
    side : {"G41", "G42"}
        Side of the tool (after a negative radius swapped it).
    radius_mm : float
        Tool radius in force, mm (>= 0).
    """

    block: int
    role: str
    side: str
    radius_mm: float


@dataclass(frozen=True, slots=True, eq=False)
class TrcResult:
    """The compensated path and what was done.

    Attributes
    ----------
    path : Path
        The tool centre path (``path`` itself when no block compensates).
    blocks : tuple[TrcBlock, ...]
        Every block of every compensated run, in path order.
    corners : tuple[TrcCorner, ...]
        Every corner between two plane elements of a run, in path order.
    """

    path: Path
    blocks: tuple[TrcBlock, ...] = ()
    corners: tuple[TrcCorner, ...] = ()


# ------------------------------------------------------------------ 2-D helpers
def _cross(a, b) -> float:
    return a[0] * b[1] - a[1] * b[0]


def _dot(a, b) -> float:
    return a[0] * b[0] + a[1] * b[1]


def _add(a, b, k: float = 1.0):
    return (a[0] + k * b[0], a[1] + k * b[1])


def _sub(a, b):
    return (a[0] - b[0], a[1] - b[1])


def _norm(a) -> float:
    return math.hypot(a[0], a[1])


def _left(t):
    """Left normal of a plane direction (the G41 side)."""
    return (-t[1], t[0])


def _angle_between(t1, t2) -> float:
    """Angle between unit directions, rad in [0, pi] (accurate near 0 and pi)."""
    return 2.0 * math.atan2(_norm(_sub(t1, t2)), _norm(_add(t1, t2)))


def _line_line(p1, t1, p2, t2):
    den = _cross(t1, t2)
    if abs(den) < 1e-15:
        return []
    lam = _cross(_sub(p2, p1), t2) / den
    return [_add(p1, t1, lam)]


def _line_circle(p, t, c, R):
    f = _sub(p, c)
    b = _dot(t, f)
    disc = b * b - (_dot(f, f) - R * R)
    if disc < 0:
        return []
    s = math.sqrt(disc)
    return [_add(p, t, -b - s), _add(p, t, -b + s)]


def _circle_circle(c1, r1, c2, r2):
    dvec = _sub(c2, c1)
    d = _norm(dvec)
    if d < 1e-15 or d > r1 + r2 or d < abs(r1 - r2):
        return []
    a = (r1 * r1 - r2 * r2 + d * d) / (2 * d)
    h = math.sqrt(max(r1 * r1 - a * a, 0.0))
    mid = _add(c1, dvec, a / d)
    off = (-dvec[1] * h / d, dvec[0] * h / d)
    return [_add(mid, off), _sub(mid, off)]


def _wrap(a: float) -> float:
    """Angle wrapped to (-pi, pi]."""
    return math.pi - (math.pi - a) % (2 * math.pi)


# ------------------------------------------------------------------ elements
class _El:
    """A plane element of a compensated run while the run is built (mutable helper).

    Lines: programmed ends ``P0, P1``, direction ``t``; offset ends ``A0, A1``; the
    approach line also its own direction ``pre`` (it is not parallel to ``t``).
    Arcs: centre ``c``, signed sweep ``S`` (CCW > 0), offset ends ``A0, A1`` on the
    offset circle(s); ``dS0``/``dS1`` how far corners moved the start / end angle (rad,
    counter-clockwise positive): the new sweep is ``S - dS0 + dS1``.
    """

    __slots__ = ("j", "block", "is_arc", "P0", "P1", "t", "c", "S", "R0", "R1", "A0", "A1",
                 "dS0", "dS1", "t0", "t1", "approach", "pre")

    def start_primitive(self):
        return ("arc", self.c, _norm(_sub(self.A0, self.c))) if self.is_arc else (
            "line", self.A0, self._dir())

    def end_primitive(self):
        return ("arc", self.c, _norm(_sub(self.A1, self.c))) if self.is_arc else (
            "line", self.A1, self._dir())

    def _dir(self):
        return self.pre if self.approach else self.t     # the entry line itself


def _intersections(p1, p2):
    k1, a1, b1 = p1
    k2, a2, b2 = p2
    if k1 == "line" and k2 == "line":
        return _line_line(a1, b1, a2, b2)
    if k1 == "line":
        return _line_circle(a1, b1, a2, b2)
    if k2 == "line":
        return _line_circle(a2, b2, a1, b1)
    return _circle_circle(a1, b1, a2, b2)


def _nearest(points, ref):
    return min(points, key=lambda q: _norm(_sub(q, ref))) if points else None


def _move_end(el: _El, X) -> None:
    """End of element ``el`` moved to ``X`` (on its offset line or circle)."""
    if el.is_arc:
        old = math.atan2(el.A1[1] - el.c[1], el.A1[0] - el.c[0])
        new = math.atan2(X[1] - el.c[1], X[0] - el.c[0])
        el.dS1 += _wrap(new - old)
    el.A1 = X


def _move_start(el: _El, X) -> None:
    """Start of element ``el`` moved to ``X``."""
    if el.is_arc:
        old = math.atan2(el.A0[1] - el.c[1], el.A0[0] - el.c[0])
        new = math.atan2(X[1] - el.c[1], X[0] - el.c[0])
        el.dS0 += _wrap(new - old)
    el.A0 = X


# ------------------------------------------------------------------ the stage
def compensate_path(path: Path, program: Program, machine: Machine) -> TrcResult:
    """Apply tool radius compensation to a path (see the module docstring).

    Parameters
    ----------
    path : Path
        The programmed contour over the machine's axes, one segment per moving block
        (:func:`reference.prepare.restrict_to_machine`).
    program : Program
        Its program (G40/G41/G42, G450/G451, DISC, plane, tool data per block).
    machine : Machine
        Tool table, MD20210/20220/20230 and the 840C MD6 option.

    Returns
    -------
    TrcResult

    Raises
    ------
    PathError
        Naming file and line: a missing tool radius, the tool does not fit (collision),
        an approach or retract on an arc, or a model limit (see the module docstring).
    """
    blocks = program.blocks
    m = path.n_segments
    if m == 0 or not _uses(blocks, "tool_compensation", "G40"):
        return TrcResult(path)
    comp = [blocks[b].modal.tool_compensation for b in path.block.tolist()]
    runs: list[tuple[list[int], int | None]] = []
    j = 0
    while j < m:
        if comp[j] == "G40":
            j += 1
            continue
        run = []
        while j < m and comp[j] != "G40":
            run.append(j)
            j += 1
        runs.append((run, j if j < m else None))
    builder = _Builder(path, program, machine)
    for run, retract in runs:
        builder.run(run, retract)
    return builder.result()


def _uses(blocks, field: str, off) -> bool:
    """Whether some block's modal ``field`` differs from ``off``. Consecutive blocks share
    one modal state object, so a change of object is all there is to look at (10^6
    blocks in some 30 ms)."""
    prev = None
    for b in blocks:
        md = b.modal
        if md is not prev:
            prev = md
            if getattr(md, field) != off:
                return True
    return False


def apply_trc(path: Path, program: Program, machine: Machine) -> Path:
    """The compensated path alone (:func:`compensate_path` ``.path``)."""
    return compensate_path(path, program, machine).path


class _Builder:
    """Collects the new rows of the path, run by run (private to :func:`compensate_path`)."""

    def __init__(self, path: Path, program: Program, machine: Machine) -> None:
        self.path, self.program, self.machine = path, program, machine
        self.ngc = program.dialect == "ngc"
        self.index = {a: i for i, a in enumerate(path.axes)}
        # per old segment: None (copy unchanged) or a list of row specs
        self.rows: dict[int, list[tuple]] = {}
        self.tblocks: list[TrcBlock] = []
        self.corners: list[TrcCorner] = []

    # ------------------------------------------------------------ messages
    def _where(self, block: int) -> str:
        return f"{self.program.file}:{self.program.blocks[block].line}"

    def _fail(self, block: int, message: str) -> PathError:
        return PathError(f"{self._where(block)}: {message}", block)

    # ------------------------------------------------------------ tool data
    def _radius(self, blk: Block) -> tuple[float, float]:
        """(radius >= 0, side sign +1 left / -1 right) for a block in G41/G42."""
        r = blk.tool_radius_mm
        if r is None:
            key = blk.trc_tool
            hint = ("G10 L1 P<tool> R<radius>, a tool table (--tool-table) or [tools] in "
                    "the machine data" if self.ngc else
                    "$TC_DP6[t,d] in the program or [tools] in the machine data")
            if key is None or key[0] is None:
                raise self._fail(blk.index, f"{blk.tool_compensation} needs a tool radius, "
                                            f"but no tool is selected (T); define it with "
                                            f"{hint}")
            r = self.machine.tools.radius(*key)
            if r is None:
                tool = f'T="{key[0]}"' if isinstance(key[0], str) else f"T{key[0]}"
                raise self._fail(blk.index, f"{blk.tool_compensation}: tool {tool} D{key[1]} "
                                            f"has no radius; define it with {hint}")
        side = 1.0 if blk.tool_compensation == "G41" else -1.0
        if r < 0:                       # a negative radius compensates on the other side
            r, side = -r, -side
        return float(r), side

    # ------------------------------------------------------------ one run
    def run(self, run: list[int], retract: int | None) -> None:
        path, blocks = self.path, self.program.blocks
        first = blocks[int(path.block[run[0]])]
        plane = first.plane
        if self.ngc and plane == "G19":
            raise self._fail(first.index, "cutter compensation in the YZ plane (G19): "
                                          "LinuxCNC compensates in G17 and G18 only")
        r, side = self._radius(first)
        label = "G41" if side > 0 else "G42"
        seen = None
        for bi in path.block[run].tolist():
            b = blocks[bi]
            if b.modal is seen:          # consecutive blocks share their modal state
                continue
            seen = b.modal
            if b.plane != plane:
                raise self._fail(b.index, f"plane change ({plane} -> {b.plane}) while tool "
                                          "radius compensation is active; program G40 first")
            rb, sb = self._radius(b)
            if b.tool_compensation != first.tool_compensation:
                raise self._fail(b.index, f"{first.tool_compensation} -> "
                                          f"{b.tool_compensation} without G40 between is not "
                                          "modelled; program G40 first")
            if abs(rb - r) > POS_TOL_MM or sb != side:
                raise self._fail(b.index, f"the tool radius changes ({r:g} -> {rb:g} mm) "
                                          "while compensation is active; not modelled: "
                                          "program G40 first")
        u, v = (self.index[a] for a in _PLANES[plane])
        els = self._elements(run, u, v)
        if r <= 0.0:                     # D0 or a zero radius: the contour itself
            for j in run:
                self.tblocks.append(TrcBlock(int(path.block[j]), "contour", label, 0.0))
            return
        if self.ngc and els[0] is None:
            # LinuxCNC takes the first move after G41/G42 as the entry move, whatever it
            # moves (convert_straight_comp1): without motion in the plane it is too short
            raise self._fail(int(path.block[run[0]]), "length of the cutter compensation "
                                                      "entry move is not greater than the "
                                                      "tool radius (LinuxCNC refuses it)")
        plane_els = [e for e in els if e is not None]
        if not plane_els:
            return
        # --- approach: the first element in the plane must be a line
        ap = plane_els[0]
        if ap.is_arc:
            raise self._fail(ap.block, f"{label} is selected in an arc block: the approach "
                                       "to the contour must be a G0/G1 line (not modelled on "
                                       "an arc)")
        ap.approach = True
        for e in plane_els:
            self._offset(e, r, side)
        if self.ngc:
            if _norm(_sub(ap.P1, ap.P0)) <= r:
                raise self._fail(ap.block, "length of the cutter compensation entry move is "
                                           "not greater than the tool radius (LinuxCNC refuses "
                                           "it)")
            ap.A0 = ap.P0                # from the uncompensated point; A1 is offset already
        else:
            ap.A0 = ap.P0
            if len(plane_els) > 1:       # NORM: perpendicular to the next element's start
                ap.A1 = plane_els[1].A0
        entry = _sub(ap.A1, ap.A0)
        ap.pre = (entry[0] / _norm(entry), entry[1] / _norm(entry)) if _norm(entry) > 0 \
            else ap.t                   # the direction of the entry line itself
        ap.t1 = ap.t                    # the corner test uses the programmed direction
        # --- corners between consecutive plane elements
        inserted: dict[int, list[tuple]] = {}
        for a, b in zip(plane_els[:-1], plane_els[1:]):
            if a is ap and not self.ngc:
                self.corners.append(TrcCorner(a.block, b.block, "tangential",
                                              "none (NORM approach)", 0.0, 0.0))
                continue
            inserted[b.j] = self._corner(a, b, r, side)
        # --- checks: every element keeps its direction (else the tool does not fit)
        for e in plane_els:
            if e is not ap or self.ngc:     # a NORM approach is any straight line
                self._check(e, r)
        # --- rows
        last_end = None
        for j, e in zip(run, els):
            blk = int(path.block[j])
            if e is None:
                # a block without plane motion: at the compensated point reached so far
                at = last_end
                self.rows[j] = [("line", at, at, blk, _LINE)]
                self.tblocks.append(TrcBlock(blk, "infeed" if at is not None else
                                             "contour", label, r))
                continue
            specs = inserted.get(j, [])
            if e.is_arc:
                specs = specs + [("arc", e.A0, e.A1, blk, _ARC, e.c, e.S - e.dS0 + e.dS1)]
            else:
                specs = specs + [("line", e.A0, e.A1, blk, _LINE)]
            self.rows[j] = specs
            self.tblocks.append(TrcBlock(blk, "approach" if e is ap else "contour", label, r))
            last_end = e.A1
        if retract is not None:
            rb = blocks[int(path.block[retract])]
            if path.radius[retract] > 0:
                raise self._fail(rb.index, "G40 deselects compensation in an arc block: the "
                                           "retract must be a G0/G1 line")
            self.rows[retract] = [("line", last_end, None, int(path.block[retract]), _LINE)]
            self.tblocks.append(TrcBlock(int(path.block[retract]), "retract", label, r))

    def _elements(self, run: list[int], u: int, v: int) -> list[_El | None]:
        """Plane elements of a run (``None`` for segments without plane motion)."""
        path = self.path
        out: list[_El | None] = []
        js = np.asarray(run, dtype=np.int64)
        # the run's columns as Python numbers at once (element access to numpy arrays
        # costs a microsecond each)
        cols = zip(js.tolist(), path.block[js].tolist(), path.length[js].tolist(),
                   path.origin[js, u].tolist(), path.origin[js, v].tolist(),
                   path.radius[js].tolist(), path.omega[js].tolist(),
                   path.theta0[js].tolist(), path.dradius[js].tolist(),
                   path.d[js, u].tolist(), path.d[js, v].tolist(),
                   (path.e1[js, u] == 1.0).tolist(), (path.e2[js, v] == 1.0).tolist())
        for j, blk, L, ou, ov, rad, om, th0, dr, du, dv, in_u, in_v in cols:
            e = _El()
            e.j, e.block, e.approach, e.pre = j, blk, False, None
            e.dS0 = e.dS1 = 0.0
            if rad > 0:
                if not (in_u and in_v):
                    raise self._fail(blk, "tool radius compensation on an arc outside the "
                                          "working plane (a rotated frame tilts it) is not "
                                          "modelled")
                e.is_arc = True
                e.c = (ou, ov)
                e.S = om * L
                R0 = rad
                th1 = th0 + e.S
                R1 = R0 + dr * abs(e.S)
                e.R0, e.R1 = R0, R1
                e.P0 = (e.c[0] + R0 * math.cos(th0), e.c[1] + R0 * math.sin(th0))
                e.P1 = (e.c[0] + R1 * math.cos(th1), e.c[1] + R1 * math.sin(th1))
                sgn = 1.0 if e.S > 0 else -1.0
                e.t0 = (-sgn * math.sin(th0), sgn * math.cos(th0))
                e.t1 = (-sgn * math.sin(th1), sgn * math.cos(th1))
                e.t = e.t0
            else:
                dp = (du * L, dv * L)
                lp = _norm(dp)
                if lp <= POS_TOL_MM:
                    out.append(None)
                    continue
                e.is_arc = False
                e.P0 = (ou, ov)
                e.P1 = _add(e.P0, dp)
                e.t = (dp[0] / lp, dp[1] / lp)
                e.t0 = e.t1 = e.t
            out.append(e)
        return out

    def _offset(self, e: _El, r: float, side: float) -> None:
        """Offset ends of an element (untrimmed); collision alarm for small inside arcs."""
        if not e.is_arc:
            n = _left(e.t)
            e.A0 = _add(e.P0, n, side * r)
            e.A1 = _add(e.P1, n, side * r)
            return
        sgn = 1.0 if e.S > 0 else -1.0
        R0o = e.R0 - side * r * sgn
        R1o = e.R1 - side * r * sgn
        if min(R0o, R1o) <= POS_TOL_MM:
            blk = self.program.blocks[e.block]
            raise self._fail(e.block, f"the arc (radius {min(e.R0, e.R1):g} mm) is not larger "
                                      f"than the tool radius {r:g} mm on the inside "
                                      f"({blk.tool_compensation} on {blk.motion}): the tool "
                                      "does not fit (the control's collision alarm)")
        e.A0 = _add(e.c, _sub(e.P0, e.c), R0o / e.R0)
        e.A1 = _add(e.c, _sub(e.P1, e.c), R1o / e.R1)

    # ------------------------------------------------------------ corners
    def _corner(self, a: _El, b: _El, r: float, side: float) -> list[tuple]:
        """Handle the corner between plane elements ``a`` and ``b``: move their offset
        ends, return the specs of inserted rows (owned by ``b``'s block)."""
        blocks = self.program.blocks
        t1, t2 = a.t1, b.t0
        theta = _angle_between(t1, t2)
        deg = math.degrees(theta)
        A, C = a.A1, b.A0
        if _norm(_sub(C, A)) <= POS_TOL_MM:
            # the offset elements meet (a tangential transition, or a kink too small to
            # move the offset by a position tolerance): no transition, b starts at A
            _move_start(b, A)
            self.corners.append(TrcCorner(a.block, b.block, "tangential", "none", deg, 0.0))
            return []
        cross = _cross(t1, t2)
        reversal = _dot(t1, t2) < 0 and abs(cross) <= REVERSAL_SIN
        turn = -side if reversal else (1.0 if cross > 0 else -1.0)   # +1 left, -1 right
        P = a.P1
        if not reversal and side * cross > 0:
            # inside corner: the intersection, always (both dialects)
            X = _nearest(_intersections(a.end_primitive(), b.start_primitive()),
                         _add(A, _sub(C, A), 0.5))
            if X is None:
                raise self._fail(b.block, f"the tool (radius {r:g} mm) does not fit into the "
                                          f"inside corner between lines "
                                          f"{blocks[a.block].line} and {blocks[b.block].line}:"
                                          " the compensated elements do not intersect (the "
                                          "control's collision alarm)")
            _move_end(a, X)
            _move_start(b, X)
            self.corners.append(TrcCorner(a.block, b.block, "inside", "intersection", deg,
                                          0.0))
            return []
        bb = blocks[b.block]
        if self.ngc:
            if theta < NGC_CORNER_TOL_RAD:
                _move_start(b, A)
                action, pieces = "joined (below 0.01 rad, LinuxCNC)", []
            elif bb.motion == "G0":
                action, pieces = "chord (G0: no arc traverse, LinuxCNC)", [("seg", A, C)]
            else:
                action, pieces = "circle (LinuxCNC)", [("arc", A, C, P, turn)]
            return self._record(a, b, deg, action, pieces)
        ch = self.machine.channel
        mode = bb.trc_corner
        disc = bb.disc
        if ch.cutcom_840c_md6_mm > 0 and (a.is_arc or b.is_arc):
            return self._corner_840c(a, b, r, theta, turn, mode)
        if theta < math.radians(ch.cutcom_curve_insert_limit_deg):
            if self._intersect_outside(a, b):
                return self._record(a, b, deg, "intersection (below CUTCOM_CURVE_INSERT_LIMIT)",
                                    [])
            why = " (no intersection)"
        elif mode == "G451" and deg <= ch.cutcom_corner_limit_deg:
            if self._intersect_outside(a, b):
                return self._record(a, b, deg, "intersection (G451)", [])
            why = " (G451: no intersection)"
        else:
            why = (" (G451 above CUTCOM_CORNER_LIMIT)" if mode == "G451" else "")
        if disc > 0 and not reversal:
            if disc > ch.cutcom_max_disc:
                raise self._fail(b.block, f"DISC={disc:g} is above MD20220 CUTCOM_MAX_DISC = "
                                          f"{ch.cutcom_max_disc:g}")
            return self._record(a, b, deg, f"DISC {disc:g}{why}",
                                self._disc_pieces(A, C, t1, t2, P, r, theta, turn, disc))
        return self._record(a, b, deg, f"circle{why}", [("arc", A, C, P, turn)])

    def _intersect_outside(self, a: _El, b: _El) -> bool:
        """Move ``a``'s end and ``b``'s start to the intersection of their offset
        elements beyond the corner; False (nothing moved) where there is none."""
        A, C = a.A1, b.A0
        X = _nearest(_intersections(a.end_primitive(), b.start_primitive()),
                     _add(A, _sub(C, A), 0.5))
        # the intersection of an outside corner lies ahead of A and before C
        if X is None or _dot(_sub(X, A), a.t1) < -POS_TOL_MM or \
                _dot(_sub(C, X), b.t0) < -POS_TOL_MM:
            return False
        _move_end(a, X)
        _move_start(b, X)
        return True

    @staticmethod
    def _disc_pieces(A, C, t1, t2, P, r, theta, turn, disc) -> list[tuple]:
        """DISC: tangent extensions of length (r - rho) tan(theta/2), then an arc of
        radius rho = r (1 - DISC/100) tangent to both (module docstring)."""
        rho = r * (1.0 - disc / 100.0)
        ext = (r - rho) * math.tan(theta / 2.0)
        T1 = _add(A, t1, ext)
        T2 = _add(C, t2, -ext)
        if rho <= POS_TOL_MM:
            return [("seg", A, T1), ("seg", T1, C)]
        Q = _add(T1, _sub(P, A), rho / r)   # centre: rho inward of T1 (P - A is r inward)
        return [("seg", A, T1), ("arc", T1, T2, Q, turn), ("seg", T2, C)]

    def _corner_840c(self, a: _El, b: _El, r: float, theta: float, turn: float,
                     mode: str) -> list[tuple]:
        """The 840C MD6 rule at an outside corner with an arc (module docstring)."""
        md6 = self.machine.channel.cutcom_840c_md6_mm
        A, C, P = a.A1, b.A0, a.P1
        deg = math.degrees(theta)
        alpha = 180.0 - deg                      # the excerpt's contour angle
        ac = _norm(_sub(C, A))
        circle = [("arc", A, C, P, turn)]
        lines = self._tangent_lines(A, C, a.t1, b.t0, r, theta)
        per_mode = circle if mode == "G450" else lines
        name = "circle" if mode == "G450" else "tangent lines"
        if ac < md6:
            X = _nearest(_intersections(a.end_primitive(), b.start_primitive()),
                         _add(A, _sub(C, A), 0.5))
            if X is not None and _norm(_sub(X, P)) <= MD6_INTERSECTION_REACH * r:
                _move_end(a, X)
                _move_start(b, X)
                return self._record(a, b, deg, "intersection (840C: AC < MD6)", [])
            if alpha >= 170.0:
                _move_start(b, A)
                return self._record(a, b, deg, "joined (840C: AC < MD6, 170..180 degrees, "
                                               "contour error)", [])
            return self._record(a, b, deg, f"{name} (840C: AC < MD6, no usable "
                                           "intersection)", per_mode)
        if ac < 2.0 * md6 and mode == "G451":
            return self._record(a, b, deg, "circle (840C: G451 -> G450, AC < 2 MD6)", circle)
        return self._record(a, b, deg, f"{name} (840C)", per_mode)

    @staticmethod
    def _tangent_lines(A, C, t1, t2, r, theta) -> list[tuple]:
        """Intermediate lines A -> S -> C, S the intersection of the tangents at A, C."""
        S = _add(A, t1, r * math.tan(theta / 2.0))
        return [("seg", A, S), ("seg", S, C)]

    def _record(self, a: _El, b: _El, deg: float, action: str,
                pieces: list[tuple]) -> list[tuple]:
        """Record the corner; the inserted pieces as row specs, chained end to start (a
        piece shorter than POS_TOL_MM is left out and the chain closes over it, so no
        gap opens; b then starts exactly where the last piece ends)."""
        specs = []
        length = 0.0
        at = a.A1
        for p in pieces:
            end = p[2]
            if _norm(_sub(end, at)) <= POS_TOL_MM:
                continue
            if p[0] == "seg":
                specs.append(("line", at, end, b.block, _TRC))
                length += _norm(_sub(end, at))
            else:
                q, turn = p[3], p[4]
                a0 = math.atan2(at[1] - q[1], at[0] - q[0])
                a1 = math.atan2(end[1] - q[1], end[0] - q[0])
                sweep = (a1 - a0) % (2 * math.pi) if turn > 0 else \
                    -((a0 - a1) % (2 * math.pi))
                specs.append(("arc", at, end, b.block, _TRC, q, sweep))
                length += _norm(_sub(at, q)) * abs(sweep)
            at = end
        _move_start(b, at)
        self.corners.append(TrcCorner(a.block, b.block, "outside", action, deg, length))
        return specs

    # ------------------------------------------------------------ checks
    def _check(self, e: _El, r: float) -> None:
        """Collision alarm: an element trimmed to nothing or running backwards."""
        if e.is_arc:
            S2 = e.S - e.dS0 + e.dS1
            ok = S2 * e.S > 0 and abs(S2) * min(_norm(_sub(e.A0, e.c)),
                                                _norm(_sub(e.A1, e.c))) > POS_TOL_MM
        else:
            ref = e.pre if e.approach else e.t
            ok = _dot(_sub(e.A1, e.A0), ref) > POS_TOL_MM * _norm(ref)
        if not ok:
            raise self._fail(e.block, f"the compensated path of this block would vanish or "
                                      f"run backwards (contour reversal): the tool (radius "
                                      f"{r:g} mm) does not fit between its neighbours (the "
                                      "control's collision alarm)")

    # ------------------------------------------------------------ assembly
    def result(self) -> TrcResult:
        """The new path: unchanged segments copied, compensated ones rebuilt exactly."""
        path = self.path
        m, n = path.n_segments, path.n_axes
        if not self.rows:
            return TrcResult(path, tuple(self.tblocks), tuple(self.corners))
        # end points of the rebuilt segments, all axes (the other axes keep their values)
        js = np.array(sorted(self.rows), dtype=np.int64)
        q0 = path.evaluate(path.s_breaks[js], segment=js)[0]
        q1 = path.evaluate(path.s_breaks[js + 1], segment=js)[0]
        owner: list[int] = []
        copy_src: list[int] = []
        copy_dst: list[int] = []
        # rebuilt rows: start, end (all axes, lists), block, kind; arcs also centre,
        # sweep and plane axes
        lines: list[tuple] = []
        arcs: list[tuple] = []
        starts, stops = q0.tolist(), q1.tolist()
        row_of = {int(j): i for i, j in enumerate(js.tolist())}
        plane_of: dict[str, tuple[int, int]] = {}
        for j in range(m):
            specs = self.rows.get(j)
            if specs is None:
                copy_src.append(j)
                copy_dst.append(len(owner))
                owner.append(j)
                continue
            plane = self.program.blocks[int(path.block[j])].plane
            if plane not in plane_of:
                plane_of[plane] = tuple(self.index[a] for a in _PLANES[plane])
            pu, pv = plane_of[plane]
            qs, qe = starts[row_of[j]], stops[row_of[j]]
            for spec in specs:
                row = len(owner)
                owner.append(j)
                p0 = list(qs)
                p1 = list(qs if spec[4] == _TRC else qe)   # a transition: others at rest
                if spec[1] is not None:
                    p0[pu], p0[pv] = spec[1]
                if spec[2] is not None:
                    p1[pu], p1[pv] = spec[2]
                if spec[0] == "line":
                    lines.append((row, p0, p1, spec[3], spec[4]))
                    continue
                c = list(p0)
                c[pu], c[pv] = spec[5]
                arcs.append((row, p0, p1, c, spec[6], spec[3], spec[4], pu, pv))
        total = len(owner)
        packed = {k: np.zeros((total, n)) for k in ("origin", "e1", "e2", "d")}
        packed.update({k: np.zeros(total) for k in ("radius", "omega", "theta0", "length",
                                                    "dradius")})
        packed["block"] = np.zeros(total, np.int64)
        packed["kind"] = np.zeros(total, np.int8)
        if copy_src:
            src = copy_rows(path, np.array(copy_src))
            for k in ROW_KEYS:
                packed[k][np.array(copy_dst)] = src[k]
        if lines:
            lp = line_segments(np.array([x[1] for x in lines]), np.array([x[2] for x in lines]),
                               path.geometry, np.array([x[3] for x in lines]))
            lp["kind"] = np.array([x[4] for x in lines], dtype=np.int8)
            rows = np.array([x[0] for x in lines])
            for k in ROW_KEYS:
                packed[k][rows] = lp[k]
        if arcs:
            s0 = np.array([x[1] for x in arcs])
            s1 = np.array([x[2] for x in arcs])
            cen = np.array([x[3] for x in arcs])
            sweep = np.array([x[4] for x in arcs])
            k = np.arange(len(arcs))
            E1 = np.zeros((len(arcs), n))
            E2 = np.zeros((len(arcs), n))
            E1[k, [x[7] for x in arcs]] = 1.0
            E2[k, [x[8] for x in arcs]] = 1.0

            def plane_radius(q):
                return np.hypot(np.sum((q - cen) * E1, axis=1), np.sum((q - cen) * E2, axis=1))
            r0, r1 = plane_radius(s0), plane_radius(s1)
            chord = np.hypot(np.sum((s1 - s0) * E1, axis=1), np.sum((s1 - s0) * E2, axis=1))
            ap = arc_segments(s0, s1, cen, E1, E2, sweep < 0, _turns(np.abs(sweep), chord),
                              path.geometry, np.array([x[5] for x in arcs]),
                              np.abs(r1 - r0) + POS_TOL_MM)
            ap["kind"] = np.array([x[6] for x in arcs], dtype=np.int8)
            rows = np.array([x[0] for x in arcs])
            for k in ROW_KEYS:
                packed[k][rows] = ap[k]
            got = np.abs(ap["omega"] * ap["length"])
            if not np.allclose(got, np.abs(sweep), rtol=0.0, atol=1e-6):
                raise AssertionError(f"TRC: an arc was rebuilt with a different sweep {got} {sweep} {s0} {s1} {cen}")
        owner_a = np.asarray(owner, dtype=np.int64)
        feed = path.feed[owner_a]
        rapid = path.rapid[owner_a]
        keep = packed["length"] > POS_TOL_MM      # an infeed trimmed to nothing, etc.
        if not keep.all():
            packed = {k: a[keep] for k, a in packed.items()}
            owner_a, feed, rapid = owner_a[keep], feed[keep], rapid[keep]
        new = splice(path, packed, owner_a, feed, rapid)
        return TrcResult(new, tuple(self.tblocks), tuple(self.corners))


def _turns(sweep: np.ndarray, chord: np.ndarray) -> np.ndarray:
    """Extra full turns that make :func:`arc_segments` sweep ``sweep`` (rad, > 0): it
    sweeps the angle from start to end plus 2 pi per turn, and a full turn where the
    ends coincide (chord within POS_TOL_MM)."""
    two_pi = 2 * np.pi
    closed = chord <= POS_TOL_MM
    turns = np.where(closed, np.maximum(np.round(sweep / two_pi) - 1, 0),
                     np.floor(sweep / two_pi))
    return turns.astype(np.int64)


__all__ = ["MD6_INTERSECTION_REACH", "NGC_CORNER_TOL_RAD", "TrcBlock", "TrcCorner",
           "TrcResult", "apply_trc", "compensate_path"]
