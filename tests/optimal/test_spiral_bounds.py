"""Spiral arcs keep the certificate: on seeded programs of strong spirals (small radii,
mismatch near the tolerance) the lower bound stays below the checked upper bound and
below the heuristic, and neither profile violates a limit on the exact spiral."""

from __future__ import annotations

import numpy as np
import pytest

import optimal
from reference.core.constraints import BOUND_SETS, check_profile
from reference.core.tolerances import ARC_RADIUS_REL_TOL, ARC_RADIUS_TOL_MM
from reference.machine import load_machine
from reference.nc import parse_text
from reference.planner import plan


def spiral_program(seed: int) -> str:
    """Arcs of radius 0.5..20 mm, end radius off by up to 95 % of the tolerance."""
    rng = np.random.default_rng(seed)
    lines = [f"G90 G64 BRISK G17 G1 X0 Y0 Z0 F{rng.choice([3000, 6000, 12000])}"]
    x = y = z = 0.0
    for _ in range(12):
        r = rng.uniform(0.5, 20)
        ang = rng.uniform(-np.pi, np.pi)
        cx, cy = x - r * np.cos(ang), y - r * np.sin(ang)
        sweep = rng.uniform(0.05, 3.0) * rng.choice([-1.0, 1.0])
        tol = max(ARC_RADIUS_TOL_MM, ARC_RADIUS_REL_TOL * r)
        r1 = r + rng.uniform(-0.95, 0.95) * tol
        ex, ey = cx + r1 * np.cos(ang + sweep), cy + r1 * np.sin(ang + sweep)
        ez = z + (rng.uniform(-2, 2) if rng.random() < 0.3 else 0.0)
        lines.append(f"{'G3' if sweep > 0 else 'G2'} X{ex:.6f} Y{ey:.6f} Z{ez:.6f} "
                     f"I{cx - x:.6f} J{cy - y:.6f}")
        x, y, z = float(f"{ex:.6f}"), float(f"{ey:.6f}"), float(f"{ez:.6f}")
        if rng.random() < 0.3:
            x, y = x + rng.uniform(-5, 5), y + rng.uniform(-5, 5)
            lines.append(f"G1 X{x:.6f} Y{y:.6f}")
    return "\n".join(lines + ["M30"]) + "\n"


@pytest.mark.parametrize("seed", range(4))
def test_lower_bound_holds_on_spirals(seed):
    machine = load_machine(None)
    p = plan(parse_text(spiral_program(seed), f"spiral{seed}.mpf"), machine)
    assert np.count_nonzero(p.path.dradius) >= 10
    sol = optimal.solve(p.path, machine.limits, bounds="acc")
    assert sol.status == "optimal"
    assert 0 < sol.lower_bound_s <= sol.upper_bound_s
    assert p.profile.duration >= sol.lower_bound_s            # BRISK: same bound set
    assert not p.report.violations(BOUND_SETS[p.bound_set])
    # the accepted (time-scaled) upper-bound profile, judged on the exact spirals
    assert not check_profile(p.path, machine.limits, sol.profile).violations(BOUND_SETS["acc"])
    assert sol.upper_bound_s == pytest.approx(sol.profile.duration, rel=1e-9)


def test_relaxation_ingredients_hold_on_a_strong_spiral():
    # r from 2 to 2.6 mm over 1.5 rad (k = 0.4 mm/rad) with a helix: far from a circle
    from scipy.integrate import quad

    from optimal.bounds import _interval_data
    from optimal.grid import initial_grid
    from reference.core import AxisLimits, MachineLimits, path_from_pieces
    from reference.core.geometry import arc_segment

    axes = ("X", "Y", "Z")
    start = np.array([2.0, 0.0, 0.0])
    end = np.array([2.6 * np.cos(1.5), 2.6 * np.sin(1.5), 1.0])
    path = path_from_pieces(axes, [arc_segment(start, end, np.zeros(3), (0, 1), False, 0,
                                               np.ones(3, bool), 0, np.inf)], feed=200.0)
    assert path.dradius[0] == pytest.approx(0.4)
    lim = MachineLimits(tuple(AxisLimits(a, 500.0, 2000.0, 40000.0) for a in axes),
                        0.004).for_axes(axes)
    grid = initial_grid(path, 40)
    geo = _interval_data(path, lim, grid)
    for k in range(grid.n_intervals):
        s0, s1 = grid.s[k], grid.s[k + 1]
        ss = np.linspace(s0, s1, 60)
        _, dq, ddq, _ = path.evaluate(ss, segment=np.zeros(ss.size, int))
        assert np.all(np.abs(ddq) <= geo.k2[k] * (1 + 1e-12))          # sup |q''_j|
        assert np.all(np.abs(dq) >= geo.lo[k] - 1e-12)                 # inf |q'_j|
        D = s1 - s0
        for j in range(3):
            f = lambda s, w: path.evaluate(s)[2][0, j] * w(s - s0) / 2   # noqa: E731
            i0, _ = quad(f, s0, s1, args=(lambda u: 1 - u / D,), epsabs=1e-15)
            i1, _ = quad(f, s0, s1, args=(lambda u: u / D,), epsabs=1e-15)
            assert abs(geo.I0[k, j] - i0) <= geo.ierr[k, j] + 1e-13
            assert abs(geo.I1[k, j] - i1) <= geo.ierr[k, j] + 1e-13
