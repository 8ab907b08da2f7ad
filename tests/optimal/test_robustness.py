"""Bad and degenerate input, result contract, JSON, progress, and seeded invariants."""

from __future__ import annotations

import json

import numpy as np
import pytest

import optimal
from oracle_cases import XYZ, line_arc_line, line_path, machine, random_blended_polyline
from reference.core import (AxisLimits, BlockSpan, InfeasibleError, MachineDataError,
                            PathError, path_from_pieces)
from reference.core.constraints import BOUND_SETS, check_profile
from reference.core.geometry import line_segments
from reference.core.tolerances import VEL_TOL_MM_S


def all_finite(sol) -> bool:
    arrays = [sol.segment_times_s, sol.block_times_s, sol.grid, sol.profile.t, sol.profile.v]
    nums = [sol.lower_bound_s, sol.upper_bound_s, sol.objective_s, sol.gap, sol.time_scale]
    nums += [b.time_s for b in sol.blocks] + [b.v_exit for b in sol.blocks]
    return all(np.all(np.isfinite(a)) for a in arrays) and all(np.isfinite(nums))


def test_zero_feed_names_block_and_line():
    pts = [[0, 0, 0], [10, 0, 0], [20, 0, 0]]
    pieces = [line_segments(np.array(pts[:-1], float), np.array(pts[1:], float),
                            np.array([True] * 3), np.array([3, 4]))]
    blocks = (BlockSpan(3, 17, "N40", "G1", 0.0, 10.0, 0, 1, feed_mm_s=100.0),
              BlockSpan(4, 18, "N50", "G1", 10.0, 20.0, 1, 1, feed_mm_s=0.0))
    p = path_from_pieces(XYZ, pieces, feed=np.array([100.0, 0.0]), blocks=blocks)
    with pytest.raises(InfeasibleError, match=r"block 4 \(line 18, N50\).*feed") as exc:
        optimal.solve(p, machine(200.0, 1000.0))
    assert exc.value.block == 4


def test_limit_of_zero_is_rejected_with_the_key():
    with pytest.raises(MachineDataError, match="axis.Y.a_max"):
        AxisLimits("Y", 100.0, 0.0, 1e4)


def test_zero_length_segments_are_rejected_by_the_path():
    with pytest.raises(PathError, match="positive length"):
        line_path([[0, 0, 0], [0, 0, 0], [1, 0, 0]])


def test_unknown_or_unsupported_bound_set_and_bad_tol():
    p = line_path([[0, 0, 0], [1, 0, 0]])
    lim = machine(100.0, 1000.0)
    with pytest.raises(ValueError, match="unknown bound set 'snap'"):
        optimal.solve(p, lim, bounds="snap")
    with pytest.raises(ValueError, match="tol"):
        optimal.solve(p, lim, tol=0.0)


@pytest.mark.parametrize("ovl", [1.0, 1.3])
def test_reversal_of_180_degrees(ovl):
    A, t_ipo = 1000.0, 0.004
    lim = machine(200.0, A, ovl=ovl, t_ipo=t_ipo)
    p = line_path([[0, 0, 0], [10, 0, 0], [0, 0, 0]])
    sol = optimal.solve(p, lim)
    v = sol.blocks[0].v_exit
    vc = A * (ovl - 1.0) * t_ipo / 2.0         # |t_out - t_in| = 2 on X
    assert v == pytest.approx(vc, rel=1e-9, abs=0.0)
    assert sol.status == optimal.SolveStatus.OPTIMAL
    assert sol.lower_bound_s <= sol.upper_bound_s
    assert all_finite(sol)
    assert check_profile(p, lim, sol.profile).ok(BOUND_SETS["acc"])


def test_empty_path_takes_no_time():
    p = path_from_pieces(XYZ, [])
    sol = optimal.solve(p, machine(100.0, 1000.0))
    assert sol.status == optimal.SolveStatus.OPTIMAL
    assert sol.lower_bound_s == sol.upper_bound_s == 0.0
    d = optimal.to_json_dict(sol)
    assert d["oracle"]["upper_bound_s"] == 0.0 and d["blocks"] == []


def test_thousands_of_micrometre_segments():
    rng = np.random.default_rng(5)
    n = 3000
    ang = np.cumsum(rng.normal(0.0, 0.05, n))
    xy = np.cumsum(np.c_[1e-3 * np.cos(ang), 1e-3 * np.sin(ang)], axis=0)
    pts = np.c_[np.vstack(([0.0, 0.0], xy)), np.zeros(n + 1)]
    p = line_path(pts, feed=100.0)
    lim = machine(500.0, 2000.0)
    sol = optimal.solve(p, lim, max_grid=100_000)
    assert sol.status in (optimal.SolveStatus.OPTIMAL, optimal.SolveStatus.GAP_NOT_MET)
    assert 0 < sol.lower_bound_s <= sol.upper_bound_s
    assert all_finite(sol)
    assert len(sol.blocks) == n


def test_small_grid_budget_gives_gap_not_met_with_valid_bounds():
    p = random_blended_polyline(20, 2)
    lim = machine((250.0, 200.0, 100.0), (3000.0, 2000.0, 1000.0))
    fine = optimal.solve(p, lim, tol=1e-3)
    coarse = optimal.solve(p, lim, tol=1e-6, max_grid=600, initial_intervals=200)
    assert coarse.status == optimal.SolveStatus.GAP_NOT_MET
    assert "both bounds are valid" in coarse.message
    assert coarse.lower_bound_s <= fine.upper_bound_s
    assert coarse.upper_bound_s >= fine.lower_bound_s
    assert coarse.grid_points <= 601 + 1


def test_solution_contract_and_json():
    lim = machine(200.0, 1000.0)
    p = line_arc_line(5.0, 20.0, feed=150.0)
    calls = []
    sol = optimal.solve(p, lim, progress=lambda msg, f: calls.append((msg, f)))
    assert sol.status is optimal.SolveStatus.OPTIMAL and sol.status == "optimal"
    assert sol.gap <= 2e-3
    assert calls and calls[-1] == ("done", 1.0)
    fr = [f for _, f in calls]
    assert all(0.0 <= f <= 1.0 for f in fr) and fr == sorted(fr)
    assert sol.segment_times_s.sum() == pytest.approx(sol.upper_bound_s)
    assert sol.block_times_s.sum() == pytest.approx(sol.upper_bound_s)
    assert len(sol.active) == sol.grid_points - 1
    assert sol.grid_points == sol.grid.size
    assert sol.total_time_s >= sol.solve_time_s >= 0
    assert all_finite(sol)
    d = optimal.to_json_dict(sol)
    json.dumps(d)
    assert set(d["oracle"]) == {"lower_bound_s", "upper_bound_s", "status", "solve_time_s",
                                "grid_points"}
    assert d["oracle"]["status"] == "optimal"
    assert [set(r) for r in d["blocks"]] == [{"block", "t_oracle_s", "v_exit_oracle",
                                             "limit_oracle"}] * 3
    assert d["blocks"][1]["limit_oracle"] in ("feed", "acceleration X", "acceleration Y")


def test_arc_limit_labels():
    lim = machine(500.0, 1000.0)
    p = line_arc_line(5.0, 20.0)
    sol = optimal.solve(p, lim)
    assert sol.blocks[1].cause.startswith("acceleration")
    assert sol.blocks[-1].v_exit == 0.0
    assert set(sol.active) <= {"feed", "stop", "velocity_jump", "none"} | {
        f"{k} {a}" for k in ("velocity", "acceleration") for a in XYZ}


@pytest.mark.parametrize("seed", range(6))
def test_seeded_invariants(seed):
    """No NaN, lower <= upper, the profile passes the checker, blocks sum to the total,
    and the lower bound on a coarse grid stays below the upper bound on a fine one."""
    rng = np.random.default_rng(seed)
    p = random_blended_polyline(int(rng.integers(3, 25)), seed,
                                max_deviation=float(rng.uniform(0.05, 2.0)))
    v = rng.uniform(50, 500, 3)
    a = rng.uniform(300, 5000, 3)
    lim = machine(v, a, ovl=float(rng.choice([1.0, 1.2])))
    sol = optimal.solve(p, lim, tol=float(rng.choice([2e-3, 1e-2])))
    assert sol.status == optimal.SolveStatus.OPTIMAL
    assert 0 < sol.lower_bound_s <= sol.upper_bound_s
    assert all_finite(sol)
    assert check_profile(p, lim, sol.profile).ok(BOUND_SETS["acc"])
    assert sol.block_times_s.sum() == pytest.approx(sol.upper_bound_s)
    coarse = optimal.solve(p, lim, max_iterations=1, initial_intervals=50)
    assert coarse.lower_bound_s <= sol.upper_bound_s
    assert coarse.upper_bound_s >= sol.lower_bound_s
    assert np.all(sol.profile.v >= 0)
    stops = sol.profile.v[np.searchsorted(sol.profile.s, p.s_breaks[p.stop])]
    assert np.all(stops <= VEL_TOL_MM_S)


def test_helix_with_feed():
    from reference.core.geometry import arc_segment
    start = np.array([10.0, 0.0, 0.0])
    arc = arc_segment(start, start + [0, 0, 8.0], np.zeros(3), (0, 1), False, 2,
                      np.array([True] * 3), 0, 1e-6)
    p = path_from_pieces(XYZ, [arc], feed=250.0)
    lim = machine((250.0, 200.0, 50.0), (3000.0, 2000.0, 1000.0))
    sol = optimal.solve(p, lim)
    assert sol.status == optimal.SolveStatus.OPTIMAL
    assert 0 < sol.lower_bound_s <= sol.upper_bound_s
    assert check_profile(p, lim, sol.profile).ok(BOUND_SETS["acc"])
    # never faster than the feed allows
    assert sol.lower_bound_s >= p.total_length / 250.0


def test_junction_label_at_a_corner_with_overload():
    lim = machine(500.0, 2000.0, ovl=1.5)
    p = line_path([[0, 0, 0], [5, 0, 0], [5, 5, 0]])
    sol = optimal.solve(p, lim)
    from optimal.problem import build_grid_problem
    # the interval ending at the corner is a deceleration ramp to the junction cap
    k = int(np.searchsorted(sol.grid, 5.0))
    assert sol.active[k - 1].startswith("acceleration")
    assert sol.blocks[0].v_exit == pytest.approx(2000.0 * 0.5 * 0.004, rel=1e-9)
    del build_grid_problem
