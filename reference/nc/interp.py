"""Stage 2 of parsing: execute parsed lines -> resolved :class:`~reference.nc.program.Block`.

The interpreter keeps the modal state of both dialects (motion, plane, units,
absolute/incremental, feed, group 10, exact-stop criterion, TRC, tangential control),
evaluates variables and control flow whose conditions depend only on program
variables, applies frames (SINUMERIK TRANS/ATRANS/ROT/AROT about Z, NGC ``G10 L2/L20``
work offsets with ``R`` rotation, G54..G59.3, G92), and emits one block per executed line
with absolute machine positions in mm / degrees.

Rules worth knowing:

* Declarations and control flow (``DEF``, ``IF``/``ELSE``/``ENDIF``, loops, ``GOTO``,
  ``CASE``, NGC O-words) make no block; every other executed line makes one, a line run
  by a loop once per pass. More than :data:`MAX_EXECUTED_BLOCKS` executed lines is an
  error naming the loop that jumped back last.
* A frame change keeps the machine position; the axes a later block does not program
  stay where they are in machine coordinates.
* Anything that needs a real control (system variables, cycles, subprograms that are not
  in the file, unknown work offsets) is kept as a block without motion and warned about,
  once per line, or rejected when a condition or a position depends on it.
* Plain ``G0/G1/G2/G3`` lines without a frame take a fast lane (:func:`_fast_block`)
  that produces exactly the blocks of the full treatment (:func:`_block`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..core.errors import NCSyntaxError
from ..core.tolerances import ARC_RADIUS_REL_TOL, ARC_RADIUS_TOL_MM, POS_TOL_MM
from ..core.units import MM_PER_INCH
from .expr import Cursor, ExprError, constant, evaluate, parse_expr
from .lines import Stmt, Word
from .program import (DEFAULT_MODAL, NO_EXTRA, Block, BlockExtra, Modal, Program,
                      ProgramWarning, Tangential)

MAX_EXECUTED_BLOCKS = 1_000_000
#: M codes that end the program (M17 only on SINUMERIK, M99 only on NGC: checked there).
_END_M = frozenset({2.0, 30.0, 17.0, 99.0})
#: Loop openers whose closer jumps to the first statement of the body (not to the opener).
_BODY_OPENERS = frozenset({"LOOP", "REPEAT", "O:REPEAT"})
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


@dataclass(slots=True)
class _Frame:
    """Programmable frame: machine = R(theta) * program + offset (theta about Z)."""

    theta_deg: float = 0.0
    offset: dict | None = None

    def to_machine(self, p: dict) -> dict:
        out = dict(p)
        if self.theta_deg:
            c, s = math.cos(math.radians(self.theta_deg)), math.sin(math.radians(self.theta_deg))
            x, y = p.get("X", 0.0), p.get("Y", 0.0)
            out["X"], out["Y"] = c * x - s * y, s * x + c * y
        if self.offset:
            for k, v in self.offset.items():
                out[k] = out.get(k, 0.0) + v
        return out

    def to_program(self, m: dict) -> dict:
        out = dict(m)
        if self.offset:
            for k, v in self.offset.items():
                out[k] = out.get(k, 0.0) - v
        if self.theta_deg:
            c, s = math.cos(math.radians(self.theta_deg)), math.sin(math.radians(self.theta_deg))
            x, y = out.get("X", 0.0), out.get("Y", 0.0)
            out["X"], out["Y"] = c * x + s * y, -s * x + c * y
        return out

    def rotate_vec(self, v: tuple[float, float, float]) -> tuple[float, float, float]:
        if not self.theta_deg:
            return v
        c, s = math.cos(math.radians(self.theta_deg)), math.sin(math.radians(self.theta_deg))
        return (c * v[0] - s * v[1], s * v[0] + c * v[1], v[2])


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
        self.otol: float | None = None
        self.atol: dict[str, float] = {}
        self.naive_cam: float | None = None
        self.accel_mode: str | None = None
        self.trc = "G40"
        self.trc_corner = "G450"
        self.disc = 0.0
        self.tool: int | None = None
        self.offset_no: int | None = None
        self.spindle_rpm = 0.0       # last S word (for G4 S)
        self.cs: dict[int, _Frame] = {}   # NGC G10 L2 work offsets, by number (G54 = 1)
        self.cs_active = 1
        self.g92: dict[str, float] = {}  # NGC G92 offsets, program units converted to mm
        self.tang_defs: dict[str, Tangential] = {}
        self.tang_active: str | None = None
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
        if self.frame.theta_deg == 0.0 and not self.frame.offset:
            return dict(self.pos)
        return self.frame.to_program(self.pos)

    def add_axis(self, name: str) -> None:
        if name not in self.pos:
            self.axes.append(name)
            self.pos[name] = 0.0


def run(file: str, dialect: str, stmts: list[Stmt], lines: tuple[str, ...]) -> Program:
    """Execute parsed statements and build the :class:`Program`.

    Raises
    ------
    NCSyntaxError
        Any error in the program, naming file, line and column.
    """
    ip = _Interp(file, dialect, stmts, lines)
    _execute(ip)
    n = len(ip.axes)
    blocks = ip.out
    for i, b in enumerate(blocks):
        if len(b.end) < n:                      # emitted before a later axis appeared
            pad = (0.0,) * (n - len(b.end))
            extra = b.extra
            if extra.center is not None and len(extra.center) < n:
                extra = BlockExtra(**{**{f: getattr(extra, f) for f in extra.__slots__},
                                      "center": extra.center + (0.0,) * (n - len(extra.center))})
            start = b.start + (0.0,) * (n - len(b.start))
            blocks[i] = Block(b.index, b.line, b.source, b.label, b.motion, start, b.end + pad,
                              b.feed_mm_s, b.exact_stop_here, b.modal, extra)
    return Program(file=file, dialect=dialect, axes=tuple(ip.axes),
                   rotary=tuple(a in ROTARY for a in ip.axes), blocks=tuple(blocks),
                   warnings=tuple(ip.warnings), source_units=ip.start_units, lines=lines)


# ====================================================================== control flow
def _match_blocks(ip: _Interp) -> dict[int, int]:
    """Pair IF/ELSE/ENDIF, WHILE/ENDWHILE, ... (statement index -> partner index)."""
    pairs: dict[int, int] = {}
    stack: list[tuple[str, int]] = []
    openers = {"IF": "ENDIF", "WHILE": "ENDWHILE", "FOR": "ENDFOR", "REPEAT": "UNTIL",
               "LOOP": "ENDLOOP"}
    closers = {v: k for k, v in openers.items()}
    o_stack: list[tuple[str, str, int]] = []
    for i, st in enumerate(ip.stmts):
        k = st.kind
        if k in openers:
            stack.append((k, i))
        elif k == "ELSE":
            if not stack or stack[-1][0] != "IF":
                raise ip.err(st, 1, "ELSE without IF")
            pairs[stack[-1][1]] = i          # IF -> ELSE; ELSE -> ENDIF set below
            stack.append(("ELSE", i))
        elif k in closers:
            want = closers[k]
            if k == "ENDIF" and stack and stack[-1][0] == "ELSE":
                _, e = stack.pop()
                pairs[e] = i
                _, f = stack.pop()
                pairs.setdefault(f, e)
                pairs[i] = f
                continue
            if not stack or stack[-1][0] != want:
                raise ip.err(st, 1, f"{k} without {want}")
            _, f = stack.pop()
            pairs.setdefault(f, i)
            pairs[i] = f
        elif k.startswith("O:"):
            kw = k[2:]
            if kw == "WHILE" and o_stack and o_stack[-1][0] == "DO" and (
                    o_stack[-1][1] == st.target):             # closes "oN do"
                _, _, f = o_stack.pop()
                pairs[f] = i
                pairs[("end", f)] = i  # type: ignore
                pairs[i] = f
            elif kw in ("IF", "WHILE", "DO", "REPEAT", "SUB"):
                o_stack.append((kw, st.target, i))
            elif kw in ("ELSEIF", "ELSE"):
                if not o_stack or o_stack[-1][1] != st.target:
                    raise ip.err(st, 1, f"o{st.target} {kw.lower()} without a matching if")
                pairs.setdefault(o_stack[-1][2], i)
                pairs.setdefault(("chain", o_stack[-1][2]), []).append(i)  # type: ignore
            elif kw in ("ENDIF", "ENDWHILE", "ENDREPEAT", "ENDSUB"):
                if not o_stack or o_stack[-1][1] != st.target:
                    raise ip.err(st, 1, f"o{st.target} {kw.lower()} has no matching opener")
                _, _, f = o_stack.pop()
                pairs.setdefault(f, i)
                pairs[("end", f)] = i  # type: ignore
                pairs[i] = f
    if stack:
        k, i = stack[-1]
        raise ip.err(ip.stmts[i], 1, f"{k} is never closed (missing {openers.get(k, 'ENDIF')})")
    if o_stack:
        kw, name, i = o_stack[-1]
        raise ip.err(ip.stmts[i], 1, f"o{name} {kw.lower()} is never closed")
    return pairs


def _labels(ip: _Interp) -> dict[str, list[int]]:
    out: dict[str, list[int]] = {}
    for i, st in enumerate(ip.stmts):
        if st.label:
            out.setdefault(st.label, []).append(i)
    return out


class _LazyLabels:
    """Label -> statement indices, built at the first jump (most programs never jump)."""

    __slots__ = ("ip", "table")

    def __init__(self, ip: _Interp) -> None:
        self.ip = ip
        self.table: dict[str, list[int]] | None = None

    def get(self, key: str, default: list[int]) -> list[int]:
        if self.table is None:
            self.table = _labels(self.ip)
        return self.table.get(key, default)


def _jump(ip: _Interp, st: Stmt, i: int, kind: str, target: str,
          labels: dict[str, list[int]]) -> int | None:
    cands = labels.get(target, [])
    fwd = [j for j in cands if j > i]
    back = [j for j in cands if j < i]
    if kind == "GOTOF":
        j = fwd[0] if fwd else None
    elif kind == "GOTOB":
        j = back[-1] if back else None
    else:                                   # GOTO, GOTOC: forward first, then backward
        j = fwd[0] if fwd else (back[-1] if back else None)
    if j is None and kind != "GOTOC":
        where = {"GOTOF": "after", "GOTOB": "before"}.get(kind, "in")
        raise ip.err(st, 1, f"{kind} {target}: no label {target} {where} this line")
    return j


def _execute(ip: _Interp) -> None:
    stmts = ip.stmts
    pairs = _match_blocks(ip)
    labels = _LazyLabels(ip)
    subs = {st.target: i for i, st in enumerate(stmts) if st.kind == "O:SUB"}
    calls: list[tuple[int, dict]] = []
    loops_for: dict[int, float] = {}
    executed = 0
    i = 0
    prev = -1
    n = len(stmts)
    while i < n:
        st = stmts[i]
        k = st.kind
        executed += 1
        if i <= prev:                       # a jump back: remember the loop for the guard
            head = stmts[i - 1] if i > 0 and stmts[i - 1].kind in _BODY_OPENERS else st
            ip.loop_line = head.line
            ip.jump_line = stmts[prev].line
        prev = i
        if executed > MAX_EXECUTED_BLOCKS:
            line = ip.loop_line or st.line
            raise NCSyntaxError(ip.file, line, 1, f"loop does not terminate within "
                                f"{MAX_EXECUTED_BLOCKS} blocks (the program does not end "
                                f"within {MAX_EXECUTED_BLOCKS} executed lines; it jumps back "
                                f"here from line {ip.jump_line or st.line})")
        if k == "block":
            fast = st.fast
            if fast is not None and _fast_block(ip, st, fast):
                i += 1
                continue
            if not st.empty:
                if _block(ip, st):
                    return
            i += 1
            continue
        if k == "IF":
            if ip.ev(st, st.cond):
                i += 1
            else:
                j = pairs[i]
                i = j + 1
            continue
        if k == "ELSE":
            i = pairs[i] + 1                # reached from the true branch: skip to ENDIF
            continue
        if k in ("ENDIF", "ENDLOOP") and k == "ENDIF":
            i += 1
            continue
        if k == "WHILE":
            i = i + 1 if ip.ev(st, st.cond) else pairs[i] + 1
            continue
        if k == "ENDWHILE":
            i = pairs[i]
            continue
        if k == "LOOP":
            i += 1
            continue
        if k == "ENDLOOP":
            i = pairs[i] + 1
            continue
        if k == "REPEAT":
            i += 1
            continue
        if k == "UNTIL":
            i = i + 1 if ip.ev(st, st.cond) else pairs[i] + 1
            continue
        if k == "FOR":
            var = st.target
            if i not in loops_for:
                ip.vars[var] = ip.ev(st, st.assigns[0][1])
                ip.declared.add(var)
            loops_for[i] = 1.0
            if ip.vars[var] <= ip.ev(st, st.cond):
                i += 1
            else:
                del loops_for[i]
                i = pairs[i] + 1
            continue
        if k == "ENDFOR":
            f = pairs[i]
            ip.vars[stmts[f].target] += 1.0
            i = f
            continue
        if k == "GOTOS":
            i = 0
            continue
        if k in ("GOTOF", "GOTOB", "GOTO", "GOTOC"):
            j = _jump(ip, st, i, k, st.target, labels)
            i = i + 1 if j is None else j
            continue
        if k == "IFGOTO":
            if ip.ev(st, st.cond):
                j = _jump(ip, st, i, st.case[0][1], st.target, labels)
                i = i + 1 if j is None else j
            else:
                i += 1
            continue
        if k == "CASE":
            val = ip.ev(st, st.cond)
            dest = None
            for cv, lab, kw in st.case:
                if cv is None or ip.ev(st, cv) == val:
                    dest = _jump(ip, st, i, kw, lab, labels)
                    break
            i = i + 1 if dest is None else dest
            continue
        if k == "DEF":
            for name, _typ in st.decl:
                ip.declared.add(name)
                ip.vars.setdefault(name, 0.0)
            for name, node, col in st.assigns:
                ip.vars[name] = ip.ev(st, node, col + 1)
            i += 1
            continue
        if k in ("PROC", "DEFINE", "EXTERN"):
            i += 1
            continue
        if k.startswith("O:"):
            i = _oword(ip, st, i, pairs, subs, calls)
            if i < 0:
                return
            continue
        i += 1


def _oword(ip: _Interp, st: Stmt, i: int, pairs: dict, subs: dict, calls: list) -> int:
    kw = st.kind[2:]
    if kw == "SUB":
        return pairs[("end", i)] + 1          # skip the definition
    if kw in ("ENDSUB", "RETURN"):
        if not calls:
            if kw == "RETURN":
                raise ip.err(st, 1, f"o{st.target} return outside a subroutine call")
            return i + 1
        ret, saved = calls.pop()
        for p in range(1, 31):
            ip.vars.pop(f"#{p}", None)
        ip.vars.update(saved)
        return ret
    if kw == "CALL":
        if st.target not in subs:
            raise ip.err(st, 1, f"o{st.target} call: no subroutine o{st.target} in this file")
        saved = {f"#{p}": ip.vars[f"#{p}"] for p in range(1, 31) if f"#{p}" in ip.vars}
        args = [ip.ev(st, a) for a in st.case]
        for p in range(1, 31):
            ip.vars.pop(f"#{p}", None)
        for p, v in enumerate(args, start=1):
            ip.vars[f"#{p}"] = v
        calls.append((i + 1, saved))
        return subs[st.target] + 1
    if kw == "IF" or kw == "ELSEIF":
        if kw == "ELSEIF":                      # reached from a taken branch: skip to endif
            return _o_endif(ip, i, pairs) + 1
        branch = i
        while True:
            s = ip.stmts[branch]
            if s.kind in ("O:IF", "O:ELSEIF") and ip.ev(s, s.cond):
                return branch + 1
            if s.kind == "O:ELSE":
                return branch + 1
            nxt = _o_next_branch(ip, branch)
            if nxt is None:
                return _o_endif(ip, i, pairs) + 1
            branch = nxt
    if kw == "ELSE":
        return _o_endif(ip, i, pairs) + 1
    if kw in ("ENDIF", "ENDREPEAT"):
        if kw == "ENDREPEAT":
            f = pairs[i]
            ip.vars[f"__rep{f}"] -= 1
            return f + 1 if ip.vars[f"__rep{f}"] > 0 else i + 1
        return i + 1
    if kw == "WHILE":
        if ("end", i) in pairs or i in pairs and pairs[i] > i:  # while ... endwhile opener
            return i + 1 if ip.ev(st, st.cond) else pairs[("end", i)] + 1
        return pairs[i] if ip.ev(st, st.cond) else i + 1     # do ... while closer
    if kw == "ENDWHILE":
        return pairs[i]
    if kw == "DO":
        return i + 1
    if kw == "REPEAT":
        cnt = ip.ev(st, st.cond)
        ip.vars[f"__rep{i}"] = cnt
        return i + 1 if cnt > 0 else pairs[("end", i)] + 1
    if kw in ("BREAK", "CONTINUE"):
        # find the innermost enclosing loop with this name
        for f, e in ((k[1], v) for k, v in pairs.items() if isinstance(k, tuple) and k[0] == "end"):
            if ip.stmts[f].target == st.target and f < i < e:
                return e + 1 if kw == "BREAK" else f
        raise ip.err(st, 1, f"o{st.target} {kw.lower()} outside a loop")
    return i + 1


def _o_scan(ip: _Interp, i: int, stop_at_branch: bool) -> int | None:
    """From the o-if (or a branch) at ``i``: index of the next same-level elseif/else
    (when ``stop_at_branch``; None if the endif comes first) or of the matching endif."""
    name = ip.stmts[i].target
    depth = 0
    for j in range(i + 1, len(ip.stmts)):
        s = ip.stmts[j]
        if s.target != name:
            continue
        if s.kind == "O:IF":
            depth += 1
        elif s.kind == "O:ENDIF":
            if depth == 0:
                return None if stop_at_branch else j
            depth -= 1
        elif stop_at_branch and s.kind in ("O:ELSEIF", "O:ELSE") and depth == 0:
            return j
    raise ip.err(ip.stmts[i], 1, f"o{name} if is never closed")  # pragma: no cover


def _o_next_branch(ip: _Interp, i: int) -> int | None:
    return _o_scan(ip, i, True)


def _o_endif(ip: _Interp, i: int, pairs: dict) -> int:
    return _o_scan(ip, i, False)


# ====================================================================== one block
def _fast_block(ip: _Interp, st: Stmt, fast: list) -> bool:
    """Plain G0/G1/G2/G3 line of X/Y/Z/I/J/K/F/S/M words (NGC also R) with no frame
    active: the bulk of CAM output.

    Reuses the current :class:`Modal` object and the previous end tuple, and builds no
    per-word objects. Returns False (changing nothing) whenever the line needs the full
    treatment, which also produces every error message.
    """
    frame = ip.frame
    if frame.theta_deg != 0.0 or frame.offset:
        return False
    motion = ip.motion
    x = y = z = f = g = ci = cj = ck = r = spindle = None
    aux = None
    for letter, text in fast:
        if letter == "X":
            if x is not None:
                return False
            x = float(text)
        elif letter == "Y":
            if y is not None:
                return False
            y = float(text)
        elif letter == "Z":
            if z is not None:
                return False
            z = float(text)
        elif letter == "G":
            if g is not None:
                return False
            g = float(text)
            if g == 1.0:
                motion = "G1"
            elif g == 0.0:
                motion = "G0"
            elif g == 2.0:
                motion = "G2"
            elif g == 3.0:
                motion = "G3"
            else:
                return False
        elif letter == "F":
            if f is not None:
                return False
            f = float(text)
            if f < 0.0:
                return False
        elif letter == "I":
            if ci is not None:
                return False
            ci = float(text)
        elif letter == "J":
            if cj is not None:
                return False
            cj = float(text)
        elif letter == "K":
            if ck is not None:
                return False
            ck = float(text)
        elif letter == "R" and ip.ngc:
            if r is not None:
                return False
            r = float(text)
        elif letter == "M":
            m = float(text)
            if m in _END_M:                    # program end: the full path decides
                return False
            if aux is None:
                aux = []
            aux.append(("M", m))
        elif letter == "S":
            if spindle is not None:
                return False
            spindle = float(text)
            if aux is None:
                aux = []
            aux.append(("S", spindle))
        else:
            return False
    feed = ip.feed
    if f is not None:
        feed = f * (MM_PER_INCH if ip.feed_inch else 1.0) / 60.0
    arc = motion == "G2" or motion == "G3"
    if arc:
        if ci is None and cj is None and ck is None and r is None:
            return False
        if x is None and y is None and z is None and g is None:
            return False                       # no axis and no G word: not a move
    elif (x is None and y is None and z is None) or ci is not None or cj is not None or (
            ck is not None or r is not None or (motion != "G1" and motion != "G0")):
        return False
    if feed is None and motion != "G0":
        return False
    pos = ip.pos
    k = MM_PER_INCH if ip.inch else 1.0
    if arc:
        ex = pos["X"] if x is None else (x * k if ip.absolute else pos["X"] + x * k)
        ey = pos["Y"] if y is None else (y * k if ip.absolute else pos["Y"] + y * k)
        ez = pos["Z"] if z is None else (z * k if ip.absolute else pos["Z"] + z * k)
        centre = _fast_arc_centre(ip, motion == "G2", ex, ey, ez, ci, cj, ck, r, k)
        if centre is None:
            return False
    ip.feed = feed
    ip.motion = motion
    if spindle is not None and spindle > 0:
        ip.spindle_rpm = spindle
    start = ip.last_end
    if start is None:
        start = tuple([pos[a] for a in ip.axes])
    if arc:
        pos["X"], pos["Y"], pos["Z"] = ex, ey, ez
    elif ip.absolute:
        if x is not None:
            pos["X"] = x * k
        if y is not None:
            pos["Y"] = y * k
        if z is not None:
            pos["Z"] = z * k
    else:
        if x is not None:
            pos["X"] += x * k
        if y is not None:
            pos["Y"] += y * k
        if z is not None:
            pos["Z"] += z * k
    axes = ip.axes
    if len(axes) == 3:
        end = (pos["X"], pos["Y"], pos["Z"])
    else:
        end = tuple([pos[a] for a in axes])
    ip.last_end = end
    if arc or aux is not None or st.comment:
        center = None
        if arc:
            cu, cv = centre
            u, v, _ = _PLANE_AXES[ip.plane]
            c = list(start)
            c[axes.index(u)] = cu
            c[axes.index(v)] = cv
            center = tuple(c)
        up = st.text.upper()
        col = up.find("G", up.find(":") + 1) + 1 if g is not None else 1
        extra = BlockExtra(center=center, aux=() if aux is None else tuple(aux),
                           comment=st.comment, column_of_motion=col)
    else:
        extra = NO_EXTRA
    out = ip.out
    out.append(Block(len(out), st.line, st.text, st.label, motion, start, end, feed,
                     ip.mode10 == "G60", ip.modal, extra))
    return True


def _fast_arc_centre(ip: _Interp, cw: bool, ex: float, ey: float, ez: float, ci, cj, ck, r,
                     k: float) -> tuple[float, float] | None:
    """Plane coordinates of the centre of a fast-lane arc, or None to take the full path
    (which then reports what is wrong). Same rules as :func:`_arc`."""
    u, v, _ = _PLANE_AXES[ip.plane]
    pos = ip.pos
    su, sv = pos[u], pos[v]
    end = {"X": ex, "Y": ey, "Z": ez}
    eu, ev = end[u], end[v]
    if r is not None:
        if ci is not None or cj is not None or ck is not None:
            return None
        r *= k
        chord = math.hypot(eu - su, ev - sv)
        if chord <= POS_TOL_MM or abs(r) <= POS_TOL_MM or chord / 2 > abs(r) + ARC_RADIUS_TOL_MM:
            return None
        return _radius_centre(su, sv, eu, ev, r, cw)
    words = {"X": ci, "Y": cj, "Z": ck}
    wu, wv = words[u], words[v]
    if ip.ngc and ip.ijk_absolute:
        cu = 0.0 if wu is None else wu * k
        cv = 0.0 if wv is None else wv * k
    else:
        cu = su if wu is None else su + wu * k
        cv = sv if wv is None else sv + wv * k
    r0 = math.hypot(su - cu, sv - cv)
    r1 = math.hypot(eu - cu, ev - cv)
    if r0 <= POS_TOL_MM or abs(r1 - r0) > max(ARC_RADIUS_TOL_MM, ARC_RADIUS_REL_TOL * r0):
        return None
    return cu, cv


def _radius_centre(su: float, sv: float, eu: float, ev: float, r: float,
                   cw: bool) -> tuple[float, float]:
    """Centre of the arc of signed radius ``r`` (negative: more than 180 degrees) from
    (su, sv) to (eu, ev), clockwise for G2; the chord must be in reach (checked before)."""
    du, dv = eu - su, ev - sv
    chord = math.hypot(du, dv)
    half = chord / 2
    h = math.sqrt(max(r * r - half * half, 0.0))
    nu, nv = -dv / chord, du / chord             # left normal of the chord
    side = (1.0 if not cw else -1.0) * (1.0 if r > 0 else -1.0)
    return su + du / 2 + side * h * nu, sv + dv / 2 + side * h * nv


def _block(ip: _Interp, st: Stmt) -> bool:
    """Execute one ordinary line; returns True at program end (M2/M30)."""
    ngc = ip.ngc
    # --- NGC parameter assignments: all values are read before any is set, and the
    # words of the line see the old values (RS274/NGC); committed after the words
    pending: list[tuple[str, float]] = []
    for target, node, col in st.assigns:
        if ngc:
            key = target[1] if target[0] == "var" else f"#{int(ip.ev(st, target[1], col + 1))}"
            pending.append((key, ip.ev(st, node, col + 1)))
        else:                                  # pragma: no cover - SINUMERIK uses words
            ip.vars[target] = ip.ev(st, node, col + 1)
    # --- words ------------------------------------------------------------------
    g_codes: list[tuple[float, int]] = []
    axis_words: list[tuple[str, float, str, int]] = []
    centre: dict[str, tuple[float, str, int]] = {}
    aux: list[tuple[str, float]] = []
    named: dict[str, tuple[float, int]] = {}
    feed_word: tuple[float, int] | None = None
    p_word = q_word = r_word = l_word = None
    seen: dict[str, float] = {}

    def once(name: str, val: float, col: int) -> None:
        """A word may repeat in a block only with the same value."""
        prev = seen.get(name)
        if prev is not None and prev != val:
            sep = "=" if len(name) > 1 else ""
            raise ip.err(st, col, f"{name} is programmed twice in this block with different "
                                  f"values ({name}{sep}{prev:g} and {name}{sep}{val:g})")
        seen[name] = val

    for w in st.words:
        name = w.name
        if not ngc and "[" in name:                  # R[i]=, ATOL[X]=, ARRAY[i]=
            _indexed_assignment(ip, st, w)
            continue
        if not ngc and name in ip.declared:          # a DEF variable, also if one letter
            ip.vars[name] = ip.ev(st, w.value, w.col)
            continue
        if not ngc and len(name) > 1 or (not ngc and name not in "GMFSTDHIJKPQRLXYZABCUVWEN"):
            if name in ("CR", "ADIS", "ADISPOS", "TURN", "CTOL", "OTOL", "DISC", "AR", "RPL",
                        "STOLF", "RND", "RNDM", "SF", "OFFN"):
                named[name] = (ip.ev(st, w.value, w.col), w.col)
                once(name, named[name][0], w.col)
                continue
            if name.startswith("R") and name[1:].isdigit():
                ip.vars[name] = ip.ev(st, w.value, w.col)
                continue
            if name in ip.declared:
                ip.vars[name] = ip.ev(st, w.value, w.col)
                continue
            if ip.is_axis_name(name):
                ip.add_axis(name)
                axis_words.append((name, ip.ev(st, w.value, w.col), w.mode, w.col))
                once(name, axis_words[-1][1], w.col)
                continue
            # an assignment to an undeclared name: accept it as a variable, say so
            ip.declared.add(name)
            ip.vars[name] = ip.ev(st, w.value, w.col)
            ip.warn(st, f"variable {name} is assigned without DEF; taken as a REAL variable",
                    once_key=f"undeclared {name}")
            continue
        val = ip.ev(st, w.value, w.col)
        if name == "G":
            g_codes.append((val, w.col))
            continue
        if name == "M":
            aux.append(("M", val))
            continue
        if name != "N":
            once(name, val, w.col)
        if name in "XYZ" or name in "ABC" or (ngc and name in "UVW") or (
                not ngc and name in "UVWE"):
            ip.add_axis(name)
            axis_words.append((name, val, w.mode, w.col))
        elif name in "IJK":
            centre[name] = (val, w.mode, w.col)
        elif name == "F":
            feed_word = (val, w.col)
        elif name in "SH":
            aux.append((name, val))
            if name == "H":
                ip.offset_no = int(val)
        elif name == "T":
            aux.append(("T", val))
            ip.tool = int(val)
        elif name == "D":
            aux.append(("D", val))
            ip.offset_no = int(val)
        elif name == "P":
            p_word = (val, w.col)
        elif name == "Q":
            q_word = (val, w.col)
        elif name == "R":
            if not ngc:
                raise ip.err(st, w.col, "R parameter needs '=' (R1=10)")
            r_word = (val, w.col)
        elif name == "L":
            l_word = (val, w.col)
        elif name == "N":
            continue                     # block numbers were taken as labels by the lexer
        else:
            raise ip.err(st, w.col, f"unknown address {name}")
    for key, value in pending:
        ip.vars[key] = value
    # --- G codes ------------------------------------------------------------------
    g9 = False
    dwell = None
    is_dwell = False
    g10 = False
    g53 = False
    g92 = False
    program_end = False
    motion_word_col = 1
    motion_set = False
    groups = _G_GROUPS_NGC if ngc else _G_GROUPS_SIN
    in_group: dict[int, float] = {}
    for g, col in g_codes:
        gi = round(g, 1)
        for k, grp in enumerate(groups):
            if gi in grp:
                if k in in_group and in_group[k] != gi:
                    raise ip.err(st, col, f"G{in_group[k]:g} and G{gi:g} are in the same modal "
                                          "group: program only one of them in a block")
                in_group[k] = gi
    for g, col in g_codes:
        gi = round(g, 1)
        if gi in (0, 1, 2, 3):
            ip.motion = f"G{int(gi)}"
            motion_word_col = col
            motion_set = True
        elif gi in _UNSUPPORTED_G:
            raise ip.err(st, col, _UNSUPPORTED_G[gi])
        elif gi == 4:
            is_dwell = True
        elif gi == 9 and not ngc:
            g9 = True
        elif gi in (17, 18, 19):
            ip.plane = f"G{int(gi)}"
        elif gi == 90:
            ip.absolute = True
        elif gi == 91:
            ip.absolute = False
        elif ngc and gi == 90.1:
            ip.ijk_absolute = True
        elif ngc and gi == 91.1:
            ip.ijk_absolute = False
        elif (not ngc and gi in (70, 700)) or (ngc and gi == 20):
            # G70 sets lengths only; G700 and NGC G20 also feeds (inch/min)
            ip.inch = True
            ip.feed_inch = gi != 70
            if not ip.out:
                ip.start_units = "inch"
        elif (not ngc and gi in (71, 710)) or (ngc and gi == 21):
            ip.inch = False
            ip.feed_inch = False
        elif not ngc and gi in _MODES10_SIN:
            ip.mode10 = _MODES10_SIN[int(gi)]
        elif not ngc and gi in (601, 602, 603):
            ip.criterion = f"G{int(gi)}"
        elif ngc and gi == 61:
            ip.mode10 = "G61"
        elif ngc and gi == 61.1:
            ip.mode10 = "G60"
        elif ngc and gi == 64:
            ip.mode10 = "G64"
            ip.ctol = p_word[0] * ip.lin("X") if p_word else None
            ip.naive_cam = (q_word[0] * ip.lin("X") if q_word else ip.ctol)
            p_word = None
        elif gi in (40, 41, 42):
            ip.trc = f"G{int(gi)}"
        elif ngc and gi in (41.1, 42.1):         # dynamic TRC: the D word is the diameter
            ip.trc = f"G{int(gi)}"
        elif not ngc and gi in (450, 451):
            ip.trc_corner = f"G{int(gi)}"
        elif ngc and gi == 10:
            g10 = True
        elif not ngc and gi == 500:              # settable frames off: zero, as modelled
            continue
        elif ngc and gi == 53 or (not ngc and gi in (53, 153)):
            g53 = True
            ip.warn(st, f"G{gi:g}: positions in machine coordinates (frames suppressed for "
                        "this block; work and tool offsets of the control are unknown)")
        elif ngc and gi in (28, 30):
            ip.warn(st, f"G{gi:g} (home move) needs the machine's home position; kept "
                        "without motion")
            axis_words = []
        elif ngc and 81 <= gi <= 89 or (ngc and gi in (73, 74)):
            raise ip.err(st, col, f"canned cycle G{gi:g} is not supported; expand it into "
                                  "G0/G1 moves")
        elif ngc and gi in _NGC_CS:
            ip.cs_active = _NGC_CS[gi]
            if ip.cs_active not in ip.cs:
                ip.warn(st, f"work offset G{gi:g} is taken as zero (its values live in the "
                            "control; set them with G10 L2 to model them)")
            _ngc_frame(ip)
        elif ngc and gi == 92:
            g92 = True
        elif ngc and gi in (92.1, 92.2):
            ip.g92 = {}
            _ngc_frame(ip)
        elif ngc and gi == 92.3:
            ip.warn(st, "G92.3 (restore saved G92 offsets) is not modelled; the offsets stay "
                        "as they are")
        elif (ngc and gi in _IGNORED_G_NGC) or (not ngc and gi in _IGNORED_G_SIN):
            why = _IGNORED_WHY.get(gi, "work offsets are taken as zero (their values live in "
                                       "the control)")
            ip.warn(st, f"G{gi:g} is kept without effect on the motion model: {why}")
        else:
            raise ip.err(st, col, f"unknown G code G{gi:g}")
    # --- flags (SINUMERIK keywords) ------------------------------------------------
    frame_cmd = None
    for flag, col in st.flags:
        if flag in ("BRISK", "SOFT", "DRIVE"):
            ip.accel_mode = flag
        elif flag in ("TRANS", "ATRANS", "ROT", "AROT"):
            frame_cmd = flag
        elif flag == "SUPA":
            g53 = True
            ip.warn(st, "SUPA: positions in machine coordinates (frames suppressed for this "
                        "block; work and tool offsets of the control are unknown)")
        elif flag == "RET":
            program_end = True
        else:
            ip.warn(st, f"{flag} is kept but not modelled")
    # --- named addresses ------------------------------------------------------------
    if "ADIS" in named:
        ip.adis = named["ADIS"][0] * ip.lin("X")
    if "ADISPOS" in named:
        ip.adispos = named["ADISPOS"][0] * ip.lin("X")
    if "CTOL" in named:
        v = named["CTOL"][0]
        ip.ctol = None if v < 0 else v * ip.lin("X")
    if "OTOL" in named:
        v = named["OTOL"][0]
        ip.otol = None if v < 0 else v
    if "AR" in named:
        raise ip.err(st, named["AR"][1], "arcs by opening angle (AR=) are not supported; "
                                         "program the end point with I/J/K or CR=")
    for word, why in (("RND", "the rounding it inserts is not modelled; the corner stays "
                                "sharp"),
                      ("RNDM", "the rounding it inserts is not modelled; corners stay sharp"),
                      ("OFFN", "the contour offset is not applied"),
                      ("STOLF", "the G0 tolerance factor is not modelled"),
                      ("SF", "the thread start angle is not modelled")):
        if word in named:
            ip.warn(st, f"{word}={named[word][0]:g} is kept without effect: {why}")
    if "DISC" in named:
        v, col = named["DISC"]
        if not 0 <= v <= 100:
            raise ip.err(st, col, f"DISC={v:g} must be between 0 and 100")
        ip.disc = v
    # --- calls (MSG, TANG..., cycles) ------------------------------------------------
    message = st.message
    kept: list[str] = []
    for name, args, col in st.calls:
        if name == "MSG":
            a = args.strip()
            message = a.strip('"') if a else ""
            if '"' in a:
                message = a[a.find('"') + 1:a.rfind('"')]
        elif name in ("TANG", "TANGON", "TANGOF", "TLIFT", "TANGDEL"):
            _tangential(ip, st, name, args, col)
        elif name.startswith("$"):
            kept.append(args)
            ip.warn(st, f"system variable statement '{args}' needs a real control; kept "
                        "without effect")
        else:
            text = f"{name}({args})" if args else name
            kept.append(text)
            ip.warn(st, f"{text} needs a real control (cycle or subprogram); kept as a "
                        "block without motion")
    if not ngc and l_word is not None:          # L123: subprogram call by number
        text = f"L{l_word[0]:g}"
        kept.append(text)
        ip.warn(st, f"{text} calls a subprogram that is not part of this file; kept as a "
                    "block without motion")
    # --- frames ------------------------------------------------------------------------
    if frame_cmd is not None:
        _apply_frame(ip, st, frame_cmd, axis_words, named)
        axis_words = []
    if g10:
        _apply_g10(ip, st, axis_words, l_word, p_word, r_word)
        axis_words = []
        r_word = None
    if g92:
        _apply_g92(ip, st, axis_words)
        axis_words = []
    # --- feed --------------------------------------------------------------------------
    if is_dwell:
        if ngc:
            if p_word is None:
                raise ip.err(st, 1, "G4 needs P (dwell time in seconds)")
            dwell = p_word[0]
        elif feed_word is not None:
            dwell = feed_word[0]
        elif any(a[0] == "S" for a in aux):
            revs = next(a[1] for a in aux if a[0] == "S")
            aux = [a for a in aux if a[0] != "S"]     # revolutions, not a spindle speed
            if ip.spindle_rpm:
                dwell = revs * 60.0 / ip.spindle_rpm
            else:
                kept.append(f"G4 S{revs:g}")
                ip.warn(st, f"G4 S{revs:g} (dwell in spindle revolutions) needs the spindle "
                            "speed, which no S word set before; the dwell time is not modelled")
        else:
            raise ip.err(st, 1, "G4 needs F (seconds) or S (spindle revolutions)")
        if dwell is not None and dwell < 0:
            raise ip.err(st, 1, f"negative dwell time {dwell:g} s")
        feed_word = None
    else:
        for a in aux:
            if a[0] == "S" and a[1] > 0:
                ip.spindle_rpm = a[1]
    if feed_word is not None and not is_dwell:   # a dwell's F is its time, not a feed
        f, col = feed_word
        if f < 0:
            raise ip.err(st, col, f"negative feed F{f:g}")
        ip.feed = f * (MM_PER_INCH if ip.feed_inch else 1.0) / 60.0
    # --- motion ------------------------------------------------------------------------
    start = tuple(ip.pos[a] for a in ip.axes)
    centre_out = None
    plane_basis = None
    motion = None
    turns = 0
    if axis_words or (motion_set and ip.motion in ("G2", "G3") and centre):
        if ip.motion is None:
            raise ip.err(st, axis_words[0][3] if axis_words else 1,
                         "axis move without a motion command (G0/G1/G2/G3)")
        motion = ip.motion
        if motion != "G0" and ip.feed is None:
            col = motion_word_col if motion_set else (axis_words[0][3] if axis_words else 1)
            raise ip.err(st, col, f"{motion} with no feed: program F before or in this block")
        prog = ip.program_pos() if not g53 else dict(ip.pos)
        target = dict(prog)
        for name, val, mode, col in axis_words:
            v = val * ip.lin(name)
            incremental = (mode == "IC") or (mode != "AC" and not ip.absolute)
            target[name] = prog.get(name, 0.0) + v if incremental else v
        identity = ip.frame.theta_deg == 0.0 and not ip.frame.offset
        machine = target if (g53 or identity) else ip.frame.to_machine(target)
        if motion in ("G2", "G3"):
            centre_out, plane_basis, turns = _arc(ip, st, motion, prog, target, centre,
                                                  named, r_word, p_word, motion_word_col)
        ip.pos.update(machine)
    end = tuple(ip.pos[a] for a in ip.axes)
    tang = ip.tang_defs.get(ip.tang_active) if ip.tang_active else None
    modal_values = (ip.plane, ip.mode10, ip.criterion, ip.adis, ip.adispos, ip.ctol, ip.otol,
                    tuple(sorted(ip.atol.items())), ip.naive_cam, ip.accel_mode, ip.trc,
                    ip.trc_corner, ip.disc, ip.tool, ip.offset_no, tang)
    if ip.last_modal_values == modal_values:
        modal = ip.modal
    else:
        modal = Modal(*modal_values)
        ip.last_modal_values = modal_values
        ip.modal = modal
    if (centre_out is None and not turns and dwell is None and not aux and message is None
            and not st.comment and not kept and plane_basis is None):
        extra = NO_EXTRA
    else:
        extra = BlockExtra(center=centre_out, turns=turns, dwell_s=dwell, aux=tuple(aux),
                           message=message, comment=st.comment, kept_unmodelled=tuple(kept),
                           column_of_motion=motion_word_col, plane_basis=plane_basis)
    ip.last_end = end
    ip.out.append(Block(len(ip.out), st.line, st.text, st.label, motion, start, end, ip.feed,
                        (ip.mode10 == "G60") or g9, modal, extra))
    if ngc and ("M", 99.0) in aux:
        ip.warn(st, "M99 in the main program repeats it on the control; taken as the end of "
                    "the program")
        return True
    return program_end or any(a == ("M", 2.0) or a == ("M", 30.0) or
                              (not ngc and a == ("M", 17.0)) for a in aux)


def _indexed_assignment(ip: _Interp, st: Stmt, w: Word) -> None:
    """SINUMERIK ``R[i]=v``, ``ATOL[axis]=v`` and ``NAME[i]=v``."""
    base, idx = w.name[:-1].split("[", 1)
    value = ip.ev(st, w.value, w.col)
    if base == "ATOL":
        ax = idx.strip()
        if value < 0:                          # a negative value deletes it
            ip.atol.pop(ax, None)
        else:
            ip.atol[ax] = value * ip.lin(ax)
        return
    try:
        node = parse_expr(Cursor(idx))
    except ExprError as exc:
        raise ip.err(st, w.col, str(exc)) from None
    i = int(ip.ev(st, node, w.col))
    ip.vars[f"R{i}" if base == "R" else f"{base}[{i}]"] = value


def _arc(ip: _Interp, st: Stmt, motion: str, prog: dict, target: dict, centre: dict,
         named: dict, r_word, p_word, col: int):
    """Centre (machine coordinates), plane basis and extra turns of one arc."""
    u, v, w = _PLANE_AXES[ip.plane]
    su, sv = prog.get(u, 0.0), prog.get(v, 0.0)
    eu, ev = target.get(u, 0.0), target.get(v, 0.0)
    radius_word = named.get("CR") if not ip.ngc else r_word
    cw = motion == "G2"
    if radius_word is None and not centre:
        raise ip.err(st, col, f"{motion} needs a centre ({_CENTER_WORD[u]}, {_CENTER_WORD[v]})"
                              f" or a radius ({'R' if ip.ngc else 'CR='})")
    if radius_word is not None and not centre:
        r, rcol = radius_word
        r *= ip.lin(u)
        du, dv = eu - su, ev - sv
        chord = math.hypot(du, dv)
        if chord <= POS_TOL_MM:
            raise ip.err(st, rcol, "a full circle cannot be programmed with a radius; "
                                   "use the centre (I, J, K)")
        if abs(r) <= POS_TOL_MM:
            raise ip.err(st, rcol, "arc radius is zero")
        half = chord / 2
        if half > abs(r) + ARC_RADIUS_TOL_MM:
            raise ip.err(st, rcol, f"arc radius {abs(r):.6g} mm cannot reach the end point: "
                                   f"the chord is {chord:.6g} mm, so the radius must be at "
                                   f"least {half:.6g} mm ({half - abs(r):.3g} mm more)")
        cu, cv = _radius_centre(su, sv, eu, ev, r, cw)
    else:
        def off(ax: str, s_val: float) -> float:
            key = _CENTER_WORD[ax]
            if key not in centre:
                return s_val if not (ip.ngc and ip.ijk_absolute) else 0.0
            val, mode, _ = centre[key]
            val *= ip.lin(ax)
            absolute = mode == "AC" or (ip.ngc and ip.ijk_absolute)
            return val if absolute else s_val + val
        cu, cv = off(u, su), off(v, sv)
        r0 = math.hypot(su - cu, sv - cv)
        r1 = math.hypot(eu - cu, ev - cv)
        if r0 <= POS_TOL_MM:
            raise ip.err(st, col, "arc with zero radius (centre on the start point)")
        if abs(r1 - r0) > max(ARC_RADIUS_TOL_MM, ARC_RADIUS_REL_TOL * r0):
            raise ip.err(st, col, f"arc start radius {r0:.6g} mm and end radius {r1:.6g} mm "
                                  f"differ by {abs(r1 - r0):.3g} mm (more than "
                                  f"{max(ARC_RADIUS_TOL_MM, ARC_RADIUS_REL_TOL * r0):.3g} mm): "
                                  "check the centre")
    turns = 0
    if ip.ngc and p_word is not None:
        p = p_word[0]
        if p < 1 or p != int(p):
            raise ip.err(st, p_word[1], f"arc P{p:g} must be a whole number of turns >= 1")
        turns = int(p) - 1
    if not ip.ngc and "TURN" in named:
        t = named["TURN"][0]
        if t < 0 or t != int(t):
            raise ip.err(st, named["TURN"][1], f"TURN={t:g} must be a whole number >= 0")
        turns = int(t)
    c_prog = dict(prog)
    c_prog[u], c_prog[v] = cu, cv
    c_mach = ip.frame.to_machine(c_prog)
    centre_out = tuple(c_mach.get(a, 0.0) for a in ip.axes)
    basis = None
    if ip.frame.theta_deg and ip.plane != "G17":
        unit = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}
        basis = (ip.frame.rotate_vec(unit[u]), ip.frame.rotate_vec(unit[v]))
    return centre_out, basis, turns


def _apply_frame(ip: _Interp, st: Stmt, cmd: str, axis_words, named) -> None:
    """SINUMERIK programmable frame: machine = R(theta about Z) * program + offset.

    ``TRANS`` and ``ROT`` are absolute: each replaces the whole programmable frame (a bare
    ``TRANS`` or ``ROT`` deletes it). ``ATRANS`` adds a translation given in the current,
    possibly rotated, coordinate system; ``AROT`` adds a rotation about the current origin.
    Rotations about X or Y tilt the working plane and are rejected.
    """
    rot = 0.0
    moves: dict[str, float] = {}
    for name, val, _mode, col in axis_words:
        if cmd in ("ROT", "AROT"):
            if name != "Z":
                raise ip.err(st, col, f"{cmd} {name}: a rotation about {name} tilts the working "
                                      f"plane, which is not supported (only rotations about "
                                      f"Z: {cmd} Z... or {cmd} RPL=...)")
            rot += val
        else:
            moves[name] = val * ip.lin(name)
    if "RPL" in named:
        if ip.plane != "G17":
            raise ip.err(st, named["RPL"][1], f"RPL= rotates in the active plane; only G17 "
                                              f"(about Z) is supported, not {ip.plane}")
        rot += named["RPL"][0]
    old = ip.frame
    if cmd == "TRANS":
        ip.frame = _Frame(0.0, moves or None)
    elif cmd == "ROT":
        ip.frame = _Frame(rot, None)
    elif cmd == "ATRANS":
        offset = dict(old.offset or {})
        d = old.rotate_vec((moves.pop("X", 0.0), moves.pop("Y", 0.0), 0.0))
        for name, v in (("X", d[0]), ("Y", d[1]), *moves.items()):
            if v or name in offset:
                offset[name] = offset.get(name, 0.0) + v
        ip.frame = _Frame(old.theta_deg, offset or None)
    else:                                               # AROT
        ip.frame = _Frame(old.theta_deg + rot, old.offset)


def _ngc_frame(ip: _Interp) -> None:
    """Effective NGC frame: machine = R(theta) * (program + G92 offset) + work offset."""
    base = ip.cs.get(ip.cs_active, _Frame())
    if not ip.g92:
        ip.frame = base
        return
    offset = dict(base.offset or {})
    g = dict(ip.g92)
    d = base.rotate_vec((g.pop("X", 0.0), g.pop("Y", 0.0), 0.0))
    for name, v in (("X", d[0]), ("Y", d[1]), *g.items()):
        offset[name] = offset.get(name, 0.0) + v
    ip.frame = _Frame(base.theta_deg, offset or None)


def _apply_g10(ip: _Interp, st: Stmt, axis_words, l_word, p_word, r_word) -> None:
    """NGC ``G10 L2 Pn`` (work offset n, P0 = active; R = XY rotation, degrees) and
    ``G10 L20`` (offset chosen so that the current point gets the given coordinates)."""
    kind = int(l_word[0]) if l_word is not None else None
    if kind not in (2, 20):
        ip.warn(st, f"G10 L{kind if kind is not None else '?'} (tool or offset tables) has "
                    "no effect on the motion model")
        return
    num = int(p_word[0]) if p_word is not None else 0
    if not 0 <= num <= 9:
        raise ip.err(st, p_word[1], f"G10 L{kind} P{num}: P must be 0 (active) or 1..9 "
                                    "(G54..G59.3)")
    num = num or ip.cs_active
    old = ip.cs.get(num, _Frame())
    offset = dict(old.offset or {})
    theta = r_word[0] if r_word is not None else old.theta_deg
    for name, val, _, _ in axis_words:
        v = val * ip.lin(name)
        if kind == 2:
            offset[name] = v
        else:       # L20: the current machine position gets program coordinate v
            offset[name] = ip.pos.get(name, 0.0) - v - (ip.g92.get(name, 0.0))
    if kind == 20 and theta and axis_words:
        ip.warn(st, "G10 L20 with a rotated coordinate system: the offset is computed per "
                    "axis without the rotation")
    ip.cs[num] = _Frame(theta, offset or None)
    _ngc_frame(ip)
    ip.warn(st, f"G10 L{kind} sets work offset {num} (G{[54, 55, 56, 57, 58, 59, 59.1, 59.2, 59.3][num - 1]:g}): "
                f"{', '.join(f'{k}{v:g}' for k, v in offset.items()) or 'no offset'} mm, "
                f"rotation {theta:g} deg (applied to the following moves)")


def _apply_g92(ip: _Interp, st: Stmt, axis_words) -> None:
    """NGC ``G92``: offsets chosen so that the current point gets the given coordinates."""
    if not axis_words:
        raise ip.err(st, 1, "G92 needs at least one axis word")
    base = ip.cs.get(ip.cs_active, _Frame())
    rel = base.to_program(ip.pos)                       # R^T (machine - work offset)
    for name, val, _, _ in axis_words:
        ip.g92[name] = rel.get(name, 0.0) - val * ip.lin(name)
    _ngc_frame(ip)


def _tangential(ip: _Interp, st: Stmt, name: str, args: str, col: int) -> None:
    parts = [a.strip().strip('"').upper() for a in args.split(",")] if args.strip() else []
    if not parts:
        raise ip.err(st, col, f"{name} needs the following axis, e.g. {name}(C)")
    axis = parts[0]
    if name == "TANG":
        if len(parts) < 3:
            raise ip.err(st, col, "TANG needs (following axis, leading axis 1, leading axis 2"
                                  "[, coupling])")
        coupling = float(parts[3]) if len(parts) > 3 and parts[3] else 1.0
        ip.tang_defs[axis] = Tangential(axis=axis, leading=(parts[1], parts[2]),
                                        coupling=coupling)
        ip.add_axis(axis)
    elif name in ("TANGON", "TLIFT", "TANGOF", "TANGDEL"):
        if axis not in ip.tang_defs:
            raise ip.err(st, col, f"{name}({axis}) without a TANG({axis}, ...) definition")
        d = ip.tang_defs[axis]
        if name == "TANGON":
            off = float(parts[1]) if len(parts) > 1 and parts[1] else 0.0
            ip.tang_defs[axis] = Tangential(d.axis, d.leading, d.coupling, off, d.tlift)
            ip.tang_active = axis
        elif name == "TLIFT":
            ip.tang_defs[axis] = Tangential(d.axis, d.leading, d.coupling, d.offset_deg, True)
        elif name == "TANGOF":
            if ip.tang_active == axis:
                ip.tang_active = None
        else:
            if ip.tang_active == axis:
                raise ip.err(st, col, f"TANGDEL({axis}) while tangential control is on; "
                                      "TANGOF first")
            del ip.tang_defs[axis]
