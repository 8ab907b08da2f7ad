"""Curvature-continuous (G2) roundings under SOFT (issue 13 item 1; reference/rounding.py
``_shape``, reference/core/geometry.py clothoids), against hand geometry.

spec 5.9, MD20480 ten-thousands digit 0xxxx: "the axis velocity profiles in the rounding
area are not jerk-limited under BRISK and jerk-limited under SOFT"; 6.3: a transition
"between blocks of different curvature" gives an acceleration step that SOFT must limit
by slowing down. A tangent arc has such steps at both ends; the clothoid pair (curvature
rising linearly from 0 to theta / L_s and back) has none, so under SOFT its speed is set
by the axis limits along it, not by the curvature-jump rule.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from scipy.integrate import quad

from reference.core.constraints import BOUND_SETS, check_profile
from reference.core.geometry import KIND_CODES
from reference.core.rules import curvature_jump_speed_cap
from reference.machine import machine_from_dict
from reference.nc import parse_text
from reference.planner import plan
from reference.prepare import build_path

ROUNDING = KIND_CODES.index("rounding")
BASE = {
    "machine": {"name": "t", "ipo_cycle_ms": 4.0},
    "channel": {"lookahead_blocks": 50, "acceleration_mode": "SOFT"},
    "axis": {ax: {"MAX_AX_VELO": 30000.0, "MAX_AX_ACCEL": 2.0, "MAX_AX_JERK": 40.0,
                  "MAX_ACCEL_OVL_FACTOR": 1.0, "LOOKAH_FREQUENCY": 20.0,
                  "COMPRESS_POS_TOL": 0.01}
             for ax in "XYZ"},
}


def machine(**channel):
    """The test machine: G64 stops at every corner (overload factor 1.0). Programs at
    F60 (1 mm/s, below the speed of their roundings) are rounded at every corner: the
    rounding then costs no speed and shortens the path (5.2)."""
    d = copy.deepcopy(BASE)
    d["channel"].update(channel)
    return machine_from_dict(d)


def fresnel_unit(theta: float) -> tuple[float, float]:
    """(X, Y) of a unit-length clothoid turning by theta/2 (c = theta), by quadrature."""
    x = quad(lambda u: math.cos(theta * u * u / 2), 0, 1, epsabs=1e-14)[0]
    y = quad(lambda u: math.sin(theta * u * u / 2), 0, 1, epsabs=1e-14)[0]
    return x, y


@pytest.mark.parametrize("accel, g2", [("SOFT", True), ("BRISK", False)])
def test_soft_rounds_with_a_clothoid_pair_brisk_with_a_tangent_arc(accel, g2):
    prog = parse_text(f"G17 G90 G642 {accel} F60\nG1 X0 Y0\nG1 X50\nG1 Y50\n")
    path = build_path(prog, machine())
    t = path.rounding
    assert list(t.inserted) == [True] and bool(t.g2[0]) is g2
    assert int(np.sum(path.kind == ROUNDING)) == (2 if g2 else 1)
    assert int(np.count_nonzero(path.sharpness)) == (2 if g2 else 0)


def test_clothoid_pair_uses_the_tolerance_exactly_by_hand():
    """spec 5.4: per axis MD33100 = 0.01 mm at a 90 degree corner, so |C - M| =
    0.01 sqrt 2. For a pair of piece length L_s (c = theta / L_s^2) the middle point is
    (X, Y) L_s from the start, d = L_s (X + Y tan(theta/2)), |C - M| = L_s Y / cos(theta/2)
    with (X, Y) of the unit clothoid by quadrature."""
    prog = parse_text("G17 G90 G642 SOFT F60\nG1 X0 Y0\nG1 X50\nG1 Y50\n")
    path = build_path(prog, machine())
    t = path.rounding
    theta = math.pi / 2
    X, Y = fresnel_unit(theta)
    Ls = 0.01 * math.sqrt(2.0) * math.cos(theta / 2) / Y
    assert t.deviation_mm[0] == pytest.approx(0.01 * math.sqrt(2.0), rel=1e-10)
    assert t.distance_mm[0] == pytest.approx(Ls * (X + Y * math.tan(theta / 2)), rel=1e-10)
    assert t.length_mm[0] == pytest.approx(2 * Ls, rel=1e-10)
    assert t.radius_mm[0] == pytest.approx(Ls / theta, rel=1e-10)    # 1 / kappa_max
    k = np.flatnonzero(path.kind == ROUNDING)
    np.testing.assert_allclose(path.length[k], Ls, rtol=1e-10)
    # the corner point moves by the tolerance on each axis: the middle point M
    m = path.evaluate(path.s_breaks[k[1]])[0][0]
    np.testing.assert_allclose(np.abs(m[:2] - [50.0, 0.0]), 0.01, rtol=1e-9)


def test_the_pair_is_curvature_continuous_where_it_meets_the_lines():
    y = 50.0 * math.tan(math.radians(20.0))
    prog = parse_text(f"G17 G90 G642 CTOL=0.1 SOFT F6000\nG1 X0 Y0\nG1 X50\nG1 X100 Y{y!r}\n")
    path = build_path(prog, machine())
    assert path.rounding.inserted.all() and path.rounding.g2.all()
    k_in, k_out = path.junction_curvatures()
    t_in, t_out = path.junction_tangents()
    np.testing.assert_allclose(k_in, k_out, atol=1e-9)
    np.testing.assert_allclose(t_in, t_out, atol=1e-12)
    for k in range(path.n_segments - 1):
        np.testing.assert_allclose(path.segment(k).end, path.segment(k + 1).start,
                                   atol=1e-9)


def test_the_curvature_jump_rule_no_longer_caps_the_rounding():
    """spec 6.3: under SOFT a curvature jump caps the speed at
    sqrt(PATH_TRANS_JERK_LIM T_ipo / |dkappa_i|). The tangent arc of the same corner
    (an arc of the clothoid pair's smallest radius, whose curvature jumps from 0 to
    1/r at its start) is capped by it; the pair's model speed is above that cap, and so
    is the planned speed all through the pair."""
    y = 50.0 * math.tan(math.radians(20.0))
    text = f"G17 G90 G642 CTOL=0.1 SOFT F6000\nG1 X0 Y0\nG1 X50\nG1 X100 Y{y!r}\n"
    mach = machine()
    path = build_path(parse_text(text), mach)
    t = path.rounding
    assert t.g2.all() and t.inserted.all()
    r_min = t.radius_mm[0]
    lim = mach.limits.for_axes(path.axes)
    n = np.array([[0.0, 1.0, 0.0]])               # unit normal of the 20 degree left turn
    cap_arc = curvature_jump_speed_cap(np.zeros((1, 3)), n / r_min, lim.path_trans_jerk,
                                       mach.limits.t_ipo_s)[0]
    assert t.v_round[0] > 1.5 * cap_arc
    res = plan(parse_text(text), mach, path=path)
    rep = check_profile(path, mach.limits, res.profile)
    assert rep.ok(BOUND_SETS[res.bound_set]), rep
    k = np.flatnonzero(path.kind == ROUNDING)
    s = np.linspace(path.s_breaks[k[0]], path.s_breaks[k[-1] + 1], 101)
    v = res.profile.state(res.profile.time_at(s))[1]
    assert v.min() > cap_arc


def test_one_ipo_cycle_per_clothoid_piece():
    """spec 5.3: "every block, the rounding block included, needs at least one
    interpolation point"; the pair is two inserted blocks, so inside each the speed is
    at most L_s / T_ipo. ADIS = 0.05 mm at a 20 degree corner makes the pieces about
    0.05 mm long: 12.5 mm/s, below the centripetal limit sqrt(0.75 * 2000 L_s / theta)
    of about 14.6 mm/s (jerk limits raised so they do not bind)."""
    y = 50.0 * math.tan(math.radians(20.0))
    text = f"G90 G641 ADIS=0.05 SOFT F3000\nG1 X0 Y0\nG1 X50\nG1 X100 Y{y!r}\n"
    d = copy.deepcopy(BASE)
    for ax in d["axis"].values():
        ax["MAX_AX_JERK"] = 1e5
        ax["PATH_TRANS_JERK_LIM"] = 1e5
    mach = machine_from_dict(d)
    path = build_path(parse_text(text), mach)
    t = path.rounding
    assert t.inserted.all() and t.g2.all()
    k = np.flatnonzero(path.kind == ROUNDING)
    Ls = float(path.length[k[0]])
    assert t.v_round[0] <= Ls / 0.004 * (1 + 1e-12)
    res = plan(parse_text(text), mach, path=path)
    s = np.linspace(path.s_breaks[k[0]], path.s_breaks[k[-1] + 1], 201)
    v = res.profile.state(res.profile.time_at(s))[1]
    assert v.max() <= Ls / 0.004 * (1 + 1e-9)
