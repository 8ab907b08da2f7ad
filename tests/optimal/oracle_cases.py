"""Test-path builders for the oracle tests and the oracle benchmark (not a test module).

* :func:`line_path`, :func:`line_arc_line` and :func:`semicircle`: hand-solvable cases;
* :func:`kunz_stilman_path`: lines plus circular blends exactly as MoveIt's TOTG builds
  them (``Path(waypoints, max_deviation)``, Kunz & Stilman 2012), for the published cases;
* :func:`random_blended_polyline`: seeded tangent-continuous line/arc paths;
* :class:`ToppraPath`: our exact :class:`Path` behind toppra's ``AbstractGeometricPath``
  interface, and :func:`toppra_time` running toppra (seidel, interpolation scheme) on it.
"""

from __future__ import annotations

import numpy as np

from reference.core import AxisLimits, MachineLimits, path_from_pieces
from reference.core.geometry import arc_segment, line_segments

XYZ = ("X", "Y", "Z")
GEO3 = np.array([True, True, True])


def machine(v, a, *, axes=XYZ, ovl=1.2, t_ipo=0.004, j=1e6) -> MachineLimits:
    """Limits with per-axis ``v`` and ``a`` (scalars or sequences)."""
    v = np.broadcast_to(np.asarray(v, float), (len(axes),))
    a = np.broadcast_to(np.asarray(a, float), (len(axes),))
    return MachineLimits(tuple(AxisLimits(n, float(vi), float(ai), j, ovl)
                               for n, vi, ai in zip(axes, v, a)), t_ipo)


def line_path(points, *, axes=XYZ, feed=np.inf, stops=None, rapid=None):
    """Polyline through ``points`` (one block per segment)."""
    pts = np.asarray(points, dtype=float)
    geo = np.array([a in XYZ for a in axes])
    m = len(pts) - 1
    pieces = [line_segments(pts[:-1], pts[1:], geo, np.arange(m))]
    return path_from_pieces(axes, pieces, feed=feed, rapid=rapid,
                            stop_reason=None if stops is None else tuple(stops))


def semicircle(R: float, *, feed=np.inf):
    """Half circle from (0, -R) to (0, R) through (R, 0), counter-clockwise, one block."""
    arc = arc_segment(np.array([0.0, -R, 0.0]), np.array([0.0, R, 0.0]), np.zeros(3), (0, 1),
                      False, 0, GEO3, 0, 1e-6)
    return path_from_pieces(XYZ, [arc], feed=feed)


def line_arc_line(R: float, L: float, *, feed=np.inf):
    """Line along +x to (0, -R), the half circle of :func:`semicircle`, line back along -x."""
    pieces = [line_segments(np.array([[-L, -R, 0.0]]), np.array([[0.0, -R, 0.0]]), GEO3,
                            np.array([0])),
              arc_segment(np.array([0.0, -R, 0.0]), np.array([0.0, R, 0.0]), np.zeros(3),
                          (0, 1), False, 0, GEO3, 1, 1e-6),
              line_segments(np.array([[0.0, R, 0.0]]), np.array([[-L, R, 0.0]]), GEO3,
                            np.array([2]))]
    return path_from_pieces(XYZ, pieces, feed=feed)


def _unit(v):
    return v / np.linalg.norm(v)


def kunz_stilman_path(waypoints, max_deviation: float, axes):
    """Lines plus circular blends (MoveIt TOTG ``Path``), as our packed pieces.

    At every interior waypoint a circular blend joins the mid-points of the adjacent
    segments: blend distance ``min(|start - p|, |end - p|, delta sin(a/2)/(1-cos(a/2)))``
    with ``start``/``end`` the mid-points, radius ``distance / tan(a/2)``, centre
    ``p + normalize(d_end - d_start) * radius / cos(a/2)``.
    """
    wp = [np.asarray(w, float) for w in waypoints]
    geo = np.array([a in XYZ for a in axes])
    pieces = []
    blk = 0
    start = wp[0]
    for i in range(1, len(wp) - 1):
        c1 = 0.5 * (wp[i - 1] + wp[i])
        c3 = 0.5 * (wp[i] + wp[i + 1])
        p = wp[i]
        ds, de = _unit(p - c1), _unit(c3 - p)
        angle = np.arccos(np.clip(ds @ de, -1, 1))
        dist = min(np.linalg.norm(c1 - p), np.linalg.norm(c3 - p))
        dist = min(dist, max_deviation * np.sin(0.5 * angle) / (1 - np.cos(0.5 * angle)))
        radius = dist / np.tan(0.5 * angle)
        center = p + _unit(de - ds) * radius / np.cos(0.5 * angle)
        x = _unit(p - dist * ds - center)
        arc_start = center + radius * x
        arc_end = center + radius * (np.cos(angle) * x + np.sin(angle) * ds)
        if np.linalg.norm(arc_start - start) > 1e-6:
            pieces.append(line_segments(start[None], arc_start[None], geo, np.array([blk])))
            blk += 1
        pieces.append(arc_segment(arc_start, arc_end, center, (x, ds), False, 0, geo, blk,
                                  1e-6))
        blk += 1
        start = arc_end
    pieces.append(line_segments(start[None], wp[-1][None], geo, np.array([blk])))
    return path_from_pieces(tuple(axes), pieces)


def random_blended_polyline(n: int, seed: int, *, step=(2.0, 20.0), max_turn_deg=115.0,
                            max_deviation=0.1, left_only=False):
    """Seeded 2-D (XYZ with Z = 0) polyline of ``n`` segments with circular blends.

    ``left_only``: every turn is to the left by 10 deg .. ``max_turn_deg`` (the curvature
    never changes sign, see ``test_toppra.py`` for why that matters to toppra).
    """
    rng = np.random.default_rng(seed)
    lo = 10.0 if left_only else -max_turn_deg
    ang = np.cumsum(np.deg2rad(rng.uniform(lo, max_turn_deg, n)))
    ln = rng.uniform(*step, n)
    pts = np.concatenate(([[0.0, 0.0]], np.cumsum(np.c_[ln * np.cos(ang), ln * np.sin(ang)],
                                                   axis=0)))
    pts3 = np.c_[pts, np.zeros(len(pts))]
    return kunz_stilman_path(pts3, max_deviation, XYZ)


class ToppraPath:
    """Our :class:`Path` behind toppra's ``AbstractGeometricPath`` interface.

    ``__call__(s, order)`` returns q, q' or q'' (shape ``(N, dof)``, or ``(dof,)`` for a
    scalar); ``dof`` and ``path_interval`` as toppra expects. At a segment break the
    right-hand segment is used.
    """

    def __init__(self, path):
        self.path = path

    def __call__(self, s, order=0):
        scalar = np.ndim(s) == 0
        out = self.path.evaluate(np.atleast_1d(np.asarray(s, float)))[order]
        return out[0] if scalar else out

    @property
    def dof(self):
        return self.path.n_axes

    @property
    def path_interval(self):
        return np.array([0.0, self.path.total_length])

    @property
    def waypoints(self):
        return None

    def eval(self, s):
        return self(s, 0)

    def evald(self, s):
        return self(s, 1)

    def evaldd(self, s):
        return self(s, 2)


def toppra_solve(path, limits, gridpoints):
    """toppra (seidel, interpolation) on ``gridpoints``: returns ``(time_s, sd, build_s,
    solve_s)`` with ``sd`` the path speed at the grid points (``None`` on failure)."""
    import time

    import toppra
    import toppra.algorithm as algo
    import toppra.constraint as constraint

    toppra.setup_logging("WARNING")
    lim = limits.for_axes(path.axes)
    t0 = time.perf_counter()
    vlim = np.c_[-lim.v_max, lim.v_max]
    alim = np.c_[-lim.a_max, lim.a_max]
    pc_v = constraint.JointVelocityConstraint(vlim)
    pc_a = constraint.JointAccelerationConstraint(
        alim, discretization_scheme=constraint.DiscretizationType.Interpolation)
    inst = algo.TOPPRA([pc_v, pc_a], ToppraPath(path), gridpoints=np.asarray(gridpoints),
                       solver_wrapper="seidel")
    t1 = time.perf_counter()
    sdd, sd, _ = inst.compute_parameterization(0, 0)
    t2 = time.perf_counter()
    if sd is None:
        return None, None, t1 - t0, t2 - t1
    sd = np.maximum(sd, 0.0)
    v = sd[:-1] + sd[1:]
    T = float(np.sum(2 * np.diff(gridpoints) / v))
    return T, sd, t1 - t0, t2 - t1


def ruckig_line_time(L: float, V: float, A: float, J: float, a_s: float = 0.0) -> float:
    """ruckig's time-optimal straight move of length ``L`` mm from rest to rest under
    ``V`` mm/s, ``A`` mm/s^2 and ``J`` mm/s^3, starting with acceleration ``a_s`` and
    ending with ``-a_s`` (the rulebook's one-cycle step at the path ends: the
    surroundings rest), s. The independent reference of the jerk tests (ruckig is a
    test dependency; the caller skips without it)."""
    import ruckig
    otg = ruckig.Ruckig(1)
    inp = ruckig.InputParameter(1)
    traj = ruckig.Trajectory(1)
    inp.current_position, inp.target_position = [0.0], [L]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [V], [A], [J]
    inp.current_acceleration, inp.target_acceleration = [a_s], [-a_s]
    otg.calculate(inp, traj)
    return traj.duration


def largest_accepted(path, lim, hand, lo_v: float, hi_v: float,
                     bounds: str = "acc+freq") -> float:
    """The largest speed ``v`` in ``[lo_v, hi_v]`` whose hand motion ``hand(v)`` (a
    :class:`~reference.core.profile.Profile`) the checker accepts under ``bounds``, by
    bisection (50 halvings), mm/s: the corner speed of a hand reference, found by the
    judge rather than by the construction under test."""
    from reference.core.constraints import BOUND_SETS, check_profile
    for _ in range(50):
        mid = 0.5 * (lo_v + hi_v)
        if check_profile(path, lim, hand(mid)).ok(BOUND_SETS[bounds]):
            lo_v = mid
        else:
            hi_v = mid
    return lo_v
