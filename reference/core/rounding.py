"""Corner rounding geometry: the tangent-arc fillet of a corner between two lines, and
the table that records, per corner, what the rounding stage decided.

Model (sinumerik-model 5.8 leaves the shape open: "the user must not assume a
particular shape inside the rounding area", 5.1): under BRISK the rounding block is the
circular arc tangent to both lines, exactly representable by the path's helical pieces
(a circle with ``d = 0``; its ``q'``, ``q''``, ``q'''`` are the arc's closed forms). It
is G1 continuous with a curvature jump ``1/R`` at both ends. Under SOFT the stage
inserts a curvature-continuous clothoid pair instead
(:func:`reference.core.geometry.clothoid_pieces`); this module's arc formulas below
describe the arc only.

For a corner ``C`` between unit directions ``t1`` (in) and ``t2`` (out) with deflection
angle ``theta`` (the angle between ``t1`` and ``t2``) and tangent distance ``d`` (how far
before and after ``C`` the rounding starts and ends, along the lines):

* radius ``R = d / tan(theta/2)``, arc length ``R theta``;
* the arc's midpoint ``M`` is the point nearest to ``C``; the contour deviation (the
  Hausdorff distance between the programmed corner and the rounded path) is
  ``|C - M| = R (1/cos(theta/2) - 1) = d tan(theta/4)``;
* ``C - M`` points along ``t1 - t2``, so axis ``i`` deviates by
  ``|C_i - M_i| = |C - M| |t2_i - t1_i| / |t2 - t1|`` (``|t2 - t1| = 2 sin(theta/2)``).

Inverting the last two gives the distance that uses a deviation ``e`` exactly:
``d = e / tan(theta/4)``.

Units: mm, rad. Shapes: ``k`` corners, ``n`` axes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .arrays import row_dots, row_min, row_norms

#: Why a corner in a rounding mode was or was not rounded (codes index this tuple).
#: Documented cases of sinumerik-model 5.2 first, then model limits of this version.
ROUNDING_REASONS: tuple[str, ...] = (
    "rounded",                                                        # 0
    "stop between the blocks",                                        # 1  5.2 group 1
    "block without path motion between",                              # 2  5.2 group 1
    "acceleration mode change (BRISK/SOFT)",                          # 3  5.2 group 1
    "geometry axes move in one block only",                           # 4  5.2 group 1
    "G64 passes the corner without reduction (overload factor)",      # 5  5.2 group 2, 4.3
    "rounding would be slower than G64",                              # 6  5.2 group 2
    "rounding distance too small",                                    # 7  5.2 group 2
    "rounding not parameterised (ADIS = 0)",                          # 8  5.2 group 3
    "rounding not parameterised (ADISPOS = 0)",                       # 9  5.2 group 3
    "rounding not parameterised (tolerance 0)",                       # 10 5.2 group 3
    "tangential transition",                                          # 11
    "arc transition: rounding not modelled yet",                      # 12 model limit
    "non-geometry axes move: rounding not modelled yet",              # 13 model limit
    "G644 SMOOTHING_MODE digit not documented",                       # 14 6xxx..9xxx
)
REASON_CODE = {r: i for i, r in enumerate(ROUNDING_REASONS)}


@dataclass(frozen=True, slots=True, eq=False)
class RoundingTable:
    """What the rounding stage decided at every corner whose first block is in a
    rounding mode (G641..G645, RND/RNDM), in path order.

    Attributes
    ----------
    block, next_block : numpy.ndarray of int, shape (k,)
        The blocks before and after the corner (the rounding segment is attributed to
        ``block``, whose end the corner is).
    mode : tuple[str, ...]
        ``"G641"`` .. ``"G645"``, ``"RND"``: the mode that governed the corner.
    reason : numpy.ndarray of int, shape (k,)
        Index into :data:`ROUNDING_REASONS` (0 = rounded).
    distance_mm : numpy.ndarray, shape (k,)
        Tangent distance ``d`` (rounding starts ``d`` before and ends ``d`` after the
        corner), mm; 0 where none was inserted.
    length_mm, deviation_mm, radius_mm : numpy.ndarray, shape (k,)
        Arc length of the rounding, contour deviation ``|C - M|``, radius, mm; 0 where
        none was inserted.
    clamped : numpy.ndarray of bool, shape (k,)
        The distance was cut to ``c`` times the shorter neighbouring block.
    v_g64, v_round : numpy.ndarray, shape (k,)
        The G64 corner speed and the model's rounding speed (centripetal, curvature
        jump, one IPO cycle), mm/s (``nan`` where not evaluated).
    g2 : numpy.ndarray of bool, shape (k,)
        The rounding is a clothoid pair (curvature continuous; ``radius_mm`` is then its
        smallest radius of curvature, in the middle), else a tangent arc.
    first_block, last_block : numpy.ndarray of int, shape (k,)
        First and last program block the rounding window touches: ``block`` and
        ``next_block`` unless the window reaches across short blocks (G642/G645), in
        which case the blocks strictly between ``first_block`` and ``block`` (and
        between ``next_block`` and ``last_block``) are covered by the rounding whole.
    """

    block: np.ndarray
    next_block: np.ndarray
    mode: tuple[str, ...]
    reason: np.ndarray
    distance_mm: np.ndarray
    length_mm: np.ndarray
    deviation_mm: np.ndarray
    radius_mm: np.ndarray
    clamped: np.ndarray
    v_g64: np.ndarray
    v_round: np.ndarray
    g2: np.ndarray
    first_block: np.ndarray
    last_block: np.ndarray

    @property
    def n(self) -> int:
        """Number of corners recorded."""
        return int(self.block.size)

    @property
    def inserted(self) -> np.ndarray:
        """True per corner where a rounding segment was inserted, shape (k,)."""
        return self.reason == 0

    @property
    def blocks_spanned(self) -> np.ndarray:
        """Program blocks the rounding window touches (2 for a rounding between two
        blocks, more across short blocks; 0 where none was inserted), shape (k,)."""
        return np.where(self.inserted, self.last_block - self.first_block + 1, 0)

    def reason_text(self, i: int) -> str:
        """The reason of corner ``i`` as words."""
        return ROUNDING_REASONS[int(self.reason[i])]

    def decision_by_block(self) -> dict[int, str]:
        """The decision at the corner each block ends in, for the block rows (issue 13:
        every case where no rounding block is inserted is "named in the trace and in
        the block rows").

        Returns
        -------
        dict
            Program block index (the block before the corner) -> ``"rounded"`` or
            ``"none: <reason>"`` (:data:`ROUNDING_REASONS`); blocks whose end is not a
            corner in a rounding mode are absent.
        """
        words = ["rounded"] + [f"none: {r}" for r in ROUNDING_REASONS[1:]]
        return dict(zip(self.block.tolist(), (words[k] for k in self.reason.tolist())))


def deflection_angle(t1: np.ndarray, t2: np.ndarray) -> np.ndarray:
    """Angle between unit directions, rad, shape (k,) from (k, n) each.

    ``2 atan2(|t2 - t1|, |t2 + t1|)`` is accurate at both ends (0 and pi), unlike
    ``arccos`` of the dot product.
    """
    return 2.0 * np.arctan2(_norms(t2 - t1), _norms(t2 + t1))


def _norms(x: np.ndarray) -> np.ndarray:
    """``numpy.linalg.norm(x, axis=-1)`` (the same numbers; faster on (k, n) arrays)."""
    return row_norms(x) if x.ndim == 2 else np.linalg.norm(x, axis=-1)


def distance_for_deviation(theta: np.ndarray, deviation: np.ndarray) -> np.ndarray:
    """Tangent distance whose fillet deviates from the corner by exactly ``deviation``.

    ``d = e / tan(theta/4)`` (module docstring), mm, shape (k,).
    """
    with np.errstate(divide="ignore"):
        return deviation / np.tan(theta / 4.0)


def axis_deviation_limit(t1: np.ndarray, t2: np.ndarray, tol: np.ndarray) -> np.ndarray:
    """Largest contour deviation ``|C - M|`` that keeps every axis within ``tol``.

    ``min_i tol_i |t2 - t1| / |t2_i - t1_i|`` over the axes whose direction changes.

    Parameters
    ----------
    t1, t2 : numpy.ndarray, shape (k, n)
        Unit directions before and after the corners.
    tol : numpy.ndarray, shape (k, n) or (n,)
        Per-axis tolerance, mm (``inf`` = no limit).

    Returns
    -------
    numpy.ndarray, shape (k,)
        mm (``inf`` where no axis limits).
    """
    dt = np.abs(t2 - t1)
    norm = _norms(t2 - t1)
    tol = np.broadcast_to(tol, dt.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        per = np.where(dt > 0, tol * norm[:, None] / np.where(dt > 0, dt, 1.0), np.inf)
    return row_min(per) if per.shape[1] else np.full(dt.shape[0], np.inf)


def fillet_pieces(corner: np.ndarray, t1: np.ndarray, t2: np.ndarray, d: np.ndarray,
                  block: np.ndarray, kind_code: int) -> dict[str, np.ndarray]:
    """Packed helical parameters of the tangent arcs rounding ``k`` corners.

    The arc starts at ``P_s = C - d t1`` with tangent ``t1`` and ends at
    ``P_e = C + d t2`` with tangent ``t2``: ``q(s) = o + R (e1 cos(s/R) + e2 sin(s/R))``
    with centre ``o = P_s + R n`` (``n`` the unit component of ``t2`` normal to ``t1``),
    ``e1 = -n``, ``e2 = t1``, ``0 <= s <= R theta``.

    Parameters
    ----------
    corner, t1, t2 : numpy.ndarray, shape (k, n)
        Corner points and unit directions (zero components on non-geometry axes).
    d : numpy.ndarray, shape (k,)
        Tangent distances, mm (> 0; ``0 < theta < pi``).
    block : numpy.ndarray of int, shape (k,)
        Block each rounding is attributed to.
    kind_code : int
        Segment kind code (index of ``"rounding"`` in the path's kind codes).

    Returns
    -------
    dict
        ``origin, e1, e2, d, radius, omega, theta0, length, block, kind, dradius``.
    """
    theta = deflection_angle(t1, t2)
    radius = d / np.tan(theta / 2.0)
    normal = t2 - row_dots(t2, t1)[:, None] * t1
    normal /= row_norms(normal)[:, None]
    start = corner - d[:, None] * t1
    k = d.size
    return {
        "origin": start + radius[:, None] * normal,
        "e1": -normal,
        "e2": t1.copy(),
        "d": np.zeros_like(t1),
        "radius": radius,
        "omega": 1.0 / radius,
        "theta0": np.zeros(k),
        "length": radius * theta,
        "block": np.asarray(block, dtype=np.int64),
        "kind": np.full(k, kind_code, dtype=np.int8),
        "dradius": np.zeros(k),
    }


__all__ = ["REASON_CODE", "ROUNDING_REASONS", "RoundingTable", "axis_deviation_limit",
           "deflection_angle", "distance_for_deviation", "fillet_pieces"]
