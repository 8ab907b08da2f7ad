"""Geometry of G645's rounding of a tangential transition between two arcs curving the
same way with different radii.

sinumerik-model 5.7: "At tangential transitions with a curvature jump (e.g. line to arc),
G645 also inserts rounding, using MD33120 PATH_TRANS_POS_TOL"; 5.8 models the inserted
block as curvature ramps (:mod:`reference.core.transition` for a line and an arc,
:mod:`reference.core.transition_sbend` for arcs curving opposite ways). Here an arc of
curvature ``k1 = 1/R1`` meets a tangent arc of curvature ``k2 = 1/R2`` curving the same
way (G2 then G2, or G3 then G3, in one plane, ``R1 != R2``): the circles touch inside
each other at the junction ``J`` and the curvature jumps by ``|k2 - k1|``.

*No monotone ramp lands on the arc.* With ``e(s) = kappa(s) - kappa_prog(s)`` (the
rounding's curvature minus the programmed one, ``k1`` before ``J`` at ``s = 0``, ``k2``
after), landing with heading and position needs ``int e ds = 0`` and, in the
small-angle picture, ``int s e ds = 0``. Say ``k2 > k1``: a curvature rising
monotonically from ``k1`` to ``k2`` has ``e >= 0`` before ``J`` and ``e <= 0`` after it,
so ``s e <= 0`` everywhere and ``int s e ds < 0`` (``k2 < k1``: every sign flips). This
is the classical result that a single clothoid joins two circles only if one lies
strictly inside the other (the egg-shaped oval, centre distance ``< |R1 - R2|``), while
tangent circles are at ``|R1 - R2|``: the curvature must leave the interval
``[k1, k2]``.

*The model.* Every clothoid piece of the path has a zero-curvature end
(:mod:`reference.core.geometry`), so the curvature leaves the interval downwards, to
zero, at both arcs, and a clothoid pair makes up the turn in between::

    1/R1 -> 0 (ramp A, length L) -> k_p -> 0 (the pair, two pieces of L_p)
         -> 1/R2 (ramp B, length L)

Rates as at the S-bend: both ramps have one length ``L`` (rates ``1/(R1 L)`` and
``1/(R2 L)``), the pair the larger rate ``c = 1/(min(R1, R2) L)``, its peak ``k_p = c
L_p``. Ramp A leaves the first arc and ends on a line ``A`` of heading ``-theta1``
(measured from the common tangent at ``J``, positive towards the arcs' centres), ramp B
starts on a line ``B`` of heading ``phi2`` and lands on the second arc: each is the
line-arc ramp (:func:`reference.core.transition.ramp_offset`) onto its own arc, so its
zero-curvature end ``Q1`` (``Q2``) is fixed by ``theta1`` (``phi2``) and ``L``. The
first arc is shortened by ``theta1 R1 + L/2``, the second by ``phi2 R2 + L/2``; both
stay the exact programmed arcs.

*Landing conditions.* The pair turns from line ``A`` to line ``B``: ``h = theta1 +
phi2 = c L_p^2`` (heading: the turns of the ramps are those of the arc stretches they
replace, so this is ``int e ds = 0`` exactly). A symmetric pair leaves ``A`` at ``Q1``
and meets ``B`` at ``Q2`` exactly when both are at its tangent distance ``d_p = L_p
d_1(h)`` (:func:`reference.core.geometry.clothoid_pair_shape`) from the lines'
intersection, i.e.

    ``Q2(phi2) - Q1(theta1) = d_p(h) (u(-theta1) + u(phi2))``

(``u`` the unit vector of a heading): two equations in the two unknowns ``theta1,
phi2`` (solved by Newton's method, below). For ``R1 = R2`` they hold along a whole
family (the construction slides along the one circle); for ``R1 != R2`` the family
breaks into two isolated solutions, each with one ramp at ``J`` (its line within
``0.06 L`` of the common tangent: the arc it leaves is cut by ``L/2`` and at most
``0.06 L`` less) and the pair on the other arc: with ``k2 > k1`` in
the small-angle picture, ``int e = 0`` then puts a negative lobe at each ramp and the
positive one (``k_p`` above the arc it sits on) between them, and ``int s e = 0``
places it. The model takes the solution with the pair on the *flatter* arc (the larger
radius): measured, it deviates less at the same rate (``R1 = 10, R2 = 5, L = 0.1``:
0.00093 against 0.0039 mm; the pair's rate ``c`` is set by the sharper arc, so its
peak above the flatter one is smaller) and so gets the gentler rate for a given
tolerance. Beyond a radius ratio of about 16 that solution no longer exists (the two
flatter-arc roots meet and vanish, measured between 15 and 17); there the pair sits on
the sharper arc, which lands at every ratio measured (up to 1000). The deviation at a
given rate then jumps, the rate sized for the tolerance with it: a property of the
model, not of the control, whose polynomial is not documented.

*Solving.* A small-angle start (the ramp at ``J`` starting or ending ``L/2`` from it,
and the heading condition ``int e ds = 0`` with ``e`` piecewise linear, a quadratic in
``L_p``), then Newton steps on the two equations with their exact Jacobian (the
derivative of ``d_1`` in closed form from the Fresnel integrals), each step halved
while it would not turn the pair forwards (``h > 0``), until the landing misses by at
most
:data:`reference.core.transition_sbend.LANDING_TOL_MM`. A transition whose Newton
iteration does not converge gets ``theta1 = nan`` (no landing; the sizing then raises
the rate, as at an S-bend).

*Sizing* is the S-bend's (:func:`reference.core.transition_sbend.size_for_deviation`,
the deviation sampled and refined by
:func:`reference.core.transition_sbend.pieces_deviation` against the two arcs, without
its scan rounds: :data:`SCAN_ROUNDS`), and so
is the placement in the world (:func:`reference.core.transition_sbend.pieces_rows`).

Canonical frame (per transition): origin ``J``, ``x`` along the direction of travel,
``y`` towards the arcs' centres (at ``(0, R1)`` and ``(0, R2)``).

Units: mm, rad. Shapes: ``k`` transitions.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache, partial

import numpy as np

from .geometry import clothoid_pair_shape
from .transition import ramp_offset
from . import transition_sbend
from .transition_sbend import (LANDING_TOL_MM, THETA_MAX, pieces_deviation, pieces_rows,
                               ratio_guess, ratio_table, scatter, size_for_deviation,
                               take)

#: Pieces per transition: ramp A, the pair's two pieces, ramp B.
SAMEDIR_PIECES = 4
#: Newton steps of the landing (quadratic convergence from the small-angle start: 3-6
#: in practice; the cap guards a start too far off).
NEWTON_MAX_ITER = 30
#: A Newton step that would turn the pair backwards (or past THETA_MAX) is halved up to
#: this many times.
STEP_HALVINGS = 8
#: Scan rounds of the full deviation search of these transitions (the S-bend's
#: :data:`~reference.core.transition_sbend.SCAN_ROUNDS` is 2): none. The S-bend's scan
#: picks the highest of close local maxima on its plateau near the junction; here the
#: samples' best already lies within one sample spacing of the maximum the refinement
#: then finds, so the scan only repeats that work. Measured against a dense search
#: (300 samples a piece, 3 scan rounds) on 20,000 random transitions (radii e^-1 ..
#: e^7.5 mm, tolerances 1e-4 .. 0.1 mm) at the sized rate and at 1.5 to 100 times it:
#: the search without the scan and with two rounds find the same deviation to 2.6e-15
#: relative; both are below the dense one in the same single transition at 10 and 100
#: times the rate (by 1.2e-4 and 1.6e-4), in none at 1, 1.5 and 3 times it
#: (``tests/reference/test_rounding_samedir.py`` keeps the comparison against dense
#: points at 1 and 3 times). Without it the
#: full search of the same-way row of ``tests/bench/bench_rounding.py`` takes 1.7
#: instead of 2.4 us a transition (8,000 searches a build).
SCAN_ROUNDS = 0


@dataclass(frozen=True, slots=True, eq=False)
class SameDirShape:
    """Size of transitions between arcs curving the same way (module docstring), shape
    (k,) each.

    Attributes
    ----------
    r_in, r_out : numpy.ndarray
        Radii of the first and second arc, mm.
    rate : numpy.ndarray
        Curvature rate ``c`` of the pair and the steeper ramp, 1/mm^2.
    ramp_in, ramp_out : numpy.ndarray
        Ramp lengths, both ``L = 1/(min(R1, R2) c)``, mm.
    piece : numpy.ndarray
        Length ``L_p`` of each pair piece, mm.
    turn, pair_distance : numpy.ndarray
        Turn ``h`` (rad) and tangent distance ``d_p`` (mm) of the pair.
    theta : numpy.ndarray
        Heading of line ``A`` below the common tangent, ``theta1``, rad (``nan``: no
        landing found).
    phi : numpy.ndarray
        Heading of line ``B`` above the common tangent, ``phi2``, rad.
    trim_in, trim_out : numpy.ndarray
        How much of the first and of the second arc the rounding replaces, mm.
    deviation : numpy.ndarray
        Largest distance from the programmed contour, mm.
    length : numpy.ndarray
        Length of the rounding ``2 L + 2 L_p``, mm.
    min_radius : numpy.ndarray
        Smallest radius of curvature along the rounding and the arcs' ends,
        ``min(R1, R2, 1/(c L_p))``, mm.
    """

    r_in: np.ndarray
    r_out: np.ndarray
    rate: np.ndarray
    ramp_in: np.ndarray
    ramp_out: np.ndarray
    piece: np.ndarray
    turn: np.ndarray
    pair_distance: np.ndarray
    theta: np.ndarray
    phi: np.ndarray
    trim_in: np.ndarray
    trim_out: np.ndarray
    deviation: np.ndarray
    length: np.ndarray
    min_radius: np.ndarray


def _unit(b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit tangent ``u(b)`` and normal ``n(b)`` (``u`` turned a quarter left) of
    headings ``b``, shape (k, 2) each."""
    c, s = np.cos(b), np.sin(b)
    return _pairs(c, s), _pairs(-s, c)


def _pairs(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``np.stack((x, y), axis=1)`` (the same numbers, without its overhead: the Newton
    steps call this on a few transitions at a time)."""
    out = np.empty(x.shape + (2,))
    out[:, 0], out[:, 1] = x, y
    return out


def _pair_distance(h: np.ndarray, rate: np.ndarray) -> np.ndarray:
    """``d_p = L_p d_1(h)`` with ``L_p = sqrt(h / c)``, mm."""
    return np.sqrt(h / rate) * clothoid_pair_shape(h)[0]


def _ends(t1, p2, r_in, r_out, off):
    """Zero-curvature ends ``Q1``, ``Q2`` (k, 2), the lines' directions and normals
    ``uA, nA, uB, nB`` (k, 2) and the derivatives ``dQ1/dtheta1``, ``dQ2/dphi2``."""
    xq1, yq1, xq2, yq2 = off
    ua, na = _unit(-t1)
    ub, nb = _unit(p2)
    # the arcs' points of headings -theta1 and phi2 (2 sin^2(b/2) = 1 - cos b, without
    # cancellation at small b)
    p1 = _pairs(-r_in * np.sin(t1), 2.0 * r_in * np.sin(0.5 * t1) ** 2)
    p2_ = _pairs(r_out * np.sin(p2), 2.0 * r_out * np.sin(0.5 * p2) ** 2)
    # ramp A is the line-arc ramp traversed backwards (its x points back along line A)
    q1 = p1 - xq1[:, None] * ua + yq1[:, None] * na
    q2 = p2_ + xq2[:, None] * ub + yq2[:, None] * nb
    dq1 = (yq1 - r_in)[:, None] * ua + xq1[:, None] * na
    dq2 = (r_out - yq2)[:, None] * ub + xq2[:, None] * nb
    return q1, q2, ua, na, ub, nb, dq1, dq2


def _landing(t1, p2, r_in, r_out, rate, off):
    """Landing miss ``Q2 - Q1 - d_p (uA + uB)`` (k, 2), mm, and its Jacobian (k, 2, 2)
    with respect to ``(theta1, phi2)``."""
    q1, q2, ua, na, ub, nb, dq1, dq2 = _ends(t1, p2, r_in, r_out, off)
    h = t1 + p2
    l_p = np.sqrt(h / rate)
    d_1, e_1 = clothoid_pair_shape(h)
    d_p = l_p * d_1
    w = ua + ub
    g = q2 - q1 - d_p[:, None] * w
    # d d_p / dh = d_p / (2 h) + L_p d_1'(h) with d_1 = X + Y tan(h/2) of the unit pair
    # (X = int_0^1 cos(h t^2/2) dt, Y = int_0^1 sin(h t^2/2) dt; Y = e_1 cos(h/2));
    # integrating t^2 sin and t^2 cos by parts: X' = (cos(h/2) - X) / (2 h),
    # Y' = (sin(h/2) - Y) / (2 h)
    ch, sh, th = np.cos(0.5 * h), np.sin(0.5 * h), np.tan(0.5 * h)
    y = e_1 * ch
    x = d_1 - y * th
    dd1 = (ch - x) / (2.0 * h) + (sh - y) / (2.0 * h) * th + 0.5 * y / (ch * ch)
    dd = 0.5 * d_p / h + l_p * dd1
    jac = np.empty(g.shape + (2,))
    jac[:, :, 0] = -dq1 - dd[:, None] * w + d_p[:, None] * na
    jac[:, :, 1] = dq2 - dd[:, None] * w - d_p[:, None] * nb
    return g, jac


def _start(r_in, r_out, ramp, rate, flat_out):
    """Small-angle start ``(theta1, phi2)`` with the pair on the second arc where
    ``flat_out`` (on the first elsewhere): the ramp on the other arc at ``J`` (ramp A
    starting ``L/2`` before ``J``, or ramp B ending ``L/2`` after it), ``L_p`` from
    ``int e ds = 0`` with ``e`` piecewise linear (module docstring)."""
    k1, k2 = 1.0 / r_in, 1.0 / r_out
    # pair on the second arc: a = -L/2, b = a + 2 L + 2 L_p, heading
    #   k1 L/2 + c L_p^2 + k2 L/2 = -k1 a + k2 b
    # -> c L_p^2 - 2 k2 L_p + (k1 + k2) L/2 + a (k1 - k2) - 2 k2 L = 0; mirrored for the
    # pair on the first arc (b = L/2, k1 and k2 exchanged)
    kp, kr = np.where(flat_out, k2, k1), np.where(flat_out, k1, k2)
    const = (kp + kr) * ramp / 2.0 - 0.5 * ramp * (kr - kp) - 2.0 * kp * ramp
    l_p = (kp + np.sqrt(kp * kp - rate * const)) / rate
    far = (ramp + 2.0 * l_p) / np.where(flat_out, r_out, r_in)
    return np.where(flat_out, 0.0, far), np.where(flat_out, far, 0.0)


def _solve(r_in, r_out, ramp, rate, off, first=None, newton=None):
    """The landing (module docstring): ``theta1, phi2``, the pair on the flatter arc
    where that lands, else on the sharper one; nan where neither does. With ``first``
    (bool, shape (k,): the pair on the second arc) that side is tried first, the other
    only where it does not land: each attempt is the transition's own Newton iteration
    from its side's start, so the result is the model's wherever the side tried first
    is the flatter arc's or the flatter arc's does not land
    (:func:`samedir_canonical`). ``newton``: another implementation of
    :func:`_newton` (:func:`samedir_shape`)."""
    flat_out = r_out > r_in
    first = flat_out if first is None else first
    newton = newton or _newton
    t1, p2 = newton(r_in, r_out, ramp, rate, off, first)
    lost = np.flatnonzero(np.isnan(t1))
    if lost.size:
        sel = (r_in[lost], r_out[lost], ramp[lost], rate[lost],
               None if off is None else tuple(o[lost] for o in off))
        t1[lost], p2[lost] = newton(*sel, ~first[lost])
    return t1, p2


def _ramp_starts(r_in, r_out, ramp, ramp_out=None) -> tuple:
    """The two ramps' zero-curvature ends in their arcs' frames, ``(x_q1, y_q1, x_q2,
    y_q2)`` (:func:`reference.core.transition.ramp_offset`, shape (k,) each, mm): the
    ``off`` of :func:`_newton` and :func:`_landing`, and the pieces' ends. ``ramp`` the
    ramps' length (``ramp_out`` the second's, where given), mm."""
    xq1, yq1, _, _ = ramp_offset(r_in, ramp)
    xq2, yq2, _, _ = ramp_offset(r_out, ramp if ramp_out is None else ramp_out)
    return xq1, yq1, xq2, yq2


def _newton(r_in, r_out, ramp, rate, off, flat_out):
    """Newton's method on the landing from the small-angle start with the pair on the
    second arc where ``flat_out`` (on the first elsewhere): ``theta1, phi2`` (nan where
    it does not converge). ``off``: the ramps' starts (:func:`_ramp_starts`), or None
    (then found here from ``ramp``: another implementation finds them its own way).

    Each transition's iterates are those it would have alone: the arrays of the ones
    still iterating are compacted whenever some stop (the per-iteration cost is then
    that of the few that wander, up to :data:`NEWTON_MAX_ITER` steps, where the pair on
    the flatter arc has no landing), and a transition's verdict is the test of the
    miss at its last iterate (the one it stopped at, or after the last step)."""
    off = _ramp_starts(r_in, r_out, ramp) if off is None else off
    t1, p2 = _start(r_in, r_out, ramp, rate, flat_out)
    lands = np.zeros(t1.shape, bool)
    act = np.arange(t1.size)
    a1, a2 = t1, p2
    r1, r2, c, o = r_in, r_out, rate, off
    for _ in range(NEWTON_MAX_ITER):
        if not act.size:
            break
        with np.errstate(invalid="ignore", divide="ignore"):
            g, jac = _landing(a1, a2, r1, r2, c, o)
        ok = np.abs(g).max(axis=1) <= LANDING_TOL_MM
        j00, j01, j10, j11 = jac[:, 0, 0], jac[:, 0, 1], jac[:, 1, 0], jac[:, 1, 1]
        g0, g1 = g[:, 0], g[:, 1]
        det = j00 * j11 - j01 * j10
        with np.errstate(divide="ignore", invalid="ignore"):
            dt = -(j11 * g0 - j01 * g1) / det
            dp = -(j00 * g1 - j10 * g0) / det
        dt, dp = _halved(a1, a2, dt, dp)
        step = ~ok & np.isfinite(dt) & np.isfinite(dp)
        lands[act[ok]] = True
        a1 = np.where(step, a1 + dt, a1)
        a2 = np.where(step, a2 + dp, a2)
        if not step.all():                    # some stop: write back, compact the rest
            t1[act], p2[act] = a1, a2
            act, a1, a2 = act[step], a1[step], a2[step]
            r1, r2, c, o = r1[step], r2[step], c[step], tuple(x[step] for x in o)
    if act.size:                              # still iterating: the miss after the last step
        t1[act], p2[act] = a1, a2
        with np.errstate(invalid="ignore", divide="ignore"):
            g, _ = _landing(a1, a2, r1, r2, c, o)
        lands[act] = np.abs(g).max(axis=1) <= LANDING_TOL_MM
    lands &= t1 + p2 > 0
    return np.where(lands, t1, np.nan), np.where(lands, p2, np.nan)


def _halved(t1, p2, dt, dp):
    """The Newton step ``(dt, dp)`` halved while it would turn the pair backwards or
    past a quarter turn (``h <= 0`` or ``|theta1|``, ``|phi2| >= THETA_MAX``), at most
    :data:`STEP_HALVINGS` times: per transition, the first of the halvings ``dt 2^-m``,
    ``m = 0 .. STEP_HALVINGS - 1``, that is allowed, else the last. The full steps are
    tested first; where one is not allowed, all its halvings at once, each made by
    halving the one before (the same numbers as halving in a loop until allowed)."""
    a, b = t1 + dt, p2 + dp
    # h summed in the loop's order, ((theta1 + dt) + phi2) + dp
    bad = np.flatnonzero(~((a + p2 + dp > 0) & (np.abs(a) < THETA_MAX)
                           & (np.abs(b) < THETA_MAX)))
    if not bad.size:
        return dt, dp
    n = STEP_HALVINGS
    half = np.full((bad.size, n + 1), 0.5)
    half[:, 0] = dt[bad]
    cand_t = np.multiply.accumulate(half, axis=1)
    half[:, 0] = dp[bad]
    cand_p = np.multiply.accumulate(half, axis=1)
    t1b, p2b = t1[bad, None], p2[bad, None]
    a, b = t1b + cand_t, p2b + cand_p
    ok = (a + p2b + cand_p > 0) & (np.abs(a) < THETA_MAX) & (np.abs(b) < THETA_MAX)
    ok[:, n] = True
    rows, m = np.arange(bad.size), ok.argmax(axis=1)
    dt, dp = dt.copy(), dp.copy()
    dt[bad], dp[bad] = cand_t[rows, m], cand_p[rows, m]
    return dt, dp


def samedir_shape(r_in: np.ndarray, r_out: np.ndarray, rate: np.ndarray,
                  deviation: bool = True, like: SameDirShape | None = None,
                  newton=None) -> SameDirShape:
    """The transition of rate ``rate`` between arcs of radii ``r_in``, ``r_out`` curving
    the same way.

    Parameters
    ----------
    r_in, r_out, rate : numpy.ndarray, shape (k,)
        mm, mm, 1/mm^2 (``r_in != r_out``).
    deviation : bool
        Also measure the deviation (else ``nan``).
    like : SameDirShape, optional
        The same transitions at a nearby rate: each tries first the side its pair sits
        on there (:func:`_solve`; the sizing's steps, where a ratio beyond the flatter
        arc's landing would otherwise let Newton's method wander for
        :data:`NEWTON_MAX_ITER` steps at every rate). The result may then put the pair
        on the sharper arc where the flatter one lands: :func:`samedir_canonical`
        makes it the model's.
    newton : callable, optional
        Another implementation of :func:`_newton` (the same arguments and results, bit
        for bit: the compiled steps of :mod:`reference.transition_kernel`, which this
        package cannot import); by default :func:`_newton`.

    Returns
    -------
    SameDirShape
        ``theta`` is ``nan`` where the landing was not found or a trim is not positive.
    """
    r_in, r_out, rate = (np.asarray(v, dtype=np.float64) for v in (r_in, r_out, rate))
    ramp = 1.0 / (np.minimum(r_in, r_out) * rate)
    first = None if like is None else np.where(np.isfinite(like.theta), _on_second(like),
                                                r_out > r_in)
    # the ramps' starts found by the Newton implementation (the compiled one's own)
    t1, p2 = _solve(r_in, r_out, ramp, rate, None, first, newton)
    sh = _shaped(r_in, r_out, rate, ramp, t1, p2)
    return samedir_measured(sh) if deviation else sh


def _shaped(r_in, r_out, rate, ramp, t1, p2) -> SameDirShape:
    """The transitions (without their deviation) of the landing ``theta1 = t1``,
    ``phi2 = p2`` (shape (k,) each, ``nan``: none) at rate ``rate`` with ramps of length
    ``ramp``: the rest of :func:`samedir_shape` once its landing is known."""
    trim_in, trim_out = t1 * r_in + 0.5 * ramp, p2 * r_out + 0.5 * ramp
    ok = (trim_in > 0) & (trim_out > 0)
    t1, p2 = np.where(ok, t1, np.nan), np.where(ok, p2, np.nan)
    h = np.where(ok, t1 + p2, 1.0)
    l_p = np.sqrt(h / rate)
    d_p = _pair_distance(h, rate)
    return SameDirShape(r_in, r_out, rate, ramp, ramp, l_p, h, d_p, t1, p2, trim_in,
                        trim_out, np.full_like(rate, np.nan), 2.0 * ramp + 2.0 * l_p,
                        np.minimum(np.minimum(r_in, r_out), 1.0 / (rate * l_p)))


def _on_second(sh: SameDirShape) -> np.ndarray:
    """The pair sits on the second arc (the ramp onto it is the one far from ``J``: its
    line is the farther from the common tangent, module docstring), shape (k,)."""
    return np.abs(sh.theta) < np.abs(sh.phi)


def samedir_canonical(sh: SameDirShape, newton=None) -> SameDirShape:
    """``sh`` (built ``like`` another shape, :func:`samedir_shape`) as the model has it:
    where its pair sits on the sharper arc, the flatter arc's landing is tried (as
    :func:`_solve` tries it first) and, where that lands, the transition is built
    again; elsewhere ``sh`` is already the model's (the same iterations). The flatter
    arc's landing found here is the one :func:`samedir_shape` would find first (the
    same Newton iteration from the same start, each transition's own), so the
    transitions are built from it (:func:`_shaped`) instead of solved a second time.
    ``newton`` as for :func:`samedir_shape`."""
    sharp = np.flatnonzero(np.isfinite(sh.theta) & (_on_second(sh) != (sh.r_out > sh.r_in)))
    if not sharp.size:
        return sh
    r1, r2, c, ramp = sh.r_in[sharp], sh.r_out[sharp], sh.rate[sharp], sh.ramp_in[sharp]
    t1, p2 = (newton or _newton)(r1, r2, ramp, c, None, r2 > r1)
    lands = np.flatnonzero(np.isfinite(t1))
    if not lands.size:
        return sh
    part = _shaped(r1[lands], r2[lands], c[lands], ramp[lands], t1[lands], p2[lands])
    return scatter(sh, sharp[lands], part)


def samedir_measured(sh: SameDirShape, search=None, pieces=None) -> SameDirShape:
    """``sh`` with its deviation measured where it lands (``nan`` elsewhere): what
    :func:`samedir_shape` returns with ``deviation=True`` for the same radii and rates
    (its landing is each transition's own, whatever the batch); ``search`` as for
    :func:`reference.core.transition_sbend.pieces_deviation`, ``pieces`` as for
    :func:`samedir_for_deviation`."""
    ok = np.isfinite(sh.theta)
    dev = np.full_like(sh.rate, np.nan)
    if ok.any():
        i = np.flatnonzero(ok)
        part = take(sh, i)
        dev[i] = pieces_deviation((pieces or _canonical_pieces)(part), part.r_in,
                                  part.r_out, part.r_out, _search(search))
    return SameDirShape(*(dev if f == "deviation" else getattr(sh, f)
                          for f in SameDirShape.__slots__))


def _canonical_pieces(sh: SameDirShape):
    """Zero-curvature ends, ``e1``, ``e2`` (shape (k, 4, 2) each), signed rates and
    lengths (shape (k, 4)) of the four pieces in the canonical frame."""
    q1, q2, ua, na, ub, nb, _, _ = _ends(sh.theta, sh.phi, sh.r_in, sh.r_out,
                                         _ramp_starts(sh.r_in, sh.r_out, sh.ramp_in,
                                                      sh.ramp_out))
    # e1 points to growing sigma from each piece's zero-curvature end, e2 to the side it
    # bends towards (every piece bends towards the arcs' centres)
    pts = [q1, q1, q2, q2]
    e1s = [-ua, ua, -ub, ub]
    e2s = [na, na, nb, nb]
    c = sh.rate
    rates = np.stack((-1.0 / (sh.r_in * sh.ramp_in), c, -c,
                      1.0 / (sh.r_out * sh.ramp_out)), axis=1)
    lengths = np.stack((sh.ramp_in, sh.piece, sh.piece, sh.ramp_out), axis=1)
    return (np.stack(pts, axis=1), np.stack(e1s, axis=1), np.stack(e2s, axis=1), rates,
            lengths)


def samedir_for_deviation(r_in: np.ndarray, r_out: np.ndarray, deviation: np.ndarray,
                          search=None, newton=None, pieces=None, defer=None) -> SameDirShape:
    """The transitions that deviate from the arcs by ``deviation`` (the S-bend's sizing,
    :func:`reference.core.transition_sbend.size_for_deviation`, from the first estimate
    of :func:`reference.core.transition_sbend.ratio_guess`: ``c^2 e R^3`` measured at
    ``L/R = 0.01`` is 1.31 at ``rho`` = 1.2, 0.47 at 2, 0.14 at 4, 0.025 at 16, and 1.94
    at 32, where the pair sits on the sharper arc).

    Parameters
    ----------
    r_in, r_out, deviation : numpy.ndarray, shape (k,)
        mm (``deviation > 0``, ``r_in != r_out``).
    search : callable, optional
        As for :func:`reference.core.transition_sbend.pieces_deviation`.
    newton : callable, optional
        As for :func:`samedir_shape`.
    pieces : callable, optional
        Another implementation of :func:`_canonical_pieces` (the same argument and
        results, bit for bit: the compiled one of :mod:`reference.transition_kernel`);
        by default :func:`_canonical_pieces`.
    defer : callable, optional
        As for :func:`reference.core.transition_sbend.size_for_deviation`.

    Returns
    -------
    SameDirShape
    """
    r_in, r_out, deviation = (np.asarray(v, dtype=np.float64)
                              for v in (r_in, r_out, deviation))
    shape_of, canonical = samedir_shape, samedir_canonical
    if newton is not None:
        shape_of = partial(samedir_shape, newton=newton)
        canonical = partial(samedir_canonical, newton=newton)
    return size_for_deviation(shape_of, pieces or _canonical_pieces, r_out, r_in, r_out,
                              deviation, ratio_guess(_samedir_table(), r_in, r_out,
                                                     deviation),
                              canonical=canonical, search=_search(search), defer=defer)


def _search(search=None):
    """The deviation search of these transitions: ``search`` (as for
    :func:`reference.core.transition_sbend.pieces_deviation`; by default the vectorised
    one, looked up at each call) with the full search's :data:`SCAN_ROUNDS`."""
    return partial(search or transition_sbend._deviation_where, scan=SCAN_ROUNDS)


@lru_cache(maxsize=None)
def _samedir_table() -> tuple[np.ndarray, np.ndarray]:
    """:func:`reference.core.transition_sbend.ratio_table` of arcs curving the same way
    (built once; its ratios avoid 1, where the two arcs are one circle)."""
    return ratio_table(samedir_shape)


def samedir_rows(junction: np.ndarray, along: np.ndarray, inward: np.ndarray,
                 sh: SameDirShape, block: np.ndarray, kind_code: int, pieces=None
                 ) -> dict[str, np.ndarray]:
    """Packed rows of the transitions, :data:`SAMEDIR_PIECES` per transition in path
    order (:func:`reference.core.transition_sbend.pieces_rows`; ``inward`` towards the
    arcs' centres); ``pieces`` as for :func:`samedir_for_deviation`."""
    return pieces_rows((pieces or _canonical_pieces)(sh), junction, along, inward, block,
                       kind_code)


__all__ = ["SAMEDIR_PIECES", "SameDirShape", "samedir_canonical", "samedir_for_deviation",
           "samedir_measured",
           "samedir_rows", "samedir_shape"]
