"""``acc+freq`` upper bound candidate: the acc optimum with its ramps capped (the capped
optimum).

The acc optimum (``v^2 = b*(s)`` piecewise linear in ``s`` on its grid) rises and falls
between its *valleys* (local minima of ``b*``: corners, the path's ends, stops) as fast as
the axes allow; on a curve its acceleration is largest at the valley and shrinks towards
the top, where the centripetal part takes the axes' limits. Its phases are then short or
front-loaded (the acceleration-weighted mean time early in the phase), and the frequency
rule (:mod:`reference.core.phases`) rejects them. The capped optimum keeps the shape and
caps the rate: on every hump between two valleys

* the rise from the first valley integrates ``b' = 2 min(alpha, a_max(s, b))`` forward
  (``a_max`` the largest path acceleration that keeps every axis acceleration
  ``|q'_i(s) s'' + q''_i(s) b|`` within ``A_i`` at both ends of the grid interval),
  never above ``b*``;
* the fall into the next valley integrates ``b' = -2 min(beta, d_max(s, b))`` backwards
  the same way (``d_max`` the largest deceleration);
* the motion is ``min`` of the two, exactly piecewise linear in ``b`` on the grid (each
  pass keeps ``b`` linear on every interval), so a constant acceleration per interval;
* the rates may grow with the time ``tau`` from the valley the pass starts at,
  ``alpha (1 + g tau)`` (:data:`CAPPED_GROWTH`: each hump takes the fastest of a few
  ``g``), which moves a rise's acceleration later where the budget would load its front.

``alpha`` and ``beta`` are chosen per hump by bisection, the largest for which the hump's
phases pass the rule as :func:`~reference.core.phases.acceleration_phases` and
:func:`~reference.core.phases.phase_frequencies` judge them (the one rule, not a copy).
On a line the rise is a constant ``alpha`` up to the cap, so a rest-to-rest line with
``v/A < 1/f`` gets ``alpha = v f``: the closed form ``L/v + 1/f`` of DESIGN 6. On an arc
the rise keeps ``alpha`` while the axes allow it and then follows their budget, which
the ramp plan of :mod:`optimal.freq.ramps` (one constant per segment, taken at its top
speed) cannot: measured on ``lcnc_arc_arc_sawtooth`` (48 arcs of R 5.08 mm between cusps,
default machine) 5.263 s against the ramp plan's 6.09 s and the NLP candidates' 5.313 s.
Where the acc optimum has many short humps (short segments between slow corners) the
capped hump is no better than the ramps, and the oracle keeps whichever is fastest per
piece.

Nothing here is trusted: the motion is judged by ``check_profile`` like every candidate
(:func:`optimal.freq.upper.verified`, which slows it down where a grid interval's
interior goes beyond what its two ends allowed).

Units: mm, s, mm/s, mm/s^2.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from reference.core.errors import ProfileError
from reference.core.geometry import Path
from reference.core.limits import MachineLimits
from reference.core.phases import (acceleration_phases, min_phase_duration,
                                   phase_frequencies)
from reference.core.profile import Profile

from .lower import segment_periods

__all__ = ["CAPPED_ACCEL_MARGIN", "CAPPED_BISECTIONS", "CAPPED_GROWTH", "CAPPED_MAX_NODES",
           "capped_optimum"]

#: Shapes of the rates tried per hump: the rate at a valley grows by this share of
#: itself per period ``1/f`` of the time from the valley (``alpha (1 + share f tau)``).
#: 0, the constant rate, is the fastest on lines (the trapezoid of ``1/f``); on arcs the
#: axes' budget grows along a rise as the tangent turns off the axes and shrinks where
#: the centripetal part takes it, so a constant rate loads the rise's front and the
#: rule then caps it, where a growing one moves its acceleration-weighted mean later:
#: measured on lcnc_arc_arc_sawtooth (default machine, 20 Hz), 5.282 s with 0 alone,
#: 5.2633 s with the faster of 0 and 0.25 per hump (0.109 7 s per arc); more shares
#: (0, 0.15, 0.3 or 0, 0.25, 0.5, 1) give 5.2631 s. A time-domain NLP of one of its arcs
#: (CasADi, 240 steps, the rule's moments as constraints) found 0.109 4 s, so the
#: shape left is worth some 0.3 %.
CAPPED_GROWTH = (0.0, 0.25)
#: Bisection steps on each hump's ``alpha`` and ``beta`` (relative resolution 2^-30 of
#: twice the acc optimum's largest acceleration: far below the checker's tolerances).
CAPPED_BISECTIONS = 30
#: After the bisection the rates of humps whose phases still fail (the rise and the fall
#: of a hump meet where both rates put them, so the two bisections interact) are lowered
#: by :data:`CAPPED_SHRINK` at most this many times.
CAPPED_FIX_ROUNDS = 40
CAPPED_SHRINK = 0.995
#: Grid nodes beyond which no capped optimum is built: each of the up to 70 bisection
#: and shrink steps is a pass over the nodes and a cut into phases (``O(N)`` time, and
#: ``O(N n)`` memory for the interval ends' derivatives: 2e6 nodes, 3 axes, ~200 MB).
CAPPED_MAX_NODES = 2_000_000
#: The passes keep each axis acceleration within ``(1 - CAPPED_ACCEL_MARGIN) A_i`` at
#: both ends of every grid interval: inside an interval on a curve the axis acceleration
#: of a constant path acceleration is not the chord of its ends (the tangent and the
#: curvature vector turn), a second-order excess measured at 1.04e-5 relative on the
#: acc grid of an R 5.08 mm arc (0.08 mm intervals, tests/optimal/test_freq_capped.py);
#: ten times that, so that the motion is accepted as built on such grids (elsewhere
#: :func:`optimal.freq.upper.verified` slows it down by the square root of the excess).
CAPPED_ACCEL_MARGIN = 1e-4
#: A phase passes at ``D_eff >= (1 + CAPPED_RULE_MARGIN) / f``: the bisection keeps the
#: rates on the passing side of the rule by more than the round-off of the phases'
#: moments (about 1e-12 relative), so that the checker judges the same.
CAPPED_RULE_MARGIN = 1e-9


@njit(cache=True, nogil=True, error_model="numpy")
def _rate_cap(cap: float, g: float, c: float, a_lim: float) -> float:  # pragma: no cover
    """``cap`` lowered to the upper end of the rates ``x`` with ``|g x + c| <= a_lim``
    (unchanged where ``g = 0``: the rate does not enter)."""
    if g > 0.0:
        return min(cap, (a_lim - c) / g)
    if g < 0.0:
        return min(cap, (-a_lim - c) / g)
    return cap


@njit(cache=True, nogil=True, error_model="numpy")
def _interval_time(h: float, b0: float, b1: float) -> float:  # pragma: no cover
    """Time over an interval of length ``h`` with ``v^2`` linear from ``b0`` to ``b1``
    (``2 h / (v_0 + v_1)``; 0 where both are at rest: the pass stays there)."""
    v = np.sqrt(b0) + np.sqrt(b1)
    return 2.0 * h / v if v > 0.0 else 0.0


@njit(cache=True, nogil=True, error_model="numpy")
def _passes(b: np.ndarray, ds: np.ndarray, first: np.ndarray, hump: np.ndarray,
            alpha: np.ndarray, beta: np.ndarray, grow: np.ndarray, dq0: np.ndarray,
            ddq0: np.ndarray, dq1: np.ndarray, ddq1: np.ndarray,
            A: np.ndarray) -> np.ndarray:  # pragma: no cover
    """``min`` of the forward (``alpha``) and backward (``beta``) passes, shape (N,).

    ``first[n]``: node ``n`` is a valley (a pass restarts from ``b[n]`` there); ``hump``
    of each interval, shape (N - 1,); ``alpha``, ``beta``, ``grow`` per hump: the rates
    at the valley and their growth with the time ``tau`` from it (the rate is ``alpha
    (1 + grow tau)``, 1/s); ``dq0, ddq0`` / ``dq1, ddq1`` the tangent and curvature
    vector at each interval's start / end on the interval's own segment, shape
    (N - 1, n); ``A`` the axis limits, shape (n,)."""
    N = b.size
    n_ax = A.size
    fwd = b.copy()
    cur = b[0]
    tau = 0.0
    for k in range(N - 1):
        if first[k]:
            cur = b[k]
            tau = 0.0
        h = ds[k]
        cap = np.inf
        for i in range(n_ax):
            # |dq0 a + ddq0 cur| <= A at the start, |(dq1 + 2 h ddq1) a + ddq1 cur| <= A
            # at the end (b there = cur + 2 h a): the upper end of each interval of a
            cap = _rate_cap(cap, dq0[k, i], ddq0[k, i] * cur, A[i])
            cap = _rate_cap(cap, dq1[k, i] + 2.0 * h * ddq1[k, i], ddq1[k, i] * cur, A[i])
        a = min(alpha[hump[k]] * (1.0 + grow[hump[k]] * tau), max(cap, 0.0))
        nxt = min(cur + 2.0 * h * a, b[k + 1])
        tau += _interval_time(h, cur, nxt)
        cur = nxt
        fwd[k + 1] = cur
    out = b.copy()
    cur = b[N - 1]
    tau = 0.0
    for k in range(N - 2, -1, -1):
        if first[k + 1]:
            cur = b[k + 1]
            tau = 0.0
        h = ds[k]
        cap = np.inf
        for i in range(n_ax):
            # s'' = -d: |-dq1 d + ddq1 cur| <= A at the end, |(-dq0 + 2 h ddq0) d + ddq0
            # cur| <= A at the start (b there = cur + 2 h d)
            cap = _rate_cap(cap, -dq1[k, i], ddq1[k, i] * cur, A[i])
            cap = _rate_cap(cap, -dq0[k, i] + 2.0 * h * ddq0[k, i], ddq0[k, i] * cur, A[i])
        d = min(beta[hump[k]] * (1.0 + grow[hump[k]] * tau), max(cap, 0.0))
        nxt = min(cur + 2.0 * h * d, b[k])
        tau += _interval_time(h, cur, nxt)
        cur = nxt
        out[k] = min(cur, fwd[k])
    out[N - 1] = min(out[N - 1], fwd[N - 1])
    return out


def capped_optimum(path: Path, limits: MachineLimits, acc_profile: Profile
                   ) -> Profile | None:
    """The capped optimum of the module docstring, unverified.

    Parameters
    ----------
    path : Path
    limits : MachineLimits
    acc_profile : Profile
        The acc optimum without holds (its knots; the velocity between them is taken as
        ``v^2`` linear in ``s``).

    Returns
    -------
    Profile or None
        ``None`` where the path has no motion, the grid is larger than
        :data:`CAPPED_MAX_NODES` or the construction leaves an interval at rest.
    """
    moving = path.moving_axes()
    work = path.restricted(moving) if 0 < moving.size < path.n_axes else path
    lim = limits.for_axes(work.axes)
    s_all = np.asarray(acc_profile.s, dtype=np.float64)
    keep = np.concatenate(([True], np.diff(s_all) > 0))
    s, v = s_all[keep], np.asarray(acc_profile.v, np.float64)[keep]
    N = s.size
    if N < 2 or N > CAPPED_MAX_NODES or work.n_segments == 0:
        return None
    block = np.asarray(acc_profile.block)[np.diff(s_all) > 0]
    b = v * v
    # valleys: local minima of b* (a plateau's two ends), the path's ends
    first = np.zeros(N, bool)
    first[0] = first[-1] = True
    first[1:-1] = ((b[1:-1] <= b[:-2]) & (b[1:-1] <= b[2:])
                   & ((b[1:-1] < b[:-2]) | (b[1:-1] < b[2:])))
    valleys = np.flatnonzero(first)
    H = valleys.size - 1
    hump = np.clip(np.searchsorted(valleys, np.arange(N - 1), side="right") - 1, 0, H - 1)
    ds = np.diff(s)
    seg = work.segment_index(0.5 * (s[:-1] + s[1:]))
    _, dq0, ddq0, _ = work.evaluate(s[:-1], segment=seg)
    _, dq1, ddq1, _ = work.evaluate(s[1:], segment=seg)
    A = np.ascontiguousarray(lim.a_max * (1.0 - CAPPED_ACCEL_MARGIN), np.float64)
    s_valley = s[valleys]

    # per hump its longest period (the smallest frequency of the axes moving on its
    # segments): the growth rates of CAPPED_GROWTH are shares of it
    period = np.zeros(H)
    np.maximum.at(period, hump, segment_periods(work, lim)[seg])
    period = np.where(period > 0, period, np.inf)      # no rule: no growth

    def motion(alpha, beta, grow):
        bn = np.maximum(_passes(b, ds, first, hump, alpha, beta, grow, dq0, ddq0, dq1,
                                ddq1, A), 0.0)
        return bn, Profile.from_path_velocity(s, np.sqrt(bn), block)

    def failing(prof):
        """Humps whose rise (first) or fall (second) holds a phase the rule rejects."""
        ph = acceleration_phases(prof)
        rise, fall = np.zeros(H, bool), np.zeros(H, bool)
        if ph.n == 0:
            return rise, fall
        # the motion's intervals are the grid's (its nodes, none repeated): their
        # segments are ``seg``
        f, _ = phase_frequencies(work, lim, ph, seg)
        bad = ph.effective_duration < min_phase_duration(f) * (1.0 + CAPPED_RULE_MARGIN)
        s0 = prof.state(ph.start_t)[0]
        s1 = prof.state(ph.end_t)[0]
        h0 = np.clip(np.searchsorted(s_valley, s0, side="right") - 1, 0, H - 1)
        h1 = np.clip(np.searchsorted(s_valley, s1, side="left") - 1, 0, H - 1)
        rise[h0[bad & (ph.sign > 0)]] = True
        fall[h1[bad & (ph.sign < 0)]] = True
        return rise, fall

    def rated(grow):
        """``v^2`` at the nodes with the largest rates that pass, shape (N,), its
        motion, and per hump whether its phases pass, shape (H,)."""
        top = 2.0 * float(np.max(np.abs(acc_profile.a), initial=0.0)) + 1.0
        hi_a, hi_b = np.full(H, top), np.full(H, top)
        lo_a, lo_b = np.full(H, top), np.full(H, top)
        rise, fall = failing(motion(hi_a, hi_b, grow)[1])
        # the humps the rule accepts as the acc optimum has them keep it; the others
        # bisect between 0 and the top (lo: the largest rate seen passing)
        lo_a[rise], lo_b[fall] = 0.0, 0.0
        for _ in range(CAPPED_BISECTIONS if (rise.any() or fall.any()) else 0):
            al = np.where(lo_a < hi_a, 0.5 * (lo_a + hi_a), lo_a)
            be = np.where(lo_b < hi_b, 0.5 * (lo_b + hi_b), lo_b)
            rise, fall = failing(motion(al, be, grow)[1])
            hi_a, lo_a = np.where(rise, al, hi_a), np.where(rise, lo_a, al)
            hi_b, lo_b = np.where(fall, be, hi_b), np.where(fall, lo_b, be)
        # a rate never seen passing: the smallest tried
        lo_a = np.where(lo_a > 0, lo_a, hi_a)
        lo_b = np.where(lo_b > 0, lo_b, hi_b)
        bn, prof = motion(lo_a, lo_b, grow)
        for _ in range(CAPPED_FIX_ROUNDS):
            rise, fall = failing(prof)
            if not (rise.any() or fall.any()):
                break
            lo_a = np.where(rise, lo_a * CAPPED_SHRINK, lo_a)
            lo_b = np.where(fall, lo_b * CAPPED_SHRINK, lo_b)
            bn, prof = motion(lo_a, lo_b, grow)
        return bn, prof, ~(rise | fall)

    try:
        # each growth share in turn; per hump the fastest that passes (the passes
        # restart at every valley, so the humps do not interact: a hump's motion under
        # one share joins its neighbours' under another at the valleys' b*; where a
        # pass arrives below b* at a valley the joined node takes the chosen hump's
        # value, and the checker judges the whole motion as every candidate)
        best_b, best_t, best_ok = None, None, None
        for share in CAPPED_GROWTH:
            bn, prof, ok = rated(share / period)
            # the motion's intervals are the grid's: each hump's time from its own
            t_h = np.bincount(hump, weights=np.diff(prof.t), minlength=H)
            if best_b is None:
                best_b, best_t, best_ok = bn, t_h, ok
                continue
            take = ok & (~best_ok | (t_h < best_t))
            if take.any():
                node = np.zeros(N, bool)
                # a hump's nodes: its intervals' ends (its valleys are kept by both)
                node[:-1] |= take[hump]
                node[1:] |= take[hump]
                best_b = np.where(node, bn, best_b)
                best_t, best_ok = np.where(take, t_h, best_t), best_ok | take
        return Profile.from_path_velocity(s, np.sqrt(best_b), block)
    except ProfileError:
        return None
