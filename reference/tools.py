"""Tool data for tool radius compensation: the radius of each cutting edge of each tool.

Three sources, in the order in which a later one overrides an earlier one:

* the ``[tools]`` table of ``machine.toml`` (the control's tool offset memory)::

      [tools]
      1 = { D1 = 5.0, D2 = 4.95 }   # tool T1: radius of cutting edge D1, D2, mm
      "END MILL 10" = { D1 = 5.0 }  # a tool by name (tool management)
      2 = 3.0                       # a bare number is the radius of edge D1

* a LinuxCNC tool table file (``--tool-table``, :func:`load_linuxcnc_tool_table`): lines
  ``T<n> P<pocket> D<diameter> ...`` with ``;`` comments; the diameter ``D`` gives the
  radius of edge 1 of tool ``n`` (LinuxCNC has one edge per tool);
* the program itself (``$TC_DP6[t,d]``, ``G10 L1 P R``, ``G41.1 D``), which the parser
  records per block (:attr:`reference.nc.program.Modal.tool_radius_mm`) and which wins
  over both tables.

A negative radius is accepted: both controls then compensate on the other side (LinuxCNC
``convert_cutter_compensation_on``: "switch side & make radius positive").
Units: mm inside; a tool table file in inch is converted once on reading.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path as FsPath
from typing import Any

from .core.errors import MachineDataError
from .core.units import MM_PER_INCH

#: Largest accepted tool radius magnitude, mm. The largest face mills are about 0.5 m
#: across; a radius beyond 1 m is a unit or typing error.
MAX_TOOL_RADIUS_MM = 1000.0

ToolKey = tuple[int | str, int]


@dataclass(frozen=True, slots=True)
class ToolTable:
    """Radius per ``(tool, cutting edge)``.

    Attributes
    ----------
    entries : tuple[tuple[tuple[int or str, int], float], ...]
        ``((tool, edge), radius_mm)`` pairs; a tool is a number or a name.
    source : str
        Where the table came from (for messages), ``""`` if empty.
    """

    entries: tuple[tuple[ToolKey, float], ...] = ()
    source: str = ""

    def radius(self, tool: int | str | None, edge: int) -> float | None:
        """Radius of ``edge`` of ``tool``, mm, or ``None`` if the table has none."""
        for key, r in self.entries:
            if key == (tool, edge):
                return r
        return None

    def merged(self, other: "ToolTable") -> "ToolTable":
        """This table with the entries of ``other`` added; ``other`` wins on a key both
        have."""
        keys = {k for k, _ in other.entries}
        entries = tuple(e for e in self.entries if e[0] not in keys) + other.entries
        source = " + ".join(s for s in (self.source, other.source) if s)
        return ToolTable(entries, source)

    def __len__(self) -> int:
        return len(self.entries)


EMPTY_TOOLS = ToolTable()


def _radius(value: Any, key: str, source: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise MachineDataError(key, value, "must be a number (tool radius in mm)", source)
    if value != value or not abs(value) <= MAX_TOOL_RADIUS_MM:
        raise MachineDataError(key, value, f"must be a finite radius of at most "
                               f"{MAX_TOOL_RADIUS_MM:g} mm (the unit is mm)", source)
    return float(value)


def tools_from_toml(section: Any, source: str) -> ToolTable:
    """The ``[tools]`` section of ``machine.toml`` as a :class:`ToolTable`.

    Parameters
    ----------
    section : dict
        ``{tool: {"D1": radius, ...}}`` or ``{tool: radius}`` (edge D1); a tool key of
        digits is a tool number, any other key a tool name.
    source : str
        File name for messages.

    Returns
    -------
    ToolTable

    Raises
    ------
    MachineDataError
        Naming the key (``tools.1.D2``), the value and the rule.
    """
    if not isinstance(section, dict):
        raise MachineDataError("tools", section, "must be a table: [tools] with one entry "
                               "per tool, e.g. 1 = { D1 = 5.0 }", source)
    entries: list[tuple[ToolKey, float]] = []
    for name, value in section.items():
        tool: int | str = int(name) if name.isdigit() else name
        if not str(name).strip():
            raise MachineDataError("tools", name, "a tool name must not be empty", source)
        if isinstance(value, dict):
            if not value:
                raise MachineDataError(f"tools.{name}", value, "needs at least one cutting "
                                       "edge, e.g. { D1 = 5.0 }", source)
            for edge_key, r in value.items():
                m = re.fullmatch(r"D([1-9]\d{0,4})", edge_key)
                if not m:
                    raise MachineDataError(f"tools.{name}.{edge_key}", r, "unknown key; a "
                                           "cutting edge is D1, D2, ... (radius in mm)",
                                           source)
                entries.append(((tool, int(m.group(1))),
                                _radius(r, f"tools.{name}.{edge_key}", source)))
        else:
            entries.append(((tool, 1), _radius(value, f"tools.{name}", source)))
    return ToolTable(tuple(entries), f"{source} [tools]")


_TT_WORD = re.compile(r"([A-Za-z])\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)")


def load_linuxcnc_tool_table(path: str | FsPath, units: str = "mm") -> ToolTable:
    """Read a LinuxCNC tool table file.

    Each non-empty line is ``T<tool> P<pocket> [X.. Y.. Z.. A.. B.. C.. U.. V.. W..]
    [D<diameter>] [I..] [J..] [Q..] [;comment]`` (LinuxCNC "Tool Table Format"). Only
    ``T`` and ``D`` matter here: edge 1 of tool ``T`` gets the radius ``D / 2``.

    Parameters
    ----------
    path : str or pathlib.Path
        The file.
    units : {"mm", "inch"}
        Units of the table (LinuxCNC keeps it in machine units).

    Returns
    -------
    ToolTable

    Raises
    ------
    MachineDataError
        Missing file, or a line that is not a tool entry (naming file and line).
    """
    p = FsPath(path)
    if units not in ("mm", "inch"):
        raise MachineDataError("--tool-table-units", units, "must be mm or inch", str(path))
    if not p.is_file():
        raise MachineDataError("--tool-table", str(path), "file not found")
    scale = MM_PER_INCH if units == "inch" else 1.0
    try:
        text = p.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as exc:
        raise MachineDataError("--tool-table", str(path), f"is not UTF-8 text (byte "
                               f"{exc.start})") from None
    entries: dict[ToolKey, float] = {}
    for num, raw in enumerate(text.splitlines(), start=1):
        code = raw.split(";", 1)[0].strip()
        if not code:
            continue
        where = f"{path}:{num}"
        words: dict[str, float] = {}
        pos = 0
        for m in _TT_WORD.finditer(code):
            if code[pos:m.start()].strip():
                raise MachineDataError("tool table line", code, f"unexpected "
                                       f"'{code[pos:m.start()].strip()}' (a tool table line "
                                       "is T<n> P<n> D<diameter> ...)", where)
            letter = m.group(1).upper()
            if letter in words:
                raise MachineDataError("tool table line", code, f"{letter} appears "
                                       "twice", where)
            words[letter] = float(m.group(2))
            pos = m.end()
        if code[pos:].strip():
            raise MachineDataError("tool table line", code, f"unexpected "
                                   f"'{code[pos:].strip()}'", where)
        if "T" not in words:
            raise MachineDataError("tool table line", code, f"a tool table line needs "
                                   "T<tool number>", where)
        t = words["T"]
        if t != int(t) or t < 0:
            raise MachineDataError("tool table line", code, f"T{t:g} must be a whole "
                                   "number >= 0", where)
        radius = words.get("D", 0.0) * scale / 2.0
        if not abs(radius) <= MAX_TOOL_RADIUS_MM:
            raise MachineDataError("tool table line", code, f"diameter D{words['D']:g} "
                                   f"is beyond {2 * MAX_TOOL_RADIUS_MM:g} mm: check the "
                                   "units (--tool-table-units)", where)
        entries[(int(t), 1)] = radius
    return ToolTable(tuple(entries.items()), str(path))


__all__ = ["EMPTY_TOOLS", "MAX_TOOL_RADIUS_MM", "ToolTable", "load_linuxcnc_tool_table",
           "tools_from_toml"]
