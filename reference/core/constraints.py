"""The one constraint checker: judges every profile (heuristic, oracle, recorded) alike.

``check_profile(path, limits, profile)`` evaluates the motion analytically or densely
*inside every interval* (never only at knots) and returns, per constraint, the worst
ratio ``value / limit`` with its place (path position, time, NC block, axis), plus the
worst ratio of every NC block. A ratio <= 1 satisfies a constraint; the report counts a
constraint as violated above ``1 + RATIO_TOL``.

Notation: ``q'``, ``q''``, ``q'''`` are the path derivatives of the axis positions with
respect to ``s`` (exact, from :class:`~reference.core.geometry.Path`), ``v = s'``,
``s''`` and ``s'''`` the path velocity, acceleration and jerk of the
:class:`~reference.core.profile.Profile`.

Constraints (:data:`CONSTRAINTS`)
---------------------------------
``velocity``
    per axis ``|q'_i v| <= v_max_i`` (mm/s; deg/s for rotary axes).
``acceleration``
    per axis ``|q'_i s'' + q''_i v^2| <= a_max_i`` (tangential plus centripetal part).
``jerk``
    per axis ``|q'_i s''' + 3 q''_i v s'' + q'''_i v^3| <= j_max_i`` inside intervals,
    **plus acceleration steps** (the rulebook, :data:`reference.core.rules.STEPS_AT_BREAKS`):
    where the geometry makes an axis acceleration ``A_i = q'_i s'' + q''_i v^2`` step
    (a segment break where the tangent or the curvature vector jumps, the start and end
    of the profile, whose surroundings are taken to be at rest with zero acceleration)
    the control spreads the step over one IPO cycle (sinumerik-model 6.3), so it counts
    as the jerk ``|delta A_i| / t_ipo``, judged against ``path_trans_jerk_i`` (MD32432)
    at a segment break where the curvature vector jumps
    (:func:`reference.core.rules.curvature_jumps`) while the path moves
    (``v > VEL_TOL_MM_S``) and against ``j_max_i`` everywhere else (a knot within the
    position tolerance of a break counts as at the break). Inside a segment a
    jerk-limited motion has a continuous acceleration: the steps at its other knots,
    summed per segment and axis, must stay within
    ``ACCEL_CONTINUITY_TOL_REL * j_max_i * t_ipo`` (round-off; the value reported is that
    sum over ``t_ipo``, the limit ``ACCEL_CONTINUITY_TOL_REL * j_max_i``). Without this, a
    profile with many knots could build up acceleration in steps, each within the
    one-cycle allowance, faster than any jerk-limited motion. A recording sampled at the
    IPO cycle is judged with ``steps="spread"`` instead
    (:data:`reference.core.rules.STEPS_SPREAD`): every knot's step counts as
    ``|delta A_i| / t_ipo``. BRISK profiles (acceleration steps by design) show large jerk
    ratios; that is expected, their bound set has no jerk.
``feed``
    path speed ``v <= F`` of the segment (``F = inf`` for G0: nothing to check). ``s``
    is the arc length of the geometry axes, or of the moving axes where only extra
    axes move; the feed applies to that speed as given.
``velocity_jump``
    at every interior segment break whose tangents differ by more than
    :data:`~reference.core.tolerances.TANGENT_TOL_RAD`, crossed at ``v > 0``: per axis
    ``delta v_i = v |q'_i(right) - q'_i(left)|`` against the MD32310 allowance
    ``jump_i = a_max_i (ovl_i - 1) t_ipo`` (sinumerik-model 4.1/4.2). A jump of at most
    ``VEL_TOL_MM_S`` counts as none (ratio 0, as ``optimal.problem`` assumes). With an
    allowance of 0 (``ovl = 1``) a larger jump has the ratio ``float('inf')`` (no
    finite limit exists; JSON writers must encode it, e.g. as ``null`` or a string).
``stop``
    ``|v| <= VEL_TOL_MM_S`` at every break where ``path.stop`` is True (the path start
    and end, exact stops, forced stops); ratio ``|v| / VEL_TOL_MM_S``, so <= 1 means at
    rest. ``v`` at a break is the smallest ``|v|`` of the profile's knots within its
    position tolerance ``POS_TOL_MM * max(1, L)`` of the break (the exact crossing is
    always among them), so a stop reached a round-off distance away counts as reached;
    the same speed enters ``velocity_jump``. Only the velocity is required; start/end accelerations are not judged here
    (a non-zero one shows up as a jerk step).
``frequency``
    DESIGN section 6, the rule of :mod:`reference.core.phases` (one definition for the
    checker, the heuristic and the oracle): every acceleration or deceleration phase (a
    maximal time span in which the path acceleration keeps one sign and is not zero,
    ``|s''| > FREQ_ACCEL_TOL_REL * max|s''|``, across knots; holds, constant-velocity
    spans and sign changes separate phases, while an acceleration that only touches
    zero for an instant, two S-ramps back to back, does not end one) lasts at least
    ``1/f``, ``f`` the smallest LOOKAH_FREQUENCY of the axes moving during it, its length
    measured as the effective duration ``2 min(t_c - t_0, t_1 - t_c)`` about the
    acceleration-weighted mean time ``t_c`` (equal to the duration for symmetric ramps;
    why, in :mod:`reference.core.phases`). Value ``1/D_eff`` (Hz), limit ``f`` (Hz), so
    the ratio is ``(1/f) / D_eff``; the place (``t``, ``s``, block) is the start of the
    shortest phase relative to its limit and the axis is the moving axis with the
    smallest ``f``.

Evaluation inside intervals and its error
-----------------------------------------
The profile is first split at the segment breaks, so that every sub-interval lies on
one segment (lines, arcs, helices).

* **Lines** (``q' = d`` constant, ``q'' = q''' = 0``): axis velocity, acceleration and
  jerk are ``|d_i|`` times polynomials of degree 2, 1, 0 in ``tau``; their maxima are
  taken exactly at the interval ends and the stationary point of ``v`` (``s''= 0``).
* **Arcs, helices and clothoids**: dense samples, uniform in time, at an angular step of
  at most
  :data:`ARC_SAMPLE_STEP_RAD` (0.125 deg) *at the interval's peak speed* (so also where
  the motion is fastest; on a spiral or clothoid at its largest angular rate
  :attr:`~reference.core.geometry.PlaneAmplitudes.omega_max`), at least
  :data:`MIN_ARC_SAMPLES` per sub-interval, plus the stationary point of ``v``. A maximum of a cos-type function sampled at step
  ``dphi`` is missed by at most ``1 - cos(dphi/2) <= dphi^2/8`` of its amplitude:
  **5.9e-7 relative** at 0.125 deg, below :data:`RATIO_TOL`. In general the deficit
  is at most ``sup|g''| dtau^2 / 8`` for a quantity ``g(tau)`` sampled at time step
  ``dtau``; on arcs ``g''`` is dominated by ``(omega v)^2 g``, which gives the bound
  above, plus terms from the time variation of ``s''`` and ``v`` inside the interval.
  On circles and helices the samples at that step are taken only where they can
  matter: a first pass samples at :data:`ARC_COARSE_FACTOR` times the step, and a
  coarse step is sampled finely only where its end values plus ``B D^2/8`` could exceed
  the largest value sampled on the interval (``D`` the coarse step, ``B`` a rigorous
  bound on the quantity's second time derivative inside the interval, from the
  circle's derivative amplitudes and the interval's largest speed, path acceleration
  and path jerk: :func:`_arc_curvature_bounds`). A step left coarse cannot hold a
  larger value, so the bound above holds unchanged.
  After sampling, the worst sample of each interval and quantity is refined once by
  the vertex of the parabola through it and its neighbours, evaluated exactly; this
  can only raise the maximum found and, for smooth maxima, brings the deficit to order
  ``dphi^4`` (about 1e-12 relative).
* The feed uses ``v`` only and is exact everywhere (ends and stationary point).

Work is vectorised and done in chunks of about :data:`CHUNK_SAMPLES` evaluation points,
so memory stays bounded for profiles of 10^5..10^6 intervals.

Attribution to NC blocks: a point inside a segment belongs to the segment's block; an
event at a segment break (velocity jump, acceleration step, stop) belongs to the block
that *ends* there, as the control reduces the speed at the end of that block; the path
start belongs to the first block.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Iterable, Mapping

import numpy as np

from .arrays import concat_ranges
from .errors import ProfileError
from .geometry import Path, clothoid_derivative_norms, plane_amplitudes
from .limits import AxisArrays, MachineLimits
from .phases import (FREQ_ACCEL_TOL_REL, acceleration_phases, min_phase_duration,
                     phase_frequencies)
from .profile import Profile
from .rules import (STEPS_AT_BREAKS, STEPS_SPREAD, axis_acceleration, axis_jerk,
                    axis_velocity, axis_velocity_jumps, curvature_jumps, jump_ratio,
                    step_jerk_limit)
from .tolerances import (ACCEL_CONTINUITY_TOL_REL, POS_TOL_MM, RATIO_TOL,
                         VEL_TOL_MM_S)

__all__ = ["BOUND_SETS", "CONSTRAINTS", "FREQ_ACCEL_TOL_REL", "ConstraintReport", "ConstraintResult", "UNITS",
           "check_profile", "scale_time", "time_scale_factor", "time_scale_factors_by_block"]

#: Every constraint the checker evaluates, in report order.
CONSTRAINTS: tuple[str, ...] = ("velocity", "acceleration", "jerk", "feed", "velocity_jump",
                                "stop", "frequency")

_ACC_SET = ("velocity", "acceleration", "feed", "velocity_jump", "stop")
#: The constraints each bound set of the oracle (DESIGN section 6) and heuristic declares.
BOUND_SETS: Mapping[str, tuple[str, ...]] = MappingProxyType({
    "acc": _ACC_SET,
    "jerk": _ACC_SET + ("jerk",),
    "acc+freq": _ACC_SET + ("frequency",),
    "jerk+freq": _ACC_SET + ("jerk", "frequency"),
})

#: Unit of value and limit of each constraint.
UNITS: Mapping[str, str] = MappingProxyType({
    "velocity": "mm/s", "acceleration": "mm/s^2", "jerk": "mm/s^3", "feed": "mm/s",
    "velocity_jump": "mm/s", "stop": "mm/s", "frequency": "Hz"})

#: Largest angular step between samples on arcs and helices, rad. 0.125 deg misses a
#: cos-type peak by at most (step)^2/8 = 5.9e-7 of its amplitude, below RATIO_TOL.
ARC_SAMPLE_STEP_RAD = float(np.deg2rad(0.125))

#: On circles and helices the first pass samples at this many times the fine step
#: (:data:`ARC_SAMPLE_STEP_RAD`), and only the coarse steps that may hold a larger value,
#: by a bound on the second derivative, are sampled at the fine step (:func:`_check_arcs`).
#: 8 (1 deg): at a cos-like peak the chord bound exceeds the peak by a few (1 deg)^2/8,
#: so one or two coarse steps per peak are refined; a larger factor refines more of each
#: step it keeps, a smaller one samples more coarsely everywhere.
ARC_COARSE_FACTOR = 8

#: Fewest uniform samples per sub-interval on an arc: keeps the time polynomials of
#: short, slow intervals resolved even when they sweep almost no angle.
MIN_ARC_SAMPLES = 8

#: Evaluation points per chunk. 65 536 points of n axes need about 0.5 MB per (N, n)
#: array and axis; a chunk uses some 20 of them, so a few tens of MB at most.
CHUNK_SAMPLES = 65_536
#: :attr:`ConstraintResult.detail` of the jerk row of acceleration steps inside
#: segments (where the path acceleration must be continuous): a BRISK profile judged
#: under a jerk set fails there by a ratio of about 1e8, which reads as nonsense beside
#: the jerk limit unless the line says what is compared.
CONTINUITY_DETAIL = ("acceleration steps inside a segment, summed per IPO cycle, against "
                     "the continuity tolerance ACCEL_CONTINUITY_TOL_REL x jerk limit: "
                     "the acceleration must be continuous there")

#: Items (intervals, arcs, processes) per step where a whole-array formula is only
#: split to bound its temporaries: the results do not depend on it (unlike
#: ``CHUNK_SAMPLES``, which also sets how a long arc interval is cut into pieces).
_WORK_CHUNK = CHUNK_SAMPLES



# =========================================================================== results
@dataclass(frozen=True, slots=True)
class ConstraintResult:
    """Worst place of one constraint.

    Attributes
    ----------
    constraint : str
        One of :data:`CONSTRAINTS`.
    ratio : float
        ``value / limit`` at the worst place (<= 1 satisfied; ``inf`` for a velocity
        jump where the allowance is 0; 0.0 when there was nothing to check).
    value, limit : float
        In :attr:`unit` (:data:`UNITS`); both 0.0 when there was nothing to check.
    unit : str
        Unit of ``value`` and ``limit``.
    s : float
        Path position, mm.
    t : float
        Time, s.
    block : int
        NC block index (``path.blocks[i].block``), -1 when there was nothing to check.
    axis : str or None
        Axis name for per-axis constraints (velocity, acceleration, jerk,
        velocity_jump), the deciding axis (smallest f) for frequency, None otherwise.
    detail : str
        What ``value`` and ``limit`` measure where that is not the constraint's plain
        quantity (the jerk row of acceleration steps inside a segment: their sum per
        IPO cycle against the continuity tolerance, not the jerk limit); ``""`` else.
    """

    constraint: str
    ratio: float
    value: float
    limit: float
    unit: str
    s: float
    t: float
    block: int
    axis: str | None
    detail: str = ""

    @property
    def violated(self) -> bool:
        """True when :attr:`ratio` exceeds ``1 + RATIO_TOL``."""
        return self.ratio > 1.0 + RATIO_TOL


def _names(constraints: Iterable[str] | None) -> tuple[str, ...]:
    names = CONSTRAINTS if constraints is None else tuple(constraints)
    unknown = [n for n in names if n not in CONSTRAINTS]
    if unknown:
        raise KeyError(f"unknown constraint {unknown[0]!r}; known: {', '.join(CONSTRAINTS)}")
    return names


@dataclass(frozen=True, slots=True)
class ConstraintReport:
    """Worst ratio per constraint, plus the worst ratio per NC block.

    Attributes
    ----------
    results : tuple[ConstraintResult, ...]
        One per constraint, in :data:`CONSTRAINTS` order.
    block_ratios : Mapping[str, numpy.ndarray]
        Per constraint, shape ``(n_blocks,)``: worst ratio in each NC block, indexed by
        block index (0 where the block has nothing to check).
    components : Mapping[str, ConstraintResult]
        Parts of a constraint that scale differently in time: ``"jerk_interval"``
        (jerk inside intervals, ``1/lam^3``) and ``"jerk_step"`` (acceleration steps
        over one IPO cycle, ``1/lam^2``). Used by :func:`time_scale_factor`.
    """

    results: tuple[ConstraintResult, ...]
    block_ratios: Mapping[str, np.ndarray] = field(default_factory=dict)
    components: Mapping[str, ConstraintResult] = field(default_factory=dict)

    def worst(self, name: str) -> ConstraintResult:
        """The worst place of one constraint.

        Raises
        ------
        KeyError
            ``name`` is not in :data:`CONSTRAINTS`.
        """
        for r in self.results:
            if r.constraint == name:
                return r
        raise KeyError(f"unknown constraint {name!r}; known: {', '.join(CONSTRAINTS)}")

    def violations(self, constraints: Iterable[str] | None = None,
                   tol: float = RATIO_TOL) -> tuple[ConstraintResult, ...]:
        """Results with ``ratio > 1 + tol``.

        Parameters
        ----------
        constraints : iterable of str, optional
            Names to consider (default: all); e.g. ``BOUND_SETS["jerk"]``.
        tol : float
            Relative tolerance on the ratio.

        Returns
        -------
        tuple[ConstraintResult, ...]
            In :data:`CONSTRAINTS` order.
        """
        names = set(_names(constraints))
        return tuple(r for r in self.results if r.constraint in names and r.ratio > 1.0 + tol)

    def ok(self, constraints: Iterable[str] | None = None, tol: float = RATIO_TOL) -> bool:
        """True when none of ``constraints`` (default: all) is violated."""
        return not self.violations(constraints, tol)

    def max_ratio(self, constraints: Iterable[str] | None = None) -> float:
        """Largest ratio among ``constraints`` (default: all); 0.0 for none."""
        names = set(_names(constraints))
        return max((r.ratio for r in self.results if r.constraint in names), default=0.0)


class _Worst:
    """Running maximum of one constraint over chunks (private accumulator).

    Ties are broken towards the earliest time, so the result does not depend on the
    chunking or on the order in which interval kinds are processed.
    """

    __slots__ = ("ratio", "value", "limit", "s", "t", "block", "axis", "found", "per_block",
                 "detail")

    def __init__(self, n_blocks: int) -> None:
        self.ratio = self.value = self.limit = self.s = self.t = 0.0
        self.block, self.axis, self.found = -1, None, False
        self.per_block = np.zeros(n_blocks)
        self.detail = ""

    def update(self, ratio, value, limit, s, t, block, axes=None, detail: str = "") -> None:
        """Fold in candidate places.

        ``ratio``, ``value`` shaped ``(N, n)`` (per axis, then ``axes`` names them) or
        ``(N,)``; ``limit`` broadcastable to that shape; ``s``, ``t``, ``block`` ``(N,)``;
        ``detail``: :attr:`ConstraintResult.detail` of these places.
        """
        N = ratio.shape[0]
        if N == 0:
            return
        r2 = ratio.reshape(N, -1)
        row_max = r2.max(axis=1)
        if self.per_block.size:
            np.maximum.at(self.per_block, block, row_max)
        best = float(row_max.max())
        if self.found and best < self.ratio:
            return
        rows = np.flatnonzero(row_max == best)
        row = int(rows[np.argmin(t[rows])])
        if self.found and best == self.ratio and t[row] >= self.t:
            return
        col = int(np.argmax(r2[row]))
        self.found = True
        self.ratio = best
        self.value = float(value.reshape(N, -1)[row, col])
        self.limit = float(np.broadcast_to(limit, ratio.shape).reshape(N, -1)[row, col])
        self.s, self.t, self.block = float(s[row]), float(t[row]), int(block[row])
        self.axis = axes[col] if axes is not None else None
        self.detail = detail

    def merge(self, other: "_Worst") -> None:
        """Fold another accumulator of the same constraint into this one."""
        if self.per_block.size:
            np.maximum(self.per_block, other.per_block, out=self.per_block)
        if other.found and (not self.found or other.ratio > self.ratio or
                            (other.ratio == self.ratio and other.t < self.t)):
            for name in ("ratio", "value", "limit", "s", "t", "block", "axis", "found",
                         "detail"):
                setattr(self, name, getattr(other, name))

    def result(self, name: str) -> ConstraintResult:
        return ConstraintResult(name, self.ratio, self.value, self.limit, UNITS[name],
                                self.s, self.t, self.block, self.axis, self.detail)


# ====================================================================== the checker
@dataclass(frozen=True, slots=True, eq=False)
class _Ctx:
    """What every stage of one check needs (private)."""

    path: Path
    lim: AxisArrays
    t_ipo: float
    prof: Profile
    h: np.ndarray          # (K,) interval durations, s
    seg: np.ndarray        # (K,) segment of each interval
    n_blocks: int


def check_profile(path: Path, limits: MachineLimits, profile: Profile, *,
                  steps: str = STEPS_AT_BREAKS) -> ConstraintReport:
    """Judge a profile against the machine limits on its path.

    Parameters
    ----------
    path : Path
        The path the profile runs on.
    limits : MachineLimits
        Machine limits; must define every axis of the path.
    profile : Profile
        The motion ``s(t)``; its knots must span ``[0, path.total_length]`` (mm).
    steps : {"breaks", "spread"}
        Where the path acceleration may step
        (:data:`~reference.core.rules.STEPS_AT_BREAKS` for planned motions, the
        default; :data:`~reference.core.rules.STEPS_SPREAD` for a recording sampled at
        the IPO cycle); see ``jerk`` in the module docstring.

    Returns
    -------
    ConstraintReport
        Worst ratio per constraint with its place, per-block worst ratios, and the jerk
        components for time scaling. See the module docstring for the rules.

    Raises
    ------
    ProfileError
        The profile does not cover the path.
    MachineDataError
        ``limits`` lacks an axis of the path.
    """
    if steps not in (STEPS_AT_BREAKS, STEPS_SPREAD):
        raise ValueError(f"steps must be {STEPS_AT_BREAKS!r} or {STEPS_SPREAD!r}, "
                         f"got {steps!r}")
    lim = limits.for_axes(path.axes)
    # judge the axes that move (exact: the others have zero derivatives everywhere, so
    # every ratio of theirs is 0); a 2-D contour on an XYZ machine samples two columns
    moving = path.moving_axes()
    if 0 < moving.size < path.n_axes:
        path = path.restricted(moving)
        lim = limits.for_axes(path.axes)
    L = path.total_length
    if profile.s.size and (abs(profile.s[0]) > POS_TOL_MM or
                           abs(profile.s[-1] - L) > POS_TOL_MM * max(1.0, L)):
        raise ProfileError(f"profile starts at s = {profile.s[0]:.6g} mm and ends at s = "
                           f"{profile.s[-1]:.6g} mm but the path is {L:.6g} mm long")
    # (a generator: a list would hold 10^6 ints for one maximum)
    n_blocks = max(int(path.blocks.block.max()) + 1 if len(path.blocks) else 0,
                   int(path.block.max()) + 1 if path.n_segments else 0)
    worst = {c: _Worst(n_blocks) for c in CONSTRAINTS}
    jerk_step = _Worst(n_blocks)
    prof = _drop_empty(profile)
    if path.n_segments and prof.n_intervals:
        # interior breaks only: a cut at a path end that the profile overshoots by
        # round-off would create a knot just short of the final rest
        prof = prof.split_at(path.s_breaks[1:-1])
        h = np.diff(prof.t)
        seg = path.segment_index(0.5 * (prof.s[:-1] + prof.s[1:]))
        ctx = _Ctx(path, lim, limits.t_ipo_s, prof, h, seg, n_blocks)
        _check_intervals(ctx, worst)
        _check_steps(ctx, jerk_step, steps)
        _check_breaks(ctx, worst)
        _check_frequency(ctx, worst["frequency"])
    else:
        # no motion to judge: only rest can be asked for
        v = np.abs(prof.v)
        k = int(np.argmax(v)) if v.size else 0
        w = worst["stop"]
        if v.size:
            blk = np.full(1, path.blocks[0].block if path.blocks else 0)
            w.update(v[k:k + 1] / VEL_TOL_MM_S, v[k:k + 1], VEL_TOL_MM_S, prof.s[k:k + 1],
                     prof.t[k:k + 1], blk)
    jerk_interval = worst["jerk"]
    components = {"jerk_interval": jerk_interval.result("jerk"),
                  "jerk_step": jerk_step.result("jerk")}
    total_jerk = _Worst(n_blocks)
    total_jerk.merge(jerk_interval)
    total_jerk.merge(jerk_step)
    worst["jerk"] = total_jerk
    for w in worst.values():
        w.per_block.setflags(write=False)
    return ConstraintReport(
        results=tuple(worst[c].result(c) for c in CONSTRAINTS),
        block_ratios=MappingProxyType({c: worst[c].per_block for c in CONSTRAINTS}),
        components=MappingProxyType(components))


def _drop_empty(profile: Profile) -> Profile:
    """The same motion without zero-duration intervals.

    Their acceleration is never held, so they must not create acceleration steps.
    """
    h = np.diff(profile.t)
    empty = h == 0
    if not np.any(empty):
        return profile
    keep_iv = ~empty
    keep_knot = np.concatenate(([True], keep_iv))
    if not np.any(keep_iv):
        keep_knot = np.zeros_like(keep_knot)
        keep_knot[0] = True
    return Profile(t=profile.t[keep_knot], s=profile.s[keep_knot], v=profile.v[keep_knot],
                   a=profile.a[keep_iv], j=profile.j[keep_iv], block=profile.block[keep_iv])


def _chunks(cost: np.ndarray) -> list[tuple[int, int]]:
    """Index ranges whose summed cost is about CHUNK_SAMPLES (at least one item each)."""
    if cost.size == 0:
        return []
    cum = np.cumsum(cost)
    cid = (cum - 1) // CHUNK_SAMPLES
    cut = np.flatnonzero(np.diff(cid)) + 1
    bounds = np.concatenate(([0], cut, [cost.size]))
    return [(int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:])]


def _poly(s0, v0, a0, j, tau):
    """Path position, velocity and acceleration at ``tau`` inside intervals."""
    s = s0 + tau * (v0 + tau * (a0 / 2 + tau * j / 6))
    v = v0 + tau * (a0 + tau * j / 2)
    return s, v, a0 + j * tau


def _speed_peak(ctx: _Ctx, k: np.ndarray):
    """Largest |v| on intervals ``k`` and where (exact: ends and stationary point)."""
    p, h = ctx.prof, ctx.h[k]
    v0, a0, j = p.v[k], p.a[k], p.j[k]
    v1 = p.v[k + 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        ts = np.where(j != 0, -a0 / np.where(j != 0, j, 1.0), -1.0)
    inside = (ts > 0) & (ts < h)
    ts = np.where(inside, ts, 0.0)
    vs = v0 + ts * (a0 + ts * j / 2)
    cand = np.stack([np.abs(v0), np.abs(v1), np.where(inside, np.abs(vs), 0.0)])
    pick = np.argmax(cand, axis=0)
    tau = np.choose(pick, [np.zeros_like(h), h, ts])
    return cand.max(axis=0), tau, ts


def _check_intervals(ctx: _Ctx, worst: dict[str, _Worst]) -> None:
    """Velocity, acceleration, jerk (inside intervals) and feed on every interval."""
    path = ctx.path
    k_all = np.flatnonzero(ctx.h > 0)
    arc = path.radius[ctx.seg[k_all]] > 0
    # samples per arc interval (lines need none), from its peak speed; formed in chunks
    # of arc intervals (the speed peak's temporaries are a dozen arrays per interval)
    n_uni = np.zeros(k_all.size, dtype=np.int64)
    arc_i = np.flatnonzero(arc)
    if arc_i.size:
        omega_max = plane_amplitudes(path).omega_max
        for lo in range(0, arc_i.size, _WORK_CHUNK):
            ii = arc_i[lo:lo + _WORK_CHUNK]
            k = k_all[ii]
            vpk, _, _ = _speed_peak(ctx, k)
            n_uni[ii] = np.maximum(
                MIN_ARC_SAMPLES,
                np.ceil(omega_max[ctx.seg[k]] * vpk * ctx.h[k]
                        / ARC_SAMPLE_STEP_RAD).astype(np.int64) + 1)
    # An arc interval needing more than a chunk of samples (a long helix run in few
    # intervals) is cut into pieces of time, each sampled at the same density; so every
    # chunk stays about CHUNK_SAMPLES points whatever the number of turns.
    if np.any(n_uni > CHUNK_SAMPLES):
        n_piece = np.maximum(1, -(-n_uni // CHUNK_SAMPLES))
        piece_k = np.repeat(k_all, n_piece)
        start = np.concatenate(([0], np.cumsum(n_piece)[:-1]))
        idx = np.arange(piece_k.size) - np.repeat(start, n_piece)
        piece_first = idx == 0
        frac0 = idx / np.repeat(n_piece, n_piece)
        frac1 = (idx + 1) / np.repeat(n_piece, n_piece)
        n_rows = np.repeat(np.maximum(MIN_ARC_SAMPLES, -(-n_uni // n_piece) + 1), n_piece)
        arc_p = np.repeat(arc, n_piece)
        n_rows = np.where(arc_p, n_rows, 0)
    else:
        # one piece per interval: the whole interval (read-only views, no copies)
        piece_k = k_all
        piece_first = np.broadcast_to(True, k_all.shape)
        frac0 = np.broadcast_to(0.0, k_all.shape)
        frac1 = np.broadcast_to(1.0, k_all.shape)
        n_rows, arc_p = n_uni, arc
    # cost: one row per line interval; uniform + stationary + 3 refinement rows per arc
    cost = np.where(arc_p, n_rows + 4, 1)
    for lo, hi in _chunks(cost):
        k = piece_k[lo:hi]
        a_mask = arc_p[lo:hi]
        once = piece_first[lo:hi]
        _check_feed(ctx, k[once], worst["feed"])
        if np.any(~a_mask):
            _check_lines(ctx, k[~a_mask], worst)
        if np.any(a_mask):
            _check_arcs(ctx, k[a_mask], n_rows[lo:hi][a_mask], worst,
                        frac0[lo:hi][a_mask], frac1[lo:hi][a_mask])


def _check_feed(ctx: _Ctx, k: np.ndarray, w: _Worst) -> None:
    feed = ctx.path.feed[ctx.seg[k]]
    fin = np.isfinite(feed)
    if not np.any(fin):
        return
    k, feed = k[fin], feed[fin]
    vpk, tau, _ = _speed_peak(ctx, k)
    p = ctx.prof
    s, _, _ = _poly(p.s[k], p.v[k], p.a[k], p.j[k], tau)
    w.update(vpk / feed, vpk, feed, s, p.t[k] + tau, ctx.path.block[ctx.seg[k]])


def _check_lines(ctx: _Ctx, k: np.ndarray, worst: dict[str, _Worst]) -> None:
    """Exact maxima on straight segments: |d_i| times a polynomial in tau."""
    p, path, lim, axes = ctx.prof, ctx.path, ctx.lim, ctx.path.axes
    h, seg = ctx.h[k], ctx.seg[k]
    d = np.abs(path.d[seg])
    blk = path.block[seg]
    vpk, tau_v, _ = _speed_peak(ctx, k)
    a0 = p.a[k]
    a1 = a0 + p.j[k] * h
    tau_a = np.where(np.abs(a1) > np.abs(a0), h, 0.0)
    apk = np.maximum(np.abs(a0), np.abs(a1))
    jpk = np.abs(p.j[k])
    for name, peak, tau, lim_i in (("velocity", vpk, tau_v, lim.v_max),
                                   ("acceleration", apk, tau_a, lim.a_max),
                                   ("jerk", jpk, np.zeros_like(h), lim.j_max)):
        val = d * peak[:, None]
        s, _, _ = _poly(p.s[k], p.v[k], p.a[k], p.j[k], tau)
        worst[name].update(val / lim_i, val, lim_i, s, p.t[k] + tau, blk, axes)


def _axis_kinematics(ctx: _Ctx, k: np.ndarray, tau: np.ndarray):
    """Axis velocity, acceleration and jerk at ``tau`` inside intervals ``k``.

    Returns
    -------
    vel, acc, jer : numpy.ndarray, shape (N, n)
        Absolute values.
    s, t : numpy.ndarray, shape (N,)
    """
    p, path = ctx.prof, ctx.path
    seg = ctx.seg[k]
    j = p.j[k]
    s, v, a = _poly(p.s[k], p.v[k], p.a[k], j, tau)
    # round-off must not push a point into the neighbouring segment
    s = np.clip(s, path.s_breaks[seg], path.s_breaks[seg + 1])
    _, dq, ddq, dddq = path.evaluate(s, segment=seg)
    vel = np.abs(axis_velocity(dq, v))
    acc = np.abs(axis_acceleration(dq, ddq, v, a))
    jer = np.abs(axis_jerk(dq, ddq, dddq, v, a, j))
    return vel, acc, jer, s, p.t[k] + tau


def _arc_curvature_bounds(ctx: _Ctx, k: np.ndarray) -> tuple[np.ndarray, ...]:
    """Bounds on the second time derivative of the axis velocity, acceleration and jerk
    inside intervals ``k`` on circles and helices, shape (len(k), n) each (mm/s^3,
    mm/s^4, mm/s^5).

    On a circle or helix of radius ``r`` and angular rate ``w`` (rad/mm) the in-plane
    part of the m-th path derivative of axis ``i`` has the amplitude ``rho_i r |w|^m``
    (``rho_i`` the axis' plane weight), and the helix adds the constant ``d_i`` to the
    first derivative only; on a clothoid the in-plane norms are bounded by
    :func:`reference.core.geometry.clothoid_derivative_norms` (an axis' share of a plane
    vector is at most ``rho_i`` times its norm). With ``V``, ``A``, ``J`` the largest ``|v|``, path
    acceleration ``|a|`` and path jerk ``|j|`` on the interval (``j`` is constant in an
    interval, so its time derivative is 0), differentiating the axis velocity
    ``q1 v``, acceleration ``q1 a + q2 v^2`` and jerk ``q1 j + 3 q2 v a + q3 v^3``
    (``qm`` the m-th path derivative of the axis) twice in time gives::

        vel''  = q3 v^3 + 3 q2 v a + q1 j
        acc''  = q4 v^4 + 6 q3 v^2 a + 3 q2 a^2 + 4 q2 v j
        jerk'' = q5 v^5 + 10 q4 v^3 a + 15 q3 v a^2 + 10 q3 v^2 j + 10 q2 a j

    and the bounds are these with every factor replaced by its bound.
    """
    path, p = ctx.path, ctx.prof
    seg = ctx.seg[k]
    h = ctx.h[k]
    V = _speed_peak(ctx, k)[0]
    A = np.maximum(np.abs(p.a[k]), np.abs(p.a[k] + p.j[k] * h))
    J = np.abs(p.j[k])
    r, w = path.radius[seg], np.abs(path.omega[seg])
    rho = np.sqrt(path.e1[seg] ** 2 + path.e2[seg] ** 2)           # (N, n)
    # norms of the in-plane parts of q', ..., q^(5): r |w|^m on circles
    norms = [r * w ** m for m in range(1, 6)]
    cl = np.flatnonzero(path.sharpness[seg])
    if cl.size:
        for m, val in enumerate(clothoid_derivative_norms(
                np.abs(path.sharpness[seg[cl]]), path.length[seg[cl]])):
            norms[m][cl] = val
    a1 = np.abs(path.d[seg]) + rho * norms[0][:, None]
    a2, a3, a4, a5 = (rho * nm[:, None] for nm in norms[1:])
    V, A, J = V[:, None], A[:, None], J[:, None]
    b_vel = a3 * V ** 3 + 3 * a2 * V * A + a1 * J
    b_acc = a4 * V ** 4 + 6 * a3 * V ** 2 * A + 3 * a2 * A ** 2 + 4 * a2 * V * J
    b_jerk = (a5 * V ** 5 + 10 * a4 * V ** 3 * A + 15 * a3 * V * A ** 2
              + 10 * a3 * V ** 2 * J + 10 * a2 * A * J)
    return b_vel, b_acc, b_jerk


def _check_arcs(ctx: _Ctx, k: np.ndarray, n_uni: np.ndarray,
                worst: dict[str, _Worst], frac0: np.ndarray | None = None,
                frac1: np.ndarray | None = None) -> None:
    """Dense samples on arcs/helices, then one parabolic refinement per interval.

    ``n_uni`` is the number of uniform samples that meets :data:`ARC_SAMPLE_STEP_RAD`
    (the fine step). On circles and helices the fine step is taken only where it can
    matter: the interval is first sampled at :data:`ARC_COARSE_FACTOR` times that step,
    and a coarse step of width ``D`` between samples ``a`` and ``b`` is sampled at the
    fine step only when, for some axis and quantity ``g``,
    ``max(g(a), g(b)) + B D^2 / 8`` exceeds the largest ``g`` sampled on the interval
    (``B`` bounds ``|g''|`` there, :func:`_arc_curvature_bounds`; a function with
    ``|g''| <= B`` exceeds the chord between two of its points by at most
    ``B D^2 / 8``). A step left coarse therefore holds no larger value than one already
    found, and each interval's maxima are those of the fine sampling or larger (all
    values exact): the documented deficit bound holds unchanged. Circles, helices and clothoids
    are pruned so; spirals are sampled at
    the fine step throughout.

    ``frac0, frac1`` (default 0 and 1) restrict each row to the time piece
    ``[frac0 h, frac1 h]`` of its interval (a long interval checked in pieces).
    """
    lim, path, axes = ctx.lim, ctx.path, ctx.path.axes
    h_full = ctx.h[k]
    ni = k.size
    t0 = np.zeros(ni) if frac0 is None else frac0 * h_full
    t1 = h_full if frac1 is None else frac1 * h_full
    h = t1 - t0
    circ = path.dradius[ctx.seg[k]] == 0
    n_c = np.where(circ, np.maximum(MIN_ARC_SAMPLES,
                                    -(-(n_uni - 1) // ARC_COARSE_FACTOR) + 1), n_uni)
    n_c = np.minimum(n_c, n_uni)
    # coarse samples (the fine ones on spirals), contiguous per interval
    first = np.concatenate(([0], np.cumsum(n_c)[:-1]))
    row_c = np.repeat(np.arange(ni), n_c)
    pos = np.arange(row_c.size) - first[row_c]
    dtau_c = h / (n_c - 1)
    tau_c = np.minimum(t0[row_c] + pos * dtau_c[row_c], t1[row_c])
    _, _, ts = _speed_peak(ctx, k)
    limits = (lim.v_max, lim.a_max, lim.j_max)
    names = ("velocity", "acceleration", "jerk")
    kin = _axis_kinematics(ctx, k[np.concatenate((row_c, np.arange(ni)))],
                           np.concatenate((tau_c, ts)))
    nc = row_c.size
    # coarse steps that may hide a larger value: sampled at the fine step
    need = np.zeros(nc, bool)               # the step from sample p to p + 1
    step = np.flatnonzero(np.diff(row_c) == 0)
    if circ.any() and step.size:
        bounds = _arc_curvature_bounds(ctx, k)
        rs = row_c[step]
        for val, b, lim_i in zip(kin[:3], bounds, limits):
            r = val / lim_i
            top = r.max(axis=1)
            thr = np.maximum(np.maximum.reduceat(top[:nc], first), top[nc:])
            ub = (np.maximum(r[step], r[step + 1])
                  + (b[rs] / lim_i) * (dtau_c[rs] ** 2 / 8.0)[:, None])
            need[step] |= circ[rs] & np.any(ub > thr[rs][:, None], axis=1)
    fine = np.flatnonzero(need)
    rf = row_c[fine]
    # as many parts as make each part no longer than the fine step
    parts = np.maximum(np.ceil(dtau_c[rf] * (n_uni[rf] - 1) / h[rf]
                               * (1.0 - 1e-12)).astype(np.int64), 1)
    cnt = parts - 1
    owner = np.repeat(np.arange(fine.size), cnt)
    m = np.arange(int(cnt.sum())) - np.repeat(np.cumsum(cnt) - cnt, cnt) + 1
    tau_f = tau_c[fine[owner]] + m * (dtau_c[rf[owner]] / parts[owner])
    row_f = rf[owner]
    kin_f = _axis_kinematics(ctx, k[row_f], tau_f)
    # every sample of each interval in time order, then the stationary points
    rows = np.concatenate((row_c, row_f))
    taus = np.concatenate((tau_c, tau_f))
    order = np.lexsort((taus, rows))
    nu = order.size
    rows, taus = rows[order], taus[order]
    counts = np.bincount(rows, minlength=ni)
    first_u = np.concatenate(([0], np.cumsum(counts)[:-1]))

    def merged(i: int) -> np.ndarray:
        return np.concatenate((np.concatenate((kin[i][:nc], kin_f[i]))[order], kin[i][nc:]))

    s_all, t_all = merged(3), merged(4)
    blk = path.block[ctx.seg[k[np.concatenate((rows, np.arange(ni)))]]]
    ref_tau = []
    for q, (name, lim_i) in enumerate(zip(names, limits)):
        val = merged(q)
        ratio = val / lim_i
        worst[name].update(ratio, val, lim_i, s_all, t_all, blk, axes)
        # refinement: worst sample of each interval, parabola through its neighbours
        r_u = ratio[:nu]
        flat = r_u.max(axis=1)
        col = r_u.argmax(axis=1)
        mx = np.maximum.reduceat(flat, first_u)
        hit = np.flatnonzero(flat == mx[rows])
        _, firsthit = np.unique(rows[hit], return_index=True)
        p = hit[firsthit]                                     # one row per interval
        c = np.clip(p, first_u + 1, first_u + counts - 2)     # centre with two neighbours
        cc = col[p]
        xm, x0, xp = taus[c - 1], taus[c], taus[c + 1]
        ym, y0, yp = r_u[c - 1, cc], r_u[c, cc], r_u[c + 1, cc]
        # vertex of the parabola through the three points (spacing may differ)
        dm, dp = x0 - xm, xp - x0
        den = dm * (y0 - yp) + dp * (y0 - ym)
        with np.errstate(divide="ignore", invalid="ignore"):
            off = np.where(den > 0, 0.5 * (dp * dp * (y0 - ym) - dm * dm * (y0 - yp)) / den,
                           0.0)
        ref_tau.append(np.clip(x0 + off, np.maximum(xm, t0), np.minimum(xp, t1)))
    riv = np.tile(np.arange(ni), len(names))
    rk = _axis_kinematics(ctx, k[riv], np.concatenate(ref_tau))
    rblk = path.block[ctx.seg[k[riv]]]
    for name, val, lim_i in zip(names, rk[:3], limits):
        worst[name].update(val / lim_i, val, lim_i, rk[3], rk[4], rblk, axes)


def _axis_acc_at_knots(ctx: _Ctx, kn: np.ndarray, side: str) -> np.ndarray:
    """Axis acceleration just before (``"left"``) or after (``"right"``) knots ``kn``.

    Outside the profile (before knot 0, after knot K) the motion is at rest: 0.
    """
    p, path = ctx.prof, ctx.path
    K = p.n_intervals
    iv = kn - 1 if side == "left" else kn
    valid = (iv >= 0) & (iv < K)
    ivc = np.clip(iv, 0, K - 1)
    a = p.a[ivc] + (p.j[ivc] * ctx.h[ivc] if side == "left" else 0.0)
    v = p.v[kn]
    seg = ctx.seg[ivc]
    s = np.clip(p.s[kn], path.s_breaks[seg], path.s_breaks[seg + 1])
    _, dq, ddq, _ = path.evaluate(s, segment=seg)
    acc = axis_acceleration(dq, ddq, v, a)
    return np.where(valid[:, None], acc, 0.0), ddq, valid, seg


def _check_steps(ctx: _Ctx, w: _Worst, steps: str) -> None:
    """Axis acceleration steps at knots (jerk; the rule in the module docstring).

    ``steps = "breaks"``: a step at a segment break or a path end counts as the jerk
    ``|delta A| / t_ipo``; at every other knot the acceleration is continuous, and the
    steps there, summed per segment and axis, count against
    ``ACCEL_CONTINUITY_TOL_REL * j_max * t_ipo``. ``steps = "spread"``: every knot's
    step counts as ``|delta A| / t_ipo`` (a recording sampled at the IPO cycle).
    """
    p, path, lim = ctx.prof, ctx.path, ctx.lim
    K = p.n_intervals
    knots = np.arange(K + 1)
    win = POS_TOL_MM * max(1.0, path.total_length)
    n = len(path.axes)
    inner_sum = np.zeros((path.n_segments, n))     # summed inner steps per segment, axis
    inner_max = np.zeros(path.n_segments)           # largest single inner step (to place)
    for lo, hi in _chunks(np.full(K + 1, 4)):
        kn = knots[lo:hi]
        acc_l, ddq_l, val_l, seg_l = _axis_acc_at_knots(ctx, kn, "left")
        acc_r, ddq_r, val_r, seg_r = _axis_acc_at_knots(ctx, kn, "right")
        step = np.abs(acc_r - acc_l)
        jump = curvature_jumps(ddq_l, ddq_r)
        curv = val_l & val_r & (seg_l != seg_r) & jump & (np.abs(p.v[kn]) > VEL_TOL_MM_S)
        jlim = step_jerk_limit(curv, lim.j_max, lim.path_trans_jerk)
        val = step / ctx.t_ipo
        # the block the motion is in just before the knot (the first block at the start)
        blk = path.block[np.where(val_l, seg_l, seg_r)]
        if steps == STEPS_SPREAD:
            w.update(val / jlim, val, jlim, p.s[kn], p.t[kn], blk, path.axes)
            continue
        s_k = p.s[kn]
        nb = np.clip(np.searchsorted(path.s_breaks, s_k), 1, path.n_segments)
        near = np.minimum(np.abs(s_k - path.s_breaks[nb - 1]),
                          np.abs(path.s_breaks[nb] - s_k)) <= win
        at_break = ~val_l | ~val_r | (seg_l != seg_r) | near
        if np.any(at_break):
            b = at_break
            w.update(val[b] / jlim[b], val[b], jlim[b], s_k[b], p.t[kn][b], blk[b],
                     path.axes)
        inner = ~at_break
        if np.any(inner):
            np.add.at(inner_sum, seg_l[inner], step[inner])
            np.maximum.at(inner_max, seg_l[inner], step[inner].max(axis=1))
    if steps == STEPS_SPREAD or not np.any(inner_sum):
        return
    # continuity inside segments: one row per segment (placed at its largest step)
    tol = ACCEL_CONTINUITY_TOL_REL * lim.j_max[None, :] * ctx.t_ipo
    ratio = inner_sum / tol
    segs = np.flatnonzero(inner_max > 0)
    where_s = np.empty(segs.size)
    where_t = np.empty(segs.size)
    for lo, hi in _chunks(np.full(K + 1, 4)):
        kn = knots[lo:hi]
        acc_l, _, val_l, seg_l = _axis_acc_at_knots(ctx, kn, "left")
        acc_r, _, val_r, seg_r = _axis_acc_at_knots(ctx, kn, "right")
        big = np.abs(acc_r - acc_l).max(axis=1)
        hit = val_l & val_r & (seg_l == seg_r) & (big == inner_max[seg_l]) & (big > 0)
        idx = np.searchsorted(segs, seg_l[hit])
        where_s[idx] = p.s[kn][hit]
        where_t[idx] = p.t[kn][hit]
    w.update(ratio[segs], inner_sum[segs] / ctx.t_ipo,
             np.broadcast_to(ACCEL_CONTINUITY_TOL_REL * lim.j_max, (segs.size, n)),
             where_s, where_t, path.block[segs], path.axes,
             detail=CONTINUITY_DETAIL)


def _check_breaks(ctx: _Ctx, worst: dict[str, _Worst]) -> None:
    """Velocity jumps at interior breaks and rest where the path stops."""
    p, path, lim = ctx.prof, ctx.path, ctx.lim
    K, m = p.n_intervals, path.n_segments
    sb = path.s_breaks
    # Speed at each break: after split_at every crossed interior break is a knot. A
    # profile that comes to rest within the position tolerance of a break (e.g. 1e-13 mm
    # after it, by round-off of its own integration) is at rest there, although it
    # crosses the exact break at sqrt(2 a 1e-13) ~ 1e-5 mm/s: so take the smallest |v|
    # of the knots within the profile's position tolerance of the break.
    win = POS_TOL_MM * max(1.0, path.total_length)
    # in chunks of breaks (bounded temporaries; each break's knots are its own)
    v_b = np.empty(m + 1)
    k_first = np.empty(m + 1, dtype=np.int64)
    for lo in range(0, m + 1, _WORK_CHUNK):
        c_sb = sb[lo:lo + _WORK_CHUNK]
        k_lo = np.clip(np.searchsorted(p.s, c_sb - win, side="left"), 0, K)
        k_hi = np.maximum(np.searchsorted(p.s, c_sb + win, side="right"), k_lo + 1)
        k_lo = np.minimum(k_lo, k_hi - 1)
        knots = concat_ranges(k_lo, k_hi)
        v_b[lo:lo + c_sb.size] = np.minimum.reduceat(
            np.abs(p.v[knots]), np.concatenate(([0], np.cumsum(k_hi - k_lo)[:-1])))
        k_first[lo:lo + c_sb.size] = k_lo
    blk_b = path.block[np.clip(np.arange(m + 1) - 1, 0, m - 1)]   # block ending there
    stop = np.flatnonzero(path.stop)
    if stop.size:
        vs = v_b[stop]
        worst["stop"].update(vs / VEL_TOL_MM_S, vs, VEL_TOL_MM_S, sb[stop], p.t[k_first[stop]],
                             blk_b[stop])
    if m < 2:
        return
    # the tangents every side uses (Path.junction_tangents), so the planner's and the
    # oracle's corner caps are judged on the very numbers they were computed from
    for lo, hi in _chunks(np.full(m - 1, 16)):
        b = np.arange(lo, hi) + 1
        t_in, t_out = path.junction_tangents(lo, hi)
        dv = axis_velocity_jumps(t_in, t_out, v_b[b])
        jump = np.broadcast_to(lim.jump, dv.shape)
        worst["velocity_jump"].update(jump_ratio(dv, jump), dv, jump, sb[b], p.t[k_first[b]],
                                      blk_b[b], path.axes)


def _check_frequency(ctx: _Ctx, w: _Worst) -> None:
    """Shortest acceleration phase against 1/f of the axes moving in it (the rule of
    :mod:`reference.core.phases`)."""
    p, path = ctx.prof, ctx.path
    ph = acceleration_phases(p)
    if ph.n == 0:
        return
    f_min, ax = phase_frequencies(path, ctx.lim, ph, ctx.seg)
    dur = ph.effective_duration
    ok = np.isfinite(f_min) & (dur > 0)
    if not np.any(ok):
        return
    need = min_phase_duration(f_min)
    ratio = np.where(ok, need / np.where(dur > 0, dur, 1.0), 0.0)
    # per block: every block a phase touches (in chunks of phases)
    if w.per_block.size:
        sel = np.flatnonzero(ok)
        for r0 in range(0, sel.size, _WORK_CHUNK):
            q = sel[r0:r0 + _WORK_CHUNK]
            n_r = ph.last[q] - ph.first[q] + 1
            idx = concat_ranges(ph.first[q], ph.last[q] + 1)
            np.maximum.at(w.per_block, path.block[ctx.seg[idx]], np.repeat(ratio[q], n_r))
    i = int(np.argmax(ratio))
    k = int(ph.first[i])
    s_at, _, _ = _poly(p.s[k], p.v[k], p.a[k], p.j[k], ph.start_tau[i])
    w.found = True
    w.ratio, w.value, w.limit = float(ratio[i]), float(1.0 / dur[i]), float(f_min[i])
    w.s, w.t = float(s_at), float(ph.start_t[i])
    w.block = int(path.block[ctx.seg[k]])
    w.axis = path.axes[int(ax[i])]




# ===================================================================== time scaling
#: How each ratio falls when time is stretched by lam: ratio / lam**power.
_POWER = {"velocity": 1, "feed": 1, "velocity_jump": 1, "stop": 1, "frequency": 1,
          "acceleration": 2, "jerk_interval": 3, "jerk_step": 2}


def time_scale_factor(report: ConstraintReport, constraints: Iterable[str]) -> float:
    """Smallest factor ``lam >= 1`` by which stretching time satisfies ``constraints``.

    Stretching time by ``lam`` (:func:`scale_time`) divides velocities by ``lam``,
    accelerations by ``lam^2`` and jerks by ``lam^3``. So velocity, feed and
    velocity-jump ratios scale like ``1/lam`` (``v`` at a break shrinks, the allowance
    does not), acceleration like ``1/lam^2``, jerk inside intervals like ``1/lam^3``,
    acceleration *steps* spread over the fixed IPO cycle like ``1/lam^2``, and
    frequency ratios like ``1/lam`` (every process lasts ``lam`` times longer). The
    stop ratio ``|v| / VEL_TOL_MM_S`` also falls like ``1/lam``; a real stop violation
    therefore gives an absurdly large but correct factor. Stops met stay met.

    Parameters
    ----------
    report : ConstraintReport
        The checker's report on the unscaled profile.
    constraints : iterable of str
        The constraints to satisfy, e.g. ``BOUND_SETS["jerk"]``.

    Returns
    -------
    float
        ``max(1, r_v, r_feed, r_jump, r_stop, r_freq, sqrt(r_a), cbrt(r_j,interval),
        sqrt(r_j,step))``; ``inf`` when a ratio is infinite (a velocity jump with zero
        allowance cannot be repaired by slowing down).
    """
    lam = 1.0
    for name in _names(constraints):
        if name == "jerk":
            parts = report.components
            if "jerk_interval" in parts and "jerk_step" in parts:
                items = [("jerk_interval", parts["jerk_interval"].ratio),
                         ("jerk_step", parts["jerk_step"].ratio)]
            else:       # no split known: 1/lam^2 is the safe (slower) assumption
                items = [("jerk_step", report.worst("jerk").ratio)]
        else:
            items = [(name, report.worst(name).ratio)]
        for key, r in items:
            if r > 1.0:
                lam = max(lam, r ** (1.0 / _POWER[key]))
    return float(lam)


def time_scale_factors_by_block(report: ConstraintReport,
                                constraints: Iterable[str]) -> np.ndarray:
    """Per program block, the factor :func:`time_scale_factor` would need there.

    The same powers as :func:`time_scale_factor`, applied to ``report.block_ratios``; the
    jerk ratio is not split by block into interval and step parts, so the safe (slower)
    ``1/lam^2`` is assumed for it. Stretching only a part of a motion is valid where that
    part starts and ends at rest (a stop), which the caller must ensure.

    Returns
    -------
    numpy.ndarray, shape (n_blocks,)
        ``>= 1``; ``inf`` where a ratio is infinite.
    """
    out = None
    for name in _names(constraints):
        r = np.asarray(report.block_ratios.get(name, np.zeros(0)), dtype=np.float64)
        if r.size == 0:
            continue
        power = 2 if name == "jerk" else _POWER[name]
        lam = np.where(r > 1.0, r ** (1.0 / power), 1.0)
        out = lam if out is None else np.maximum(out, lam)
    return np.ones(0) if out is None else out


def scale_time(profile: Profile, lam: float) -> Profile:
    """The same path motion, ``lam`` times slower.

    Parameters
    ----------
    profile : Profile
        The motion.
    lam : float
        Time-stretch factor (finite, > 0).

    Returns
    -------
    Profile
        ``t * lam``, ``v / lam``, ``a / lam^2``, ``j / lam^3``; positions, blocks and
        rest (``v = 0``) unchanged.

    Raises
    ------
    ProfileError
        ``lam`` is not a finite number > 0.
    """
    lam = float(lam)
    if not (np.isfinite(lam) and lam > 0):
        raise ProfileError(f"time-scale factor must be finite and > 0, got {lam}")
    return Profile(t=profile.t * lam, s=profile.s, v=profile.v / lam,
                   a=profile.a / lam ** 2, j=profile.j / lam ** 3, block=profile.block)
