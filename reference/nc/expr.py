"""Safe arithmetic expressions of both NC dialects (never Python ``eval``).

Expressions are parsed once into a tiny AST of tuples and evaluated many times (loops
re-run their lines). Trigonometric functions work in degrees, as on both controls.

Operator priorities follow each control's manual (equal priority: left to right):

* SINUMERIK (programming manual, "Priority of the operations"), high to low: unary
  ``NOT B_NOT - +``; ``* / DIV MOD``; ``+ -``; ``B_AND``; ``B_XOR``; ``B_OR``; ``AND``;
  ``XOR``; ``OR``; comparisons ``== <> < > <= >=``. Comparisons bind *weakest*, so
  ``R1==1 AND R2==2`` groups as ``R1 == (1 AND R2) == 2``, as on the control: write
  ``(R1==1) AND (R2==2)``.
* RS274/NGC (LinuxCNC), high to low: ``**``; ``* / MOD``; ``+ -``; comparisons
  ``EQ NE LT GT LE GE`` (also ``== <> < > <= >=``); ``AND OR XOR`` (one level).

Atoms: numbers, variables (``R1``, ``R[2]``, ``#5``, ``#<name>``, declared names),
parenthesised (SINUMERIK) or bracketed (NGC) expressions, function calls (``SIN(30)``,
``SIN[30]``, ``ATAN[y]/[x]``).
"""

from __future__ import annotations

import math
import re
from typing import Callable, Mapping

NUMBER = re.compile(r"\d+\.?\d*|\.\d+")
#: Deepest expression accepted: brackets, function calls, unary signs, ``#`` indirections
#: and chained binary operators together. Hand-written macros nest a handful of levels
#: and CAM writes plain numbers, so 100 leaves a wide margin; the bound keeps the
#: recursive parser and evaluator (at most three Python frames per level) far inside
#: Python's recursion limit of 1000 frames, so a hostile line gets a message at its
#: column instead of a RecursionError.
MAX_EXPR_DEPTH = 100
NAME = re.compile(r"[A-Z_$][A-Z0-9_$]*")
#: SINUMERIK exponent notation glued to a number: ``EX`` is the control's (1.5EX-3 =
#: 0.0015); a bare ``E`` (Python's 1e-3) is not, see :func:`sin_exponent`.
_EXPONENT = re.compile(r"E(X?)([-+]?\d+)")
_DIGITS = re.compile(r"\d+")
#: Numbered parameters of LinuxCNC: #1..#5602 (RS274NGC_MAX_PARAMETERS); anything else
#: is "parameter number out of range" on the control.
NGC_MAX_PARAMETER = 5602

_D = math.pi / 180.0
FUNCS1: dict[str, Callable[[float], float]] = {
    "SIN": lambda x: math.sin(x * _D), "COS": lambda x: math.cos(x * _D),
    "TAN": lambda x: math.tan(x * _D),
    "ASIN": lambda x: math.asin(x) / _D, "ACOS": lambda x: math.acos(x) / _D,
    "ATAN": lambda x: math.atan(x) / _D,
    "SQRT": math.sqrt, "ABS": abs, "EXP": math.exp, "LN": math.log,
    "TRUNC": lambda x: float(math.trunc(x)),
    "ROUND": lambda x: float(math.copysign(math.floor(abs(x) + 0.5), x)),  # halves away from 0
    "FIX": lambda x: float(math.floor(x)), "FUP": lambda x: float(math.ceil(x)),
    "POT": lambda x: x * x, "EXISTS": lambda x: 1.0,
}
FUNCS2: dict[str, Callable[[float, float], float]] = {
    "ATAN2": lambda y, x: math.atan2(y, x) / _D,
    "MINVAL": min, "MAXVAL": max,
}
def _div(a: float, b: float) -> float:      # zero divisors are caught before
    return a / b


_FN: dict[str, Callable[[float, float], float]] = {
    "OR": lambda a, b: float(bool(a) or bool(b)),
    "XOR": lambda a, b: float(bool(a) != bool(b)),
    "AND": lambda a, b: float(bool(a) and bool(b)),
    "B_OR": lambda a, b: float(int(a) | int(b)),
    "B_XOR": lambda a, b: float(int(a) ^ int(b)),
    "B_AND": lambda a, b: float(int(a) & int(b)),
    "==": lambda a, b: float(a == b), "EQ": lambda a, b: float(a == b),
    "<>": lambda a, b: float(a != b), "NE": lambda a, b: float(a != b),
    "<": lambda a, b: float(a < b), "LT": lambda a, b: float(a < b),
    ">": lambda a, b: float(a > b), "GT": lambda a, b: float(a > b),
    "<=": lambda a, b: float(a <= b), "LE": lambda a, b: float(a <= b),
    ">=": lambda a, b: float(a >= b), "GE": lambda a, b: float(a >= b),
    "+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b,
    "/": _div, "**": lambda a, b: a ** b, "^": lambda a, b: a ** b,
}
#: Binding strength per dialect (higher binds tighter); see the module docstring.
_PREC_SIN = {"==": 1, "<>": 1, "<": 1, ">": 1, "<=": 1, ">=": 1,
             "EQ": 1, "NE": 1, "LT": 1, "GT": 1, "LE": 1, "GE": 1,
             "OR": 2, "XOR": 3, "AND": 4, "B_OR": 5, "B_XOR": 6, "B_AND": 7,
             "+": 8, "-": 8, "*": 9, "/": 9, "DIV": 9, "MOD": 9, "**": 10, "^": 10}
_PREC_NGC = {"AND": 1, "OR": 1, "XOR": 1,
             "==": 2, "<>": 2, "<": 2, ">": 2, "<=": 2, ">=": 2,
             "EQ": 2, "NE": 2, "LT": 2, "GT": 2, "LE": 2, "GE": 2,
             "+": 3, "-": 3, "*": 4, "/": 4, "MOD": 4, "**": 5, "^": 5}
_SYMOPS = ("**", "==", "<>", "<=", ">=", "<", ">", "+", "-", "*", "/", "^")
_WORDOPS = ("B_AND", "B_XOR", "B_OR", "OR", "XOR", "AND", "DIV", "MOD", "EQ", "NE", "LT",
            "GT", "LE", "GE")


class ExprError(Exception):
    """A malformed or non-evaluable expression; ``col`` is the 0-based offset."""

    def __init__(self, message: str, col: int) -> None:
        super().__init__(message)
        self.col = col


class Cursor:
    """A position in one (upper-cased) source line."""

    __slots__ = ("text", "pos", "ngc", "depth")

    def __init__(self, text: str, pos: int = 0, ngc: bool = False) -> None:
        self.text = text
        self.pos = pos
        self.ngc = ngc
        self.depth = 0          # nesting of the expression being parsed (MAX_EXPR_DEPTH)

    def ws(self) -> None:
        t, p = self.text, self.pos
        while p < len(t) and t[p] in " \t":
            p += 1
        self.pos = p

    def peek(self) -> str:
        self.ws()
        return self.text[self.pos] if self.pos < len(self.text) else ""

    def match(self, pattern: re.Pattern) -> re.Match | None:
        self.ws()
        m = pattern.match(self.text, self.pos)
        if m:
            self.pos = m.end()
        return m


def parse_expr(cur: Cursor, min_prec: int = 0):
    """Parse an expression at the cursor (precedence climbing). Returns an AST.

    Raises
    ------
    ExprError
        Malformed, or nested deeper than :data:`MAX_EXPR_DEPTH` (at the column where the
        limit is crossed).
    """
    entry = cur.depth
    try:
        left = _atom(cur)
        table = _PREC_NGC if cur.ngc else _PREC_SIN
        while True:
            cur.ws()
            op = _peek_op(cur)
            if op is None or op not in table:
                return left
            prec = table[op]
            if prec < min_prec:
                return left
            op_pos = cur.pos
            cur.pos += len(op)
            # each operator of a chain deepens the (left-leaning) tree the evaluator walks
            _deeper(cur)
            right = parse_expr(cur, prec + 1)         # all operators group left to right
            left = ("bin", op, left, right, op_pos)
    finally:
        cur.depth = entry


def _deeper(cur: Cursor) -> None:
    """One level deeper; past :data:`MAX_EXPR_DEPTH` an error at the cursor."""
    cur.depth += 1
    if cur.depth > MAX_EXPR_DEPTH:
        raise ExprError(f"expression nested too deeply (more than {MAX_EXPR_DEPTH} levels "
                        "of brackets, functions, signs and operators): split it with "
                        "variables", cur.pos)


def _peek_op(cur: Cursor) -> str | None:
    t, p = cur.text, cur.pos
    for op in _SYMOPS:
        if t.startswith(op, p):
            return op
    for op in _WORDOPS:
        if t.startswith(op, p):
            end = p + len(op)
            # NGC text has no spaces (7MOD4); SINUMERIK needs a word boundary (MODE != MOD)
            if cur.ngc or end >= len(t) or not (t[end].isalnum() or t[end] == "_"):
                return op
    return None


def _atom(cur: Cursor):
    entry = cur.depth
    try:
        _deeper(cur)
        return _atom_body(cur)
    finally:
        cur.depth = entry


def _atom_body(cur: Cursor):
    cur.ws()
    start = cur.pos
    ch = cur.peek()
    if not ch:
        raise ExprError("expression expected", start)
    if ch in "+-":
        cur.pos += 1
        inner = _atom(cur)
        return ("neg", inner) if ch == "-" else inner
    for word, kind in (("NOT", "not"), ("B_NOT", "bnot")):
        if not cur.ngc and cur.text.startswith(word, cur.pos):
            end = cur.pos + len(word)
            if end >= len(cur.text) or not (cur.text[end].isalnum() or cur.text[end] == "_"):
                cur.pos = end
                return (kind, _atom(cur))
    if ch == "(" and not cur.ngc or ch == "[" :
        close = ")" if ch == "(" else "]"
        cur.pos += 1
        e = parse_expr(cur)
        if cur.peek() != close:
            raise ExprError(f"missing '{close}'", cur.pos)
        cur.pos += 1
        return e
    if ch == "#":
        return _ngc_param(cur)
    m = cur.match(NUMBER)
    if m:
        if not cur.ngc:
            return ("num", float(m.group() + sin_exponent(cur.text, cur)))
        return ("num", float(m.group()))
    m = cur.match(NAME)
    if not m:
        raise ExprError(f"unexpected '{ch}' in expression", start)
    name = m.group()
    if name in ("TRUE", "FALSE"):
        return ("num", 1.0 if name == "TRUE" else 0.0)
    if name in FUNCS1 or name in FUNCS2:
        opener = cur.peek()
        if opener in "([":
            close = ")" if opener == "(" else "]"
            cur.pos += 1
            args = [parse_expr(cur)]
            while cur.peek() == ",":
                cur.pos += 1
                args.append(parse_expr(cur))
            if cur.peek() != close:
                raise ExprError(f"missing '{close}' after {name}", cur.pos)
            cur.pos += 1
            # NGC two-argument arc tangent: ATAN[y]/[x]
            if cur.ngc and name == "ATAN" and cur.peek() == "/":
                save = cur.pos
                cur.pos += 1
                if cur.peek() == "[":
                    args.append(_atom(cur))
                    return ("call", "ATAN2", args, start)
                cur.pos = save
            if name in FUNCS2 and len(args) != 2 or name in FUNCS1 and len(args) != 1:
                raise ExprError(f"{name} takes {2 if name in FUNCS2 else 1} argument(s)", start)
            return ("call", name, args, start)
    if name.startswith("$"):
        raise ExprError(f"system variable {name} needs a real control and cannot be "
                        "evaluated here", start)
    if cur.peek() == "[" and not cur.ngc:      # R[1], array-like index
        cur.pos += 1
        idx = parse_expr(cur)
        if cur.peek() != "]":
            raise ExprError("missing ']'", cur.pos)
        cur.pos += 1
        return ("idx", name, idx, start)
    return ("var", name, start)


def sin_exponent(text: str, cur: Cursor) -> str:
    """The SINUMERIK exponent glued to the number that ends at ``cur.pos``, as Python text.

    ``EX`` is the control's exponent notation (``1.5EX-3``): returned as ``"E-3"`` and
    consumed. A bare ``E`` with digits (``1E308``, Python's notation) is no NC number on
    the control: read as ``1`` plus an axis ``E308`` it would silently move an axis, so
    it is an error at the ``E``. Returns ``""`` when no exponent follows.

    Raises
    ------
    ExprError
        A bare ``E`` exponent.
    """
    e = _EXPONENT.match(text, cur.pos)
    if e is None:
        return ""
    if not e.group(1):
        raise ExprError(f"'E{e.group(2)}' glued to a number: SINUMERIK writes exponents "
                        f"with EX (EX{e.group(2)}); for an axis E separate the words with "
                        "a blank", cur.pos)
    cur.pos = e.end()
    return "E" + e.group(2)


def _ngc_param(cur: Cursor):
    start = cur.pos
    cur.pos += 1
    ch = cur.peek()
    if ch == "<":
        end = cur.text.find(">", cur.pos)
        if end < 0:
            raise ExprError("missing '>' after '#<'", start)
        name = "#<" + cur.text[cur.pos + 1:end].replace(" ", "").replace("\t", "") + ">"
        cur.pos = end + 1
        return ("var", name, start)
    if ch == "[" or ch == "#":
        return ("pidx", _atom(cur), start)
    m = cur.match(_DIGITS)
    if not m:
        raise ExprError("parameter number expected after '#'", start)
    num = int(m.group())
    _check_parameter(num, start)
    return ("var", f"#{num}", start)


def _check_parameter(num: float, col: int) -> None:
    """An NGC parameter number within #1..#NGC_MAX_PARAMETER, else an error at ``col``."""
    if not (1 <= num <= NGC_MAX_PARAMETER and num == int(num)):
        raise ExprError(f"parameter number #{num:g} is out of range (LinuxCNC has "
                        f"#1..#{NGC_MAX_PARAMETER} and named parameters #<name>)", col)


def ngc_parameter_name(num: float, col: int) -> str:
    """``"#<n>"`` for a computed parameter number (``#[expr]``), checked like a literal.

    Raises
    ------
    ExprError
        Out of range or not a whole number.
    """
    _check_parameter(num, col)
    return f"#{int(num)}"


def evaluate(node, env: Mapping[str, float]) -> float:
    """Evaluate an AST; unknown variables and math errors raise :class:`ExprError`."""
    kind = node[0]
    if kind == "num":
        return node[1]
    if kind == "var":
        name = node[1]
        if name in env:
            return env[name]
        if name.startswith("#") and name[1:].isdigit():
            return 0.0  # numbered NGC parameters default to 0, as in rs274ngc
        raise ExprError(f"unknown variable {name}", node[2])
    if kind == "idx":
        i = evaluate(node[2], env)
        key = f"{node[1]}{int(i)}" if node[1] == "R" else f"{node[1]}[{int(i)}]"
        if key in env:
            return env[key]
        if node[1] == "R":
            return 0.0
        raise ExprError(f"unknown variable {key}", node[3])
    if kind == "pidx":
        i = evaluate(node[1], env)
        return env.get(ngc_parameter_name(i, node[2]), 0.0)
    if kind == "neg":
        return -evaluate(node[1], env)
    if kind == "not":
        return float(not evaluate(node[1], env))
    if kind == "bnot":
        return float(~int(evaluate(node[1], env)))
    if kind == "call":
        args = [evaluate(a, env) for a in node[2]]
        try:
            if node[1] in FUNCS2:
                return float(FUNCS2[node[1]](*args))
            return float(FUNCS1[node[1]](args[0]))
        except (ValueError, OverflowError) as exc:
            raise ExprError(f"{node[1]}({', '.join(f'{a:g}' for a in args)}) is undefined "
                            f"({exc})", node[3]) from None
    if kind == "bin":
        op = node[1]
        a = evaluate(node[2], env)
        b = evaluate(node[3], env)
        if op in ("/", "DIV", "MOD"):
            if b == 0:
                raise ExprError("division by zero", node[4])
            if op == "/":
                return a / b
            if op == "DIV":
                return float(math.trunc(a / b))
            return math.fmod(a, b)
        try:
            return float(_FN[op](a, b))
        except (OverflowError, ValueError, ZeroDivisionError) as exc:
            raise ExprError(f"{a:g} {op} {b:g} is undefined ({exc})", node[4]) from None
    raise ExprError(f"bad expression node {kind}", 0)  # pragma: no cover


def constant(node) -> float | None:
    """The value of a constant AST (a plain number), else ``None``."""
    if node[0] == "num":
        return node[1]
    if node[0] == "neg" and node[1][0] == "num":
        return -node[1][1]
    return None
