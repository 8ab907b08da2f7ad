"""Hand-solvable cases with exact optima: lower <= exact <= upper, and published values."""

from __future__ import annotations

import numpy as np
import pytest

import optimal
from oracle_cases import (XYZ, kunz_stilman_path, line_arc_line, line_path, machine,
                          semicircle)
from reference.core import BlockSpan, path_from_pieces
from reference.core.constraints import BOUND_SETS, check_profile
from reference.core.geometry import line_segments


def rest_to_rest(L: float, v: float, a: float) -> float:
    """Minimum time of a straight rest-to-rest move with path limits v, a."""
    if v * v / a >= L:
        return 2.0 * np.sqrt(L / a)
    return L / v + v / a


def assert_brackets(sol, exact: float, slack: float = 1e-9) -> None:
    assert sol.lower_bound_s <= exact * (1 + slack)
    assert sol.upper_bound_s >= exact * (1 - slack)
    assert sol.lower_bound_s <= sol.upper_bound_s


def assert_accepted(path, limits, sol) -> None:
    rep = check_profile(path, limits, sol.profile)
    assert rep.ok(BOUND_SETS["acc"]), rep.violations(BOUND_SETS["acc"])
    assert sol.profile.duration == pytest.approx(sol.upper_bound_s, rel=1e-12)


@pytest.mark.parametrize("L", [0.5, 10.0, 100.0])
def test_single_line_triangular_or_trapezoid(L):
    lim = machine(200.0, 1000.0)
    p = line_path([[0, 0, 0], [L, 0, 0]])
    exact = rest_to_rest(L, 200.0, 1000.0)
    sol = optimal.solve(p, lim)
    assert sol.status == optimal.SolveStatus.OPTIMAL
    assert_brackets(sol, exact)
    assert sol.upper_bound_s == pytest.approx(exact, rel=2e-3)
    assert sol.lower_bound_s == pytest.approx(exact, rel=1e-6)   # interval-exact on lines
    assert_accepted(p, lim, sol)


def test_diagonal_line_uses_per_axis_projection():
    lim = machine((250.0, 200.0, 100.0), (3000.0, 2000.0, 1000.0))
    d = np.array([200.0, 100.0, 0.0])
    L = float(np.linalg.norm(d))
    t = np.abs(d / L)
    v = min(250.0 / t[0], 200.0 / t[1])
    a = min(3000.0 / t[0], 2000.0 / t[1])
    exact = rest_to_rest(L, v, a)
    p = line_path([[0, 0, 0], d])
    sol = optimal.solve(p, lim, tol=1e-4)
    assert_brackets(sol, exact)
    assert sol.upper_bound_s == pytest.approx(exact, rel=1e-4)
    assert sol.blocks[0].cause in ("velocity X", "acceleration X", "acceleration Y",
                                          "velocity Y")


def test_feed_limits_path_speed():
    lim = machine(500.0, 2000.0)
    p = line_path([[0, 0, 0], [100, 0, 0]], feed=50.0)
    exact = rest_to_rest(100.0, 50.0, 2000.0)
    sol = optimal.solve(p, lim)
    assert_brackets(sol, exact)
    assert sol.upper_bound_s == pytest.approx(exact, rel=1e-3)
    assert sol.blocks[0].cause == "feed"
    assert "feed" in sol.active


def test_rapid_moves_at_axis_limits():
    lim = machine((300.0, 100.0, 100.0), 2000.0)
    p = line_path([[0, 0, 0], [1000, 0, 0]], feed=np.inf, rapid=np.array([True]))
    exact = rest_to_rest(1000.0, 300.0, 2000.0)
    sol = optimal.solve(p, lim)
    assert_brackets(sol, exact)
    assert sol.upper_bound_s == pytest.approx(exact, rel=1e-3)
    assert sol.blocks[0].cause == "velocity X"


def test_exact_stop_inside_a_straight_line():
    lim = machine(200.0, 1000.0)
    p = line_path([[0, 0, 0], [30, 0, 0], [60, 0, 0]], stops=("start", "exact stop G9", "end"))
    exact = 2 * rest_to_rest(30.0, 200.0, 1000.0)
    sol = optimal.solve(p, lim)
    assert_brackets(sol, exact)
    assert sol.blocks[0].v_exit == 0.0
    assert sol.upper_bound_s == pytest.approx(exact, rel=1e-3)


def test_semicircle_rest_to_rest():
    """Tangential axis X unconstrained (A_x = 1e9): b = 2 A R / (1 + |sin phi|) exactly,
    so T = 2 sqrt(2 R / A_y) (up to a transient below 1e-6 relative)."""
    R, A = 10.0, 1000.0
    lim = machine((1e4, 1e4, 1e4), (1e9, A, A))
    p = semicircle(R)
    exact = 2 * np.sqrt(2 * R / A)
    sol = optimal.solve(p, lim)
    assert sol.status == optimal.SolveStatus.OPTIMAL
    assert sol.lower_bound_s <= exact * (1 + 1e-6)
    assert sol.upper_bound_s >= exact
    assert sol.upper_bound_s <= exact * (1 + 2e-3)
    assert_accepted(p, lim, sol)


def test_line_arc_line_tangent():
    """Arc entry speed sqrt(A_y R) (the y axis carries all of the centripetal
    acceleration there), lines at feed with X acceleration, arc as in the semicircle."""
    R, L, A, Ax, F = 10.0, 50.0, 1000.0, 1e5, 400.0
    lim = machine((1e4, 1e4, 1e4), (Ax, A, A))
    p = line_arc_line(R, L, feed=F)
    ve = np.sqrt(A * R)
    t_line = F / Ax + (F - ve) / Ax + (L - F * F / (2 * Ax) - (F * F - ve * ve) / (2 * Ax)) / F
    exact = 2 * t_line + 2 * np.sqrt(2 * R / A)
    sol = optimal.solve(p, lim)
    assert sol.lower_bound_s <= exact * (1 + 1e-6)
    assert sol.upper_bound_s >= exact
    assert sol.upper_bound_s <= exact * (1 + 2e-3)
    # speed at the arc entry: the centripetal cap
    assert sol.blocks[0].v_exit == pytest.approx(ve, rel=1e-3)
    assert sol.blocks[0].v_exit <= ve * (1 + 1e-9)
    assert sum(b.time_s for b in sol.blocks) == pytest.approx(sol.upper_bound_s)


@pytest.mark.parametrize("ovl", [1.0, 1.2])
def test_corner_90_degrees(ovl):
    A, V, t_ipo = 2000.0, 500.0, 0.004
    lim = machine(V, A, ovl=ovl, t_ipo=t_ipo)
    p = line_path([[0, 0, 0], [50, 0, 0], [50, 50, 0]])
    jump = A * (ovl - 1.0) * t_ipo          # |t_out - t_in| = 1 on X and Y
    vc = jump / 1.0

    def leg(v0, v1, L):   # fastest line with boundary speeds v0, v1 (both reachable)
        vp2 = (2 * A * L + v0 * v0 + v1 * v1) / 2
        if vp2 <= V * V:
            vp = np.sqrt(vp2)
            return (vp - v0) / A + (vp - v1) / A
        return ((V - v0) / A + (V - v1) / A
                + (L - (V * V - v0 * v0) / (2 * A) - (V * V - v1 * v1) / (2 * A)) / V)

    exact = 2 * leg(0.0, vc, 50.0)
    sol = optimal.solve(p, lim)
    assert_brackets(sol, exact)
    assert sol.upper_bound_s == pytest.approx(exact, rel=1e-3)
    v_corner = sol.blocks[0].v_exit
    if ovl == 1.0:
        assert v_corner == 0.0
    else:
        assert v_corner == pytest.approx(vc, rel=1e-9)
        assert sol.blocks[0].cause.startswith("acceleration")
    assert_accepted(p, lim, sol)


def test_dwell_adds_time_to_its_block():
    lim = machine(200.0, 1000.0)
    pts = np.array([[0, 0, 0], [20, 0, 0.0], [40, 0, 0]])
    pieces = [line_segments(pts[:-1], pts[1:], np.array([True] * 3), np.array([0, 2]))]
    blocks = (BlockSpan(0, 1, "N10", "G1", 0.0, 20.0, 0, 1, stop_reason=""),
              BlockSpan(1, 2, "N20", "none", 20.0, 20.0, 1, 0, stop_reason="dwell G4 0.5 s",
                        dwell_s=0.5),
              BlockSpan(2, 3, "N30", "G1", 20.0, 40.0, 1, 1, stop_reason=""))
    p = path_from_pieces(XYZ, pieces, stop_reason=("start", "dwell G4 0.5 s", "end"),
                         blocks=blocks)
    exact = 2 * rest_to_rest(20.0, 200.0, 1000.0) + 0.5
    sol = optimal.solve(p, lim)
    assert_brackets(sol, exact)
    assert sol.dwell_s == 0.5
    assert sol.block_times_s[1] == pytest.approx(0.5)
    assert sol.blocks[1].cause == "dwell G4 0.5 s"
    assert sol.profile.duration == pytest.approx(sol.upper_bound_s)
    assert sol.block_times_s.sum() == pytest.approx(sol.upper_bound_s)


# ---------------------------------------------------------------- published cases
MOVEIT_AXES = ("X", "Y", "Z", "A")


def test_moveit_totg_test3_within_0_02_percent():
    """MoveIt TOTG unit test ``test3``: published 1919.5597888812974 s (time_step 0.001)."""
    wp = [(1427, 368, 690, 90), (1427, 368, 790, 90), (952.499938964844, 433, 1051, 90),
          (452.5, 533, 1051, 90), (452.5, 533, 951, 90)]
    p = kunz_stilman_path(wp, 100.0, MOVEIT_AXES)
    assert p.n_segments == 7
    assert p.total_length == pytest.approx(1213.34, abs=0.01)
    lim = machine((1.3, 0.67, 0.67, 0.5), 0.002, axes=MOVEIT_AXES)
    pub = 1919.5597888812974
    sol = optimal.solve(p, lim, tol=1e-4)
    assert sol.status == optimal.SolveStatus.OPTIMAL
    assert abs(sol.upper_bound_s - pub) / pub <= 2e-4
    assert abs(sol.lower_bound_s - pub) / pub <= 2e-4
    assert sol.lower_bound_s <= pub * (1 + 2e-4)


def test_moveit_totg_test1_straight_line_b2():
    p = line_path([[1424, 984.999694824219, 2126, 0], [1423, 985.000244140625, 2126, 0]],
                  axes=MOVEIT_AXES)
    lim = machine((1.3, 0.67, 0.67, 0.5), 0.00249, axes=MOVEIT_AXES)
    sol = optimal.solve(p, lim, tol=1e-6)
    ref = 40.0802408
    assert sol.upper_bound_s == pytest.approx(ref, rel=1e-5)
    assert sol.lower_bound_s == pytest.approx(ref, rel=1e-5)


def test_moveit_single_dof_b3():
    p = line_path([[1.881943], [2.600542]], axes=("X",))
    lim = machine(4.54, 28.0, axes=("X",))
    sol = optimal.solve(p, lim, tol=1e-6)
    ref = 0.320401
    assert sol.upper_bound_s == pytest.approx(ref, rel=1e-5)
    assert sol.lower_bound_s == pytest.approx(ref, rel=1e-5)
    assert 2 * np.sqrt((2.600542 - 1.881943) / 28.0) == pytest.approx(ref, rel=1e-5)


@pytest.mark.parametrize("n", [4, 16, 64, 256])
def test_lower_bound_holds_on_every_grid(n):
    """The relaxation is a bound on any grid, however coarse (no refinement here)."""
    from optimal.bounds import lower_bound
    from optimal.grid import initial_grid

    R, L, A, Ax, F = 10.0, 50.0, 1000.0, 1e5, 400.0
    lim = machine((1e4, 1e4, 1e4), (Ax, A, A))
    cases = []
    p = line_arc_line(R, L, feed=F)
    ve = np.sqrt(A * R)
    t_line = F / Ax + (F - ve) / Ax + (L - F * F / (2 * Ax) - (F * F - ve * ve) / (2 * Ax)) / F
    cases.append((p, lim, 2 * t_line + 2 * np.sqrt(2 * R / A)))
    lim2 = machine((1e4, 1e4, 1e4), (1e9, A, A))
    cases.append((semicircle(R), lim2, 2 * np.sqrt(2 * R / A)))
    lim3 = machine((250.0, 200.0, 100.0), (3000.0, 2000.0, 1000.0))
    d = np.array([200.0, 100.0, 0.0])
    t = np.abs(d / np.linalg.norm(d))
    cases.append((line_path([[0, 0, 0], d]), lim3,
                  rest_to_rest(float(np.linalg.norm(d)), min(250 / t[0], 200 / t[1]),
                               min(3000 / t[0], 2000 / t[1]))))
    for path, limits, exact in cases:
        g = initial_grid(path, n, min_arc_intervals=2, max_arc_step_rad=np.pi)
        lb, t_lb, _, _ = lower_bound(path, limits.for_axes(path.axes), g)
        assert lb <= exact * (1 + 1e-6)
        assert np.all(t_lb >= 0) and np.all(np.isfinite(t_lb))
