"""Candidate of ``acc+freq``: the rule's rows in path position, with the phases' ends free
between the breaks of a rest-to-rest piece.

:mod:`optimal.freq.phase_nlp` keeps the phases of a verified motion where they are,
rounded to the nodes of a fixed grid, and lets them grow by part of ``1/f`` per round.
On a piece of short segments between low corner caps that is where its motions stay
slow: the fastest motion the rule accepts there changes speed next to the corners
(:mod:`reference.core.phases`: a phase may hold a corner's low speed up to the corner
and change right after it, in its creep), and it joins phases that the seed has apart.
Here the ends of the phases are variables of the NLP, each free inside one *gap* (the
stretch between two breaks of the path) or fixed at a break, and a short search moves
them from gap to gap (:func:`free_phase_motions`).

Model of one piece (``s`` from rest to rest; every quantity is exact for the motion it
describes, and the motion is judged by the checker before it counts):

* the events: the piece's ends, its interior breaks and the phase ends; between two
  events :data:`FREE_FRACTIONS` place the nodes (finer next to each event, where the
  speed changes most), each interval with a constant path acceleration
  (``v^2`` linear in ``s``, :meth:`reference.core.profile.Profile.from_path_velocity`);
* the phases alternate, a rise from rest first and a fall to rest last; inside a phase
  every interval keeps the phase's sign with at least the creep :func:`creep_accel`
  (so that the checker finds one phase there and not two);
* the rule in its lost-time form (:mod:`reference.core.phases`): a rise from ``v0`` to
  ``v1`` over the time ``T`` and the distance ``D`` keeps ``v1 T - D >= dv g / 2`` and
  ``D - v0 T >= dv g / 2`` (``g = 1/f``, ``f`` the smallest LOOKAH_FREQUENCY of the axes
  moving on the segments it touches, :func:`optimal.freq.lower.segment_periods`; falls
  mirrored), exact in the nodes' speeds and positions;
* the limits of the ``acc`` set: the junction caps of the rulebook at the breaks
  (:func:`optimal.problem.junction_speed_caps`, the feasible flavour), per segment the
  feed and the axis velocity over the segment's supremum of ``|q'_j|``, and per axis
  ``sup|q'_j| |s''| + sup|q''_j| v^2 <= A_j`` at both ends of every interval
  (:func:`reference.core.geometry.axis_tangent_amplitudes`,
  :func:`reference.core.geometry.plane_amplitudes`): exact on lines, conservative on arcs
  (where the two parts peak at different points).

Search (:func:`free_phase_motions`), per piece, the slowest pieces first: the first
layout is the seed's phases with the runs of one sign joined (as
:func:`optimal.freq.phase_nlp._merged` joins them; the model has no constant-speed
stretch, a joined phase creeps across it). Where its NLP does not beat the seed, the
search takes that as a sign that the seed's phases already lie where the rule wants them
and leaves the piece (a zig-zag of 60 moves at one plateau, tests/optimal/
test_freq_humps.py: 40 moves in 25 s, none faster). Else, while the
budget lasts (:data:`FREE_MAX_SOLVES` per piece, :data:`FREE_NODE_BUDGET` in all),
the moves of :func:`_moves`, the first one that gains :data:`FREE_MIN_GAIN` and that the
caller's checker accepts is taken, and the moves from there. Moves that did not help
before, with the same codes around them, come last (:func:`_move_key`): after a gain
elsewhere in the piece they seldom help now. The best layout is solved once more on the
finer nodes of :data:`FREE_FINE_FRACTIONS`. Every result is a motion; the oracle keeps
those the checker accepts.

Measured (``acc+freq``, default machine): on lcnc_sam_tolerance_issue (19 segments, two
pieces; the bracket the other candidates leave is 12.57 %) the first layout alone takes
the upper bound from 2.3261 to 2.2010 s (6.52 %); 20 solves give 2.1732 s (5.17 %), 40
(the default) 2.1505 s (4.08 %), 80 the same; the last solve on finer nodes then
2.1482 s (3.96 %), the oracle 8 s -> 28 to 37 s. A scratch NLP written independently of
this one (phases in path position, a randomised search over layouts for some 500 s) had
found 2.1604 s there. On the line of five blocks with a wiggle between two point caps
(tests) the search drops the wiggle: 0.83639 s, 0.83564 s on finer nodes, faster than the
hand motion of 0.84197 s, and the oracle meets its bracket (2.24 -> 1.27 %).

Units: mm, s, mm/s.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from reference.core.errors import ProfileError
from reference.core.geometry import Path, axis_tangent_amplitudes, plane_amplitudes
from reference.core.limits import AxisArrays
from reference.core.phases import FREQ_ACCEL_TOL_REL, Phases, acceleration_phases
from reference.core.profile import Profile

from ..problem import junction_speed_caps
from .lower import rest_pieces, segment_periods

__all__ = ["FREE_ACCEPT_SCALE", "FREE_FINE_FRACTIONS", "FREE_FRACTIONS", "FREE_MAX_SOLVES",
           "FREE_NODE_BUDGET", "FreePhaseNLP", "Layout", "PieceModel", "creep_accel",
           "free_phase_motions", "layout_nlp", "layout_profile", "piece_model",
           "seed_layout", "solve_layout"]

#: Node places between two events, as shares of the stretch: finer next to each event,
#: where the motion changes its speed most (a phase holding a corner's cap up to the
#: corner changes right after it).
FREE_FRACTIONS = np.array([0.0, 0.01, 0.05, 0.2, 0.5, 0.8, 0.95, 0.99, 1.0])
#: The nodes of the last solve on a piece's best layout (:func:`free_phase_motions`):
#: those of :data:`FREE_FRACTIONS` refined towards the events, and even steps of 1/16
#: between. Measured, against the search's own motion: the line through a feed cap of
#: tests/optimal/test_freq.py 0.47045 -> 0.46876 s (its hand motion 0.46875 s), the
#: five-block wiggle 0.83639 -> 0.83564 s, lcnc_sam_tolerance_issue's last piece
#: 2.01721 -> 2.01490 s (one solve of 2.9 s); clustered steps alone reached 0.46912 s
#: on the first, even steps of 1/32 alone 2.02325 s on the last.
FREE_FINE_FRACTIONS = np.union1d(
    np.array([0.0, 0.002, 0.01, 0.03, 0.07, 0.15, 0.3, 0.5, 0.7, 0.85, 0.93, 0.97, 0.99,
              0.998, 1.0]), np.linspace(0.0, 1.0, 17))
#: The least path acceleration inside a phase, as a multiple of the checker's threshold
#: (:data:`reference.core.phases.FREQ_ACCEL_TOL_REL` of the profile's largest ``|s''|``,
#: which is at most ``sqrt(n)`` times the largest axis limit on the path): a creep the
#: checker still sees as part of the phase, small enough to cost no measurable time.
FREE_CREEP_FACTOR = 25.0
#: Shares (1) by which the NLP stays inside its rows: the rule's ``g`` is raised by
#: ``FREE_RULE_MARGIN``, the caps and the acceleration rows lowered by
#: ``FREE_LIMIT_MARGIN``. IPOPT meets its rows to ``1e-11`` absolute; the rows are in mm
#: and mm/s over stretches down to 1e-4 mm, so relative round-off reaches some 1e-7.
FREE_RULE_MARGIN = 1e-5
FREE_LIMIT_MARGIN = 1e-6
#: A free phase end stays this share of its gap's length away from the gap's ends (two
#: ends in one gap as far apart): the nodes must not collapse.
FREE_END_GAP_REL = 1e-4
#: Slowest interior node speed the NLP may take, mm/s (its times ``2 ds / (v0 + v1)``
#: must stay finite); far below any corner cap that leaves a piece in motion.
FREE_V_FLOOR_MM_S = 1e-3
#: NLP solves per piece at most (the first layout's included). Measured on
#: lcnc_sam_tolerance_issue (module docstring): 1, 20, 40 solves 2.2010, 2.1732,
#: 2.1505 s; 80 the same 2.1505 s (no move from there gains; the oracle then
#: solves the layout on finer nodes, 2.1482 s).
FREE_MAX_SOLVES = 40
#: NLP nodes summed over all solves on the whole path at most (a program of many
#: rest-to-rest pieces, or long ones): a solve costs 1.5 to 3 ms per node (measured on
#: lcnc_sam_tolerance_issue's last piece, some 240 nodes, 0.3 to 1.5 s a solve), so
#: 45 to 90 s at most. The search there takes 40 solves, 9,700 nodes.
FREE_NODE_BUDGET = 30_000
#: IPOPT iterations per solve at most; a solve that stops there counts as failed. On
#: lcnc_sam_tolerance_issue the solves that succeed take 20 to 200 iterations, those
#: that do not run on to 600 and more (at some 8 ms each) without a faster motion.
FREE_MAX_ITER = 200
#: IPOPT iterations at most of the last solve on finer nodes: started from a motion of
#: the coarse nodes it has further to go (the five-block wiggle of the tests, from the
#: oracle's seed: not done in 200).
FREE_FINE_MAX_ITER = 600
#: Pieces with more breaks than this are left to the other candidates: the NLP grows
#: with breaks and phase ends (up to some 3 of each per break, 8 nodes each), and its
#: solves would take the whole of :data:`FREE_NODE_BUDGET` in a few.
FREE_MAX_BREAKS = 200
#: A motion of a piece counts where the checker slows it (joined into the seed) by at
#: most this share (s/s): round-off at ratio 1 on the rows the NLP keeps with its margins.
FREE_ACCEPT_SCALE = 1e-9
#: A move is taken where its motion is faster than the best by this share (s/s).
FREE_MIN_GAIN = 1e-3


@dataclass(frozen=True, slots=True, eq=False)
class PieceModel:
    """The limits of one rest-to-rest piece, per break and per segment.

    Attributes
    ----------
    lo, hi : int
        Segment range ``[lo, hi)`` of the piece.
    s_break : numpy.ndarray, shape (C + 2,)
        Break positions from the piece's start to its end, mm.
    v_break : numpy.ndarray, shape (C + 2,)
        Speed cap at each break, mm/s (0 at the piece's ends, ``inf`` where nothing caps).
    v_seg : numpy.ndarray, shape (C + 1,)
        Speed cap on each segment (feed, axis velocity), mm/s.
    alpha, beta : numpy.ndarray, shape (C + 1, n)
        ``sup|q'_j| / A_j`` (s^2/mm) and ``sup|q''_j| / A_j`` (s^2/mm^2) per segment
        and axis.
    period : numpy.ndarray, shape (C + 1,)
        ``1/f`` of each segment, s.
    creep : float
        Least ``|s''|`` inside a phase, mm/s^2 (:func:`creep_accel`).
    """

    lo: int
    hi: int
    s_break: np.ndarray
    v_break: np.ndarray
    v_seg: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray
    period: np.ndarray
    creep: float

    @property
    def n_breaks(self) -> int:
        """Interior breaks ``C``."""
        return int(self.s_break.size - 2)


@dataclass(frozen=True, slots=True, eq=False)
class Layout:
    """Where the phases of a piece end, and the NLP's motion for it.

    ``codes`` has one entry per phase end (``P - 1`` of them for ``P`` phases, ``P``
    even, nondecreasing): ``2k`` puts the end exactly at interior break ``k``
    (``1 <= k <= C``), ``2k + 1`` free inside gap ``k`` (between break ``k`` and
    ``k + 1``; gap 0 starts at the piece's start).

    Attributes
    ----------
    codes : tuple of int
    sigma : numpy.ndarray, shape (P - 1,)
        Position of each phase end, mm.
    s, v : numpy.ndarray, shape (K + 1,)
        Nodes (mm) and speeds (mm/s) of the motion.
    time_s : float
        Its duration, s (``inf`` where the NLP failed).
    ok : bool
        Whether IPOPT reported success.
    """

    codes: tuple[int, ...]
    sigma: np.ndarray
    s: np.ndarray
    v: np.ndarray
    time_s: float
    ok: bool


def creep_accel(lim: AxisArrays) -> float:
    """:data:`FREE_CREEP_FACTOR` times the checker's threshold for a zero acceleration
    on the largest ``|s''|`` the limits allow (``sqrt(n)`` times the largest ``A_j``),
    mm/s^2."""
    a = np.asarray(lim.a_max, np.float64)
    return float(FREE_CREEP_FACTOR * FREQ_ACCEL_TOL_REL * np.sqrt(a.size) * np.max(a))


@dataclass(frozen=True, slots=True, eq=False)
class _PathLimits:
    """The per-segment and per-break arrays of :class:`PieceModel` over the whole path
    (computed once for all its pieces)."""

    alpha: np.ndarray
    beta: np.ndarray
    v_seg: np.ndarray
    v_break: np.ndarray
    period: np.ndarray
    creep: float


def _path_limits(path: Path, lim: AxisArrays) -> _PathLimits:
    D, Pv = axis_tangent_amplitudes(path)
    amp = plane_amplitudes(path)
    rho = np.sqrt(path.e1 ** 2 + path.e2 ** 2)
    dq_sup = D + Pv
    ddq_sup = rho * amp.curvature[:, None]
    a = np.asarray(lim.a_max, np.float64)[None, :]
    vmax = np.asarray(lim.v_max, np.float64)[None, :]
    v_ax = np.where(dq_sup > 0, vmax / np.where(dq_sup > 0, dq_sup, 1.0), np.inf)
    v_seg = np.minimum(v_ax.min(axis=1, initial=np.inf), path.feed)
    v_break, _ = junction_speed_caps(path, lim, permissive=False)
    return _PathLimits(dq_sup / a, ddq_sup / a, v_seg, v_break,
                       segment_periods(path, lim), creep_accel(lim))


def piece_model(path: Path, lim: AxisArrays, lo: int, hi: int,
                data: _PathLimits | None = None) -> PieceModel:
    """The :class:`PieceModel` of segments ``[lo, hi)`` of ``path`` (a rest-to-rest
    piece: the path stops at both ends), limits ``lim`` in the path's axis order;
    ``data``: the path's arrays when the caller has them (:func:`free_phase_motions`
    builds them once for every piece)."""
    d = _path_limits(path, lim) if data is None else data
    v_break = d.v_break[lo:hi + 1].copy()
    v_break[[0, -1]] = 0.0
    return PieceModel(lo, hi, path.s_breaks[lo:hi + 1].copy(), v_break, d.v_seg[lo:hi],
                      d.alpha[lo:hi], d.beta[lo:hi], d.period[lo:hi], d.creep)


def _valid(codes: tuple[int, ...], C: int) -> bool:
    """Whether ``codes`` is a layout of a piece with ``C`` interior breaks."""
    c = np.asarray(codes, np.int64)
    if c.size % 2 == 0 or np.any(c < 1) or np.any(c > 2 * C + 1) or np.any(np.diff(c) < 0):
        return False
    at = c[c % 2 == 0]
    return at.size == np.unique(at).size


def _code_of(model: PieceModel, s: float) -> int:
    """The code of a phase end at ``s`` (mm): the break it is on (within
    :data:`FREE_END_GAP_REL` of the gaps beside it), else its gap."""
    sb = model.s_break
    k = int(np.clip(np.searchsorted(sb, s, side="right") - 1, 0, sb.size - 2))
    tol = FREE_END_GAP_REL * np.diff(sb)
    if 1 <= k and s - sb[k] <= tol[k]:
        return 2 * k
    if k + 1 <= model.n_breaks and sb[k + 1] - s <= tol[k]:
        return 2 * (k + 1)
    return 2 * k + 1


def seed_layout(model: PieceModel, prof: Profile, phases: Phases | None = None
                ) -> tuple[tuple[int, ...], np.ndarray] | None:
    """The phase ends of ``prof`` on the piece, runs of one sign joined: codes and
    positions (mm), or ``None`` where the motion has no rise followed by a fall there.
    ``phases``: :func:`~reference.core.phases.acceleration_phases` of ``prof`` when the
    caller has them."""
    ph = acceleration_phases(prof) if phases is None else phases
    s0, s1 = model.s_break[0], model.s_break[-1]
    ps = prof.s[ph.first]
    pe = prof.s[ph.last + 1]
    mid = 0.5 * (ps + pe)
    sel = (mid > s0) & (mid < s1)
    sign, ps, pe = ph.sign[sel].astype(np.int64), ps[sel], pe[sel]
    order = np.argsort(ps, kind="stable")
    sign, ps, pe = sign[order], ps[order], pe[order]
    ends = []
    for i in range(1, sign.size):
        if sign[i] != sign[i - 1]:
            # the end between them: the middle of the stretch between the two phases
            ends.append(0.5 * (pe[i - 1] + ps[i]) if ps[i] > pe[i - 1] else ps[i])
    if sign.size == 0 or sign[0] != 1 or sign[-1] != -1:
        return None
    sigma = np.clip(np.asarray(ends, np.float64), s0, s1)
    codes = tuple(_code_of(model, x) for x in sigma)
    # two ends at one break, or out of order: the later one into the next gap
    fixed = []
    for c in codes:
        if fixed and c <= fixed[-1] and c % 2 == 0:
            c = fixed[-1] + 1 if fixed[-1] % 2 == 0 else fixed[-1]
        fixed.append(max(c, fixed[-1]) if fixed else c)
    codes = tuple(min(c, 2 * model.n_breaks + 1) for c in fixed)
    return (codes, sigma) if _valid(codes, model.n_breaks) else None


@dataclass(frozen=True, slots=True, eq=False)
class FreePhaseNLP:
    """The NLP of one layout (module docstring) as data, for the backend
    (:func:`optimal.freq.backends.ipopt.solve_free_phases`).

    Variables: the speeds ``v`` at the ``K + 1`` nodes (mm/s) and the shares ``u`` of
    their gaps of the free ends (1). Node positions from the piece's start are affine in
    ``u``: ``S = s0 + M u`` (mm).

    Attributes
    ----------
    s0 : numpy.ndarray, shape (K + 1,)
    M : numpy.ndarray, shape (K + 1, U)
        mm per unit share.
    sign : numpy.ndarray, shape (K,)
        ``+1`` inside a rise, ``-1`` inside a fall, per interval.
    alpha, beta : numpy.ndarray, shape (K, n)
        As :class:`PieceModel`'s, per interval.
    v_lo, v_hi : numpy.ndarray, shape (K + 1,)
        Speed bounds, mm/s (0 at both ends).
    u_lo, u_hi : numpy.ndarray, shape (U,)
    order : numpy.ndarray of int, shape (Q,)
        ``u[order + 1] - u[order] >= order_gap``: two free ends in one gap.
    order_gap : float
    phase_start, phase_stop : numpy.ndarray of int, shape (P,)
        First and last node of each phase.
    phase_g : numpy.ndarray, shape (P,)
        The rule's ``g`` of each phase, margin included, s.
    creep : float
        mm/s^2.
    keep : float
        Share (1) of the axis limits the rows keep.
    v0 : numpy.ndarray, shape (K + 1,)
    u0 : numpy.ndarray, shape (U,)
        Initial point.
    """

    s0: np.ndarray
    M: np.ndarray
    sign: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray
    v_lo: np.ndarray
    v_hi: np.ndarray
    u_lo: np.ndarray
    u_hi: np.ndarray
    order: np.ndarray
    order_gap: float
    phase_start: np.ndarray
    phase_stop: np.ndarray
    phase_g: np.ndarray
    creep: float
    keep: float
    v0: np.ndarray
    u0: np.ndarray


def layout_nlp(model: PieceModel, codes: tuple[int, ...], sigma0: np.ndarray,
               v_of: Callable[[np.ndarray], np.ndarray],
               fractions: np.ndarray = FREE_FRACTIONS) -> FreePhaseNLP | None:
    """The :class:`FreePhaseNLP` of the piece with its phase ends at ``codes`` (module
    docstring), started from the ends ``sigma0`` (mm, shape (P - 1,); those of free ends
    are clipped into their gaps) and the speeds ``v_of(s)`` (mm/s); ``None`` where a
    node's caps leave no speed above :data:`FREE_V_FLOOR_MM_S`."""
    C = model.n_breaks
    sb = model.s_break
    codes = tuple(int(c) for c in codes)
    P = len(codes) + 1
    gap_len = np.diff(sb)
    free = [j for j, c in enumerate(codes) if c % 2 == 1]
    gap_of = np.array([codes[j] // 2 for j in free], np.int64)
    U = max(len(free), 1)
    # a free end's variable is its share of its gap (scaled as the speeds are, where
    # positions along the path would be hundreds of mm against gaps of a few tenths);
    # events in order: (x, L, n, break, end, gap), at the position x + L u_n (n = -1:
    # at x), on a break (its index) or a phase end (its index), the stretch after it in
    # gap ``gap``
    x0 = sb - sb[0]
    events: list[tuple[float, float, int, int | None, int | None, int]] = []
    for k in range(C + 2):
        at = [j for j, c in enumerate(codes) if c == 2 * k]
        events.append((float(x0[k]), 0.0, -1, k, at[0] if at else None, k))
        for n, j in enumerate(free):
            if codes[j] == 2 * k + 1:
                events.append((float(x0[k]), float(gap_len[k]), n, None, j, k))
    nf = fractions.size - 1
    K = (len(events) - 1) * nf
    s0 = np.zeros(K + 1)
    M = np.zeros((K + 1, U))
    seg = np.zeros(K, np.int64)
    phase_of = np.zeros(K, np.int64)
    end_node, break_node = {}, {}
    phase, i = 0, 0
    for e, (c0, l0, n0, brk, end, gap) in enumerate(events):
        if brk is not None:
            break_node[brk] = i
        if end is not None:
            end_node[end] = i
            phase = end + 1
        if e == len(events) - 1:
            s0[i] = c0
            if n0 >= 0:
                M[i, n0] = l0
            break
        c1, l1, n1 = events[e + 1][:3]
        for f in fractions[:-1]:
            s0[i] = (1 - f) * c0 + f * c1
            if n0 >= 0:
                M[i, n0] += (1 - f) * l0
            if n1 >= 0:
                M[i, n1] += f * l1
            seg[i] = gap
            phase_of[i] = phase
            i += 1
    keep = 1.0 - FREE_LIMIT_MARGIN
    # speed caps: per node the smaller of its segments' and, at a break, the break's
    cap = np.full(K + 1, np.inf)
    cap[:-1] = model.v_seg[seg]
    cap[1:] = np.minimum(cap[1:], model.v_seg[seg])
    for k, n in break_node.items():
        cap[n] = min(cap[n], model.v_break[k])
    v_lo = np.full(K + 1, FREE_V_FLOOR_MM_S)
    v_lo[[0, -1]] = 0.0
    v_hi = cap * keep
    v_hi[[0, -1]] = 0.0
    if np.any(v_hi[1:-1] < v_lo[1:-1]):
        return None
    # each phase's g: the largest 1/f of the gaps it touches
    first_gap = [0] + [c // 2 for c in codes]
    last_gap = [c // 2 - (c % 2 == 0) for c in codes] + [C]
    g = np.array([float(np.max(model.period[first_gap[p]:max(last_gap[p], first_gap[p]) + 1]))
                  for p in range(P)]) * (1.0 + FREE_RULE_MARGIN)
    # the initial point: the ends' shares of their gaps (two in one gap apart), the
    # seed's speeds
    u0 = np.full(U, 0.5)
    for n, (j, k) in enumerate(zip(free, gap_of)):
        u0[n] = np.clip((sigma0[j] - sb[k]) / gap_len[k], 2 * FREE_END_GAP_REL,
                        1.0 - 2 * FREE_END_GAP_REL)
    order = np.array([n for n in range(len(free) - 1) if gap_of[n] == gap_of[n + 1]],
                     np.int64)
    for n in order:
        if u0[n + 1] <= u0[n]:
            u0[n], u0[n + 1] = 1.0 / 3.0, 2.0 / 3.0
    v0 = np.clip(np.asarray(v_of(s0 + M @ u0 + sb[0]), np.float64), v_lo, v_hi)
    v0[1:-1] = np.maximum(v0[1:-1], np.minimum(10 * FREE_V_FLOOR_MM_S, v_hi[1:-1]))
    return FreePhaseNLP(
        s0=s0, M=M, sign=np.where(phase_of % 2 == 0, 1.0, -1.0),
        alpha=model.alpha[seg], beta=model.beta[seg], v_lo=v_lo, v_hi=v_hi,
        u_lo=np.full(U, FREE_END_GAP_REL), u_hi=np.full(U, 1.0 - FREE_END_GAP_REL),
        order=order, order_gap=FREE_END_GAP_REL,
        phase_start=np.array([0] + [end_node[j] for j in range(P - 1)], np.int64),
        phase_stop=np.array([end_node[j] for j in range(P - 1)] + [K], np.int64),
        phase_g=g, creep=model.creep, keep=keep, v0=v0, u0=u0)


def solve_layout(model: PieceModel, codes: tuple[int, ...], sigma0: np.ndarray,
                 v_of: Callable[[np.ndarray], np.ndarray], *,
                 max_iter: int = FREE_MAX_ITER,
                 fractions: np.ndarray = FREE_FRACTIONS) -> Layout:
    """The fastest motion of the piece with its phase ends at ``codes``
    (:func:`layout_nlp`, solved by :func:`optimal.freq.backends.ipopt.solve_free_phases`);
    time ``inf`` where the caps leave no room."""
    from .backends.ipopt import solve_free_phases

    codes = tuple(int(c) for c in codes)
    nlp = layout_nlp(model, codes, sigma0, v_of, fractions)
    if nlp is None:
        return Layout(codes, np.asarray(sigma0, np.float64), np.zeros(0), np.zeros(0),
                      np.inf, False)
    ok, v, u = solve_free_phases(nlp, max_iter=max_iter)
    sb = model.s_break
    s_nodes = nlp.s0 + nlp.M @ u + sb[0]
    free = [j for j, c in enumerate(codes) if c % 2 == 1]
    gap_len = np.diff(sb)
    sigma = np.array([float(sb[c // 2] + gap_len[c // 2] * u[free.index(j)]) if c % 2
                      else float(sb[c // 2]) for j, c in enumerate(codes)])
    with np.errstate(divide="ignore", invalid="ignore"):
        t = float(np.sum(2 * np.diff(s_nodes) / (v[:-1] + v[1:])))
    return Layout(codes, sigma, s_nodes, v, t if np.isfinite(t) and t > 0 else np.inf, ok)


def layout_profile(path: Path, model: PieceModel, lay: Layout) -> Profile | None:
    """The motion of ``lay`` as a :class:`~reference.core.profile.Profile` over the
    piece (constant acceleration per interval, path positions absolute, times from 0),
    or ``None`` where it is no motion."""
    s, v = lay.s, np.maximum(lay.v, 0.0)
    if s.size < 2 or not np.isfinite(lay.time_s):
        return None
    s = np.clip(s, model.s_break[0], model.s_break[-1])
    s[0], s[-1] = model.s_break[0], model.s_break[-1]
    v[0] = v[-1] = 0.0
    keep = np.concatenate(([True], np.diff(s) > 0))
    s, v = s[keep], v[keep]
    mid = 0.5 * (s[:-1] + s[1:])
    seg = np.clip(path.segment_index(mid), model.lo, model.hi - 1)
    try:
        return Profile.from_path_velocity(s, v, path.block[seg])
    except ProfileError:
        return None


def _moves(lay: Layout, model: PieceModel) -> list[tuple[int, ...]]:
    """Layouts next to ``lay``, in this order: every free end the NLP pressed against
    its gap's end moved onto that break and every phase it shrank to nothing dropped,
    all at once, then each of these alone; then each end on a break moved into the gap
    on either side (the change before the corner or after it); then each phase dropped
    with its two ends (its neighbours, of one sign, joined), the smallest speed change
    first. Measured on lcnc_sam_tolerance_issue's last piece (40 solves): three ends
    moved off corners gained 0.045 s, one phase dropped 0.005 s."""
    codes = list(lay.codes)
    sb = model.s_break
    eps = FREE_END_GAP_REL * np.diff(sb)
    n = len(codes)
    pressed: list[tuple[int, int]] = []          # (end, new code)
    for j, c in enumerate(codes):
        if c % 2 == 1:
            k = c // 2
            if lay.sigma[j] - sb[k] <= 3 * eps[k] and k >= 1:
                pressed.append((j, 2 * k))
            elif sb[k + 1] - lay.sigma[j] <= 3 * eps[k] and k + 1 <= model.n_breaks:
                pressed.append((j, 2 * k + 2))
    shrunk = [j for j in range(n - 1)
              if lay.sigma[j + 1] - lay.sigma[j] <= 3 * float(np.max(eps))]
    out: list[list[int]] = []
    if pressed or shrunk:
        allc = codes.copy()
        for j, c in pressed:
            allc[j] = c
        drop = set()
        for j in shrunk:
            if j not in drop and j + 1 not in drop:
                drop |= {j, j + 1}
        out.append([c for i, c in enumerate(allc) if i not in drop])
    out += [codes[:j] + [c] + codes[j + 1:] for j, c in pressed]
    out += [codes[:j] + codes[j + 2:] for j in shrunk]
    for j, c in enumerate(codes):
        if c % 2 == 0:
            out += [codes[:j] + [c - 1] + codes[j + 1:], codes[:j] + [c + 1] + codes[j + 1:]]
    # the phase between ends j and j + 1 dropped, the smallest speed change first
    if lay.s.size:
        dv = np.abs(np.diff(np.interp(lay.sigma, lay.s, lay.v)))
        out += [codes[:int(j)] + codes[int(j) + 2:] for j in np.argsort(dv, kind="stable")]
    seen, uniq = set(), []
    for c in out:
        t = tuple(c)
        if t not in seen and t != lay.codes and _valid(t, model.n_breaks):
            seen.add(t)
            uniq.append(t)
    return uniq


def _move_key(old: tuple[int, ...], new: tuple[int, ...]) -> tuple:
    """What a move changes, with one end of context on either side: the codes of
    ``old`` and ``new`` between their common prefix and suffix, widened by one."""
    p = 0
    while p < min(len(old), len(new)) and old[p] == new[p]:
        p += 1
    q = 0
    while q < min(len(old), len(new)) - p and old[-1 - q] == new[-1 - q]:
        q += 1
    lo = max(p - 1, 0)
    return old[lo:len(old) - q + 1], new[lo:len(new) - q + 1]


def _sigma_for(codes: tuple[int, ...], lay: Layout, model: PieceModel) -> np.ndarray:
    """Starting ends for ``codes``: the ends of ``lay`` with the same code (in order),
    else the middle of the code's gap."""
    sb = model.s_break
    pool: dict[int, list[float]] = {}
    for c, x in zip(lay.codes, lay.sigma):
        pool.setdefault(c, []).append(float(x))
    out = []
    for c in codes:
        if pool.get(c):
            out.append(pool[c].pop(0))
        elif c % 2 == 0:
            out.append(float(sb[c // 2]))
        else:
            k = c // 2
            out.append(0.5 * (sb[k] + sb[k + 1]))
    return np.asarray(out)


def free_phase_motions(path: Path, lim: AxisArrays, seed: Profile, *,
                       max_solves: int = FREE_MAX_SOLVES,
                       node_budget: int = FREE_NODE_BUDGET, enough: float = 0.0,
                       accept: Callable[[int, Profile], bool] | None = None,
                       progress: Callable[[str], object] | None = None
                       ) -> dict[int, Profile]:
    """The fastest motion the search of the module docstring finds on each rest-to-rest
    piece of ``path``, from the phases of ``seed`` (a motion on the whole path, holds
    excluded).

    Parameters
    ----------
    path : Path
    lim : AxisArrays
        Limits in the path's axis order.
    seed : Profile
    max_solves : int
        :data:`FREE_MAX_SOLVES`: NLP solves per piece at most.
    node_budget : int
        :data:`FREE_NODE_BUDGET`: NLP nodes summed over the solves of all pieces at most
        (the slowest pieces first).
    enough : float
        s. The search stops once ``seed`` with the motions found so far takes at most
        this long (the caller's bracket is met); 0: only the budget stops it.
    accept : callable, optional
        ``accept(piece, motion)``: whether the checker accepts the motion of a piece
        (joined into ``seed``); a faster motion it refuses is not taken. Default: every
        motion counts (the caller judges).
    progress : callable, optional
        ``progress(message)`` after each piece.

    Returns
    -------
    dict
        Piece index (rows of :func:`optimal.freq.lower.rest_pieces`) to its motion, only
        where one is faster than ``seed`` on that piece.
    """
    pieces = rest_pieces(path)
    seg_t = seed.segment_times(path)
    out: dict[int, Profile] = {}
    gained = 0.0                                  # s, by the pieces done so far
    spent = 0                                     # nodes solved so far
    # the slowest pieces first: the budget goes where the most time is
    piece_t = np.add.reduceat(seg_t, pieces[:, 0]) if pieces.size else np.zeros(0)
    data, phases = None, None                     # built for the first piece searched
    for k in np.argsort(-piece_t, kind="stable"):
        k = int(k)
        lo, hi = int(pieces[k, 0]), int(pieces[k, 1])
        if spent >= node_budget or seed.duration - gained <= enough:
            break
        if hi - lo - 1 > FREE_MAX_BREAKS:
            continue
        if data is None:
            data, phases = _path_limits(path, lim), acceleration_phases(seed)
        model = piece_model(path, lim, lo, hi, data)
        start = seed_layout(model, seed, phases)
        if start is None:
            continue
        t_seed = float(piece_t[k])
        best = solve_layout(model, start[0], start[1],
                            lambda s: np.interp(s, seed.s, seed.v))
        solves = 1
        spent += best.s.size
        best_prof = None
        if best.ok and best.time_s < t_seed * (1 - FREE_MIN_GAIN):
            p = layout_profile(path, model, best)
            if p is not None and (accept is None or accept(k, p)):
                best_prof = p
        tried, failed = {best.codes}, set()
        # the search follows only where freeing the ends of the seed's own phases gains
        # (module docstring); from here on ``best`` is an accepted motion
        improved = best_prof is not None
        while improved and solves < max_solves and spent < node_budget and \
                seed.duration - gained - (t_seed - best.time_s) > enough:
            improved = False
            # moves that did not help before, with the same codes around them, last:
            # after a gain elsewhere they seldom help now
            moves = [(c, _move_key(best.codes, c)) for c in _moves(best, model)
                     if c not in tried]
            moves = [m for m in moves if m[1] not in failed] + \
                [m for m in moves if m[1] in failed]
            for codes, key in moves:
                if solves >= max_solves or spent >= node_budget:
                    break
                tried.add(codes)
                failed.add(key)
                lay = solve_layout(model, codes, _sigma_for(codes, best, model),
                                   lambda s, c=best: np.interp(s, c.s, c.v))
                solves += 1
                spent += lay.s.size
                if not lay.ok or lay.time_s >= best.time_s * (1 - FREE_MIN_GAIN):
                    continue
                p = layout_profile(path, model, lay)
                if p is None or (accept is not None and not accept(k, p)):
                    continue
                failed.discard(key)
                best, best_prof, improved = lay, p, True
                break
        if best_prof is not None:
            # the best layout once more on finer nodes: its motion's acceleration steps
            # then fall nearer where it wants them
            lay = solve_layout(model, best.codes, best.sigma,
                               lambda s, c=best: np.interp(s, c.s, c.v),
                               fractions=FREE_FINE_FRACTIONS, max_iter=FREE_FINE_MAX_ITER)
            spent += lay.s.size
            if lay.ok and lay.time_s < best.time_s:
                p = layout_profile(path, model, lay)
                if p is not None and (accept is None or accept(k, p)):
                    best, best_prof = lay, p
            out[k] = best_prof
            gained += t_seed - best.time_s
        if progress:
            t_new = best.time_s if best_prof is not None else t_seed
            progress(f"free phase ends, piece {k + 1}/{pieces.shape[0]}: "
                     f"{t_seed:.4f} -> {t_new:.4f} s ({solves} solves)")
    return out
