"""Reference planner, profile stage: closed forms, S-curve cases, agreement with Ruckig.

Hand-derived answers (trapezoid ``L/v + v/a``, triangle ``2 sqrt(L/a)``), the S-curve
case enumeration, and single straight rest-to-rest blocks against Ruckig (a test-time
dependency) to 1e-6 relative, including moves that never reach v_max or a_max.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from reference.machine import load_machine
from reference.nc import parse_text
from reference.planner import lookahead as LA
from reference.planner import plan
from reference.planner.profiles import (CASE_CRUISE, CASE_FALL_ACC, CASE_RISE_ACC,
                                        case_name, ramp_distance, ramp_reach, ramp_time,
                                        solve_peak, unit_profiles)

MACHINE = load_machine()
A_X = 2000.0       # default machine X: MAX_AX_ACCEL 2 m/s^2
J_X = 40000.0      # MAX_AX_JERK 40 m/s^3


def _plan(text: str, **channel):
    m = dataclasses.replace(MACHINE, channel=dataclasses.replace(MACHINE.channel, **channel))
    return plan(parse_text(text, "t.mpf"), m)


def _ruckig_time(length: float, v: float, a: float, j: float) -> float:
    ruckig = pytest.importorskip("ruckig")
    inp = ruckig.InputParameter(1)
    inp.current_position, inp.target_position = [0.0], [length]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [v], [a], [j]
    traj = ruckig.Trajectory(1)
    res = ruckig.Ruckig(1).calculate(inp, traj)
    assert res in (ruckig.Result.Working, ruckig.Result.Finished)
    return traj.duration


# ----------------------------------------------------------------- ramp formulas
def test_ramp_time_cases():
    # acceleration-limited: dv >= A^2/J -> dv/A + A/J ; jerk-limited: 2 sqrt(dv/J)
    assert ramp_time(200.0, A_X, J_X) == pytest.approx(200 / A_X + A_X / J_X, rel=1e-15)
    assert ramp_time(25.0, A_X, J_X) == pytest.approx(2 * np.sqrt(25 / J_X), rel=1e-15)
    # continuous at the case boundary dv = A^2/J = 100 mm/s
    assert ramp_time(100.0, A_X, J_X) == pytest.approx(2 * A_X / J_X, rel=1e-15)
    # BRISK (J = inf): dv / A
    assert ramp_time(100.0, A_X, np.inf) == pytest.approx(0.05, rel=1e-15)


def test_ramp_reach_inverts_distance():
    rng = np.random.default_rng(3)
    n = 2000
    v = rng.uniform(0, 300, n) * (rng.random(n) < 0.8)
    dist = 10 ** rng.uniform(-3, 3, n)
    acc = rng.uniform(100, 5000, n)
    jerk = np.where(rng.random(n) < 0.2, np.inf, 10 ** rng.uniform(3, 6, n))
    r = ramp_reach(v, dist, acc, jerk)
    d = ramp_distance(v, r, acc, jerk)
    # relative to the distance, with the conditioning of dv = r - v: the speeds carry
    # a round-off of eps * r, which is eps * r / dv relative to the speed change
    eps = np.finfo(float).eps
    rel = 1e-9 + 8 * eps * r / np.maximum(r - v, 1e-300)
    assert np.all(np.abs(d - dist) <= rel * dist)
    brisk = np.isinf(jerk)
    np.testing.assert_allclose(r[brisk], np.sqrt(v[brisk] ** 2 + 2 * acc[brisk] * dist[brisk]),
                               rtol=1e-13)


def test_braking_to_a_higher_speed_can_take_longer_with_zero_end_acceleration():
    # A property of the a = 0 end condition the LookAhead has to respect: braking from
    # 100 mm/s to 10 mm/s needs more distance than braking to rest (the last jerk phase
    # runs at a higher speed), for dv >> A^2/J: v^2/2A + v A/2J terms.
    assert ramp_distance(10.0, 100.0, A_X, J_X) > ramp_distance(0.0, 100.0, A_X, J_X)


# ----------------------------------------------------------------- unit profiles
def test_unit_profile_cases_are_enumerated_and_verified():
    # (v0, v1, L, cap) chosen to hit: cruise with a_max, cruise without a_max,
    # no cruise with a_max, no cruise without a_max
    v0 = np.array([0.0, 0.0, 0.0, 0.0, 50.0])
    v1 = np.array([0.0, 0.0, 0.0, 0.0, 10.0])
    L = np.array([100.0, 100.0, 10.0, 0.2, 5.0])
    cap = np.array([200.0, 50.0, 500.0, 500.0, 500.0])
    a = np.full(5, A_X)
    j = np.full(5, J_X)
    u = unit_profiles(v0, v1, L, cap, a, j, a, j)
    names = [case_name(int(c)) for c in u.case]
    assert names[0] == "RISE_ACC+CRUISE+FALL_ACC"
    assert names[1] == "RISE_JERK+CRUISE+FALL_JERK"
    assert names[2] == "RISE_ACC+FALL_ACC"
    assert names[3] == "RISE_JERK+FALL_JERK"
    np.testing.assert_allclose(u.dist_rise + u.dist_cruise + u.dist_fall, L, rtol=1e-12)
    # every phase respects the limits
    assert np.all(np.abs(u.a0) <= A_X * (1 + 1e-12))
    assert np.all(np.abs(u.jerk) <= J_X * (1 + 1e-12))


def test_peak_is_the_largest_that_fits():
    rng = np.random.default_rng(7)
    n = 3000
    v0 = rng.uniform(0, 100, n)
    L = 10 ** rng.uniform(-2, 2, n)
    v1 = rng.uniform(0, 1, n) * ramp_reach(v0, L, A_X, J_X)
    ok = ramp_distance(np.minimum(v0, v1), np.maximum(v0, v1), A_X, J_X) <= L
    v0, v1, L = v0[ok], v1[ok], L[ok]
    cap = np.maximum(np.maximum(v0, v1), rng.uniform(0, 400, v0.size))
    a = np.full(v0.size, A_X)
    j = np.full(v0.size, J_X)
    vp = solve_peak(v0, v1, L, cap, a, j, a, j)

    def g(x):
        return ramp_distance(v0, x, a, j) + ramp_distance(v1, x, a, j) - L

    assert np.all(g(vp) <= 1e-12 * L)
    not_max = (vp < cap * (1 - 1e-9)) & (g(vp * (1 + 1e-9) + 1e-12) <= 0)
    assert not not_max.any()


def test_brisk_peak_is_the_closed_form_root():
    """BRISK (jerk = inf): the peak of a unit is the closed form
    ``vp^2 = (v0^2/(2 A_up) + v1^2/(2 A_dn) + L) / (1/(2 A_up) + 1/(2 A_dn))`` (the rise
    and the fall fill the length), capped; the solve returns it to round-off, on the
    feasible side (distance at most L)."""
    rng = np.random.default_rng(11)
    n = 4000
    au, ad = rng.uniform(100, 5000, n), rng.uniform(100, 5000, n)
    v0 = rng.uniform(0, 150, n)
    L = 10 ** rng.uniform(-3, 1.5, n)
    v1 = rng.uniform(0, 1, n) * np.sqrt(v0 ** 2 + 2 * ad * L)
    ok = np.abs(v1 ** 2 - v0 ** 2) <= 2 * np.minimum(au, ad) * L
    au, ad, v0, v1, L = au[ok], ad[ok], v0[ok], v1[ok], L[ok]
    exact = np.sqrt((v0 ** 2 / (2 * au) + v1 ** 2 / (2 * ad) + L) / (0.5 / au + 0.5 / ad))
    cap = np.where(rng.random(v0.size) < 0.3, rng.uniform(0.5, 1.0, v0.size) * exact,
                   np.inf)
    cap = np.maximum(cap, np.maximum(v0, v1))
    inf = np.full(v0.size, np.inf)
    vp = solve_peak(v0, v1, L, cap, au, inf, ad, inf)
    np.testing.assert_allclose(vp, np.minimum(exact, cap), rtol=1e-13)
    dist = (vp ** 2 - v0 ** 2) / (2 * au) + (vp ** 2 - v1 ** 2) / (2 * ad)
    assert np.all(dist <= L * (1 + 1e-12))


def _passes_in_order(units):
    """The LookAhead passes as the model states them: every step in turn, backward from
    the end, then forward from the start, each keeping the node's own limit where the
    cheap test or the reachable speed allows it (the stage's scalar step functions)."""
    n = units.n_units
    cap, cause, L = units.node_cap, units.node_cause, units.length
    drive = np.isfinite(units.knee)
    mode = np.where(drive, 2, units.jerk_limited.astype(int))
    r_fit = np.where(drive, units.knee_ratio, 1.0)
    b, origin = cap.astype(float).copy(), cause.astype(np.int64).copy()
    for k in range(n - 1, -1, -1):
        be, c = float(b[k + 1]), float(cap[k])
        if c <= be or LA._fits(be, c, L[k], units.acc_dn[k] * r_fit[k], units.jerk_dn[k]):
            continue
        r = LA._REACH[mode[k]](be, L[k], units.acc_dn[k], units.jerk_dn[k], units.knee[k],
                               units.knee_ratio[k])
        if c > r:
            b[k], origin[k] = r, origin[k + 1]
    w, lim = b.copy(), np.zeros(n + 1, dtype=bool)
    for k in range(n):
        ws, bn = float(w[k]), float(b[k + 1])
        if bn <= ws or LA._fits(ws, bn, L[k], units.acc_up[k] * r_fit[k], units.jerk_up[k]):
            continue
        f = LA._REACH[mode[k]](ws, L[k], units.acc_up[k], units.jerk_up[k], units.knee[k],
                               units.knee_ratio[k])
        if bn > f:
            w[k + 1], lim[k + 1] = f, True
    return w, b, origin, lim


def _random_units(rng, n, soft, drive):
    jl = rng.random(n) < soft
    dr = ~jl & (rng.random(n) < drive)
    acc = rng.uniform(100, 3000, n)
    jerk = np.where(jl, rng.uniform(1e3, 1e5, n), np.inf)
    cap = np.where(rng.random(n) < 0.5, 100.0, rng.uniform(1, 200, n))
    L = rng.choice([1e-3, 0.05, 0.5, 5.0], n) * rng.uniform(0.5, 1.5, n)
    node = np.minimum(np.concatenate(([0.0], cap)), np.concatenate((cap, [0.0])))
    node = np.where(rng.random(n + 1) < 0.3, node * rng.uniform(0, 1, n + 1), node)
    node[[0, -1]] = 0.0
    z = np.zeros(n, dtype=bool)
    return LA.Units(
        first_segment=np.arange(n), n_segments=np.ones(n, dtype=int),
        node_break=np.arange(n + 1), s_start=np.cumsum(L) - L, length=L, cap=cap,
        cap_cause=np.zeros(n, dtype=int), acc_up=acc, jerk_up=jerk,
        acc_dn=acc * rng.uniform(0.5, 1.5, n), jerk_dn=jerk.copy(),
        frequency=np.full(n, 10.0), jerk_limited=jl, node_cap=node,
        node_cause=rng.integers(0, 9, n + 1), adapted_up=z, adapted_dn=z.copy(),
        knee=np.where(dr, rng.uniform(5, 100, n), np.inf),
        knee_ratio=np.where(dr, rng.uniform(0.3, 1, n), 1.0))


@pytest.mark.parametrize("soft, drive", [(0.0, 0.0), (1.0, 0.0), (0.3, 0.2), (0.0, 0.3)])
def test_lookahead_passes_equal_every_step_in_order(soft, drive):
    """Model note 7, step 3: a backward pass from the end and a forward pass from the
    start, each step the closed-form reachable speed. The stage decides the steps whose
    neighbour keeps its own limit all at once and steps one by one only along binding
    chains; its speeds, causes and flags must be those of taking every step in turn
    (bit for bit), on BRISK, SOFT and DRIVE units and their mixes; for BRISK the
    speeds also meet the closed form ``b_k = min(cap_k, sqrt(b_{k+1}^2 + 2 A_k L_k))``."""
    rng = np.random.default_rng(int(100 * soft + 10 * drive))
    for _ in range(60):
        u = _random_units(rng, int(rng.integers(1, 300)), soft, drive)
        got = LA.lookahead_passes(u)
        w, b, origin, lim = _passes_in_order(u)
        np.testing.assert_array_equal(got.backward, b)
        np.testing.assert_array_equal(got.v, w)
        np.testing.assert_array_equal(got.origin_cause, origin)
        np.testing.assert_array_equal(got.accel_limited, lim)
        if soft == 0.0 and drive == 0.0:
            reach = np.sqrt(got.backward[1:] ** 2 + 2 * u.acc_dn * u.length)
            np.testing.assert_allclose(got.backward[:-1], np.minimum(u.node_cap[:-1], reach),
                                       rtol=1e-12)
            reach = np.sqrt(got.v[:-1] ** 2 + 2 * u.acc_up * u.length)
            np.testing.assert_allclose(got.v[1:], np.minimum(got.backward[1:], reach),
                                       rtol=1e-12)


@pytest.mark.parametrize("length, feed", [
    (100.0, 9000.0),    # cruise at 150 mm/s, a_max reached (dv = 150 > A^2/J = 100)
    (100.0, 3000.0),    # cruise at 50 mm/s, a_max never reached
    (2.0, 30000.0),     # v_max never reached, a_max reached
    (0.2, 30000.0),     # neither v_max nor a_max reached
    (37.5, 6000.0),     # cruise at the case boundary dv = A^2/J
])
def test_soft_single_block_matches_ruckig(length, feed):
    p = _plan(f"G90 G64 SOFT F{feed}\nG1 X{length}\nM30\n")
    assert p.bound_set == "jerk" and p.ok
    expected = _ruckig_time(length, feed / 60.0, A_X, J_X)
    assert p.time_s == pytest.approx(expected, rel=1e-6)


def test_soft_diagonal_block_matches_ruckig_with_path_limits():
    # along (3, 4, 0)/5 the path limits are min_i A_i/|t_i| = 2000/0.8 and 40000/0.8
    p = _plan("G90 G64 SOFT F12000\nG1 X30 Y40\nM30\n")
    expected = _ruckig_time(50.0, 200.0, A_X / 0.8, J_X / 0.8)
    assert p.time_s == pytest.approx(expected, rel=1e-6)


def test_soft_unit_profiles_match_ruckig_randomly():
    rng = np.random.default_rng(11)
    for _ in range(200):
        L, V = 10 ** rng.uniform(-2, 3), rng.uniform(1, 500)
        A, J = rng.uniform(100, 5000), 10 ** rng.uniform(3, 6)
        u = unit_profiles([0.0], [0.0], [L], [V], [A], [J], [A], [J])
        assert u.time[0] == pytest.approx(_ruckig_time(L, V, A, J), rel=1e-6)


def test_brisk_trapezoid_closed_form():
    # L/v + v/a for a block that reaches its feed
    p = _plan("G90 G64 BRISK F6000\nG1 X100\nM30\n")
    assert p.bound_set == "acc" and p.ok
    assert p.time_s == pytest.approx(100 / 100 + 100 / A_X, rel=1e-12)
    case = p.blocks[1].case
    assert case == "RISE_ACC+CRUISE+FALL_ACC"


def test_brisk_triangle_closed_form():
    # 2 sqrt(L/a) when the feed is never reached (peak sqrt(a L) = 63 < 100 mm/s)
    p = _plan("G90 G64 BRISK F6000\nG1 X2\nM30\n")
    assert p.time_s == pytest.approx(2 * np.sqrt(2 / A_X), rel=1e-12)
    assert p.blocks[1].v_peak == pytest.approx(np.sqrt(A_X * 2), rel=1e-12)
    # the block brakes for the program end before it reaches F
    assert p.blocks[1].cause == "forced stop"


def test_case_bits_name_the_reached_limits():
    assert case_name(CASE_RISE_ACC | 1 | CASE_CRUISE) == "RISE_ACC+CRUISE"
    assert case_name(8 | CASE_FALL_ACC) == "FALL_ACC"
    assert case_name(0) == "HOLD"
