"""Exact path geometry: lines, arcs and helices in any plane and any number of axes.

Every segment is a *helical piece* parameterised by the arc length ``s`` of the
geometry axes (X, Y, Z) where they move, otherwise of all moving axes:

.. math::

    q(s) = o + r\\,(e_1 \\cos\\varphi + e_2 \\sin\\varphi) + d\\,s,\\qquad
    \\varphi = \\theta_0 + \\omega s,\\quad 0 \\le s \\le L

A line has ``r = 0`` (so ``q = o + d s``); an arc or helix has ``r > 0`` with ``e1, e2``
the orthonormal plane axes and ``d`` the linear motion of the helix axis and of every
extra axis (rotary axes move linearly with the path). The derivatives are exact:

``q' = r w (-e1 sin + e2 cos) + d``, ``q'' = -r w^2 (e1 cos + e2 sin)``,
``q''' = r w^3 (e1 sin - e2 cos)``.

A :class:`Path` stores all pieces as packed arrays (one row per segment) so that
evaluation at 10^5 points is one vectorised numpy expression.

Units: mm for linear axes, degrees for rotary axes, ``s`` in mm.
Shapes: ``m`` segments, ``n`` axes, ``N`` evaluation points.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from .errors import PathError
from .tolerances import MIN_SEGMENT_LENGTH_MM, POS_TOL_MM

SegmentKind = Literal["line", "arc", "rounding", "trc", "tlift"]
KIND_CODES: tuple[str, ...] = ("line", "arc", "rounding", "trc", "tlift")


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a, dtype=np.float64)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, slots=True, eq=False)
class HelicalSegment:
    """One path segment (line, arc or helix) with exact derivatives.

    Attributes
    ----------
    origin, e1, e2, d : numpy.ndarray
        Shape ``(n,)``: see the module docstring. ``e1``/``e2`` are zero for lines.
    radius : float
        Arc radius in mm, 0 for lines.
    omega : float
        Angular rate ``dphi/ds`` in rad/mm (positive = counter-clockwise in the plane
        spanned by ``e1``, ``e2``), 0 for lines.
    theta0 : float
        Angle at ``s = 0``, rad.
    length : float
        Path length, mm.
    source_block : int
        Index of the NC block this segment belongs to.
    kind : str
        ``"line"``, ``"arc"``, or the kind of an inserted block.
    """

    origin: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    d: np.ndarray
    radius: float
    omega: float
    theta0: float
    length: float
    source_block: int
    kind: str = "line"

    def evaluate(self, s: np.ndarray | float) -> tuple[np.ndarray, ...]:
        """Position and its first three derivatives with respect to ``s``.

        Parameters
        ----------
        s : array_like, shape (N,)
            Local path positions in ``[0, length]``, mm.

        Returns
        -------
        q, dq, ddq, dddq : numpy.ndarray
            Each of shape ``(N, n)``: mm, 1, 1/mm, 1/mm^2 (degrees for rotary axes).
        """
        s = np.atleast_1d(np.asarray(s, dtype=np.float64))
        return _eval_helical(
            self.origin[None], self.e1[None], self.e2[None], self.d[None],
            np.array([self.radius]), np.array([self.omega]), np.array([self.theta0]),
            np.zeros(len(s), dtype=np.intp), s)

    @property
    def start_tangent(self) -> np.ndarray:
        """``q'(0)``, shape ``(n,)`` (unit length over the geometry axes)."""
        return self.evaluate(0.0)[1][0]

    @property
    def end_tangent(self) -> np.ndarray:
        """``q'(L)``, shape ``(n,)``."""
        return self.evaluate(self.length)[1][0]

    @property
    def start_curvature(self) -> np.ndarray:
        """Curvature vector ``q''(0)``, shape ``(n,)``, 1/mm."""
        return self.evaluate(0.0)[2][0]

    @property
    def end_curvature(self) -> np.ndarray:
        """Curvature vector ``q''(L)``, shape ``(n,)``, 1/mm."""
        return self.evaluate(self.length)[2][0]

    @property
    def start(self) -> np.ndarray:
        """Start point, shape ``(n,)``."""
        return self.evaluate(0.0)[0][0]

    @property
    def end(self) -> np.ndarray:
        """End point, shape ``(n,)``."""
        return self.evaluate(self.length)[0][0]


def _eval_helical(origin, e1, e2, d, radius, omega, theta0, idx, s):
    """Vectorised kernel: rows ``idx`` of the packed arrays at local positions ``s``."""
    r = radius[idx][:, None]
    w = omega[idx][:, None]
    phi = theta0[idx][:, None] + w * s[:, None]
    c, sn = np.cos(phi), np.sin(phi)
    E1, E2 = e1[idx], e2[idx]
    radial = E1 * c + E2 * sn          # unit radial direction (zero rows for lines)
    along = E2 * c - E1 * sn           # unit tangential direction of the circle
    q = origin[idx] + r * radial + d[idx] * s[:, None]
    dq = (r * w) * along + d[idx]
    ddq = -(r * w * w) * radial
    dddq = -(r * w * w * w) * along
    return q, dq, ddq, dddq


def _path_length(delta: np.ndarray, geometry: np.ndarray) -> np.ndarray:
    """Length of linear moves ``delta`` (shape ``(m, n)``) by the path-length rule."""
    geo = np.sqrt(np.sum(delta[:, geometry] ** 2, axis=1))
    allax = np.sqrt(np.sum(delta ** 2, axis=1))
    return np.where(geo > MIN_SEGMENT_LENGTH_MM, geo, allax)


def line_segments(starts: np.ndarray, ends: np.ndarray, geometry: np.ndarray,
                  blocks: np.ndarray) -> dict[str, np.ndarray]:
    """Packed parameters of straight segments (vectorised).

    Parameters
    ----------
    starts, ends : numpy.ndarray, shape (m, n)
        End points, mm / degrees.
    geometry : numpy.ndarray of bool, shape (n,)
        True for the geometry axes X, Y, Z.
    blocks : numpy.ndarray of int, shape (m,)
        Source NC block of each segment.

    Returns
    -------
    dict
        Packed arrays (keys as in :class:`Path`) for the ``m`` lines.
    """
    starts = np.asarray(starts, dtype=np.float64)
    ends = np.asarray(ends, dtype=np.float64)
    m, n = starts.shape
    delta = ends - starts
    length = _path_length(delta, geometry)
    with np.errstate(invalid="ignore", divide="ignore"):
        d = np.where(length[:, None] > 0, delta / length[:, None], 0.0)
    zeros = np.zeros((m, n))
    return dict(origin=starts, e1=zeros, e2=zeros.copy(), d=d, radius=np.zeros(m),
                omega=np.zeros(m), theta0=np.zeros(m), length=length,
                block=np.asarray(blocks, dtype=np.int64),
                kind=np.zeros(m, dtype=np.int8))


def arc_segments(starts: np.ndarray, ends: np.ndarray, centers: np.ndarray,
                 e1: np.ndarray, e2: np.ndarray, clockwise: np.ndarray, turns: np.ndarray,
                 geometry: np.ndarray, blocks: np.ndarray, radius_tol: np.ndarray
                 ) -> dict[str, np.ndarray]:
    """Packed parameters of many circular arcs or helices at once (vectorised).

    Parameters
    ----------
    starts, ends, centers : numpy.ndarray, shape (m, n)
        Start and end points and arc centres (absolute; only the in-plane part of the
        centre is used), mm / degrees.
    e1, e2 : numpy.ndarray, shape (m, n)
        Orthonormal plane vectors; counter-clockwise turns from ``e1`` to ``e2``
        (G17: X->Y, G18: Z->X, G19: Y->Z).
    clockwise : numpy.ndarray of bool, shape (m,)
        True for G2.
    turns : numpy.ndarray of int, shape (m,)
        Additional full turns (>= 0).
    geometry : numpy.ndarray of bool, shape (n,)
        True for the geometry axes.
    blocks : numpy.ndarray of int, shape (m,)
        Source NC block of each arc.
    radius_tol : numpy.ndarray, shape (m,)
        Largest accepted difference between start and end radius, mm.

    Returns
    -------
    dict
        Packed arrays for the ``m`` arcs.

    Raises
    ------
    PathError
        The first arc (in order) with zero radius or with start and end radius
        differing by more than its ``radius_tol``; ``PathError.block`` names its block.
    """
    starts = np.asarray(starts, dtype=np.float64)
    ends = np.asarray(ends, dtype=np.float64)
    ps, pe = starts - centers, ends - centers
    su, sv = np.sum(ps * e1, axis=1), np.sum(ps * e2, axis=1)
    eu, ev = np.sum(pe * e1, axis=1), np.sum(pe * e2, axis=1)
    r0, r1 = np.hypot(su, sv), np.hypot(eu, ev)
    bad = (r0 <= POS_TOL_MM) | (np.abs(r1 - r0) > radius_tol)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        if r0[i] <= POS_TOL_MM:
            raise PathError("arc with zero radius (centre on the start point)", int(blocks[i]))
        raise PathError(
            f"arc start radius {r0[i]:.6g} mm and end radius {r1[i]:.6g} mm differ by "
            f"{abs(r1[i] - r0[i]):.3g} mm (> {radius_tol[i]:.3g} mm)", int(blocks[i]))
    th0, th1 = np.arctan2(sv, su), np.arctan2(ev, eu)
    # Direction decides the sweep; an arc ending where it started (in the plane) is a
    # full turn, as both dialects define it.
    closed = np.hypot(eu - su, ev - sv) <= POS_TOL_MM
    two_pi = 2 * np.pi
    sweep = np.where(clockwise, np.where(closed, -two_pi, -((th0 - th1) % two_pi)),
                     np.where(closed, two_pi, (th1 - th0) % two_pi))
    sweep = sweep + np.where(clockwise, -1.0, 1.0) * two_pi * turns
    delta = ends - starts
    lin = (delta - np.sum(delta * e1, axis=1)[:, None] * e1
           - np.sum(delta * e2, axis=1)[:, None] * e2)
    geo_lin = np.sqrt(np.sum(lin[:, geometry] ** 2, axis=1))
    length = np.hypot(r0 * sweep, geo_lin)
    origin = starts - r0[:, None] * (np.cos(th0)[:, None] * e1 + np.sin(th0)[:, None] * e2)
    return dict(origin=origin, e1=np.array(e1, dtype=np.float64),
                e2=np.array(e2, dtype=np.float64), d=lin / length[:, None], radius=r0,
                omega=sweep / length, theta0=th0, length=length,
                block=np.asarray(blocks, dtype=np.int64),
                kind=np.full(r0.size, KIND_CODES.index("arc"), dtype=np.int8))


def arc_segment(start: np.ndarray, end: np.ndarray, center: np.ndarray,
                plane, clockwise: bool, turns: int,
                geometry: np.ndarray, block: int, radius_tol: float) -> dict[str, np.ndarray]:
    """Packed parameters of one circular arc or helix (see :func:`arc_segments`).

    Parameters
    ----------
    start, end, center : numpy.ndarray, shape (n,)
        Start and end points and the arc centre, mm / degrees.
    plane : tuple of two int, or tuple of two numpy.ndarray of shape (n,)
        The plane as axis indices ``(u, v)`` or as orthonormal vectors ``(e1, e2)``;
        counter-clockwise means from the first to the second.
    clockwise : bool
        True for G2.
    turns : int
        Additional full turns (>= 0).
    geometry : numpy.ndarray of bool, shape (n,)
        True for the geometry axes.
    block : int
        Source NC block.
    radius_tol : float
        Largest accepted difference between start and end radius, mm.

    Returns
    -------
    dict
        Packed arrays for one segment.

    Raises
    ------
    PathError
        Zero radius, or start and end radius differing by more than ``radius_tol``.
    """
    start = np.asarray(start, dtype=np.float64)
    n = start.size
    if isinstance(plane[0], (int, np.integer)):
        e1 = np.zeros(n)
        e2 = np.zeros(n)
        e1[plane[0]] = 1.0
        e2[plane[1]] = 1.0
    else:
        e1 = np.asarray(plane[0], dtype=np.float64)
        e2 = np.asarray(plane[1], dtype=np.float64)
    return arc_segments(start[None], np.asarray(end, dtype=np.float64)[None],
                        np.asarray(center, dtype=np.float64)[None], e1[None], e2[None],
                        np.array([clockwise]), np.array([turns]), geometry,
                        np.array([block]), np.array([radius_tol]))


@dataclass(frozen=True, slots=True)
class BlockSpan:
    """Where one NC block lies on the path.

    Attributes
    ----------
    block : int
        Index of the block in the program.
    line : int
        1-based source line.
    label : str
        Block number or label, ``""`` if none.
    kind : str
        ``"G0"``, ``"G1"``, ``"G2"``, ``"G3"`` or ``"none"`` (no path motion), or the kind
        of an inserted block (``"rounding"``, ...).
    s_start, s_end : float
        Path positions of the block's start and end, mm (equal for zero-length blocks).
    first_segment, n_segments : int
        Segment range ``[first_segment, first_segment + n_segments)``.
    feed_mm_s : float
        Programmed path feed, mm/s; ``inf`` for rapid (G0) and non-motion blocks.
    stop_reason : str
        Why the motion must be at rest at the block *end* (``""`` if it need not):
        ``"exact stop G60"``, ``"exact stop G9"``, ``"dwell"``, ``"M0"``, ...
    dwell_s : float
        Time the block waits at rest (G4), s.
    """

    block: int
    line: int
    label: str
    kind: str
    s_start: float
    s_end: float
    first_segment: int
    n_segments: int
    feed_mm_s: float = float("inf")
    stop_reason: str = ""
    dwell_s: float = 0.0

    @property
    def length(self) -> float:
        """Block path length, mm."""
        return self.s_end - self.s_start


@dataclass(frozen=True, slots=True, eq=False)
class Path:
    """An ordered sequence of segments parameterised by cumulative path length.

    Attributes
    ----------
    axes : tuple[str, ...]
        Axis names, length ``n``.
    geometry : numpy.ndarray of bool, shape (n,)
        True for geometry axes (X, Y, Z), whose path speed the feed F limits.
    rotary : numpy.ndarray of bool, shape (n,)
        True for rotary axes (degrees).
    origin, e1, e2, d : numpy.ndarray, shape (m, n)
        Packed helical parameters (see module docstring).
    radius, omega, theta0, length : numpy.ndarray, shape (m,)
        Packed helical parameters; ``length`` in mm.
    block : numpy.ndarray of int, shape (m,)
        Source NC block of each segment.
    kind : numpy.ndarray of int8, shape (m,)
        Index into :data:`KIND_CODES`.
    feed : numpy.ndarray, shape (m,)
        Programmed path-speed cap per segment, mm/s (``inf`` for G0: axis limits only).
    rapid : numpy.ndarray of bool, shape (m,)
        True for G0 segments.
    stop : numpy.ndarray of bool, shape (m + 1,)
        True where the motion must be at rest at break ``k`` (``k = 0`` is the start,
        ``k = m`` the end; both are always True).
    stop_reason : tuple[str, ...]
        Length ``m + 1``: why the motion stops at each break (``""`` if it need not).
    blocks : tuple[BlockSpan, ...]
        One span per NC block of the program, in program order (zero-length blocks too).
    source : str
        Program file the path was built from.
    """

    axes: tuple[str, ...]
    geometry: np.ndarray
    rotary: np.ndarray
    origin: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    d: np.ndarray
    radius: np.ndarray
    omega: np.ndarray
    theta0: np.ndarray
    length: np.ndarray
    block: np.ndarray
    kind: np.ndarray
    feed: np.ndarray
    rapid: np.ndarray
    stop: np.ndarray
    stop_reason: tuple[str, ...]
    blocks: tuple[BlockSpan, ...]
    source: str = ""
    s_breaks: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        for name in ("origin", "e1", "e2", "d", "radius", "omega", "theta0", "length",
                     "feed"):
            object.__setattr__(self, name, _readonly(getattr(self, name)))
        for name in ("geometry", "rotary", "rapid", "stop"):
            a = np.ascontiguousarray(getattr(self, name), dtype=bool)
            a.setflags(write=False)
            object.__setattr__(self, name, a)
        for name, dt in (("block", np.int64), ("kind", np.int8)):
            a = np.ascontiguousarray(getattr(self, name), dtype=dt)
            a.setflags(write=False)
            object.__setattr__(self, name, a)
        m = self.length.size
        n = len(self.axes)
        if self.origin.shape != (m, n) or self.d.shape != (m, n):
            raise PathError(f"packed arrays have shape {self.origin.shape}, expected {(m, n)}")
        if self.stop.shape != (m + 1,) or len(self.stop_reason) != m + 1:
            raise PathError("stop flags must have one entry per segment break (m + 1)")
        if m and not np.all(self.length > 0):
            raise PathError("segments must have positive length")
        sb = np.concatenate(([0.0], np.cumsum(self.length)))
        sb.setflags(write=False)
        object.__setattr__(self, "s_breaks", sb)

    # ---------------------------------------------------------------- queries
    @property
    def n_segments(self) -> int:
        """Number of segments ``m``."""
        return int(self.length.size)

    @property
    def n_axes(self) -> int:
        """Number of axes ``n``."""
        return len(self.axes)

    @property
    def total_length(self) -> float:
        """Total path length, mm."""
        return float(self.s_breaks[-1])

    def segment(self, i: int) -> HelicalSegment:
        """Segment ``i`` as a standalone object (local ``s`` from 0 to its length)."""
        return HelicalSegment(
            origin=self.origin[i], e1=self.e1[i], e2=self.e2[i], d=self.d[i],
            radius=float(self.radius[i]), omega=float(self.omega[i]),
            theta0=float(self.theta0[i]), length=float(self.length[i]),
            source_block=int(self.block[i]), kind=KIND_CODES[int(self.kind[i])])

    @property
    def segments(self) -> tuple[HelicalSegment, ...]:
        """All segments as objects (builds ``m`` objects; prefer :meth:`evaluate`)."""
        return tuple(self.segment(i) for i in range(self.n_segments))

    def segment_index(self, s: np.ndarray | float, side: Literal["left", "right"] = "right"
                      ) -> np.ndarray:
        """Index of the segment that holds each ``s``.

        Parameters
        ----------
        s : array_like, shape (N,)
            Global path positions, mm.
        side : {"right", "left"}
            At a segment break, ``"right"`` picks the segment that starts there and
            ``"left"`` the one that ends there. The path ends are clamped.

        Returns
        -------
        numpy.ndarray of int, shape (N,)
        """
        s = np.atleast_1d(np.asarray(s, dtype=np.float64))
        idx = np.searchsorted(self.s_breaks, s, side="right" if side == "right" else "left") - 1
        return np.clip(idx, 0, self.n_segments - 1)

    def evaluate(self, s: np.ndarray | float, side: Literal["left", "right"] = "right",
                 segment: np.ndarray | None = None) -> tuple[np.ndarray, ...]:
        """Exact position and derivatives at global path positions.

        Parameters
        ----------
        s : array_like, shape (N,)
            Global path positions in ``[0, total_length]``, mm.
        side : {"right", "left"}
            Which segment to use exactly at a break (see :meth:`segment_index`).
        segment : numpy.ndarray of int, shape (N,), optional
            Segment of each point, when the caller knows it (skips the search).

        Returns
        -------
        q, dq, ddq, dddq : numpy.ndarray
            Each of shape ``(N, n)``: position (mm), tangent ``dq/ds`` (1),
            curvature vector ``d2q/ds2`` (1/mm) and ``d3q/ds3`` (1/mm^2).
        """
        s = np.atleast_1d(np.asarray(s, dtype=np.float64))
        idx = self.segment_index(s, side) if segment is None else np.asarray(segment)
        local = s - self.s_breaks[idx]
        return _eval_helical(self.origin, self.e1, self.e2, self.d, self.radius,
                             self.omega, self.theta0, idx, local)

    def junction_tangents(self) -> tuple[np.ndarray, np.ndarray]:
        """Tangents on both sides of every interior break.

        Returns
        -------
        t_in, t_out : numpy.ndarray, shape (m - 1, n)
            ``q'`` at the end of segment ``k`` and at the start of segment ``k + 1``.
        """
        m = self.n_segments
        if m < 2:
            z = np.zeros((0, self.n_axes))
            return z, z
        idx_in = np.arange(m - 1)
        idx_out = idx_in + 1
        _, t_in, _, _ = _eval_helical(self.origin, self.e1, self.e2, self.d, self.radius,
                                      self.omega, self.theta0, idx_in, self.length[:-1])
        _, t_out, _, _ = _eval_helical(self.origin, self.e1, self.e2, self.d, self.radius,
                                       self.omega, self.theta0, idx_out, np.zeros(m - 1))
        return t_in, t_out

    def junction_curvatures(self) -> tuple[np.ndarray, np.ndarray]:
        """Curvature vectors ``q''`` on both sides of every interior break, shape (m-1, n)."""
        m = self.n_segments
        if m < 2:
            z = np.zeros((0, self.n_axes))
            return z, z
        idx_in = np.arange(m - 1)
        _, _, k_in, _ = _eval_helical(self.origin, self.e1, self.e2, self.d, self.radius,
                                      self.omega, self.theta0, idx_in, self.length[:-1])
        _, _, k_out, _ = _eval_helical(self.origin, self.e1, self.e2, self.d, self.radius,
                                       self.omega, self.theta0, idx_in + 1, np.zeros(m - 1))
        return k_in, k_out

    def block_of(self, s: np.ndarray | float) -> np.ndarray:
        """NC block index at each global path position (segment rule ``side="right"``)."""
        return self.block[self.segment_index(s)]


def path_from_pieces(axes: tuple[str, ...], pieces: list[dict[str, np.ndarray]], *,
                     feed: np.ndarray | float | None = None,
                     rapid: np.ndarray | None = None,
                     stop_reason: tuple[str, ...] | None = None,
                     blocks: tuple[BlockSpan, ...] | None = None,
                     rotary: tuple[bool, ...] | None = None,
                     source: str = "") -> Path:
    """Assemble a :class:`Path` from packed pieces (from :func:`line_segments`,
    :func:`arc_segment`).

    Parameters
    ----------
    axes : tuple[str, ...]
        Axis names; X, Y and Z are the geometry axes.
    pieces : list of dict
        Packed parameter dicts, concatenated in order.
    feed : float or numpy.ndarray of shape (m,), optional
        Path-speed cap per segment, mm/s (default ``inf``).
    rapid : numpy.ndarray of bool, shape (m,), optional
        G0 flags (default all False).
    stop_reason : tuple[str, ...], optional
        Length ``m + 1``; the path ends always stop (default: only the ends).
    blocks : tuple[BlockSpan, ...], optional
        Block table; by default one block per segment source block.
    rotary : tuple[bool, ...], optional
        Rotary flags per axis (default: A, B, C are rotary).
    source : str
        File name for messages.

    Returns
    -------
    Path
    """
    keys = ("origin", "e1", "e2", "d", "radius", "omega", "theta0", "length", "block", "kind")
    n = len(axes)
    if pieces:
        packed = {k: np.concatenate([p[k] for p in pieces]) for k in keys}
    else:
        packed = {k: np.zeros((0, n)) if k in ("origin", "e1", "e2", "d") else np.zeros(0)
                  for k in keys}
    m = packed["length"].size
    feed_arr = np.full(m, np.inf) if feed is None else np.broadcast_to(
        np.asarray(feed, dtype=np.float64), (m,)).copy()
    rapid_arr = np.zeros(m, bool) if rapid is None else np.asarray(rapid, bool)
    if stop_reason is None:
        stop_reason = ("start",) + ("",) * (m - 1) + ("end",) if m else ("start",)
    stop_reason = tuple(stop_reason)
    if m:
        stop_reason = (stop_reason[0] or "start",) + stop_reason[1:-1] + (stop_reason[-1] or "end",)
    stop = np.array([bool(r) for r in stop_reason])
    geometry = np.array([a in ("X", "Y", "Z") for a in axes])
    rot = np.array([a in ("A", "B", "C") for a in axes]) if rotary is None else np.array(rotary)
    if blocks is None:
        sb = np.concatenate(([0.0], np.cumsum(packed["length"])))
        spans = []
        blk = packed["block"]
        ids = np.unique(blk) if m else np.zeros(0, int)
        for b in ids:
            segs = np.flatnonzero(blk == b)
            first, last = int(segs[0]), int(segs[-1])
            spans.append(BlockSpan(block=int(b), line=int(b) + 1, label="",
                                   kind=KIND_CODES[int(packed["kind"][first])],
                                   s_start=float(sb[first]), s_end=float(sb[last + 1]),
                                   first_segment=first, n_segments=last - first + 1,
                                   feed_mm_s=float(feed_arr[first]),
                                   stop_reason=stop_reason[last + 1]))
        blocks = tuple(spans)
    return Path(axes=tuple(axes), geometry=geometry, rotary=rot, feed=feed_arr,
                rapid=rapid_arr, stop=stop, stop_reason=stop_reason, blocks=blocks,
                source=source, **packed)
