"""NC program data: the parser's output, one resolved :class:`Block` per NC line.

The parser does all modal bookkeeping (units, absolute/incremental, planes, frames,
variables, control flow), so every block here carries *absolute* positions in mm
(degrees for rotary axes) and feeds in mm/s. Later stages never look at NC text again,
except to show it (``Block.source``) and to point at it (``Block.line``).

Symbols: ``n_axes = len(Program.axes)``; all position tuples are in that axis order.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

Dialect = Literal["sinumerik", "ngc"]
Motion = Literal["G0", "G1", "G2", "G3"]
Plane = Literal["G17", "G18", "G19"]
#: Group 10 of the SINUMERIK dialect. NGC maps G61.1 -> "G60" (exact stop),
#: G61 -> "G61" (exact path: stop at every non-tangential corner), G64 -> "G64".
ContinuousMode = Literal["G60", "G61", "G64", "G641", "G642", "G643", "G644", "G645"]
ExactStopCriterion = Literal["G601", "G602", "G603"]
AccelMode = Literal["BRISK", "SOFT", "DRIVE"]
ToolCompensation = Literal["G40", "G41", "G42"]
TrcCorner = Literal["G450", "G451"]


@dataclass(frozen=True, slots=True)
class ProgramWarning:
    """Something the parser kept but could not model (a cycle, a system variable, ...).

    Attributes
    ----------
    file : str
        Program file name as given by the user.
    line : int
        1-based source line.
    message : str
        What was kept and why it does not affect the motion model.
    """

    file: str
    line: int
    message: str

    def __str__(self) -> str:
        return f"{self.file}:{self.line}: warning: {self.message}"


@dataclass(frozen=True, slots=True)
class Tangential:
    """Tangential control of a following rotary axis (TANG/TANGON/TLIFT), SINUMERIK only.

    Attributes
    ----------
    axis : str
        Following axis name (e.g. ``"C"``).
    leading : tuple[str, str]
        The two leading geometry axes whose tangent the axis follows.
    coupling : float
        Angle ratio (TANG parameter 4; 1.0 by default).
    offset_deg : float
        TANGON offset angle, degrees.
    tlift : bool
        TLIFT active: stop and turn the axis alone at corners above MD37400.
    """

    axis: str
    leading: tuple[str, str]
    coupling: float = 1.0
    offset_deg: float = 0.0
    tlift: bool = False


_MODAL_FIELDS = ("plane", "continuous_mode", "exact_stop_criterion", "adis_mm", "adispos_mm",
                 "contour_tol_mm", "orientation_tol_deg", "axis_tol", "naive_cam_tol_mm",
                 "accel_mode", "tool_compensation", "trc_corner", "disc", "tool",
                 "tool_offset", "tangential", "rndm_mm", "trc_tool", "tool_radius_mm")
_EXTRA_FIELDS = ("center", "turns", "dwell_s", "aux", "message", "comment",
                 "kept_unmodelled", "column_of_motion", "plane_basis", "rnd_mm")


@dataclass(frozen=True, slots=True)
class Modal:
    """Modal state in force for a block. One object is shared by consecutive blocks
    while nothing modal changes (which also keeps 10^5-block programs cheap).

    Attributes
    ----------
    plane : {"G17", "G18", "G19"}
        Active working plane (G17 = XY, G18 = ZX, G19 = YZ).
    continuous_mode : str
        Active group-10 mode (see :data:`ContinuousMode`).
    exact_stop_criterion : {"G601", "G602", "G603"}
        Block-change criterion for exact stop.
    adis_mm, adispos_mm : float
        Rounding distances for G641 (ADIS for G1/G2/G3, ADISPOS for G0), mm; 0 if unset.
    contour_tol_mm : float or None
        CTOL (SINUMERIK) or ``G64 P`` (NGC), mm; ``None`` = machine data applies.
    orientation_tol_deg : float or None
        OTOL, degrees; ``None`` = machine data applies.
    axis_tol : tuple[tuple[str, float], ...]
        ATOL[axis] values as (axis, tolerance) pairs (mm or degrees).
    naive_cam_tol_mm : float or None
        NGC ``G64 Q`` (collinear-segment merge tolerance), mm.
    accel_mode : {"BRISK", "SOFT", "DRIVE"} or None
        Programmed group-21 mode, ``None`` = the machine's default.
    tool_compensation : {"G40", "G41", "G42"}
        Active tool radius compensation.
    trc_corner : {"G450", "G451"}
        TRC corner behaviour.
    disc : float
        DISC value (0..100) for G450 corners.
    tool : int or str or None
        Active tool: number (T1) or name (``T="DRILL 8.5"``, tool management); ``None``
        if never set.
    tool_offset : int or None
        Active tool offset (D on SINUMERIK, H/D on NGC).
    tangential : Tangential or None
        Active tangential control, ``None`` if off.
    rndm_mm : float
        Modal rounding radius RNDM, mm (0 = off): every corner between lines gets a
        tangent arc of this radius.
    trc_tool : tuple[int or str or None, int] or None
        ``(tool, cutting edge)`` whose radius tool radius compensation uses. SINUMERIK:
        the active T and D (a T without D selects edge D1, MD20270
        CUTTING_EDGE_DEFAULT = 1; D0 is edge 0, no offset); NGC: the D word of the
        G41/G42 block, else the last T word, edge 1. ``None`` before any T or D.
    tool_radius_mm : float or None
        Radius of that edge as the program itself defines it, mm: SINUMERIK
        ``$TC_DP6[t,d]``, NGC ``G10 L1 P<t> R<r>`` or ``G41.1/G42.1 D<diameter>`` (half
        the diameter); ``None`` when the program defines none (the machine's tool
        table then applies, :class:`reference.machine.ToolTable`).
    """

    plane: Plane = "G17"
    continuous_mode: ContinuousMode = "G64"
    exact_stop_criterion: ExactStopCriterion = "G601"
    adis_mm: float = 0.0
    adispos_mm: float = 0.0
    contour_tol_mm: float | None = None
    orientation_tol_deg: float | None = None
    axis_tol: tuple[tuple[str, float], ...] = ()
    naive_cam_tol_mm: float | None = None
    accel_mode: AccelMode | None = None
    tool_compensation: ToolCompensation = "G40"
    trc_corner: TrcCorner = "G450"
    disc: float = 0.0
    tool: int | str | None = None
    tool_offset: int | None = None
    tangential: Tangential | None = None
    rndm_mm: float = 0.0
    trc_tool: tuple[int | str | None, int] | None = None
    tool_radius_mm: float | None = None


@dataclass(frozen=True, slots=True)
class BlockExtra:
    """Per-block data most blocks do not have (shared empty instance otherwise).

    Attributes
    ----------
    center : tuple[float, ...] or None
        Arc centre, absolute, shape ``(n_axes,)`` (only the two plane components are
        meaningful); ``None`` for lines.
    turns : int
        Additional full turns of an arc (SINUMERIK ``TURN=``, NGC ``P`` minus 1), >= 0.
    dwell_s : float or None
        Dwell time of a G4 block in seconds, else ``None``.
    aux : tuple[tuple[str, float or str], ...]
        M, S, T, D, H words of this block in source order, e.g. ``(("M", 3.0),)``; a
        tool by name keeps its name (``("T", "DRILL 8.5")``).
    message : str or None
        ``MSG("...")`` or ``(MSG, ...)`` text of this block.
    comment : str
        Comment text of the line (both comment styles), ``""`` if none.
    kept_unmodelled : tuple[str, ...]
        Words/cycles kept but not modelled (e.g. ``"CYCLE800(...)"``); each also raised
        a :class:`ProgramWarning`.
    column_of_motion : int
        1-based column of the motion word (for error messages); 1 if none.
    plane_basis : tuple of two 3-tuples or None
        Unit vectors (in X, Y, Z) of the arc plane from its first to its second axis,
        when a rotated frame tilts the plane out of G17/G18/G19; ``None`` otherwise.
    rnd_mm : float
        Non-modal rounding radius RND of the corner at this block's end, mm (0 = none).
    """

    center: tuple[float, ...] | None = None
    turns: int = 0
    dwell_s: float | None = None
    aux: tuple[tuple[str, float | str], ...] = ()
    message: str | None = None
    comment: str = ""
    kept_unmodelled: tuple[str, ...] = ()
    column_of_motion: int = 1
    plane_basis: tuple[tuple[float, float, float], tuple[float, float, float]] | None = None
    rnd_mm: float = 0.0


NO_EXTRA = BlockExtra()
DEFAULT_MODAL = Modal()


def _delegate(holder: str, name: str):
    def get(self):
        return getattr(getattr(self, holder), name)
    get.__doc__ = f"Same as ``{holder}.{name}``."
    return property(get)


@dataclass(frozen=True, slots=True)
class Block:
    """One executable NC block after modal resolution.

    Every source line that holds anything other than whitespace, comments or control
    flow becomes one block, also when it does not move (dwell, M words, assignments,
    messages); blocks skipped by control flow are not emitted, and a line executed
    several times by a loop yields several blocks (same ``line``, increasing ``index``).
    The modal state and the rarer per-block data live in :class:`Modal` and
    :class:`BlockExtra`; their fields are also readable directly on the block
    (``block.continuous_mode``, ``block.dwell_s``, ...).

    Attributes
    ----------
    index : int
        Position in :attr:`Program.blocks`, 0-based.
    line : int
        1-based source line number.
    source : str
        The source line as written (without the line ending).
    label : str
        Block number or label as written (``"N10"``, ``"LOOP1"``), ``""`` if none.
    motion : {"G0", "G1", "G2", "G3"} or None
        Active motion of this block if it programs an axis move, else ``None``.
    start, end : tuple[float, ...]
        Absolute machine positions before and after the block, shape ``(n_axes,)``,
        mm for linear axes, degrees for rotary axes. Equal for non-motion blocks.
    feed_mm_s : float or None
        Active programmed path feed F converted to mm/s, ``None`` if none programmed yet
        (legal only for G0 and non-motion blocks).
    exact_stop_here : bool
        True when the block ends in exact stop (G60 active, or non-modal G9).
    modal : Modal
        Modal state in force.
    extra : BlockExtra
        Arc centre, dwell, aux words, message, comment, ...
    """

    index: int
    line: int
    source: str
    label: str
    motion: Motion | None
    start: tuple[float, ...]
    end: tuple[float, ...]
    feed_mm_s: float | None = None
    exact_stop_here: bool = False
    modal: Modal = DEFAULT_MODAL
    extra: BlockExtra = NO_EXTRA

    for _n in _MODAL_FIELDS:
        locals()[_n] = _delegate("modal", _n)
    for _n in _EXTRA_FIELDS:
        locals()[_n] = _delegate("extra", _n)
    del _n

    @classmethod
    def make(cls, **kw) -> "Block":
        """Build a block from flat keywords (modal and extra fields included)."""
        modal = {k: kw.pop(k) for k in _MODAL_FIELDS if k in kw}
        extra = {k: kw.pop(k) for k in _EXTRA_FIELDS if k in kw}
        return cls(modal=Modal(**modal) if modal else DEFAULT_MODAL,
                   extra=BlockExtra(**extra) if extra else NO_EXTRA, **kw)

    @property
    def is_arc(self) -> bool:
        """True for G2/G3 blocks."""
        return self.motion in ("G2", "G3")

    @property
    def moves(self) -> bool:
        """True when any axis position changes (or an arc does full turns)."""
        return self.motion is not None and (self.start != self.end or self.is_arc)


@dataclass(frozen=True, slots=True)
class Program:
    """A parsed NC program.

    Attributes
    ----------
    file : str
        File name as given by the user (used in every message).
    dialect : {"sinumerik", "ngc"}
        Dialect the text was parsed in.
    axes : tuple[str, ...]
        Channel axes in position order: always ``("X", "Y", "Z")`` first, then every
        other axis the program uses, in order of first appearance (``"A"``, ``"C"``, ...).
    rotary : tuple[bool, ...]
        Per axis: True for rotary axes (A, B, C), whose positions are degrees.
    blocks : tuple[Block, ...]
        Executed blocks in execution order.
    warnings : tuple[ProgramWarning, ...]
        Everything kept without being modelled, each naming its line.
    source_units : {"mm", "inch"}
        Units the program started in (G71/G21 vs G70/G20); all stored values are mm.
    lines : tuple[str, ...]
        The full source text split into lines (for reports that show the program).
    """

    file: str
    dialect: Dialect
    axes: tuple[str, ...]
    rotary: tuple[bool, ...]
    blocks: tuple[Block, ...]
    warnings: tuple[ProgramWarning, ...] = ()
    source_units: Literal["mm", "inch"] = "mm"
    lines: tuple[str, ...] = field(default=(), repr=False)
