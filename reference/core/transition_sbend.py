"""Geometry of G645's rounding of a tangential S-bend: two arcs curving opposite ways.

sinumerik-model 5.7: "At tangential transitions with a curvature jump (e.g. line to arc),
G645 also inserts rounding, using MD33120 PATH_TRANS_POS_TOL"; 5.8 models the inserted
block as a curvature ramp (:mod:`reference.core.transition` for a line and an arc).
Between an arc of curvature ``+1/R1`` and a tangent arc of curvature ``-1/R2`` (G2 then
G3, or G3 then G2, in one plane) the curvature jumps by ``1/R1 + 1/R2``.

*No monotone ramp lands on the arc.* Let ``e(s) = kappa(s) - kappa_prog(s)`` be the
curvature of a rounding minus the programmed one (``+1/R1`` before the junction ``J``
at ``s = 0``, ``-1/R2`` after). For the rounding to leave the first arc and land on the
second with its position and tangent, in the small-angle picture ``int e ds = 0``
(heading) and ``int s e ds = 0`` (sideways position). If ``kappa`` fell monotonically
from ``1/R1`` to ``-1/R2``, then ``e <= 0`` before ``J`` and ``e >= 0`` after it, so
``s e >= 0`` everywhere and ``int s e ds > 0``: it cannot land (the classical result that
a reverse clothoid joins two circles only if they are apart, centre distance
``> R1 + R2``, while tangent circles are at ``R1 + R2``). The curvature must overshoot.

*The model*, built of clothoid pieces that each have a zero-curvature end
(:mod:`reference.core.geometry`)::

    1/R1 -> 0 (ramp A, length L) -> +k_s -> 0 -> -k_s -> 0 (the S, 4 pieces of L_s)
         -> -1/R2 (ramp B, length L)

Both ramps have one length ``L`` (rates ``1/(R1 L)`` and ``1/(R2 L)``), the S pieces the
larger rate ``c = 1/(min(R1, R2) L)``: the fastest-changing piece sets the path jerk
``v^3 c``, none is steeper than it must be, and the ramp onto the flatter arc is not
shorter than the other (every piece costs an IPO cycle, spec 5.3).

Ramp A leaves the first arc, ramp B lands on the second: each is the ramp of the
line-arc transition (:func:`reference.core.transition.ramp_offset`) onto its own arc,
with its zero-curvature end on a line of heading ``-theta`` (``theta`` measured from
the common tangent at ``J``, towards the second arc's side). Both lines are parallel;
the one of ramp B lies ``lat = 2 (R1 + R2) sin^2(theta/2) + p1 + p2`` further towards
the first arc's centre (``p = -y_Q`` each ramp's classical shift) and starts ``adv =
(R1 + R2) sin theta + x_Q1 + x_Q2`` further along. The S of two symmetric clothoid pairs
(turn ``h``, :func:`reference.core.transition.s_shift` with the rate ``c``) takes up
``lat`` sideways and ``2 d_p (1 + cos h)`` along; ``theta`` is the root of "the S's
advance equals ``adv``" (one unknown per transition). It is solved in the S's turn
``h`` instead of ``theta`` (:func:`_turn_root`): for a given ``h`` the S's pieces,
``d_p`` and ``lat`` are closed forms and so is the ``theta`` whose lines are ``lat``
apart, so each step is one Fresnel evaluation and Newton's method has the exact
derivative; where the ramps are long or the first bracket fails, by a safeguarded
secant in ``theta`` (each step the fixed point of ``s_shift``).
The rounding then is G2 continuous with both arcs and lands exactly; the first arc is
shortened by ``theta R1 + L1/2``, the second by ``theta R2 + L2/2`` (both stay the exact
programmed arcs). The curvature overshoot is the S's peak ``k_s = c L_s`` (about
``2.4/R`` for ``R1 = R2 = R``): the price of landing, and why a given deviation needs a
much shorter ramp than at a line-arc transition.

*Sizing.* The largest distance from the programmed contour (the two arcs) has no closed
form: it is sampled along the rounding (:data:`DEV_SAMPLES` per piece), the largest
sample refined on finer grids around it (:data:`SCAN_ROUNDS`) and then by Newton steps
on the distance's slope (:func:`pieces_deviation`). The rate ``c`` is the root of
"deviation = tolerance" (the deviation grows like ``1/c^2``; Newton-secant steps in
``log c`` from a table of the model's own deviation against the radius ratio,
:func:`ratio_table`), the steps measuring cheaply by following one local maximum and
the answer by the full search (:func:`size_for_deviation`).

Canonical frame (per transition): origin ``J``, ``x`` along the direction of travel,
``y`` towards the first arc's centre (so the centres are at ``(0, R1)`` and
``(0, -R2)``).

Units: mm, rad. Shapes: ``k`` transitions, ``n`` axes.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .geometry import _fresnel, clothoid_pair_shape, clothoid_rows
from .transition import SOLVE_MAX_ITER, SOLVE_REL_TOL, ramp_offset

#: Pieces per S-bend transition: ramp A, the S's four pieces, ramp B.
SBEND_PIECES = 6
#: Samples per piece of the deviation search. The largest sample is then refined, so
#: this only has to separate the local maxima (each piece turns by less than a quarter
#: turn and the deviation has at most one bump per piece; 12 samples put several on
#: each).
DEV_SAMPLES = 12
#: Scan rounds after the samples (:func:`sbend_deviation`): each evaluates
#: :data:`REFINE_POINTS` points evenly over the span ``+-h`` around the best so far
#: (``h`` at first the sample spacing) and divides ``h`` by :data:`REFINE_SHRINK` (the
#: points' own spacing, so the maximum stays inside). Two rounds pick the highest of
#: the local maxima on the plateau near the junction (~1e-5 apart in value, ~0.1 mm in
#: place at R ~ 100 mm); Newton steps then find the maximum in the last span.
SCAN_ROUNDS = 2
REFINE_POINTS = 9
REFINE_SHRINK = 4.0
#: Samples per piece of the first, coarse search of the sizing (:func:`size_for_deviation`:
#: it only has to find a local maximum to follow; the answer is measured in full).
LOCATE_SAMPLES = 4
#: Cap of the Newton steps on the distance's slope (3-6 in practice) and the step
#: below which they stop, relative to the rounding's length (the maximum's value is then
#: exact to round-off: it is flat to second order).
NEWTON_MAX_ITER = 12
NEWTON_STEP_TOL = 1e-12
#: Rounds of the fallback refinement by sampling where the Newton steps do not converge
#: (as the scan; after 6 rounds ``h`` is 4^-6 ~ 2.4e-4 of the sample spacing, and the
#: vertex of the parabola through the last three points puts a smooth maximum's value
#: far below round-off of the tolerance).
REFINE_ROUNDS = 6
#: Iteration cap of the ``theta`` root (bracketed secant with the Illinois correction;
#: 8-25 steps over a batch in practice) and of the ``log c`` root (4-7 in practice).
ROOT_MAX_ITER = 100
#: The ``theta`` root stops when the S's advance misses the ramp B's start by at most
#: this (the landing error, mm: a thousandth of the 1e-9 mm to which consecutive
#: segments must meet), or when its bracket is narrower than THETA_TOL (rad: round-off
#: of the heading).
LANDING_TOL_MM = 1e-12
THETA_TOL = 1e-15
#: The turn ``h`` of the S (:func:`_turn_root`) also stops when its bracket is this
#: narrow relative to ``h`` (round-off: the landing then misses by round-off too).
TURN_REL_TOL = 4e-16
#: The root is sought in the turn where the ramps are at most this long relative to the
#: smaller radius, ``L / R = L^2 c`` (:func:`sbend_shape`).
TURN_ROOT_MAX_RAMP = 0.1
#: The rate aims at a deviation this much (relative) below the tolerance, and stops
#: within half of it (the deviation itself is found to about 1e-13 relative), so the
#: tolerance is used to 1.5e-9 and never exceeded.
DEVIATION_REL_TOL = 1e-9
#: The sizing is done where ``log`` of the measured deviation is within this of its aim
#: (:func:`sizing_aim`); a measure at most this above the aim is within the tolerance.
ACCEPT_LOG_TOL = 0.5 * DEVIATION_REL_TOL
#: A followed local maximum (:func:`size_for_deviation`) is taken to have met the aim
#: when its ``log`` deviation is this close to it; the full measure at that rate then
#: decides (it finds the same maximum to round-off, well inside the margin's half).
TRACK_REL_TOL = 0.1 * DEVIATION_REL_TOL
#: Steps of the sizing that follow a local maximum (4-6 in practice); a transition not
#: settled by then is sized with the full search at every step.
TRACK_MAX_ITER = 20
#: A step of the sizing taken by the secant from a followed maximum this close to the
#: aim (``|log`` deviation less the aim``|``) is measured by the full search at once,
#: which decides it (:func:`size_for_deviation`), instead of by the refinement alone and
#: the full search after it. Measured on the same-way row of
#: ``tests/bench/bench_rounding.py``: such steps start 2e-7 .. 1e-3 from the aim (median
#: 9e-7) and land below 1e-10 for 94 % of the transitions; measured so, 5,700 of the
#: 6,200 transitions sized there are decided one refinement sooner (6,800 instead of
#: 12,800 refinements a build), and none is sized in full any more (13 were: their full
#: measure found a higher maximum, which the steps now follow).
CHECK_LOG_TOL = 1e-5
#: A transition still being sized is handed over to the caller's ``defer`` (the
#: block-length clamp) once its trim exceeds the cap by more than ``2 |g|`` plus this
#: (``log``; ``g`` the last measure's ``log`` deviation less the aim): the rate of the
#: tolerance is then within ``|g| / 2`` of the present one at the deviation's slope of
#: -2 (within ``2 |g|`` for any slope the steps accept, down to -0.5), the trims shrink
#: about like ``1 / rate``, so the clamp's rate is the higher and the answer (the
#: larger of the two rates) is the clamp's. This margin covers the slope's spread at
#: the first estimate; where the clamp's measure shows the tolerance's rate higher
#: after all (the maximum followed was not the highest), the caller sizes it again.
DEFER_LOG_MARGIN = 0.01
#: Largest ``theta`` searched, rad: a larger one would mean a rounding that replaces
#: more than a quarter turn of each arc (the block-length clamp acts long before).
THETA_MAX = 0.5 * np.pi
#: First upper end of the ``theta`` bracket, times ``(L1 + L2) / (R1 + R2)`` (the
#: small-angle root is about 5.4 times it for ``R1 = R2``); THETA_MAX where it does not
#: bracket.
THETA_GUESS = 16.0
#: A rate for which no heading lands (pieces far too long) is raised by this factor.
RATE_BRACKET_STEP = 4.0
#: The table of the sizing's first estimate (:func:`ratio_table`): ``L/R`` of its
#: transitions, its number of radius ratios and the largest ``|log rho|`` (a ratio of
#: 1000); the small-angle S-bend value ``e c^2 R^3`` for ``R1 = R2`` where it has none.
GUESS_RAMP = 0.01
GUESS_POINTS = 96
GUESS_MAX_LOG_RATIO = np.log(1000.0)
GUESS_G = 1.8


@dataclass(frozen=True, slots=True, eq=False)
class SBendShape:
    """Size of S-bend transitions (module docstring), shape (k,) each.

    Attributes
    ----------
    r_in, r_out : numpy.ndarray
        Radii of the first and second arc, mm.
    rate : numpy.ndarray
        Curvature rate ``c`` of the S pieces and the steeper ramp, 1/mm^2.
    ramp_in, ramp_out : numpy.ndarray
        Ramp lengths, both ``L = 1/(min(R1, R2) c)``, mm.
    piece : numpy.ndarray
        Length ``L_s`` of each S piece, mm.
    turn, pair_distance : numpy.ndarray
        Turn ``h`` (rad) and tangent distance ``d_p`` (mm) of each S pair.
    theta : numpy.ndarray
        Heading of the S, from the common tangent towards the second arc's side, rad.
    trim_in, trim_out : numpy.ndarray
        How much of the first and of the second arc the rounding replaces, mm.
    deviation : numpy.ndarray
        Largest distance from the programmed contour, mm.
    length : numpy.ndarray
        Length of the rounding ``2 L + 4 L_s``, mm.
    min_radius : numpy.ndarray
        Smallest radius of curvature along the rounding and the arcs' ends,
        ``min(R1, R2, 1/(c L_s))``, mm.
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
    trim_in: np.ndarray
    trim_out: np.ndarray
    deviation: np.ndarray
    length: np.ndarray
    min_radius: np.ndarray


def _s_of(theta, r_in, r_out, rate, xq, yq):
    """The S for heading ``theta``: residual ``adv - advance`` (mm), ``L_s``, ``h``,
    ``d_p`` (:func:`_s_shift_each`, each transition's own fixed point)."""
    rr = r_in + r_out
    lat = 2.0 * rr * np.sin(0.5 * theta) ** 2 - yq
    l_s, h, d_p = _s_shift_each(lat, rate)
    return rr * np.sin(theta) + xq - 2.0 * d_p * (1.0 + np.cos(h)), l_s, h, d_p


def _s_shift_each(shift: np.ndarray, rate: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`reference.core.transition.s_shift` with each transition's fixed point
    stopped on its own (there the batch stops at once): ``L_s``, ``h``, ``d_p``, mm,
    rad, mm, shape (k,) each, what each transition gives alone."""
    l_s = np.cbrt(shift / (2.0 * rate))
    act = np.arange(l_s.size)
    sa, ca, la = shift, rate, l_s
    for _ in range(SOLVE_MAX_ITER):
        h = ca * la * la
        d_1, _ = clothoid_pair_shape(h)
        step = np.cbrt(sa / (2.0 * la * d_1 * np.sin(h)))
        la = la * step
        go = ~(np.abs(step - 1.0) <= SOLVE_REL_TOL)
        if not go.all():
            l_s[act] = la
            act, sa, ca, la = act[go], sa[go], ca[go], la[go]
            if not act.size:
                break
    l_s[act] = la
    h = rate * l_s * l_s
    d_1, _ = clothoid_pair_shape(h)
    return l_s, h, l_s * d_1


def _s_of_turn(h, rr, rate, xq, yq):
    """The S of turn ``h`` (rad, shape (m,)) and the heading it needs: the residual ``F =
    adv - advance`` (mm), its derivative ``dF/dh`` (mm/rad), ``theta``, ``L_s``, ``d_p``.

    The S of two symmetric pairs of turn ``h`` at rate ``c`` has pieces ``L_s = sqrt(h /
    c)``, the tangent distance ``d_p = L_s d_1(h)`` and moves sideways by ``lat = 2 d_p
    sin h``; the heading ``theta`` whose lines are that far apart follows from ``lat =
    2 (R1 + R2) sin^2(theta/2) - y_Q`` in closed form, so the landing is one equation in
    ``h`` with no inner fixed point (:func:`_s_of` has one per heading). Derivatives:
    ``d_p' = d_p / (2 h) + L_s d_1'(h)`` (``d_1'`` in closed form,
    :func:`_pair_distance_slope`), ``lat' = 2 (d_p' sin h + d_p cos h)``, ``d(rr sin
    theta) = lat' cot(theta) dh`` (from ``rr sin(theta) dtheta = dlat``) and
    ``advance' = 2 d_p' (1 + cos h) - 2 d_p sin h``."""
    l_s = np.sqrt(h / rate)
    d_1, e_1 = clothoid_pair_shape(h)
    d_p = l_s * d_1
    sin_h, cos_h = np.sin(h), np.cos(h)
    lat = 2.0 * d_p * sin_h
    u = np.clip((lat + yq) / (2.0 * rr), 0.0, 1.0)            # sin^2(theta/2)
    theta = 2.0 * np.arcsin(np.sqrt(u))
    sin_t, cos_t = np.sin(theta), np.cos(theta)
    f = rr * sin_t + xq - 2.0 * d_p * (1.0 + cos_h)
    dd_p = 0.5 * d_p / h + l_s * _pair_distance_slope(h, d_1, e_1)
    dlat = 2.0 * (dd_p * sin_h + d_p * cos_h)
    with np.errstate(divide="ignore", invalid="ignore"):
        df = dlat * cos_t / sin_t - 2.0 * dd_p * (1.0 + cos_h) + 2.0 * d_p * sin_h
    return f, df, theta, l_s, d_p


def _pair_distance_slope(h: np.ndarray, d_1: np.ndarray, e_1: np.ndarray) -> np.ndarray:
    """``d_1'(h)``, the derivative of the unit pair's tangent distance
    (:func:`reference.core.geometry.clothoid_pair_shape`, ``d_1``, ``e_1`` its values at
    ``h``): ``d_1 = X + Y tan(h/2)`` with ``X = int_0^1 cos(h t^2/2) dt``, ``Y = int_0^1
    sin(h t^2/2) dt`` (``Y = e_1 cos(h/2)``); integrating ``t^2 sin`` and ``t^2 cos`` by
    parts, ``X' = (cos(h/2) - X) / (2 h)`` and ``Y' = (sin(h/2) - Y) / (2 h)``
    (relative error ``~eps / h^2`` from the cancellation in ``cos(h/2) - X``; it only
    slows Newton's method, whose root is the residual's)."""
    ch, sh, th = np.cos(0.5 * h), np.sin(0.5 * h), np.tan(0.5 * h)
    y = e_1 * ch
    x = d_1 - y * th
    return (ch - x) / (2.0 * h) + (sh - y) / (2.0 * h) * th + 0.5 * y / (ch * ch)


def _turn_root(rr, rate, xq, yq, lo, hi, f_lo, f_hi):
    """The S's turn ``h`` in ``[lo, hi]`` (``F(lo) < 0 < F(hi)``, :func:`_s_of_turn`)
    where the S lands: Newton steps from the secant point, kept inside a bracket that
    each value's sign shrinks (a step leaving it bisects instead), each transition until
    ``|F| <= LANDING_TOL_MM`` or its bracket is round-off of ``h``; a transition that is
    done is no longer moved (each is what it would be alone). Returns ``h`` and whether
    it converged within :data:`ROOT_MAX_ITER` steps, shape (m,) each.
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        h = lo - f_lo * (hi - lo) / (f_hi - f_lo)
    h = np.where((h > lo) & (h < hi), h, 0.5 * (lo + hi))
    out = h.copy()
    conv = np.ones(h.size, bool)
    act = np.arange(h.size)
    cols = (rr, rate, xq, yq)
    for _ in range(ROOT_MAX_ITER):
        f, df = _s_of_turn(h, *cols)[:2]
        lo = np.where(f < 0, h, lo)
        hi = np.where(f < 0, hi, h)
        with np.errstate(divide="ignore", invalid="ignore"):
            nxt = h - f / df
        nxt = np.where((nxt > lo) & (nxt < hi), nxt, 0.5 * (lo + hi))
        stop = (np.abs(f) <= LANDING_TOL_MM) | (hi - lo <= TURN_REL_TOL * h)
        h = np.where(stop, h, nxt)
        if stop.any():
            out[act] = h
            go = ~stop
            act, h, lo, hi = act[go], h[go], lo[go], hi[go]
            cols = tuple(c[go] for c in cols)
            if not act.size:
                break
    out[act] = h
    conv[act] = False
    return out, conv


def _illinois(f, lo, hi, f_lo, f_hi, tol, ftol):
    """Vectorised Illinois root of ``f`` in brackets ``[lo, hi]`` (``f_lo < 0 < f_hi``),
    each until its bracket is narrower than ``tol`` or its last value below ``ftol``;
    the last iterates. A root that is done is no longer moved, so each one is what it
    would be alone (not depending on the others in the batch)."""
    side = np.zeros(lo.shape, np.int8)
    x = 0.5 * (lo + hi)
    fx = np.full(lo.shape, np.inf)
    for _ in range(ROOT_MAX_ITER):
        w = hi - lo
        todo = ~((w <= tol) | (np.abs(fx) <= ftol))
        if not todo.any():
            break
        with np.errstate(divide="ignore", invalid="ignore"):
            xn = lo - f_lo * w / (f_hi - f_lo)
        bad = ~((xn > lo) & (xn < hi))
        xn = np.where(bad, 0.5 * (lo + hi), xn)
        fn = f(xn)
        x, fx = np.where(todo, xn, x), np.where(todo, fn, fx)
        neg = todo & (fn < 0)
        pos = todo & ~(fn < 0)
        # Illinois: halve the value kept twice on the same side
        f_hi = np.where(neg & (side == -1), 0.5 * f_hi, f_hi)
        f_lo = np.where(pos & (side == 1), 0.5 * f_lo, f_lo)
        lo, f_lo = np.where(neg, xn, lo), np.where(neg, fn, f_lo)
        hi, f_hi = np.where(pos, xn, hi), np.where(pos, fn, f_hi)
        side = np.where(neg, -1, np.where(pos, 1, side)).astype(np.int8)
    return x


def _canonical_pieces(sh: SBendShape):
    """Zero-curvature ends, ``e1``, ``e2`` (shape (k, 6, 2) each), signed rates and
    lengths (shape (k, 6)) of the six pieces in the canonical frame."""
    th, h, d_p = sh.theta, sh.turn, sh.pair_distance
    u = np.stack((np.cos(th), -np.sin(th)), axis=1)
    nrm = np.stack((np.sin(th), np.cos(th)), axis=1)
    xq1, yq1, _, _ = ramp_offset(sh.r_in, sh.ramp_in)
    xq2, yq2, _, _ = ramp_offset(sh.r_out, sh.ramp_out)
    # the points where each ramp's line touches its arc (heading -theta)
    j1 = np.stack((-sh.r_in * np.sin(th), 2.0 * sh.r_in * np.sin(0.5 * th) ** 2), axis=1)
    q1 = j1 - xq1[:, None] * u + yq1[:, None] * nrm
    ch, s_h = np.cos(h)[:, None], np.sin(h)[:, None]
    p1 = q1 + (d_p[:, None] * (1.0 + ch)) * u + (d_p[:, None] * s_h) * nrm
    q2 = q1 + (2.0 * d_p[:, None] * (1.0 + ch)) * u + (2.0 * d_p[:, None] * s_h) * nrm
    heading = ch * u + s_h * nrm                      # between the pairs
    # e2: the side each piece bends towards (its centre of curvature): ramp A towards
    # the first arc's centre, the first pair to the left, the second to the right,
    # ramp B towards the second arc's centre
    pts = [q1, q1, p1, p1, q2, q2]
    e1s = [-u, u, -heading, heading, -u, u]
    e2s = [nrm, nrm, ch * nrm - s_h * u, s_h * u - ch * nrm, -nrm, -nrm]
    c = sh.rate
    rates = np.stack((-1.0 / (sh.r_in * sh.ramp_in), c, -c, c, -c,
                      1.0 / (sh.r_out * sh.ramp_out)), axis=1)
    lengths = np.stack((sh.ramp_in, sh.piece, sh.piece, sh.piece, sh.piece, sh.ramp_out),
                       axis=1)
    return (np.stack(pts, axis=1), np.stack(e1s, axis=1), np.stack(e2s, axis=1), rates,
            lengths)


def _samples(pieces, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``n + 1`` evenly spaced points on each piece (both ends): distances from the
    rounding's start and the points' canonical ``x`` and ``y``, shape (k, 6 (n + 1))
    each (the model of :mod:`reference.core.geometry`, positions only: ``sigma`` from
    the zero-curvature end, ``q = o + a C(sigma / a) e1 + a S(sigma / a) e2`` with
    ``a = sqrt(pi / c)``)."""
    origin, e1, e2, rates, lengths = pieces
    k = rates.shape[0]
    s_local = lengths[:, :, None] * np.linspace(0.0, 1.0, n + 1)[None, None, :]
    sigma = np.where(rates[:, :, None] < 0, lengths[:, :, None] - s_local, s_local)
    scale = np.sqrt(np.pi / np.abs(rates))[:, :, None]
    fs, fc = _fresnel(sigma / scale)
    fc, fs = scale * fc, scale * fs
    x = origin[:, :, None, 0] + fc * e1[:, :, None, 0] + fs * e2[:, :, None, 0]
    y = origin[:, :, None, 1] + fc * e1[:, :, None, 1] + fs * e2[:, :, None, 1]
    starts = np.cumsum(lengths, axis=1) - lengths
    return ((starts[:, :, None] + s_local).reshape(k, -1), x.reshape(k, -1),
            y.reshape(k, -1))


def _packed(pieces) -> np.ndarray:
    """The pieces of each transition as one array, shape (k, p, 9): zero-curvature
    end (2), ``e1`` (2), ``e2`` (2), signed rate, length, distance of the piece's start
    from the rounding's start (one gather per point instead of one per field)."""
    origin, e1, e2, rates, lengths = pieces
    starts = np.cumsum(lengths, axis=1) - lengths
    return np.concatenate((origin, e1, e2, rates[..., None], lengths[..., None],
                           starts[..., None]), axis=2)


def _on_pieces(packed: np.ndarray, s: np.ndarray, derivatives: bool = True):
    """Canonical points, unit tangents and second derivatives at distances ``s`` (shape
    (k,) or (k, N)) from the rounding's start, shape ``s.shape + (2,)`` each (the model
    of :mod:`reference.core.geometry`: ``sigma`` from the zero-curvature end, the
    heading ``c sigma^2 / 2`` from ``e1`` towards ``e2``, the tangent reversed on a
    piece whose zero-curvature end is its last point); the points alone unless
    ``derivatives``."""
    k, p = packed.shape[:2]
    ends = packed[:, :, 7] + packed[:, :, 8]
    col = (k,) + (1,) * (s.ndim - 1)
    # the piece each point lies on: how many pieces end at or before it (the last
    # piece at most), counted piece by piece, and one gather from the flattened rows
    idx = np.zeros(s.shape, np.intp)
    for j in range(p - 1):
        idx += s >= ends[:, j].reshape(col)
    flat = idx + (np.arange(k) * p).reshape(col)
    g = packed.reshape(k * p, packed.shape[2]).take(flat, axis=0)   # s.shape + (9,)
    # (the two components apart: the same numbers as on s.shape + (2,) rows, without
    # broadcasting over strided views)
    rate, length = g[..., 6], g[..., 7]
    s_local = s - g[..., 8]
    c = np.abs(rate)
    sigma = np.minimum(np.maximum(np.where(rate < 0, length - s_local, s_local), 0.0),
                       length)
    scale = np.sqrt(np.pi / c)
    fs, fc = _fresnel(sigma / scale)
    a, b = scale * fc, scale * fs
    p = _xy(g[..., 0] + a * g[..., 2] + b * g[..., 4],
            g[..., 1] + a * g[..., 3] + b * g[..., 5])
    if not derivatives:
        return p
    phi = 0.5 * c * sigma * sigma
    cos, sin = np.cos(phi), np.sin(phi)
    sign = np.where(rate < 0, -1.0, 1.0)
    tangent = _xy(sign * (cos * g[..., 2] + sin * g[..., 4]),
                  sign * (cos * g[..., 3] + sin * g[..., 5]))
    kappa = c * sigma
    second = _xy(kappa * (cos * g[..., 4] - sin * g[..., 2]),
                 kappa * (cos * g[..., 5] - sin * g[..., 3]))
    return p, tangent, second


def _xy(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Components ``x``, ``y`` as one array, shape ``x.shape + (2,)``."""
    out = np.empty(x.shape + (2,))
    out[..., 0], out[..., 1] = x, y
    return out


def _circle(first: np.ndarray, r_in: np.ndarray, r_out: np.ndarray,
            centre_out: np.ndarray):
    """Centre height ``y_c`` and radius of the programmed circle that measures the
    distance: the first where ``first`` (``x <= 0``), else the second
    (:func:`_distance`)."""
    return np.where(first, r_in, centre_out), np.where(first, r_in, r_out)


def _distance(x: np.ndarray, y: np.ndarray, r_in: np.ndarray, r_out: np.ndarray,
              centre_out: np.ndarray) -> np.ndarray:
    """Distance of canonical points ``(x, y)`` (shape (k, N) each; radii shape (k,))
    from the programmed contour: the first arc (``x <= 0`` near ``J``, centre ``(0,
    r_in)``) and the second (``x >= 0``, centre ``(0, centre_out)``: ``-r_out`` at an
    S-bend, ``+r_out`` for arcs curving the same way).

    Where a point's radial projection falls beyond an arc's end at ``J``, that arc's
    nearest point is ``J``; ``J`` lies on the other circle, whose distance is at most
    the distance from ``J``, so the contour distance is that from the first circle for
    ``x < 0`` and from the second for ``x > 0`` (at ``x = 0`` both give ``|y|`` near
    ``J``: the distance is continuous there, with its gradient, only its second
    derivative along the rounding jumps). It is computed as ``|x^2 + y^2 - 2 y y_c| /
    (|p - centre| + R)`` (``= ||p - centre| - R|``, centre ``(0, y_c)``, ``|y_c| =
    R``): ``|p - centre| - R`` would lose ``R eps`` to cancellation (2.4e-9 of a 1e-4 mm
    deviation on a 1000 mm arc, above the sizing's margin :data:`DEVIATION_REL_TOL`),
    this form a few ``eps`` of it (the denominator ``~2 R`` needs no more)."""
    yc, r = _circle(x <= 0, r_in[:, None], r_out[:, None], centre_out[:, None])
    qy = y - yc
    return np.abs(x * x + y * (y - 2.0 * yc)) / (np.sqrt(x * x + qy * qy) + r)


def _distance_slopes(packed, s, first, r_in, r_out, centre_out):
    """Distance from one programmed circle (the first where ``first``, else the second)
    of the points at ``s`` and its first and second derivatives along the rounding,
    shape (k,) each (``packed`` (k, 6, 9), the rest (k,)): with ``q = p - centre`` and
    ``D = |q| - R``, ``d = |D|``, ``d' = sign(D) q.t / |q|`` and ``d'' = sign(D)
    ((1 + q.p'') / |q| - (q.t)^2 / |q|^3)`` (``|t| = 1``)."""
    p, tangent, second = _on_pieces(packed, s)
    x, y = p[:, 0], p[:, 1]
    yc, r = _circle(first, r_in, r_out, centre_out)
    qy = y - yc
    norm = np.sqrt(x * x + qy * qy)
    num = x * x + y * (y - 2.0 * yc)                  # |q|^2 - R^2
    sign = np.sign(num)
    qt = x * tangent[:, 0] + qy * tangent[:, 1]
    qa = x * second[:, 0] + qy * second[:, 1]
    slope = sign * qt / norm
    # |q|^3 as two products, not ``** 3``: numpy's power may take a vectorised path
    # (SVML on AVX-512) whose last bit differs from the C library's, so a compiled
    # search (reference.transition_kernel) could not give the same numbers
    bend = sign * ((1.0 + qa) / norm - qt * qt / (norm * norm * norm))
    return np.abs(num) / (norm + r), slope, bend


def _crossing(packed, a, b, xa, xb):
    """Where the roundings cross ``x = 0`` (the normal at ``J``) between ``a`` and
    ``b`` (shape (m,); ``x`` is ``xa <= 0`` at ``a`` and ``xb > 0`` at ``b``, and grows
    along the rounding: its heading stays within a quarter turn of the common tangent),
    by Newton steps on ``x(s)`` (slope the tangent's ``x``) from the secant's root,
    kept inside ``[a, b]``; shape (m,)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t = a - xa * (b - a) / (xb - xa)
    t = np.where((t >= a) & (t <= b), t, 0.5 * (a + b))
    act = np.arange(t.size)               # each steps until its own step is that small
    for _ in range(NEWTON_MAX_ITER):
        if not act.size:
            break
        ta, aa, ba = t[act], a[act], b[act]
        p, tangent, _ = _on_pieces(packed[act], ta)
        nxt = np.clip(ta - p[:, 0] / tangent[:, 0], aa, ba)
        t[act] = nxt
        act = act[~(np.abs(nxt - ta) <= NEWTON_STEP_TOL * ba)]
    return t


def _bracket_max(packed, a, b, first, start, r_in, r_out, centre_out):
    """Largest distance from one programmed circle (``first``: the first) over
    ``[a, b]`` (shape (m,) each, ``packed`` (m, 6, 9)), taken to have one local maximum
    there (:func:`sbend_deviation`). Where the distance falls from ``a`` (rises to
    ``b``) the maximum is that end; else Newton steps on the slope from ``start``, kept
    inside a bracket that each step's slope sign shrinks (a step leaving it, or a point
    where the distance is not concave, bisects instead), until a step is below
    :data:`NEWTON_STEP_TOL` of ``b``. Returns the value, whether it converged and where
    (the distance from the rounding's start), shape (m,) each."""
    d_a, g_a, _ = _distance_slopes(packed, a, first, r_in, r_out, centre_out)
    d_b, g_b, _ = _distance_slopes(packed, b, first, r_in, r_out, centre_out)
    at_a = g_a <= 0
    at_b = ~at_a & (g_b >= 0)
    value = np.where(at_a, d_a, np.where(at_b, d_b, -np.inf))
    where = np.where(at_a, a, b)
    inner = np.flatnonzero(~(at_a | at_b))
    done = np.ones(a.shape, dtype=bool)
    if not inner.size:
        return value, done, where
    pk, lo, hi = packed[inner], a[inner], b[inner]
    fi, r1, r2, c2 = first[inner], r_in[inner], r_out[inner], centre_out[inner]
    x = start[inner]
    x = np.where((x > lo) & (x < hi), x, 0.5 * (lo + hi))
    tol = NEWTON_STEP_TOL * b[inner]
    conv = np.zeros(inner.size, dtype=bool)
    act = np.arange(inner.size)           # each steps until its own step is that small
    for _ in range(NEWTON_MAX_ITER):
        if not act.size:
            break
        xa, la, ha = x[act], lo[act], hi[act]
        _, slope, bend = _distance_slopes(pk[act], xa, fi[act], r1[act], r2[act], c2[act])
        la = np.where(slope > 0, xa, la)
        ha = np.where(slope > 0, ha, xa)
        with np.errstate(divide="ignore", invalid="ignore"):
            nxt = xa - slope / bend
        nxt = np.where((bend < 0) & (nxt >= la) & (nxt <= ha), nxt, 0.5 * (la + ha))
        done_now = np.abs(nxt - xa) <= tol[act]
        x[act], lo[act], hi[act], conv[act] = nxt, la, ha, done_now
        act = act[~done_now]
    value[inner] = _distance_slopes(pk, x, fi, r1, r2, c2)[0]
    done[inner] = conv
    where[inner] = x
    return value, done, where


def sbend_deviation(sh: SBendShape) -> np.ndarray:
    """Largest distance of the rounding from the programmed arcs, mm, shape (k,)
    (:func:`pieces_deviation`)."""
    return pieces_deviation(_canonical_pieces(sh), sh.r_in, sh.r_out, -sh.r_out)


def pieces_deviation(pieces, r_in: np.ndarray, r_out: np.ndarray,
                     centre_out: np.ndarray, search=None) -> np.ndarray:
    """Largest distance of clothoid pieces between two tangent arcs from the arcs, mm,
    shape (k,), for every transition between two arcs.

    Sampled (:data:`DEV_SAMPLES` per piece); the maximum lies within one sample spacing
    ``h`` of the largest sample (the samples separate the local maxima: module
    docstring). :data:`SCAN_ROUNDS` rounds then each evaluate :data:`REFINE_POINTS`
    points over ``+-h`` around the best so far and divide ``h`` by
    :data:`REFINE_SHRINK` (near ``J`` the deviation is a plateau with local maxima
    ~1e-5 apart in value and less than a sample spacing apart in place: the scan picks
    the highest). In the last window the distance is a smooth function of the arc
    length (the curvature is continuous across the pieces) on either side of the point
    where the rounding crosses the normal at ``J`` (:func:`_distance`: the circle that
    measures it changes there, and with it the distance's second derivative); the
    window is cut there and the largest distance on each part from its own circle found
    by :func:`_bracket_max` (Newton steps: a smooth maximum is flat to second order, so
    its value is then exact to round-off). The few transitions not converged in
    :data:`NEWTON_MAX_ITER` steps are refined by sampling (:func:`_refine_sampled`).
    The result is never below the largest point evaluated.

    Parameters
    ----------
    pieces : tuple
        Canonical zero-curvature ends, ``e1``, ``e2`` (shape (k, p, 2) each), signed
        rates and lengths (shape (k, p)) of the ``p`` pieces in path order.
    r_in, r_out, centre_out : numpy.ndarray, shape (k,)
        Radii of the arcs and the canonical ``y`` of the second arc's centre, mm.
    search : callable, optional
        Another implementation of :func:`_deviation_where` (the same arguments and
        results, bit for bit: the compiled search of
        :mod:`reference.transition_kernel`, which this package cannot import); by
        default :func:`_deviation_where`.
    """
    return (search or _deviation_where)(pieces, r_in, r_out, centre_out)[0]


def _deviation_where(pieces, r_in, r_out, centre_out, near=None, samples=DEV_SAMPLES,
                     scan=SCAN_ROUNDS):
    """:func:`pieces_deviation` and where the largest distance was found (distance from
    the rounding's start, mm), shape (k,) each.

    ``samples`` per piece and ``scan`` rounds other than :data:`DEV_SAMPLES` and
    :data:`SCAN_ROUNDS` make a coarser search (:data:`LOCATE_SAMPLES`, no scan: the
    refinement then starts from the largest sample over ``+-`` its spacing), which
    finds a local maximum, not always the largest.

    With ``near`` (shape (k,), mm) the search is local instead: no samples and no scan,
    the refinement alone (the window cut at the crossing, :func:`_bracket_max`) over
    ``+-h`` around ``near``, ``h`` the sample spacing of the piece there divided by
    :data:`REFINE_SHRINK` (one scan round's window): the local maximum a full search
    found, followed to a nearby rate (:func:`size_for_deviation`), at a fraction of the
    cost. It is the largest distance only where no other local maximum is higher, which
    the sizing checks by a full search at its answer.

    The full search with scan rounds is run once on each side of the normal at ``J``
    from the same samples (:func:`_side_search`) and the larger taken (:func:`larger_side`):
    where the circle the distance is measured from changes, the distance has a sharp
    peak, and a smooth maximum just beyond it on the other side can be higher by less
    than the scan points miss it by, which the scan then never refines (measured: an
    S-bend of 20,000 random ones, R1 13.856 mm, R2 8.986 mm, tolerance 3.1795e-4 mm, its
    largest distance 0.0023 mm past the crossing, 8.6e-11 mm above the peak at the
    crossing the search took: the sizing's answer was 2.7e-7 relative above the
    tolerance).

    Returns the deviation, where it was found and whether that lies inside the last
    window (a maximum at its end lies beyond it, which a search ``near`` misses)."""
    packed = _packed(pieces)
    sampled = None
    if near is None:
        s, sx, sy = _samples(pieces, samples)
        sampled = (s, sx, _distance(sx, sy, r_in, r_out, centre_out))
    if near is None and scan > 0:
        return larger_side(*(_side_search(pieces, packed, r_in, r_out, centre_out, None,
                                          samples, scan, side, sampled)
                             for side in (1, 2)))
    return _side_search(pieces, packed, r_in, r_out, centre_out, near, samples, scan, 0,
                        sampled)


def _side_search(pieces, packed, r_in, r_out, centre_out, near, samples, scan, side,
                 sampled):
    """The search of :func:`_deviation_where` (``packed`` its pieces, :func:`_packed`)
    with the samples and scan points on ``side`` of the normal at ``J`` (1: ``x <= 0``,
    2: ``x > 0``, 0: all; :func:`_on_side`); ``sampled`` the samples' distances from the
    start, ``x`` and distances, shape (k, p (samples + 1)) each (None with ``near``)."""
    lengths = pieces[4]
    k, n_pieces = lengths.shape
    rows = np.arange(k)
    total = lengths.sum(axis=1)
    if near is None:
        s, sx, dev = sampled
        dev = _on_side(dev, sx, side)
        i = dev.argmax(axis=1)
        best, at = dev[rows, i], s[rows, i]
        h0 = lengths[rows, np.minimum(i // (samples + 1), n_pieces - 1)] / samples
        off = (np.arange(REFINE_POINTS) - REFINE_POINTS // 2) / (REFINE_POINTS // 2)
        h = h0
        for _ in range(scan):
            x = np.clip(at[:, None] + h[:, None] * off[None, :], 0.0, total[:, None])
            p = _on_pieces(packed, x, derivatives=False)
            d = _on_side(_distance(p[..., 0], p[..., 1], r_in, r_out, centre_out),
                         p[..., 0], side)
            j = d.argmax(axis=1)
            better = d[rows, j] > best
            best = np.where(better, d[rows, j], best)
            at = np.where(better, x[rows, j], at)
            h = h / REFINE_SHRINK
    else:
        at = np.clip(near, 0.0, total)
        piece = (at[:, None] >= np.cumsum(lengths, axis=1)[:, :-1]).sum(axis=1)
        h0 = lengths[rows, piece] / DEV_SAMPLES
        h = h0 / REFINE_SHRINK
        best = np.full(k, -np.inf)
    where = at.copy()
    lo, hi = np.maximum(at - h, 0.0), np.minimum(at + h, total)
    win_lo, win_hi = lo, hi
    # the window's parts either side of the crossing, each with its circle
    ends = _on_pieces(packed, np.stack((lo, hi), axis=1), derivatives=False)[..., 0]
    split = np.flatnonzero((ends[:, 0] <= 0) & (ends[:, 1] > 0))
    cross = _crossing(packed[split], lo[split], hi[split], ends[split, 0], ends[split, 1])
    mid = hi.copy()
    mid[split] = cross
    which = np.concatenate((rows, split))
    a = np.concatenate((lo, cross))
    b = np.concatenate((mid, hi[split]))
    first = np.concatenate((ends[:, 0] <= 0, np.zeros(split.size, dtype=bool)))
    value, done, at_value = _bracket_max(packed[which], a, b, first, at[which],
                                         r_in[which], r_out[which], centre_out[which])
    # where: the window's part with the larger value (the first part where they tie,
    # as np.maximum.at keeps it)
    for part in (slice(0, k), slice(k, None)):
        rw = which[part]
        up = value[part] > best[rw]
        where[rw[up]] = at_value[part][up]
        best[rw[up]] = value[part][up]
    ok = np.ones(k, dtype=bool)
    np.logical_and.at(ok, which, done)
    return finished(packed, best, where, at, h0, win_lo, win_hi, ok, r_in, r_out,
                    centre_out)


def finished(packed, best, where, at, h0, win_lo, win_hi, ok, r_in, r_out, centre_out):
    """A search's result (:func:`_side_search`, and the compiled one alike) from its
    refinement (shape (k,) each): where the Newton steps did not converge (``ok``
    false), the deviation raised to what :func:`_refine_sampled` finds around ``at``;
    the deviation, where and whether that is inside the last window ``[win_lo,
    win_hi]``."""
    if not ok.all():
        rest = np.flatnonzero(~ok)
        best[rest] = np.maximum(best[rest], _refine_sampled(
            packed[rest], at[rest], h0[rest], best[rest], r_in[rest], r_out[rest],
            centre_out[rest]))
    return best, where, (where > win_lo) & (where < win_hi)


def _on_side(d: np.ndarray, x: np.ndarray, side: int) -> np.ndarray:
    """The distances ``d`` of points with canonical ``x`` on ``side`` of the normal at
    ``J`` (:func:`_deviation_where`: 1 ``x <= 0``, 2 ``x > 0``, 0 all), ``-inf``
    elsewhere (so the search's ``argmax`` and comparisons take none of them)."""
    if side == 0:
        return d
    return np.where((x <= 0) if side == 1 else (x > 0), d, -np.inf)


def larger_side(first, second):
    """Of two searches' results (deviation, where, inside; shape (k,) each), per
    transition the second where its deviation is larger, else the first (where they
    tie or either is nan): how the full search combines its two sides (:func:`_deviation_where`
    and the compiled one alike)."""
    take_second = second[0] > first[0]
    return tuple(np.where(take_second, b, a) for a, b in zip(first, second))


def _refine_sampled(packed: np.ndarray, at: np.ndarray, h: np.ndarray, best: np.ndarray,
                    r_in: np.ndarray, r_out: np.ndarray, centre_out: np.ndarray
                    ) -> np.ndarray:
    """The largest distance within ``h`` of ``at`` by sampling: each of
    :data:`REFINE_ROUNDS` rounds evaluates :data:`REFINE_POINTS` points over ``+-h``
    around the best so far and divides ``h`` by :data:`REFINE_SHRINK`; then the vertex
    of the parabola through the best point and its neighbours."""
    k = at.size
    rows = np.arange(k)
    total = (packed[:, -1, 7] + packed[:, -1, 8])
    off = (np.arange(REFINE_POINTS) - REFINE_POINTS // 2) / (REFINE_POINTS // 2)

    def dist(s):
        p = _on_pieces(packed, s, derivatives=False)
        return _distance(p[..., 0], p[..., 1], r_in, r_out, centre_out)

    for _ in range(REFINE_ROUNDS):
        x = np.clip(at[:, None] + h[:, None] * off[None, :], 0.0, total[:, None])
        d = dist(x)
        j = d.argmax(axis=1)
        better = d[rows, j] > best
        best = np.where(better, d[rows, j], best)
        at = np.where(better, x[rows, j], at)
        h = h / REFINE_SHRINK
    x = np.clip(at[:, None] + h[:, None] * np.array([-1.0, 1.0])[None, :], 0.0,
                total[:, None])
    nb = dist(x)
    curv = nb[:, 0] + nb[:, 1] - 2.0 * best
    with np.errstate(divide="ignore", invalid="ignore"):
        v = at + 0.5 * h * (nb[:, 0] - nb[:, 1]) / curv
    v = np.where((curv < 0) & (np.abs(v - at) <= h), v, at)
    top = dist(np.clip(v, 0.0, total)[:, None])
    return np.maximum(np.maximum(best, top[:, 0]), nb.max(axis=1))


def sbend_shape(r_in: np.ndarray, r_out: np.ndarray, rate: np.ndarray,
                deviation: bool = True) -> SBendShape:
    """The S-bend transition of rate ``rate`` between arcs of radii ``r_in``, ``r_out``.

    Parameters
    ----------
    r_in, r_out, rate : numpy.ndarray, shape (k,)
        mm, mm, 1/mm^2.
    deviation : bool
        Also measure the deviation (else ``nan``).

    Returns
    -------
    SBendShape
        ``theta`` is ``nan`` where no heading up to :data:`THETA_MAX` lands (pieces too
        long for the radii).
    """
    r_in, r_out, rate = (np.asarray(v, dtype=np.float64) for v in (r_in, r_out, rate))
    l1 = l2 = 1.0 / (np.minimum(r_in, r_out) * rate)
    xq1, yq1, _, _ = ramp_offset(r_in, l1)
    xq2, yq2, _, _ = ramp_offset(r_out, l2)
    xq, yq = xq1 + xq2, yq1 + yq2
    lo = np.zeros_like(rate)
    hi = np.minimum(THETA_GUESS * (l1 + l2) / (r_in + r_out), THETA_MAX)
    # the bracket's ends (headings 0 and hi): the residual and the S's turn there
    f_lo, l_s, h, d_p = _s_of(lo, r_in, r_out, rate, xq, yq)
    f_hi, _, h_hi, _ = _s_of(hi, r_in, r_out, rate, xq, yq)
    wide = ~(f_hi > 0)
    if wide.any():
        w = np.flatnonzero(wide)
        hi[w] = THETA_MAX
        f_hi[w], _, h_hi[w], _ = _s_of(hi[w], r_in[w], r_out[w], rate[w], xq[w], yq[w])
    ok = (f_lo < 0) & (f_hi > 0)
    theta = np.full_like(rate, np.nan)
    # (where none lands, the S of heading 0, as it was)
    # the root in the S's turn (_turn_root) where the first bracket holds, the ramps
    # are short (there the residual has one root in it: none of 2783 seeded
    # transitions with L/R <= 0.1 has two, on a grid of 401 headings) and the turns at
    # its ends bracket the root below a quarter turn; elsewhere, and where it does not
    # converge, the root in the heading (_illinois)
    by_turn = np.flatnonzero(ok & ~wide & (l1 * rate * l1 <= TURN_ROOT_MAX_RAMP)
                             & (h_hi > h) & (h_hi < THETA_MAX))
    if by_turn.size:
        i = by_turn
        cols = (r_in[i] + r_out[i], rate[i], xq[i], yq[i])
        # the bracket in the turn, its residuals as _s_of_turn has them
        g_lo = _s_of_turn(h[i], *cols)[0]
        g_hi = _s_of_turn(h_hi[i], *cols)[0]
        fits = (g_lo < 0) & (g_hi > 0)
        i, g_lo, g_hi = i[fits], g_lo[fits], g_hi[fits]
        cols = tuple(c[fits] for c in cols)
        h_i, conv = _turn_root(*cols, h[i], h_hi[i], g_lo, g_hi)
        _, _, th_i, ls_i, dp_i = _s_of_turn(h_i, *cols)
        i, h_i, th_i, ls_i, dp_i = (v[conv] for v in (i, h_i, th_i, ls_i, dp_i))
        theta[i], h[i], l_s[i], d_p[i] = th_i, h_i, ls_i, dp_i
    rest = np.flatnonzero(ok & np.isnan(theta))
    if rest.size:
        sel = (r_in[rest], r_out[rest], rate[rest], xq[rest], yq[rest])
        theta[rest] = _illinois(lambda t: _s_of(t, *sel)[0], lo[rest], hi[rest],
                                f_lo[rest], f_hi[rest], THETA_TOL, LANDING_TOL_MM)
        _, l_s[rest], h[rest], d_p[rest] = _s_of(theta[rest], *sel)
    sh = SBendShape(r_in, r_out, rate, l1, l2, l_s, h, d_p, theta, theta * r_in + 0.5 * l1,
                    theta * r_out + 0.5 * l2, np.full_like(rate, np.nan),
                    l1 + l2 + 4.0 * l_s,
                    np.minimum(np.minimum(r_in, r_out), 1.0 / (rate * l_s)))
    return sbend_measured(sh) if deviation and ok.any() else sh


def sbend_for_deviation(r_in: np.ndarray, r_out: np.ndarray, deviation: np.ndarray,
                        search=None, defer=None) -> SBendShape:
    """The S-bend transitions that deviate from the arcs by ``deviation``
    (:func:`size_for_deviation` from the first estimate :func:`ratio_guess`).

    Parameters
    ----------
    r_in, r_out, deviation : numpy.ndarray, shape (k,)
        mm (``deviation > 0``).
    search : callable, optional
        As for :func:`pieces_deviation`.
    defer : callable, optional
        As for :func:`size_for_deviation`.

    Returns
    -------
    SBendShape
    """
    r_in, r_out, deviation = (np.asarray(v, dtype=np.float64)
                              for v in (r_in, r_out, deviation))
    return size_for_deviation(sbend_shape, _canonical_pieces, -r_out, r_in, r_out,
                              deviation, ratio_guess(_sbend_table(), r_in, r_out, deviation),
                              search=search, defer=defer)


@lru_cache(maxsize=None)
def _sbend_table() -> tuple[np.ndarray, np.ndarray]:
    """:func:`ratio_table` of the S-bend (built once)."""
    return ratio_table(sbend_shape)


def ratio_table(shape_of) -> tuple[np.ndarray, np.ndarray]:
    """The deviation of a two-arc transition against its radius ratio, the table of the
    sizing's first estimate (:func:`ratio_guess`).

    Every length of a transition scales like ``1/c`` and its deviation like their
    square over the radius, so ``e c^2 R^3 = G(rho, L/R)`` (``R = min(R1, R2)``, ``rho
    = R2/R1``, ``L = 1/(R c)``), nearly independent of ``L/R`` when that is small
    (measured: 1e-3 relative from ``L/R`` = 0.003 to 0.03), but with ``rho`` by a
    factor of ten and more (S-bends: 1.94 at ``rho`` = 1.2, 0.17 at 16). Built from the
    model itself (``shape_of``, with its deviation) at ``L/R`` = :data:`GUESS_RAMP` on
    :data:`GUESS_POINTS` ratios, ``log rho`` evenly from ``-GUESS_MAX_LOG_RATIO`` to
    ``+GUESS_MAX_LOG_RATIO``; where one does not land, none (``nan``).

    Returns
    -------
    log_rho, log_g : numpy.ndarray, shape (GUESS_POINTS,)
    """
    q = np.linspace(-GUESS_MAX_LOG_RATIO, GUESS_MAX_LOG_RATIO, GUESS_POINTS)
    r_in = np.exp(np.minimum(-q, 0.0))          # the smaller radius is 1 mm
    r_out = np.exp(np.minimum(q, 0.0))
    r_in, r_out = r_in / np.minimum(r_in, r_out), r_out / np.minimum(r_in, r_out)
    rate = np.full(q.size, 1.0 / GUESS_RAMP)
    sh = shape_of(r_in, r_out, rate)
    return q, np.log(sh.deviation * rate * rate)


def ratio_guess(table: tuple[np.ndarray, np.ndarray], r_in: np.ndarray, r_out: np.ndarray,
                deviation: np.ndarray) -> np.ndarray:
    """First estimate of ``log c`` for the sizing (:func:`size_for_deviation`): ``e c^2
    R^3 = G(rho)`` with ``G`` interpolated in ``log rho`` from ``table``
    (:func:`ratio_table`, over the ratios that have a value; beyond its ends, its end
    values; where none has one, the small-angle S-bend estimate :data:`GUESS_G`). Only
    the number of steps depends on it, not the answer's accuracy.

    Parameters
    ----------
    table : tuple
        ``(log_rho, log_g)`` of :func:`ratio_table`.
    r_in, r_out, deviation : numpy.ndarray, shape (k,)
        mm.

    Returns
    -------
    numpy.ndarray, shape (k,)
        ``log c``, ``c`` in 1/mm^2.
    """
    q, log_g = table
    fin = np.isfinite(log_g)
    g = (np.interp(np.log(r_out / r_in), q[fin], log_g[fin]) if fin.any()
         else np.full(r_in.shape, np.log(GUESS_G)))
    return 0.5 * (g - np.log(np.minimum(r_in, r_out) ** 3 * deviation))


def sbend_measured(sh: SBendShape, search=None) -> SBendShape:
    """``sh`` with its deviation measured where it lands (``nan`` elsewhere): what
    :func:`sbend_shape` returns with ``deviation=True`` for the same radii and rates
    (its heading root is each transition's own, whatever the batch); ``search`` as
    for :func:`pieces_deviation`."""
    return _measured(sh, _canonical_pieces, -sh.r_out, search)


def _measured(sh, pieces_of, centre_out: np.ndarray, search=None):
    """``sh`` (a two-arc shape, ``theta`` nan where it does not land) with its
    deviation measured by :func:`pieces_deviation` (``search``) where it lands."""
    ok = np.isfinite(sh.theta)
    dev = np.full_like(sh.rate, np.nan)
    if ok.any():
        i = np.flatnonzero(ok)
        part = take(sh, i)
        dev[i] = pieces_deviation(pieces_of(part), part.r_in, part.r_out, centre_out[i],
                                  search)
    return type(sh)(*(dev if f == "deviation" else getattr(sh, f)
                      for f in type(sh).__slots__))


def size_for_deviation(shape_of, pieces_of, centre_out: np.ndarray, r_in: np.ndarray,
                       r_out: np.ndarray, deviation: np.ndarray, log_rate: np.ndarray,
                       canonical=None, search=None, defer=None):
    """The transitions between two arcs whose rate makes them deviate by ``deviation``;
    the one sizing of every two-arc transition.

    The deviation grows about like ``1/c^2`` (all lengths scale like ``1/c``, the
    deviation like their square over the radius): Newton steps in ``log c`` with the
    slope measured by the last two (secant; -2 at first), from a small-angle estimate
    ``log_rate``, each step only for the transitions not yet done; a rate for
    which no heading lands (``theta`` nan: pieces far too long) is raised by
    :data:`RATE_BRACKET_STEP`. The aim is ``deviation (1 - DEVIATION_REL_TOL)``, met to
    half of that margin: the result never exceeds ``deviation`` and is at most ``1.5
    DEVIATION_REL_TOL`` below it.

    The steps measure cheaply: a coarse search at the first rate finds a local maximum
    (:data:`LOCATE_SAMPLES`), and each later step follows it by the refinement alone
    around the same fraction of the rounding's length (:func:`_deviation_where` with
    ``near``: the shape changes little from one rate to the next, every length scales
    about like ``1/c``), until it meets the aim to :data:`TRACK_REL_TOL`, or until a
    secant step starts within :data:`CHECK_LOG_TOL` of the aim (it then lands within
    the margin, mostly, and the refinement there would only confirm it). A transition
    is done only when the full search (:func:`pieces_deviation`) at that rate (the
    model's shape) meets the aim to half the margin: the answer's deviation is always
    the full search's, as :func:`pieces_deviation` gives it for that shape. Where it
    does not, that measure is the next point of the steps, and they follow the maximum
    the full search found (another local maximum where it is higher). Where the
    followed maximum leaves its window or the steps do not settle in
    :data:`TRACK_MAX_ITER`, the transition is sized again by the steps with the full
    search from the start (:func:`_size_in_full`, the sizing as it was).

    Parameters
    ----------
    shape_of : callable
        ``shape_of(r_in, r_out, rate, deviation=False)``: the transitions of that rate,
        a frozen dataclass with ``rate``, ``theta`` (``nan`` where none lands) and
        ``deviation`` among its fields, shape (k,) each, each transition's own
        (not depending on the others in the batch).
    pieces_of : callable
        A shape of transitions that land -> their canonical pieces
        (:func:`pieces_deviation`).
    centre_out : numpy.ndarray, shape (k,)
        Canonical ``y`` of the second arc's centre, mm.
    r_in, r_out, deviation : numpy.ndarray, shape (k,)
        mm (``deviation > 0``).
    log_rate : numpy.ndarray, shape (k,)
        ``log c`` of the first estimate (``c`` in 1/mm^2).
    canonical : callable, optional
        Where given, the steps build each shape ``like`` the one before
        (``shape_of(..., like=...)``, a cheaper solve that may differ from the model's),
        and ``canonical`` makes the answer's shape the model's before its full measure.
    search : callable, optional
        The implementation of :func:`_deviation_where` every measure uses (as for
        :func:`pieces_deviation`).
    defer : callable, optional
        ``defer(part, i, slack) -> bool (m,)``: of the shapes ``part`` (transitions
        ``i``; ``slack`` shape (m,), ``log``), those the caller takes over: whose trim
        exceeds its cap by more than the factor ``exp(slack)``. It is asked of the
        answers (the model's shapes, before their full measure; ``slack`` 0) and, with
        the slack of :data:`DEFER_LOG_MARGIN`, of the shapes of every step still short
        of the aim (those are then not sized further). The ones taken over are
        returned with the deviation ``nan``, at the rate they were left at. The
        block-length clamp (:func:`reference.rounding_tangential._size_arcs`) raises
        the rate of every transition whose trim exceeds its cap and measures it in full
        at the raised rate, so the measure at this one would be thrown away, and so
        would the steps towards it (on the same-way row of
        ``tests/bench/bench_rounding.py`` 1,819 of 7,950 transitions); where the
        measure there finds a higher maximum than the one followed, the caller sizes
        it again without ``defer``.

    Returns
    -------
    The ``shape_of`` result of the rates found, with the deviation.
    """
    aim = sizing_aim(deviation)
    half = ACCEPT_LOG_TOL
    x = np.array(log_rate, dtype=np.float64)
    k = x.size
    sh = shape_of(r_in, r_out, np.exp(x), deviation=False)
    gx = np.full(k, np.nan)                  # log(deviation) - aim; nan: no landing
    where = np.full(k, np.nan)               # the followed maximum's place / length
    lost = np.zeros(k, bool)                 # to be sized in full (_size_in_full)
    pieces = (pieces_of, centre_out, r_in, r_out, search)

    def follow(i, part):
        """Deviation of the shape ``part`` of transitions ``i`` where it lands, near
        ``where`` (by the coarse search where none was found yet); writes gx, where and
        lost."""
        dev, at, inside = _measure(part, i, pieces, where[i])
        where[i] = at
        lost[i] |= ~inside
        gx[i] = np.log(dev) - aim[i]
        return dev

    early = np.zeros(k, bool)                # left to the caller while still sized

    def hand_over(i, part):
        """Marks ``early`` those of transitions ``i`` (shape ``part``, just measured)
        whose trim exceeds its cap even at the rate of the tolerance as far off as the
        last measure leaves it (``2 |gx| + DEFER_LOG_MARGIN`` in ``log c``)."""
        if defer is None:
            return
        open_ = np.flatnonzero(np.isfinite(gx[i]) & ~(np.abs(gx[i]) <= TRACK_REL_TOL)
                               & ~lost[i])
        if open_.size:
            slack = 2.0 * np.abs(gx[i[open_]]) + DEFER_LOG_MARGIN
            early[i[open_]] = defer(take(part, open_), i[open_], slack)

    sh = _with_deviation(sh, np.arange(k), follow(np.arange(k), sh))
    hand_over(np.arange(k), sh)
    x_old, g_old = np.full_like(x, np.nan), np.full_like(x, np.nan)
    done = np.zeros(k, bool)                 # accepted by the full search at its rate

    def check(i):
        """The full search at the shapes of transitions ``i`` (made the model's), except
        where a trim exceeds its cap (those are left to the caller, ``early``): those
        within half the margin are done; for the others the measure is the next point
        of their steps, which then follow the maximum the full search found."""
        nonlocal sh
        part = take(sh, i)
        if canonical is not None:
            part = canonical(part)
            sh = scatter(sh, i, part)
        later = (np.zeros(i.size, bool) if defer is None
                 else defer(part, i, np.zeros(i.size)))
        early[i[later]] = True
        now = np.flatnonzero(~later)
        j = i[now]
        dev, at, _ = _measure(take(part, now) if later.any() else part, j, pieces, None)
        sh = _with_deviation(sh, j, dev)
        gx[j] = np.log(dev) - aim[j]
        where[j] = at
        done[j] = np.abs(gx[j]) <= half

    for _ in range(TRACK_MAX_ITER):
        open_ = ~done & ~lost & ~early
        settled = np.flatnonzero(open_ & (np.abs(gx) <= TRACK_REL_TOL))
        todo = np.flatnonzero(open_ & ~(np.abs(gx) <= TRACK_REL_TOL))
        if not (settled.size or todo.size):
            break
        # a secant step from within CHECK_LOG_TOL of the aim: measured by the full search
        # at once (the step lands within the acceptance, mostly: CHECK_LOG_TOL)
        ready = np.isfinite(g_old[todo]) & (np.abs(gx[todo]) <= CHECK_LOG_TOL)
        if todo.size:
            x[todo], x_old[todo], g_old[todo] = _secant_step(x[todo], gx[todo],
                                                             x_old[todo], g_old[todo])
            like = {} if canonical is None else {"like": take(sh, todo)}
            part = shape_of(r_in[todo], r_out[todo], np.exp(x[todo]), deviation=False,
                            **like)
            sh = scatter(sh, todo, part)
            step = np.flatnonzero(~ready)
            if step.size:
                near = take(part, step) if ready.any() else part
                sh = _with_deviation(sh, todo[step], follow(todo[step], near))
                hand_over(todo[step], near)
        checked = np.concatenate((settled, todo[ready]))
        if checked.size:
            check(checked)
    # handed over while still sized: the caller measures them at its own rate
    if early.any():
        sh = _with_deviation(sh, np.flatnonzero(early), np.nan)
    rest = np.flatnonzero(~done & ~early)
    if rest.size:
        sh = scatter(sh, rest, _size_in_full(shape_of, pieces_of, centre_out[rest],
                                             r_in[rest], r_out[rest], aim[rest],
                                             np.asarray(log_rate, np.float64)[rest],
                                             search))
    return sh


def sizing_aim(deviation: np.ndarray) -> np.ndarray:
    """``log`` of the deviation the sizing aims at, ``deviation (1 - DEVIATION_REL_TOL)``
    (``deviation`` in mm, any shape)."""
    return np.log(deviation) + np.log1p(-DEVIATION_REL_TOL)


def not_above_aim(measured: np.ndarray, deviation: np.ndarray) -> np.ndarray:
    """Whether measured deviations (mm) are at most :data:`ACCEPT_LOG_TOL` above the aim of
    ``deviation`` (mm): what the sizing accepts from above, so never above ``deviation``
    (``False`` where ``measured`` is nan)."""
    return np.log(measured) - sizing_aim(deviation) <= ACCEPT_LOG_TOL


def _size_in_full(shape_of, pieces_of, centre_out, r_in, r_out, aim, log_rate,
                  search=None):
    """:func:`size_for_deviation` with every step measured by the full search: the
    steps from ``log_rate`` until ``log(deviation)`` is within half the margin of
    ``aim`` (shape (k,) each), each only for the transitions not yet done."""
    x = np.array(log_rate, dtype=np.float64)
    pieces = (pieces_of, centre_out, r_in, r_out, search)
    sh = shape_of(r_in, r_out, np.exp(x), deviation=False)
    dev = _measure(sh, np.arange(x.size), pieces, None)[0]
    sh = _with_deviation(sh, np.arange(x.size), dev)
    gx = np.log(dev) - aim
    x_old, g_old = np.full_like(x, np.nan), np.full_like(x, np.nan)
    for _ in range(ROOT_MAX_ITER):
        todo = np.flatnonzero(~(np.abs(gx) <= ACCEPT_LOG_TOL))
        if not todo.size:
            break
        x[todo], x_old[todo], g_old[todo] = _secant_step(x[todo], gx[todo], x_old[todo],
                                                         g_old[todo])
        part = shape_of(r_in[todo], r_out[todo], np.exp(x[todo]), deviation=False)
        dev = _measure(part, todo, pieces, None)[0]
        sh = scatter(sh, todo, _with_deviation(part, np.arange(todo.size), dev))
        gx[todo] = np.log(dev) - aim[todo]
    return sh


def _secant_step(x, g, x_old, g_old):
    """One step of the sizing in ``x = log c`` from ``(x, g)`` with the last point
    ``(x_old, g_old)`` (shape (m,) each; ``g`` nan: no landing, the rate raised by
    :data:`RATE_BRACKET_STEP`): the new ``x`` and the new last point."""
    lost = np.isnan(g)
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = (g - g_old) / (x - x_old)
    # the secant slope where it is sane (the deviation falls with the rate), else -2
    slope = np.where((slope < -0.5) & (slope > -8.0), slope, -2.0)
    step = np.where(lost, np.log(RATE_BRACKET_STEP), -g / slope)
    return x + step, np.where(lost, x_old, x), np.where(lost, g_old, g)


def _measure(part, i, pieces, near):
    """Deviation of the two-arc shape ``part`` (of transitions ``i`` of the sizing,
    ``pieces`` = (pieces_of, centre_out, r_in, r_out) of all) where it lands (``nan``
    elsewhere), where it was found (a fraction of the rounding's length; ``near`` where
    it does not land) and whether that is inside the search's window, shape (m,) each:
    by the full search (``near`` None), else near the fractions ``near`` (shape (m,);
    ``nan``: the coarse search)."""
    pieces_of, centre_out, r_in, r_out, search = pieces
    ok = np.isfinite(part.theta)
    dev = np.full(i.size, np.nan)
    at = np.full(i.size, np.nan) if near is None else near.copy()
    inside = np.ones(i.size, bool)
    modes = ((ok, {}),) if near is None else (
        (ok & np.isnan(near), {"samples": LOCATE_SAMPLES, "scan": 0}),
        (ok & ~np.isnan(near), None))
    for sel, kw in modes:
        sel = np.flatnonzero(sel)
        if not sel.size:
            continue
        j = i[sel]
        pc = pieces_of(take(part, sel))
        total = pc[4].sum(axis=1)
        kw = {"near": near[sel] * total} if kw is None else kw
        d, s, ins = (search or _deviation_where)(pc, r_in[j], r_out[j], centre_out[j],
                                                 **kw)
        dev[sel], at[sel], inside[sel] = d, s / total, ins
    return dev, at, inside


def _with_deviation(sh, i: np.ndarray, dev: np.ndarray):
    """``sh`` with the deviation of transitions ``i`` set to ``dev``."""
    d = sh.deviation.copy()
    d[i] = dev
    return type(sh)(*(d if f == "deviation" else getattr(sh, f)
                      for f in type(sh).__slots__))


def sbend_rows(junction: np.ndarray, along: np.ndarray, inward: np.ndarray,
               sh: SBendShape, block: np.ndarray, kind_code: int) -> dict[str, np.ndarray]:
    """Packed rows of the transitions, :data:`SBEND_PIECES` per transition in path order
    (:func:`pieces_rows`)."""
    return pieces_rows(_canonical_pieces(sh), junction, along, inward, block, kind_code)


def pieces_rows(pieces, junction: np.ndarray, along: np.ndarray, inward: np.ndarray,
                block: np.ndarray, kind_code: int) -> dict[str, np.ndarray]:
    """Packed rows of canonical clothoid pieces between two arcs, ``p`` per transition in
    path order; the one placement of every two-arc transition in the world.

    Parameters
    ----------
    pieces : tuple
        As :func:`pieces_deviation`.
    junction : numpy.ndarray, shape (k, n)
        Where the arcs meet.
    along : numpy.ndarray, shape (k, n)
        Unit tangent there, in the direction of travel.
    inward : numpy.ndarray, shape (k, n)
        Unit normal towards the first arc's centre.
    block : numpy.ndarray of int, shape (k,)
    kind_code : int

    Returns
    -------
    dict
        Keys of :class:`reference.core.geometry.Path` rows, plus ``sharpness``.
    """
    k, n = junction.shape
    pts, e1c, e2c, rates, lengths = pieces
    p = rates.shape[1]

    def world(xy, offset):
        return (offset[:, None, :] + xy[..., 0:1] * along[:, None, :]
                + xy[..., 1:2] * inward[:, None, :])

    origin = world(pts, junction)
    zero = np.zeros_like(junction)
    e1, e2 = world(e1c, zero), world(e2c, zero)
    m = k * p
    return clothoid_rows(origin.reshape(m, n), e1.reshape(m, n), e2.reshape(m, n),
                         rates.ravel(), lengths.ravel(),
                         np.repeat(np.asarray(block, np.int64), p), kind_code)


def take(sh, i: np.ndarray):
    """The transitions ``i`` of a shape (any frozen dataclass of arrays shape (k,))."""
    return type(sh)(*(getattr(sh, f)[i] for f in type(sh).__slots__))


def scatter(sh, i: np.ndarray, part):
    """``sh`` with the transitions ``i`` replaced by ``part`` (same dataclass)."""
    out = []
    for f in type(sh).__slots__:
        a = getattr(sh, f).copy()
        a[i] = getattr(part, f)
        out.append(a)
    return type(sh)(*out)


__all__ = ["ACCEPT_LOG_TOL", "SBEND_PIECES", "SBendShape", "not_above_aim",
           "pieces_deviation", "pieces_rows", "sbend_deviation", "sbend_for_deviation",
           "sbend_measured", "sbend_rows", "sbend_shape", "scatter", "ratio_guess",
           "ratio_table", "size_for_deviation", "sizing_aim", "take"]
