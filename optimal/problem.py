"""The discretised velocity/acceleration problem in ``b = v^2`` (numpy only).

Formulation (formulation note 1.1, Verscheure 2009, TOPP-RA 2018): the squared path
speed ``b_k`` lives on the nodes of a :class:`~optimal.grid.Grid`; the path acceleration
``a_k = (b_{k+1} - b_k) / (2 ds_k)`` is constant on each interval, so ``b`` is linear in
``s`` and the exact traversal time is

.. math::  T = \\sum_k 2\\,\\Delta s_k / (\\sqrt{b_k} + \\sqrt{b_{k+1}}).

Every discrete problem here, the grid problem behind the upper bound and the relaxation
behind the lower bound (:mod:`optimal.bounds`), has the same *lattice form*:

* node caps ``0 <= b_k <= cap_k`` (``cap_k = 0`` at stops);
* per interval ``k``, rows ``c1[k, r] b_k + c2[k, r] b_{k+1} <= h[k, r]`` with
  ``c1 * c2 <= 0`` (each row bounds one end by an increasing function of the other) and
  ``h >= 0``.

Such a feasible set is closed under the point-wise maximum and contains ``b = 0``, so it
has a greatest element, and that element minimises ``T`` (``T`` decreases in every
``b_k``). Hence the LP ``max sum b`` and the SOCP ``min T`` have the same solution, and
a backward/forward sweep finds it exactly (:mod:`optimal.backends.fast`).

The grid problem imposes the axis-acceleration constraint
``|q'_j a + q''_j b| <= A_j`` at both ends of every interval with that interval's ``a``
(toppra's "interpolation" scheme). Optionally each interval carries a given slope
``gamma_k`` of the path acceleration (mm/s^2 per mm): then ``b`` is quadratic in ``s`` on
the interval, ``b(s_k + t) = b_k + 2 a_k t + gamma_k t^2``, ``a`` runs linearly from
``a_k = (b_{k+1} - b_k) / (2 ds) - gamma_k ds / 2`` to ``a_k + gamma_k ds``, and the rows
at both ends use those end values. With ``gamma`` fixed the rows are still linear in
``(b_k, b_{k+1})`` with the same coefficients, only their right-hand sides move, so the
lattice form and the exact sweep are kept, while a profile whose acceleration follows an
axis limit along an arc is represented to second order instead of first
(:func:`acceleration_slopes` estimates ``gamma`` from a solution; the oracle solves twice). Where a row would break the lattice form (both
coefficients positive: ``|q'_j| < 2 ds |q''_j|``, the axis nearly at rest on an arc) it
is replaced by the stronger pure-curvature caps ``|q''_j| b <= A_j`` at both ends
(because ``c1 b_k + c2 b_{k+1} <= (c1 + c2) max(b_k, b_{k+1})``), so the grid problem
stays a restriction of the interpolation scheme; the upper bound is verified by
``check_profile`` anyway.

Units: mm, s; ``b`` in mm^2/s^2, rows in mm/s^2. Shapes: ``N`` intervals, ``R`` rows
per interval, ``n`` axes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from reference.core.arrays import readonly
from reference.core.errors import InfeasibleError, InternalError
from reference.core.geometry import Path, clothoid_derivative_norms
from reference.core.limits import AxisArrays
from reference.core.rules import FEASIBLE, RELAXED, junction_speed_cap

from .grid import Grid
from .status import SolveStatus

# Codes of the constraint behind a node cap (for the "active constraint" labels).
CAP_NONE = 0
CAP_STOP = 1
CAP_JUNCTION = 2
CAP_FEED = 3
CAP_VELOCITY = 4          # axis velocity (cap_axis names the axis)
CAP_ACCELERATION = 5      # pure-curvature acceleration cap (cap_axis names the axis)
CAP_BOUND = 6             # a-priori interval bound of the relaxation (lower bound only)

CAP_NAMES = {CAP_NONE: "none", CAP_STOP: "stop", CAP_JUNCTION: "velocity_jump",
             CAP_FEED: "feed", CAP_VELOCITY: "velocity", CAP_ACCELERATION: "acceleration",
             CAP_BOUND: "bound"}




@dataclass(frozen=True, slots=True, eq=False)
class DiscreteProblem:
    """A discrete problem in lattice form (see the module docstring).

    Attributes
    ----------
    s : numpy.ndarray, shape (N + 1,)
        Nodes, mm (strictly increasing).
    cap : numpy.ndarray, shape (N + 1,)
        Upper bounds of ``b`` at the nodes, mm^2/s^2 (finite, >= 0; 0 at stops).
    c1, c2, h : numpy.ndarray, shape (N, R)
        Rows ``c1 b_k + c2 b_{k+1} <= h`` (1/mm, 1/mm, mm/s^2); ``c1 * c2 <= 0``,
        ``h >= 0``; unused rows have ``c1 = c2 = 0``.
    segment : numpy.ndarray of int, shape (N,)
        Path segment of each interval.
    row_axis : numpy.ndarray of int, shape (R,)
        Axis index each row column belongs to.
    cap_code, cap_axis : numpy.ndarray of int, shape (N + 1,)
        Which constraint gives each cap (``CAP_*`` codes) and its axis (-1 if none).
    axes : tuple[str, ...]
        Axis names.
    accel_scale : float
        A typical acceleration, mm/s^2 (the largest ``a_max``); backends use it to scale.
    kind : str
        ``"grid"`` (the problem whose optimum is verified for the upper bound) or
        ``"relaxed"`` (the lower-bound relaxation).
    gamma : numpy.ndarray, shape (N,), optional
        Slope of the path acceleration along ``s`` on each interval, 1/s^2 (``b``
        quadratic in ``s``; see the module docstring). Zeros when not given: ``b``
        linear, ``a`` constant per interval. It enters the rows' right-hand sides, the
        interval times (:func:`interval_times`) and the profile.
    """

    s: np.ndarray
    cap: np.ndarray
    c1: np.ndarray
    c2: np.ndarray
    h: np.ndarray
    segment: np.ndarray
    row_axis: np.ndarray
    cap_code: np.ndarray
    cap_axis: np.ndarray
    axes: tuple[str, ...]
    accel_scale: float
    kind: str = "grid"
    gamma: np.ndarray | None = None
    ds: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        for name in ("s", "cap", "c1", "c2", "h"):
            object.__setattr__(self, name, readonly(getattr(self, name), np.float64))
        for name in ("segment", "row_axis", "cap_code", "cap_axis"):
            object.__setattr__(self, name, readonly(getattr(self, name), np.int64))
        N = self.s.size - 1
        if N < 0:
            raise ValueError("a discrete problem needs at least one node")
        if self.cap.shape != (N + 1,):
            raise ValueError(f"cap has shape {self.cap.shape}, expected {(N + 1,)}")
        R = self.row_axis.size
        for name in ("c1", "c2", "h"):
            if getattr(self, name).shape != (N, R):
                raise ValueError(f"{name} has shape {getattr(self, name).shape}, "
                                 f"expected {(N, R)}")
        ds = np.diff(self.s)
        if np.any(ds <= 0):
            raise ValueError(f"nodes must increase strictly (interval {int(np.argmin(ds))})")
        if not np.all(np.isfinite(self.cap)) or np.any(self.cap < 0):
            raise ValueError("caps must be finite and >= 0")
        if np.any((self.c1 > 0) & (self.c2 > 0)) or np.any((self.c1 < 0) & (self.c2 < 0)) \
                or np.any(self.h < 0):
            raise ValueError("rows are not in lattice form (c1 * c2 <= 0, h >= 0)")
        object.__setattr__(self, "ds", readonly(ds, np.float64))
        gamma = np.zeros(N) if self.gamma is None else np.asarray(self.gamma, np.float64)
        if gamma.shape != (N,) or not np.all(np.isfinite(gamma)):
            raise ValueError(f"gamma must be {N} finite numbers, got shape {gamma.shape}")
        object.__setattr__(self, "gamma", readonly(gamma, np.float64))

    @property
    def n_intervals(self) -> int:
        """Number of intervals ``N``."""
        return int(self.s.size - 1)


@dataclass(frozen=True, slots=True, eq=False)
class DiscreteResult:
    """Solution of a :class:`DiscreteProblem` by one backend.

    Attributes
    ----------
    status : SolveStatus
        ``optimal``, ``optimal_inaccurate``, ``infeasible`` or ``solver_error``.
    b : numpy.ndarray or None
        Shape (N + 1,): squared path speed at the nodes, mm^2/s^2 (``None`` only when
        the status says there is no solution).
    time_s : float
        Exact time of the piecewise-constant-acceleration profile through ``b``, s
        (``inf`` without a solution).
    backend : str
        Backend name.
    build_time_s, solve_time_s : float
        Model construction and solver time, s.
    iterations : int
        Solver iterations (policy-iteration rounds for the fast method).
    message : str
        Backend detail (native status, fallback used, ...).
    """

    status: SolveStatus
    b: np.ndarray | None
    time_s: float
    backend: str
    build_time_s: float = 0.0
    solve_time_s: float = 0.0
    iterations: int = 0
    message: str = ""


def interval_times(s: np.ndarray, b: np.ndarray, gamma: np.ndarray | None = None
                   ) -> np.ndarray:
    """Exact time of every interval of a profile with ``b = v^2`` linear or quadratic in
    ``s``, s.

    With ``gamma = 0`` (``b`` linear): ``dt_k = 2 ds_k / (sqrt(b_k) + sqrt(b_{k+1}))``.
    Otherwise ``b(t) = b_k + 2 alpha t + gamma t^2`` on ``[0, D]`` with
    ``alpha = mbar - gamma D / 2`` and ``mbar = (b_{k+1} - b_k) / (2 D)``, and
    ``int_0^D dt / sqrt(b(t))`` in closed form, written without cancellation as
    ``gamma -> 0`` (both tend to the linear formula):

    * ``gamma > 0``: ``2 artanh(r) / sqrt(gamma)``,
      ``r = sqrt(gamma) (2 D mbar / (u0 + u1) + sqrt(gamma) D)
      / (sqrt(gamma) (u0 + u1) + 2 mbar)`` (the logarithm of the ratio of
      ``sqrt(gamma) sqrt(b) + alpha + gamma t`` at both ends, rewritten);
    * ``gamma < 0``: ``atan2(sqrt(g) X, Y) / sqrt(g)`` with ``g = -gamma``,
      ``X = g D u0 + alpha (u1 - u0)``, ``Y = g (u0 u1 - alpha D) + alpha^2`` (the
      difference of two arcsines, rewritten).

    ``u0, u1`` are the end speeds. Callers keep ``b > 0`` inside intervals with
    ``gamma != 0`` (:func:`acceleration_slopes` does).

    Parameters
    ----------
    s : numpy.ndarray, shape (N + 1,)
        Nodes, mm.
    b : numpy.ndarray, shape (N + 1,)
        Squared path speed, mm^2/s^2 (negative round-off is clipped to 0).
    gamma : numpy.ndarray, shape (N,), optional
        Slope of the path acceleration on each interval, 1/s^2 (default 0).

    Returns
    -------
    numpy.ndarray, shape (N,)
        ``inf`` where both ends are at rest.
    """
    b = np.maximum(np.asarray(b, dtype=np.float64), 0.0)
    v = np.sqrt(b)
    vs = v[:-1] + v[1:]
    ds = np.diff(s)
    out = np.full(ds.size, np.inf)
    pos = vs > 0
    out[pos] = 2.0 * ds[pos] / vs[pos]
    if gamma is None:
        return out
    g = np.asarray(gamma, dtype=np.float64)
    for sel, sign in ((pos & (g > 0), 1.0), (pos & (g < 0), -1.0)):
        if not np.any(sel):
            continue
        D, u0, u1, w = ds[sel], v[:-1][sel], v[1:][sel], vs[sel]
        gg = np.abs(g[sel])
        rg = np.sqrt(gg)
        mbar = (b[1:][sel] - b[:-1][sel]) / (2.0 * D)
        du = 2.0 * D * mbar / w                                   # u1 - u0
        if sign > 0:
            r = rg * (du + rg * D) / (rg * w + 2.0 * mbar)
            out[sel] = 2.0 * np.arctanh(r) / rg
        else:
            alpha = mbar + gg * D / 2.0
            X = gg * D * u0 + alpha * du
            Y = gg * (u0 * u1 - alpha * D) + alpha * alpha
            out[sel] = np.arctan2(rg * X, Y) / rg
    return out


# --------------------------------------------------------------------------- helpers
def check_feed(path: Path) -> None:
    """Raise :class:`InfeasibleError` for a segment whose feed is zero, negative or NaN.

    The message names the NC block and its source line (from ``path.blocks``).
    """
    bad = ~(path.feed > 0)       # also catches NaN
    if not np.any(bad):
        return
    i = int(np.flatnonzero(bad)[0])
    blk = int(path.block[i])
    span = next((b for b in path.blocks if b.block == blk), None)
    where = (f"block {blk} (line {span.line}{', ' + span.label if span.label else ''})"
             if span else f"block {blk}")
    raise InfeasibleError(f"{where}: programmed feed F = {path.feed[i]:g} mm/s; the path "
                          f"cannot be traversed with zero feed", blk)


def junction_speed_caps(path: Path, lim: AxisArrays, *, permissive: bool
                        ) -> tuple[np.ndarray, np.ndarray]:
    """Largest path speed at every interior segment break allowed by the axis jumps.

    The rule is the rulebook's (:func:`reference.core.rules.junction_speed_cap`, the one
    the checker and the heuristic apply): the grid problem takes its *feasible* flavour
    (every speed at or below it passes ``check_profile``; tangential breaks are free, the
    standstill floor ``VEL_TOL_MM_S`` counts as an allowance, caps at standstill level
    become a stop), the lower-bound relaxation its *relaxed* flavour (no speed above it
    passes ``check_profile``).

    Parameters
    ----------
    path : Path
        The path.
    lim : AxisArrays
        Limits in the path's axis order.
    permissive : bool
        False: the feasible cap of the grid problem. True: the relaxed cap of the
        lower-bound relaxation.

    Returns
    -------
    v_cap : numpy.ndarray, shape (m + 1,)
        mm/s; ``inf`` where nothing limits (path ends included: stops come separately).
    axis : numpy.ndarray of int, shape (m + 1,)
        Axis that sets the cap, -1 where none.
    """
    m = path.n_segments
    v_cap = np.full(m + 1, np.inf)
    axis = np.full(m + 1, -1, dtype=np.int64)
    if m < 2:
        return v_cap, axis
    t_in, t_out = path.junction_tangents()
    v, ax = junction_speed_cap(t_in, t_out, lim.jump, RELAXED if permissive else FEASIBLE)
    v_cap[1:m] = v
    axis[1:m] = ax
    return v_cap, axis


class _CapStack:
    """Running minimum of node caps with the code and axis of the tightest one."""

    def __init__(self, n_nodes: int) -> None:
        self.cap = np.full(n_nodes, np.inf)
        self.code = np.full(n_nodes, CAP_NONE, dtype=np.int64)
        self.axis = np.full(n_nodes, -1, dtype=np.int64)

    def add(self, idx, value, code: int, axis=-1) -> None:
        """Lower the caps at nodes ``idx`` to ``value`` where that is smaller."""
        idx = np.asarray(idx, dtype=np.int64)
        if idx.size == 0:
            return
        value = np.broadcast_to(np.asarray(value, dtype=np.float64), idx.shape)
        axis = np.broadcast_to(np.asarray(axis, dtype=np.int64), idx.shape)
        new = self.cap.copy()
        np.minimum.at(new, idx, value)
        changed = new < self.cap
        hit = changed[idx] & (value == new[idx])
        self.code[idx[hit]] = code
        self.axis[idx[hit]] = axis[hit]
        self.cap = new


def common_node_caps(path: Path, lim: AxisArrays, grid: Grid, dq0: np.ndarray,
                     dq1: np.ndarray, *, permissive: bool) -> _CapStack:
    """Stops, junction, feed and axis-velocity caps of ``b`` at every node.

    Parameters
    ----------
    path, lim, grid
        Problem data.
    dq0, dq1 : numpy.ndarray, shape (N, n)
        Tangent at the start and end of every interval (on the interval's segment).
    permissive : bool
        Junction rule (see :func:`junction_speed_caps`).

    Returns
    -------
    _CapStack
        Caps in mm^2/s^2 with their codes.
    """
    N = grid.n_intervals
    st = _CapStack(N + 1)
    seg = grid.segment
    left = np.arange(N)            # interval k: nodes k (its start) and k + 1 (its end)
    # axis velocity: b <= (v_max_j / |q'_j|)^2 at both ends of each interval
    for j in range(len(path.axes)):
        for nodes, dq in ((left, dq0[:, j]), (left + 1, dq1[:, j])):
            nz = np.abs(dq) > 0
            if np.any(nz):
                st.add(nodes[nz], (lim.v_max[j] / np.abs(dq[nz])) ** 2, CAP_VELOCITY, j)
    # programmed feed (inf for G0)
    feed = path.feed[seg]
    fin = np.isfinite(feed)
    if np.any(fin):
        st.add(left[fin], feed[fin] ** 2, CAP_FEED)
        st.add(left[fin] + 1, feed[fin] ** 2, CAP_FEED)
    # velocity jumps at non-tangential breaks
    v_cap, ax = junction_speed_caps(path, lim, permissive=permissive)
    fin = np.isfinite(v_cap)
    if np.any(fin):
        st.add(grid.break_node[fin], v_cap[fin] ** 2, CAP_JUNCTION, ax[fin])
    # rest where the path stops (start, end, exact and forced stops)
    stop_nodes = grid.break_node[path.stop]
    st.add(stop_nodes, np.zeros(stop_nodes.size), CAP_STOP)
    return st


def interval_geometry(path: Path, grid: Grid):
    """Tangent and curvature vector at both ends of every interval, on its own segment.

    Returns
    -------
    dq0, ddq0, dq1, ddq1 : numpy.ndarray, shape (N, n)
    """
    seg = grid.segment
    _, dq0, ddq0, _ = path.evaluate(grid.s[:-1], segment=seg)
    _, dq1, ddq1, _ = path.evaluate(grid.s[1:], segment=seg)
    return dq0, ddq0, dq1, ddq1


def moving_axes(dq0, ddq0, dq1, ddq1) -> np.ndarray:
    """Indices of the axes that move or curve anywhere on the grid."""
    act = (np.any(dq0 != 0, axis=0) | np.any(dq1 != 0, axis=0)
           | np.any(ddq0 != 0, axis=0) | np.any(ddq1 != 0, axis=0))
    return np.flatnonzero(act)


def pair_mvc(dq: np.ndarray, ddq: np.ndarray, a_max: np.ndarray) -> np.ndarray:
    """Exact static bound ``max b`` s.t. some ``a`` has ``|q'_j a + q''_j b| <= A_j``.

    The 2-variable LP's optimum is the smallest optimum over its two-constraint
    sub-problems: ``(A_j |q'_l| + A_l |q'_j|) / |q'_l q''_j - q'_j q''_l|`` for axis pairs
    and ``A_j / |q''_j|`` for an axis with ``q'_j = 0``. Shape ``(K, n) -> (K,)``.
    """
    K, n = dq.shape
    out = np.full(K, np.inf)
    for j in range(n):
        single = (dq[:, j] == 0) & (ddq[:, j] != 0)
        if np.any(single):
            out[single] = np.minimum(out[single], a_max[j] / np.abs(ddq[single, j]))
        for m in range(j + 1, n):
            W = np.abs(dq[:, m] * ddq[:, j] - dq[:, j] * ddq[:, m])
            ok = W > 0
            if np.any(ok):
                val = (a_max[j] * np.abs(dq[ok, m]) + a_max[m] * np.abs(dq[ok, j])) / W[ok]
                out[ok] = np.minimum(out[ok], val)
    return out


def build_grid_problem(path: Path, lim: AxisArrays, grid: Grid,
                       gamma: np.ndarray | None = None,
                       b_guess: np.ndarray | None = None,
                       geometry: tuple[np.ndarray, ...] | None = None) -> DiscreteProblem:
    """The grid (interpolation-scheme) problem whose optimum gives the upper bound.

    Rows, for every moving axis ``j``, sign ``sigma`` and interval end, with the
    interval's end accelerations ``a_k = abar - gamma D / 2`` and ``a_k + gamma D``
    (``abar = (b_{k+1} - b_k) / (2 D)``, the module docstring)::

        near end:  sigma (q'_j(s_k) a_k + q''_j(s_k) b_k)                <= A_j - m_kj
        far end:   sigma (q'_j(s_{k+1}) (a_k + gamma D) + q''_j(s_{k+1}) b_{k+1}) <= A_j - m_kj

    with the interior margin ``m`` of :func:`interior_margins`.

    Parameters
    ----------
    path : Path
        Path with at least one segment and positive feeds (see :func:`check_feed`).
    lim : AxisArrays
        Limits in the path's axis order.
    grid : Grid
        Nodes.
    gamma : numpy.ndarray, shape (N,), optional
        Slopes of the path acceleration per interval, 1/s^2 (default 0: ``b`` linear).
        They are clipped (:func:`clip_slopes`) so that every row keeps at least three
        quarters of its limit, and set to 0 on lines and spirals.
    b_guess : numpy.ndarray, shape (N + 1,), optional
        The solution the slopes were estimated from (mm^2/s^2); it sizes the margin for
        the difference between the quadratic-``b`` motion and the constant-jerk profile
        that represents it (:func:`interior_margins`). Slopes without a guess are 0.
    geometry : tuple of numpy.ndarray, optional
        :func:`interval_geometry` of ``grid``, when the caller has it already (the
        oracle builds two problems per grid).

    Returns
    -------
    DiscreteProblem
        With ``gamma`` the clipped slopes actually used.
    """
    dq0, ddq0, dq1, ddq1 = (interval_geometry(path, grid) if geometry is None
                            else geometry)
    caps = common_node_caps(path, lim, grid, dq0, dq1, permissive=False)
    N = grid.n_intervals
    D = np.diff(grid.s)
    inv2ds = 1.0 / (2.0 * D)
    g = clip_slopes(path, lim, grid, dq0, dq1,
                    np.zeros(N) if gamma is None or b_guess is None else gamma)
    left = np.arange(N)
    # a concave b (gamma < 0) rises above the larger end value by up to |gamma| D^2 / 4
    # inside the interval: keep that much below the speed caps at both ends
    sag = np.flatnonzero(g < 0)
    if sag.size:
        bulge = -g[sag] * D[sag] ** 2 / 4
        lowered = caps.cap.copy()            # (same constraint, same code and axis)
        for nodes in (sag, sag + 1):
            np.minimum.at(lowered, nodes, np.maximum(caps.cap[nodes] - bulge, 0.0))
        caps.cap = lowered
    m0, mc = interior_margins(path, lim, grid, dq0, ddq0, dq1, ddq1, caps.cap, g, b_guess)
    tilted = mc > 0
    axes_used = moving_axes(dq0, ddq0, dq1, ddq1)
    rows = RowWriter(N, sum(8 if np.any(tilted[:, j]) else 4 for j in axes_used))
    for j in axes_used:
        A = lim.a_max[j]
        h_j = A - m0[:, j]
        # the margin's part mc |abar| as two rows, +abar and -abar (abar = (b1 - b0) / 2D)
        tilt = mc[:, j] * inv2ds
        signs = (1.0, -1.0) if np.any(tilted[:, j]) else (0.0,)
        for sigma in (1.0, -1.0):
            near_c1 = sigma * (ddq0[:, j] - dq0[:, j] * inv2ds)
            near_c2 = sigma * dq0[:, j] * inv2ds
            far_c1 = -sigma * dq1[:, j] * inv2ds
            far_c2 = sigma * (dq1[:, j] * inv2ds + ddq1[:, j])
            # the slope moves the end accelerations by -/+ gamma D / 2
            near_h = h_j + sigma * dq0[:, j] * g * D / 2
            far_h = h_j - sigma * dq1[:, j] * g * D / 2
            for c1, c2, hh in ((near_c1, near_c2, near_h), (far_c1, far_c2, far_h)):
                hh = np.maximum(hh, 0.0)
                for pm in signs:
                    e1 = c1 - pm * tilt
                    e2 = c2 + pm * tilt
                    if pm < 0:          # without a tilt the second row is the first one
                        e1 = np.where(tilted[:, j], e1, 0.0)
                        e2 = np.where(tilted[:, j], e2, 0.0)
                    both = (e1 > 0) & (e2 > 0)
                    if np.any(both):
                        # (e1 + e2) max(b_k, b_k+1) >= e1 b_k + e2 b_k+1: caps at both ends
                        capv = hh[both] / (e1[both] + e2[both])
                        caps.add(left[both], capv, CAP_ACCELERATION, j)
                        caps.add(left[both] + 1, capv, CAP_ACCELERATION, j)
                    rows.append(np.where(both, 0.0, e1), np.where(both, 0.0, e2), hh, j)
    return _assemble(path, lim, grid, caps, rows, "grid", g)


#: Largest share of an axis' acceleration limit that the slope terms of one row may take
#: (:func:`clip_slopes`): the rest stays for the motion, and the right-hand sides stay
#: positive (the lattice form needs ``h >= 0``).
SLOPE_SHARE_MAX = 0.25

#: A slope is dropped where it would bend ``b`` inside an interval by more than this
#: fraction of the smaller end value (``|gamma| D^2 > SLOPE_BEND_MAX min(b_k, b_k+1)``,
#: :func:`acceleration_slopes`): ``b`` must stay positive inside (next to a stop it is
#: near zero), and intervals bent that much are switching points, where a slope
#: estimated across the switch would only shift the wrong end.
SLOPE_BEND_MAX = 0.1


def clip_slopes(path: Path, lim: AxisArrays, grid: Grid, dq0: np.ndarray, dq1: np.ndarray,
                gamma: np.ndarray) -> np.ndarray:
    """Slopes limited to what the rows can carry (see :data:`SLOPE_SHARE_MAX`).

    In every row of interval ``k`` the slope takes ``|q'_j| |gamma| D / 2`` (the shift of
    the end acceleration) plus ``D^2 sup|q''_j| |gamma| / 2`` (its share of the interior
    margin, :func:`interior_margins`); both together stay within
    ``SLOPE_SHARE_MAX A_j``. Lines and spirals get 0.

    Returns
    -------
    numpy.ndarray, shape (N,)
        1/s^2.
    """
    g = np.asarray(gamma, dtype=np.float64)
    seg = grid.segment
    D = np.diff(grid.s)
    k2 = (np.abs(path.radius[seg] * path.omega[seg] ** 2)[:, None]
          * np.sqrt(path.e1[seg] ** 2 + path.e2[seg] ** 2))
    per = (D[:, None] * np.maximum(np.abs(dq0), np.abs(dq1)) / 2 + D[:, None] ** 2 * k2 / 2)
    with np.errstate(divide="ignore"):
        cap = np.min(np.where(per > 0, SLOPE_SHARE_MAX * lim.a_max[None, :]
                              / np.where(per > 0, per, 1.0), np.inf), axis=1)
    g = np.clip(g, -cap, cap)
    # lines: the allowed acceleration is the same all along, the optimum's is piecewise
    # constant (a slope there only spreads a switch); spirals: no slope term in their
    # margin
    return np.where((path.dradius[seg] != 0) | (path.sharpness[seg] != 0)
                    | (path.radius[seg] == 0), 0.0, g)


def acceleration_slopes(grid: Grid, b: np.ndarray) -> np.ndarray:
    """Slopes of the path acceleration per interval, estimated from a grid solution.

    The mean acceleration of interval ``k`` is ``abar_k = (b_{k+1} - b_k) / (2 D_k)``
    (whatever slope it was solved with); its divided differences estimate ``a'``.
    Inside a segment the smaller of the two neighbouring differences is taken when they
    agree in sign and 0 otherwise (the *minmod* limiter: at a switch between
    accelerating and braking ``a`` jumps, and a slope there would only shift the wrong
    end); at the ends of a segment the one-sided difference; 0 where the slope would
    bend ``b`` too much (:data:`SLOPE_BEND_MAX`). Any slope gives a valid grid problem
    (the checker judges the result); a good one makes it second-order accurate.

    Parameters
    ----------
    grid : Grid
        The grid.
    b : numpy.ndarray, shape (N + 1,)
        A solution of the grid problem on it, mm^2/s^2.

    Returns
    -------
    numpy.ndarray, shape (N,)
        1/s^2.
    """
    D = np.diff(grid.s)
    N = D.size
    b = np.maximum(np.asarray(b, dtype=np.float64), 0.0)
    if N < 2:
        return np.zeros(N)
    abar = (b[1:] - b[:-1]) / (2.0 * D)
    same = grid.segment[1:] == grid.segment[:-1]
    fd = np.where(same, (abar[1:] - abar[:-1]) / (0.5 * (D[1:] + D[:-1])), np.nan)
    left = np.concatenate(([np.nan], fd))        # difference with the interval before
    right = np.concatenate((fd, [np.nan]))       # ... and with the one after
    both = np.isfinite(left) & np.isfinite(right)
    with np.errstate(invalid="ignore"):
        mm = np.where(left * right > 0,
                      np.sign(left) * np.minimum(np.abs(left), np.abs(right)), 0.0)
    g = np.where(both, mm, np.where(np.isfinite(left), left,
                                    np.where(np.isfinite(right), right, 0.0)))
    low = np.minimum(b[:-1], b[1:])
    return np.where(np.abs(g) * D * D > SLOPE_BEND_MAX * low, 0.0, g)


def slopes_keep_positive(grid: Grid, b: np.ndarray, gamma: np.ndarray) -> np.ndarray:
    """Intervals where ``b(t) = b_k + 2 alpha t + gamma t^2`` stays well above 0 inside.

    Returns
    -------
    numpy.ndarray of bool, shape (N,)
        True where ``gamma = 0``, or where the smallest value of ``b`` on the interval
        is at least half the smaller end value.
    """
    D = np.diff(grid.s)
    b = np.maximum(np.asarray(b, dtype=np.float64), 0.0)
    g = np.asarray(gamma, dtype=np.float64)
    alpha = (b[1:] - b[:-1]) / (2.0 * D) - g * D / 2
    with np.errstate(divide="ignore", invalid="ignore"):
        tv = np.where(g > 0, -alpha / np.where(g > 0, g, 1.0), -1.0)
    inside = (tv > 0) & (tv < D)
    bmin = np.where(inside, b[:-1] + alpha * tv, np.inf)
    return (g == 0) | (bmin >= 0.5 * np.minimum(b[:-1], b[1:]))


def interior_margins(path: Path, lim: AxisArrays, grid: Grid, dq0: np.ndarray,
                     ddq0: np.ndarray, dq1: np.ndarray, ddq1: np.ndarray,
                     cap: np.ndarray, gamma: np.ndarray | None = None,
                     b_guess: np.ndarray | None = None
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Margins of the grid rows that keep the axis accelerations inside every interval.

    The grid problem bounds ``f(s) = q'_j(s) a(s) + q''_j(s) b(s)`` at the two ends of an
    interval (``a`` linear with slope ``gamma``, ``b' = 2a``). Inside, ``f`` exceeds the
    chord of its end values by at most ``D^2 / 8 sup|f''|``.

    * **Circles and helices** (``q''' = -omega^2 (q' - d)``, ``q'''' = -omega^2 q''``,
      ``d`` the helix' linear part): ``f'' = 5 q''' a + 4 q'' gamma + q'''' b
      = -omega^2 (f + (4 q'_j - 5 d_j) a) + 4 q''_j gamma``. With ``F = sup|f|``,
      ``rho = (omega D)^2 / 8``, ``C_j = 4 r |omega| |e_j| + |d_j| >= |4 q'_j - 5 d_j|``
      (``|e_j|`` the axis' share of the arc plane) and the end values within
      ``A_j - m`` (both signs have rows),
      ``F <= A_j - m + rho (F + C_j sup|a|) + D^2 sup|q''_j| |gamma| / 2``, so
      ``F <= A_j`` as soon as
      ``m = rho (A_j + C_j sup|a|) + D^2 sup|q''_j| |gamma| / 2`` (``rho < 1``), and
      ``a`` is linear on the interval: ``sup|a| = |abar| + |gamma| D / 2`` with
      ``abar = (b_{k+1} - b_k) / (2 D)``. The part ``rho C_j |abar|`` is returned
      separately (``mc``): the grid problem writes it as two linear rows, with
      ``+abar`` and ``-abar``, so the margin follows the interval's own acceleration
      (on a machine whose tangential axis is far stiffer than the others an a-priori
      bound of ``|a|`` would be a hundred times too large). The margin is second order
      in the angle an interval sweeps.
    * **Spirals** (no closed form of the fourth derivative here):
      ``|f''| <= 5 sup|q'''_j| abar + sup|q''''_j| Bbar`` with ``abar`` an a-priori
      bound of ``|a|`` (at a node ``q' . q'' = 0`` on circles gives
      ``|q'|^2 |a| = |q' . acc| <= sum_j |q'_j| A_j`` for every grid-feasible ``b``; on
      spirals it holds up to the small ``q' . q''``, and the checker judges the result
      anyway; the larger end value is taken) and ``Bbar`` the larger end
      bound of ``b`` (its cap and the static limit :func:`pair_mvc`, which the rows at
      that node imply); their slope is always 0 (:func:`clip_slopes`).
    * **Lines**: ``f = q'_j a`` is linear in ``s``: no margin.
    * **The profile of a sloped interval** is piecewise constant jerk in time
      (:func:`optimal.bounds.grid_profile`), not the quadratic-``b`` motion itself: its
      acceleration is the projection of the model's ``a(t)`` on linear functions (the
      two share duration, speed change and length, i.e. the integrals of ``a`` against
      1 and ``t``), and since ``d^2 a / dt^2 = gamma a`` along the model, the two differ
      by at most about ``|gamma| abar h^2 / 12`` (exact for a quadratic; ``/ 8`` is
      taken). With ``h <= D / sqrt(min(b_k, b_{k+1}) / 2)`` (the slopes keep ``b`` above
      half its smaller end value, :func:`slopes_keep_positive`) the margin adds
      ``sup|q'_j| |gamma| abar D^2 / (4 min(b_k, b_{k+1}))``, with ``b`` from the
      solution the slopes were estimated from (``b_guess``).

    A margin is at most half of ``A_j`` (it is only an efficiency device: the checker
    and time scaling keep the upper bound valid whatever it is).

    Returns
    -------
    m0 : numpy.ndarray, shape (N, n)
        The constant part of the margins, mm/s^2.
    mc : numpy.ndarray, shape (N, n)
        Coefficient of ``|abar|`` (1), non-zero on circles and helices only.
    """
    N = grid.n_intervals
    n = path.n_axes
    seg = grid.segment
    out = np.zeros((N, n))
    coef = np.zeros((N, n))
    curved_all = np.flatnonzero(path.radius[seg] > 0)
    g = np.zeros(N) if gamma is None else np.asarray(gamma, dtype=np.float64)
    bg = None if b_guess is None else np.maximum(np.asarray(b_guess, dtype=np.float64), 0.0)
    # in chunks of intervals (a dozen (chunk, n) temporaries each)
    for lo in range(0, curved_all.size, _MARGIN_CHUNK):
        curved = curved_all[lo:lo + _MARGIN_CHUNK]
        out[curved], coef[curved] = _curved_margins(path, lim, grid, curved, dq0, ddq0, dq1,
                                                    ddq1, cap, g, bg)
    return out, coef


#: Intervals per chunk of :func:`interior_margins` (bounds its temporaries).
_MARGIN_CHUNK = 1 << 16


def _curved_margins(path, lim, grid, curved, dq0, ddq0, dq1, ddq1, cap, g, bg):
    """:func:`interior_margins` on the curved intervals ``curved``: ``(m0, mc)`` rows."""
    seg = grid.segment
    sa = seg[curved]
    r, w = path.radius[sa], np.abs(path.omega[sa])
    plane = np.sqrt(path.e1[sa] ** 2 + path.e2[sa] ** 2)             # (K, n)
    A = lim.a_max[None, :]
    d0, d1 = dq0[curved], dq1[curved]
    with np.errstate(divide="ignore", invalid="ignore"):
        a0 = (np.abs(d0) * A).sum(axis=1) / (d0 ** 2).sum(axis=1)
        a1 = (np.abs(d1) * A).sum(axis=1) / (d1 ** 2).sum(axis=1)
        abar = np.maximum(a0, a1)
    D = grid.s[curved + 1] - grid.s[curved]
    # spirals and clothoids: the generic margin (no helix closed forms)
    spiral = (path.dradius[sa] != 0) | (path.sharpness[sa] != 0)
    # circles and helices: second order in the swept angle, free of b
    rho = (w * D) ** 2 / 8.0
    C = 4.0 * (r * w)[:, None] * plane + np.abs(path.d[sa])
    k2 = (r * w * w)[:, None] * plane
    gd = np.abs(g[curved]) * D
    m = (rho[:, None] * (A + C * (gd / 2.0)[:, None]) + (D * gd / 2.0)[:, None] * k2)
    mc = rho[:, None] * C
    if bg is not None and np.any(g[curved]):
        blo = np.minimum(bg[curved], bg[curved + 1])
        with np.errstate(divide="ignore", invalid="ignore"):
            fit = np.where(g[curved] != 0, np.abs(g[curved]) * abar * D * D
                           / (4.0 * np.where(blo > 0, blo, 0.0)), 0.0)
        hi = np.maximum(np.abs(d0), np.abs(d1)) + (D / 2.0)[:, None] * k2
        m = m + hi * np.where(np.isfinite(fit), fit, np.inf)[:, None]
    if np.any(spiral):
        k3 = (r * w ** 3)[:, None] * plane
        k4 = (r * w ** 4)[:, None] * plane
        clo = np.flatnonzero(path.sharpness[sa] != 0)
        if clo.size:        # clothoids: the suprema of their third and fourth derivative
            norms = clothoid_derivative_norms(np.abs(path.sharpness[sa[clo]]),
                                              path.length[sa[clo]])
            k3[clo] = norms[2][:, None] * plane[clo]
            k4[clo] = norms[3][:, None] * plane[clo]
        c = curved[spiral]
        mvc0 = pair_mvc(dq0[c], ddq0[c], lim.a_max)
        mvc1 = pair_mvc(dq1[c], ddq1[c], lim.a_max)
        bbar = np.maximum(np.minimum(cap[c], mvc0), np.minimum(cap[c + 1], mvc1))
        m[spiral] = (D[spiral] ** 2 / 8.0)[:, None] * (5.0 * k3[spiral] * abar[spiral, None]
                                                       + k4[spiral] * bbar[:, None])
        mc[spiral] = 0.0
    big = ~np.isfinite(m) | (rho >= 0.5)[:, None]
    return np.where(big, 0.5 * A, np.minimum(m, 0.5 * A)), np.where(big, 0.0, mc)


class RowWriter:
    """The row columns of a discrete problem, written into arrays sized up front.

    The rows are the largest arrays of a round (a few hundred bytes per interval), so
    they are written in place instead of being collected as columns and copied.

    Parameters
    ----------
    n_intervals : int
        ``N``.
    n_rows : int
        ``R``, the number of columns that will be written (exactly).
    """

    def __init__(self, n_intervals: int, n_rows: int) -> None:
        self.c1 = np.zeros((n_intervals, n_rows))
        self.c2 = np.zeros((n_intervals, n_rows))
        self.h = np.zeros((n_intervals, n_rows))
        self.axis = np.zeros(n_rows, dtype=np.int64)
        self.n = 0

    def append(self, c1: np.ndarray, c2: np.ndarray, h: np.ndarray, axis: int) -> None:
        """Write the next column."""
        r = self.n
        self.c1[:, r] = c1
        self.c2[:, r] = c2
        self.h[:, r] = h
        self.axis[r] = axis
        self.n = r + 1

    def last(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Views of the last column written (to be replaced in place)."""
        r = self.n - 1
        return self.c1[:, r], self.c2[:, r], self.h[:, r]


def _assemble(path, lim, grid, caps, rows: RowWriter, kind, gamma=None):
    N = grid.n_intervals
    if rows.n != rows.c1.shape[1]:
        raise InternalError(f"{rows.n} row columns written, {rows.c1.shape[1]} sized")
    c1, c2, h, row_axis = rows.c1, rows.c2, rows.h, rows.axis
    # rows with both coefficients <= 0 can never bind (b >= 0, h >= 0): blank them
    vac = (c1 <= 0) & (c2 <= 0)
    c1[vac] = 0.0
    c2[vac] = 0.0
    del vac
    if not np.all(np.isfinite(caps.cap)):
        k = int(np.flatnonzero(~np.isfinite(caps.cap))[0])
        raise InfeasibleError(f"no finite speed limit at s = {grid.s[k]:.6g} mm "
                              "(no axis moves there)", int(path.block[grid.segment[
                                  min(k, N - 1)]]))
    return DiscreteProblem(s=grid.s, cap=caps.cap, c1=c1, c2=c2, h=h, segment=grid.segment,
                           row_axis=row_axis,
                           cap_code=caps.code, cap_axis=caps.axis, axes=path.axes,
                           accel_scale=float(np.max(lim.a_max)), kind=kind, gamma=gamma)
