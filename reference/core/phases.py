"""The frequency rule (DESIGN section 6, as sharpened by issue 12): acceleration phases,
their effective duration and its minimum ``1/f``.

One rule, applied alike by the checker (:func:`reference.core.constraints.check_profile`,
constraint ``frequency``), the heuristic's self-check (through the checker) and the oracle
(:mod:`optimal.freq`):

    every acceleration or deceleration **phase** of the path motion lasts at least
    ``1/f``, ``f`` the smallest LOOKAH_FREQUENCY (MD32440) of the axes moving in it,
    where a phase's length is its **effective duration**
    ``D_eff = 2 min(t_c - t_0, t_1 - t_c)``, ``t_c`` the acceleration-weighted mean time
    ``int t |s''| dt / int |s''| dt`` of the phase ``[t_0, t_1]``.

A phase is a maximal time span over which the path acceleration ``s''`` keeps one sign and
is not zero, ``|s''| > FREQ_ACCEL_TOL_REL * max|s''|`` (:data:`FREQ_ACCEL_TOL_REL`,
relative to the profile's largest ``|s''|``). Holds, constant-velocity spans and sign
changes separate phases; an acceleration that only *touches* zero for an instant (two
S-ramps back to back) does not end one. Phases run across profile knots.

Why the effective duration and not the plain one
------------------------------------------------
The plain duration ``t_1 - t_0`` constrains only the sign of ``s''``: a ramp may reach
nearly full speed at full acceleration and *creep* the last fraction of the change with a
tiny acceleration until the phase has lasted ``1/f``. The checker would accept it, it
excites what the rule is there to avoid, and the closed form of DESIGN 6 (a rest-to-rest
line at speed ``v`` with ``v/A < 1/f`` takes exactly ``L/v + 1/f``) would be false
(tests/core/test_phases.py builds such a ramp 5 % faster). The effective duration closes
that hole without touching the profiles the rule is meant for:

* ``D_eff <= t_1 - t_0`` always, so an accepted profile also meets the literal rule;
* ``D_eff = t_1 - t_0`` for every ramp whose acceleration pulse is symmetric in time: a
  constant acceleration (BRISK), a jerk-limited S-curve (SOFT), the adapted ramps of the
  dynamic response adaptation, a moving average (FIR) of a step; back-to-back symmetric
  ramps of at least ``1/f`` each also pass;
* it is a statement on lost time: ``int_P (v_1 - v) dt = dv (t_c - t_0)`` and
  ``int_P (v - v_0) dt = dv (t_1 - t_c)`` (integration by parts; ``v_0, v_1`` the speeds
  at the phase ends, ``dv`` the change), so the rule says that every phase loses, against
  either end speed, at least the time a linear ramp of ``1/f`` loses. That is what makes
  ``L/v + 1/f`` exact and what the lower bound of :mod:`optimal.freq.lower` uses.

What it still accepts: a speed change concentrated in the *middle* of a long phase whose
ends creep (the centroid stays central), in the limit a jump with ``1/(2f)`` of creep on
either side. Such a phase loses exactly as much time as the linear ramp of its effective
duration, and the bounds of every bound set hold for it (they are proven for the rule as
written). But where speed caps change inside the phase it can be *faster* than any ramp:
it holds a corner's low speed up to the corner and jumps right after it. On the tail of
lcnc_sam_tolerance_issue (corners 0.1-0.4 mm apart, caps of 1-8 mm/s, 15 Hz) an
exploratory lattice search found such jump motions about 9 % faster than the best with
linear ramps of ``1/f`` (1.25 s against 1.37 s). So on paths like that the optimum under
this rule is a motion no adaptation produces, and the oracle's verified motions, built
from ramps or keeping the phases of one (:mod:`optimal.freq.phase_nlp`, the jerk NLP with
this rule as its rows), stay above it. The oracle's NLP with the phases' ends free in path
position (:mod:`optimal.freq.free_phases`) finds such motions: on that program 2.3261 ->
2.1482 s under ``acc+freq``. The rule is a rule on time, not a guarantee of a smooth
acceleration spectrum. A rule that also bounds the acceleration within a phase by its
change (``|s''| <= 2 f dv``, which linear ramps and S-curves of ``1/f`` meet) would close
this; it is not adopted (issue 12 defines the rule by the phases' durations).

The mirror image is accepted too, and that one such a rule would not close: two abrupt
changes of one sign joined by a creep are one phase whose centroid lies in the creep
(tests/core/test_phases.py), so a fall may do most of its change at full acceleration,
pass a corner's low cap in the creep and finish at full acceleration, where ramps spend
``1/f`` on each change. ``|s''| <= 2 f dv`` hardly binds there (``dv`` is the whole
phase's change). On lcnc_test_12mmflat (default machine) this is where the bracket stayed
open: on its first pass (a line and four arcs, the last of radius 2.83 mm ending at a
1.4 mm/s corner) a hand-built motion of this kind, checked and time-scaled by 0.12 %, takes
3.3766 s against the oracle's ramps' 3.4153 s and a lower bound of 3.3360 s, so the lower
bound is near the optimum of the rule and the ramps are not. The oracle's NLP with the
rule's rows now joins such phases (:mod:`optimal.freq.phase_nlp`) and finds 3.3749 s.

Units: s, mm, Hz. numpy only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .arrays import concat_ranges
from .geometry import Path, axis_tangent_amplitudes, moving_axes
from .limits import AxisArrays
from .profile import Profile

__all__ = ["FREQ_ACCEL_TOL_REL", "Phases", "acceleration_phases", "min_phase_duration",
           "moving_axes_by_segment", "phase_frequencies"]

#: Path accelerations below this fraction of the profile's largest |s''| count as zero
#: when cutting the motion into phases. It absorbs the round-off of a = 0 spans
#: (a = dv/dt of equal speeds, about 1e-12 relative) and solver noise of a few 1e-7,
#: while a phase whose acceleration stays below 1e-6 of the profile's largest one changes
#: the speed by a negligible amount and excites nothing.
FREQ_ACCEL_TOL_REL = 1e-6

#: Intervals per step of the whole-array work (bounds temporaries only; results do not
#: depend on it): 10^6 blocks make some 5e6 pieces.
_STEP = 65_536


@dataclass(frozen=True, slots=True)
class Phases:
    """Acceleration and deceleration phases of a profile.

    Attributes
    ----------
    start_t, end_t : numpy.ndarray, shape (P,)
        Start and end time of each phase, s.
    sign : numpy.ndarray of int8, shape (P,)
        ``+1`` acceleration, ``-1`` deceleration.
    first, last : numpy.ndarray of int64, shape (P,)
        First and last profile interval the phase touches (inclusive).
    start_tau : numpy.ndarray, shape (P,)
        Start of the phase inside interval ``first``, s from its start.
    dv : numpy.ndarray, shape (P,)
        Speed change ``int |s''| dt`` over the phase, mm/s (>= 0).
    lead : numpy.ndarray, shape (P,)
        ``t_c - t_0``: from the phase start to its acceleration-weighted mean time, s.
    """

    start_t: np.ndarray
    end_t: np.ndarray
    sign: np.ndarray
    first: np.ndarray
    last: np.ndarray
    start_tau: np.ndarray
    dv: np.ndarray
    lead: np.ndarray

    @property
    def duration(self) -> np.ndarray:
        """``end_t - start_t``, s, shape (P,)."""
        return self.end_t - self.start_t

    @property
    def effective_duration(self) -> np.ndarray:
        """``2 min(t_c - t_0, t_1 - t_c)``, s, shape (P,): the length the rule judges."""
        lead = np.clip(self.lead, 0.0, self.duration)
        return 2.0 * np.minimum(lead, self.duration - lead)

    @property
    def n(self) -> int:
        """Number of phases."""
        return int(self.start_t.size)


def _empty() -> Phases:
    z = np.zeros(0)
    i = np.zeros(0, np.int64)
    return Phases(z, z, np.zeros(0, np.int8), i, i, z, z, z)


def acceleration_phases(profile: Profile, tol_rel: float = FREQ_ACCEL_TOL_REL) -> Phases:
    """Cut a profile into its acceleration and deceleration phases.

    Parameters
    ----------
    profile : Profile
        The motion; ``a`` is linear in time inside each interval (constant jerk).
        Zero-duration intervals must have been dropped (they carry no acceleration).
    tol_rel : float
        Accelerations with ``|s''| <= tol_rel * max|s''|`` count as zero.

    Returns
    -------
    Phases
        In time order; none for a motion without acceleration.
    """
    h = np.diff(profile.t)
    a0, j = profile.a, profile.j
    K = h.size
    scale = 0.0
    for lo in range(0, K, _STEP):
        hi = min(K, lo + _STEP)
        a1 = a0[lo:hi] + j[lo:hi] * h[lo:hi]
        scale = max(scale, float(np.max(np.abs(a0[lo:hi]))), float(np.max(np.abs(a1))))
    if scale == 0.0:
        return _empty()
    tol = tol_rel * scale
    parents, signs, taus0, taus1 = [], [], [], []
    for lo in range(0, K, _STEP):
        hi = min(K, lo + _STEP)
        c_a0, c_j, c_h = a0[lo:hi], j[lo:hi], h[lo:hi]
        c_a1 = c_a0 + c_j * c_h
        # pieces: intervals cut where a(tau), linear in tau, changes sign clearly (both
        # ends beyond tol); an end within tol of zero is a touch, not a change of sign, so
        # that round-off at the end of a ramp (a = -1e-13 instead of 0) cannot split a
        # phase
        cross = (c_j != 0) & (c_a0 * c_a1 < 0) & (np.abs(c_a0) > tol) & (np.abs(c_a1) > tol)
        with np.errstate(divide="ignore", invalid="ignore"):
            tz = np.where(cross, -c_a0 / np.where(cross, c_j, 1.0), 0.0)
        npc = 1 + cross.astype(np.int64)
        local = np.repeat(np.arange(hi - lo), npc)
        second = np.zeros(local.size, bool)
        second[np.cumsum(npc)[cross] - 1] = True
        first_of_two = np.repeat(cross, npc) & ~second
        tau0 = np.where(second, tz[local], 0.0)
        tau1 = np.where(first_of_two, tz[local], c_h[local])
        pa0 = c_a0[local] + c_j[local] * tau0
        pa1 = c_a0[local] + c_j[local] * tau1
        amax = np.maximum(np.abs(pa0), np.abs(pa1))
        moving = (profile.s[lo + 1:hi + 1] > profile.s[lo:hi])[local]
        dominant = np.where(np.abs(pa1) > np.abs(pa0), pa1, pa0)
        signs.append(np.where((amax > tol) & moving, np.sign(dominant), 0.0).astype(np.int8))
        parents.append(local + lo)
        taus0.append(tau0)
        taus1.append(tau1)
    sign = np.concatenate(signs)
    del signs
    if not np.any(sign):
        return _empty()
    parent = np.concatenate(parents)
    del parents
    tau0 = np.concatenate(taus0)
    del taus0
    tau1 = np.concatenate(taus1)
    del taus1
    starts = np.concatenate(([0], np.flatnonzero(np.diff(sign)) + 1))
    ends = np.concatenate((starts[1:], [sign.size]))
    nz = sign[starts] != 0
    starts, ends = starts[nz], ends[nz]
    t = profile.t
    start_t = t[parent[starts]] + tau0[starts]
    end_t = t[parent[ends - 1]] + tau1[ends - 1]
    keep = end_t > start_t
    starts, ends = starts[keep], ends[keep]
    start_t, end_t = start_t[keep], end_t[keep]
    dv, lead = _pulse_moments(a0, j, t, parent, tau0, tau1, sign, starts, ends, start_t)
    return Phases(start_t=start_t, end_t=end_t, sign=sign[starts].copy(),
                  first=parent[starts].astype(np.int64),
                  last=parent[ends - 1].astype(np.int64), start_tau=tau0[starts].copy(),
                  dv=dv, lead=lead)


def _pulse_moments(a0: np.ndarray, j: np.ndarray, t: np.ndarray, parent: np.ndarray,
                   tau0: np.ndarray, tau1: np.ndarray, sign: np.ndarray,
                   starts: np.ndarray, ends: np.ndarray, start_t: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Area ``int |a| dt`` and first moment about the phase start of each phase's pulse.

    The pieces ``[starts[p], ends[p])`` of phase ``p`` carry ``a(tau) = a0 + j tau`` on
    ``[tau0, tau1]`` of their interval; the signed acceleration is multiplied by the
    phase's sign, so a piece that dips a round-off below zero at its end subtracts its
    (negligible) share instead of adding it. Moments are taken about the phase start
    (times of the order of the phase, not of the whole motion: no cancellation).

    Returns
    -------
    dv : numpy.ndarray, shape (P,)
        mm/s.
    lead : numpy.ndarray, shape (P,)
        s; ``0`` where ``dv = 0``.
    """
    P = starts.size
    dv = np.zeros(P)
    mom = np.zeros(P)
    n_p = ends - starts
    for lo in range(0, P, _STEP):
        hi = min(P, lo + _STEP)
        idx = concat_ranges(starts[lo:hi], ends[lo:hi])
        which = np.repeat(np.arange(hi - lo), n_p[lo:hi])
        k = parent[idx]
        c0 = a0[k] * sign[idx]
        c1 = j[k] * sign[idx]
        u0, u1 = tau0[idx], tau1[idx]
        # offset of the interval start from the phase start
        off = t[k] - start_t[lo:hi][which]
        d1 = u1 - u0
        d2 = (u1 * u1 - u0 * u0) / 2.0
        d3 = (u1 ** 3 - u0 ** 3) / 3.0
        area = c0 * d1 + c1 * d2
        first = off * area + c0 * d2 + c1 * d3
        dv[lo:hi] = np.bincount(which, area, minlength=hi - lo)
        mom[lo:hi] = np.bincount(which, first, minlength=hi - lo)
    with np.errstate(divide="ignore", invalid="ignore"):
        lead = np.where(dv > 0, mom / np.where(dv > 0, dv, 1.0), 0.0)
    return np.maximum(dv, 0.0), lead


def moving_axes_by_segment(path: Path) -> np.ndarray:
    """Which axes can move on each segment.

    Parameters
    ----------
    path : Path

    Returns
    -------
    numpy.ndarray of bool, shape (m, n_axes)
        :func:`reference.core.geometry.moving_axes` (the rule the heuristic's limits use
        too).
    """
    return moving_axes(*axis_tangent_amplitudes(path))


def phase_frequencies(path: Path, lim: AxisArrays, phases: Phases,
                      interval_segment: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The deciding frequency of each phase: the smallest f of the axes moving in it.

    Parameters
    ----------
    path : Path
        The path.
    lim : AxisArrays
        Limits of ``path.axes``.
    phases : Phases
        From :func:`acceleration_phases`.
    interval_segment : numpy.ndarray of int, shape (K,)
        Segment of each profile interval (every interval on one segment).

    Returns
    -------
    f : numpy.ndarray, shape (P,)
        Hz; ``inf`` where no axis moves.
    axis : numpy.ndarray of int, shape (P,)
        Index (into ``path.axes``) of the deciding axis.
    """
    P = phases.n
    f_out = np.full(P, np.inf)
    ax_out = np.zeros(P, np.int64)
    if P == 0:
        return f_out, ax_out
    seg_moving = moving_axes_by_segment(path).astype(np.uint8)
    for lo in range(0, P, _STEP):
        hi = min(P, lo + _STEP)
        first, last = phases.first[lo:hi], phases.last[lo:hi]
        n_r = last - first + 1
        idx = concat_ranges(first, last + 1)
        run = np.maximum.reduceat(seg_moving[interval_segment[idx]],
                                  np.concatenate(([0], np.cumsum(n_r)[:-1])), axis=0)
        f = np.where(run.astype(bool), lim.frequency_hz[None, :], np.inf)
        f_out[lo:hi] = f.min(axis=1)
        ax_out[lo:hi] = f.argmin(axis=1)
    return f_out, ax_out


def min_phase_duration(f: np.ndarray | float) -> np.ndarray:
    """The rule itself: the shortest allowed phase, ``1/f`` s (0 where ``f = inf``)."""
    f = np.asarray(f, dtype=np.float64)
    with np.errstate(divide="ignore"):
        return np.where(np.isfinite(f), 1.0 / f, 0.0)


