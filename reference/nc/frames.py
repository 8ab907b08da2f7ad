"""Frames and work offsets: where program coordinates sit in machine coordinates.

SINUMERIK programmable frames (``TRANS``/``ATRANS``/``ROT``/``AROT``, rotations about
X, Y and Z) and NGC work offsets (``G10 L2``/``L20`` with ``R`` rotation, G54..G59.3, ``G92``).
Every frame is ``machine = R * program + offset`` (R about Z, or tilted); changing it keeps the
machine position. Units: mm, degrees.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from .lines import Stmt

if TYPE_CHECKING:          # the state holds the frames; only annotations need it here
    from .state import _Interp


_Mat = tuple[tuple[float, float, float], tuple[float, float, float],
             tuple[float, float, float]]


def _rot(axis: str, deg: float) -> _Mat:
    """Rotation matrix about X, Y or Z by ``deg`` degrees (right hand)."""
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    if axis == "X":
        return ((1.0, 0.0, 0.0), (0.0, c, -s), (0.0, s, c))
    if axis == "Y":
        return ((c, 0.0, s), (0.0, 1.0, 0.0), (-s, 0.0, c))
    return ((c, -s, 0.0), (s, c, 0.0), (0.0, 0.0, 1.0))


def _matmul(a: _Mat, b: _Mat) -> _Mat:
    return tuple(tuple(sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3))
                 for i in range(3))  # type: ignore[return-value]


@dataclass(slots=True)
class _Frame:
    """Programmable frame: machine = R * program + offset.

    ``R`` is a rotation by ``theta_deg`` about Z, or, when the frame also rotates about X
    or Y (SINUMERIK ``ROT Y-90``), the full 3x3 matrix ``tilt`` (``theta_deg`` is then
    0 and unused). Rotations act on the geometry axes X, Y, Z only.
    """

    theta_deg: float = 0.0
    offset: dict | None = None
    tilt: _Mat | None = None

    @property
    def identity(self) -> bool:
        """No rotation and no offset."""
        return self.theta_deg == 0.0 and not self.offset and self.tilt is None

    def matrix(self) -> _Mat:
        """The rotation ``R`` as a 3x3 matrix."""
        return self.tilt if self.tilt is not None else _rot("Z", self.theta_deg)

    def to_machine(self, p: dict) -> dict:
        out = dict(p)
        if self.tilt is not None:
            v = self.rotate_vec((p.get("X", 0.0), p.get("Y", 0.0), p.get("Z", 0.0)))
            out["X"], out["Y"], out["Z"] = v
        elif self.theta_deg:
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
        if self.tilt is not None:
            r = self.tilt                              # R^-1 = R^T
            x, y, z = out.get("X", 0.0), out.get("Y", 0.0), out.get("Z", 0.0)
            out["X"], out["Y"], out["Z"] = (r[0][i] * x + r[1][i] * y + r[2][i] * z
                                            for i in range(3))
        elif self.theta_deg:
            c, s = math.cos(math.radians(self.theta_deg)), math.sin(math.radians(self.theta_deg))
            x, y = out.get("X", 0.0), out.get("Y", 0.0)
            out["X"], out["Y"] = c * x + s * y, -s * x + c * y
        return out

    def rotate_vec(self, v: tuple[float, float, float]) -> tuple[float, float, float]:
        if self.tilt is not None:
            r = self.tilt
            return tuple(r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2]
                         for i in range(3))  # type: ignore[return-value]
        if not self.theta_deg:
            return v
        c, s = math.cos(math.radians(self.theta_deg)), math.sin(math.radians(self.theta_deg))
        return (c * v[0] - s * v[1], s * v[0] + c * v[1], v[2])


def _with_rotation(old: _Frame, rot: _Mat | None, theta: float, offset: dict | None,
                   additive: bool) -> _Frame:
    """A frame with the rotation ``rot`` (or ``theta`` about Z when ``rot`` is None),
    replacing (``ROT``) or following (``AROT``) the rotation of ``old``."""
    if rot is None and old.tilt is None:
        return _Frame((old.theta_deg if additive else 0.0) + theta, offset)
    new = rot if rot is not None else _rot("Z", theta)
    full = _matmul(old.matrix(), new) if additive else new
    return _Frame(0.0, offset, full)


def _apply_frame(ip: _Interp, st: Stmt, cmd: str, axis_words, named) -> None:
    """SINUMERIK programmable frame: machine = R * program + offset.

    ``TRANS`` and ``ROT`` are absolute: each replaces the whole programmable frame (a bare
    ``TRANS`` or ``ROT`` deletes it). ``ATRANS`` adds a translation given in the current,
    possibly rotated, coordinate system; ``AROT`` adds a rotation about the current origin.
    ``ROT X.. Y.. Z..`` take the control's default angle convention (MD10600
    FRAME_ANGLE_INPUT_MODE = 1, RPY): about Z, then the new Y, then the newest X, i.e.
    ``R = Rz Ry Rx``. A tilted frame (about X or Y) rotates the working plane with it: a
    G17 arc then lies in the tilted plane; only the positions are modelled (no tool
    orientation, which needs TRAORI and the machine's kinematics).
    """
    angles: dict[str, float] = {}
    moves: dict[str, float] = {}
    for name, val, _mode, col in axis_words:
        if cmd in ("ROT", "AROT"):
            if name not in ("X", "Y", "Z"):
                raise ip.err(st, col, f"{cmd} {name}: rotations are about the geometry axes "
                                      f"X, Y and Z only")
            angles[name] = angles.get(name, 0.0) + val
        else:
            moves[name] = val * ip.lin(name)
    if "RPL" in named:
        if ip.plane != "G17":
            raise ip.err(st, named["RPL"][1], f"RPL= rotates in the active plane; only G17 "
                                              f"(about Z) is supported, not {ip.plane}")
        angles["Z"] = angles.get("Z", 0.0) + named["RPL"][0]
    rot: _Mat | None = None
    if angles.get("X", 0.0) or angles.get("Y", 0.0):
        rot = _matmul(_matmul(_rot("Z", angles.get("Z", 0.0)), _rot("Y", angles.get("Y", 0.0))),
                      _rot("X", angles.get("X", 0.0)))
    theta = angles.get("Z", 0.0)
    old = ip.frame
    if cmd == "TRANS":
        ip.frame = _Frame(0.0, moves or None)
    elif cmd == "ROT":
        ip.frame = _with_rotation(_Frame(), rot, theta, None, additive=False)
    elif cmd == "ATRANS":
        offset = dict(old.offset or {})
        d = old.rotate_vec((moves.pop("X", 0.0), moves.pop("Y", 0.0), moves.pop("Z", 0.0)))
        for name, v in (("X", d[0]), ("Y", d[1]), ("Z", d[2]), *moves.items()):
            if v or name in offset:
                offset[name] = offset.get(name, 0.0) + v
        ip.frame = _Frame(old.theta_deg, offset or None, old.tilt)
    else:                                               # AROT
        ip.frame = _with_rotation(old, rot, theta, old.offset, additive=True)


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
    """NGC ``G10 L2 Pn`` (work offset n, P0 = active; R = XY rotation, degrees),
    ``G10 L20`` (offset chosen so that the current point gets the given coordinates) and
    ``G10 L1 P<tool> R<radius>`` (the tool table's radius, for cutter compensation)."""
    kind = int(l_word[0]) if l_word is not None else None
    if kind == 1 and p_word is not None and r_word is not None:
        # G10 L1 P<tool> R<radius>: the tool table's radius (cutter compensation uses it)
        if p_word[0] != int(p_word[0]) or p_word[0] < 0:
            raise ip.err(st, p_word[1], f"G10 L1 P{p_word[0]:g}: P must be a whole tool "
                                        "number >= 0")
        ip.tool_data[(int(p_word[0]), 1)] = r_word[0] * ip.lin("X")
        if axis_words:
            ip.warn(st, "G10 L1: tool length offsets are not modelled; only the radius R "
                        "is used")
        return
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
