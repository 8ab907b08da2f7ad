"""Lower bound of the frequency rule over the whole path: a shortest path over humps.

:mod:`optimal.freq.lower` bounds each rest-to-rest piece on its own and knows nothing of
the corners inside it; the ``acc`` bound knows the corners but lets the speed dip at each
of them as fast as the acceleration allows. Where corners are closer than a speed change
lasting ``1/f`` can follow (short zig-zags, small arcs), the true motion cannot dip at every
corner: it holds a speed below the lowest corner cap of a whole stretch. This module
bounds that: a dynamic programme over where the motion turns from falling to rising.

Proof
=====
Notation: ``g`` the shortest phase the checker accepts, ``(1/f)/(1 + RATIO_TOL)``;
``eta = FREQ_ACCEL_TOL_REL``; ``abar`` a bound on ``|s''|`` of every motion of the ``acc``
problem (half the largest slope bound ``M_k`` of ``b = v^2`` of its relaxation,
:mod:`optimal.bounds`); ``T_up`` a verified upper bound of the minimum time. A motion
slower than ``T_up`` is not the minimum, so only motions with ``T <= T_up`` need the bound.

1. *Speed envelope.* The ``acc`` relaxation on a grid gives node bounds ``b_hat`` (its
   greatest element), interval bounds ``Bbar_k`` and slopes ``M_k`` valid for every motion
   of the ``acc`` problem, hence for every motion of ``acc+freq``:
   ``v(s)^2 <= phi(s) = min(Bbar_k, b_hat_k + M_k (s - s_k), b_hat_{k+1} + M_k (s_{k+1} - s))``
   on interval ``k``. On each *cell* (a piece of an interval, :func:`_envelope`)
   ``e_hi = sqrt(max phi)`` bounds ``v`` at every point of the cell and
   ``e_lo = sqrt(min phi)`` at *some* point of it (``phi`` is concave, so its least value is
   at an end of the cell). Any node bound valid for every motion the programme is for may
   lower ``b_hat``: the slopes ``M_k`` hold for every motion of the ``acc`` problem, so
   ``phi`` stays a bound. Under ``jerk+freq`` these are the jerk set's reach caps
   (:func:`optimal.jerk.lower.reach_speed_caps`, step 7 there; ``node_caps`` of
   :func:`humps_piece_bounds`).
2. *Phase speed.* Let ``w(t) = v(0) + int_0^t s'' 1[in a phase] dt``: the speed with only
   the phases' accelerations. Outside phases ``|s''| <= eta abar``, so
   ``|v - w| <= delta = eta abar T_up``. ``w`` changes only inside phases, so it is
   piecewise monotone and each of its maximal monotone *stretches* contains at least one
   whole phase (a stretch ends only where a phase of the other sign begins; the motion
   starts and ends at rest), which lasts at least its effective duration ``>= g_P``.
   Bounds carried along a stretch by the monotonicity of ``w`` (the running minima of
   step 3, the valley's speed) are on ``w``; ``v <= w + delta`` and ``w <= v + delta <=
   e + delta`` turn them into bounds on ``v`` with the cell speeds raised by ``2 delta``,
   and all bounds by the checker's standstill tolerance ``VEL_TOL_MM_S`` (the relaxation
   has ``b = 0`` at stops, the checker accepts that speed there). A cell's own bound on
   ``v``, and the stretch's largest speed ``V`` (step 3), need no drift: ``hi = e_hi +
   VEL_TOL_MM_S`` there, ``e_hi + 2 delta + VEL_TOL_MM_S`` where carried, ``lo`` (only
   ever carried) ``e_lo + 2 delta + VEL_TOL_MM_S``.
3. *One stretch.* A rising stretch from a valley ``a`` (in cell ``i``) to a peak ``p`` (in
   cell ``c``) has ``w(s) <= w(s') <= e(s') + delta`` for every ``s' in [s, p]``; with
   step 1, in each cell ``k`` strictly between ``i`` and ``c``:
   ``v <= ub_k = min(hi_k, lo_{k+1}, ..., lo_{c-1}, hi_c)``. Its time is at least:

   * ``R = sum_k ds_k / ub_k`` over those cells;
   * ``g`` (it holds a whole phase; ``g`` the smallest over the cells ``i..c``);
   * ``LT``, from lost time: each phase ``P`` of the stretch loses
     ``int_P (V - v) dt >= dv_P g_P / 2`` against the stretch's largest speed ``V``
     (integration by parts, :mod:`reference.core.phases`), the phases carry the whole
     change of ``w``, at least ``V - u`` with ``u`` the valley's speed, and
     ``V - v >= 0`` elsewhere. The distance ``d >= sum_k ds_k`` is
     ``V D - int (V - v) dt``, so ``D >= (d + sum_P dv_P g_P / 2) / V``.
     *Weights*: a phase lasts at least the period of every cell it touches (its axes
     include those of each), and ``w`` is monotone, so each level ``x`` between the
     valley and the top is crossed once, by one phase, at a point where ``w = x``. In
     cell ``k`` ``w`` is at most ``W_k = min(hi_k, lo_{k+1}, ..., lo_{c-1}, hi_c)``
     (its own bound and every later one, with the drift: ``W_k`` is at least the bound
     on ``w`` plus ``delta``), so the phase that crosses ``x`` lasts at least
     ``gamma(x + delta)``, ``gamma(y)`` the least period of the cells with
     ``W_k >= y``. With the levels crossed, at least ``(u - delta, V - delta)``,
     ``sum_P dv_P g_P >= int_u^V gamma(y) dy``, and the phase that crosses the top
     levels makes the stretch last at least ``gamma(V-)``. So for a top speed ``V``
     the stretch lasts at least ``max(gamma(V-), (d + int_u^V gamma / 2) / V)``, and at
     least ``d / V`` where ``V <= u``; minimised over ``V <= hi_c``. ``gamma`` is a step
     function (a step per drop of the period along the stretch, so one per frequency
     of the axes), the first term constant and the second ``C / V + gamma / 2`` on each
     step, so the least value is at a step's end. With one period ``gamma = g`` and
     this is ``LT = min(d / u, (d - u g / 2) / hi_c + g / 2)``; at a corner between
     axes of two frequencies (an X move into a Z plunge) it charges the rise out of
     the corner the plunge's period on every level above the corner's cap, where
     ``g`` charged the shorter one. The bound falls as ``u`` grows (``d / V`` is at
     most the lost-time term for ``V >= u``), so any upper bound on ``u`` may stand
     in for it. The valley lies in cell ``i``: the fall into it passes the cell's start
     and the rise out of it its end, and ``w`` is at least ``u`` on both stretches, so
     ``u <= lo_i`` (``lo`` is the envelope at one of the cell's ends, step 1),
     ``u <= lo_k`` for every cell ``k`` strictly inside the rise and ``u <= hi_c``.

   Falling stretches alike, mirrored.
4. *The programme.* Any motion is a chain of stretches, valley (rest at the start) to
   peak to valley (rest at the end), and its time is the sum of their times. A cell that
   holds a turn is left out of both stretches' sums (the turn can be anywhere in it). A
   long stretch may also be cut at cell starts (*cuts*): the pieces' ``R`` add to at most
   the stretch's ``R`` (each piece's minima run over fewer cells, so they are larger), and
   the pieces carry no ``g`` or ``LT`` term. The shortest path over the states "valley /
   peak / rising cut / falling cut in cell ``k``" with these edge costs is therefore at
   most the time of every motion with ``T <= T_up``, as long as every motion is one of
   its paths. A path may leave out edges for strength and still have that: a piece
   ending in a cut must hold ``HUMP_CHAIN_PERIODS`` periods of ``R`` (without that floor
   a chain of cuts could follow every dip of the envelope, as no hump could), and edges
   from each cell reach ``HUMP_CHAIN_PERIODS + 1`` periods at the speeds ``hi`` (and two
   cells more). A stretch within reach is one edge; a longer one is cut where its first
   ``HUMP_CHAIN_PERIODS`` periods at ``hi`` end (``R >= sum ds / hi``, so the piece holds
   them), inside the reach, and so on. Edges that reach further would not shorten any
   path: a cut at that point already splits them at no more cost (the pieces' ``R`` add
   to at most the whole's, and the whole's cost is at least its ``R``).

4b. *Turn cells.* The time spent in a turn cell ``k`` is split between the stretch into
   the turn (``tau_out``) and the one out of it (``tau_in``), ``tau_out + tau_in >= E_k =
   ds_k / hi_k``. A stretch ``s`` lasts ``T_s >= G_s`` (the ``g`` and ``LT`` terms) and
   ``T_s >= R_s + tau_in + tau_out``. Charge the stretch out of a turn ``ch_s <= (E_k -
   sigma)^+``, ``sigma = (G - R - ch)^+`` the slack of the stretch into it, and let
   ``A_s = max(G_s, R_s + ch_s)``. By induction over the stretches,
   ``sum_{s <= n} T_s >= sum_{s <= n} A_s + (tau_out(n) - sigma_n)^+``: adding ``T_n`` to
   the hypothesis, ``ch_n <= (tau_out(n-1) - sigma_{n-1})^+ + tau_in(n)`` and
   ``T_n >= max(G_n, R_n + tau_in(n) + tau_out(n))`` give ``T_n + (tau_out(n-1) -
   sigma_{n-1})^+ >= max(G_n, R_n + ch_n + tau_out(n)) = A_n + (tau_out(n) -
   sigma_n)^+``. So ``sum A_s`` bounds the time: a stretch whose bound leaves no slack
   passes the whole next turn cell on, one with slack absorbs that much of it. The
   programme keeps the slack in levels (:data:`HUMP_SLACK_LEVELS`, shares of the next
   turn cell's time), rounded up, which only charges less. A cut piece is ``R`` alone
   (slack 0); the piece's start, at rest, passes nothing on.
4c. *Valley speeds.* Each side of a valley bounds its speed ``u`` (step 3) and each uses
   ``u`` in its ``LT``; the true ``u`` satisfies both. The programme carries ``u`` from
   the fall to the rise in levels ``(lo_i r^(k+1), lo_i r^k]`` (the last down to 0,
   :data:`HUMP_SPEED_RATIO`, :data:`HUMP_SPEED_LEVELS`): a valley state per level, a
   fall or a rise admits a level whose lower end is at or below its own bound and takes
   ``u = min(lo_i r^k, bound)``. The motion's own levels give a path of the programme,
   so its shortest path is still at most every motion's time. Where the corner is in
   the valley's fall, say, the rise then loses the lost time of a dip to the corner's
   cap, not to the envelope beside it.

4d. *Peak speeds.* The rise into a peak and the fall out of it each take the least
   over their top speed ``V``, and the two need not agree: a rise that creeps over a
   slow corner at a speed below the corner's next-cell bounds pays little (``d / V``
   over a short ``d``, no phase above the corner), while the fall after it takes the
   peak cell's full speed. Their top speeds differ by at most ``2 delta`` (both are
   within ``delta`` of ``w`` at the peak). The programme carries the rise's top speed
   in levels of the peak cell's ``hi`` (:data:`HUMP_PEAK_RATIO`,
   :data:`HUMP_PEAK_LEVELS`): a peak state per level, the rise minimised over its
   level, the fall over the level widened by ``2 delta``. The motion's own levels give
   a path, so the shortest path is still at most every motion's time.
5. *Per piece.* At a stop the speed is (within the checker's tolerances) zero and cannot
   fall further, so no phase runs through it: every rest-to-rest piece is such a chain on
   its own, and the programme bounds the time spent between the piece's ends. So does the
   ``acc`` relaxation's time on the piece's intervals (its interval estimates integrate
   pointwise bounds of ``b``, so each holds on its own). The bound is the sum over the
   pieces of the larger of the two.

What it does not know: the acceleration inside a stretch beyond the envelope, the
time a phase adds where its lost time and the envelope's overlap, and a quarter of a
turn cell's time at most per turn (step 4b's rounding; :data:`HUMP_CELL_TIME_REL` keeps a
cell a few per cent of a period, and where the bound is near what the oracle needs, the
turn run of :func:`humps_bound` cuts the cells at the turns four times finer).
Measured on single corners (two lines at F1200 on the default machine) it comes within
0.7 % of the verified motion, and at corners between axes of two frequencies (an X
move, a Z plunge, an X move: tests) within 0.75 % of a hand motion of ramps, where
before the weights of step 3 and the peak levels of step 4d it was 1.7 % below
(lcnc_test_12mmflat, whose plunges and step-overs are such corners: 37.28 -> 37.59 s
against a verified 38.32 s, acc+freq); on paths of many short segments at low speed
(lcnc_sam_tolerance_issue, one frequency) it is still some 11 % below it (acc+freq).

Where that 11 % is, measured (acc+freq, default machine, the programme run on parts of
the one rest-to-rest piece): over the first 164 mm (two long moves) 0.910 s against the
motion's 0.939 s; over the last 4 mm, fourteen blocks of 0.1-0.5 mm with corner caps of
0.8-8.6 mm/s, 1.023 s against 1.254 s. There the shortest path turns inside blocks and
pays about ``g`` per stretch (from 166.53 mm to the end six stretches, 0.400 s, against
the motion's 0.509 s). Motions sketched by hand from 166.58 mm to the end (estimates,
not checked profiles), with phases that creep, jump and creep as the rule accepts
(:mod:`reference.core.phases`), come to about the motion's 0.495 s, and the exploratory
lattice search that module cites found 1.25 s on the tail. Those were the motion's
numbers before :mod:`optimal.freq.free_phases`: its NLP with the phases' ends free in
path position takes the whole program from 2.3261 to 2.1482 s (checked), so on sam the
upper side was the weaker one. Where the 3.96 % still open lies is not known. One
suspect was tested and gained almost nothing: a fall phase ``[t_0, t_1]`` that changes
the speed by ``D_b`` before a corner (passed at ``t_x``) and by ``D_a`` after it has
``D_b (t_x - t_0) + D_a (t_1 - t_0) >= (D_b + D_a) g / 2`` (its acceleration-weighted
mean time is at least ``g/2`` after its start), so a fall from a peak far above a cap
just after it lasts long. A prototype of the programme that carried
the peak's speed in levels (as step 4c carries the valley's) and charged every fall that
passes a cap this bound raised the piece's bound by 0.001 s only (1.9332 -> 1.9342 s,
with 6 and 12 levels of ratio 0.8, the bound taken at the least cap between peak and
valley): its shortest path then peaks at about the cap's speed and pays the same ``g``
per stretch. Two further tries gained nothing there either (measured 2026-12-07, not
kept). A bound on the top speed a stretch reaches in its distance: a rise's phases gain
``int (w - w_a) dt >= sum_P dv_P tail_P``, the same weights as the lost time, so
``int_u^V gamma / 2 <= d_max + (2 delta - u_lo) T``, with ``d_max`` from the valley
cell's start to the peak cell's end, ``u_lo`` the valley level's lower end and
``gm <= T <= T_up`` (falls mirrored, with the leads). It is valid, but it left every
bound the same with two peak levels (sam 1.93299 s, lcnc_arc_arc_sawtooth 5.17477 s,
lcnc_test_12mmflat 37.58713 s on their fine cells). With six peak levels of ratio 0.6
sam reached only 1.93597 s (eight of 0.7: 1.93629 s), because the shortest path moves
its turns and still pays about ``g`` per stretch. On the upper side, a local search
moved each phase boundary of the NLP with the rule's rows (:mod:`optimal.freq.phase_nlp`)
by 1, 3 and 6 grid nodes. Over about 200 s it took sam from 2.3286 to 2.3237 s (0.2 %);
the free phase ends (above) gained 7.6 %.

Units: mm, s, mm/s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from reference.core.geometry import Path
from reference.core.limits import AxisArrays
from reference.core.phases import FREQ_ACCEL_TOL_REL
from reference.core.tolerances import RATIO_TOL, VEL_TOL_MM_S

from ..bounds import speed_envelope_bounds
from ..grid import Grid
from ..tolerances import LB_ROUNDOFF_REL
from .lower import path_accel_bound, rest_pieces, segment_periods

__all__ = ["HUMP_CELL_TIME_REL", "HUMP_CHAIN_PERIODS", "HUMP_COARSE_CELL_TIME_REL",
           "HUMP_PEAK_LEVELS", "HUMP_PEAK_RATIO",
           "HUMP_MAX_CELLS", "HUMP_MERGE_SHARE", "HUMP_REFINE_MARGIN", "HUMP_SPREAD_REL",
           "HUMP_SLACK_LEVELS", "HUMP_SPEED_LEVELS", "HUMP_SPEED_RATIO",
           "HUMP_SPREAD_ROUNDS", "HUMP_TURN_MARGIN", "HUMP_TURN_SPLIT", "HUMP_TURN_WIDTH",
           "Envelope",
           "HumpPlan", "hump_lower_bound", "hump_plan", "humps_bound", "humps_piece_bounds"]

#: Cells are cut so that each takes at most this fraction of its period at the fastest
#: speed the envelope allows in it. Each turn leaves out its cell's time (step 4 of the
#: module docstring); a hump lasts at least two periods, so this keeps that loss near
#: 3 % of a hump's shortest time on uniform paths, while the programme's work grows as
#: the cells' count times the window's.
HUMP_CELL_TIME_REL = 0.02

#: Cells of the first, coarse run (:func:`humps_bound`): five times fewer turns' worth of
#: cells, about 25 times less work; its bound is some 10-15 % below the fine one where
#: the rule decides (measured on the corpus), so the fine run follows only where the
#: coarse bound comes within HUMP_REFINE_MARGIN of the best bound known.
HUMP_COARSE_CELL_TIME_REL = 0.1

#: See HUMP_COARSE_CELL_TIME_REL.
HUMP_REFINE_MARGIN = 0.2

#: Cells shorter together than this share of the cell size are merged
#: (:func:`_merged`): the grid's tiny intervals on short segments would otherwise fill
#: the programme's reach with cells. A quarter keeps the bound (lcnc_sam_tolerance_issue:
#: 1.9767 s against 1.9772 s unmerged; merging up to the full size lost 6 %) at a third
#: of the work on lcnc_test_12mmflat. (This constant said a half while
#: :func:`_merge_starts` used a quarter written out; the measurements are the code's.)
HUMP_MERGE_SHARE = 0.25

#: Ceiling on the number of cells (work and memory of the programme: about
#: ``cells x window`` float64 operations). Above it the cells get longer, which only
#: weakens the bound, and :func:`_spread` does not cut at all. Measured on
#: lcnc_test_12mmflat (``acc+freq``, one piece of 38 s; 24,512 cells of
#: HUMP_CELL_TIME_REL, 84,935 after the cuts of :func:`_spread`): a ceiling of 20,000
#: gave 37.107 s of bound (its ``compare`` 38 s, 296 MB), 100,000 37.285 s (69 s, 316 MB),
#: 400,000 37.290 s (and twice the time); measured before the weights of step 3 and the
#: peak levels of step 4d, with which 100,000 gives 37.587 s.
HUMP_MAX_CELLS = 100_000

#: Cells whose speed bounds differ by more than this share (``hi > (1 + x) lo``) are cut
#: further in the programme's last run (:func:`_spread`): near corners the envelope climbs
#: steeply, and ``ds / hi`` falls short of the time there. 1 % keeps that shortfall at
#: the level of the bracket's own 2 % while adding cells only near corners and ends
#: (lcnc_sam_tolerance_issue: 1.98 -> 2.07 s of bound).
HUMP_SPREAD_REL = 0.01

#: Rounds of four-way cuts of :func:`_spread` (each quarters the spread of a cell on a
#: tent's straight side).
HUMP_SPREAD_ROUNDS = 6

#: The turn run (:func:`humps_bound`): each turn of the fine run's shortest path and this
#: many cells either side of it are cut into :data:`HUMP_TURN_SPLIT` cells, and the
#: programme runs once more. A turn leaves up to its cell's time uncharged (step 4b), and
#: the next shortest path turns near the last one's, so cutting there recovers most of
#: what uniformly finer cells would, at a fraction of the cells. Measured on
#: lcnc_arc_arc_sawtooth (``acc+freq``, default machine; bracket 2.06 % without the run):
#: 0 cells either side 1.91 %, 1: 1.70 %, 2 and 3: 1.67 %; a second run adds nothing.
#: (Uniform cells of 1 % of a period instead of 2 %: 1.82 %, at 14 times the work.)
#: Those figures are under a HUMP_MAX_CELLS of 20,000. Under 100,000 the fine run's cuts
#: of :func:`_spread` reach 1.70 % on the sawtooth by themselves (93,410 cells; its
#: bound 5.1752 s is above the one that meets the bracket, 5.1601 s), so the run does
#: not follow there; on lcnc_test_12mmflat it would pass the ceiling (84,935 cells before
#: it) and is left out. Allowed a ceiling of 200,000, the cuts go on (144,566 cells,
#: bound 37.2849 -> 37.2899 s) and the turn run after them adds nothing, at 1.7 times
#: the oracle's wall time (57.7 -> 98.6 s; these before the weights of step 3 and the
#: peak levels of step 4d, with which the fine run alone meets the bracket there).
HUMP_TURN_WIDTH = 2

#: See HUMP_TURN_WIDTH. Eight instead of four: 1.67-1.74 %, no better.
HUMP_TURN_SPLIT = 4

#: The turn run follows only where the bound after the fine run comes within this share
#: of the bound the caller needs (``enough`` of :func:`humps_bound`). The run raised the
#: bound by 0.2-0.4 % where measured (lcnc_arc_arc_sawtooth 0.39 %, lcnc_test_12mmflat
#: 0.21 %) and costs about a fine run (12mmflat: 14 -> 52 s of bound), so further away
#: it would not meet the bracket and only take time.
HUMP_TURN_MARGIN = 0.01

#: Levels of the slack a stretch leaves (step 4b), in shares of the next turn cell's
#: time: a stretch whose bound is set by ``g`` or the lost time with room to spare may
#: absorb that much of the turn cell, and the next stretch is charged the rest, rounded
#: down to a level. Quarters: at most a quarter of a cell per turn goes uncharged.
HUMP_SLACK_LEVELS = np.array([0.0, 0.25, 0.5, 0.75, 1.0])

#: Valley speed levels (step 4c): a valley's speed is carried from the fall into it to
#: the rise out of it in levels of ``lo ratio^k`` of the valley cell's ``lo``, so that
#: both stretches' lost time use the lower of their two bounds on it. Ratio 0.7 over 7
#: levels reaches 12 % of ``lo``; a level's width costs at most ``(1 - ratio) u g / (2 V)``
#: of lost time per stretch. The work grows with the levels: 13 levels (down to 1.4 %)
#: gave the same bounds on the corpus programs where the programme decides (measured
#: on the fine cells: lcnc_sam_tolerance_issue 1.93299 s both, lcnc_arc_arc_sawtooth's
#: first 8,000 cells 2.14296 against 2.14291 s, lcnc_test_12mmflat's 7.39289 s both) at
#: about twice the time.
HUMP_SPEED_RATIO = 0.7

#: See HUMP_SPEED_RATIO.
HUMP_SPEED_LEVELS = 7

#: Peak speed levels (step 4d): the rise's top speed is carried to the fall after it in
#: two levels, above and below this share of the peak cell's ``hi``.
#: Without them a rise may take the low top speed that suits it (a creep over a corner
#: between axes of different frequencies costs less than the phase that climbs out of
#: it) while the fall after it takes the cell's full speed. Measured on
#: lcnc_test_12mmflat (``acc+freq``, fine cells): 37.348 s of bound with one level,
#: 37.593 s with two at 0.3, 37.468 s at 0.2; three or four levels gave no more.
HUMP_PEAK_RATIO = 0.3

#: See HUMP_PEAK_RATIO.
HUMP_PEAK_LEVELS = 2

#: A stretch may be cut into pieces of at least this many periods (step 4). A cut forgets
#: that the speed before it stays below the speeds after it, and a cut stretch carries
#: no lost time (``LT``, up to half a period per stretch: the whole of the rule's cost
#: at an isolated corner); edges need only reach ``HUMP_CHAIN_PERIODS + 1`` periods (the
#: work grows with the reach). 24 periods keep whole the stretches of corners a second
#: apart at 20 Hz (lcnc_corner_decel: 8 periods gave 6.99 s of bound, 24 give 7.10 s).
HUMP_CHAIN_PERIODS = 24.0


@dataclass(frozen=True, slots=True)
class Envelope:
    """Speed bounds per cell for :func:`hump_lower_bound`.

    Attributes
    ----------
    s : numpy.ndarray, shape (N + 1,)
        Cell ends, mm.
    hi : numpy.ndarray, shape (N,)
        Upper bound of the speed everywhere in the cell, mm/s.
    lo : numpy.ndarray, shape (N,)
        Upper bound of the speed at some point of the cell, mm/s (``<= hi``).
    period : numpy.ndarray, shape (N,)
        Shortest phase a motion may have in the cell, s.
    accel : float
        Bound on ``|s''|`` of every motion (``abar`` of step 2), mm/s^2.
    interval : numpy.ndarray of int64, shape (N,), optional
        Grid interval of each cell (for cutting cells further).
    """

    s: np.ndarray
    hi: np.ndarray
    lo: np.ndarray
    period: np.ndarray
    accel: float
    interval: np.ndarray | None = None


def _tent(x: np.ndarray, s0, s1, b0, b1, B, M) -> np.ndarray:
    """``phi`` of the module docstring at ``x`` inside the interval ``[s0, s1]``."""
    with np.errstate(invalid="ignore"):
        t = np.minimum(b0 + M * (x - s0), b1 + M * (s1 - x))
    t = np.where(np.isfinite(M), t, np.inf)
    # the node bounds hold at the nodes themselves whatever the slope
    t = np.where(x <= s0, np.minimum(t, b0), t)
    t = np.where(x >= s1, np.minimum(t, b1), t)
    return np.minimum(t, B)


@dataclass(frozen=True, slots=True, eq=False)
class _Tents:
    """The relaxation's bound ``phi`` on every interval (step 1), for cutting cells."""

    s: np.ndarray        # (N + 1,) nodes, mm
    b0: np.ndarray       # (N,) node bound at the start, mm^2/s^2
    b1: np.ndarray       # (N,) node bound at the end
    B: np.ndarray        # (N,) interval bound
    M: np.ndarray        # (N,) slope, inf where none
    top: np.ndarray      # (N,) where the tent peaks, from the start, mm
    period: np.ndarray   # (N,) shortest phase, s
    accel: float         # abar, mm/s^2


def _tents(path: Path, lim: AxisArrays, grid: Grid,
           bounds: tuple[np.ndarray, ...] | None) -> _Tents:
    b_hat, B, M, _ = bounds if bounds is not None else speed_envelope_bounds(path, lim, grid)
    b_hat = np.maximum(b_hat, 0.0)
    s = grid.s
    D = np.diff(s)
    b0, b1 = b_hat[:-1], b_hat[1:]
    good = np.isfinite(M) & (M > 0)
    Mg = np.where(good, M, np.inf)
    with np.errstate(invalid="ignore", divide="ignore"):
        top = np.where(good, np.clip((b1 - b0 + Mg * D) / (2 * np.where(good, Mg, 1.0)),
                                     0.0, D), 0.0)
    per = segment_periods(path, lim)[grid.segment] / (1.0 + RATIO_TOL)
    # |s''| <= M / 2 where the slopes are finite; the axes' bound holds everywhere
    a_bar = path_accel_bound(path, lim)
    if np.all(np.isfinite(M)):
        a_bar = min(a_bar, 0.5 * float(np.max(M, initial=0.0)) * (1.0 + RATIO_TOL))
    return _Tents(s, b0, b1, B, Mg, top, per, a_bar)


def _cells(t: _Tents, k: np.ndarray, x0: np.ndarray, x1: np.ndarray) -> Envelope:
    """Cells ``[x0, x1]`` inside intervals ``k`` (in order, covering the path)."""
    good = np.isfinite(t.M[k])
    args = (t.s[k], t.s[k + 1], t.b0[k], t.b1[k], t.B[k], t.M[k])
    f0 = _tent(x0, *args)
    f1 = _tent(x1, *args)
    apex = np.clip(t.s[k] + t.top[k], x0, x1)
    # phi is concave: its top on the cell is at the tent's apex clipped to the cell, or
    # B where the slope bounds nothing
    hi = np.where(good, np.maximum(np.maximum(f0, f1), _tent(apex, *args)),
                  np.maximum(np.maximum(f0, f1), t.B[k]))
    lo = np.minimum(f0, f1)
    # the checker's slack on every speed limit
    scale = 1.0 + RATIO_TOL
    return Envelope(s=np.concatenate((x0, [t.s[-1]])),
                    hi=np.sqrt(np.maximum(hi, 0.0)) * scale,
                    lo=np.sqrt(np.maximum(lo, 0.0)) * scale, period=t.period[k],
                    accel=t.accel, interval=k)


def _split(t: _Tents, k: np.ndarray, x0: np.ndarray, x1: np.ndarray,
           pieces: np.ndarray) -> Envelope:
    """Cells ``[x0, x1]`` of intervals ``k``, each cut into ``pieces`` equal cells."""
    pieces = np.maximum(pieces.astype(np.int64), 1)
    rep = np.repeat(np.arange(k.size), pieces)
    first = np.concatenate(([0], np.cumsum(pieces)[:-1]))
    j = np.arange(rep.size) - first[rep]
    w = x1[rep] - x0[rep]
    a = x0[rep] + w * (j / pieces[rep])
    b = np.where(j + 1 == pieces[rep], x1[rep], x0[rep] + w * ((j + 1) / pieces[rep]))
    return _cells(t, k[rep], a, b)


def _envelope(t: _Tents, cell_time_rel: float, max_cells: int) -> Envelope:
    """Cells of the relaxation's intervals, each at most ``cell_time_rel`` periods long
    at speed ``hi`` (at most ``max_cells`` of them: longer cells only weaken the bound),
    with their speed bounds (step 1)."""
    whole = _cells(t, np.arange(t.b0.size), t.s[:-1], t.s[1:])
    pieces = _pieces(whole, cell_time_rel)
    total = float(pieces.sum())
    if total > max_cells:
        # longer cells only weaken the bound; spread what the ceiling allows
        pieces = np.clip(np.floor(pieces * (max_cells - pieces.size) / total), 0, None) + 1
    return _split(t, whole.interval, whole.s[:-1], whole.s[1:], pieces)


def _spread(t: _Tents, env: Envelope, spread: float, max_cells: int) -> Envelope:
    """``env`` with every cell whose speed bounds differ by more than ``spread``
    (``hi > (1 + spread) lo``) cut into four, repeatedly, up to ``max_cells`` cells.

    Near a corner the envelope climbs from the corner's cap within a fraction of a
    millimetre, and a cell's time ``ds / hi`` there is far below the time at the speeds
    the cell actually allows; these cuts make it the envelope's own time to within
    ``spread``. Valid for any cut (step 1 holds on every cell).
    """
    for _ in range(HUMP_SPREAD_ROUNDS):
        with np.errstate(divide="ignore", invalid="ignore"):
            wide = env.hi > (1.0 + spread) * env.lo
        n_new = env.hi.size + 3 * int(np.count_nonzero(wide))
        if not np.any(wide) or n_new > max_cells or env.interval is None:
            break
        env = _split(t, env.interval, env.s[:-1], env.s[1:], np.where(wide, 4, 1))
    return env


def _merge_starts(env: Envelope, cell_time_rel: float) -> np.ndarray:
    """First cell of each run of :func:`_merged`, shape (M,) (all cells: none merged)."""
    ds = np.diff(env.s)
    with np.errstate(divide="ignore", invalid="ignore"):
        fast = np.where(env.hi > 0, ds / env.hi, np.inf)
    target = cell_time_rel * HUMP_MERGE_SHARE * np.maximum(env.period, 1e-300)
    before = np.concatenate(([0.0], np.cumsum(fast / target)[:-1]))
    key = np.floor(np.where(np.isfinite(before), before, np.arange(before.size) + 1e300))
    return np.concatenate(([0], np.flatnonzero(np.diff(key) != 0) + 1))


def _merged(env: Envelope, cell_time_rel: float,
            starts: np.ndarray | None = None) -> Envelope:
    """Runs of cells shorter together than ``HUMP_MERGE_SHARE * cell_time_rel`` periods at
    speed ``hi``, each made one cell (short segments make many tiny cells, and the
    programme's work grows with the cells in reach); ``starts``: the runs' first cells
    where known (:func:`_merge_starts`). Valid: the merged cell's ``hi`` is the largest
    of its parts' (a bound everywhere in it), its ``lo`` the least (the least bound over
    the cell), its period the least."""
    if starts is None:
        starts = _merge_starts(env, cell_time_rel)
    if starts.size == env.hi.size:
        return env
    return Envelope(s=np.concatenate((env.s[starts], env.s[-1:])),
                    hi=np.maximum.reduceat(env.hi, starts),
                    lo=np.minimum.reduceat(env.lo, starts),
                    period=np.minimum.reduceat(env.period, starts), accel=env.accel,
                    interval=None if env.interval is None else env.interval[starts])


def _pieces(env: Envelope, cell_time_rel: float) -> np.ndarray:
    """Pieces per cell for cells of at most ``cell_time_rel`` periods at speed ``hi``."""
    with np.errstate(divide="ignore", invalid="ignore"):
        want = np.diff(env.s) / env.hi / (cell_time_rel * env.period)
    want = np.where(np.isfinite(want) & (env.period > 0), want, 1.0)
    return np.clip(np.ceil(want), 1, None)


@dataclass(frozen=True, slots=True)
class HumpPlan:
    """The shortest path of step 4: its length and where it turns.

    Attributes
    ----------
    time_s : float
        Lower bound on the motion time over the cells, holds excluded, s.
    valleys, peaks : numpy.ndarray of int64
        Cells of the path's valleys (first and last cell included) and peaks, in order;
        one more valley than peaks. Empty when the programme has no path.
    """

    time_s: float
    valleys: np.ndarray
    peaks: np.ndarray


# state kinds of the programme, for the way back
_VALLEY, _PEAK, _RISE_CUT, _FALL_CUT = 0, 1, 2, 3


def hump_plan(env: Envelope, drift: float = 0.0,
              chain: float = HUMP_CHAIN_PERIODS) -> HumpPlan:
    """The shortest path of step 4 of the module docstring, with its turns.

    Parameters
    ----------
    env : Envelope
        Cells and speed bounds.
    drift : float
        ``delta`` of step 2, mm/s (``>= 0``).
    chain : float
        A stretch may be cut once its piece holds this many periods (step 4).

    Returns
    -------
    HumpPlan
    """
    s = env.s
    ds = np.diff(s)
    N = ds.size
    none = np.zeros(0, np.int64)
    if N < 3:
        return HumpPlan(0.0, none, none)
    # step 2's drift, and the checker's standstill: at a stop it accepts up to
    # VEL_TOL_MM_S where the relaxation has b = 0
    slack = 2.0 * drift + VEL_TOL_MM_S
    # a cell's own bound on v needs the standstill tolerance only; bounds carried along
    # a stretch by the monotonicity of w (the running minima, the valley's speed) also
    # the drift (step 2)
    hi = env.hi + VEL_TOL_MM_S
    hi_m = env.hi + slack
    lo = np.minimum(env.lo, env.hi) + slack
    g = env.period
    with np.errstate(divide="ignore"):
        fast = ds / hi
    # a turn cell's own time (step 4b): at least its length at the cell's top speed
    turn_t = fast
    # reach of the edges: from every start, chain + 1 of the largest period at speed hi
    cum = np.concatenate(([0.0], np.cumsum(fast)))
    need = (chain + 1.0) * float(np.max(g))
    # edges from cell i reach cell last[i]; last is nondecreasing, so the cells whose
    # edges reach c start at first[c]
    last = np.minimum(np.searchsorted(cum, cum[:-1] + need, side="left") + 2, N - 1)
    first = np.searchsorted(last, np.arange(N), side="left")
    # the cost of the best path to each state, turns (valley, peak) per slack level of
    # step 4b and cuts (which leave no cell out), and for the way back each state's
    # predecessor (kind, level, cell): compiled (optimal.freq.humps_kernel), the states
    # and costs of steps 3, 4 and 4b as plain loops
    from .humps_kernel import programme, unpack
    valley, _, _, pv, pp, pc = programme(np.ascontiguousarray(s, np.float64), hi, hi_m, lo,
                                   np.ascontiguousarray(g, np.float64), turn_t,
                                   first.astype(np.int64), last.astype(np.int64),
                                   float(chain), HUMP_SLACK_LEVELS, HUMP_SPEED_RATIO,
                                   HUMP_SPEED_LEVELS, HUMP_PEAK_RATIO, HUMP_PEAK_LEVELS,
                                   2.0 * drift)
    last_v = valley[:, :, N - 1]
    q, k = np.unravel_index(int(np.argmin(last_v)), last_v.shape)
    T = float(last_v[q, k])
    if not math.isfinite(T):
        return HumpPlan(T, none, none)
    valleys, peaks = [], []
    kind, cell = _VALLEY, N - 1
    while cell >= 0:
        if kind == _VALLEY:
            valleys.append(cell)
        elif kind == _PEAK:
            peaks.append(cell)
        x = (pv[q, k, cell] if kind == _VALLEY else pp[q, k, cell] if kind == _PEAK
             else pc[kind - _RISE_CUT, cell])
        kind, q, k, cell = unpack(x, HUMP_SLACK_LEVELS.size,
                                  max(HUMP_SPEED_LEVELS, HUMP_PEAK_LEVELS))
    return HumpPlan(T, np.array(valleys[::-1], np.int64), np.array(peaks[::-1], np.int64))


def hump_lower_bound(env: Envelope, drift: float = 0.0,
                     chain: float = HUMP_CHAIN_PERIODS) -> float:
    """:attr:`HumpPlan.time_s` of :func:`hump_plan`, s."""
    return hump_plan(env, drift, chain).time_s


def humps_bound(path: Path, lim: AxisArrays, grid: Grid, t_upper: float,
                beat: float = 0.0, segment_floor: np.ndarray | None = None,
                enough: float = math.inf) -> float:
    """Lower bound on the motion time under ``acc+freq`` (holds excluded), s: the sum of
    :func:`humps_piece_bounds` (same parameters)."""
    return float(np.sum(humps_piece_bounds(path, lim, grid, t_upper, beat, segment_floor,
                                           enough)))


def humps_piece_bounds(path: Path, lim: AxisArrays, grid: Grid, t_upper: float,
                       beat: float = 0.0, segment_floor: np.ndarray | None = None,
                       enough: float = math.inf, node_caps: np.ndarray | None = None
                       ) -> np.ndarray:
    """Lower bound on the time of each rest-to-rest piece under ``acc+freq`` (holds
    excluded), s; under ``jerk+freq`` with ``node_caps``.

    Per rest-to-rest piece (:func:`optimal.freq.lower.rest_pieces`) the larger of the
    ``acc`` relaxation's time on the piece and the turn programme on the piece's cells,
    summed. Both bound the time spent between the piece's ends: the relaxation's
    interval estimates hold one by one (:func:`optimal.bounds.speed_envelope_bounds`),
    and a motion turns from falling to rising at each stop (its speed cannot fall below
    zero), so the programme applies to each piece alone, from a valley to a valley.

    Parameters
    ----------
    path : Path
        Restricted to its moving axes.
    lim : AxisArrays
        Limits of ``path.axes``.
    grid : Grid
        Nodes of the ``acc`` relaxation.
    t_upper : float
        A time (holds excluded), s: the bound holds for every motion no slower than it
        (step 2's drift grows with it), so ``min(bound, t_upper)`` holds for every
        motion; a verified upper bound of the minimum keeps that at the bound.
    beat : float
        The best lower bound known so far, s. The programme runs on coarse cells
        (:data:`HUMP_COARSE_CELL_TIME_REL`) first, and on fine ones, cut further where the
        envelope climbs (:data:`HUMP_SPREAD_REL`), only on the pieces where that comes
        within :data:`HUMP_REFINE_MARGIN` of their ``acc`` time, and only while the sum
        comes that near ``beat``. Effort only: every run gives a bound.
    segment_floor : numpy.ndarray, shape (m,), optional
        Certified time per segment of the base bound set
        (:attr:`optimal.solution.OptimalSolution.segment_lower_bounds_s`, the ``jerk``
        oracle's): taken per segment where larger than the ``acc`` relaxation's.
    enough : float
        A bound the caller needs no more than, s (the oracle: the bound that meets its
        bracket). Where the fine run's sum is below it but within
        :data:`HUMP_TURN_MARGIN` of it, the turn run follows: the cells at and beside
        each turn of the fine run's shortest paths (:data:`HUMP_TURN_WIDTH`) cut into
        :data:`HUMP_TURN_SPLIT`, the programme run again on the same pieces. Effort only,
        as ``beat``: the bound holds for any cells (step 1 holds on every cell).
    node_caps : numpy.ndarray, shape (N + 1,), optional
        Upper bounds of the speed at the grid's nodes valid for every motion the bound
        is for (mm/s; for ``jerk+freq`` the reach envelope,
        :func:`optimal.jerk.lower.reach_speed_caps`): they lower ``b_hat`` of step 1.
        The tents stay valid (each motion has ``b(s_k) <= b_hat_k`` and the slope bound
        ``M_k`` of the ``acc`` problem, whose motions include these), so the programme
        then bounds the time of every such motion.

    Returns
    -------
    numpy.ndarray, shape (P,)
        One per piece of :func:`optimal.freq.lower.rest_pieces`, s; 0 where the rule
        does not apply.
    """
    pieces = rest_pieces(path)
    if path.n_segments == 0 or not math.isfinite(t_upper):
        return np.zeros(pieces.shape[0])
    bounds = speed_envelope_bounds(path, lim, grid)
    if node_caps is not None:
        caps = np.asarray(node_caps, dtype=np.float64)
        bounds = (np.minimum(bounds[0], caps * caps),) + tuple(bounds[1:])
    t = _tents(path, lim, grid, bounds)
    drift = FREQ_ACCEL_TOL_REL * t.accel * t_upper
    if not np.any(t.period > 0) or not math.isfinite(drift):
        return np.zeros(pieces.shape[0])
    ends = grid.break_node[pieces]                     # (P, 2) first and end interval
    seg_t = np.bincount(grid.segment, weights=bounds[3], minlength=path.n_segments)
    if segment_floor is not None and segment_floor.shape == seg_t.shape:
        seg_t = np.maximum(seg_t, np.where(np.isfinite(segment_floor), segment_floor, 0.0))
    acc = np.add.reduceat(seg_t, pieces[:, 0]) if pieces.size else np.zeros(0)
    dp = np.zeros(pieces.shape[0])
    todo = np.ones(pieces.shape[0], bool)
    runs = ((HUMP_COARSE_CELL_TIME_REL, False), (HUMP_CELL_TIME_REL, True))
    for rel, spread in runs:
        env = _envelope(t, rel, HUMP_MAX_CELLS)
        if spread:
            env = _spread(t, env, HUMP_SPREAD_REL, HUMP_MAX_CELLS)
        turns = _run_pieces(env, ends, np.flatnonzero(todo), rel, drift, dp)
        T = float(np.sum(np.maximum(acc, dp)))
        if spread:
            break
        # fine cells only for the pieces where the coarse run comes near the acc bound,
        # and only while the whole can come near the best bound known
        todo = dp >= (1.0 - HUMP_REFINE_MARGIN) * acc
        if T < (1.0 - HUMP_REFINE_MARGIN) * beat or not np.any(todo):
            return np.maximum(acc, dp)
    if not (T < enough and T >= (1.0 - HUMP_TURN_MARGIN) * enough) or not turns.any():
        return np.maximum(acc, dp)
    cut = np.where(turns, HUMP_TURN_SPLIT, 1)
    if int(cut.sum()) > HUMP_MAX_CELLS:
        return np.maximum(acc, dp)
    # only the pieces with a cell cut run again (the others' cells are the same)
    lo, hi = _piece_cells(env, ends)
    n_cut = np.concatenate(([0], np.cumsum(turns)))
    again = np.flatnonzero(todo & (n_cut[hi] > n_cut[lo]))
    env = _split(t, env.interval, env.s[:-1], env.s[1:], cut)
    _run_pieces(env, ends, again, HUMP_CELL_TIME_REL, drift, dp)
    return np.maximum(acc, dp)


def _piece_cells(env: Envelope, ends: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """First and end cell of each piece (its first and end grid intervals ``ends``,
    shape (P, 2)), shape (P,) each: cells never straddle intervals."""
    return (np.searchsorted(env.interval, ends[:, 0], side="left"),
            np.searchsorted(env.interval, ends[:, 1], side="left"))


def _run_pieces(env: Envelope, ends: np.ndarray, todo: np.ndarray, rel: float,
                drift: float, dp: np.ndarray) -> np.ndarray:
    """The programme on the cells of each piece ``todo`` (their first and end grid
    intervals ``ends``, shape (P, 2)), cells of ``rel`` periods merged
    (:func:`_merged`); raises ``dp`` (shape (P,), s) in place to each bound found, less
    the round-off of the programme's sums (as the relaxation's own times). Returns, per
    cell of ``env``, whether it lies within :data:`HUMP_TURN_WIDTH` merged cells of a
    turn of a shortest path (its inner valleys and peaks), shape (N,) of bool."""
    lo, hi = _piece_cells(env, ends)
    # +1 where a turn's neighbourhood starts, -1 where it ends: marked where the sum > 0
    depth = np.zeros(env.hi.size + 1, np.int64)
    w = HUMP_TURN_WIDTH
    for k in todo:
        a, b = lo[k], hi[k]
        part = Envelope(s=env.s[a:b + 1], hi=env.hi[a:b], lo=env.lo[a:b],
                        period=env.period[a:b], accel=env.accel)
        starts = _merge_starts(part, rel)
        plan = hump_plan(_merged(part, rel, starts), drift)
        x = plan.time_s * (1.0 - LB_ROUNDOFF_REL)
        if not math.isfinite(x):              # no path cannot happen with the cuts
            continue
        dp[k] = max(dp[k], x)
        # the merged cells c - w .. c + w of each turn c, as cells of env
        edges = np.concatenate((starts, [b - a]))
        c = np.concatenate((plan.valleys[1:-1], plan.peaks))
        np.add.at(depth, a + edges[np.maximum(c - w, 0)], 1)
        np.add.at(depth, a + edges[np.minimum(c + w + 1, starts.size)], -1)
    return np.cumsum(depth[:-1]) > 0
