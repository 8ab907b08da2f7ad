"""Stage 2 of parsing: execute parsed lines -> resolved :class:`~reference.nc.program.Block`.

The interpreter keeps the modal state of both dialects (motion, plane, units,
absolute/incremental, feed, group 10, exact-stop criterion, TRC, tangential control),
evaluates variables and control flow whose conditions depend only on program
variables, applies frames (SINUMERIK TRANS/ATRANS/ROT/AROT RPL, NGC ``G10 L2 ... R``),
and emits one block per executed line with absolute machine positions in mm / degrees.

Anything that needs a real control (system variables, cycles) is kept as a non-motion
block with a warning naming the line, or rejected when a condition depends on it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..core.errors import NCSyntaxError
from ..core.tolerances import ARC_RADIUS_REL_TOL, ARC_RADIUS_TOL_MM, POS_TOL_MM
from ..core.units import MM_PER_INCH
from .expr import ExprError, constant, evaluate
from .lines import Stmt, Word
from .program import NO_EXTRA, Block, BlockExtra, Modal, Program, ProgramWarning, Tangential

MAX_EXECUTED_BLOCKS = 1_000_000
GEOMETRY = ("X", "Y", "Z")
ROTARY = frozenset("ABC")
_PLANE_AXES = {"G17": ("X", "Y", "Z"), "G18": ("Z", "X", "Y"), "G19": ("Y", "Z", "X")}
_CENTER_WORD = {"X": "I", "Y": "J", "Z": "K"}
_MODES10_SIN = {60: "G60", 64: "G64", 641: "G641", 642: "G642", 643: "G643", 644: "G644",
                645: "G645"}
# G codes accepted without effect on the motion model (kept, warned once per program)
_IGNORED_G_SIN = {53, 153, 500, 25, 26, 96, 97, 94, 110, 111, 112, 147, 148, 247, 248, 347,
                  348, 340, 341, 55, 56, 57, 54, 505, 506, 507, 508, 509, 510}
_IGNORED_G_NGC = {43, 49, 54, 55, 56, 57, 58, 59, 59.1, 59.2, 59.3, 80, 94, 17.1, 18.1, 19.1,
                  92.1, 92.2, 92.3, 40.0, 49.0, 98, 99, 7, 8, 43.1, 50, 51, 64.0}
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
        self.inch = False
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
        self.tang_defs: dict[str, Tangential] = {}
        self.tang_active: str | None = None
        self.out: list = []
        self.warnings: list[ProgramWarning] = []
        self.warned: set[str] = set()
        self.last_modal_values: tuple | None = None

    # ----------------------------------------------------------------- messages
    def err(self, st: Stmt, col: int, msg: str) -> NCSyntaxError:
        return NCSyntaxError(self.file, st.line, max(col, 1), msg)

    def warn(self, st: Stmt, msg: str, once_key: str | None = None) -> None:
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
    blocks = []
    for i, (kw, s, e, modal, extra) in enumerate(ip.out):
        if len(s) < n:
            s = s + (0.0,) * (n - len(s))
        if len(e) < n:
            e = e + (0.0,) * (n - len(e))
        if extra.center is not None and len(extra.center) < n:
            extra = BlockExtra(**{**{f: getattr(extra, f) for f in extra.__slots__},
                                  "center": extra.center + (0.0,) * (n - len(extra.center))})
        blocks.append(Block(i, kw[0], kw[1], kw[2], kw[3], s, e, kw[4], kw[5], modal, extra))
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
            if kw in ("IF", "WHILE", "DO", "REPEAT", "SUB"):
                o_stack.append((kw, st.target, i))
            elif kw in ("ELSEIF", "ELSE"):
                if not o_stack or o_stack[-1][1] != st.target:
                    raise ip.err(st, 1, f"o{st.target} {kw.lower()} without a matching if")
                pairs.setdefault(o_stack[-1][2], i)
                pairs.setdefault(("chain", o_stack[-1][2]), []).append(i)  # type: ignore
            elif kw in ("ENDIF", "ENDWHILE", "ENDREPEAT", "ENDSUB") or (
                    kw == "WHILE" and o_stack and o_stack[-1][0] == "DO"):
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
    labels = _labels(ip)
    subs = {st.target: i for i, st in enumerate(stmts) if st.kind == "O:SUB"}
    calls: list[tuple[int, dict]] = []
    loops_for: dict[int, float] = {}
    executed = 0
    i = 0
    n = len(stmts)
    while i < n:
        st = stmts[i]
        k = st.kind
        executed += 1
        if executed > MAX_EXECUTED_BLOCKS:
            raise ip.err(st, 1, f"the program does not end within {MAX_EXECUTED_BLOCKS} "
                                "executed lines (endless loop?)")
        if k == "block":
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
_FAST_LETTERS = frozenset("GXYZFN")


def _fast_block(ip: _Interp, st: Stmt) -> bool:
    """Plain G0/G1 line of constant X/Y/Z/F words with no frame active: the bulk of CAM
    output. Reuses the previous block's modal fields. Returns False to fall back."""
    if not ip.out or st.assigns or st.flags or st.calls or st.message is not None:
        return False
    frame = ip.frame
    if frame.theta_deg != 0.0 or frame.offset:
        return False
    motion = ip.motion
    motion_col = 1
    feed = None
    targets = []
    for w in st.words:
        name = w.name
        if name not in _FAST_LETTERS or w.mode or w.value[0] != "num":
            return False
        val = w.value[1]
        if name == "G":
            if val == 0.0 or val == 1.0:
                motion = "G0" if val == 0.0 else "G1"
                motion_col = w.col
            else:
                return False
        elif name == "F":
            feed = w
        elif name != "N":
            targets.append((name, val))
    if not targets or motion not in ("G0", "G1"):
        return False
    if feed is not None:
        if feed.value[1] < 0:
            return False
        ip.feed = feed.value[1] * (MM_PER_INCH if ip.inch else 1.0) / 60.0
    if motion == "G1" and ip.feed is None:
        return False
    ip.motion = motion
    pos = ip.pos
    start = tuple(pos[a] for a in ip.axes)
    k = MM_PER_INCH if ip.inch else 1.0
    if ip.absolute:
        for name, val in targets:
            pos[name] = val * k
    else:
        for name, val in targets:
            pos[name] += val * k
    end = tuple(pos[a] for a in ip.axes)
    extra = NO_EXTRA if not st.comment else BlockExtra(comment=st.comment)
    kw = (st.line, st.text, st.label, motion, ip.feed, ip.mode10 == "G60")
    ip.out.append((kw, start, end, ip.out[-1][3], extra))
    return True


def _block(ip: _Interp, st: Stmt) -> bool:
    """Execute one ordinary line; returns True at program end (M2/M30)."""
    if _fast_block(ip, st):
        return False
    ngc = ip.ngc
    # --- assignments ------------------------------------------------------------
    for target, node, col in st.assigns:
        if ngc:
            key = target[1] if target[0] == "var" else f"#{int(ip.ev(st, target[1], col + 1))}"
            ip.vars[key] = ip.ev(st, node, col + 1)
        else:
            name = target
            if "[" in name:
                base, idx = name[:-1].split("[", 1)
                if base == "R":
                    try:
                        from .expr import Cursor, parse_expr
                        ival = int(ip.ev(st, parse_expr(Cursor(idx))))
                    except ExprError as exc:
                        raise ip.err(st, col + 1, str(exc)) from None
                    ip.vars[f"R{ival}"] = ip.ev(st, node, col + 1)
                elif base == "ATOL":
                    ip.atol[idx.strip()] = ip.ev(st, node, col + 1) * ip.lin(idx.strip())
                else:
                    ip.vars[name] = ip.ev(st, node, col + 1)
            else:
                ip.vars[name] = ip.ev(st, node, col + 1)
    # --- words ------------------------------------------------------------------
    g_codes: list[tuple[float, int]] = []
    axis_words: list[tuple[str, float, str, int]] = []
    centre: dict[str, tuple[float, str, int]] = {}
    aux: list[tuple[str, float]] = []
    named: dict[str, tuple[float, int]] = {}
    feed_word: tuple[float, int] | None = None
    p_word = q_word = r_word = l_word = None
    for w in st.words:
        name = w.name
        if not ngc and name in ip.declared:          # a DEF variable, also if one letter
            ip.vars[name] = ip.ev(st, w.value, w.col)
            continue
        if not ngc and len(name) > 1 or (not ngc and name not in "GMFSTDHIJKPQRLXYZABCUVWEN"):
            if name in ("CR", "ADIS", "ADISPOS", "TURN", "CTOL", "OTOL", "DISC", "AR", "RPL",
                        "STOLF", "RND", "RNDM", "SF", "OFFN"):
                named[name] = (ip.ev(st, w.value, w.col), w.col)
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
        elif name == "M":
            aux.append(("M", val))
        elif name in "XYZ" or name in "ABC" or (ngc and name in "UVW") or (
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
            pass
        else:
            raise ip.err(st, w.col, f"unknown address {name}")
    # --- G codes ------------------------------------------------------------------
    g9 = False
    dwell = None
    is_dwell = False
    g10 = False
    g53 = False
    motion_word_col = 1
    motion_set = False
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
            ip.inch = True
            if not ip.out:
                ip.start_units = "inch"
        elif (not ngc and gi in (71, 710)) or (ngc and gi == 21):
            ip.inch = False
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
        elif not ngc and gi in (450, 451):
            ip.trc_corner = f"G{int(gi)}"
        elif ngc and gi == 10:
            g10 = True
        elif ngc and gi == 53 or (not ngc and gi in (53, 153)):
            g53 = True
            ip.warn(st, f"G{gi:g}: positions in machine coordinates (frames suppressed for "
                        "this block)", once_key=f"G{gi}")
        elif ngc and gi in (28, 30):
            ip.warn(st, f"G{gi:g} (home move) needs the machine's home position; kept "
                        "without motion")
            axis_words = []
        elif ngc and 81 <= gi <= 89 or (ngc and gi in (73, 74)):
            raise ip.err(st, col, f"canned cycle G{gi:g} is not supported; expand it into "
                                  "G0/G1 moves")
        elif (ngc and gi in _IGNORED_G_NGC) or (not ngc and gi in _IGNORED_G_SIN):
            ip.warn(st, f"G{gi:g} has no effect on the motion model (work offsets and tool "
                        "lengths are taken as zero)", once_key=f"G{gi}")
        else:
            raise ip.err(st, col, f"unknown G code G{gi:g}")
    # --- flags (SINUMERIK keywords) ------------------------------------------------
    frame_cmd = None
    for flag, col in st.flags:
        if flag in ("BRISK", "SOFT", "DRIVE"):
            ip.accel_mode = flag
        elif flag in ("TRANS", "ATRANS", "ROT", "AROT"):
            frame_cmd = flag
        elif flag == "G500":
            pass
        else:
            ip.warn(st, f"{flag} is kept but not modelled", once_key=flag)
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
    # --- frames ------------------------------------------------------------------------
    if frame_cmd is not None:
        _apply_frame(ip, st, frame_cmd, axis_words, named)
        axis_words = []
    if g10:
        _apply_g10(ip, st, axis_words, l_word, p_word, r_word)
        axis_words = []
        r_word = None
    # --- feed --------------------------------------------------------------------------
    if is_dwell:
        if ngc:
            if p_word is None:
                raise ip.err(st, 1, "G4 needs P (dwell time in seconds)")
            dwell = p_word[0]
        elif feed_word is not None:
            dwell = feed_word[0]
        elif any(a[0] == "S" for a in aux):
            ip.warn(st, "G4 S (dwell in spindle revolutions) needs the spindle speed; "
                        "the dwell time is not modelled")
        else:
            raise ip.err(st, 1, "G4 needs F (seconds) or S (spindle revolutions)")
        if dwell is not None and dwell < 0:
            raise ip.err(st, 1, f"negative dwell time {dwell:g} s")
        feed_word = None
    elif feed_word is not None:
        f, col = feed_word
        if f < 0:
            raise ip.err(st, col, f"negative feed F{f:g}")
        ip.feed = f * (MM_PER_INCH if ip.inch else 1.0) / 60.0
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
    elif centre and not axis_words:
        pass
    end = tuple(ip.pos[a] for a in ip.axes)
    tang = ip.tang_defs.get(ip.tang_active) if ip.tang_active else None
    modal_values = (ip.plane, ip.mode10, ip.criterion, ip.adis, ip.adispos, ip.ctol, ip.otol,
                    tuple(sorted(ip.atol.items())), ip.naive_cam, ip.accel_mode, ip.trc,
                    ip.trc_corner, ip.disc, ip.tool, ip.offset_no, tang)
    prev = ip.out[-1][3] if ip.out else None
    if prev is not None and ip.last_modal_values == modal_values:
        modal = prev
    else:
        modal = Modal(*modal_values)
        ip.last_modal_values = modal_values
    if (centre_out is None and not turns and dwell is None and not aux and message is None
            and not st.comment and not kept and plane_basis is None):
        extra = NO_EXTRA
    else:
        extra = BlockExtra(center=centre_out, turns=turns, dwell_s=dwell, aux=tuple(aux),
                           message=message, comment=st.comment, kept_unmodelled=tuple(kept),
                           column_of_motion=motion_word_col, plane_basis=plane_basis)
    kw = (st.line, st.text, st.label, motion, ip.feed, (ip.mode10 == "G60") or g9)
    ip.out.append((kw, start, end, modal, extra))
    return any(a == ("M", 2.0) or a == ("M", 30.0) for a in aux)


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
        h = math.sqrt(max(r * r - half * half, 0.0))
        nu, nv = -dv / chord, du / chord             # left normal of the chord
        side = (1.0 if not cw else -1.0) * (1.0 if r > 0 else -1.0)
        cu = su + du / 2 + side * h * nu
        cv = sv + dv / 2 + side * h * nv
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
    old_prog = None
    if cmd in ("TRANS", "ROT"):
        # an absolute frame command replaces the frame; bare TRANS / ROT resets it
        theta = ip.frame.theta_deg if cmd == "TRANS" else 0.0
        offset = {} if cmd == "TRANS" else dict(ip.frame.offset or {})
        if cmd == "ROT" and "RPL" in named:
            theta = named["RPL"][0]
        if cmd == "TRANS":
            for name, val, _, _ in axis_words:
                offset[name] = val * ip.lin(name)
        ip.frame = _Frame(theta, offset or None)
    else:
        theta = ip.frame.theta_deg + (named["RPL"][0] if "RPL" in named else 0.0)
        offset = dict(ip.frame.offset or {})
        for name, val, _, _ in axis_words:
            offset[name] = offset.get(name, 0.0) + val * ip.lin(name)
        ip.frame = _Frame(theta, offset or None)
    del old_prog


def _apply_g10(ip: _Interp, st: Stmt, axis_words, l_word, p_word, r_word) -> None:
    if l_word is None or int(l_word[0]) != 2:
        ip.warn(st, "G10 other than L2 (tool/offset tables) has no effect on the motion "
                    "model", once_key="G10")
        return
    offset = {name: val * ip.lin(name) for name, val, _, _ in axis_words}
    theta = r_word[0] if r_word is not None else 0.0
    ip.frame = _Frame(theta, offset or None)
    ip.warn(st, f"G10 L2 sets the active coordinate system: offset "
                f"{', '.join(f'{k}{v:g}' for k, v in offset.items()) or 'none'}, rotation "
                f"{theta:g} deg", once_key="G10L2")


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
