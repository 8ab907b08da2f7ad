"""Interpreter state: the modal state of both dialects, the tables of G codes and
modal groups, and the messages (errors and warnings naming the line).

:class:`_Interp` is the only mutable object of the NC reader: :func:`reference.nc.interp.run`
makes one per call and drops it afterwards (no state survives a call). Positions are
machine coordinates, mm / degrees.
"""

from __future__ import annotations

from ..core.errors import NCSyntaxError
from ..core.units import MM_PER_INCH
from .expr import ExprError, constant, evaluate
from .frames import _Frame
from .lines import Stmt
from .program import DEFAULT_MODAL, ProgramWarning, Tangential

#: Largest position magnitude accepted, mm (degrees for rotary axes), also for arc
#: centres. No machine tool travels a kilometre (large gantries: tens of metres), and
#: below it float64 resolves a position to 1e6 * 2.2e-16 = 2e-10 mm, four decades under
#: POS_TOL_MM (1e-6 mm) that every geometric test relies on. A position beyond it is a
#: typing error (X123456789012345678901234567890) and would otherwise overflow into inf
#: or lose all precision downstream.
MAX_COORDINATE_MM = 1e6
#: Largest programmed feed, mm/min. CAM writes "as fast as possible" as F99999 or so,
#: and a feed above the axis limits is simply capped by them, so the bound is generous:
#: 1e9 mm/min (1000 km/min) is five decades above the fastest axes (MAX_AX_VELO <= 1e7
#: by the machine-data rules) and keeps v^2 far from float overflow (a feed of 1e300
#: overflowed in the planners).
MAX_FEED_MM_MIN = 1e9
#: Longest dwell, s: 1e6 s (11.6 days) is no machining dwell, and keeps the program's
#: times at magnitudes where float64 still resolves a microsecond.
MAX_DWELL_S = 1e6

#: M codes that end the program (M17 only on SINUMERIK, M99 only on NGC: checked there).
_END_M = frozenset({2.0, 30.0, 17.0, 99.0})
GEOMETRY = ("X", "Y", "Z")
ROTARY = frozenset("ABC")
_PLANE_AXES = {"G17": ("X", "Y", "Z"), "G18": ("Z", "X", "Y"), "G19": ("Y", "Z", "X")}
_CENTER_WORD = {"X": "I", "Y": "J", "Z": "K"}
_MODES10_SIN = {60: "G60", 64: "G64", 641: "G641", 642: "G642", 643: "G643", 644: "G644",
                645: "G645"}
# G codes accepted without effect on the motion model (kept with a warning naming the line)
_IGNORED_G_SIN = {25, 26, 96, 97, 94, 110, 111, 112, 147, 148, 247, 248, 347,
                  348, 340, 341, 55, 56, 57, 54, 505, 506, 507, 508, 509, 510}
_IGNORED_G_NGC = {43, 49, 80, 94, 17.1, 18.1, 19.1, 40.0, 49.0, 98, 99, 7, 8, 43.1, 50, 51,
                  64.0}
_IGNORED_WHY = {
    43: "the tool length offset is taken as zero", 43.1: "the tool length offset is taken "
    "as zero", 49: "tool length offsets are not modelled (taken as zero)",
    80: "canned cycles are not modelled", 94: "feed per minute is the only feed mode "
    "modelled (already active)", 98: "canned cycles are not modelled", 99: "canned cycles "
    "are not modelled", 7: "lathe diameter mode is not modelled", 8: "lathe radius mode is "
    "not modelled", 17.1: "UVW planes are not modelled", 18.1: "UVW planes are not "
    "modelled", 19.1: "UVW planes are not modelled", 96: "constant cutting speed is not modelled",
    97: "constant cutting speed is not modelled"}
#: NGC work coordinate systems G54..G59.3 -> number (G10 L2 P1..P9).
_NGC_CS = {54: 1, 55: 2, 56: 3, 57: 4, 58: 5, 59: 6, 59.1: 7, 59.2: 8, 59.3: 9}
#: Modal groups whose members exclude each other within one block.
_G_GROUPS_SIN = ({0, 1, 2, 3}, {17, 18, 19}, {90, 91}, {70, 71, 700, 710},
                 {60, 64, 641, 642, 643, 644, 645}, {601, 602, 603}, {40, 41, 42},
                 {450, 451}, {93, 94, 95}, {53, 153, 500, 54, 55, 56, 57})
_G_GROUPS_NGC = ({0, 1, 2, 3, 33, 38.2, 73, 76, 80, 81, 82, 83, 84, 85, 86, 87, 88, 89},
                 {17, 18, 19, 17.1, 18.1, 19.1}, {90, 91}, {90.1, 91.1}, {20, 21},
                 {61, 61.1, 64}, {40, 41, 42, 41.1, 42.1}, {93, 94, 95}, {43, 43.1, 49},
                 {54, 55, 56, 57, 58, 59, 59.1, 59.2, 59.3})
_UNSUPPORTED_G = {93: "inverse-time feed (G93) is not supported",
                  95: "feed per revolution (G95) is not supported",
                  33: "thread cutting (G33) is not supported",
                  76: "threading cycle (G76) is not supported",
                  5: "cubic spline G5 is not supported", 5.1: "quadratic spline G5.1 is not "
                  "supported", 5.2: "NURBS G5.2 is not supported", 2.1: "G2.1 is not supported"}


class _Interp:
    """Mutable execution state, private to :func:`run` (no state survives a call)."""

    def __init__(self, file: str, dialect: str, stmts: list[Stmt], lines: tuple[str, ...]):
        self.file, self.dialect, self.stmts, self.lines = file, dialect, stmts, lines
        self.ngc = dialect == "ngc"
        self.vars: dict[str, float] = {}
        self.declared: set[str] = set()
        self.axes: list[str] = list(GEOMETRY)
        self.pos: dict[str, float] = {a: 0.0 for a in GEOMETRY}      # machine position
        self.frame = _Frame()
        self.motion: str | None = None
        self.plane = "G17"
        self.absolute = True
        self.ijk_absolute = False
        self.inch = False            # lengths in inch (G70/G700, G20)
        self.feed_inch = False       # feeds in inch/min (G700, G20)
        self.start_units = "mm"
        self.feed: float | None = None
        self.mode10 = "G64"
        self.criterion = "G601"
        self.adis = 0.0
        self.adispos = 0.0
        self.ctol: float | None = None
        self.rndm = 0.0              # RNDM, mm (0 = off)
        self.otol: float | None = None
        self.atol: dict[str, float] = {}
        self.naive_cam: float | None = None
        self.accel_mode: str | None = None
        self.trc = "G40"
        self.trc_corner = "G450"
        self.disc = 0.0
        self.tool: int | None = None
        self.offset_no: int | None = None
        self.edge = 1                # cutting edge for TRC (D; D1 after a T without D)
        self.tool_data: dict[tuple, float] = {}  # (tool, edge) -> radius, mm ($TC_DP6, G10 L1)
        self.ngc_comp_tool: int | None = None     # NGC: D word of the G41/G42 block
        self.ngc_comp_radius: float | None = None  # NGC: G41.1/G42.1 D<diameter> / 2, mm
        self.spindle_rpm = 0.0       # last S word (for G4 S)
        self.cs: dict[int, _Frame] = {}   # NGC G10 L2 work offsets, by number (G54 = 1)
        self.cs_active = 1
        self.g92: dict[str, float] = {}  # NGC G92 offsets, program units converted to mm
        self.tang_defs: dict[str, Tangential] = {}
        self.tang_active: str | None = None
        self.fa: dict[str, float] = {}   # FA[axis]: positioning-axis feed, mm/s or deg/s
        self.out: list = []
        self.warnings: list[ProgramWarning] = []
        self.warned: set[str] = set()
        self.last_modal_values: tuple | None = None
        self.modal = DEFAULT_MODAL   # Modal object of the current modal state
        self.last_end: tuple | None = None   # end of the last emitted block
        self.loop_line = 0           # head line of the loop that last jumped back
        self.jump_line = 0           # line of that backward jump

    # ----------------------------------------------------------------- messages
    def err(self, st: Stmt, col: int, msg: str) -> NCSyntaxError:
        return NCSyntaxError(self.file, st.line, max(col, 1), msg)

    def warn(self, st: Stmt, msg: str, once_key: str | None = None) -> None:
        """Record a warning naming the line: once per line and message (a loop does not
        repeat it), or once per program for an explicit ``once_key``."""
        if once_key is None:
            once_key = f"{st.line}:{msg}"
        if once_key is not None:
            if once_key in self.warned:
                return
            self.warned.add(once_key)
        self.warnings.append(ProgramWarning(self.file, st.line, msg))

    def ev(self, st: Stmt, node, col: int = 1) -> float:
        c = constant(node)
        if c is not None:
            return c
        try:
            return evaluate(node, self.vars)
        except ExprError as exc:
            # the expression knows where it failed (an offset into the line's code)
            where = col
            if exc.col > 0:
                where = (st.colmap[min(exc.col, len(st.colmap) - 1)] + 1 if st.colmap
                         else exc.col + 1)
            raise self.err(st, where, str(exc)) from None

    # ----------------------------------------------------------------- helpers
    def lin(self, axis: str) -> float:
        return MM_PER_INCH if (self.inch and axis not in ROTARY) else 1.0

    def is_axis_name(self, name: str) -> bool:
        if name in GEOMETRY or name in self.axes:
            return True
        if self.ngc:
            return name in ("A", "B", "C", "U", "V", "W")
        return (name not in self.declared and "_" not in name and name.isalnum()
                and name[0].isalpha() and len(name) <= 4 and not name.startswith("R")
                and name not in ("I", "J", "K", "F", "S", "T", "D", "H", "M", "G", "N", "P"))

    def program_pos(self) -> dict:
        if self.frame.identity:
            return dict(self.pos)
        return self.frame.to_program(self.pos)

    def add_axis(self, name: str) -> None:
        if name not in self.pos:
            self.axes.append(name)
            self.pos[name] = 0.0
