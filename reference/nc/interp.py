"""Stage 2 of parsing: execute parsed lines -> resolved :class:`~reference.nc.program.Block`.

The interpreter keeps the modal state of both dialects (motion, plane, units,
absolute/incremental, feed, group 10, exact-stop criterion, TRC, tangential control),
evaluates variables and control flow whose conditions depend only on program
variables, applies frames (SINUMERIK TRANS/ATRANS/ROT/AROT about X, Y, Z, NGC ``G10 L2/L20``
work offsets with ``R`` rotation, G54..G59.3, G92), and emits one block per executed line
with absolute machine positions in mm / degrees.

Rules worth knowing:

* Declarations and control flow (``DEF``, ``IF``/``ELSE``/``ENDIF``, loops, ``GOTO``,
  ``CASE``, NGC O-words) make no block; every other executed line makes one, a line run
  by a loop once per pass. The guard against endless loops counts *re-executions*: the
  lines executed beyond the program's own statements (loop passes, subprogram calls). More
  than :data:`MAX_EXECUTED_BLOCKS` of them is an error naming the loop that jumped back
  last; a loop-free program of any length is never stopped by it.
* A frame change keeps the machine position; the axes a later block does not program
  stay where they are in machine coordinates.
* Anything that needs a real control (system variables, cycles, subprograms that are not
  in the file, unknown work offsets) is kept as a block without motion and warned about,
  once per line, or rejected when a condition or a position depends on it.
* Plain ``G0/G1/G2/G3`` lines without a frame take a fast lane (:func:`_fast_block`)
  that produces exactly the blocks of the full treatment (:func:`_block`).

Modules of this stage:

* :mod:`reference.nc.interp` (this one): :func:`run` and the interpreter loop
  :func:`_execute`, one statement after the other;
* :mod:`reference.nc.state`: the mutable state ``_Interp`` (modal state, variables,
  messages) and the tables of G codes and modal groups;
* :mod:`reference.nc.flow`: control flow (pairing, labels, jumps, NGC O-words);
* :mod:`reference.nc.fastlane`: the fast lane;
* :mod:`reference.nc.block`: one line, full treatment;
* :mod:`reference.nc.arcs`: arc centres, radius checks and turns;
* :mod:`reference.nc.frames`: frames and work offsets.
"""

from __future__ import annotations

from ..core.errors import NCSyntaxError
from .block import _block
from .fastlane import _fast_block
from .flow import _LazyLabels, _jump, _match_blocks, _oword
from .lines import Stmt, fast_pairs
from .program import Block, BlockExtra, Program
from .state import ROTARY, _Interp


#: Largest number of re-executed lines (statements run again by a loop, a jump back or a
#: subprogram call), beyond each statement's first run. It stops endless loops; a
#: loop-free program's own length is limited only by the memory budget, not by this.
MAX_EXECUTED_BLOCKS = 1_000_000
#: Loop openers whose closer jumps to the first statement of the body (not to the opener).
_BODY_OPENERS = frozenset({"LOOP", "REPEAT", "O:REPEAT"})


def run(file: str, dialect: str, stmts: list[Stmt], lines: tuple[str, ...], *,
        max_repeats: int = MAX_EXECUTED_BLOCKS) -> Program:
    """Execute parsed statements and build the :class:`Program`.

    ``max_repeats`` is the endless-loop guard: the most statements executed beyond the
    program's own ``len(stmts)`` (default :data:`MAX_EXECUTED_BLOCKS`).

    Raises
    ------
    NCSyntaxError
        Any error in the program, naming file, line and column.
    """
    ip = _Interp(file, dialect, stmts, lines)
    _execute(ip, max_repeats)
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


def _execute(ip: _Interp, max_repeats: int = MAX_EXECUTED_BLOCKS) -> None:
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
    # Each statement runs once in a loop-free program, so at most n executions are the
    # program itself; only what lies beyond counts against the guard.
    cap = n + max_repeats
    while i < n:
        st = stmts[i]
        k = st.kind
        executed += 1
        if i <= prev:                       # a jump back: remember the loop for the guard
            head = stmts[i - 1] if i > 0 and stmts[i - 1].kind in _BODY_OPENERS else st
            ip.loop_line = head.line
            ip.jump_line = stmts[prev].line
        prev = i
        if executed > cap:
            line = ip.loop_line or st.line
            raise NCSyntaxError(ip.file, line, 1, f"loop does not terminate within "
                                f"{max_repeats} blocks (the program does not end within "
                                f"{max_repeats} lines executed again by loops and jumps; "
                                f"it jumps back here from line {ip.jump_line or st.line})")
        if k == "block":
            if st.fast is not None and _fast_block(ip, st, fast_pairs(st)):
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
