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
(toppra's "interpolation" scheme). Where a row would break the lattice form (both
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
from reference.core.errors import InfeasibleError
from reference.core.geometry import Path
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
        if np.any(self.c1 * self.c2 > 0) or np.any(self.h < 0):
            raise ValueError("rows are not in lattice form (c1 * c2 <= 0, h >= 0)")
        object.__setattr__(self, "ds", readonly(ds, np.float64))

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


def interval_times(s: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Exact time of every interval of a ``b``-linear profile, s.

    ``dt_k = 2 ds_k / (sqrt(b_k) + sqrt(b_{k+1}))``; ``inf`` where both ends are 0.

    Parameters
    ----------
    s : numpy.ndarray, shape (N + 1,)
        Nodes, mm.
    b : numpy.ndarray, shape (N + 1,)
        Squared path speed, mm^2/s^2 (negative round-off is clipped to 0).

    Returns
    -------
    numpy.ndarray, shape (N,)
    """
    v = np.sqrt(np.maximum(b, 0.0))
    vs = v[:-1] + v[1:]
    ds = np.diff(s)
    out = np.full(ds.size, np.inf)
    pos = vs > 0
    out[pos] = 2.0 * ds[pos] / vs[pos]
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


def build_grid_problem(path: Path, lim: AxisArrays, grid: Grid) -> DiscreteProblem:
    """The grid (interpolation-scheme) problem whose optimum gives the upper bound.

    Rows, for every moving axis ``j``, sign ``sigma`` and interval end (with
    ``a = (b_{k+1} - b_k) / (2 ds)``)::

        near end:  sigma (q'_j(s_k) a + q''_j(s_k) b_k)         <= A_j
        far end:   sigma (q'_j(s_{k+1}) a + q''_j(s_{k+1}) b_{k+1}) <= A_j

    Parameters
    ----------
    path : Path
        Path with at least one segment and positive feeds (see :func:`check_feed`).
    lim : AxisArrays
        Limits in the path's axis order.
    grid : Grid
        Nodes.

    Returns
    -------
    DiscreteProblem
    """
    dq0, ddq0, dq1, ddq1 = interval_geometry(path, grid)
    caps = common_node_caps(path, lim, grid, dq0, dq1, permissive=False)
    N = grid.n_intervals
    inv2ds = 1.0 / (2.0 * np.diff(grid.s))
    cols_c1, cols_c2, cols_h, row_axis = [], [], [], []
    left = np.arange(N)
    margin = interior_margins(path, lim, grid, dq0, ddq0, dq1, ddq1, caps.cap)
    for j in moving_axes(dq0, ddq0, dq1, ddq1):
        A = lim.a_max[j]
        h_j = A - margin[:, j]
        for sigma in (1.0, -1.0):
            near_c1 = sigma * (ddq0[:, j] - dq0[:, j] * inv2ds)
            near_c2 = sigma * dq0[:, j] * inv2ds
            far_c1 = -sigma * dq1[:, j] * inv2ds
            far_c2 = sigma * (dq1[:, j] * inv2ds + ddq1[:, j])
            for c1, c2 in ((near_c1, near_c2), (far_c1, far_c2)):
                both = (c1 > 0) & (c2 > 0)
                if np.any(both):
                    # (c1 + c2) max(b_k, b_k+1) >= c1 b_k + c2 b_k+1: caps at both ends
                    capv = A / (c1[both] + c2[both])
                    caps.add(left[both], capv, CAP_ACCELERATION, j)
                    caps.add(left[both] + 1, capv, CAP_ACCELERATION, j)
                c1 = np.where(both, 0.0, c1)
                c2 = np.where(both, 0.0, c2)
                cols_c1.append(c1)
                cols_c2.append(c2)
                cols_h.append(h_j)
                row_axis.append(j)
    return _assemble(path, lim, grid, caps, cols_c1, cols_c2, cols_h, row_axis, "grid")


def interior_margins(path: Path, lim: AxisArrays, grid: Grid, dq0: np.ndarray,
                     ddq0: np.ndarray, dq1: np.ndarray, ddq1: np.ndarray,
                     cap: np.ndarray) -> np.ndarray:
    """Margins of the grid rows that keep the axis accelerations inside every interval.

    The grid problem bounds ``f(s) = q'_j(s) a + q''_j(s) b(s)`` at the two ends of an
    interval, where ``b`` is linear and ``a`` constant. Inside, ``f`` exceeds the chord
    of its end values by at most ``D^2 / 8 sup|f''|``, and
    ``f'' = 5 q'''_j a + q''''_j b`` (``b' = 2a``), so
    ``|f''| <= 5 sup|q'''_j| abar + sup|q''''_j| Bbar``. The rows ask for
    ``A_j - margin`` at the ends with that margin, so the grid profile keeps ``A_j``
    inside (the checker still judges it; this only avoids slowing the whole profile down
    for one interval's excess, which costs a first-order share of the bracket).

    * ``abar``: on lines, circles and helices ``q' . q'' = 0``, so at a node
      ``|q'|^2 |a| = |q' . acc| <= sum_j |q'_j| A_j`` for every grid-feasible ``b``
      (the rows hold there with the interval's ``a``); the larger end value is taken.
    * ``Bbar``: ``b <= max(b_k, b_{k+1})`` on the interval, and each node value is at
      most its cap and the static limit :func:`pair_mvc` (which the rows at that node
      imply).

    Spirals and clothoids (no closed form of the fourth derivative here) and lines get
    no margin. A
    margin is at most half of ``A_j`` (it is only an efficiency device: the checker
    and time scaling keep the upper bound valid whatever it is).

    Returns
    -------
    numpy.ndarray, shape (N, n)
        mm/s^2.
    """
    N = grid.n_intervals
    n = path.n_axes
    seg = grid.segment
    out = np.zeros((N, n))
    arc = np.flatnonzero((path.radius[seg] > 0) & (path.dradius[seg] == 0)
                         & (path.sharpness[seg] == 0))
    if arc.size == 0:
        return out
    sa = seg[arc]
    r, w = path.radius[sa], np.abs(path.omega[sa])
    plane = np.sqrt(path.e1[sa] ** 2 + path.e2[sa] ** 2)             # (K, n)
    k3 = (r * w ** 3)[:, None] * plane
    k4 = (r * w ** 4)[:, None] * plane
    A = lim.a_max[None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        a0 = (np.abs(dq0[arc]) * A).sum(axis=1) / (dq0[arc] ** 2).sum(axis=1)
        a1 = (np.abs(dq1[arc]) * A).sum(axis=1) / (dq1[arc] ** 2).sum(axis=1)
        abar = np.maximum(a0, a1)
    mvc0 = pair_mvc(dq0[arc], ddq0[arc], lim.a_max)
    mvc1 = pair_mvc(dq1[arc], ddq1[arc], lim.a_max)
    bbar = np.maximum(np.minimum(cap[arc], mvc0), np.minimum(cap[arc + 1], mvc1))
    D = grid.s[arc + 1] - grid.s[arc]
    m = (D * D / 8.0)[:, None] * (5.0 * k3 * abar[:, None] + k4 * bbar[:, None])
    m = np.where(np.isfinite(m), m, np.inf)
    out[arc] = np.minimum(m, 0.5 * A)
    return out


def _assemble(path, lim, grid, caps, cols_c1, cols_c2, cols_h, row_axis, kind):
    N = grid.n_intervals
    if cols_c1:
        # column by column into one array each, releasing every column as it is copied
        # (the rows are the largest arrays of a round)
        out = []
        for cols in (cols_c1, cols_c2, cols_h):
            arr = np.empty((N, len(cols)))
            for r in range(len(cols)):
                arr[:, r] = cols[r]
                cols[r] = None
            cols.clear()
            out.append(arr)
        c1, c2, h = out
    else:
        c1 = c2 = h = np.zeros((N, 0))
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
                           row_axis=np.asarray(row_axis, dtype=np.int64),
                           cap_code=caps.code, cap_axis=caps.axis, axes=path.axes,
                           accel_scale=float(np.max(lim.a_max)), kind=kind)
