"""Geometry of G645's rounding of a tangential line-arc transition with a curvature jump.

sinumerik-model 5.7: "At tangential transitions with a curvature jump (e.g. line to arc),
G645 also inserts rounding, using MD33120 PATH_TRANS_POS_TOL"; 5.8: "model the inserted
block as a clothoid-like curvature ramp of length L. The classical clothoid lateral shift
p ~ L^2/(24R) must stay <= PATH_TRANS_POS_TOL".

A clothoid whose curvature rises from 0 to ``1/R`` over ``L`` and that joins the arc
curvature-continuously does not start on the programmed line: it starts on a parallel
line shifted outwards by the classical shift ``p`` (for the programmed line and arc both
kept, no single curvature ramp joins them G2). The model keeps the programmed line and
the programmed arc exact and makes the shift part of the rounding block: leaving the
line, the path moves sideways by ``p`` along an S of two symmetric clothoid pairs, then
follows the ramp onto the arc. Curvature along the rounding (all pieces are clothoids
with a zero-curvature end, :mod:`reference.core.geometry`)::

    0 -> -k_s -> 0 -> +k_s -> 0 (the S, rate c) -> 1/R (the ramp, rate c = 1/(R L))

so the rounding is G2 continuous with the line (curvature 0) and with the arc (1/R),
and every curvature rate is the ramp's ``c`` (the two pairs are sized so: ``h = c L_s^2``,
the fastest-changing piece sets the path jerk ``v^3 c``, so none is steeper than it must
be). The sideways move is monotone and the ramp then closes on the arc, so the largest
distance from the programmed contour is ``p = |y_Q|``, the shift (checked against dense
samples in the tests).

Canonical frame (per transition): origin at the junction ``J`` (the arc's end at the
line), ``x`` along the common tangent towards the arc, ``y`` towards the arc's centre.
Closed forms there (``psi = L / (2R)`` the ramp's turn, ``X, Y`` its end in its own
frame, by the Fresnel integrals):

* the ramp ends on the arc at ``E = (R sin psi, R (1 - cos psi))`` with heading ``psi``,
  i.e. ``L / 2`` along the arc, so the arc is shortened by ``L / 2`` and stays an exact
  arc;
* it starts at ``Q = E - (X, Y)`` (heading 0): ``x_Q = R sin psi - X``,
  ``y_Q = 2 R sin^2(psi/2) - Y ~ -L^2/(24 R)``;
* each pair (piece length ``L_s``, turn ``h``) has the tangent distance ``d_p = L_s
  d_1(h)`` (:func:`reference.core.geometry.clothoid_pair_shape`); the S moves sideways by
  ``2 d_p sin h = |y_Q|`` and along by ``2 d_p (1 + cos h)``, so the rounding leaves the
  line at ``x_S = x_Q - 2 d_p (1 + cos h)``: the line is shortened by ``-x_S``.

The arc-into-line transition is the same construction traversed backwards (frame at the
arc's end, ``x`` pointing back along the line): its pieces in reverse order, each with
its curvature rate negated (a clothoid piece traversed backwards, module docstring of
:mod:`reference.core.geometry`).

Units: mm, rad. Shapes: ``k`` transitions, ``n`` axes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .geometry import _fresnel, clothoid_pair_shape, clothoid_rows

#: Fixed-point iterations stop when the relative change is below this (the solved
#: quantities then agree with their defining equations to a few units of round-off).
SOLVE_REL_TOL = 1e-14
#: Iteration cap of the fixed points below (each converges linearly with a ratio of
#: order ``(L/R)^2``; 40 steps would reach round-off from any start, in practice 3-6).
SOLVE_MAX_ITER = 40

#: Pieces per transition: two clothoid pairs (the sideways S) and the ramp.
PIECES = 5


def ramp_offset(radius: np.ndarray, length: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Start of the curvature ramp that ends on the arc, in the canonical frame.

    Parameters
    ----------
    radius, length : numpy.ndarray, shape (k,)
        Arc radius ``R`` and ramp length ``L``, mm.

    Returns
    -------
    x_q, y_q : numpy.ndarray, shape (k,)
        The ramp's start ``Q`` (``y_q < 0``: outside the line, by the classical shift), mm.
    x_r, y_r : numpy.ndarray, shape (k,)
        The ramp's end in its own frame (``E - Q``), mm.
    """
    c = 1.0 / (radius * length)
    scale = np.sqrt(np.pi / c)
    fs, fc = _fresnel(length / scale)
    x_r, y_r = scale * fc, scale * fs
    psi = length / (2.0 * radius)
    # 1 - cos(psi) = 2 sin^2(psi/2): no cancellation at small psi
    return radius * np.sin(psi) - x_r, 2.0 * radius * np.sin(psi / 2.0) ** 2 - y_r, x_r, y_r


def s_shift(shift: np.ndarray, rate: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Piece length ``L_s``, turn ``h`` and tangent distance ``d_p`` of the two symmetric
    clothoid pairs that move the path sideways by ``shift`` with curvature rate ``rate``.

    ``h = rate L_s^2`` (each piece turns ``h/2 = rate L_s^2 / 2``) and ``2 d_p sin h =
    shift`` with ``d_p = L_s d_1(h)``; ``f(L_s) = 2 L_s d_1 sin h`` grows like
    ``2 rate L_s^3``, so the fixed point ``L_s <- L_s (shift / f(L_s))^(1/3)`` converges.

    Parameters
    ----------
    shift : numpy.ndarray, shape (k,)
        Sideways move ``|y_Q|``, mm (> 0).
    rate : numpy.ndarray, shape (k,)
        Curvature rate, 1/mm^2.

    Returns
    -------
    l_s, h, d_p : numpy.ndarray, shape (k,)
        mm, rad, mm.
    """
    l_s = np.cbrt(shift / (2.0 * rate))
    for _ in range(SOLVE_MAX_ITER):
        h = rate * l_s * l_s
        d_1, _ = clothoid_pair_shape(h)
        step = np.cbrt(shift / (2.0 * l_s * d_1 * np.sin(h)))
        l_s = l_s * step
        if np.all(np.abs(step - 1.0) <= SOLVE_REL_TOL):
            break
    h = rate * l_s * l_s
    d_1, _ = clothoid_pair_shape(h)
    return l_s, h, l_s * d_1


@dataclass(frozen=True, slots=True, eq=False)
class TransitionShape:
    """Size of G645 transitions in the canonical frame (module docstring), shape (k,) each.

    Attributes
    ----------
    radius, ramp : numpy.ndarray
        Arc radius ``R`` and ramp length ``L``, mm.
    rate : numpy.ndarray
        Curvature rate of every piece ``c = 1 / (R L)``, 1/mm^2.
    piece : numpy.ndarray
        Length ``L_s`` of each of the four S pieces, mm.
    turn : numpy.ndarray
        Turn ``h`` of each S pair, rad.
    pair_distance : numpy.ndarray
        Tangent distance ``d_p`` of each pair, mm.
    x_q, y_q : numpy.ndarray
        The ramp's start ``Q``, mm.
    line_trim, arc_trim : numpy.ndarray
        How much of the line (``-x_S``) and of the arc (``L/2``) the rounding replaces, mm.
    deviation : numpy.ndarray
        Largest distance from the programmed contour, ``|y_Q|``, mm.
    length : numpy.ndarray
        Length of the rounding, ``4 L_s + L``, mm.
    """

    radius: np.ndarray
    ramp: np.ndarray
    rate: np.ndarray
    piece: np.ndarray
    turn: np.ndarray
    pair_distance: np.ndarray
    x_q: np.ndarray
    y_q: np.ndarray
    line_trim: np.ndarray
    arc_trim: np.ndarray
    deviation: np.ndarray
    length: np.ndarray


def transition_shape(radius: np.ndarray, ramp: np.ndarray) -> TransitionShape:
    """The transition with ramp length ``ramp`` onto an arc of radius ``radius``."""
    radius = np.asarray(radius, dtype=np.float64)
    ramp = np.asarray(ramp, dtype=np.float64)
    x_q, y_q, _, _ = ramp_offset(radius, ramp)
    rate = 1.0 / (radius * ramp)
    l_s, h, d_p = s_shift(np.abs(y_q), rate)
    x_s = x_q - 2.0 * d_p * (1.0 + np.cos(h))
    return TransitionShape(radius, ramp, rate, l_s, h, d_p, x_q, y_q, -x_s, 0.5 * ramp,
                           np.abs(y_q), 4.0 * l_s + ramp)


def ramp_for_deviation(radius: np.ndarray, deviation: np.ndarray) -> np.ndarray:
    """Ramp length ``L`` whose transition deviates from the contour by ``deviation``.

    ``|y_Q(L)| ~ L^2 / (24 R)`` (spec 5.8), so ``L <- L sqrt(e / |y_Q(L)|)`` from
    ``L = sqrt(24 R e)`` converges to the exact ``|y_Q(L)| = e``.

    Parameters
    ----------
    radius, deviation : numpy.ndarray, shape (k,)
        mm (``deviation > 0``).

    Returns
    -------
    numpy.ndarray, shape (k,)
        mm.
    """
    ramp = np.sqrt(24.0 * radius * deviation)
    for _ in range(SOLVE_MAX_ITER):
        step = np.sqrt(deviation / np.abs(ramp_offset(radius, ramp)[1]))
        ramp = ramp * step
        if np.all(np.abs(step - 1.0) <= SOLVE_REL_TOL):
            break
    return ramp


def transition_rows(junction: np.ndarray, along: np.ndarray, inward: np.ndarray,
                    shape: TransitionShape, backward: np.ndarray, block: np.ndarray,
                    kind_code: int) -> dict[str, np.ndarray]:
    """Packed rows of the transitions, :data:`PIECES` per transition in path order.

    Parameters
    ----------
    junction : numpy.ndarray, shape (k, n)
        The arc's end at the line (its start for line-into-arc, its end for arc-into-line).
    along : numpy.ndarray, shape (k, n)
        The canonical ``x`` axis: for line-into-arc the arc's start tangent, for
        arc-into-line minus the arc's end tangent (pointing from the line into the arc
        in the construction's own direction of travel).
    inward : numpy.ndarray, shape (k, n)
        Unit normal towards the arc's centre there (canonical ``y``).
    shape : TransitionShape
    backward : numpy.ndarray of bool, shape (k,)
        Arc-into-line (the construction is traversed backwards).
    block : numpy.ndarray of int, shape (k,)
        Block each rounding is attributed to.
    kind_code : int
        Segment kind code.

    Returns
    -------
    dict
        Keys of :class:`reference.core.geometry.Path` rows, plus ``sharpness``.
    """
    k, n = junction.shape
    h, d_p, l_s = shape.turn, shape.pair_distance, shape.piece
    ch, sh = np.cos(h), np.sin(h)
    z, o = np.zeros(k), np.ones(k)
    x_s = -shape.line_trim
    # canonical points (x, y) and directions of the five pieces' zero-curvature ends
    p1 = (x_s + d_p + d_p * ch, -d_p * sh)                  # end of the first pair
    q = (shape.x_q, shape.y_q)
    pts = [(x_s, z), p1, p1, q, q]
    e1s = [(o, z), (-ch, sh), (ch, -sh), (-o, z), (o, z)]
    e2s = [(z, -o), (-sh, -ch), (sh, ch), (z, o), (z, o)]
    rates = [shape.rate, -shape.rate, shape.rate, -shape.rate, shape.rate]
    lengths = [l_s, l_s, l_s, l_s, shape.ramp]

    def world(xy, offset):
        return offset + xy[0][:, None] * along + xy[1][:, None] * inward

    origin = np.stack([world(p, junction) for p in pts], axis=1)      # (k, 5, n)
    e1 = np.stack([world(v, 0.0) for v in e1s], axis=1)
    e2 = np.stack([world(v, 0.0) for v in e2s], axis=1)
    sharp = np.stack(rates, axis=1)
    length = np.stack(lengths, axis=1)
    # backwards: pieces in reverse order, each traversed the other way (rate negated)
    rev = np.flatnonzero(backward)
    if rev.size:
        origin[rev] = origin[rev, ::-1]
        e1[rev] = e1[rev, ::-1]
        e2[rev] = e2[rev, ::-1]
        sharp[rev] = -sharp[rev, ::-1]
        length[rev] = length[rev, ::-1]
    m = k * PIECES
    return clothoid_rows(origin.reshape(m, n), e1.reshape(m, n), e2.reshape(m, n),
                         sharp.ravel(), length.ravel(),
                         np.repeat(np.asarray(block, np.int64), PIECES), kind_code)


__all__ = ["PIECES", "TransitionShape", "ramp_for_deviation", "ramp_offset", "s_shift",
           "transition_rows", "transition_shape"]
