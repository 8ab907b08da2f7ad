"""copp (TOPP3-SOCP, the ``copp-py`` package) on our :class:`Path`: a test-time reference.

copp (Wang et al., IJMTM 215, 2026) solves jerk-limited time-optimal path
parameterisation as a sequence of second-order cone programs (Clarabel): the node
profile ``a_k = s'^2``, ``b_k = s''`` (copp's names; ours are ``b = v^2``, ``a = s''``)
with ``b`` linear in ``s`` on every interval, per-axis velocity, acceleration and jerk
rows at the nodes, and the non-convex jerk row ``sqrt(a) (q' c + 3 q'' b + q''' a) <= J``
(``c = db/ds``) replaced by its tangent in ``a`` around a reference profile. The tangent
of the convex ``J / sqrt(a)`` lies below it, so every round is feasible at the nodes and
re-linearising around the last round never makes the time worse.

This module is not a test (no ``test_`` prefix); ``tests/optimal/test_copp.py`` and
``tests/bench/bench_copp.py`` import it. :func:`solve_copp` is the one entry point.

Decisions (each measured; numbers in ``test_copp.py`` and the benchmark):

* **units**: time unit ``A/J`` and length unit ``A^3/J^2`` (``A``, ``J``: the largest
  acceleration and jerk limit of the moving axes), so speeds, accelerations and jerks
  of the scaled problem are near 1. In mm and s (the same code, units 1) its rounds
  do not settle and stop far too slow: measured at 500 nodes, 0.613 s on a 100 mm line
  (ruckig 0.5000 s) and 2.04 s on the stadium (scaled: 1.7298 s).
* **linearisation**: copp's own TOPP2-RA (velocity and acceleration only) gives the
  first reference; then TOPP3-SOCP is re-solved around its own last profile, with
  ``b_linearization`` (copp's adaptive anchoring, which its documentation recommends
  when ``a`` comes near 0: it always does at rest) until the time changes by less than
  :data:`ROUND_RTOL` (2-4 re-solves, at most :data:`MAX_ROUNDS`).
* **rest**: both ends at rest with zero path acceleration (copp's stationary boundary
  interval, a constant-``s'''`` ramp from rest). The rulebook also allows an
  acceleration step of ``J T_ipo`` at the path ends
  (:mod:`reference.core.rules`, "acceleration steps"); copp cannot take it: with
  ``a = 0, b != 0`` at a boundary its ``c = s'''/s'`` model degenerates (measured on a
  100 mm line: 0.579 s against ruckig's 0.4924 s, and Clarabel fails at 3,000 nodes).
  So copp solves rest-to-rest without the end steps: on a single line of the default
  machine that costs it 7.6 ms (ruckig: 0.5000 s without, 0.4924 s with the steps).
* **first jerk ramp**: copp's stationary interval is one constant-jerk ramp from rest;
  unless a node sits where the optimum's first ramp ends, the intervals after it
  (``c`` constant, so ``s'''`` proportional to ``s'``) cannot follow ``s''' = J`` at low
  speed and copp under-uses the jerk limit, and a finer grid does not help (measured
  on a 100 mm line against ruckig: +0.18 % at 300 nodes, +0.37 % at 1,000, +0.42 % at
  3,000; with the node: +1.4e-5, +3.9e-6, +1.3e-6 relative). The node goes at the end of the
  1-D ramp along the first (last) tangent, :func:`ramp_length`, and the nodes before it
  are dropped, so the stationary interval is that ramp; then copp converges to ruckig.
* **curvature jumps** (line into arc, S-bend): copp's rows are pointwise in ``s``:
  acceleration ``q' b + q'' a`` and jerk ``sqrt(a) (q' c + 3 q'' b + q''' a)`` at each
  node with that node's geometry, so a single node at a break would see one side only.
  Every break with a curvature jump therefore gets nodes on both sides, each with its
  own segment's derivatives, within ``2 delta`` (:data:`BREAK_HALF_GAP_REL`) of it.
  No row sees the centripetal step ``dq'' a`` across them: copp alone would cross the
  break at any speed its acceleration rows allow. The rulebook holds the axis
  acceleration step ``q'_i ds'' + dq''_i v^2``, spread over one IPO cycle, to
  ``Jstep_i T_ipo`` (PATH_TRANS_JERK_LIM at a curvature jump,
  :func:`reference.core.rules.step_jerk_limit`). The wrapper writes it in two parts:

  - centripetal part: ``a`` at the break nodes capped by
    :func:`reference.core.rules.curvature_jump_speed_cap` (a first-order row);
  - tangential part (``"step"``, the default): four nodes ``A < B < C < D`` around the
    break (``B``, ``C`` at ``-/+ delta``), and the jerk limit of ``B`` and ``C`` set so
    that the rows of the interval ``[B, C]``, ``sqrt(a) q'_i (b_C - b_B) / (C - B)``,
    read ``|q'_i ds''| <= Jstep_i T_ipo v_hat / v``, ``v_hat`` the speed cap there: the
    rule itself where the break is crossed at the cap, looser where slower. (The
    lifted limit also frees the tiny intervals ``[A, B]``, ``[C, D]`` at their inner
    ends; their outer ends keep ``J``.) With ``"pair"`` (two nodes, every jerk row
    kept) ``s''`` cannot step at all.

  The rulebook bounds the *sum* of both parts per axis; the wrapper bounds each part by
  the whole allowance. That is exact when the tangent and the curvature jump lie on
  different axes (a line along X into an arc in XY: X steps tangentially, Y
  centripetally; every test path here), a relaxation otherwise. Measured on the
  stadium at 500 nodes: "step" 1.72981 s, "pair" 1.73867 s (the tangential steps at
  four breaks are worth 0.5 %).
* **jerk between nodes**: copp's acceleration, jerk and speed rows hold at the nodes,
  and ``a = s'^2`` is quadratic in ``s`` between them. Where the jerk limit does not
  bind over a node spacing, ``s''`` can alternate from node to node and ``s'^2`` bulge
  above the speed limit between them, and copp's time drops below the exact optimum.
  On ``linuxcnc_xyz.toml`` (MAX_AX_JERK 1000 m/s^3: a jerk ramp of 0.76 ms, 7e-5 mm
  from rest) the time of a 100 mm line moved by 1-6 % between 500 and 2,000 nodes
  without settling, with each of three unit choices (the one above, ``V/A`` and
  ``V^2/A``, and a least-squares balance of ``V``, ``A`` and ``J``; on the default
  machine all three agree to 1e-7), and with the last it came out 2 % *below* ruckig's
  exact time (0.7446 s against 0.7596 s). So the wrapper refuses a path whose end
  jerk ramp is shorter than :data:`RAMP_MIN_SPACING` node spacings; copp is a
  reference for jerk-limited machines only.
* **feed**: copp has a per-node first-order row ``a <= amax`` (a path-speed cap), so the
  programmed feed is ``amax = F^2`` at the nodes of each segment; no virtual axis.

So copp solves the rulebook's problem without the end steps (a *restriction*: slower),
with the break rule as above; its limits hold at the nodes only and the tangent of
the jerk row is conservative, so its time is not a bound either way: it is compared as
a number with an error measured by its convergence over node counts (first order from
above: measured exponents 1.03-1.1 on lines, the stadium, S-bends and a line into an
arc from 250 to 4,000 nodes).

Units: mm, s unless a name says ``scaled``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from reference.core.geometry import Path, arc_segment, line_segments, path_from_pieces
from reference.core.limits import MachineLimits
from reference.core.rules import (RELAXED, curvature_jump_speed_cap, curvature_jumps,
                                  is_tangential, step_jerk_limit)

#: Half the gap of the node pair at a curvature jump, relative to the shortest
#: neighbouring interval: small enough that the pair is one place on the path (1e-4 of
#: an interval), large enough that the coefficient ``1 / (2 delta)`` of its jerk rows
#: stays within what Clarabel handles (measured on the stadium at 1,000 nodes: the time
#: moves by 4.4e-6 relative from 1e-3 to 1e-4 and by 4.4e-7 from 1e-4 to 1e-5).
BREAK_HALF_GAP_REL = 1e-4

#: Break treatment: ``"pair"`` (jerk rows across the break kept: no tangential step) or
#: ``"step"`` (the tangential step held to the rulebook's allowance, see the module
#: docstring).
BREAK_PAIR = "pair"
BREAK_STEP = "step"

#: Shortest end jerk ramp accepted, in base node spacings (see "jerk between nodes" in the
#: module docstring): measured fine from 0.73 up (the stadium at 250 nodes).
RAMP_MIN_SPACING = 0.5

#: First-order bound (scaled ``a``) written where no cap applies (copp takes finite rows).
UNCAPPED = 1e30

#: Re-linearisation stops when a round changes the time by less than this (relative).
ROUND_RTOL = 1e-6

#: Most TOPP3-SOCP solves (the first around TOPP2, the rest around the last round).
MAX_ROUNDS = 8


@dataclass(frozen=True, slots=True, eq=False)
class CoppResult:
    """copp's answer on one path and node set.

    Attributes
    ----------
    time_s : float
        Traversal time of copp's last profile (``copp.interpolation.s_to_t_topp3``:
        ``b`` linear in ``s`` per interval, integrated exactly), s.
    round_times_s : tuple[float, ...]
        Time of the TOPP2-RA reference, then of every TOPP3-SOCP round, s.
    s : numpy.ndarray, shape (K,)
        Nodes, mm.
    v, acc : numpy.ndarray, shape (K,)
        Path speed (mm/s) and path acceleration (mm/s^2) at the nodes.
    solve_time_s : float
        Wall time of the TOPP2-RA solve and every TOPP3-SOCP solve (with its
        linearisation), s; set-up (path evaluation, rows) not included.
    setup_time_s : float
        Wall time of the path evaluation and of loading the rows into copp, s.
    exceed : tuple[float, float, float]
        copp's own audit of the last profile at its nodes (first-, second-, third-order
        rows, the jerk rows in their nonlinear form; ``<= 0`` when they hold), scaled.
    """

    time_s: float
    round_times_s: tuple[float, ...]
    s: np.ndarray
    v: np.ndarray
    acc: np.ndarray
    solve_time_s: float
    setup_time_s: float
    exceed: tuple[float, float, float]

    @property
    def n_nodes(self) -> int:
        """Number of nodes ``K``."""
        return int(self.s.size)

    @property
    def rounds(self) -> int:
        """Number of TOPP3-SOCP solves."""
        return len(self.round_times_s) - 1


def copp_units(lim) -> tuple[float, float]:
    """Time and length unit of the scaled problem, s and mm (module docstring)."""
    A = float(np.max(lim.a_max))
    J = float(np.max(lim.j_max))
    return A / J, A ** 3 / J ** 2


def check_supported(path: Path) -> None:
    """Raise ``ValueError`` unless the path is one motion copp can take whole.

    The wrapper solves rest-to-rest over the whole path: no stop inside it, and no corner
    (the velocity-jump rule at a corner has no form in copp's rows).
    """
    if path.n_segments == 0:
        raise ValueError("copp wrapper: empty path")
    if np.any(path.stop[1:-1]):
        k = int(np.flatnonzero(path.stop[1:-1])[0]) + 1
        raise ValueError(f"copp wrapper: stop inside the path at break {k} "
                         f"({path.stop_reason[k]!r}); split the path there")
    t_in, t_out = path.junction_tangents()
    if t_in.shape[0] and not np.all(is_tangential(t_in, t_out, RELAXED)):
        k = int(np.flatnonzero(~is_tangential(t_in, t_out, RELAXED))[0])
        raise ValueError(f"copp wrapper: corner at break {k + 1} (s = "
                         f"{path.s_breaks[k + 1]:.6g} mm); tangent-continuous paths only")


def ramp_length(path: Path, limits: MachineLimits, end: bool = False) -> float:
    """Length of the first (``end=True``: last) jerk ramp of the 1-D rest-to-rest move
    along the first (last) segment's end tangent, mm.

    Path limits along the tangent ``t``: ``A = min_i A_i / |t_i|``, ``J = min_i J_i /
    |t_i|``, ``V = min(F, min_i V_i / |t_i|)``. From rest with zero acceleration the
    ramp at ``s''' = J`` lasts ``min(A/J, sqrt(V/J), (L/(2J))^(1/3))`` (the acceleration,
    the speed or the segment length ``L`` stops it first), over ``J t^3 / 6``.
    """
    lim = limits.for_axes(path.axes)
    k = path.n_segments - 1 if end else 0
    s0 = path.s_breaks[k + 1] if end else path.s_breaks[k]
    _, dq, _, _ = path.evaluate(np.array([s0]), segment=np.array([k]))
    t = np.abs(dq[0])
    on = t > 0
    A = float(np.min(lim.a_max[on] / t[on]))
    J = float(np.min(lim.j_max[on] / t[on]))
    V = float(min(path.feed[k], np.min(lim.v_max[on] / t[on])))
    L = float(path.length[k])
    tr = min(A / J, np.sqrt(V / J), (L / (2.0 * J)) ** (1.0 / 3.0))
    return J * tr ** 3 / 6.0


def copp_nodes(path: Path, limits: MachineLimits, base: np.ndarray,
               breaks: str = BREAK_STEP, ramp_nodes: bool = True
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """copp's nodes from ``base`` nodes: break pairs and the end-ramp nodes added.

    Parameters
    ----------
    path : Path
    limits : MachineLimits
    base : numpy.ndarray, shape (K0,)
        Increasing nodes in ``[0, L]`` (e.g. an oracle grid's ``s``), mm; the path ends
        and the breaks need not be in it.
    breaks : {"pair", "step"}
        Break treatment (module docstring).
    ramp_nodes : bool
        Put nodes at the ends of the first and last jerk ramp (:func:`ramp_length`) and
        none inside them (False: only to show what they are for).

    Returns
    -------
    s : numpy.ndarray, shape (K,)
        Strictly increasing nodes, mm.
    segment : numpy.ndarray of int, shape (K,)
        Segment whose geometry each node carries (the side of the break it lies on).
    lift : numpy.ndarray of bool, shape (K,)
        The inner two of each break's four nodes (``"step"``), whose jerk rows hold the
        tangential step.
    junction : numpy.ndarray of int, shape (K,)
        Interior break (0-based junction index) of the nodes placed around a curvature
        jump, -1 elsewhere.
    """
    if breaks not in (BREAK_PAIR, BREAK_STEP):
        raise ValueError(f"breaks must be {BREAK_PAIR!r} or {BREAK_STEP!r}, got {breaks!r}")
    L = path.total_length
    sb = path.s_breaks
    k_in, k_out = path.junction_curvatures()
    jumps = np.flatnonzero(curvature_jumps(k_in, k_out))
    base = np.asarray(base, dtype=np.float64)
    if ramp_nodes:
        r0, r1 = ramp_length(path, limits), ramp_length(path, limits, end=True)
        # the stationary intervals are the end ramps: no node inside them
        keep = (base > r0) & (base < L - r1)
        s = np.unique(np.concatenate(([0.0, r0, L - r1, L], base[keep], sb[1:-1])))
    else:
        s = np.unique(np.concatenate(([0.0, L], base[(base > 0) & (base < L)], sb[1:-1])))
    h = np.diff(s)
    extra, seg_of, lift, junction = [], [], [], []
    for j in jumps:
        x = sb[j + 1]
        i = int(np.searchsorted(s, x))          # s[i] == x
        d = BREAK_HALF_GAP_REL * min(h[i - 1], h[i])
        pts = ([x - d, x + d] if breaks == BREAK_PAIR
               else [x - 2 * d, x - d, x + d, x + 2 * d])
        half = len(pts) // 2
        extra += pts
        seg_of += [j] * half + [j + 1] * half   # segment j ends at break j + 1
        lift += [False, False] if breaks == BREAK_PAIR else [False, True, True, False]
        junction += [j] * len(pts)
    s = s[~np.isin(s, sb[jumps + 1])]
    # a node at any other break carries the segment that starts there
    seg = path.segment_index(s)
    s_all = np.concatenate((s, extra))
    seg_all = np.concatenate((seg, np.asarray(seg_of, dtype=np.int64)))
    lift_all = np.concatenate((np.zeros(s.size, bool), np.asarray(lift, dtype=bool)))
    jun_all = np.concatenate((np.full(s.size, -1), np.asarray(junction, dtype=np.int64)))
    order = np.argsort(s_all, kind="stable")
    s_all = s_all[order]
    if np.any(np.diff(s_all) <= 0):
        raise ValueError("copp wrapper: nodes not strictly increasing")
    return s_all, seg_all[order], lift_all[order], jun_all[order]


def solve_copp(path: Path, limits: MachineLimits, nodes: int | np.ndarray = 1000, *,
               breaks: str = BREAK_STEP, ramp_nodes: bool = True,
               max_rounds: int = MAX_ROUNDS, round_rtol: float = ROUND_RTOL) -> CoppResult:
    """Jerk-limited minimum time of ``path`` by copp's TOPP3-SOCP, rest to rest.

    Parameters
    ----------
    path : Path
        Tangent-continuous, no stop inside (:func:`check_supported`).
    limits : MachineLimits
        Per-axis ``v_max``, ``a_max``, ``j_max``, ``path_trans_jerk`` and ``t_ipo_s``.
    nodes : int or numpy.ndarray
        Number of evenly spaced base nodes, or the base nodes themselves (mm); break
        pairs and the end-ramp nodes are added (:func:`copp_nodes`).
    breaks : {"pair", "step"}
        Treatment of curvature jumps (module docstring).
    ramp_nodes : bool
        Nodes at the ends of the end ramps (:func:`copp_nodes`).
    max_rounds, round_rtol : int, float
        Re-linearisation stop (:data:`MAX_ROUNDS`, :data:`ROUND_RTOL`).

    Returns
    -------
    CoppResult

    Raises
    ------
    ValueError
        Unsupported path.
    copp_py.CoppError
        copp's own failure (Clarabel status not accepted) in the first round.
    """
    import copp_py as copp

    check_supported(path)
    t_setup = time.perf_counter()
    path = path.restricted(path.moving_axes())
    lim = limits.for_axes(path.axes)
    T0, L0 = copp_units(lim)
    V0, A0, J0 = L0 / T0, L0 / T0 ** 2, L0 / T0 ** 3
    base = (np.linspace(0.0, path.total_length, int(nodes)) if np.ndim(nodes) == 0
            else np.asarray(nodes, dtype=np.float64))
    h = float(np.max(np.diff(np.unique(np.concatenate(([0.0, path.total_length], base))))))
    ramp = min(ramp_length(path, limits), ramp_length(path, limits, end=True))
    if ramp < RAMP_MIN_SPACING * h:
        raise ValueError(f"copp wrapper: the end jerk ramp ({ramp:.3g} mm) is shorter than "
                         f"{RAMP_MIN_SPACING:g} node spacing ({h:.3g} mm): the jerk limit "
                         "does not hold copp's profile between its nodes; give more nodes")
    s, seg, lift, junction = copp_nodes(path, limits, base, breaks, ramp_nodes)
    K, n = s.size, path.n_axes
    q, dq, ddq, dddq = path.evaluate(s, segment=seg)
    ss = s / L0
    robot = copp.Robot(n, capacity=K)
    robot.append_s(ss)
    robot.set_q(q / L0, dq, ddq * L0, 0, dddq=dddq * L0 ** 2)
    v_lim, a_lim = lim.v_max / V0, lim.a_max / A0
    j_lim = np.broadcast_to(lim.j_max / J0, (K, n)).copy()
    if np.any(lift):
        # "step": the jerk rows of the inner interval [B, C] of a break read
        # sqrt(a) q'_i (b_C - b_B) / (C - B) <= J_inner_i; with J_inner_i =
        # Jstep_i T_ipo v_hat / (C - B) that is |q'_i (b_C - b_B)| <= Jstep_i T_ipo v_hat /
        # v: the rulebook's one-cycle step where the break is crossed at v_hat (the cap
        # below), looser where slower. The same limit at B and C also lifts the rows of
        # the tiny outer intervals [A, B], [C, D] at their inner ends (their outer ends
        # keep J_i).
        inner = np.flatnonzero(lift).reshape(-1, 2)
        jun = junction[inner[:, 0]]
        k_in, k_out = path.junction_curvatures()
        jstep = step_jerk_limit(np.ones(jun.size, bool), lim.j_max, lim.path_trans_jerk)
        v_hat = np.minimum(curvature_jump_speed_cap(k_in[jun], k_out[jun],
                                                    lim.path_trans_jerk, limits.t_ipo_s),
                           np.minimum(path.feed[jun], path.feed[jun + 1]))
        gap = s[inner[:, 1]] - s[inner[:, 0]]
        j_inner = jstep * limits.t_ipo_s * (v_hat / gap)[:, None] / J0
        j_lim[inner[:, 0]] = j_inner
        j_lim[inner[:, 1]] = j_inner
    robot.add_velocity_limits(v_lim, -v_lim, start_idx_s=0, length=K)
    robot.add_acceleration_limits(a_lim, -a_lim, start_idx_s=0, length=K)
    robot.add_jerk_limits(j_lim, -j_lim, start_idx_s=0, length=K)
    # first-order rows: the feed, and the curvature-jump speed cap at break nodes
    cap = path.feed[seg].astype(np.float64)
    k_in, k_out = path.junction_curvatures()
    if k_in.shape[0]:
        vb = curvature_jump_speed_cap(k_in, k_out, lim.path_trans_jerk, limits.t_ipo_s)
        at = junction >= 0
        cap[at] = np.minimum(cap[at], vb[junction[at]])
    if np.any(np.isfinite(cap)):
        amax = np.where(np.isfinite(cap), (cap / V0) ** 2, UNCAPPED)
        robot.constraints.add_constraint_1st(amax[:, None], 0)
    setup = time.perf_counter() - t_setup

    t0 = time.perf_counter()
    p2 = copp.solver.topp2_ra.Problem(robot.constraints, idx_s_interval=(0, K - 1),
                                      a_boundary=(0.0, 0.0))
    a_lin = copp.solver.topp2_ra.solve(p2, copp.solver.topp2_ra.Options())
    t2, _ = copp.interpolation.s_to_t_topp2(ss, a_lin, 0.0)
    times = [t2 * T0]
    b_lin = None
    prof = None
    for r in range(max_rounds):
        p3 = copp.solver.topp3_socp.Problem(robot.constraints, a_lin, a_boundary=(0.0, 0.0),
                                            b_boundary=(0.0, 0.0), b_linearization=b_lin)
        try:
            new = copp.solver.topp3_socp.solve(p3)
        except copp.CoppError:
            if prof is None:
                raise
            break   # keep the last accepted round (each round is feasible at the nodes)
        # copp's a may come out at -1e-19 at rest; s_to_t_topp3 needs a >= 0
        new = copp.Profile3rd(np.maximum(new.a, 0.0), new.b, new.num_stationary)
        tr, _ = copp.interpolation.s_to_t_topp3(ss, new, 0.0)
        prof = new
        times.append(tr * T0)
        a_lin, b_lin = new.a, new.b
        if r > 0 and abs(times[-2] - times[-1]) <= round_rtol * times[-1]:
            break
    solve = time.perf_counter() - t0
    exceed = robot.constraints.exceed_topp3(prof)
    return CoppResult(time_s=times[-1], round_times_s=tuple(times), s=s,
                      v=np.sqrt(prof.a) * V0, acc=prof.b * A0, solve_time_s=solve,
                      setup_time_s=setup, exceed=tuple(float(x) for x in exceed))


# ------------------------------------------------------------------ test paths
_XYZ = ("X", "Y", "Z")
_GEO = np.array([True, True, True])


def _line(a, b, block):
    return line_segments(np.array([a], float), np.array([b], float), _GEO,
                         np.array([block]))


def _arc(a, b, c, cw, block):
    return arc_segment(np.array(a, float), np.array(b, float), np.array(c, float), (0, 1),
                       cw, 0, _GEO, block, 1e-9)


def stadium(R: float = 20.0, L: float = 80.0, feed: float = 250.0, laps: int = 1) -> Path:
    """Laps of a stadium in XY: line along +X, half circle (G3), line back, half circle
    home; four curvature jumps per lap, every line axis-aligned. ``feed`` in mm/s."""
    pieces = []
    for k in range(laps):
        pieces += [_line([0, 0, 0], [L, 0, 0], 4 * k),
                   _arc([L, 0, 0], [L, 2 * R, 0], [L, R, 0], False, 4 * k + 1),
                   _line([L, 2 * R, 0], [0, 2 * R, 0], 4 * k + 2),
                   _arc([0, 2 * R, 0], [0, 0, 0], [0, R, 0], False, 4 * k + 3)]
    return path_from_pieces(_XYZ, pieces, feed=feed)


def s_bends(n: int = 3, R: float = 15.0, lead: float = 30.0, feed: float = 250.0) -> Path:
    """A lead-in line along +X, ``n`` tangent half circles of alternating sense (G3, G2,
    ...; the curvature flips at every joint) and a lead-out line. ``feed`` in mm/s."""
    pieces = [_line([-lead, 0, 0], [0, 0, 0], 0)]
    y, heading = 0.0, 1.0
    for i in range(n):
        cw = bool(i % 2)
        # heading +X, G3 turns up to -X; heading -X, G2 turns up to +X
        pieces.append(_arc([0, y, 0], [0, y + 2 * R, 0], [0, y + R, 0], cw, i + 1))
        y += 2 * R
        heading = -heading
    pieces.append(_line([0, y, 0], [heading * lead, y, 0], n + 1))
    return path_from_pieces(_XYZ, pieces, feed=feed)


def line_into_arc(L: float = 60.0, R: float = 25.0, feed: float = 250.0) -> Path:
    """A line along +X into a quarter circle (G3) that ends the path. ``feed`` in mm/s."""
    pieces = [_line([-L, 0, 0], [0, 0, 0], 0), _arc([0, 0, 0], [R, R, 0], [0, R, 0], False, 1)]
    return path_from_pieces(_XYZ, pieces, feed=feed)
