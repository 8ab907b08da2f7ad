"""check_profile on hand-made profiles that each break exactly one limit.

Every motion here is jerk-limited (S-curve ramps that start and end with zero path
acceleration) and its velocity changes last at least 1/f, so a profile meant to break
one constraint keeps all the others, jerk and frequency included. The expected ratios
and places are derived by hand in each test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from reference.core import AxisLimits, MachineLimits, Profile, ProfileError, path_from_pieces
from reference.core import constraints as cmod
from reference.core.constraints import (BOUND_SETS, CONSTRAINTS, CONTINUITY_DETAIL, UNITS,
                                        check_profile, scale_time, time_scale_factor)
from reference.core.geometry import arc_segment, line_segments
from reference.core.tolerances import ACCEL_CONTINUITY_TOL_REL, RATIO_TOL, VEL_TOL_MM_S

AX = ("X", "Y", "Z")
GEO = np.array([True, True, True])
V, A, J = 500.0, 2000.0, 40000.0      # axis limits, mm/s, mm/s^2, mm/s^3
T_IPO = 0.004
F_HZ = 10.0                           # processes must last >= 0.1 s
RA, RJ = 1000.0, 20000.0              # acceleration and jerk of the test ramps


def limits(ovl=1.2, f=F_HZ, ptj=J, v=V, a=A, j=J) -> MachineLimits:
    """Three equal axes; every argument may be a per-axis tuple."""
    per = lambda x: x if isinstance(x, tuple) else (x,) * 3  # noqa: E731
    return MachineLimits(tuple(AxisLimits(n, vv, aa, jj, o, ff, pp) for n, vv, aa, jj, o, ff, pp
                               in zip(AX, per(v), per(a), per(j), per(ovl), per(f), per(ptj))),
                         T_IPO)


def line_path(points, feed=np.inf, stops=None):
    pts = np.asarray(points, dtype=float)
    m = len(pts) - 1
    return path_from_pieces(AX, [line_segments(pts[:-1], pts[1:], GEO, np.arange(m))],
                            feed=feed, stop_reason=None if stops is None else tuple(stops))


# ------------------------------------------------------------------ motion builder
def ramp(v0, v1, a=RA, j=RJ):
    """Jerk-limited velocity change v0 -> v1, zero acceleration at both ends.

    Returns the phases (durations, start accelerations, jerks), the duration and the
    distance, which is (v0 + v1)/2 times the duration (the ramp is point-symmetric).
    """
    dv = abs(v1 - v0)
    sg = 1.0 if v1 >= v0 else -1.0
    if dv == 0:
        return ([], [], []), 0.0, 0.0
    if dv >= a * a / j:
        tj, ta = a / j, dv / a - a / j
    else:
        tj, ta, a = math.sqrt(dv / j), 0.0, math.sqrt(dv * j)
    T = 2 * tj + ta
    return ([tj, ta, tj], [0.0, sg * a, sg * a], [sg * j, 0.0, -sg * j]), T, 0.5 * (v0 + v1) * T


def motion(L, plan, v0=0.0):
    """Profile over length L from a plan of ("ramp", v_to[, a, j]) and ("cruise", mm|None).

    Exactly one cruise may be None: it takes the length the others leave.
    """
    parts, v, fixed, free = [], v0, 0.0, None
    for item in plan:
        if item[0] == "ramp":
            ph, _, dist = ramp(v, *item[1:])
            parts.append(("phases", ph))
            fixed += dist
            v = item[1]
        else:
            parts.append(("cruise", v, item[1]))
            if item[1] is None:
                free = len(parts) - 1
            else:
                fixed += item[1]
    d, a0, jj = [], [], []
    for i, p in enumerate(parts):
        if p[0] == "phases":
            d += p[1][0]
            a0 += p[1][1]
            jj += p[1][2]
        else:
            length = L - fixed if i == free else p[2]
            assert length >= 0, "plan longer than the path"
            d.append(length / p[1])
            a0.append(0.0)
            jj.append(0.0)
    prof = Profile.from_phases(d, a0, jj, v0=v0)
    assert prof.s[-1] == pytest.approx(L, abs=1e-9)
    return prof


def rest_to_rest(L, v, a=RA, j=RJ):
    return motion(L, [("ramp", v, a, j), ("cruise", None), ("ramp", 0.0, a, j)])


def assert_only(report, broken):
    """``broken`` is violated, every other constraint holds."""
    assert report.worst(broken).ratio > 1 + RATIO_TOL
    for r in report.results:
        if r.constraint != broken:
            assert r.ratio <= 1 + RATIO_TOL, (broken, r)


# ---------------------------------------------------------------------- feasible
def test_feasible_s_curve_passes_every_constraint():
    p = line_path([[0, 0, 0], [300, 0, 0]])
    rep = check_profile(p, limits(), rest_to_rest(300, 400))
    assert rep.ok() and rep.ok(BOUND_SETS["jerk+freq"])
    assert rep.worst("velocity").ratio == pytest.approx(400 / V)
    assert rep.worst("acceleration").ratio == pytest.approx(RA / A)
    assert rep.worst("jerk").ratio == pytest.approx(RJ / J)
    assert rep.worst("feed").ratio == 0.0 and rep.worst("velocity_jump").ratio == 0.0


def test_feasible_trapezoid_passes_acc_bounds_and_shows_its_brisk_steps_as_jerk():
    L, v, a = 100.0, 400.0, 2000.0
    prof = Profile.from_phases([v / a, (L - v * v / a) / v, v / a], [a, 0, -a], [0, 0, 0])
    rep = check_profile(line_path([[0, 0, 0], [L, 0, 0]]), limits(), prof)
    assert rep.ok(BOUND_SETS["acc"])
    assert rep.worst("acceleration").ratio == pytest.approx(1.0)
    assert rep.worst("velocity").ratio == pytest.approx(0.8)
    # a planned jerk-limited motion keeps its acceleration continuous inside a segment:
    # the two steps of 2000 mm/s^2 there, summed, against the round-off allowance
    cont = ACCEL_CONTINUITY_TOL_REL * J * T_IPO
    assert rep.worst("jerk").ratio == pytest.approx(2 * a / cont)
    assert rep.components["jerk_step"].ratio == pytest.approx(2 * a / cont)
    assert rep.components["jerk_interval"].ratio == 0.0
    assert not rep.ok(BOUND_SETS["jerk"])
    # the same motion as a recording sampled at the IPO cycle: each step is spread
    # over one cycle, 2000 mm/s^2 in 4 ms = 5e5 mm/s^3 (sinumerik-model 6.3)
    spread = check_profile(line_path([[0, 0, 0], [L, 0, 0]]), limits(), prof,
                           steps="spread")
    assert spread.worst("jerk").ratio == pytest.approx(a / T_IPO / J)
    assert spread.components["jerk_step"].ratio == pytest.approx(a / T_IPO / J)


def test_steps_inside_a_segment_break_continuity_but_not_at_breaks():
    """The rulebook's acceleration steps (reference.core.rules): a step of J T_ipo at a
    segment break is exactly the allowance; the same step at a knot inside a segment is
    not (a staircase of such steps would beat every jerk-limited motion)."""
    v, a0 = 100.0, J * T_IPO             # one-cycle allowance of the path acceleration
    h = 0.01
    L1 = v * h                           # cruise, then accelerate at a0
    prof = Profile.from_phases([h, h], [0.0, a0], [0.0, 0.0], v0=v)
    s_end = float(prof.s[-1])
    # the step at the break between two collinear lines (no curvature jump): J T_ipo
    two = line_path([[0, 0, 0], [L1, 0, 0], [s_end, 0, 0]])
    cut = Profile(t=prof.t, s=prof.s, v=prof.v, a=prof.a, j=prof.j, block=prof.block)
    rep = check_profile(two, limits(), cut)
    assert rep.components["jerk_step"].ratio == pytest.approx(1.0)
    # the same step inside one line: continuity broken by a factor 1e8
    one = line_path([[0, 0, 0], [s_end, 0, 0]])
    rep1 = check_profile(one, limits(), cut)
    assert rep1.components["jerk_step"].ratio == pytest.approx(1.0 / ACCEL_CONTINUITY_TOL_REL)
    # the line says what is compared: its limit is the tolerance, not the jerk limit
    # (a BRISK plan judged under jerk read "> limit 0.01 mm/s^3" without a word)
    assert rep1.worst("jerk").detail == CONTINUITY_DETAIL
    assert rep1.worst("jerk").limit == pytest.approx(ACCEL_CONTINUITY_TOL_REL * J)
    assert rep.worst("jerk").detail == ""          # the step at the break: a plain jerk
    # steps below the round-off allowance pass
    tiny = Profile.from_phases([h, h], [0.0, 0.5 * ACCEL_CONTINUITY_TOL_REL * a0],
                               [0.0, 0.0], v0=v)
    assert check_profile(line_path([[0, 0, 0], [float(tiny.s[-1]), 0, 0]]), limits(),
                         tiny).components["jerk_step"].ratio == pytest.approx(0.5)


# -------------------------------------------------------------- one limit each
def test_velocity_on_a_diagonal_line_names_axis_and_place():
    p = line_path([[0, 0, 0], [600, 300, 0]])
    L = p.total_length
    rep = check_profile(p, limits(), rest_to_rest(L, 600))
    w = rep.worst("velocity")
    assert w.ratio == pytest.approx(600 * 600 / L / V)
    assert (w.axis, w.block, w.unit) == ("X", 0, "mm/s")
    _, T, dist = ramp(0, 600)
    assert w.s == pytest.approx(dist) and w.t == pytest.approx(T)   # first at full speed
    assert w.value == pytest.approx(600 * 600 / L) and w.limit == V
    assert_only(rep, "velocity")


def test_acceleration_on_a_line():
    a, j = 2500.0, 20000.0
    p = line_path([[0, 0, 0], [400, 0, 0]])
    rep = check_profile(p, limits(), rest_to_rest(400, 450, a, j))
    w = rep.worst("acceleration")
    assert w.ratio == pytest.approx(a / A) and w.axis == "X"
    tj = a / j                                        # a is first reached after tj
    assert w.t == pytest.approx(tj) and w.s == pytest.approx(j * tj ** 3 / 6)
    assert_only(rep, "acceleration")


def _arc_between_lines(r0, th0, th1, lead=100.0):
    """Line, CCW arc (centre 0) from th0 to th1, line; all tangent; blocks 0, 1, 2."""
    c = np.zeros(3)
    p0 = np.array([r0 * np.cos(th0), r0 * np.sin(th0), 0.0])
    p1 = np.array([r0 * np.cos(th1), r0 * np.sin(th1), 0.0])
    t0 = np.array([-np.sin(th0), np.cos(th0), 0.0])
    t1 = np.array([-np.sin(th1), np.cos(th1), 0.0])
    pieces = [line_segments((p0 - lead * t0)[None], p0[None], GEO, np.array([0])),
              arc_segment(p0, p1, c, (0, 1), False, 0, GEO, 1, 1e-9),
              line_segments(p1[None], (p1 + lead * t1)[None], GEO, np.array([2]))]
    return path_from_pieces(AX, pieces)


def test_centripetal_peak_between_knots_inside_an_arc():
    # Arc from -45 to +45 deg at constant speed: |x''| = v^2/r cos(theta) peaks at
    # theta = 0, mid-arc, inside one profile interval (split_at only adds knots at the
    # arc ends, where cos = 0.707). The checker must find the peak between knots.
    r0 = 10.0
    p = _arc_between_lines(r0, -np.pi / 4, np.pi / 4)
    v = math.sqrt(1.1 * A * r0)                   # 10 % over the centripetal limit
    prof = rest_to_rest(p.total_length, v)
    inside = (prof.s > 100) & (prof.s < 100 + r0 * np.pi / 2)
    assert not np.any(inside)                     # no knot inside the arc
    rep = check_profile(p, limits(ptj=1e9), prof)
    w = rep.worst("acceleration")
    assert w.ratio == pytest.approx(1.1, rel=1e-9)          # refined peak, not a sample
    assert w.axis == "X" and w.block == 1
    assert w.s == pytest.approx(100 + r0 * np.pi / 4, abs=1e-3)
    assert w.ratio * np.cos(np.pi / 4) < 1                  # the knots alone would pass
    assert_only(rep, "acceleration")


def test_jerk_inside_an_s_curve():
    p = line_path([[0, 0, 0], [400, 0, 0]])
    rep = check_profile(p, limits(), rest_to_rest(400, 300, 1000, 50000))
    w = rep.worst("jerk")
    assert w.ratio == pytest.approx(50000 / J)
    assert (w.axis, w.block, w.s, w.t) == ("X", 0, 0.0, 0.0)
    # the knots of the S-curve recompute its acceleration from closed forms: round-off
    # far below the continuity allowance (ratio 1 at ACCEL_CONTINUITY_TOL_REL J T_ipo)
    assert rep.components["jerk_step"].ratio == pytest.approx(0.0, abs=1e-4)
    assert_only(rep, "jerk")


def test_acceleration_step_at_a_line_arc_junction_against_path_trans_jerk():
    # Line along +X into a CCW quarter circle (centre 0, r = 20) at 100 mm/s: the Y
    # acceleration steps from 0 to v^2/r = 500 mm/s^2, i.e. 125 000 mm/s^3 over one IPO
    # cycle. Y's PATH_TRANS_JERK_LIM is set to 1/1.5 of that; X's (the arc exit step)
    # is large. j_max (40 000) would give 3.125: the checker must use ptj here.
    r0, v = 20.0, 100.0
    p = _arc_between_lines(r0, -np.pi / 2, 0.0)
    step_jerk = v * v / r0 / T_IPO
    rep = check_profile(p, limits(ptj=(1e9, step_jerk / 1.5, 1e9)),
                        rest_to_rest(p.total_length, v))
    w = rep.worst("jerk")
    assert w.ratio == pytest.approx(1.5, rel=1e-9)
    assert w.axis == "Y" and w.s == pytest.approx(100.0)
    assert w.block == 0                               # the block that ends at the break
    assert w.value == pytest.approx(step_jerk) and w.limit == pytest.approx(step_jerk / 1.5)
    assert rep.components["jerk_step"].ratio == pytest.approx(1.5, rel=1e-9)
    assert_only(rep, "jerk")


def test_acceleration_step_inside_a_line_uses_j_max():
    # S-curve up to 100 mm/s, cruise, then a BRISK-like step of the path acceleration
    # from 0 to -100 mm/s^2 at s = 250 mm (no curvature jump: judged against j_max =
    # 10 000 although PATH_TRANS_JERK_LIM is huge), braking to rest at s = 300 where the
    # acceleration steps back to 0 (the motion after the end is rest).
    p = line_path([[0, 0, 0], [300, 0, 0]])
    prof = motion(250, [("ramp", 100.0, 500.0, 5000.0), ("cruise", None)])
    prof = Profile.from_phases(np.r_[np.diff(prof.t), 1.0], np.r_[prof.a, -100.0],
                               np.r_[prof.j, 0.0])
    assert prof.s[-2] == pytest.approx(250.0) and prof.v[-1] == pytest.approx(0.0, abs=1e-9)
    # judged as a recording sampled at the IPO cycle: a step spread over one cycle
    rep = check_profile(p, limits(ptj=1e9, j=10000.0), prof, steps="spread")
    w = rep.worst("jerk")
    assert w.ratio == pytest.approx(100.0 / T_IPO / 10000.0)
    assert w.s == pytest.approx(250.0) and (w.axis, w.block) == ("X", 0)   # the earlier tie
    assert rep.components["jerk_interval"].ratio == pytest.approx(0.5)
    assert_only(rep, "jerk")


def test_feed():
    p = line_path([[0, 0, 0], [400, 0, 0]], feed=300.0)
    rep = check_profile(p, limits(), rest_to_rest(400, 330))
    w = rep.worst("feed")
    assert w.ratio == pytest.approx(1.1) and w.axis is None and w.unit == "mm/s"
    assert w.t == pytest.approx(ramp(0, 330)[1])
    assert_only(rep, "feed")


def test_rapid_has_no_feed_limit():
    p = line_path([[0, 0, 0], [400, 0, 0]], feed=np.inf)
    assert check_profile(p, limits(), rest_to_rest(400, 450)).worst("feed").ratio == 0.0


def _through_corner(p, vc, j=800.0):
    """Up to vc, cruise through the corner at s = 100 with zero acceleration, down."""
    return motion(p.total_length, [("ramp", vc, RA, j), ("cruise", None), ("ramp", 0.0, RA, j)])


def test_velocity_jump_at_a_90_degree_corner_above_the_allowance():
    p = line_path([[0, 0, 0], [100, 0, 0], [100, 100, 0]])
    vc = 2.0                                         # |dt| = 1 on X and on Y: 2 mm/s jumps
    rep = check_profile(p, limits(), _through_corner(p, vc))
    w = rep.worst("velocity_jump")
    allowance = A * 0.2 * T_IPO                      # 1.6 mm/s
    assert w.ratio == pytest.approx(vc / allowance)
    assert (w.axis, w.block) == ("X", 0) and w.s == pytest.approx(100.0)
    assert w.value == pytest.approx(vc) and w.limit == pytest.approx(allowance)
    assert_only(rep, "velocity_jump")


def test_small_kink_within_the_allowance_is_passed_at_speed():
    th = np.deg2rad(0.5)
    p = line_path([[0, 0, 0], [100, 0, 0], [100 + 100 * np.cos(th), 100 * np.sin(th), 0]])
    vc = 150.0
    rep = check_profile(p, limits(), _through_corner(p, vc, j=RJ))
    w = rep.worst("velocity_jump")
    assert w.ratio == pytest.approx(vc * np.sin(th) / (A * 0.2 * T_IPO))
    assert 0.5 < w.ratio < 1 and w.axis == "Y"
    assert rep.ok()


def test_overload_factor_one_forbids_any_jump_and_time_scaling_cannot_help():
    p = line_path([[0, 0, 0], [100, 0, 0], [100, 100, 0]])
    prof = _through_corner(p, 2.0)
    rep = check_profile(p, limits(ovl=1.0), prof)
    assert rep.worst("velocity_jump").ratio == np.inf
    assert rep.worst("velocity_jump").limit == 0.0
    assert time_scale_factor(rep, BOUND_SETS["acc"]) == np.inf
    with pytest.raises(ProfileError, match="finite and > 0"):
        scale_time(prof, np.inf)


def test_required_stop_not_honoured():
    p = line_path([[0, 0, 0], [100, 0, 0], [200, 0, 0]], stops=("", "exact stop G60", ""))
    rep = check_profile(p, limits(), rest_to_rest(200, 300))
    w = rep.worst("stop")
    assert w.ratio == pytest.approx(300 / VEL_TOL_MM_S)
    assert w.s == pytest.approx(100.0) and w.block == 0 and w.axis is None
    assert_only(rep, "stop")


def test_start_not_at_rest():
    p = line_path([[0, 0, 0], [100, 0, 0]])
    prof = motion(100, [("cruise", None), ("ramp", 0.0)], v0=200.0)
    rep = check_profile(p, limits(), prof)
    w = rep.worst("stop")
    assert w.ratio == pytest.approx(200 / VEL_TOL_MM_S)
    assert (w.s, w.t, w.block) == (0.0, 0.0, 0)
    assert_only(rep, "stop")


def test_frequency_short_bump_names_the_slowest_moving_axis():
    # diagonal X/Y move; Z has the smallest LOOKAH_FREQUENCY but does not move, so Y
    # (10 Hz: processes >= 0.1 s) decides. The bump 200 -> 230 -> 200 mm/s with
    # a = 1000, j = 20000 never reaches a: each half lasts 2 sqrt(30/20000) = 77 ms.
    p = line_path([[0, 0, 0], [400, 300, 0]])
    lim = limits(f=(20.0, 10.0, 2.0))
    prof = motion(500, [("ramp", 200.0), ("cruise", 100.0), ("ramp", 230.0), ("ramp", 200.0),
                        ("cruise", None), ("ramp", 0.0)])
    rep = check_profile(p, lim, prof)
    w = rep.worst("frequency")
    dur = 2 * math.sqrt(30 / RJ)
    assert w.ratio == pytest.approx(0.1 / dur)
    assert (w.axis, w.block, w.unit) == ("Y", 0, "Hz")
    assert w.value == pytest.approx(1 / dur) and w.limit == 10.0
    assert w.s == pytest.approx(ramp(0, 200)[2] + 100.0)
    assert w.t == pytest.approx(ramp(0, 200)[1] + 0.5)
    assert_only(rep, "frequency")


def test_frequency_process_spans_knots_and_constant_speed_separates_processes():
    p = line_path([[0, 0, 0], [500, 0, 0]])
    slow_stop = ("ramp", 0.0, 500.0, RJ)             # 0.425 s: never the shortest
    T1, T2 = ramp(0, 100)[1], ramp(100, 200)[1]      # 0.15 s each
    assert ramp(200, 0, 500.0, RJ)[1] > T1 + T2
    # two S-ramps 0 -> 100 -> 200 back to back: the acceleration touches 0 for an
    # instant only, so they form ONE process (across five knots)
    back_to_back = motion(500, [("ramp", 100.0), ("ramp", 200.0), ("cruise", None), slow_stop])
    rep = check_profile(p, limits(f=1.0), back_to_back)
    assert rep.worst("frequency").value == pytest.approx(1 / (T1 + T2))
    assert rep.worst("frequency").s == 0.0
    # 10 mm of constant speed between them: two processes
    apart = motion(500, [("ramp", 100.0), ("cruise", 10.0), ("ramp", 200.0), ("cruise", None),
                         slow_stop])
    rep2 = check_profile(p, limits(f=1.0), apart)
    assert rep2.worst("frequency").value == pytest.approx(1 / T1)


# ------------------------------------------------------------------ time scaling
@pytest.mark.parametrize("case", ["velocity", "acceleration", "jerk", "jerk_step",
                                  "velocity_jump", "arc"])
def test_time_scaling_repairs_the_violation(case):
    lim = limits()
    if case == "velocity":
        p, prof = line_path([[0, 0, 0], [600, 0, 0]]), rest_to_rest(600, 650)
    elif case == "acceleration":
        p, prof = line_path([[0, 0, 0], [600, 0, 0]]), rest_to_rest(600, 450, 3000, 30000)
    elif case == "jerk":
        p, prof = line_path([[0, 0, 0], [600, 0, 0]]), rest_to_rest(600, 450, 1500, 90000)
    elif case == "jerk_step":            # BRISK steps: 1/lam^2, not 1/lam^3
        L, v, a = 100.0, 400.0, 2000.0
        p = line_path([[0, 0, 0], [L, 0, 0]])
        prof = Profile.from_phases([v / a, (L - v * v / a) / v, v / a], [a, 0, -a], [0, 0, 0])
    elif case == "velocity_jump":
        p = line_path([[0, 0, 0], [100, 0, 0], [100, 100, 0]])
        prof = _through_corner(p, 3.0)
    else:                                # centripetal and in-arc jerk on a helix
        r0 = 10.0
        p = _arc_between_lines(r0, -np.pi / 4, np.pi)
        prof = rest_to_rest(p.total_length, math.sqrt(1.7 * A * r0))
        lim = limits(ptj=1e9)
    names = BOUND_SETS["jerk"]
    rep = check_profile(p, lim, prof)
    assert not rep.ok(names)
    lam = time_scale_factor(rep, names)
    assert lam > 1
    scaled = scale_time(prof, lam)
    assert scaled.duration == pytest.approx(lam * prof.duration)
    assert scaled.v[0] == 0.0 and scaled.v[-1] <= prof.v[-1]      # rest stays rest
    rep2 = check_profile(p, lim, scaled)
    assert rep2.ok(names, tol=1e-9)
    assert rep2.max_ratio(names) == pytest.approx(1.0, abs=1e-9)


def test_time_scale_factor_formula():
    rep = check_profile(line_path([[0, 0, 0], [600, 0, 0]]), limits(),
                        rest_to_rest(600, 450, 3000, 30000))       # r_a = 1.5 only
    assert time_scale_factor(rep, ["acceleration"]) == pytest.approx(math.sqrt(1.5))
    assert time_scale_factor(rep, ["velocity"]) == 1.0
    with pytest.raises(KeyError, match="unknown constraint"):
        time_scale_factor(rep, ["speed"])


# ------------------------------------------------------------ sampling accuracy
def test_dense_sampling_against_brute_force_on_random_helices():
    # the checker only evaluates real points, so its maximum is never above the true
    # one, and by the module's bound never below it by more than ~dphi^2/8
    rng = np.random.default_rng(11)
    ax = ("X", "Y", "Z", "A")
    geo = np.array([True, True, True, False])
    lim = MachineLimits(tuple(AxisLimits(n, 1e3, 1e4, 1e6, 1.2, 1.0) for n in ax), T_IPO)
    la = lim.for_axes(ax)
    for _ in range(6):
        r0 = rng.uniform(5, 20)
        th1 = rng.uniform(1.0, 5.0)
        start = np.array([r0, 0, 0, 0])
        end = np.array([r0 * np.cos(th1), r0 * np.sin(th1), rng.uniform(-5, 5),
                        rng.uniform(-30, 30)])
        p = path_from_pieces(ax, [arc_segment(start, end, np.zeros(4), (0, 1), False, 0, geo,
                                              0, 1e-9)])
        L = p.total_length
        prof = motion(L, [("ramp", rng.uniform(20, 40), 2000.0, 40000.0), ("cruise", None),
                          ("ramp", rng.uniform(5, 15), 2000.0, 40000.0), ("cruise", 0.1 * L),
                          ("ramp", 0.0, 2000.0, 40000.0)])
        rep = check_profile(p, lim, prof)
        # brute force: a fine time grid plus the knots (where |g| may have a corner)
        t = np.union1d(np.linspace(0, prof.duration, 200_001), prof.t)
        s, v, a, j = prof.state(t)
        _, dq, ddq, dddq = p.evaluate(np.clip(s, 0, L))
        brute = {
            "velocity": np.max(np.abs(dq * v[:, None]) / la.v_max),
            "acceleration": np.max(np.abs(dq * a[:, None] + ddq * (v * v)[:, None]) / la.a_max),
            "jerk": np.max(np.abs(dq * j[:, None] + 3 * ddq * (v * a)[:, None]
                                  + dddq * (v ** 3)[:, None]) / la.j_max)}
        for name, b in brute.items():
            r = rep.components["jerk_interval"].ratio if name == "jerk" else \
                rep.worst(name).ratio
            assert b * (1 - 6e-7) <= r <= b * (1 + 1e-7), name


# ------------------------------------------------------------------- chunking
def _lines_and_half_circles(rng, rounds=40, n_lines=20):
    """Short lines, then a half circle reversing the direction; alternating CW/CCW."""
    pieces, pos, direction, blk = [], np.zeros(3), np.array([1.0, 0, 0]), 0
    for i in range(rounds):
        steps = rng.uniform(0.5, 1.0, n_lines)
        pts = pos + np.cumsum(steps)[:, None] * direction
        pieces.append(line_segments(np.vstack([pos, pts[:-1]]), pts, GEO,
                                    np.arange(blk, blk + n_lines)))
        blk += n_lines
        pos = pts[-1]
        cw = bool(i % 2)
        left = np.array([-direction[1], direction[0], 0.0])
        c = pos + rng.uniform(3, 8) * (-left if cw else left)
        end = 2 * c - pos
        pieces.append(arc_segment(pos, end, c, (0, 1), cw, 0, GEO, blk, 1e-9))
        blk += 1
        pos, direction = end, -direction
    return path_from_pieces(AX, pieces)


def test_chunking_gives_the_same_result(monkeypatch):
    p = _lines_and_half_circles(np.random.default_rng(3))
    L = p.total_length
    s = np.linspace(0, L, 10_001)
    v = 120 * np.sqrt(np.sin(np.pi * s / L)) * (1 + 0.1 * np.sin(s))
    v[[0, -1]] = 0.0
    prof = Profile.from_path_velocity(s, v)
    assert prof.n_intervals == 10_000
    lim = limits(ovl=1.5)
    ref = check_profile(p, lim, prof)
    monkeypatch.setattr(cmod, "CHUNK_SAMPLES", 97)
    chunked = check_profile(p, lim, prof)
    for a, b in zip(ref.results, chunked.results):
        assert a == b, a.constraint
    for name in CONSTRAINTS:
        np.testing.assert_array_equal(ref.block_ratios[name], chunked.block_ratios[name])
    assert ref.worst("acceleration").ratio > 0 and ref.worst("frequency").ratio > 0


# ------------------------------------------------------------------ report API
def test_profile_must_cover_the_path():
    p = line_path([[0, 0, 0], [100, 0, 0]])
    with pytest.raises(ProfileError, match=r"ends at s = 50 mm but the path is 100 mm long"):
        check_profile(p, limits(), rest_to_rest(50, 100))


def test_report_api_and_block_ratios():
    p = line_path([[0, 0, 0], [100, 0, 0], [150, 0, 0], [250, 0, 0]])
    prof = rest_to_rest(p.total_length, 400, 2500, 20000)
    rep = check_profile(p, limits(), prof)
    assert [r.constraint for r in rep.results] == list(CONSTRAINTS)
    assert all(r.unit == UNITS[r.constraint] for r in rep.results)
    assert [r.constraint for r in rep.violations(BOUND_SETS["acc"])] == ["acceleration"]
    assert rep.violations(["velocity"]) == ()
    assert not rep.ok() and rep.ok(["velocity", "feed"])
    assert rep.max_ratio(["acceleration", "velocity"]) == pytest.approx(1.25)
    assert rep.worst("acceleration").violated
    br = rep.block_ratios["acceleration"]
    assert br.shape == (3,)
    # block 0 holds the acceleration ramp, block 1 only cruise, block 2 the braking ramp
    assert br.tolist() == pytest.approx([1.25, 0.0, 1.25])
    assert rep.block_ratios["velocity"].tolist() == pytest.approx([0.8, 0.8, 0.8])
    with pytest.raises(ValueError):
        br[0] = 0.0                                      # read-only
    with pytest.raises(KeyError, match="unknown constraint"):
        rep.worst("speed")
    with pytest.raises(KeyError, match="unknown constraint"):
        rep.violations(["speed"])


def test_zero_length_path_only_judges_rest():
    p = path_from_pieces(AX, [])
    prof = Profile(t=np.array([0.0, 1.0]), s=np.zeros(2), v=np.zeros(2), a=np.zeros(1),
                   j=np.zeros(1), block=np.zeros(1, int))
    rep = check_profile(p, limits(), prof)
    assert rep.max_ratio() == 0.0


@pytest.mark.parametrize("factor", [8, 64])
def test_coarse_to_fine_arc_sampling_against_brute_force(monkeypatch, factor):
    """Module docstring: on arcs the maxima are within dphi^2/8 of the true ones. The
    circles are sampled coarsely first and finely only where a bound on the second
    derivative says a larger value may hide (``ARC_COARSE_FACTOR``); with the factor
    raised to 64 (8 deg coarse steps) almost everything rests on that bound, so a wrong
    bound shows here as a missed peak. Reference: a brute-force time grid (1e5 points per
    arc, both sides of every knot)
    with the kinematics written out (q' v, q' a + q'' v^2, q' j + 3 q'' v a + q''' v^3),
    per constraint and per block. Small rounding-like arcs (R 0.05..2 mm, 20..170 deg)
    traversed by random BRISK and SOFT motions, in planes tilted to all axes."""
    monkeypatch.setattr(cmod, "ARC_COARSE_FACTOR", factor)
    rng = np.random.default_rng(5)
    ax = ("X", "Y", "Z")
    geo = np.array([True, True, True])
    lim = MachineLimits(tuple(AxisLimits(n, 1e3, 1e4, 1e6, 1.2, 1.0) for n in ax), T_IPO)
    la = lim.for_axes(ax)
    for case in range(8):
        pieces, pos = [], np.zeros(3)
        for b in range(4):
            r = rng.uniform(0.05, 2.0)
            sweep = np.radians(rng.uniform(20.0, 170.0))
            e1 = rng.normal(size=3)
            e1 /= np.linalg.norm(e1)
            e2 = rng.normal(size=3)
            e2 -= e1 * (e2 @ e1)
            e2 /= np.linalg.norm(e2)
            c = pos - r * e1
            end = c + r * (np.cos(sweep) * e1 + np.sin(sweep) * e2)
            pieces.append(arc_segment(pos, end, c, (e1, e2), False, 0, geo, b, 1e-9))
            pos = end
        p = path_from_pieces(ax, pieces)
        L = p.total_length
        vmax = rng.uniform(5.0, 40.0)
        if case % 2:          # BRISK-like: constant path acceleration per interval
            s = np.linspace(0, L, 40)
            v = vmax * np.sin(np.pi * s / L) ** 0.5 * (1 + 0.2 * np.sin(7 * s / L))
            v[[0, -1]] = 0.0
            prof = Profile.from_path_velocity(s, v)
        else:                 # SOFT: jerk-limited ramps
            prof = motion(L, [("ramp", vmax, 2000.0, 40000.0), ("cruise", None),
                              ("ramp", 0.3 * vmax, 2000.0, 40000.0), ("cruise", 0.2 * L),
                              ("ramp", 0.0, 2000.0, 40000.0)])
        rep = check_profile(p, lim, prof)
        # per arc (its own end points included: a corner follows each arc): its time
        # span and the knots in it, positions clipped onto the arc
        tb = prof.time_at(p.s_breaks)
        # the path acceleration steps at knots: both one-sided values (next floats)
        kn = np.concatenate((np.nextafter(prof.t, -np.inf), prof.t,
                             np.nextafter(prof.t, np.inf)))
        ts = [np.union1d(np.linspace(t0, t1, 100_001), kn[(kn > t0) & (kn < t1)])
              for t0, t1 in zip(tb[:-1], tb[1:])]
        seg = np.concatenate([np.full(x.size, i) for i, x in enumerate(ts)])
        s, v, a, j = prof.state(np.concatenate(ts))
        s = np.clip(s, p.s_breaks[seg], p.s_breaks[seg + 1])
        _, dq, ddq, dddq = p.evaluate(s, segment=seg)
        vals = {
            "velocity": np.abs(dq * v[:, None]) / la.v_max,
            "acceleration": np.abs(dq * a[:, None] + ddq * (v * v)[:, None]) / la.a_max,
            "jerk": np.abs(dq * j[:, None] + 3 * ddq * (v * a)[:, None]
                           + dddq * (v ** 3)[:, None]) / la.j_max}
        blk = p.block[seg]
        for name, val in vals.items():
            b = val.max()
            r = rep.components["jerk_interval"].ratio if name == "jerk" else \
                rep.worst(name).ratio
            assert b * (1 - 6e-7) <= r <= b * (1 + 1e-7), (case, name)
            if name == "jerk":
                continue       # block jerk ratios also hold the acceleration steps
            per = np.zeros(4)
            np.maximum.at(per, blk, val.max(axis=1))
            got = rep.block_ratios[name][:4]
            assert np.all(got >= per * (1 - 6e-7)), (case, name, got, per)
            assert np.all(got <= per * (1 + 1e-7) + 1e-12), (case, name)


@pytest.mark.parametrize("factor", [8, 64])
def test_coarse_sampling_finds_the_highest_of_nearly_equal_peaks(monkeypatch, factor):
    """The case the second-derivative bound exists for: ten turns of a circle in one
    interval of slowly rising speed, so every half turn the X and Y accelerations peak,
    each peak about 1e-5 higher than the one before (the last ones inside the interval,
    not at its end). The coarse samples (1 or 8 deg apart) catch
    some earlier peak better than the last one; only the bound sends the fine sampling
    to the last, highest peak. Reference: 2e6 uniform samples (0.0018 deg apart)."""
    monkeypatch.setattr(cmod, "ARC_COARSE_FACTOR", factor)
    R, v0, v1 = 5.0, 20.0, 20.002
    start = np.array([R, 0.0, 0.0])
    end = R * np.array([np.cos(1.3), np.sin(1.3), 0.0])      # 10 turns and 1.3 rad
    p = path_from_pieces(AX, [arc_segment(start, end, np.zeros(3), (0, 1), False, 10, GEO,
                                          0, 1e-9)])
    L = p.total_length
    assert L == pytest.approx(R * (20 * np.pi + 1.3))
    h = 2 * L / (v0 + v1)
    a = (v1 - v0) / h
    prof = Profile(t=np.array([0.0, h]), s=np.array([0.0, L]), v=np.array([v0, v1]),
                   a=np.array([a]), j=np.zeros(1), block=np.zeros(1, dtype=np.int64))
    lim = MachineLimits(tuple(AxisLimits(n, 1e3, 1e4, 1e6, 1.2, 1.0) for n in AX), T_IPO)
    rep = check_profile(p, lim, prof)
    t = np.linspace(0.0, h, 2_000_001)
    s, v, acc, _ = prof.state(t)
    _, dq, ddq, _ = p.evaluate(np.clip(s, 0, L))
    brute = np.max(np.abs(dq * acc[:, None] + ddq * (v * v)[:, None])) / 1e4
    got = rep.worst("acceleration").ratio
    assert brute * (1 - 6e-7) <= got <= brute * (1 + 1e-9)


@pytest.mark.parametrize("factor", [8, 64])
def test_sampling_on_clothoid_pairs_against_brute_force(monkeypatch, factor):
    """The checker's accuracy statement holds on clothoid roundings too (their coarse
    steps are pruned by bounds from :func:`reference.core.geometry.clothoid_derivative_norms`): lines with
    clothoid pairs of 30..170 deg between them, random BRISK-like and SOFT motions,
    against a brute-force grid per segment (1e5 points, both sides of every knot)."""
    from reference.core.geometry import KIND_CODES, clothoid_pair_shape, clothoid_pieces
    monkeypatch.setattr(cmod, "ARC_COARSE_FACTOR", factor)
    rng = np.random.default_rng(21)
    lim = MachineLimits(tuple(AxisLimits(n, 1e3, 1e4, 1e6, 1.2, 1.0) for n in AX), T_IPO)
    la = lim.for_axes(AX)
    for case in range(6):
        pos, t_in = np.zeros(3), np.array([1.0, 0.0, 0.0])
        pieces, blk = [], 0
        for _ in range(3):
            end = pos + rng.uniform(0.5, 3.0) * t_in
            pieces.append(line_segments(pos[None], end[None], GEO, np.array([blk])))
            ang = np.radians(rng.uniform(30.0, 170.0)) * rng.choice((-1.0, 1.0))
            axis = rng.normal(size=3)
            axis -= t_in * (axis @ t_in)
            axis /= np.linalg.norm(axis)
            t_out = np.cos(ang) * t_in + np.sin(ang) * axis
            half = rng.uniform(0.05, 1.0)
            pieces.append(clothoid_pieces(end[None], t_in[None], t_out[None],
                                          np.array([half]), np.array([blk]),
                                          KIND_CODES.index("rounding")))
            d1, _ = clothoid_pair_shape(np.array([abs(ang)]))
            pos = end + half * d1[0] * (t_in + t_out)
            t_in, blk = t_out, blk + 1
        end = pos + 2.0 * t_in
        pieces.append(line_segments(pos[None], end[None], GEO, np.array([blk])))
        p = path_from_pieces(AX, pieces)
        L = p.total_length
        vmax = rng.uniform(5.0, 40.0)
        if case % 2:
            s = np.linspace(0, L, 60)
            v = vmax * np.sin(np.pi * s / L) ** 0.5 * (1 + 0.2 * np.sin(5 * s / L))
            v[[0, -1]] = 0.0
            prof = Profile.from_path_velocity(s, v)
        else:
            prof = motion(L, [("ramp", vmax, 2000.0, 40000.0), ("cruise", None),
                              ("ramp", 0.0, 2000.0, 40000.0)])
        rep = check_profile(p, lim, prof)
        tb = prof.time_at(p.s_breaks)
        kn = np.concatenate((np.nextafter(prof.t, -np.inf), prof.t,
                             np.nextafter(prof.t, np.inf)))
        ts = [np.union1d(np.linspace(t0, t1, 100_001), kn[(kn > t0) & (kn < t1)])
              for t0, t1 in zip(tb[:-1], tb[1:])]
        seg = np.concatenate([np.full(x.size, i) for i, x in enumerate(ts)])
        s, v, a, j = prof.state(np.concatenate(ts))
        s = np.clip(s, p.s_breaks[seg], p.s_breaks[seg + 1])
        _, dq, ddq, dddq = p.evaluate(s, segment=seg)
        vals = {
            "velocity": np.abs(dq * v[:, None]) / la.v_max,
            "acceleration": np.abs(dq * a[:, None] + ddq * (v * v)[:, None]) / la.a_max,
            "jerk": np.abs(dq * j[:, None] + 3 * ddq * (v * a)[:, None]
                           + dddq * (v ** 3)[:, None]) / la.j_max}
        for name, val in vals.items():
            b = val.max()
            r = rep.components["jerk_interval"].ratio if name == "jerk" else \
                rep.worst(name).ratio
            assert b * (1 - 6e-7) <= r <= b * (1 + 1e-7), (case, name)
