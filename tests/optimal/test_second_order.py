"""The second-order upper bound and the sharper interval bounds of the lower bound, each
against an independent reference.

* :func:`optimal.problem.interval_times` with a slope (``b`` quadratic in ``s``): against
  adaptive quadrature of ``int ds / sqrt(b)``;
* line tents (:mod:`optimal.upper`): on straight programs with feed changes and stops the
  upper bound equals the exact optimum, computed here independently from the closed-form
  speed envelope ``b*(s) = min_sigma (cap(sigma) + 2 A |s - sigma|)``, on the first grid;
* slopes (:func:`optimal.problem.acceleration_slopes`): on tangent S-bends the grid upper
  bound converges at second order (against a Richardson-extrapolated toppra reference),
  and the checker needs no time scaling;
* exact derivative ranges (:func:`optimal.bounds.derivative_ranges`): against dense
  sampling of the path;
* the monotone interval bound (:func:`optimal.bounds._monotone_peak`): a feasible motion
  (toppra on a fine grid, accepted by the checker) never exceeds it inside any interval.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

import optimal
from oracle_cases import line_path, machine
from optimal.backends import get_backend
from optimal.bounds import _interval_data, _monotone_peak, derivative_ranges, lower_bound
from optimal.grid import grid_from_counts, initial_grid
from optimal.oracle import _solve_grid
from optimal.problem import interval_geometry, interval_times
from optimal.upper import line_tents, upper_interval_times, verified_profile
from reference.machine import load_machine
from reference.nc import parse_text
from reference.prepare import build_path


def test_interval_times_with_slopes_match_quadrature():
    rng = np.random.default_rng(11)
    for _ in range(400):
        D = 10 ** rng.uniform(-3, 1)
        b0 = 10 ** rng.uniform(0, 6)
        b1 = b0 * 10 ** rng.uniform(-2, 2)
        g = rng.choice([-1.0, 1.0]) * 0.25 * min(b0, b1) / D ** 2 * 10 ** rng.uniform(-12, 0)
        got = interval_times(np.array([0.0, D]), np.array([b0, b1]), np.array([g]))[0]
        alpha = (b1 - b0) / (2 * D) - g * D / 2
        ref = quad(lambda t: 1 / np.sqrt(b0 + 2 * alpha * t + g * t * t), 0, D,
                   epsabs=0, epsrel=1e-13, limit=200)[0]
        assert got == pytest.approx(ref, rel=1e-12)
    # gamma = 0 is the linear formula exactly
    s, b = np.array([0.0, 2.0, 5.0]), np.array([4.0, 9.0, 1.0])
    assert np.array_equal(interval_times(s, b, np.zeros(2)), interval_times(s, b))


def _envelope_time(s_breaks, caps, A_path):
    """Exact minimum time of a straight rest-to-rest run with piecewise constant speed
    caps (per segment): ``b*`` is the lower envelope of ``cap_i + 2 A dist(s, seg_i)``
    and ``2 A |s - end|`` (rest at both ends). Every piece of these is affine, so ``b*``
    is linear between the crossings of any two of them; with all crossings among the
    sample points ``int ds / sqrt(b)`` is exact piece by piece."""
    M = 2.0 * A_path
    lines = [(0.0, cap) for cap in caps]                        # (slope, value at s = 0)
    for i, c in enumerate(caps):
        lo, hi = s_breaks[i], s_breaks[i + 1]
        lines += [(-M, c + M * lo), (M, c - M * hi)]
    lines += [(M, -M * s_breaks[0]), (-M, M * s_breaks[-1])]
    pts = set(np.linspace(s_breaks[0], s_breaks[-1], 20001).tolist()) | set(s_breaks)
    for i in range(len(lines)):
        for j in range(i + 1, len(lines)):
            (k1, c1), (k2, c2) = lines[i], lines[j]
            if k1 != k2:
                x = (c2 - c1) / (k1 - k2)
                if s_breaks[0] < x < s_breaks[-1]:
                    pts.add(x)
    s = np.array(sorted(pts))
    b = np.full(s.size, np.inf)
    for i, c in enumerate(caps):
        lo, hi = s_breaks[i], s_breaks[i + 1]
        d = np.where(s < lo, lo - s, np.where(s > hi, s - hi, 0.0))
        b = np.minimum(b, c + M * d)
    b = np.minimum(b, M * np.minimum(s - s_breaks[0], s_breaks[-1] - s))
    v = np.sqrt(np.maximum(b, 0.0))
    vs = v[:-1] + v[1:]
    return float(np.sum(np.where(vs > 0, 2 * np.diff(s) / vs, 0.0)))


@pytest.mark.parametrize("feeds", [(6000.0,), (6000.0, 600.0, 6000.0), (300.0, 9000.0, 120.0)])
def test_line_tents_make_straight_runs_exact_on_the_first_grid(feeds):
    """A run of collinear lines with feed changes (the slow segment forces the speed
    down to its feed at its breaks): the oracle's upper bound is the exact optimum, on
    its first grid, however short the acceleration phases are against the intervals."""
    A, L = 1000.0, 20.0
    pts = [[i * L, 0.0, 0.0] for i in range(len(feeds) + 1)]
    path = line_path(pts, feed=np.array(feeds) / 60.0)
    lim = machine(1e4, A)
    exact = _envelope_time(path.s_breaks, (np.array(feeds) / 60.0) ** 2, A)
    sol = optimal.solve(path, lim)
    assert sol.iterations == 1
    assert sol.upper_bound_s == pytest.approx(exact, rel=1e-9)
    assert sol.lower_bound_s <= exact * (1 + 1e-12)


def test_line_tent_profile_is_the_exact_trapezoid():
    A, V, L = 1000.0, 100.0, 50.0
    path = line_path([[0.0, 0.0, 0.0], [L, 0.0, 0.0]], feed=V)
    lim = machine(1e4, A)
    la = lim.for_axes(path.axes)
    g = grid_from_counts(path, np.array([2]))
    b = np.array([0.0, V * V, 0.0])
    tents = line_tents(path, la, g)
    t = upper_interval_times(g.s, b, None, tents)
    assert t.sum() == pytest.approx(L / V + V / A, rel=1e-14)
    prof, lam, rep = verified_profile(path, lim, g.s, b, path.block[g.segment], "acc",
                                      None, tents)
    assert lam == 1.0 and rep.ok(("velocity", "acceleration", "feed", "stop"))
    assert prof.duration == pytest.approx(L / V + V / A, rel=1e-14)
    assert np.max(np.abs(prof.a)) == pytest.approx(A, rel=1e-12)


def test_a_ramp_shorter_than_round_off_of_its_interval_is_kept_where_it_changes_the_speed():
    """At 1 mm/min the ramp to 1.5 mm/min at 2.5 m/s^2 is 6.9e-8 mm long, below 1e-9 of
    its 87 mm interval: dropped as round-off, it left the interval cruising at the old
    speed into a node at the new one, and the next interval, integrated from the speed
    the profile arrived with, ended 29 mm short of its knot (a fuzzer's program, exit 3).
    Hand motion: the ramp at the tent's M / 2, then 1.5 mm/min to the end."""
    from optimal.upper import LineTents, grid_profile
    v0, v1, M, D, D2 = 1.0 / 60.0, 1.5 / 60.0, 5000.0, 86.75434355, 10.0
    b0, b1 = v0 * v0, v1 * v1
    s = np.array([0.0, D, D + D2])
    tents = LineTents(cap=np.array([b1, b1]), slope=np.array([M, M]))
    prof = grid_profile(s, np.array([b0, b1, b1]), np.array([0, 0]), None, tents)
    ramp = (b1 - b0) / M
    assert ramp < 1e-9 * D
    hand = ramp / (0.5 * (v0 + v1)) + (D - ramp) / v1 + D2 / v1
    assert prof.duration == pytest.approx(hand, rel=1e-12)
    assert prof.s[-1] == s[-1] and prof.v[-1] == pytest.approx(v1, rel=1e-12)
    assert np.max(np.abs(prof.a)) <= M / 2 * (1 + 1e-12)


def _grid_upper(path, limits, counts, slopes: bool):
    la = limits.for_axes(path.axes)
    g = grid_from_counts(path, counts)
    if slopes:
        _, res, gamma, _, _ = _solve_grid(path, la, g, get_backend("fast"), None)
        b = res.b
    else:
        from optimal.backends.fast import sweep
        from optimal.problem import build_grid_problem
        b, _, _ = sweep(build_grid_problem(path, la, g))
        gamma = None
    prof, lam, _ = verified_profile(path, limits, g.s, b, path.block[g.segment], "acc",
                                    gamma, line_tents(path, la, g))
    return prof.duration, lam


def test_slopes_make_the_grid_optimum_second_order_on_tangent_arcs():
    """On eight tangent S-bends (the optimum follows an axis limit along most of every
    arc, where a constant acceleration per interval is first order) the grid upper bound
    with slopes converges about fourfold per halving (measured 3.9-4.5), without them
    twofold, and the checker accepts every grid profile as it is. Reference: toppra's
    checker-accepted times at 2,000 and 4,000 nodes per arc, Richardson-extrapolated
    (as in ``test_arc_bounds``)."""
    from optimal.grid import initial_counts
    from test_arc_bounds import _sbend_path, _toppra_feasible_time

    path = _sbend_path(8)
    limits = load_machine(None).limits
    c0 = initial_counts(path).astype(np.int64)
    t_ref = (2 * _toppra_feasible_time(path, limits, per_arc=4000)[0]
             - _toppra_feasible_time(path, limits, per_arc=2000)[0])
    err_s, err_0 = [], []
    for f in (1, 2, 4):
        t, lam = _grid_upper(path, limits, f * c0, True)
        assert lam <= 1 + 1e-9
        err_s.append(t - t_ref)
        err_0.append(_grid_upper(path, limits, f * c0, False)[0] - t_ref)
    assert all(e > 0 for e in err_s + err_0), (err_s, err_0)
    assert err_s[0] / err_s[1] > 3.3 and err_s[1] / err_s[2] > 3.3, err_s
    assert err_0[0] / err_0[1] < 2.5            # the first-order reference behaviour
    assert err_s[2] < 0.25 * err_0[2], (err_s, err_0)


def test_derivative_ranges_match_dense_sampling():
    text = ("G90 G17 G1 X10 Y0 Z0 F6000\nG3 X0 Y10 Z4 I-10 J0\nG2 X-7 Y3 I0 J-7 TURN=1\n"
            "G18 G3 X-7 Y3 Z10 I5 K3\nG1 X4 Y-2 Z1\nM30\n")
    path = build_path(parse_text(text, "h.mpf"), load_machine(None))
    g = initial_grid(path, 40)
    geo = interval_geometry(path, g)
    t_lo, t_hi, k_lo, k_hi, exact, tol = derivative_ranges(path, g, *geo)
    assert np.all(exact)
    u = np.linspace(0.0, 1.0, 2001)
    for k in range(g.n_intervals):
        s = g.s[k] + u * (g.s[k + 1] - g.s[k])
        _, dq, ddq, _ = path.evaluate(s, segment=np.full(u.size, g.segment[k]))
        assert np.all(dq.min(axis=0) >= t_lo[k] - 1e-12)
        assert np.all(dq.max(axis=0) <= t_hi[k] + 1e-12)
        assert np.all(ddq.min(axis=0) >= k_lo[k] - 1e-12)
        assert np.all(ddq.max(axis=0) <= k_hi[k] + 1e-12)
        # and tight: the sampled extremes come within the sampling error
        step = (g.s[k + 1] - g.s[k]) / 2000
        assert np.all(dq.min(axis=0) - t_lo[k] <= step ** 2 + 1e-12)
        assert np.all(t_hi[k] - dq.max(axis=0) <= step ** 2 + 1e-12)


@pytest.mark.parametrize("text,lim", [
    ("G90 G17 G1 X10 Y0 F9000\nG3 X-10 Y0 I-10 J0\nG2 X-30 Y0 I-10 J0\nM30\n",
     ((500,) * 3, (2000,) * 3)),
    ("G90 G17 G1 X10 Y0 F9000\nG2 X0 Y-10 I-10 J0\nM30\n", ((500, 80, 500), (3000, 300, 1000))),
])
def test_monotone_interval_bound_holds_for_a_feasible_motion(text, lim):
    """Inside every interval the speed of a motion accepted by the checker (toppra on a
    fine grid, time-scaled until accepted) stays below ``_monotone_peak`` of the
    relaxation's node bounds."""
    toppra = pytest.importorskip("toppra")
    from test_arc_bounds import _FeedPath, _limits
    import toppra.algorithm as algo
    import toppra.constraint as constraint

    toppra.setup_logging("WARNING")
    path = build_path(parse_text(text, "m.mpf"), load_machine(None))
    limits = _limits(*lim)
    la = limits.for_axes(path.axes)
    fine = grid_from_counts(path, np.where(path.radius > 0, 3000, 200))
    v = np.r_[la.v_max, float(np.min(path.feed))]
    a = np.r_[la.a_max, 1e30]
    inst = algo.TOPPRA([constraint.JointVelocityConstraint(np.c_[-v, v]),
                        constraint.JointAccelerationConstraint(
                            np.c_[-a, a],
                            discretization_scheme=constraint.DiscretizationType.Interpolation)],
                       _FeedPath(path), gridpoints=fine.s, solver_wrapper="seidel")
    _, sd, _ = inst.compute_parameterization(0, 0)
    prof, _, _ = verified_profile(path, limits, fine.s, np.maximum(sd, 0.0) ** 2,
                                  path.block[fine.segment])
    g = initial_grid(path, 60)
    _, _, _, b_hat = lower_bound(path, la, g)
    peak = _monotone_peak(_interval_data(path, la, g), b_hat)
    assert np.any(np.isfinite(peak))
    k = np.clip(np.searchsorted(g.s, prof.s, side="right") - 1, 0, g.n_intervals - 1)
    assert np.all(prof.v ** 2 <= peak[k] * (1 + 1e-9) + 1e-9)
