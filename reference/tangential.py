"""Stage: tangential control (TANG, TANGON, TANGOF, TLIFT), after tool radius
compensation and before rounding (DESIGN section 5, sinumerik-model 10).

A following rotary axis (``TANG(C, X, Y, k)``) tracks the tangent of the path in the
plane of its two leading axes: ``C = k phi + offset + C_programmed`` with ``phi`` the
tangent angle ``atan2(t_Y, t_X)`` in degrees, unwrapped continuously, ``offset`` the
TANGON angle and ``C_programmed`` a position of the axis the program writes ("an
explicitly programmed position of the following axis is added to the offset angle",
10). The axis becomes a real component of every segment, so its velocity, acceleration
and jerk limits enter the heuristic, the oracle and the checker through the one axis
kinematics of the rulebook:

* on a line ``phi`` is constant; on an arc or helix in the plane of the leading axes
  ``phi`` changes linearly with ``s`` (``dphi/ds = omega``), so ``C`` is a linear
  component ``d_C = k omega 180/pi`` (deg/mm) of the helical segment, exact. On a
  spiral (an arc whose radii differ within the arc tolerance) ``C`` runs linearly between
  the exact tangents at both ends; inside it differs from the exact tangent by the
  change of ``atan(dr/dt / r)``, below 1e-3 degrees for the accepted radius errors.
  A segment without motion in the leading plane (a Z infeed) has no tangent: the axis
  keeps its angle, and the next tangent is compared with the last one before it (a
  "hidden corner in space": the projection onto the leading plane is what counts, T3).
* at a corner (the tangent angle steps by ``dphi``):

  - TLIFT active and ``|dphi|`` above MD37400 EPS_TLIFT_TANG_STEP of the axis: an
    intermediate block of kind ``"tlift"`` is inserted in front of the block causing the
    step (T3, "before the block causing the tangential jump"), owned by that block. The
    path rests at both its ends ("at the beginning of the intermediate block, the path
    velocity of the leading axes is zero") and the following axis turns alone to the new
    tangent, "as fast as possible" within its own limits (feed unlimited, only the axis
    limits apply); the block transition is therefore never rounded.
  - otherwise (no TLIFT, a step within EPS_TLIFT_TANG_STEP, or the block before the
    corner in a rounding mode G641..G645/RND/RNDM: "in blocks with G641 rounding, no
    intermediate block is generated", T3; the model applies it to every rounding mode
    [I]): the axis reaches its new alignment at the end of the next block, moving
    linearly in ``s`` over it ("the path velocity is reduced to such an extent that the
    following axis reaches its new alignment synchronously with the target position of
    the leading axes", T3; "aligns the axis only in the next path segment" [S20]). Its
    velocity step at the corner is then an ordinary axis velocity jump, which the
    shared junction rule limits like that of any other axis.

  At TANGON the axis turns from where it is to the first tangent in the same way (the
  branch of ``phi`` nearest to its position).
* after TANGOF the axis stays where it is; a later programmed position of it is
  approached from there.

The corner rounding stage runs afterwards on this path; it rounds only corners where
geometry axes alone move, so a corner with the tangential axis moving is passed as G64
(its decision table says so).

Errors: the following axis missing on the machine (``MachineDataError`` naming the axis
and the line), a linear following axis, leading axes that are not geometry axes, an arc
outside the leading plane (its tangent angle is not linear in ``s``): ``PathError``
naming the line. Units: degrees for the following axis, mm for the path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .core.errors import MachineDataError, PathError
from .core.geometry import KIND_CODES, Path, line_segments
from .core.tolerances import MOVING_AXIS_TOL, POS_TOL_MM
from .machine import Machine
from .nc.program import Program
from .rounding import ROUNDING_MODES
from .splice import ROW_KEYS, copy_rows, splice

_TLIFT = KIND_CODES.index("tlift")
#: A segment has a tangent in the leading plane when the plane part of ``q'`` is at
#: least this long (1): the same threshold as a moving axis.
_PLANE_TANGENT_MIN = MOVING_AXIS_TOL
#: Two tangent angles are the same, degrees (round-off of atan2 on unit vectors).
_ANGLE_TOL_DEG = 1e-9


@dataclass(frozen=True, slots=True)
class TangentialCorner:
    """What the stage did where the following axis had to turn.

    Attributes
    ----------
    axis : str
        Following axis.
    block : int
        Program block in front of which the axis turns (the block causing the step).
    step_deg : float
        Tangent angle step (degrees of the tangent; the axis turns ``coupling`` times it).
    action : str
        ``"TLIFT block"``, or how the step is taken without one and why.
    """

    axis: str
    block: int
    step_deg: float
    action: str


@dataclass(frozen=True, slots=True, eq=False)
class TangentialResult:
    """The path with the following axes and the corners of each.

    Attributes
    ----------
    path : Path
    corners : tuple[TangentialCorner, ...]
    """

    path: Path
    corners: tuple[TangentialCorner, ...] = ()


def apply_tangential(path: Path, program: Program, machine: Machine) -> Path:
    """The path with tangential control applied (:func:`tangential_path` ``.path``)."""
    return tangential_path(path, program, machine).path


def tangential_path(path: Path, program: Program, machine: Machine) -> TangentialResult:
    """Make every following axis of the program track the path tangent.

    Parameters
    ----------
    path : Path
        After tool radius compensation, over the machine's axes.
    program : Program
        Its program (``Block.tangential`` per block).
    machine : Machine
        Axis limits (the following axis must exist) and MD37400 per axis.

    Returns
    -------
    TangentialResult

    Raises
    ------
    MachineDataError
        The machine has no such axis (names the axis and the line).
    PathError
        A linear following axis, non-geometry leading axes, an arc outside the leading
        plane (names the line).
    """
    blocks = program.blocks
    # consecutive blocks share one modal state: look at each change of it once, and at
    # each tangential record with the first block that uses it (for messages)
    firsts: dict = {}
    prev = None
    for b in blocks:
        md = b.modal
        if md is not prev:
            prev = md
            if md.tangential is not None and md.tangential not in firsts:
                firsts[md.tangential] = b
    if path.n_segments == 0 or not firsts:
        return TangentialResult(path)
    corners: list[TangentialCorner] = []
    for axis in dict.fromkeys(t.axis for t in firsts):
        mine = {t: b for t, b in firsts.items() if t.axis == axis}
        first = min(mine.values(), key=lambda b: b.index)
        where = f"{program.file}:{first.line}"
        if axis not in machine.limits.names or axis not in path.axes:
            raise MachineDataError(f"axis.{axis}", None,
                                   f"{where}: tangential control turns axis {axis}, but "
                                   f"machine '{machine.name}' defines no limits for it (add "
                                   f"an [axis.{axis}] section)")
        f = path.axes.index(axis)
        if not path.rotary[f]:
            raise PathError(f"{where}: the following axis {axis} of tangential control "
                            "must be a rotary axis", first.index)
        for t, b in mine.items():
            for lead in t.leading:
                if lead not in ("X", "Y", "Z") or lead not in path.axes:
                    raise PathError(f"{program.file}:{b.line}: the leading axes of "
                                    f"TANG({axis}, ...) must be geometry axes (X, Y, Z), "
                                    f"got {lead}", b.index)
        path, got = _follow(path, program, machine, axis, f)
        corners.extend(got)
    return TangentialResult(path, tuple(corners))


def _follow(path: Path, program: Program, machine: Machine, axis: str,
            f: int) -> tuple[Path, list[TangentialCorner]]:
    """One following axis: new values of column ``f`` on every segment, TLIFT rows."""
    blocks = program.blocks
    m = path.n_segments
    eps = machine.settings_of(axis).eps_tlift_deg
    seg = np.arange(m)
    q0, t0 = path.evaluate(path.s_breaks[:-1], segment=seg)[:2]
    q1, t1 = path.evaluate(path.s_breaks[1:], segment=seg)[:2]
    c_start = np.empty(m)
    c_end = np.empty(m)
    tlift_at: dict[int, float] = {}       # segment -> axis value before its TLIFT turn
    corners: list[TangentialCorner] = []
    cur = float(q0[0, f])                 # where the axis is
    phi_prev: float | None = None         # last defined tangent angle, degrees
    was_on = False
    # Python numbers per segment at once (numpy element access costs a microsecond)
    block_of = path.block.tolist()
    prog0_l, prog1_l = q0[:, f].tolist(), q1[:, f].tolist()
    t0_l = t0.tolist()
    is_arc = (path.radius > 0).tolist()
    follow: dict[int, object] = {}        # modal state -> its tangential record for axis
    rounds: dict[int, bool] = {}          # block -> a rounding mode governs its end corner
    for j in range(m):
        blk = blocks[block_of[j]]
        key = id(blk.modal)
        if key not in follow:
            t = blk.modal.tangential
            follow[key] = t if (t is not None and t.axis == axis) else None
        tg = follow[key]
        prog0, prog1 = prog0_l[j], prog1_l[j]
        if tg is None:
            if was_on:
                phi_prev, was_on = None, False
            c_start[j] = cur
            # a programmed move of the axis goes to its programmed end; else it rests
            c_end[j] = prog1 if abs(prog1 - prog0) > POS_TOL_MM else cur
            cur = float(c_end[j])
            continue
        was_on = True
        lu, lv = (path.axes.index(a) for a in tg.leading)
        k, off = tg.coupling, tg.offset_deg
        tu, tv = t0_l[j][lu], t0_l[j][lv]
        # an arc must lie in the leading plane (checked first: an arc in another plane
        # may start with no tangent there and still move in it)
        turn = _turn_deg(path, j, lu, lv, t0[j], t1[j], blk.line, program.file) if (
            is_arc[j]) else 0.0
        if math.hypot(tu, tv) <= _PLANE_TANGENT_MIN:
            # no tangent in the leading plane: the axis keeps its angle (plus what the
            # program itself moves it by)
            c_start[j] = cur
            c_end[j] = cur + (prog1 - prog0)
            cur = float(c_end[j])
            continue
        phi0 = math.degrees(math.atan2(tv, tu))
        if phi_prev is None:
            # at TANGON (or after a gap): the branch nearest to where the axis is
            want = (cur - off - prog0) / k if k != 0 else phi0
            phi0 += 360.0 * round((want - phi0) / 360.0)
        else:
            phi0 = phi_prev + _wrap_deg(phi0 - phi_prev)
        target0 = k * phi0 + off + prog0
        target1 = k * (phi0 + turn) + off + prog1
        step = abs(target0 - cur) / abs(k) if k != 0 else abs(target0 - cur)
        if step > _ANGLE_TOL_DEG:
            before = block_of[j - 1] if j > 0 else -1
            if before >= 0 and before not in rounds:
                bb = blocks[before]
                rounds[before] = (bb.continuous_mode in ROUNDING_MODES or bb.rnd_mm > 0
                                  or bb.rndm_mm > 0)
            rounding = before >= 0 and rounds[before]
            if tg.tlift and step > eps and not rounding:
                tlift_at[j] = cur
                c_start[j] = target0
                action = "TLIFT block"
            else:
                c_start[j] = cur
                action = ("follows in this block: "
                          + ("no TLIFT block with rounding (G641..G645/RND)" if (
                              tg.tlift and step > eps) else
                             f"step within EPS_TLIFT_TANG_STEP {eps:g} deg" if tg.tlift
                             else "no TLIFT"))
            corners.append(TangentialCorner(axis, block_of[j], step, action))
        else:
            c_start[j] = cur
        c_end[j] = target1
        cur = float(target1)
        phi_prev = phi0 + turn
    changed = (np.abs(c_start - q0[:, f]) > 0) | (np.abs(c_end - q1[:, f]) > 0)
    if not changed.any() and not tlift_at:
        return path, corners
    return _rebuild(path, f, q0, q1, c_start, c_end, tlift_at, axis), corners


def _turn_deg(path: Path, j: int, lu: int, lv: int, ts: np.ndarray, te: np.ndarray,
              line: int, file: str) -> float:
    """Change of the tangent angle in the leading plane along segment ``j``, degrees."""
    if path.radius[j] == 0:
        return 0.0
    e1, e2 = path.e1[j], path.e2[j]
    orient = e1[lu] * e2[lv] - e1[lv] * e2[lu]
    if abs(abs(orient) - 1.0) > 1e-12:
        raise PathError(f"{file}:{line}: tangential control follows the tangent in the "
                        "plane of its leading axes; an arc in another plane is not "
                        "modelled", int(path.block[j]))
    nominal = math.degrees(orient * float(path.omega[j]) * float(path.length[j]))
    if path.dradius[j] == 0:
        return nominal
    # a spiral: the exact end tangents (the nominal sweep fixes the number of turns)
    a0 = math.degrees(math.atan2(ts[lv], ts[lu]))
    a1 = math.degrees(math.atan2(te[lv], te[lu]))
    return nominal + _wrap_deg(a1 - a0 - nominal)


def _wrap_deg(a: float) -> float:
    """Angle wrapped to (-180, 180], degrees."""
    return 180.0 - (180.0 - a) % 360.0


def _rebuild(path: Path, f: int, q0: np.ndarray, q1: np.ndarray, c_start: np.ndarray,
             c_end: np.ndarray, tlift_at: dict[int, float], axis: str) -> Path:
    """The path with column ``f`` running from ``c_start`` to ``c_end`` on every segment
    and a TLIFT row in front of the segments in ``tlift_at``."""
    m, n = path.n_segments, path.n_axes
    rows = copy_rows(path, np.arange(m))
    L = path.length
    is_line = path.radius == 0
    # lines: rebuilt from their ends (a line of the axis alone changes its length)
    li = np.flatnonzero(is_line)
    if li.size:
        a, b = q0[li].copy(), q1[li].copy()
        a[:, f], b[:, f] = c_start[li], c_end[li]
        lp = line_segments(a, b, path.geometry, path.block[li])
        for k in ("origin", "d", "length"):
            rows[k][li] = lp[k]
    # arcs: the geometry axes keep the length; the axis is a linear component
    ai = np.flatnonzero(~is_line)
    if ai.size:
        rows["origin"][ai, f] = c_start[ai]
        rows["d"][ai, f] = (c_end[ai] - c_start[ai]) / L[ai]
    order = []                             # (old segment, kind of row, index)
    for j in range(m):
        if j in tlift_at:
            order.append((j, "tlift"))
        order.append((j, "row"))
    total = len(order)
    packed = {k: np.zeros((total, n)) for k in ("origin", "e1", "e2", "d")}
    packed.update({k: np.zeros(total) for k in ("radius", "omega", "theta0", "length",
                                                "dradius")})
    packed["block"] = np.zeros(total, np.int64)
    packed["kind"] = np.zeros(total, np.int8)
    owner = np.array([o[0] for o in order], dtype=np.int64)
    is_row = np.array([o[1] == "row" for o in order])
    for k in ROW_KEYS:
        packed[k][is_row] = rows[k]
    feed = np.where(is_row, path.feed[owner], np.inf)
    rapid = np.where(is_row, path.rapid[owner], False)
    inner: dict[int, str] = {}
    brk: dict[int, str] = {}
    ti = np.flatnonzero(~is_row)
    if ti.size:
        js = owner[ti]
        a = q0[js].copy()
        b = q0[js].copy()
        a[:, f] = [tlift_at[int(j)] for j in js]
        b[:, f] = c_start[js]
        lp = line_segments(a, b, path.geometry, path.block[js])
        lp["kind"] = np.full(js.size, _TLIFT, dtype=np.int8)
        for k in ROW_KEYS:
            packed[k][ti] = lp[k]
        for r, j in zip(ti.tolist(), js.tolist()):
            why = f"TLIFT: {axis} turns alone by {abs(c_start[j] - tlift_at[j]):.6g} deg"
            brk[j] = why                   # the path rests in front of the TLIFT block
            inner[r + 1] = why             # and after it
    keep = packed["length"] > POS_TOL_MM
    if not keep.all():
        # a move of the axis alone that now goes nowhere (its stops stay: splice merges
        # the breaks of a segment without rows); a TLIFT row and the row after it are
        # never dropped (both move), so the inner stops only shift
        new_index = np.cumsum(keep) - 1
        inner = {int(new_index[r]): w for r, w in inner.items()}
        packed = {k: v[keep] for k, v in packed.items()}
        owner, feed, rapid = owner[keep], feed[keep], rapid[keep]
    return splice(path, packed, owner, feed, rapid, inner_stops=inner, break_stops=brk)


__all__ = ["TangentialCorner", "TangentialResult", "apply_tangential", "tangential_path"]
