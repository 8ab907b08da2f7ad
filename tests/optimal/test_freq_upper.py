"""Building blocks of the frequency oracle's upper bound (optimal.freq.upper), each
against a brute-force evaluation of its definition or, for the eroded caps, against a
dense simulation of the moving average they are built for."""

from __future__ import annotations

import numpy as np
import pytest

from optimal.freq.upper import _passes, _window_min, window_caps
from reference.core.profile import Profile


@pytest.mark.parametrize("seed", range(4))
def test_window_caps_is_its_definition(seed):
    # c(p) = min cap(q) over the q whose band |s - s_q| <= cap(q) W / 2, widened by one
    # node on each side, holds p: by an O(N^2) table
    rng = np.random.default_rng(seed)
    s = np.sort(rng.uniform(0.0, 50.0, 300))
    cap = rng.uniform(0.0, 200.0, 300)
    cap[rng.integers(0, 300, 30)] = rng.uniform(0.0, 5.0, 30)    # a few corners
    cap[rng.integers(0, 300, 10)] = np.inf
    W = 0.05
    ref = cap.copy()
    for q in np.flatnonzero(np.isfinite(cap) & (cap > 0)):
        inside = np.flatnonzero(np.abs(s - s[q]) <= cap[q] * W / 2)
        lo, hi = max(inside.min() - 1, 0), min(inside.max() + 1, s.size - 1)
        ref[lo:hi + 1] = np.minimum(ref[lo:hi + 1], cap[q])
    np.testing.assert_array_equal(window_caps(s, cap, W), ref)


@pytest.mark.parametrize("seed", range(4))
def test_window_min_is_the_minimum_of_each_window(seed):
    rng = np.random.default_rng(seed)
    x = rng.normal(size=1000)
    lo = rng.integers(0, 999, 500)
    hi = lo + 1 + rng.integers(0, 1000 - lo)
    np.testing.assert_array_equal(_window_min(x, lo, hi),
                                  [x[a:b].min() for a, b in zip(lo, hi)])


@pytest.mark.parametrize("seed", range(4))
def test_passes_are_the_largest_profile_under_the_caps(seed):
    # forward then backward recursion, one node at a time (the textbook passes)
    rng = np.random.default_rng(seed)
    b = rng.uniform(0.0, 1e4, 400)
    b[[0, -1]] = 0.0
    step = rng.uniform(0.0, 300.0, 399)
    ref = b.copy()
    for i in range(399):
        ref[i + 1] = min(ref[i + 1], ref[i] + step[i])
    for i in range(398, -1, -1):
        ref[i] = min(ref[i], ref[i + 1] + step[i])
    np.testing.assert_allclose(_passes(b, step), ref, rtol=1e-12, atol=1e-9)


def _moving_average_at_caps(s, cap, W, seed):
    """Speed of the moving average (window W) of a motion under ``window_caps``, where
    the filtered motion passes each capped node, and the caps there: by a dense time
    simulation, independent of how the caps were computed. The motion: the largest
    speed under the eroded caps with |dv^2/ds| <= 2 A, at rest at both ends."""
    u_cap = window_caps(s, cap, W)
    b = np.minimum(u_cap, np.max(cap[np.isfinite(cap)])) ** 2
    b[[0, -1]] = 0.0
    b = _passes(b, 2.0 * 2000.0 * np.diff(s))
    prof = Profile.from_path_velocity(s, np.sqrt(b))
    dt = 2e-5
    t = np.arange(-W, prof.duration + W, dt)
    pos, _, _, _ = prof.state(np.clip(t, 0.0, prof.duration))
    pos = np.where(t < 0.0, 0.0, pos)
    k = int(round(W / dt))
    # v_out(t) = (s_u(t) - s_u(t - W)) / W; s_out(t) = mean of s_u over [t - W, t]
    v_out = (pos[k:] - pos[:-k]) / W
    c = np.concatenate(([0.0], np.cumsum(0.5 * (pos[1:] + pos[:-1]) * dt)))
    s_out = (c[k:] - c[:-k]) / W
    q = np.flatnonzero(np.isfinite(cap) & (cap > 0))
    q = q[(s[q] > s_out[0]) & (s[q] < s_out[-1])]
    i = np.searchsorted(s_out, s[q])           # s_out increases (u > 0 inside)
    v_at = np.maximum(v_out[i - 1], v_out[i])  # both samples around the crossing
    return v_at, cap[q], u_cap


@pytest.mark.parametrize("seed", range(3))
def test_window_caps_keep_every_cap_after_the_moving_average(seed):
    # the guarantee of window_caps (band or cone per cap), by simulating the filter
    rng = np.random.default_rng(seed)
    s = np.concatenate(([0.0], np.sort(rng.uniform(0.0, 60.0, 400)), [60.0]))
    cap = rng.uniform(40.0, 120.0, s.size)
    corners = rng.integers(5, s.size - 5, 12)
    cap[corners] = rng.uniform(0.5, 20.0, corners.size)     # slow corners
    cap[[0, -1]] = 0.0
    v_at, c_at, u_cap = _moving_average_at_caps(s, cap, 0.05, seed)
    assert np.all(u_cap <= cap)
    # sampling: two samples of 2e-5 s around each crossing, at most 2000 mm/s^2 apart
    np.testing.assert_array_less(v_at, c_at + 2000.0 * 2e-5 * 2 + 1e-9)


@pytest.mark.parametrize("radius", [5.0, 10.0, 30.0])
def test_filtered_motion_with_jerk_reach_keeps_the_axis_jerk_on_a_curve(radius):
    # eroded_plans keeps u's acceleration to the jerk room the curvature terms leave,
    # over the distance the filter lags behind: the filtered motion on a half circle
    # (rest to rest, no curvature jump) keeps every axis' jerk, measured here by third
    # differences of the axis positions sampled every 0.2 ms (not by the checker)
    import sys
    from pathlib import Path as FsPath
    sys.path.insert(0, str(FsPath(__file__).parent))
    from oracle_cases import semicircle
    from optimal.freq.lower import segment_periods
    from optimal.freq.upper import candidate_windows, eroded_plans, fir_filtered
    from reference.machine import load_machine

    m = load_machine(None)
    path = semicircle(radius, feed=100.0)
    lim = m.limits.for_axes(path.axes)
    T = float(np.max(segment_periods(path, lim)))
    for W in candidate_windows(path, lim, T, True):
        u = eroded_plans(path, m.limits, T, W, True, jerk_reach=True)
        p = fir_filtered(path, m.limits, u.profile, True, u.rest_breaks, window_s=W)
        dt = 2e-4
        s, _, _, _ = p.state(np.arange(0.0, p.duration, dt))
        jerk = np.diff(path.evaluate(s)[0], 3, axis=0) / dt ** 3
        assert np.all(np.max(np.abs(jerk), axis=0) <= lim.j_max * (1 + 1e-3))


# --- per-piece candidates: closed-form lines and the fastest motion per piece ----------

def _xyz(v=500.0, a=2000.0, f=10.0):
    from reference.core import AxisLimits, MachineLimits
    return MachineLimits(tuple(AxisLimits(n, v, a, 1e6, 1.2, f) for n in "XYZ"), 0.004)


@pytest.mark.parametrize("L, F, a, f, expected", [
    # DESIGN 6: v/A < 1/f -> L/v + 1/f
    (100.0, 100.0, 2000.0, 10.0, 100.0 / 100.0 + 0.1),
    # v/A > 1/f: the classical trapezoid L/v + v/A
    (100.0, 100.0, 200.0, 10.0, 100.0 / 100.0 + 100.0 / 200.0),
    # too short to reach v: a triangle 2 sqrt(L/A) while its ramps last >= 1/f ...
    (1.0, 100.0, 50.0, 10.0, 2.0 * np.sqrt(1.0 / 50.0)),
    # ... and two ramps of exactly 1/f (peak L f) when they would not
    (1.0, 100.0, 2000.0, 10.0, 0.2),
])
def test_ramp_plan_closed_forms_on_single_lines(L, F, a, f, expected):
    """Rest-to-rest single lines: the closed forms of the fastest ``acc+freq`` motion
    (the ramp plan's one hump), and the checker accepts each."""
    from oracle_cases import line_path
    from optimal.freq.ramps import ramp_plan
    from reference.core.constraints import BOUND_SETS, check_profile

    path = line_path([[0, 0, 0], [L, 0, 0]], feed=F, stops=("start", "end"))
    lim = _xyz(a=a, f=f)
    prof = ramp_plan(path, lim)[0]
    assert prof.duration == pytest.approx(expected, rel=1e-12)
    assert check_profile(path, lim, prof).ok(BOUND_SETS["acc+freq"])


@pytest.mark.parametrize("F, L1, L2", [(20.0, 20.0, 20.0), (43.1, 4.16, 3.10),
                                       (100.0, 30.0, 1.0)])
def test_ramp_plan_on_a_corner_is_the_hand_motion(F, L1, L2):
    """Two lines with a 90 degree corner: the ramp plan is the hand motion of ramps of
    exactly 1/f: rest to the feed, down to the corner's speed ``v_c`` and back, down to
    rest; where the second line is too short for that (1 mm at F100: ramps of 1/f cover
    (v_c + P) / (2 f) + P / (2 f)), up to the plateau ``P = f L2 - v_c / 2`` and straight
    down. ``v_c`` is the largest corner speed the checker accepts (bisection); the plan,
    at the junction rule's cap, is that motion to 1e-8. The checker accepts the plan."""
    from oracle_cases import largest_accepted, line_path
    from optimal.freq.ramps import ramp_plan
    from reference.core.constraints import BOUND_SETS, check_profile

    f = 20.0
    lim = _xyz(a=2000.0, f=f)
    path = line_path([[0, 0, 0], [L1, 0, 0], [L1, L2, 0]], feed=F)
    prof = ramp_plan(path, lim)[0]
    assert check_profile(path, lim, prof).ok(BOUND_SETS["acc+freq"])

    def hand(vc):
        up, dn = F / (2 * f), (F + vc) / (2 * f)
        if F / (2 * f) + (F + vc) / (2 * f) <= L2:
            return Profile.from_path_velocity([0.0, up, L1 - dn, L1, L1 + dn, L1 + L2 - up,
                                               L1 + L2], [0.0, F, F, vc, F, F, 0.0])
        P = f * L2 - vc / 2
        return Profile.from_path_velocity([0.0, up, L1 - dn, L1, L1 + (vc + P) / (2 * f),
                                           L1 + L2], [0.0, F, F, vc, P, 0.0])

    vc = largest_accepted(path, lim, hand, 0.0, min(F, 10.0))
    assert prof.duration == pytest.approx(hand(vc).duration, rel=1e-8)


@pytest.mark.parametrize("J, expected", [
    # the shortest S-curve to 100 mm/s lasts 2 sqrt(100 / 4e4) = 0.1 s = 1/f: L/v + 1/f
    (4e4, 100.0 / 100.0 + 0.1),
    # a jerk ten times lower: 2 sqrt(100 / 4e3) = 0.316 s, longer than 1/f
    (4e3, 100.0 / 100.0 + 2.0 * np.sqrt(100.0 / 4e3)),
])
def test_ramp_plan_s_curves_on_single_lines(J, expected):
    """Rest-to-rest single lines under ``jerk+freq``: S-curve ramps of ``max(1/f, the
    shortest S-curve)`` (L = 100 mm at F100, A = 2000, f = 10 Hz), time ``L/v + tau`` by
    hand, accepted under ``jerk+freq``."""
    from oracle_cases import line_path
    from reference.core import AxisLimits, MachineLimits
    from optimal.freq.ramps import ramp_plan
    from reference.core.constraints import BOUND_SETS, check_profile

    path = line_path([[0, 0, 0], [100.0, 0, 0]], feed=100.0, stops=("start", "end"))
    lim = MachineLimits(tuple(AxisLimits(n, 500.0, 2000.0, J, 1.2, 10.0) for n in "XYZ"),
                        0.004)
    prof = ramp_plan(path, lim, jerk=True)[0]
    assert prof.duration == pytest.approx(expected, rel=1e-12)
    assert check_profile(path, lim, prof).ok(BOUND_SETS["jerk+freq"])


def test_ramp_plan_s_curves_keep_the_corner_times_where_1_f_binds():
    """A 90 degree corner between 20 mm lines at F1200, 20 Hz, jerk 40 m/s^3: every
    S-curve to a change of at most 20 mm/s is shorter than 1/f, and an S-curve of 1/f
    covers what the constant ramp of 1/f covers, so the S plan takes the constant plan's
    time; and it keeps every axis jerk at the corner (the ramps end there at zero
    acceleration, each segment's phases end exactly at the break)."""
    from oracle_cases import line_path
    from reference.core import AxisLimits, MachineLimits
    from optimal.freq.ramps import ramp_plan
    from reference.core.constraints import BOUND_SETS, check_profile

    lim = MachineLimits(tuple(AxisLimits(n, 500.0, 2000.0, 4e4, 1.2, 20.0) for n in "XYZ"),
                        0.004)
    path = line_path([[0, 0, 0], [20.0, 0, 0], [20.0, 20.0, 0]], feed=20.0)
    brisk = ramp_plan(path, lim)[0]
    soft = ramp_plan(path, lim, jerk=True)[0]
    assert soft.duration == pytest.approx(brisk.duration, rel=1e-12)
    assert check_profile(path, lim, soft).ok(BOUND_SETS["jerk+freq"])


def _sampled_axis_derivatives(path, prof, order, dt=2e-4, skip_s=None):
    """Largest ``|d^order q_i / dt^order|`` per axis by finite differences of the axis
    positions sampled every ``dt`` (an independent judge, not the checker); differences
    touching a sample within ``skip_s`` mm of an inner segment break are left out (steps
    the rulebook spreads over one IPO cycle)."""
    t = np.arange(0.0, prof.duration, dt)
    s, _, _, _ = prof.state(t)
    d = np.diff(path.evaluate(s)[0], order, axis=0) / dt ** order
    if skip_s is not None and path.n_segments > 1:
        gap = np.min(np.abs(s[:, None] - path.s_breaks[None, 1:-1]), axis=1)
        near = np.convolve(gap <= skip_s, np.ones(order + 1), "valid") > 0
        d = d[~near]
    return np.max(np.abs(d), axis=0)


def test_ramp_plan_on_a_wide_arc_is_the_closed_form():
    """Rest to rest on a half circle of R = 200 mm at F100 (A = 2000 mm/s^2, 10 Hz): the
    centripetal 100^2 / 200 = 50 mm/s^2 leaves the ramps 1950 mm/s^2, more than the
    1000 mm/s^2 of a ramp to 100 mm/s in 1/f, so DESIGN 6's closed form L/v + 1/f holds
    on the curve too; the axis accelerations, by second differences of the sampled
    positions, stay within A."""
    from oracle_cases import semicircle
    from optimal.freq.ramps import ramp_plan
    from reference.core.constraints import BOUND_SETS, check_profile

    R, F = 200.0, 100.0
    path = semicircle(R, feed=F)
    lim = _xyz(a=2000.0, f=10.0)
    prof = ramp_plan(path, lim)[0]
    assert prof.duration == pytest.approx(np.pi * R / F + 0.1, rel=1e-12)
    assert check_profile(path, lim, prof).ok(BOUND_SETS["acc+freq"])
    assert np.all(_sampled_axis_derivatives(path, prof, 2)[:2] <= 2000.0 * (1 + 1e-3))


def test_ramp_plan_crosses_a_tight_arc_at_its_curvature_limit():
    """Line, half circle of R = 5 mm, line (50 mm each) at F200, A = 2000 mm/s^2, 10 Hz:
    the arc's centripetal limit sqrt(A R) = 100 mm/s leaves no room to ramp on it, so the
    fastest plan crosses it at exactly 100 mm/s, and the lines ramp by hand: rest to 200
    mm/s in 1/f (10 mm), 25 mm at 200, down to 100 in 1/f (15 mm), i.e. 0.325 s each,
    plus pi R / 100 on the arc."""
    from oracle_cases import line_arc_line
    from optimal.freq.ramps import ramp_plan
    from reference.core.constraints import BOUND_SETS, check_profile

    path = line_arc_line(5.0, 50.0, feed=200.0)
    lim = _xyz(a=2000.0, f=10.0)
    prof = ramp_plan(path, lim)[0]
    assert prof.duration == pytest.approx(2 * 0.325 + np.pi * 5.0 / 100.0, rel=1e-9)
    assert check_profile(path, lim, prof).ok(BOUND_SETS["acc+freq"])
    on_arc = (prof.s[:-1] >= 50.0) & (prof.s[1:] <= 50.0 + np.pi * 5.0)
    assert np.any(on_arc)
    np.testing.assert_allclose(prof.v[:-1][on_arc], 100.0, rtol=1e-12)


def test_ramp_plan_s_curves_on_arcs_keep_the_axis_jerk():
    """``jerk+freq`` on the half circle of R = 200 mm at F100 (J = 1e5 mm/s^3, 10 Hz):
    the curve's jerk terms (``3 |q''| v s''`` and ``|q'''| v^3``) leave the S-curve more
    than the jerk of a ramp to 100 mm/s in 1/f, so L/v + 1/f holds. On the line-arc-line
    of R = 5 mm the break where the curvature jumps is crossed at most at sqrt(J t_ipo R)
    (the centripetal step over one IPO cycle, by hand). The axis jerks by third
    differences stay within J away from the breaks, and the checker accepts both."""
    from oracle_cases import line_arc_line, semicircle
    from optimal.freq.ramps import ramp_plan
    from reference.core import AxisLimits, MachineLimits
    from reference.core.constraints import BOUND_SETS, check_profile

    J = 1e5
    lim = MachineLimits(tuple(AxisLimits(n, 500.0, 2000.0, J, 1.2, 10.0) for n in "XYZ"),
                        0.004)
    arc = semicircle(200.0, feed=100.0)
    prof = ramp_plan(arc, lim, jerk=True)[0]
    assert prof.duration == pytest.approx(np.pi * 200.0 / 100.0 + 0.1, rel=1e-12)
    assert check_profile(arc, lim, prof).ok(BOUND_SETS["jerk+freq"])
    assert np.all(_sampled_axis_derivatives(arc, prof, 3)[:2] <= J * (1 + 1e-2))
    path = line_arc_line(5.0, 50.0, feed=200.0)
    prof = ramp_plan(path, lim, jerk=True)[0]
    assert check_profile(path, lim, prof).ok(BOUND_SETS["jerk+freq"])
    v_break = prof.state(np.interp(50.0, prof.s, prof.t))[1]
    assert v_break <= np.sqrt(J * 0.004 * 5.0) * (1 + 1e-9)
    jerk_away = _sampled_axis_derivatives(path, prof, 3, skip_s=0.5)
    assert np.all(jerk_away[:2] <= J * (1 + 1e-2))


def test_pieced_takes_the_faster_motion_on_each_piece():
    """Two pieces (an exact stop between), two hand motions each faster on one piece: the
    joined motion takes the sum of the faster halves and is accepted."""
    from oracle_cases import line_path
    from optimal.freq.upper import Candidate, pieced
    from reference.core.constraints import BOUND_SETS, check_profile

    path = line_path([[0, 0, 0], [40, 0, 0], [40, 30, 0]], feed=200.0,
                     stops=("start", "exact", "end"))
    lim = _xyz(f=10.0)

    def trapezoid(s0, L, v):
        # ramps of 1/f at v f <= A: accepted under acc+freq, time L/v + 0.1
        return Profile.from_phases([0.1, L / v - 0.1, 0.1], [v / 0.1, 0.0, -v / 0.1],
                                   [0.0] * 3, s0=s0)

    def joined(p, q):
        t = np.concatenate((p.t, p.t[-1] + q.t[1:]))
        return Profile(t=t, s=np.concatenate((p.s, q.s[1:])), v=np.concatenate((p.v, q.v[1:])),
                       a=np.concatenate((p.a, q.a)), j=np.concatenate((p.j, q.j)),
                       block=np.concatenate((p.block, q.block)))

    fast_a, slow_a = trapezoid(0.0, 40.0, 100.0), trapezoid(0.0, 40.0, 50.0)
    fast_b, slow_b = trapezoid(40.0, 30.0, 100.0), trapezoid(40.0, 30.0, 50.0)
    one, two = joined(fast_a, slow_b), joined(slow_a, fast_b)
    for p in (one, two):
        assert check_profile(path, lim, p).ok(BOUND_SETS["acc+freq"])
    rep = check_profile(path, lim, one)
    cands = [Candidate("one", one, 1.0, rep), Candidate("two", two, 1.0, rep)]
    out = pieced(path, cands)
    assert out.duration == pytest.approx(40.0 / 100.0 + 0.1 + 30.0 / 100.0 + 0.1, rel=1e-12)
    assert check_profile(path, lim, out).ok(BOUND_SETS["acc+freq"])
    # one motion fastest everywhere: nothing to join
    assert pieced(path, cands[:1]) is None


@pytest.mark.parametrize("machine_name", [None, "linuxcnc_xyz"])
@pytest.mark.parametrize("jerk", [False, True])
def test_ramp_plan_is_accepted_as_built_on_blended_polylines(machine_name, jerk):
    """Random polylines with circular blends (segments of 0.05-30 mm, blends of 0.01-1 mm
    deviation, feeds of 20-200 mm/s) on both bundled machines: the checker accepts every
    ramp plan as it is built (no time scaling), under the plan's own bound set. It found
    two round-off holes before they were closed (each fails it without its fix): a
    curve crossed at its curvature limit left a budget of 1e-14 mm/s^2 (ramps of ~1e14
    s, position lost), and an S-curve's constant part of ~1e-17 s did not advance the
    position, so the checker cut the phase in two there."""
    from dataclasses import replace

    from oracle_cases import random_blended_polyline
    from optimal.freq.ramps import ramp_plan
    from reference.core.constraints import BOUND_SETS, check_profile
    from reference.machine import load_machine

    m = load_machine(machine_name)
    cons = BOUND_SETS["jerk+freq" if jerk else "acc+freq"]
    # 24 seeds, and three that hit the S-curve hole on the default machine
    for seed in (*range(24), 39, 49, 77):
        rng = np.random.default_rng(seed + 1000)
        step = [(0.1, 20.0), (2.0, 30.0), (0.05, 2.0)][seed % 3]
        path = random_blended_polyline(int(rng.integers(2, 12)), seed, step=step,
                                       max_deviation=[0.01, 0.1, 1.0][seed % 3])
        path = replace(path, feed=np.full(path.n_segments, float(rng.uniform(20, 200))))
        prof = ramp_plan(path, m.limits, jerk=jerk)[0]
        assert check_profile(path, m.limits, prof).ok(cons), (machine_name, jerk, seed)


def test_fir_window_of_round_off_is_none():
    """A line whose trapezoid ramps take exactly 1/f (v/A = 100/2000 = 50 ms at 20 Hz)
    leaves the moving average a window of round-off (1.4e-17 s): its acceleration
    ``(v(t) - v(t - W)) / W`` was round-off divided by W, and the filtered motion ran
    30 mm past the end of a 20 mm line. Such a window is none: the filtered motion is
    the trapezoid itself, the closed form L/v + v/A = 0.25 s, ending at rest at 20 mm."""
    from optimal.freq.upper import fir_filtered

    lim = _xyz(v=100.0, a=2000.0, f=20.0)
    import sys
    from pathlib import Path as FsPath
    sys.path.insert(0, str(FsPath(__file__).parent))
    from oracle_cases import line_path
    path = line_path([[0, 0, 0], [20, 0, 0]])
    # the trapezoid, with its ramps a hair under 1/f as an optimum's round-off leaves them
    r = 0.05 - 1.4e-17
    trap = Profile.from_phases([r, (20.0 - 100.0 * r) / 100.0, r],
                               [100.0 / r, 0.0, -100.0 / r], [0, 0, 0])
    out = fir_filtered(path, lim, trap, jerk_limited=False)
    assert out.s[-1] == pytest.approx(20.0, abs=1e-9)
    assert out.duration == pytest.approx(20.0 / 100.0 + 100.0 / 2000.0, rel=1e-12)
    assert abs(out.v[-1]) <= 1e-9 and np.max(out.v) <= 100.0 * (1 + 1e-12)


def test_a_ramp_the_grid_puts_into_one_interval_becomes_the_ramp_of_1_f():
    """A line between two slow corners (1.2 mm/s) at 20 mm/s, A = 1500 mm/s^2, 15 Hz, on
    a grid of 1/6 mm: each acc ramp (0.13 mm) fits inside one interval. The adaptation
    (:func:`optimal.freq.upper._adapted`) must turn each into the ramp of ``1/f`` at the
    constant rate ``(v - v_c) f``: the hand motion of two such ramps and a cruise at
    ``v``. It used to slow the intervals it had already set on later rounds (the phase
    grew one interval a round, its far end halved each time): 0.385 s against the hand
    0.313 s (examples/demo.mpf's plunge under acc+freq: 0.378 s of 0.317). The ramps end
    inside an interval (0.707 mm on 1/6 mm steps), whose constant acceleration is then
    a little gentler: measured 6e-4 above the hand motion."""
    from optimal.freq.upper import ADAPT_MARGIN, _adapted
    from optimal.grid import grid_on
    from reference.core.phases import acceleration_phases
    from oracle_cases import line_path

    f, A, v, v_c, L, ds = 15.0, 1500.0, 20.0, 1.2, 5.0, 1.0 / 6.0
    lim = _xyz(a=A, f=f)
    path = line_path([[0, 0, 0], [L, 0, 0]], feed=v)
    grid = grid_on(path, np.linspace(0.0, L, int(round(L / ds)) + 1))
    b = np.full(grid.s.size, v * v)
    b[0] = b[-1] = v_c * v_c
    blocks = path.block[grid.segment]
    out = _adapted(path, lim.for_axes(path.axes), grid, b, 2.0 * A * np.diff(grid.s),
                   blocks, 0.0)
    prof = Profile.from_path_velocity(grid.s, np.sqrt(out), blocks)
    ph = acceleration_phases(prof)
    ramp_t = (1.0 + ADAPT_MARGIN) / f            # the adaptation aims a hair above 1/f
    hand = 2.0 * ramp_t + (L - (v + v_c) * ramp_t) / v
    assert ph.sign.size == 2 and np.all(ph.effective_duration >= (1.0 - ADAPT_MARGIN) / f)
    assert prof.duration == pytest.approx(hand, rel=1e-3)
