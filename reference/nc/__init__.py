"""NC programs in both dialects: SINUMERIK (``.mpf``, ``.spf``) and RS274/NGC as used by
LinuxCNC (``.ngc``, ``.nc``, ``.tap``).

``parse_file`` / ``parse_text`` return a :class:`~reference.nc.program.Program` of
resolved blocks (absolute positions in mm / degrees, feeds in mm/s) or raise
:class:`~reference.core.errors.NCSyntaxError` naming file, line and column.
"""

from __future__ import annotations

import gc
from pathlib import Path as FsPath

from ..core.errors import NCSyntaxError
from .expr import ExprError
from .interp import MAX_EXECUTED_BLOCKS, run
from .lines import LineError, parse_ngc, parse_sinumerik
from .program import Block, Program, ProgramWarning, Tangential

DIALECT_BY_SUFFIX = {".mpf": "sinumerik", ".spf": "sinumerik", ".ngc": "ngc", ".nc": "ngc",
                     ".tap": "ngc"}


def _split_lines(text: str) -> list[str]:
    # CRLF, CR and LF in any mix; a trailing line end adds no empty line
    return text.replace("\r\n", "\n").replace("\r", "\n").split("\n")


def parse_text(text: str, file: str = "<string>", dialect: str = "sinumerik", *,
               max_repeats: int = MAX_EXECUTED_BLOCKS) -> Program:
    """Parse NC program text.

    Parameters
    ----------
    text : str
        Program text.
    file : str
        Name used in messages.
    dialect : {"sinumerik", "ngc"}
        NC dialect.
    max_repeats : int
        Endless-loop guard: the most lines executed *again* (loop passes, jumps back,
        subprogram calls) beyond each statement's first run. A loop-free program of
        any length passes it.

    Returns
    -------
    Program

    Raises
    ------
    NCSyntaxError
        Naming file, 1-based line and column.
    """
    if dialect not in ("sinumerik", "ngc"):
        raise NCSyntaxError(file, 1, 1, f"unknown dialect {dialect!r} (sinumerik or ngc)")
    # The parser allocates a few objects per line and creates no reference cycles; the
    # cyclic collector would only re-scan the growing block list (about 30 % of the time
    # for 10^5 lines). It is paused for the call and restored as it was.
    collecting = gc.isenabled()
    gc.disable()
    try:
        return _parse(text, file, dialect, max_repeats)
    finally:
        if collecting:
            gc.enable()


def _parse(text: str, file: str, dialect: str, max_repeats: int) -> Program:
    lines = _split_lines(text)
    if lines and lines[-1] == "":
        lines.pop()
    parse_line = parse_ngc if dialect == "ngc" else parse_sinumerik
    stmts = []
    for i, raw in enumerate(lines, start=1):
        try:
            st = parse_line(i, raw)
        except LineError as exc:
            raise NCSyntaxError(file, i, _col(raw, exc.col, dialect), str(exc)) from None
        except ExprError as exc:
            raise NCSyntaxError(file, i, _col(raw, exc.col, dialect), str(exc)) from None
        if not st.empty or st.kind != "block":
            stmts.append(st)
    return run(file, dialect, stmts, tuple(lines), max_repeats=max_repeats)


def _col(raw: str, col0: int, dialect: str) -> int:
    """1-based column; SINUMERIK columns index the line as written (upper-casing keeps it)."""
    return max(1, min(col0 + 1, len(raw) + 1))


def parse_file(path: str | FsPath, dialect: str | None = None) -> Program:
    """Read and parse a program file; the dialect follows the extension unless given.

    Raises
    ------
    NCSyntaxError
        Unknown extension without ``dialect``, or any error in the program.
    OSError
        The file cannot be read.
    """
    p = FsPath(path)
    if dialect is None:
        dialect = DIALECT_BY_SUFFIX.get(p.suffix.lower())
        if dialect is None:
            raise NCSyntaxError(str(path), 1, 1, f"unknown program extension "
                                f"'{p.suffix}': use .mpf/.spf (SINUMERIK) or .ngc/.nc/.tap "
                                "(LinuxCNC), or give --dialect")
    data = p.read_bytes()
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        text = data.decode("latin-1")
    return parse_text(text, str(path), dialect)


__all__ = ["Block", "DIALECT_BY_SUFFIX", "Program", "ProgramWarning", "Tangential",
           "parse_file", "parse_text"]
