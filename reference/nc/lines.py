"""Stage 1 of parsing: one source line -> one :class:`Stmt` (both dialects).

Lines are parsed once; loops re-execute the parsed statements. Values are expression
ASTs from :mod:`reference.nc.expr` (constants for plain numbers), so execution never
re-reads text. Columns are 1-based and refer to the line as written.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from .expr import NAME, Cursor, ExprError, parse_expr, sin_exponent

#: Single-letter addresses that take a number (both dialects).
ADDRESSES = frozenset("ABCDEFGHIJKLMNPQRSTUVWXYZ")
#: SINUMERIK named addresses written ``NAME=value``.
NAMED_ADDRESSES = frozenset({"CR", "ADIS", "ADISPOS", "TURN", "CTOL", "OTOL", "DISC", "AR",
                             "RND", "RNDM", "STOLF", "SF", "FA", "OFFN", "RPL", "SPOS",
                             "SPOSA", "FB", "AP", "RP", "CIP", "CT"})
#: SINUMERIK keywords that are a whole word on their own.
FLAGS = frozenset({"BRISK", "SOFT", "DRIVE", "SUPA", "CFC", "CFTCP", "CFIN",
                   "FNORM", "FLIN", "FCUB", "COMPON", "COMPOF", "COMPCURV", "COMPCAD",
                   "ORISON", "ORISOF", "FFWON", "FFWOF", "TRANS", "ATRANS", "ROT", "AROT",
                   "SCALE", "ASCALE", "MIRROR", "AMIRROR", "TRAORI", "TRAFOOF", "CDON",
                   "CDOF", "CDOF2", "DYNNORM", "DYNPOS", "DYNROUGH", "DYNSEMIFIN",
                   "DYNFINISH", "RET", "STOPRE", "BRISKA", "SOFTA", "DRIVEA"})
CONTROL = frozenset({"IF", "ELSE", "ENDIF", "WHILE", "ENDWHILE", "FOR", "ENDFOR", "REPEAT",
                     "UNTIL", "LOOP", "ENDLOOP", "GOTOF", "GOTOB", "GOTOC", "GOTO", "GOTOS",
                     "CASE", "DEF", "PROC", "DEFINE", "EXTERN"})
_NUM_SIGNED = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)")
_LABEL = re.compile(r"([A-Z_][A-Z0-9_]*):(?!=)")
_BLOCKNO = re.compile(r"N(\d+)|:(\d+)")
_INT = re.compile(r"\d+")
_GOTO_TARGET = re.compile(r"[A-Z_][A-Z0-9_]*|:\d+")
_MODE_CALL = re.compile(r"(AC|IC|ACP|ACN|DC)\s*\(")
_NON_BLANK = re.compile(r"[^ \t]+")
_NON_LETTERS = re.compile(r"[^A-Z]*")


@dataclass(slots=True)
class Word:
    """One address word: ``name`` (``"G"``, ``"X"``, ``"CR"``, ``"ELX"``), value AST."""

    name: str
    value: tuple
    col: int
    mode: str = ""          # "" | "AC" | "IC"


class Stmt:
    """One parsed line.

    ``kind`` is ``"block"`` for ordinary lines and the control keyword otherwise
    (``"IF"``, ``"ENDWHILE"``, ``"O:IF"`` for NGC O-words, ...).

    Plain word lines (the bulk of CAM output) take a fast lane and are instances of this
    class: they keep the line, its text and where its words lie (``fast``, ``fast_end``:
    a span of :func:`normalized` text), and nothing else; the interpreter reads their
    ``(letter, number text)`` pairs with :func:`fast_pairs` when it executes them, and
    :attr:`words` builds :class:`Word` objects (with columns) only when asked. The class
    attributes below are the (immutable) defaults of such lines. Lines that need the
    full grammar are :class:`FullStmt`, which holds every field itself.

    Every field is a slot: a program of 10^6 lines holds 10^6 of these at once while
    it is interpreted, about 100 bytes each (a ``__dict__`` and the word pairs would be
    some 600).
    """

    __slots__ = ("line", "text", "label", "comment", "dialect", "fast", "fast_end",
                 "_words")

    kind = "block"
    assigns: list = ()          # (target, AST, col)
    calls: list = ()            # (NAME, raw args, col)
    flags: list = ()            # (NAME, col)
    cond: tuple | None = None
    target = ""                 # GOTO label / O-word name
    case: list = ()             # [(value AST or None, label)]
    decl: list = ()             # DEF names
    message: str | None = None
    empty = False
    colmap: list | None = None  # NGC: code offset -> line column

    @property
    def words(self) -> list:
        """Address words (:class:`Word`) with their columns."""
        if self._words is None:                 # a fast-lane line: add the columns now
            self._words = _fast_words(self)
        return self._words

    @words.setter
    def words(self, value: list) -> None:
        self._words = value


class FullStmt(Stmt):
    """A line parsed with the full grammar: every field of :class:`Stmt` is its own
    (fresh lists for words, assignments, calls, ...)."""

    __slots__ = ("kind", "assigns", "calls", "flags", "cond", "target", "case", "decl",
                 "message", "empty", "colmap")

    def __init__(self, line: int, text: str, kind: str = "block", label: str = "",
                 comment: str = "", message: str | None = None) -> None:
        self.line = line
        self.text = text
        self.kind = kind
        self.label = label
        self.comment = comment
        self.message = message
        self.dialect = "sinumerik"
        self.fast = None
        self.fast_end = 0
        self._words = []
        self.assigns = []
        self.calls = []
        self.flags = []
        self.cond = None
        self.target = ""
        self.case = []
        self.decl = []
        self.empty = False
        self.colmap = None


_NEW = object.__new__


class LineError(Exception):
    """Syntax error at a 0-based column of the upper-cased code part."""

    def __init__(self, message: str, col: int) -> None:
        super().__init__(message)
        self.col = col


# ----------------------------------------------------------------------- SINUMERIK
def _split_comment_sin(text: str) -> tuple[str, str]:
    in_str = False
    for i, ch in enumerate(text):
        if ch == '"':
            in_str = not in_str
        elif ch == ";" and not in_str:
            return text[:i], text[i + 1:].strip()
    return text, ""


def _call_args(cur: Cursor) -> str:
    """Raw text between a '(' at the cursor and its matching ')'."""
    start = cur.pos
    depth, in_str, p, t = 0, False, cur.pos, cur.text
    while p < len(t):
        ch = t[p]
        if ch == '"':
            in_str = not in_str
        elif not in_str and ch == "(":
            depth += 1
        elif not in_str and ch == ")":
            depth -= 1
            if depth == 0:
                cur.pos = p + 1
                return t[start + 1:p]
        p += 1
    raise LineError("missing ')'", start)


# A line of plain ``letter number`` words (the bulk of CAM output): one regex, no
# per-word objects. SINUMERIK keeps blanks between words; NGC text is matched with all
# blanks removed (LinuxCNC ignores them, also inside numbers).
_SIMPLE_SIN = re.compile(r"[ \t]*(?:(N\d+)[ \t]+)?(?:([A-Z_][A-Z0-9_]*):(?!=)[ \t]*)?"
                         r"((?:[A-MP-Z][-+]?(?:\d+\.?\d*|\.\d+)[ \t]*)+)(?:;(.*))?$")
_SIMPLE_NGC = re.compile(r"(?:(N\d+))?((?:[A-MP-Z][-+]?(?:\d+\.?\d*|\.\d+))+)$")
_SIMPLE_WORD = re.compile(r"([A-Z])([-+]?(?:\d+\.?\d*|\.\d+))")
_NOT_SIMPLE_NGC = re.compile(r"[(;#\[/%<=]")
_GLUED_E = re.compile(r"[\d.]E")          # an exponent, or X1E5: the full grammar decides


def _fast_stmt(lineno: int, raw: str, label: str | None, comment: str | None,
               span: tuple[int, int], dialect: str) -> Stmt:
    """A fast-lane :class:`Stmt` (class-level defaults for everything else)."""
    st = _NEW(Stmt)
    st.line = lineno
    st.text = raw
    st.label = label or ""
    st.comment = comment.strip() if comment else ""
    st.dialect = dialect
    st.fast, st.fast_end = span
    st._words = None
    return st


def normalized(st: Stmt) -> str:
    """The text a fast-lane line's word span indexes: upper case, and for NGC without
    blanks (LinuxCNC ignores them, also inside numbers)."""
    raw = st.text
    if st.dialect == "ngc":
        return raw.replace(" ", "").replace("\t", "").upper()
    return raw.upper()


def fast_pairs(st: Stmt) -> list[tuple[str, str]]:
    """``(letter, number text)`` of a fast-lane line, in source order.

    Read again from the text each time the line runs rather than kept from parsing: a
    program's lines are all held at once while it runs, and the pairs would triple
    their size."""
    return _SIMPLE_WORD.findall(normalized(st), st.fast, st.fast_end)


def _fast_words(st: Stmt) -> list:
    """:class:`Word` objects (with 1-based columns) of a fast-lane line."""
    up = normalized(st)
    if st.dialect == "ngc":
        cols = [i for i, ch in enumerate(st.text) if ch not in " \t"]
    else:
        cols = None
    return [Word(w.group(1), ("num", float(w.group(2))),
                 (cols[w.start()] if cols is not None else w.start()) + 1)
            for w in _SIMPLE_WORD.finditer(up, st.fast, st.fast_end)]


def _simple_sin(lineno: int, raw: str) -> Stmt | None:
    """Fast lane for plain SINUMERIK word lines; None when the line needs the grammar."""
    up = raw.upper()
    m = _SIMPLE_SIN.match(up)
    if m is None:
        return None
    if "E" in up and _GLUED_E.search(up, m.start(3), m.end(3)):
        return None
    comment = None
    if m.group(4) is not None:
        if len(up) != len(raw):          # upper-casing changed the length (rare letters)
            return None
        comment = raw[m.start(4):]
    return _fast_stmt(lineno, raw, m.group(2) or m.group(1), comment, m.span(3),
                      "sinumerik")


def _simple_ngc(lineno: int, raw: str) -> Stmt | None:
    """Fast lane for plain NGC word lines (no comments, parameters or expressions)."""
    if _NOT_SIMPLE_NGC.search(raw) is not None:
        return None
    up = raw.replace(" ", "").replace("\t", "").upper()
    m = _SIMPLE_NGC.match(up)
    if m is None:
        return None
    return _fast_stmt(lineno, raw, m.group(1), None, m.span(2), "ngc")


def parse_sinumerik(lineno: int, raw: str) -> Stmt:
    """Parse one SINUMERIK line."""
    st = _simple_sin(lineno, raw)
    if st is not None:
        return st
    return parse_sinumerik_full(lineno, raw)


_SKIP_LEVEL = re.compile(r"/[0-9]?")


def parse_sinumerik_full(lineno: int, raw: str) -> Stmt:
    """Parse one SINUMERIK line with the full grammar."""
    code, comment = _split_comment_sin(raw)
    st = FullStmt(line=lineno, text=raw, comment=comment)
    up = code.upper()
    cur = Cursor(up)
    cur.ws()
    if cur.peek() == "/":            # block delete (skip levels /0../9): the switch is off
        cur.match(_SKIP_LEVEL)
    if not cur.peek() or cur.peek() == "%":   # blank, or a %_N_NAME_MPF file header
        st.empty = True
        return st
    m = cur.match(_BLOCKNO)
    if m:
        st.label = "N" + m.group(1) if m.group(1) else ":" + m.group(2)
    m = _LABEL.match(up, (cur.ws(), cur.pos)[1])
    if m and m.group(1) not in ("N",):
        st.label = m.group(1)
        cur.pos = m.end()
    cur.ws()
    m = NAME.match(up, cur.pos)
    if m and m.group() in CONTROL:
        _control_sin(st, cur, m, code)
        return st
    _words_sin(st, cur, code)
    return st


def _expr(cur: Cursor):
    try:
        return parse_expr(cur)
    except ExprError as exc:
        raise LineError(str(exc), exc.col) from None


def _control_sin(st: Stmt, cur: Cursor, m: re.Match, code: str) -> None:
    kw = m.group()
    cur.pos = m.end()
    st.kind = kw
    if kw in ("IF", "WHILE", "UNTIL"):
        st.cond = _expr(cur)
        rest = NAME.match(cur.text, (cur.ws(), cur.pos)[1])
        if kw == "IF" and rest and rest.group() in ("GOTOF", "GOTOB", "GOTOC", "GOTO"):
            cur.pos = rest.end()
            st.kind = "IFGOTO"
            st.target = _goto_target(cur, rest.group())
            st.case = [(None, rest.group())]
        elif cur.peek():
            raise LineError(f"unexpected text after {kw} condition", cur.pos)
    elif kw in ("GOTOF", "GOTOB", "GOTOC", "GOTO"):
        st.target = _goto_target(cur, kw)
    elif kw == "FOR":
        var = cur.match(NAME)
        if not var or cur.peek() != "=":
            raise LineError("FOR needs 'FOR variable = start TO end'", cur.pos)
        cur.pos += 1
        start = _expr(cur)
        to = cur.match(NAME)
        if not to or to.group() != "TO":
            raise LineError("FOR needs 'TO'", cur.pos)
        st.target = var.group()
        st.assigns = [(var.group(), start, 0)]
        st.cond = _expr(cur)
    elif kw == "CASE":
        st.cond = _expr(cur)
        of = cur.match(NAME)
        if not of or of.group() != "OF":
            raise LineError("CASE needs 'OF'", cur.pos)
        while cur.peek():
            dm = NAME.match(cur.text, cur.pos)
            if dm and dm.group() == "DEFAULT":
                cur.pos = dm.end()
                val = None
            else:
                val = _expr(cur)
            g = cur.match(NAME)
            if not g or not g.group().startswith("GOTO"):
                raise LineError("CASE entries need 'value GOTOF label'", cur.pos)
            st.case.append((val, _goto_target(cur, g.group()), g.group()))
    elif kw in ("DEF", "DEFINE", "EXTERN", "PROC"):
        if kw != "DEF":
            return
        typ = cur.match(NAME)
        if not typ or typ.group() not in ("REAL", "INT", "BOOL", "CHAR", "STRING", "AXIS", "FRAME"):
            raise LineError("DEF needs a type (REAL, INT, BOOL, ...)", cur.pos)
        while cur.peek():
            nm = cur.match(NAME)
            if not nm:
                raise LineError("variable name expected after DEF type", cur.pos)
            if cur.peek() == "[":
                _call_args_bracket(cur)
            st.decl.append((nm.group(), typ.group()))
            if cur.peek() == "=":
                cur.pos += 1
                st.assigns.append((nm.group(), _expr(cur), nm.start()))
            if cur.peek() == ",":
                cur.pos += 1
    elif cur.peek():
        if kw in ("ELSE", "ENDIF", "ENDWHILE", "ENDFOR", "LOOP", "ENDLOOP", "REPEAT", "GOTOS"):
            raise LineError(f"unexpected text after {kw}", cur.pos)


def _call_args_bracket(cur: Cursor) -> str:
    start = cur.pos
    end = cur.text.find("]", start)
    if end < 0:
        raise LineError("missing ']'", start)
    cur.pos = end + 1
    return cur.text[start + 1:end]


def _goto_target(cur: Cursor, kw: str) -> str:
    m = cur.match(_GOTO_TARGET)
    if not m:
        raise LineError(f"{kw} needs a label", cur.pos)
    return m.group()


def _words_sin(st: Stmt, cur: Cursor, code: str) -> None:
    t = cur.text
    while True:
        ch = cur.peek()
        if not ch:
            return
        start = cur.pos
        m = NAME.match(t, start)
        if not m:
            if ch == "$":
                raise LineError("system variable assignment", start)
            raise LineError(f"unexpected '{ch}'", start)
        name = m.group()
        cur.pos = m.end()
        after = cur.peek()
        if name.startswith("$"):
            # system variables need a real control: keep the statement, evaluate nothing
            st.calls.append((name, t[start:].strip(), start))
            cur.pos = len(t)
            return
        if after == "(" and not (name in ("AC", "IC")):
            cur.pos = t.index("(", cur.pos)
            _call_args(cur)                      # moves past the matching ')'
            raw_args = code[start + (t.index("(", start) - start) + 1:cur.pos - 1]
            st.calls.append((name, raw_args, start))
            continue
        if after == "[" and name != "R" or (name == "R" and after == "["):
            cur.pos = t.index("[", cur.pos)
            idx = _call_args_bracket(cur)
            if cur.peek() != "=":
                raise LineError(f"'=' expected after {name}[{idx}]", cur.pos)
            cur.pos += 1
            # in source order with the other words: R1=10 R[2]=R1/4 uses the new R1
            val, mode = _value_with_mode(cur)
            st.words.append(Word(f"{name}[{idx.strip()}]", val, start + 1, mode))
            continue
        if after == "=" and not t.startswith("==", cur.pos):
            cur.pos = t.index("=", cur.pos) + 1
            if name == "T" and cur.peek() == '"':
                # a tool by name (tool management): T="DRILL 8.5", kept as written
                q = cur.pos
                end = t.find('"', q + 1)
                if end < 0:
                    raise LineError("tool name: missing closing '\"'", q)
                tool = code[q + 1:end]
                if not tool.strip():
                    raise LineError('empty tool name T=""', q)
                st.words.append(Word(name, ("str", tool), start + 1))
                cur.pos = end + 1
                continue
            val, mode = _value_with_mode(cur)
            st.words.append(Word(name, val, start + 1, mode))
            continue
        # address + number, possibly glued (G1, X10.5, Y-2., G1X10Y5)
        if name[0] in ADDRESSES and _ADDR_NUM.match(t, start) and name not in FLAGS:
            cur.pos = start
            _address_word(st, cur)
            continue
        if name in FLAGS:
            st.flags.append((name, start))
            continue
        # a bare name: subprogram call or an unknown keyword, kept with a warning
        st.calls.append((name, "", start))


def _value_with_mode(cur: Cursor) -> tuple[tuple, str]:
    """The value after ``=``: an expression, or ``AC(...)``/``IC(...)`` (also ``ACP``,
    ``ACN``, ``DC``, read as absolute). Returns (AST, "" | "AC" | "IC")."""
    t = cur.text
    mm = _MODE_CALL.match(t, (cur.ws(), cur.pos)[1])
    if not mm:
        return _expr(cur), ""
    mode = mm.group(1)
    cur.pos = mm.end()
    val = _expr(cur)
    if cur.peek() != ")":
        raise LineError(f"missing ')' after {mode}(", cur.pos)
    cur.pos += 1
    return val, mode if mode in ("AC", "IC") else ""


_ADDR_NUM = re.compile(r"([A-Z])[ \t]*([-+]?(?:\d+\.?\d*|\.\d+))")
_NEXT_WORD = re.compile(r"[A-Z][-+]?[\d.]|[A-Z_][A-Z0-9_]*\s*[=(\[]")


def _address_word(st: Stmt, cur: Cursor) -> None:
    """One ``letter number`` word at the cursor; checks the word ends cleanly."""
    t = cur.text
    m = _ADDR_NUM.match(t, cur.pos)
    end = m.end()
    cur.pos = end
    try:
        exponent = sin_exponent(t, cur)         # 1.5EX-3; 1E5 is an error
    except ExprError as exc:
        raise LineError(str(exc), exc.col) from None
    end = cur.pos
    if end < len(t) and t[end] not in " \t":
        # a glued next word (G1X10) is fine; anything else is a typo such as Y1O
        nm = NAME.match(t, end)
        if not (t[end].isalpha() and _NEXT_WORD.match(t, end)) and not (
                nm and nm.group() in FLAGS):
            bad = _NON_BLANK.match(t, m.start(2)).group()
            raise LineError(f"invalid number '{bad}' after address {m.group(1)}", m.start(2))
    st.words.append(Word(m.group(1), ("num", float(m.group(2) + exponent)), m.start() + 1))
    cur.pos = end


# ----------------------------------------------------------------------------- NGC
def _strip_ngc(raw: str) -> tuple[str, list[int], str, str | None]:
    """Remove comments and whitespace; return (code, column map, comment, message)."""
    out, cols, comments, msg = [], [], [], None
    i, n = 0, len(raw)
    while i < n:
        ch = raw[i]
        if ch == "(":
            j = raw.find(")", i)
            if j < 0:
                raise LineError("comment '(' is not closed with ')'", len(out))
            body = raw[i + 1:j]
            if body.strip().upper().startswith("MSG,"):
                msg = body.strip()[4:].strip()
            comments.append(body.strip())
            i = j + 1
            continue
        if ch == ";":
            comments.append(raw[i + 1:].strip())
            break
        if ch not in " \t\r":
            out.append(ch.upper())
            cols.append(i)
        i += 1
    return "".join(out), cols, " ".join(c for c in comments if c), msg


_OWORD = re.compile(r"O(<[^>]*>|\d+)(IF|ELSEIF|ELSE|ENDIF|WHILE|ENDWHILE|DO|REPEAT|ENDREPEAT|"
                    r"SUB|ENDSUB|CALL|RETURN|BREAK|CONTINUE)?")
_NGC_WORD = re.compile(r"([A-Z])")


def parse_ngc(lineno: int, raw: str) -> Stmt:
    """Parse one RS274/NGC (LinuxCNC) line."""
    st = _simple_ngc(lineno, raw)
    if st is not None:
        return st
    return parse_ngc_full(lineno, raw)


def parse_ngc_full(lineno: int, raw: str) -> Stmt:
    """Parse one RS274/NGC line with the full grammar."""
    code, cols, comment, msg = _strip_ngc(raw)
    st = FullStmt(line=lineno, text=raw, comment=comment, message=msg)
    st.dialect = "ngc"
    if code.startswith("/"):
        code, cols = code[1:], cols[1:]
        if code[:1].isdigit():           # skip level /1../9
            code, cols = code[1:], cols[1:]
    if not code or code == "%":
        st.empty = msg is None
        return st
    cur = Cursor(code, ngc=True)
    try:
        _parse_ngc_code(st, cur)
    except LineError as exc:
        exc.col = cols[min(exc.col, len(cols) - 1)] if cols else 0
        raise
    except ExprError as exc:
        raise LineError(str(exc), cols[min(exc.col, len(cols) - 1)] if cols else 0) from None
    for w in st.words:
        w.col = cols[min(w.col - 1, len(cols) - 1)] + 1
    st.colmap = cols
    return st


def _parse_ngc_code(st: Stmt, cur: Cursor) -> None:
    t = cur.text
    m = _BLOCKNO.match(t, 0)
    if m and m.group(1):
        st.label = "N" + m.group(1)
        cur.pos = m.end()
    if t.startswith("O", cur.pos):
        m = _OWORD.match(t, cur.pos)
        if m and m.group(2):
            st.kind = "O:" + m.group(2)
            st.target = m.group(1).lower() if m.group(1).startswith("<") else m.group(1)
            cur.pos = m.end()
            if cur.peek() == "[" and m.group(2) in ("IF", "ELSEIF", "WHILE", "REPEAT"):
                st.cond = parse_expr(cur)
            elif m.group(2) in ("CALL", "RETURN", "ENDSUB"):
                args = []
                while cur.peek() == "[":
                    args.append(parse_expr(cur))
                st.case = args
            if cur.peek():
                raise LineError(f"unexpected text after O-word {m.group(2).lower()}", cur.pos)
            return
        if m and not m.group(2):
            st.label = "O" + m.group(1)   # a program number
            cur.pos = m.end()
    while cur.pos < len(t):
        ch = t[cur.pos]
        start = cur.pos
        if ch == "#":
            target = parse_expr(cur)     # parses the parameter reference only (an atom)
            if cur.peek() != "=":
                raise LineError("'=' expected after parameter", cur.pos)
            cur.pos += 1
            val = parse_expr(cur)
            st.assigns.append((target, val, start))
            continue
        if not ch.isalpha():
            raise LineError(f"unexpected '{ch}'", start)
        cur.pos += 1
        nxt = t[cur.pos] if cur.pos < len(t) else ""
        if nxt and nxt in "[#":
            val = parse_expr(cur)
        elif nxt in "+-" and cur.pos + 1 < len(t) and t[cur.pos + 1] in "[#":
            cur.pos += 1
            inner = parse_expr(cur)
            val = ("neg", inner) if nxt == "-" else inner
        else:
            m = _NUM_SIGNED.match(t, cur.pos)
            if not m:
                bad = _NON_LETTERS.match(t, cur.pos).group() or nxt or "end of line"
                raise LineError(f"number expected after address {ch}, found '{bad}'", cur.pos)
            cur.pos = m.end()
            # a letter glued to a number is the next word; anything else is a typo (Y1O)
            if cur.pos < len(t) and t[cur.pos] in "O" and ch not in "GM" and (
                    cur.pos + 1 >= len(t) or not t[cur.pos + 1].isalpha()):
                raise LineError(f"invalid number '{m.group()}{t[cur.pos]}' after address {ch}",
                                m.start())
            val = ("num", float(m.group()))
        st.words.append(Word(ch, val, start + 1))
