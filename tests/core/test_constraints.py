"""check_profile on hand-made profiles that each break exactly one limit."""

from __future__ import annotations

import numpy as np
import pytest

from reference.core import AxisLimits, MachineLimits, Profile, ProfileError, path_from_pieces
from reference.core.constraints import (BOUND_SETS, CONSTRAINTS, check_profile, scale_time,
                                        time_scale_factor)
from reference.core.geometry import arc_segment, line_segments
from reference.core.tolerances import RATIO_TOL, VEL_TOL_MM_S

AX = ("X", "Y", "Z")
GEO = np.array([True, True, True])
V, A, J = 500.0, 2000.0, 40000.0


def limits(ovl: float = 1.2, f: float = 1000.0, ptj: float = 40000.0) -> MachineLimits:
    return MachineLimits(tuple(AxisLimits(a, V, A, J, ovl, f, ptj) for a in AX), 0.004)


def line_path(points, feed=np.inf, stops=None):
    pts = np.asarray(points, dtype=float)
    pieces = [line_segments(pts[:-1], pts[1:], GEO, np.arange(len(pts) - 1))]
    m = len(pts) - 1
    reasons = None if stops is None else tuple(stops)
    return path_from_pieces(AX, pieces, feed=feed, stop_reason=reasons)


def trapezoid(L: float, v: float, a: float) -> Profile:
    ta = v / a
    tc = (L - v * v / a) / v
    return Profile.from_phases([ta, tc, ta], [a, 0, -a], [0, 0, 0])


def scurve_rest_to_rest(L: float, v: float, a: float, j: float) -> Profile:
    """Symmetric 7-phase profile reaching v and a (requires L large enough)."""
    tj = a / j
    ta = v / a - tj
    s_acc = v * (tj + ta / 2 + tj / 2)  # distance of one ramp (v (ta + 2 tj)/2)
    s_acc = v * (ta + 2 * tj) / 2
    tc = (L - 2 * s_acc) / v
    assert tc > 0
    d = [tj, ta, tj, tc, tj, ta, tj]
    a0 = [0, a, a, 0, 0, -a, -a]
    jj = [j, 0, -j, 0, -j, 0, j]
    return Profile.from_phases(d, a0, jj)


def others_ok(report, broken: str) -> None:
    for r in report.results:
        if r.constraint in (broken, "frequency", "jerk"):
            continue
        assert r.ratio <= 1 + RATIO_TOL, (r.constraint, r)


def test_feasible_trapezoid_passes_acc_bounds():
    p = line_path([[0, 0, 0], [100, 0, 0]])
    r = check_profile(p, limits(), trapezoid(100, 400, 2000))
    assert r.ok(BOUND_SETS["acc"])
    assert r.worst("acceleration").ratio == pytest.approx(1.0)
    assert r.worst("velocity").ratio == pytest.approx(0.8)


def test_velocity_violation_on_a_diagonal_line_names_the_axis():
    p = line_path([[0, 0, 0], [200, 100, 0]])
    L = np.hypot(200, 100)
    r = check_profile(p, limits(), trapezoid(L, 600, 2000))
    w = r.worst("velocity")
    assert w.ratio == pytest.approx(600 * 200 / L / V) and w.ratio > 1
    assert w.axis == "X" and w.block == 0
    others_ok(r, "velocity")


def test_acceleration_violation_on_a_line():
    p = line_path([[0, 0, 0], [100, 0, 0]])
    r = check_profile(p, limits(), trapezoid(100, 400, 2500))
    assert r.worst("acceleration").ratio == pytest.approx(1.25)
    others_ok(r, "acceleration")


def test_centripetal_peak_between_knots_inside_an_arc():
    # quarter arc r = 10 from angle -45 to 45 deg: |x''| = v^2/r cos(theta) peaks at
    # theta = 0, in the middle of the only interval; knots sit where cos = 0.707.
    r0 = 10.0
    c = np.array([0.0, 0.0, 0.0])
    start = np.array([r0 * np.cos(-np.pi / 4), r0 * np.sin(-np.pi / 4), 0.0])
    end = np.array([r0 * np.cos(np.pi / 4), r0 * np.sin(np.pi / 4), 0.0])
    arc = arc_segment(start, end, c, (0, 1), False, 0, GEO, 0, 1e-9)
    p = path_from_pieces(AX, [arc], stop_reason=("", "", ))
    L = p.total_length
    v = np.sqrt(1.1 * A * r0)                  # 10 % over the centripetal limit at theta=0
    prof = Profile(t=np.array([0, L / v]), s=np.array([0, L]), v=np.array([v, v]),
                   a=np.zeros(1), j=np.zeros(1), block=np.zeros(1, int))
    rep = check_profile(p, limits(), prof)
    w = rep.worst("acceleration")
    assert w.ratio == pytest.approx(1.1, rel=1e-6)
    assert w.axis == "X" and w.s == pytest.approx(L / 2, abs=L / 200)
    # at the knots alone the ratio would have been 1.1 * cos(45 deg) < 1
    assert 1.1 * np.cos(np.pi / 4) < 1


def test_jerk_inside_an_s_curve():
    p = line_path([[0, 0, 0], [200, 0, 0]])
    ok = check_profile(p, limits(), scurve_rest_to_rest(200, 400, 2000, 40000))
    assert ok.worst("jerk").ratio == pytest.approx(1.0)
    bad = check_profile(p, limits(), scurve_rest_to_rest(200, 400, 2000, 50000))
    assert bad.worst("jerk").ratio == pytest.approx(1.25)
    others_ok(bad, "jerk")


def test_acceleration_step_at_line_arc_junction_against_path_trans_jerk():
    # line tangent into an arc at constant speed: the centripetal acceleration jumps
    r0 = 20.0
    line = line_segments(np.array([[-50.0, -r0, 0]]), np.array([[0.0, -r0, 0]]), GEO,
                         np.array([0]))
    arc = arc_segment(np.array([0.0, -r0, 0]), np.array([r0, 0, 0]), np.zeros(3), (0, 1),
                      False, 0, GEO, 1, 1e-9)
    p = path_from_pieces(AX, [line, arc], stop_reason=("", "", ""))
    v = 100.0
    L = p.total_length
    prof = Profile(t=np.array([0, L / v]), s=np.array([0, L]), v=np.array([v, v]),
                   a=np.zeros(1), j=np.zeros(1), block=np.zeros(1, int))
    step = v * v / r0                       # Y acceleration jumps from 0 to v^2/r
    lim = limits(ptj=step / 0.004 / 1.5)
    rep = check_profile(p, lim, prof)
    w = rep.worst("jerk")
    assert w.ratio == pytest.approx(1.5, rel=1e-9)
    assert w.axis == "Y" and w.s == pytest.approx(50.0)
    assert rep.worst("velocity_jump").ratio == 0.0


def test_feed_violation():
    p = line_path([[0, 0, 0], [100, 0, 0]], feed=300.0)
    r = check_profile(p, limits(), trapezoid(100, 330, 2000))
    assert r.worst("feed").ratio == pytest.approx(1.1)
    others_ok(r, "feed")


@pytest.mark.parametrize("angle_deg, expect_violation", [(90.0, True), (0.05, False)])
def test_velocity_jump_at_corner(angle_deg, expect_violation):
    th = np.deg2rad(angle_deg)
    p = line_path([[0, 0, 0], [50, 0, 0], [50 + 50 * np.cos(th), 50 * np.sin(th), 0]])
    vc = 50.0                                          # crossing speed at the corner
    # accelerate to vc at the corner with a = vc^2/(2*50), decelerate the same way
    a = vc * vc / 100
    prof = Profile.from_phases([vc / a, vc / a], [a, -a], [0, 0])
    rep = check_profile(p, limits(), prof)
    w = rep.worst("velocity_jump")
    allow = A * 0.2 * 0.004
    dv = vc * np.max(np.abs(np.array([np.cos(th) - 1, np.sin(th), 0])))
    assert w.ratio == pytest.approx(dv / allow)
    assert (w.ratio > 1) == expect_violation
    assert w.s == pytest.approx(50.0)


def test_overload_factor_one_forbids_any_jump():
    p = line_path([[0, 0, 0], [50, 0, 0], [50, 50, 0]])
    prof = Profile.from_phases([2.0, 2.0], [25.0, -25.0], [0, 0])   # 50 mm/s at the corner
    rep = check_profile(p, limits(ovl=1.0), prof)
    assert rep.worst("velocity_jump").ratio == np.inf


def test_required_stop_not_honoured():
    p = line_path([[0, 0, 0], [50, 0, 0], [100, 0, 0]], stops=("start", "exact stop G60", "end"))
    rep = check_profile(p, limits(), trapezoid(100, 400, 2000))
    w = rep.worst("stop")
    assert w.ratio > 1 and w.s == pytest.approx(50.0)
    others_ok(rep, "stop")


def test_start_not_at_rest():
    p = line_path([[0, 0, 0], [100, 0, 0]])
    prof = Profile.from_phases([0.25], [-400 / 0.25], [0], v0=400.0 / 1.0)
    prof = Profile.from_phases([0.5], [-800.0], [0], v0=400.0)   # 400 -> 0 over 100 mm
    rep = check_profile(p, limits(), prof)
    assert rep.worst("stop").ratio == pytest.approx(400.0 / VEL_TOL_MM_S)
    assert rep.worst("stop").s == 0.0


def test_frequency_short_bump():
    p = line_path([[0, 0, 0], [10, 0, 0]])
    lim = limits(f=20.0)                       # processes must last >= 50 ms
    prof = trapezoid(10, 100, 2000)            # accelerations of 50 ms: exactly at the limit
    assert check_profile(p, lim, prof).worst("frequency").ratio == pytest.approx(1.0)
    short = trapezoid(10, 50, 2000)            # 25 ms processes
    rep = check_profile(p, lim, short)
    assert rep.worst("frequency").ratio == pytest.approx(2.0)
    assert rep.worst("frequency").axis == "X"
    others_ok(rep, "frequency")


def test_time_scaling_repairs_v_a_j():
    p = line_path([[0, 0, 0], [200, 0, 0]])
    prof = scurve_rest_to_rest(200, 600, 3000, 60000)
    rep = check_profile(p, limits(), prof)
    assert not rep.ok(BOUND_SETS["jerk"])
    lam = time_scale_factor(rep, BOUND_SETS["jerk"])
    rep2 = check_profile(p, limits(), scale_time(prof, lam))
    assert rep2.ok(BOUND_SETS["jerk"], tol=1e-9)
    assert rep2.max_ratio(BOUND_SETS["jerk"]) == pytest.approx(1.0)


def test_chunking_gives_the_same_worst_ratios(monkeypatch):
    import reference.core.constraints as cmod
    rng = np.random.default_rng(3)
    pts = np.c_[np.cumsum(rng.uniform(0.5, 1.0, 3001)), np.zeros(3001), np.zeros(3001)]
    p = line_path(pts)
    L = p.total_length
    prof = trapezoid(L, 300, 1500)
    ref = check_profile(p, limits(), prof)
    monkeypatch.setattr(cmod, "CHUNK_INTERVALS", 97)
    chunked = check_profile(p, limits(), prof)
    for a, b in zip(ref.results, chunked.results):
        assert a.ratio == pytest.approx(b.ratio, rel=1e-12), a.constraint
        assert a.s == pytest.approx(b.s)


def test_profile_must_cover_the_path():
    p = line_path([[0, 0, 0], [100, 0, 0]])
    with pytest.raises(ProfileError, match=r"ends at s = 50 mm but the path is 100 mm long"):
        check_profile(p, limits(), trapezoid(50, 100, 2000))


def test_report_api_and_block_ratios():
    p = line_path([[0, 0, 0], [50, 0, 0], [100, 0, 0]])
    rep = check_profile(p, limits(), trapezoid(100, 400, 2500))
    assert [r.constraint for r in rep.results] == list(CONSTRAINTS)
    assert [v.constraint for v in rep.violations(BOUND_SETS["acc"])] == ["acceleration"]
    assert rep.block_ratios["acceleration"].shape == (2,)
    assert np.all(rep.block_ratios["acceleration"] == pytest.approx(1.25))
    with pytest.raises(KeyError, match="unknown constraint"):
        rep.worst("speed")
