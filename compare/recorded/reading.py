"""Reading a recorded trajectory: the first stage of ``feedoracle check``.

A recording is a CSV file with a header ``t,X,Y,Z[,A,...]`` (time in s, linear axes in
mm, rotary axes in degrees; a unit may be given in brackets: ``t[ms]``, ``X[in]``,
``A[deg]``, or in parentheses), one row per sample, at a constant or varying period.
Lines starting with ``#`` are comments; ``;`` is accepted as the delimiter.

:func:`read_trajectory` validates the header, the units, every number and the strictly
increasing time; every problem is a :class:`TrajectoryError` naming file and row.
:func:`align_axes` then puts the recorded columns in the path's axis order.

Inputs
    a CSV file; the path's axis names and rotary flags (to pick the unit table and to
    name what is missing).
Outputs
    :class:`Recording` (times, s, shape ``(N,)``; positions, mm / degrees, shape
    ``(N, n)``; the file line of each sample) and, from :func:`align_axes`, the positions
    in the path's axis order, shape ``(N, n_axes)``.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path as FsPath

import numpy as np

from reference.core.errors import TrajectoryError
from reference.core.geometry import Path

#: Unit suffixes accepted in the header and their factor to s / mm / degrees.
TIME_UNITS = {"s": 1.0, "ms": 1e-3}
LINEAR_UNITS = {"mm": 1.0, "in": 25.4, "inch": 25.4}
ROTARY_UNITS = {"deg": 1.0, "°": 1.0}

#: Columns that are not axes: the path position and speed that ``feedoracle plan --csv``
#: writes beside the axes. They are ignored; ``s`` is always recomputed by projection.
IGNORED_COLUMNS = ("s", "v")


@dataclass(frozen=True, slots=True)
class Recording:
    """A recorded trajectory as read from CSV.

    Attributes
    ----------
    file : str
        File name as given.
    axes : tuple[str, ...]
        Axis names of the columns after ``t``.
    t : numpy.ndarray, shape (N,)
        Sample times, s, strictly increasing.
    q : numpy.ndarray, shape (N, n)
        Axis positions, mm / degrees.
    rows : numpy.ndarray of int, shape (N,)
        1-based line of each sample in the file.
    """

    file: str
    axes: tuple[str, ...]
    t: np.ndarray
    q: np.ndarray
    rows: np.ndarray


def _header_name(raw: str, file: str) -> tuple[str, str | None]:
    name = raw.strip()
    unit = None
    if "[" in name and name.endswith("]"):
        name, unit = name[:-1].split("[", 1)
        name, unit = name.strip(), unit.strip()
    elif "(" in name and name.endswith(")"):
        name, unit = name[:-1].split("(", 1)
        name, unit = name.strip(), unit.strip()
    return name, unit


def read_trajectory(file: str | FsPath, path_axes: tuple[str, ...] = (),
                    rotary: tuple[bool, ...] = ()) -> Recording:
    """Read and validate a recorded trajectory.

    Parameters
    ----------
    file : path
        CSV file with header ``t,X,Y,Z[,...]``.
    path_axes : tuple[str, ...]
        Axes of the program's path (to name what is missing or extra).
    rotary : tuple[bool, ...]
        Rotary flag per path axis (for unit checks).

    Returns
    -------
    Recording

    Raises
    ------
    TrajectoryError
        Naming file and row: no header, unknown unit, wrong column count, a value that
        is not a finite number, time not strictly increasing, fewer than 3 samples.
    """
    name = str(file)
    text = FsPath(file).read_text(encoding="utf-8-sig", errors="replace")
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    header_row = next((i for i, ln in enumerate(lines) if ln.strip()
                       and not ln.lstrip().startswith("#")), None)
    if header_row is None:
        raise TrajectoryError(f"{name}: empty file (expected a header t,X,Y,Z)")
    delim = ";" if lines[header_row].count(";") > lines[header_row].count(",") else ","
    cols = next(csv.reader([lines[header_row]], delimiter=delim))
    parsed = [_header_name(c, name) for c in cols]
    tname, tunit = parsed[0]
    if tname.lower() not in ("t", "time", "t_s"):
        raise TrajectoryError(f"{name}:{header_row + 1}: first column is {cols[0]!r}, expected "
                              f"'t' (time in s), then one column per axis (X,Y,Z,...)")
    tfac = 1.0 if tunit is None else TIME_UNITS.get(tunit.lower())
    if tfac is None:
        raise TrajectoryError(f"{name}:{header_row + 1}: time unit {tunit!r} not supported "
                              f"(use s or ms)")
    rot = dict(zip(path_axes, rotary))
    axes, facs, used = [], [], [0]
    for ci, (raw, (ax, unit)) in enumerate(zip(cols[1:], parsed[1:]), start=1):
        if ax in IGNORED_COLUMNS:
            continue
        used.append(ci)
        ax = ax.upper()
        if not ax or not ax.replace("_", "").isalnum():
            raise TrajectoryError(f"{name}:{header_row + 1}: column {raw!r} is not an axis name")
        if ax in axes:
            raise TrajectoryError(f"{name}:{header_row + 1}: axis {ax} appears twice")
        is_rot = rot.get(ax, ax in ("A", "B", "C"))
        table = ROTARY_UNITS if is_rot else LINEAR_UNITS
        f = 1.0 if unit is None else table.get(unit.lower())
        if f is None:
            raise TrajectoryError(
                f"{name}:{header_row + 1}: column {raw!r}: unit {unit!r} not supported "
                f"(use {' or '.join(table)})")
        axes.append(ax)
        facs.append(f)
    if not axes:
        raise TrajectoryError(f"{name}:{header_row + 1}: no axis columns after 't'")
    data, rows = [], []
    for i in range(header_row + 1, len(lines)):
        ln = lines[i]
        if not ln.strip() or ln.lstrip().startswith("#"):
            continue
        cells = next(csv.reader([ln], delimiter=delim))
        if len(cells) != len(cols):
            raise TrajectoryError(f"{name}:{i + 1}: {len(cells)} values, the header has "
                                  f"{len(cols)} columns")
        vals = []
        for c, cell in zip(cols, cells):
            try:
                x = float(cell)
            except ValueError:
                raise TrajectoryError(f"{name}:{i + 1}: column {c.strip()!r}: "
                                      f"{cell.strip()!r} is not a number") from None
            if not math.isfinite(x):
                raise TrajectoryError(f"{name}:{i + 1}: column {c.strip()!r}: "
                                      f"{cell.strip()!r} is not a finite number")
            vals.append(x)
        data.append(vals)
        rows.append(i + 1)
    if len(data) < 3:
        raise TrajectoryError(f"{name}: {len(data)} sample(s); at least 3 are needed")
    arr = np.array(data, dtype=np.float64)[:, used]
    t = arr[:, 0] * tfac
    q = arr[:, 1:] * np.array(facs)
    dt = np.diff(t)
    if np.any(dt <= 0):
        k = int(np.flatnonzero(dt <= 0)[0])
        raise TrajectoryError(f"{name}:{rows[k + 1]}: time {float(arr[k + 1, 0])!r} is not "
                              f"after the previous row's {float(arr[k, 0])!r} (time must "
                              f"increase)")
    return Recording(file=name, axes=tuple(axes), t=t, q=q, rows=np.array(rows))


def align_axes(rec: Recording, path: Path) -> np.ndarray:
    """The recording's positions in the path's axis order, shape ``(N, n)``.

    Axes the path has but the recording lacks must not move on the path (they are
    filled with the path's constant value); recorded axes the path lacks must stay
    constant.

    Raises
    ------
    TrajectoryError
        A moving axis missing on either side.
    """
    N = rec.t.size
    out = np.empty((N, path.n_axes))
    q0 = path.evaluate(0.0)[0][0] if path.n_segments else np.zeros(path.n_axes)
    probe = path.evaluate(np.linspace(0, path.total_length, 200))[0] if path.n_segments \
        else np.zeros((1, path.n_axes))
    for i, ax in enumerate(path.axes):
        if ax in rec.axes:
            out[:, i] = rec.q[:, rec.axes.index(ax)]
        elif np.ptp(probe[:, i]) > 1e-9:
            raise TrajectoryError(f"{rec.file}: no column for axis {ax}, which the program "
                                  f"moves (columns: {', '.join(rec.axes)})")
        else:
            out[:, i] = q0[i]
    for j, ax in enumerate(rec.axes):
        if ax not in path.axes and np.ptp(rec.q[:, j]) > 1e-9:
            k = int(np.argmax(np.abs(rec.q[:, j] - rec.q[0, j]) > 1e-9))
            raise TrajectoryError(f"{rec.file}:{rec.rows[k]}: axis {ax} moves, but the "
                                  f"program's path has no axis {ax} "
                                  f"(path axes: {', '.join(path.axes)})")
    return out
