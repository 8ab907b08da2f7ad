"""Result types of :func:`reference.planner.plan`: the :class:`ReferencePlan`, its
per-block and per-corner rows (columnar read-only tables) and the stage trace.

Kept apart from the stage composition (:mod:`reference.planner.engine`) so that readers
of a plan (the JSON export, IPO sampling, :mod:`compare`) need not read the planner.
Units: mm, s.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..core.arrays import readonly
from ..core.constraints import BOUND_SETS, ConstraintReport
from ..core.geometry import Path
from ..core.holds import Holds
from ..core.limits import MachineLimits
from ..core.profile import Profile
from ..core.rows import BlockRow
from . import causes as C
from .parameters import PlannerParameters
from .profiles import case_name
from .stops import ACCEL_MODES

__all__ = ["PlannedBlock", "BlockTable", "CornerRow", "CornerTable", "ReferencePlan",
           "TraceEntry"]


class TraceEntry(NamedTuple):
    """One line of the stage trace (a named tuple: unpacks as ``(stage, note)``).

    Attributes
    ----------
    stage : str
        Stage name (``"prepare"``, ``"stops"``, ..., ``"time"``).
    note : str
        What the stage did, for humans.
    """

    stage: str
    note: str


@dataclass(frozen=True, slots=True)
class PlannedBlock(BlockRow):
    """One NC block of the plan: the shared row (:class:`reference.core.rows.BlockRow`,
    whose ``cause`` is ``""`` for blocks that neither move nor wait) plus what only the
    heuristic knows.

    Attributes
    ----------
    mode : str
        Acceleration mode (``"BRISK"``, ``"SOFT"``, ``"DRIVE"``; ``""`` without motion).
    case : str
        Profile case of the planning unit the block lies in (``RISE_ACC+CRUISE+...``).
    """

    mode: str = ""
    case: str = ""


class CornerRow(NamedTuple):
    """One interior segment break (a block transition with motion on both sides); an
    immutable named tuple.

    Attributes
    ----------
    index : int
        Break index ``k`` (between segments ``k-1`` and ``k``).
    s : float
        Path position, mm.
    block_before, block_after : int
        NC blocks on both sides.
    v : float
        Planned speed at the break, mm/s.
    v_limit : float
        The break's own limit (junction rules, horizon, neighbouring caps), mm/s.
    v_g64 : float
        The G64 corner speed alone (``inf`` when tangential), mm/s.
    tangential : bool
        True for tangential transitions.
    cause : str
        Limiting cause of ``v``.
    """

    index: int
    s: float
    block_before: int
    block_after: int
    v: float
    v_limit: float
    v_g64: float
    tangential: bool
    cause: str




class _Table(Sequence):
    """Immutable columnar table of rows: read-only arrays per field, rows made on demand
    (10^5 blocks cost arrays, not 10^5 objects, until someone iterates)."""

    __slots__ = ("_cols", "_n")
    _row: type = tuple
    _fields: tuple[str, ...] = ()

    def __init__(self, **cols) -> None:
        for k, v in cols.items():
            if isinstance(v, np.ndarray):
                cols[k] = readonly(v)
        object.__setattr__(self, "_cols", cols)
        object.__setattr__(self, "_n", len(next(iter(cols.values()))) if cols else 0)

    def __setattr__(self, name, value):
        raise AttributeError(f"{type(self).__name__} is immutable")

    def __len__(self) -> int:
        return self._n

    def column(self, name: str):
        """One column (read-only array or tuple of str), e.g. ``table.column("v_exit")``."""
        if name in self._cols:
            return self._cols[name]
        return tuple(getattr(r, name) for r in self)

    def __getitem__(self, i):
        if isinstance(i, slice):
            return tuple(self[j] for j in range(*i.indices(self._n)))
        if i < 0:
            i += self._n
        if not 0 <= i < self._n:
            raise IndexError(i)
        return self._make(i)

    def __iter__(self):
        for i in range(self._n):
            yield self._make(i)

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self._n} rows)"


class BlockTable(_Table):
    """The per-block rows of a plan (a read-only sequence of :class:`PlannedBlock`)."""

    __slots__ = ()

    def _make(self, i: int) -> PlannedBlock:
        c = self._cols
        cause = int(c["cause_code"][i])
        mode = int(c["mode_code"][i])
        case = int(c["case_code"][i])
        return PlannedBlock(block=int(c["block"][i]), line=int(c["line"][i]), label=c["label"][i],
                        kind=c["kind"][i], length_mm=float(c["length_mm"][i]),
                        v_entry=float(c["v_entry"][i]), v_exit=float(c["v_exit"][i]),
                        v_peak=float(c["v_peak"][i]), time_s=float(c["time_s"][i]),
                        cause=C.CAUSES[cause] if cause >= 0 else "",
                        hold_s=float(c["hold_s"][i]),
                        mode=ACCEL_MODES[mode].name if mode >= 0 else "",
                        case=case_name(case) if case >= 0 else "")


class CornerTable(_Table):
    """The per-corner rows of a plan (a read-only sequence of :class:`CornerRow`)."""

    __slots__ = ()

    def _make(self, i: int) -> CornerRow:
        c = self._cols
        return CornerRow(index=int(c["index"][i]), s=float(c["s"][i]),
                         block_before=int(c["block_before"][i]),
                         block_after=int(c["block_after"][i]), v=float(c["v"][i]),
                         v_limit=float(c["v_limit"][i]), v_g64=float(c["v_g64"][i]),
                         tangential=bool(c["tangential"][i]),
                         cause=C.CAUSES[int(c["cause_code"][i])])


@dataclass(frozen=True, slots=True, eq=False)
class ReferencePlan:
    """Result of :func:`plan`.

    Attributes
    ----------
    program : str
        Program file.
    machine : str
        Machine name.
    path : Path
        The path the profile runs on.
    profile : Profile
        The planned motion.
    blocks : BlockTable
        One :class:`PlannedBlock` per NC block (in ``path.blocks`` order); a read-only
        sequence, columns via ``blocks.column(name)``.
    corners : CornerTable
        One :class:`CornerRow` per interior segment break.
    holds : Holds
        The imposed holds (dwell, exact-stop settle) contained in ``profile``; the
        oracle must be given the same (:func:`reference.holds.imposed_holds`).
    trace : tuple[TraceEntry, ...]
        ``(stage, note)`` pairs in stage order.
    bound_set : str
        ``"jerk"`` if every segment is SOFT, else ``"acc"`` (key of ``BOUND_SETS``).
    report : ConstraintReport or None
        ``check_profile`` of the own profile (``None`` when planned with
        ``check=False``).
    limits : MachineLimits
        The machine limits used.
    parameters : PlannerParameters
        The model parameters used.
    segment_cause : numpy.ndarray of int, shape (m,), optional
        Limiting cause code per path segment (index into
        :data:`reference.planner.causes.CAUSES`): what the rows of inserted blocks
        (corner roundings) report.
    """

    program: str
    machine: str
    path: Path
    profile: Profile
    blocks: BlockTable
    corners: CornerTable
    holds: Holds
    trace: tuple[TraceEntry, ...]
    bound_set: str
    report: ConstraintReport | None
    limits: MachineLimits
    parameters: PlannerParameters
    segment_cause: np.ndarray | None = None

    @property
    def time_s(self) -> float:
        """Total planned time, s."""
        return self.profile.duration

    @property
    def ok(self) -> bool:
        """True when the own profile keeps the declared bound set (False if unchecked)."""
        return self.report is not None and self.report.ok(BOUND_SETS[self.bound_set])
