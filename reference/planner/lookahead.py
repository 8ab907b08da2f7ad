"""Stage: LookAhead, the path velocity preview over a receding horizon (model note 7).

Three steps, all O(n) in the number of segments:

1. **Horizon** (:func:`horizon_caps`). The control prepares ``N = lookahead_blocks``
   blocks ahead and assumes ``v = 0`` at the end of the last one, because the next block
   could be tiny or an exact stop [S6]. It re-plans whenever a block arrives and executes
   only the current block. While segment ``k-1`` runs, the horizon holds segments
   ``k .. k+N-1``, so its exit speed (the speed at break ``k``) can be at most the speed
   from which the motion still stops at break ``k+N``. In a receding-horizon plan the
   horizon end acts on the executed motion *only* through this exit cap (any constraint
   beyond the horizon is weaker than the zero at its end), so instead of re-running a
   backward pass per block the stage computes one cap per break:

   - BRISK: ``z_k^2 = 2 sum_{i=k}^{k+N-1} A_i L_i`` (exact, a cumulative sum); a DRIVE
     segment with a knee counts with its acceleration above the knee all the way down
     (a cumulative sum still; the cap is lower than the knee-shaped braking would give:
     safe, never faster than the characteristic allows);
   - SOFT: one jerk-limited braking ramp from ``z_k`` to rest over the horizon distance
     with the weakest ``A``, ``J`` of the horizon (a sliding-window minimum).

   Breaks whose horizon reaches the path end get no cap (the end is a real stop).
   With short blocks and a small ``N`` this cap binds at every break: the speed rises in
   each block and falls again (the documented saw-tooth); a long horizon removes it.

2. **Planning units** (:func:`planning_units`). BRISK plans each segment on its own (its
   trapezoids are optimal between the junction speeds). SOFT plans with zero acceleration
   at the ends of a unit, so consecutive SOFT segments are merged into one unit, through
   which the jerk-limited ramps continue, when the break between them does not bind (its
   own limit is at least the unit's cap), the caps stay within ``soft_merge_cap_ratio``
   and the two segments' accelerations and jerks within ``soft_merge_accel_ratio`` of
   each other; the unit runs at the smallest cap of its segments with the smallest
   acceleration and jerk (a safe model). The last condition keeps a segment whose
   dynamics are far lower (a short curved segment at its speed cap: a clothoid pair
   of a rounding, whose jerk budget the centripetal part uses up) from imposing them on
   the lines beside it: those ramp with their own limits, and the curved segment is
   passed at about the speed it is entered with. Once planned, merged breaks that a
   unit with mixed dynamics passes at its cap (cruising: no ramp crosses them) are cut
   where a part would move faster on its own, and the units planned again
   (:func:`cruise_splits`; only the changed units' profiles are computed again).

3. **Passes** (:func:`lookahead_passes`): a backward pass from the end and a forward pass
   from the start over the units, each step the closed-form reachable speed of
   :func:`reference.planner.profiles.ramp_reach` (dispatch on the unit's mode: BRISK,
   SOFT or DRIVE with a knee). Every pair of consecutive node speeds is then joinable by
   one unit profile.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, replace

import numpy as np
from scipy.ndimage import minimum_filter1d

from ..core.geometry import Path
from . import causes as C
from .corners import JunctionLimits
from .limit_curves import SegmentLimits
from .profiles import ramp_reach
from .stops import SegmentModes

#: A part of a unit moves faster on its own (:func:`cruise_splits`) only where its cap,
#: acceleration or jerk exceeds the unit's by more than this, relative: the two pieces
#: of a clothoid pair differ by round-off (1e-13), and a gain below 1e-9 is not worth
#: planning the program again.
SPLIT_GAIN_REL = 1e-9

#: Units (segments, for the merges) from which :func:`lookahead_passes` and
#: :func:`_merge_flags` run the compiled loops of :mod:`reference.planner.lookahead_kernel`
#: (the same speeds and merges, bitwise): loading numba and the cached kernel costs about
#: 0.5 s once per process, what the Python passes cost on some 10^5 units; once it is
#: loaded (a large program earlier in this process, or a caller that imports it, as the
#: benchmarks do) every size uses it.
PASSES_COMPILED_MIN_UNITS = 100_000
_KERNEL = __name__.rsplit(".", 1)[0] + ".lookahead_kernel"


def _compiled(size: int, compiled: bool | None) -> bool:
    """Whether to run the compiled loops: ``compiled`` if given, else from
    :data:`PASSES_COMPILED_MIN_UNITS` on or once the kernel is loaded."""
    if compiled is not None:
        return compiled
    return size >= PASSES_COMPILED_MIN_UNITS or _KERNEL in sys.modules


# ----------------------------------------------------------------- horizon
def _forward_window_min(x: np.ndarray, n: int) -> np.ndarray:
    """``out[k] = min(x[k : k + n])`` (shorter windows at the end)."""
    if x.size == 0:
        return x.copy()
    if n >= x.size:
        return np.minimum.accumulate(x[::-1])[::-1]
    return minimum_filter1d(x, size=n, mode="nearest", origin=-(n // 2))


def horizon_caps(path: Path, seg: SegmentLimits, modes: SegmentModes, n_blocks: int
                 ) -> np.ndarray:
    """Exit-speed cap of every break from the LookAhead horizon (``inf`` where none).

    Parameters
    ----------
    path : Path
    seg : SegmentLimits
        Tangential acceleration and jerk per segment.
    modes : SegmentModes
    n_blocks : int
        LookAhead horizon, in prepared (moving) blocks after the current one (>= 1).

    Returns
    -------
    numpy.ndarray, shape (m + 1,)
        mm/s.
    """
    m = path.n_segments
    z = np.full(m + 1, np.inf)
    n = max(int(n_blocks), 1)
    k = np.arange(1, m)
    e = k + n
    inside = e < m
    if not inside.any():
        return z
    k, e = k[inside], e[inside]
    acc = seg.accel * seg.knee_ratio         # DRIVE: the reduced acceleration (safe)
    cal = np.concatenate(([0.0], np.cumsum(acc * path.length)))
    z_brisk = np.sqrt(2.0 * np.maximum(cal[e] - cal[k], 0.0))
    a_min = _forward_window_min(acc, n)[k]
    j_min = _forward_window_min(seg.jerk, n)[k]
    dist = path.s_breaks[e] - path.s_breaks[k]
    z_soft = ramp_reach(np.zeros(k.size), dist, a_min, j_min)
    soft = _forward_window_min(np.where(modes.jerk_limited, 0.0, 1.0), n)[k] == 0.0
    z[k] = np.where(soft, z_soft, z_brisk)
    return z


# ----------------------------------------------------------------- planning units
@dataclass(frozen=True, slots=True, eq=False)
class Units:
    """Planning units: runs of segments planned as one profile (arrays over units).

    Attributes
    ----------
    first_segment, n_segments : numpy.ndarray of int, shape (u,)
        Segment range of each unit.
    node_break : numpy.ndarray of int, shape (u + 1,)
        Break index of each unit boundary (node).
    s_start, length : numpy.ndarray, shape (u,)
        Start position and length, mm.
    cap : numpy.ndarray, shape (u,)
        Speed cap, mm/s.
    cap_cause : numpy.ndarray of int, shape (u,)
        Its cause.
    acc_up, jerk_up, acc_dn, jerk_dn : numpy.ndarray, shape (u,)
        Limits of rising and falling ramps (jerk ``inf`` for BRISK).
    frequency : numpy.ndarray, shape (u,)
        Smallest LOOKAH_FREQUENCY of the axes moving in the unit, Hz.
    jerk_limited : numpy.ndarray of bool, shape (u,)
        SOFT units.
    node_cap : numpy.ndarray, shape (u + 1,)
        Speed limit at each node (junction rules, horizon, neighbouring unit caps).
    node_cause : numpy.ndarray of int, shape (u + 1,)
        Its cause.
    adapted_up, adapted_dn : numpy.ndarray of bool, shape (u,)
        Ramps whose dynamics the dynamic adaptation lowered.
    knee : numpy.ndarray, shape (u,)
        DRIVE: path speed above which the acceleration is reduced, mm/s (``inf``: none).
    knee_ratio : numpy.ndarray, shape (u,)
        DRIVE: share of ``acc_up``/``acc_dn`` above the knee (1 without a knee).
    """

    first_segment: np.ndarray
    n_segments: np.ndarray
    node_break: np.ndarray
    s_start: np.ndarray
    length: np.ndarray
    cap: np.ndarray
    cap_cause: np.ndarray
    acc_up: np.ndarray
    jerk_up: np.ndarray
    acc_dn: np.ndarray
    jerk_dn: np.ndarray
    frequency: np.ndarray
    jerk_limited: np.ndarray
    node_cap: np.ndarray
    node_cause: np.ndarray
    adapted_up: np.ndarray
    adapted_dn: np.ndarray
    knee: np.ndarray
    knee_ratio: np.ndarray

    @property
    def n_units(self) -> int:
        """Number of units."""
        return int(self.length.size)

    def with_caps(self, cap: np.ndarray, cap_cause: np.ndarray) -> "Units":
        """Same units with new caps; node caps are re-limited by the neighbouring caps."""
        node_cap, node_cause = _limit_nodes(self.node_cap, self.node_cause, cap, cap_cause)
        return replace(self, cap=cap, cap_cause=cap_cause, node_cap=node_cap,
                       node_cause=node_cause)


def _limit_nodes(node_cap, node_cause, cap, cap_cause):
    """Node caps limited by the caps of the units on both sides."""
    left = np.concatenate(([np.inf], cap))
    right = np.concatenate((cap, [np.inf]))
    lc = np.concatenate(([C.FEED], cap_cause))
    rc = np.concatenate((cap_cause, [C.FEED]))
    nb = np.minimum(left, right)
    nbc = np.where(left <= right, lc, rc)
    use = nb < node_cap
    return np.where(use, nb, node_cap), np.where(use, nbc, node_cause)


def _merge_flags(path: Path, seg: SegmentLimits, modes: SegmentModes,
                 own_cap: np.ndarray, through: np.ndarray, ratio: float,
                 accel_ratio: float, split: np.ndarray | None = None,
                 compiled: bool | None = None) -> np.ndarray:
    """True at interior breaks where two SOFT segments become one unit (greedy runs):
    both SOFT, no stop, not ``split``, the break lets ``accel_ratio`` of the smaller
    acceleration through, the two segments' accelerations and jerks within
    ``accel_ratio`` of each other, and the effective caps of the run within ``ratio``.
    The runs are walked in Python or, with ``compiled`` (default: :func:`_compiled`), by
    :func:`reference.planner.lookahead_kernel.greedy_merges` (the same comparisons)."""
    m = path.n_segments
    merge = np.zeros(m + 1, dtype=bool)
    if m < 2:
        return merge
    jl = modes.jerk_limited
    cand = np.zeros(m + 1, dtype=bool)
    a0, a1, j0, j1 = seg.accel[:-1], seg.accel[1:], seg.jerk[:-1], seg.jerk[1:]
    cand[1:m] = (jl[:-1] & jl[1:] & ~modes.stop[1:m]
                 & (through[1:m] >= accel_ratio * np.minimum(a0, a1))
                 & (np.minimum(a0, a1) >= accel_ratio * np.maximum(a0, a1))
                 & (np.minimum(j0, j1) >= accel_ratio * np.maximum(j0, j1)))
    if split is not None:
        cand &= ~split
    idx = np.flatnonzero(cand)
    if idx.size == 0:
        return merge
    # effective cap: the speed a segment could reach on its own between neighbours that
    # run at their caps (rise over half of it, fall over the other half); merging gives
    # away at most the difference between effective caps, so short blocks merge freely
    c = seg.cap
    low = np.minimum(c, np.minimum(np.concatenate(([np.inf], c[:-1])),
                                   np.concatenate((c[1:], [np.inf]))))
    reach = ramp_reach(low, 0.5 * path.length, seg.accel, seg.jerk)
    if _compiled(m, compiled):
        from .lookahead_kernel import greedy_merges
        eff = np.minimum(c, reach)
        merge[idx[greedy_merges(idx.astype(np.int64), np.ascontiguousarray(c, np.float64),
                                eff, np.ascontiguousarray(own_cap, np.float64),
                                float(ratio))]] = True
        return merge
    eff = np.minimum(c, reach).tolist()
    cap = c.tolist()
    own = own_cap.tolist()
    lo = elo = ehi = 0.0
    prev = -2
    merged = []
    # ``b if b < a else a`` is ``min(a, b)`` and ``b if b > a else a`` is ``max(a, b)``
    # (the same value, NaN included), without a builtin call per candidate
    for k in idx.tolist():
        if k != prev + 1:
            lo, elo, ehi = cap[k - 1], eff[k - 1], eff[k - 1]
        c_k, e_k = cap[k], eff[k]
        new_lo = c_k if c_k < lo else lo
        new_elo = e_k if e_k < elo else elo
        new_ehi = e_k if e_k > ehi else ehi
        if own[k] >= new_lo and new_elo >= ratio * new_ehi:
            merged.append(k)
            lo, elo, ehi = new_lo, new_elo, new_ehi
        else:
            lo, elo, ehi = c_k, e_k, e_k
        prev = k
    merge[merged] = True
    return merge


def planning_units(path: Path, seg: SegmentLimits, junc: JunctionLimits,
                   modes: SegmentModes, horizon: np.ndarray, merge_ratio: float,
                   merge_accel_ratio: float, split: np.ndarray | None = None) -> Units:
    """Group segments into planning units and set their node limits.

    Parameters
    ----------
    path : Path
    seg : SegmentLimits
    junc : JunctionLimits
    modes : SegmentModes
    horizon : numpy.ndarray, shape (m + 1,)
        Horizon caps (:func:`horizon_caps`).
    merge_ratio : float
        ``soft_merge_cap_ratio``.
    merge_accel_ratio : float
        ``soft_merge_accel_ratio``.
    split : numpy.ndarray of bool, shape (m + 1,), optional
        Breaks never merged (:func:`cruise_splits`).

    Returns
    -------
    Units
    """
    m = path.n_segments
    # a break's own limit (without the neighbouring caps): rules other than "caps"
    own = np.minimum(np.minimum(junc.g64, junc.curvature), horizon)
    own = np.where(modes.stop, 0.0, own)
    merge = _merge_flags(path, seg, modes, own, junc.through_accel, merge_ratio,
                         merge_accel_ratio, split)
    nodes = np.flatnonzero(~merge)          # includes 0 and m
    first = nodes[:-1]
    count = np.diff(nodes)
    cap = np.minimum.reduceat(seg.cap, first)
    unit_of = np.repeat(np.arange(first.size), count)
    is_min = seg.cap == cap[unit_of]
    pos = np.where(is_min, np.arange(m), m)
    arg = np.minimum.reduceat(pos, first)
    cap_cause = seg.cap_cause[arg]
    acc = np.minimum.reduceat(seg.accel, first)
    # merged breaks: the acceleration that may cross them
    thru = np.where(merge, junc.through_accel, np.inf)[:m] if m else np.zeros(0)
    if m:
        acc = np.minimum(acc, np.minimum.reduceat(thru, first))
    jerk = np.minimum.reduceat(seg.jerk, first)
    freq = np.minimum.reduceat(seg.frequency, first)
    # DRIVE knees: DRIVE units are single segments (only SOFT segments merge)
    knee = np.minimum.reduceat(seg.knee, first) if m else np.zeros(0)
    knee_ratio = np.minimum.reduceat(seg.knee_ratio, first) if m else np.zeros(0)
    node_cap = junc.cap[nodes]
    node_cause = junc.cause[nodes]
    hz = horizon[nodes]
    use_h = hz < node_cap
    node_cap = np.where(use_h, hz, node_cap)
    node_cause = np.where(use_h, C.HORIZON, node_cause)
    node_cap, node_cause = _limit_nodes(node_cap, node_cause, cap, cap_cause)
    z = np.zeros(first.size, dtype=bool)
    return Units(first_segment=first, n_segments=count, node_break=nodes,
                 s_start=path.s_breaks[first], length=path.s_breaks[nodes[1:]] -
                 path.s_breaks[first], cap=cap, cap_cause=cap_cause, acc_up=acc,
                 jerk_up=jerk, acc_dn=acc.copy(), jerk_dn=jerk.copy(), frequency=freq,
                 jerk_limited=np.isfinite(jerk), node_cap=node_cap, node_cause=node_cause,
                 adapted_up=z, adapted_dn=z.copy(), knee=knee, knee_ratio=knee_ratio)


# ----------------------------------------------------------------- passes
def _reach_brisk(v: float, dist: float, acc: float, jerk: float, knee: float,
                 ratio: float) -> float:
    return math.sqrt(v * v + 2.0 * acc * dist)


def _reach_drive(v: float, dist: float, acc: float, jerk: float, knee: float,
                 ratio: float) -> float:
    """BRISK with ``acc`` up to ``knee`` and ``ratio * acc`` above (scalar
    :func:`reference.planner.profiles.knee_reach`)."""
    e_k = knee * knee / (2.0 * acc)
    x = (v * v + max(v * v - knee * knee, 0.0) * (1.0 / ratio - 1.0)) / (2.0 * acc) + dist
    if x <= e_k:
        return math.sqrt(2.0 * acc * x)
    return math.sqrt(knee * knee + 2.0 * ratio * acc * (x - e_k))


def _reach_soft(v: float, dist: float, acc: float, jerk: float, knee: float,
                ratio: float) -> float:
    thr = acc * acc / jerk
    # jerk-limited: x^3 + p x + q = 0, dv = x^2
    p = 2.0 * v
    q = -dist * math.sqrt(jerk)
    q2 = 0.25 * q * q
    p3 = p * p * p / 27.0
    if q2 >= p3:
        u = (-0.5 * q + math.sqrt(q2 + p3)) ** (1.0 / 3.0)
        x = u - p / (3.0 * u) if u > 0 else 0.0
    else:
        x = 2.0 * math.sqrt(p / 3.0) * math.sinh(math.asinh(math.sqrt(q2 / p3)) / 3.0)
    df = 3.0 * x * x + p
    if df > 0:
        x -= (x * x * x + p * x + q) / df
    dv = x * x
    if dv <= thr:
        return v + max(dv, 0.0)
    b = 2.0 * v + thr
    c = 2.0 * v * thr - 2.0 * acc * dist
    dv = -2.0 * c / (b + math.sqrt(max(b * b - 4.0 * c, 0.0)))
    return v + max(dv, 0.0)


#: Reachable speed over a distance, by mode (index: 0 BRISK, 1 SOFT, 2 DRIVE with a knee).
_REACH = (_reach_brisk, _reach_soft, _reach_drive)


@dataclass(frozen=True, slots=True, eq=False)
class NodeSpeeds:
    """Speeds at the unit nodes after the LookAhead passes.

    Attributes
    ----------
    v : numpy.ndarray, shape (u + 1,)
        Node speeds, mm/s.
    backward : numpy.ndarray, shape (u + 1,)
        Result of the backward pass alone (largest speed that can still brake), mm/s.
    origin_cause : numpy.ndarray of int, shape (u + 1,)
        Cause of the limit the backward pass propagated to each node.
    accel_limited : numpy.ndarray of bool, shape (u + 1,)
        Nodes below their backward speed because the forward ramp could not go faster.
    """

    v: np.ndarray
    backward: np.ndarray
    origin_cause: np.ndarray
    accel_limited: np.ndarray


def _fits(v_lo: float, v_hi: float, dist: float, acc: float, jerk: float) -> bool:
    """Cheap sufficient test: a ramp between the speeds fits into ``dist``.

    Uses ``ramp_distance <= (v_hi^2 - v_lo^2)/(2A) + (v_hi + v_lo) A/(2J)`` (the
    jerk-limited ramp time ``2 sqrt(dv/J)`` never exceeds ``dv/A + A/J``).
    """
    return (v_hi * v_hi - v_lo * v_lo) / (2.0 * acc) + (v_hi + v_lo) * acc / (2.0 * jerk) \
        <= dist


def _keeps_own(v_own: np.ndarray, v_from: np.ndarray, dist: np.ndarray, acc_fit: np.ndarray,
               jerk: np.ndarray, acc: np.ndarray, brisk: np.ndarray) -> np.ndarray:
    """True where a step of :func:`lookahead_passes` from ``v_from`` keeps ``v_own``
    without computing a reachable speed one by one: the scalar tests of the pass
    (``v_own <= v_from``, :func:`_fits`, and for BRISK units :func:`_reach_brisk`) with
    the same operations, element by element, so the answers are bitwise theirs. False
    does not mean the step binds: the pass then takes the step itself.
    """
    with np.errstate(invalid="ignore", over="ignore"):
        keeps = ((v_own <= v_from)
                 | ((v_own * v_own - v_from * v_from) / (2.0 * acc_fit)
                    + (v_own + v_from) * acc_fit / (2.0 * jerk) <= dist))
        keeps |= brisk & (v_own <= np.sqrt(v_from * v_from + 2.0 * acc * dist))
    return keeps


def cruise_splits(path: Path, seg: SegmentLimits, units: Units, v_peak: np.ndarray,
                  dist_rise: np.ndarray, dist_cruise: np.ndarray, dist_fall: np.ndarray
                  ) -> np.ndarray:
    """Merged breaks to plan apart: True there, shape (m + 1,).

    A merge lets a ramp continue through a break, and the unit then runs with the
    smallest cap, acceleration and jerk of its segments over its whole length and in the
    ramps from and to its nodes, so a segment with lower dynamics slows those beside it
    (three S-bends: the S pieces' jerk, 0.5-0.7 of the arcs', ramped the arcs from and
    to rest and made the G645 program slower than under G64). Where the planned motion
    cruises at the unit's cap no ramp crosses a break: cut there, the motion planned
    before stays feasible (each part has the same or a higher cap, acceleration and
    jerk; the break's own limit is at least the cap, as the merge required, and the
    motion crosses it at zero acceleration), so the passes find node speeds at least as
    high and each part ramps with its own dynamics. A unit is cut only where one of the
    parts would move faster on its own: a higher cap, or higher dynamics in the part
    that holds the unit's rise (its first) or fall (its last), by more than
    :data:`SPLIT_GAIN_REL`; elsewhere the same motion would be planned again.

    Parameters
    ----------
    path : Path
    seg : SegmentLimits
    units : Units
    v_peak, dist_rise, dist_cruise, dist_fall : numpy.ndarray, shape (u,)
        Of the units' profiles (:class:`reference.planner.profiles.UnitProfiles`): peak
        speed (mm/s), rise, cruise and fall distances (mm).

    Returns
    -------
    numpy.ndarray of bool, shape (m + 1,)
    """
    m = path.n_segments
    split = np.zeros(m + 1, dtype=bool)
    multi = np.flatnonzero((units.n_segments > 1) & (dist_cruise > 0)
                           & (v_peak >= units.cap))
    if multi.size == 0:
        return split
    unit_of = np.repeat(np.arange(units.n_units), units.n_segments)
    # segments whose own dynamics the unit lowers
    g = 1.0 + SPLIT_GAIN_REL
    lowered = ((seg.cap > g * units.cap[unit_of]) | (seg.accel > g * units.acc_up[unit_of])
               | (seg.accel > g * units.acc_dn[unit_of])
               | (seg.jerk > g * units.jerk_up[unit_of])
               | (seg.jerk > g * units.jerk_dn[unit_of]))
    mixed = np.zeros(units.n_units, dtype=bool)
    np.logical_or.at(mixed, unit_of, lowered)
    multi = multi[mixed[multi]]
    if multi.size == 0:
        return split
    lo = units.s_start[multi] + dist_rise[multi]
    hi = lo + dist_cruise[multi]
    # the interior breaks of those units inside their cruise
    first, count = units.first_segment[multi], units.n_segments[multi]
    owner = np.repeat(np.arange(multi.size), count - 1)
    brk = (np.arange(owner.size) - np.repeat(np.cumsum(count - 1) - (count - 1), count - 1)
           + first[owner] + 1)
    s_brk = path.s_breaks[brk]
    inside = (s_brk > lo[owner]) & (s_brk < hi[owner])
    cut, cut_owner = brk[inside], owner[inside]
    # the parts the cuts leave, and whether one of them would move faster on its own: a
    # higher cap, or higher dynamics in the part that holds the unit's rise (its first)
    # or fall (its last); elsewhere the motion stays the cruise and a new plan of the
    # program would give the same (a cost, no gain)
    starts = np.concatenate((first, cut))
    part_owner = np.concatenate((np.arange(multi.size), cut_owner))
    order = np.argsort(starts, kind="stable")
    starts, part_owner = starts[order], part_owner[order]
    ends = np.append(starts[1:], m)
    ends = np.where(np.append(part_owner[1:], -1) == part_owner, ends,
                    (first + count)[part_owner])
    # the smallest over [start, end) of each part: reduceat over (start, end) pairs,
    # every second result (an end may be m: one padding element)
    pairs = np.stack((starts, ends), axis=1).ravel()

    def part_min(x):
        return np.minimum.reduceat(np.append(x, np.inf), pairs)[::2]

    cap_p, acc_p, jerk_p = part_min(seg.cap), part_min(seg.accel), part_min(seg.jerk)
    u = multi[part_owner]
    at_first = starts == units.first_segment[u]
    at_last = ends == units.first_segment[u] + units.n_segments[u]
    faster = ((cap_p > g * units.cap[u])
              | (at_first & (dist_rise[u] > 0)
                 & ((acc_p > g * units.acc_up[u]) | (jerk_p > g * units.jerk_up[u])))
              | (at_last & (dist_fall[u] > 0)
                 & ((acc_p > g * units.acc_dn[u]) | (jerk_p > g * units.jerk_dn[u]))))
    gains = np.zeros(multi.size, dtype=bool)
    np.logical_or.at(gains, part_owner, faster)
    split[cut[gains[cut_owner]]] = True
    return split


def lookahead_passes(units: Units, compiled: bool | None = None) -> NodeSpeeds:
    """Backward and forward passes over the units (closed-form steps).

    Each step first tries the cheap sufficient test :func:`_fits` (most nodes are bound
    by their own limit; a DRIVE unit takes its reduced acceleration there, which keeps
    the test sufficient) and computes the exact reachable speed only when it fails.

    Most nodes keep their own limit: where the neighbour a step comes from keeps its
    own, that step's outcome is decided for all units at once (:func:`_keeps_own`).
    The steps run one by one only along the chains that start where that fails (a
    braking or an acceleration that binds, or a SOFT or DRIVE step the cheap test does
    not settle) and end at the first node that keeps its limit. The speeds are those of
    taking every step in order: each node is either decided from its neighbour's own
    limit with the same operations, or stepped from its neighbour's final speed.

    With ``compiled`` (default: :func:`_compiled`) the same steps run as the compiled
    loops of :func:`reference.planner.lookahead_kernel.passes`, every node in order
    (bitwise the same speeds).

    Parameters
    ----------
    units : Units
    compiled : bool, optional
        Force (True) or avoid (False) the compiled loops.

    Returns
    -------
    NodeSpeeds
    """
    n = units.n_units
    cap = np.array(units.node_cap, dtype=np.float64)
    L = units.length
    drive = np.isfinite(units.knee)
    jl = np.where(drive, 2, units.jerk_limited.astype(np.int64))
    ad, jd, au, ju = units.acc_dn, units.jerk_dn, units.acc_up, units.jerk_up
    kn, kr = units.knee, units.knee_ratio
    # the cheap test with the acceleration above the knee (the smallest of a unit)
    r_fit = np.where(drive, units.knee_ratio, 1.0)
    ad_fit, au_fit = ad * r_fit, au * r_fit
    if _compiled(n, compiled):
        from .lookahead_kernel import passes
        f64 = np.float64
        w, b, origin, acc_lim = passes(
            cap, np.ascontiguousarray(L, f64), jl.astype(np.int64),
            *(np.ascontiguousarray(x, f64) for x in (ad, jd, au, ju, kn, kr, ad_fit,
                                                     au_fit)),
            np.array(units.node_cause, dtype=np.int64))
        return NodeSpeeds(v=w, backward=b, origin_cause=origin, accel_limited=acc_lim)
    brisk = ~units.jerk_limited & ~drive
    reach = _REACH
    fits = _fits
    # The chains touch few nodes: their values are read one by one as Python floats
    # (``item``), which is cheaper than converting every array to a list.
    # backward: b[k] from b[k + 1]; a chain walks on while its nodes fall below their
    # caps, so a node it does not reach has a neighbour at its cap (decided above)
    start = ~_keeps_own(cap[:-1], cap[1:], L, ad_fit, jd, ad, brisk)
    b = cap.copy()
    origin = np.array(units.node_cause, dtype=np.int64)
    low = n                             # nodes >= low are final
    for s0 in np.flatnonzero(start)[::-1].tolist():
        if s0 >= low:
            continue                    # inside the chain walked last
        k = s0
        while k >= 0:
            be, c, dist = b.item(k + 1), cap.item(k), L.item(k)
            if c <= be or fits(be, c, dist, ad_fit.item(k), jd.item(k)):
                break
            r = reach[jl.item(k)](be, dist, ad.item(k), jd.item(k), kn.item(k), kr.item(k))
            if c <= r:
                break
            b[k], origin[k] = r, origin[k + 1]
            k -= 1
        low = k
    # forward: w[k + 1] from w[k], the same way (a node no chain reaches keeps b)
    start = ~_keeps_own(b[1:], b[:-1], L, au_fit, ju, au, brisk)
    w = b.copy()
    acc_lim = np.zeros(n + 1, dtype=bool)
    high = 0                            # nodes <= high are final
    for s0 in np.flatnonzero(start).tolist():
        if s0 < high:
            continue
        k = s0
        while k < n:
            ws, bn, dist = w.item(k), b.item(k + 1), L.item(k)
            if bn <= ws or fits(ws, bn, dist, au_fit.item(k), ju.item(k)):
                break
            f = reach[jl.item(k)](ws, dist, au.item(k), ju.item(k), kn.item(k), kr.item(k))
            if bn <= f:
                break
            w[k + 1] = f
            acc_lim[k + 1] = True
            k += 1
        high = k + 1
    return NodeSpeeds(v=w, backward=b, origin_cause=origin, accel_limited=acc_lim)
