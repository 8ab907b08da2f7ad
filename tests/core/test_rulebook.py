"""The rulebook (reference/core/rules.py) against hand geometry, and the certificate it
makes possible: on random polylines with near-tangent kinks, on machines with overload
factors 1.0 to 1.5, the heuristic (which the checker accepts) is never faster than the
oracle's lower bound, and the oracle's upper bound is never below it.

The closed forms here are written out by hand (angles of hand-made tangents, the corner
speed of a 90 degree corner), not taken from the module under test.
"""

from __future__ import annotations

import copy
import math
import tomllib
from importlib import resources

import numpy as np
import pytest

from optimal import solve
from reference.core.constraints import BOUND_SETS, check_profile
from reference.core.rules import (FEASIBLE, RELAXED, axis_acceleration, axis_jerk,
                                  axis_velocity, axis_velocity_jumps, curvature_jumps,
                                  is_tangential, jump_ratio, junction_angle,
                                  junction_speed_cap, speed_caps)
from reference.core.tolerances import (CURVATURE_JUMP_TOL_PER_MM, RATIO_TOL, TANGENT_TOL_RAD,
                                       VEL_TOL_MM_S)
from reference.machine import machine_from_dict
from reference.nc import parse_text
from reference.planner import plan

DEFAULT_DICT = tomllib.loads(resources.files("reference.machines").joinpath(
    "default.toml").read_text())


def _tangents(angle: float) -> tuple[np.ndarray, np.ndarray]:
    """Unit tangents along X and turned by ``angle`` in the XY plane, shape (1, 3)."""
    return (np.array([[1.0, 0.0, 0.0]]),
            np.array([[math.cos(angle), math.sin(angle), 0.0]]))


@pytest.mark.parametrize("angle", [0.0, 1e-12, 1e-9, 5e-8, 1e-7, 3e-7, 1e-3, 0.5,
                                   math.pi / 2, 3.0])
def test_junction_angle_is_accurate_down_to_round_off(angle):
    t_in, t_out = _tangents(angle)
    assert junction_angle(t_in, t_out)[0] == pytest.approx(angle, rel=1e-12, abs=1e-15)


@pytest.mark.parametrize("factor, tangential", [(0.5, True), (1.5, False)])
def test_tangency_threshold_at_half_and_one_and_a_half(factor, tangential):
    t_in, t_out = _tangents(factor * TANGENT_TOL_RAD)
    for flavour in (FEASIBLE, RELAXED):
        assert bool(is_tangential(t_in, t_out, flavour)[0]) is tangential
    dv = axis_velocity_jumps(t_in, t_out, np.array([1000.0]))
    assert bool(np.all(dv == 0.0)) is tangential


def test_feasible_tangency_implies_relaxed_tangency():
    angles = TANGENT_TOL_RAD * np.linspace(0.99, 1.01, 2001)
    t_in = np.tile([1.0, 0.0, 0.0], (angles.size, 1))
    t_out = np.stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)], axis=1)
    feas = is_tangential(t_in, t_out, FEASIBLE)
    relx = is_tangential(t_in, t_out, RELAXED)
    assert np.all(relx[feas])          # feasible-tangential => relaxed-tangential
    assert np.any(relx & ~feas)        # the band between them is not empty


def test_90_degree_corner_speed_by_hand():
    # X then Y: |dt| = (1, 1, 0); allowance A (ovl - 1) T_ipo per axis
    A, ovl, T = 2000.0, 1.2, 0.004
    allow = np.full(3, A * (ovl - 1) * T)           # 1.6 mm/s
    t_in, t_out = np.array([[1.0, 0.0, 0.0]]), np.array([[0.0, 1.0, 0.0]])
    v_feas, ax = junction_speed_cap(t_in, t_out, allow, FEASIBLE)
    v_relx, _ = junction_speed_cap(t_in, t_out, allow, RELAXED)
    assert v_feas[0] == pytest.approx(1.6, rel=1e-15)
    assert ax[0] in (0, 1)
    assert v_relx[0] == pytest.approx(1.6 * (1 + RATIO_TOL), rel=1e-8)


def test_overload_factor_one_stops_at_real_corners_and_floats_over_near_tangent_kinks():
    allow = np.zeros(3)
    # 90 degrees: the floor 1e-6 / 1 is standstill level: a stop
    v, _ = junction_speed_cap(np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]]), allow, FEASIBLE)
    assert v[0] == 0.0
    # a 1e-6 rad kink: |dt_y| = 1e-6, the floor allows 1e-6 mm/s of step, v ~ 1 mm/s
    t_in, t_out = _tangents(1e-6)
    v_f = junction_speed_cap(t_in, t_out, allow, FEASIBLE)[0][0]
    v_r = junction_speed_cap(t_in, t_out, allow, RELAXED)[0][0]
    assert v_f == pytest.approx(VEL_TOL_MM_S / math.sin(1e-6), rel=1e-8)
    assert v_f < v_r < v_f * (1 + 1e-8)


def test_feasible_caps_pass_the_checker_rule_and_relaxed_caps_bound_it():
    """At the feasible cap every axis step has jump ratio <= 1 + RATIO_TOL; just above the
    relaxed cap some axis step has a larger ratio (checked on random tangents)."""
    rng = np.random.default_rng(7)
    for ovl in (1.0, 1.05, 1.5):
        allow = 2000.0 * (ovl - 1.0) * 0.004 * np.array([1.0, 0.5, 2.0])
        t_in = rng.normal(size=(500, 3))
        t_in /= np.linalg.norm(t_in, axis=1, keepdims=True)
        kink = rng.normal(size=(500, 3)) * 10.0 ** rng.uniform(-8, 0, size=(500, 1))
        t_out = t_in + kink
        t_out /= np.linalg.norm(t_out, axis=1, keepdims=True)
        v_f, _ = junction_speed_cap(t_in, t_out, allow, FEASIBLE)
        v_r, _ = junction_speed_cap(t_in, t_out, allow, RELAXED)
        assert np.all(v_f <= v_r)
        fin = np.isfinite(v_f)
        r = jump_ratio(axis_velocity_jumps(t_in[fin], t_out[fin], v_f[fin]), allow)
        assert np.all(r <= 1 + RATIO_TOL)
        fr = np.isfinite(v_r)
        above = v_r[fr] * (1 + 1e-7)
        r = jump_ratio(axis_velocity_jumps(t_in[fr], t_out[fr], above), allow)
        assert np.all(np.max(r, axis=1) > 1 + RATIO_TOL)


@pytest.mark.parametrize("factor, jumps", [(0.5, False), (1.5, True)])
def test_curvature_jump_threshold(factor, jumps):
    k_in = np.zeros((1, 3))
    k_out = np.array([[0.0, factor * CURVATURE_JUMP_TOL_PER_MM, 0.0]])
    assert bool(curvature_jumps(k_in, k_out)[0]) is jumps


def test_axis_kinematics_on_a_circle_by_hand():
    # q(s) = R (cos(s/R), sin(s/R)) at s = 0: q' = (0, 1), q'' = (-1/R, 0), q''' = (0, -1/R^2)
    R, v, a, j = 10.0, 50.0, 300.0, 4000.0
    dq, ddq, dddq = np.array([[0.0, 1.0]]), np.array([[-1 / R, 0.0]]), np.array([[0.0, -1 / R**2]])
    V, A, J = np.array([v]), np.array([a]), np.array([j])
    np.testing.assert_allclose(axis_velocity(dq, V), [[0.0, v]])
    np.testing.assert_allclose(axis_acceleration(dq, ddq, V, A), [[-v * v / R, a]])
    np.testing.assert_allclose(axis_jerk(dq, ddq, dddq, V, A, J),
                               [[-3 * v * a / R, j - v**3 / R**2]])


# ------------------------------------------------------------------ the certificate
def _machine(ovl: float, mode: str):
    d = copy.deepcopy(DEFAULT_DICT)
    d["channel"]["acceleration_mode"] = mode
    for ax in d["axis"].values():
        ax["MAX_ACCEL_OVL_FACTOR"] = ovl
    return machine_from_dict(d, f"<ovl {ovl}>")


def _kinky_polyline(seed: int) -> str:
    """A polyline whose joints mix near-tangent kinks (1e-9 .. 1e-5 rad, some right at the
    tangency threshold) with ordinary corners; lengths from 0.05 to 40 mm."""
    rng = np.random.default_rng(seed)
    heading = rng.uniform(0, 2 * np.pi)
    x = y = 0.0
    lines = [f"G90 G64 G1 X0 Y0 F{rng.choice([3000, 6000, 12000])}"]
    for _ in range(int(rng.integers(4, 12))):
        kind = rng.uniform()
        if kind < 0.4:
            turn = 10.0 ** rng.uniform(-9, -5)
        elif kind < 0.6:
            turn = TANGENT_TOL_RAD * rng.choice([0.999999, 1.000001, 0.5, 2.0])
        else:
            turn = rng.uniform(0.01, 2.5)
        heading += turn * rng.choice([-1.0, 1.0])
        length = 10.0 ** rng.uniform(np.log10(0.05), np.log10(40.0))
        x += length * np.cos(heading)
        y += length * np.sin(heading)
        lines.append(f"X{x:.12f} Y{y:.12f}")
    lines.append("M30")
    return "\n".join(lines) + "\n"


CASES = ([(seed, ovl, "BRISK") for seed in range(6) for ovl in (1.0, 1.001, 1.2, 1.5)]
         + [(seed, ovl, "SOFT") for seed in range(3) for ovl in (1.0, 1.5)])


@pytest.mark.parametrize("seed, ovl, mode", CASES)
def test_heuristic_is_never_below_the_lower_bound(seed, ovl, mode):
    machine = _machine(ovl, mode)
    prog = parse_text(_kinky_polyline(seed), f"kinky{seed}.mpf")
    p = plan(prog, machine)
    # the premise: the checker accepts the heuristic's profile under the acc bound set
    rep = check_profile(p.path, machine.limits, p.profile)
    assert rep.ok(BOUND_SETS["acc" if mode == "BRISK" else "jerk"]), rep
    sol = solve(p.path, machine.limits, bounds="acc")
    assert sol.status.value == "optimal", sol.status
    assert sol.lower_bound_s <= sol.upper_bound_s
    assert sol.lower_bound_s <= p.profile.duration, (
        f"LB {sol.lower_bound_s!r} above a profile the checker accepts "
        f"({p.profile.duration!r})")


def test_speed_caps_on_a_circle_by_hand():
    # a circle of radius 10 in XY at 30 degrees: |q'| = (sin 30, cos 30), |q''| = (cos, sin)/R
    R, th = 10.0, math.radians(30)
    dq = np.array([[-math.sin(th), math.cos(th), 0.0]])
    ddq = np.array([[-math.cos(th) / R, -math.sin(th) / R, 0.0]])
    V, A = np.array([500.0, 400.0, 100.0]), np.array([2000.0, 1000.0, 1.0])
    v_ax, v_cen = speed_caps(dq, ddq, V, A)
    assert v_ax[0] == pytest.approx(min(500 / 0.5, 400 / math.cos(th)))
    assert v_cen[0] == pytest.approx(min(math.sqrt(2000 * R / math.cos(th)),
                                         math.sqrt(1000 * R / 0.5)))
