"""Hand references and shared checks for the G645 tests (not a test module):
tests/reference/test_rounding_sbend.py (arcs curving opposite ways),
test_rounding_samedir.py (the same way) and test_rounding_g645.py (line-arc).

Frame: the junction at the origin, tangent +x, the first arc's centre (0, R1); the second
arc's centre (0, R2) when it curves the same way, (0, -R2) when it curves the other way
(``side`` = +1 / -1).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp


def integrate_curvature(knots, kappa, r1: float, trim_in: float, max_step: float):
    """The rounding by an ODE solver from its curvature profile alone: ``kappa`` linear
    in the arc length between ``knots`` (``np.interp``), started on the first arc
    ``trim_in`` before the junction with its tangent. Returns the dense solution and the
    length ``knots[-1]``, mm."""
    knots = np.asarray(knots, float)
    kappa = np.asarray(kappa, float)
    a0 = -trim_in / r1
    start = [r1 * math.sin(a0), r1 * (1 - math.cos(a0)), a0]
    sol = solve_ivp(lambda s, z: [math.cos(z[2]), math.sin(z[2]),
                                  float(np.interp(s, knots, kappa))],
                    (0.0, float(knots[-1])), start, rtol=1e-12, atol=1e-14,
                    dense_output=True, max_step=max_step)
    return sol, float(knots[-1])


def contour_distance(x, y, r1: float, r2: float, side: int):
    """Distance from the two programmed arcs near the junction: the first for x <= 0,
    the second (centre ``(0, side R2)``) for x >= 0; beyond an arc's end its nearest
    point is the junction."""
    j = np.hypot(x, y)
    d1 = np.where(x <= 0, np.abs(np.hypot(x, y - r1) - r1), j)
    d2 = np.where(x >= 0, np.abs(np.hypot(x, y - side * r2) - r2), j)
    return np.minimum(d1, d2)


def planned_under_g64_and_g645(mach, head: str, body: str) -> dict:
    """The heuristic's plan of ``head`` + ``body`` under G64 and under G645 (mode word
    ``{mode}`` in ``head``), each judged by check_profile under its own bound set:
    ``{"G64": (path, result), "G645": (path, result)}``."""
    from reference.core.constraints import BOUND_SETS, check_profile
    from reference.nc import parse_text
    from reference.planner import plan
    from reference.prepare import build_path

    out = {}
    for mode in ("G64", "G645"):
        prog = parse_text(head.format(mode=mode) + body)
        path = build_path(prog, mach)
        res = plan(prog, mach, path=path)
        rep = check_profile(path, mach.limits, res.profile)
        assert rep.ok(BOUND_SETS[res.bound_set]), rep
        out[mode] = (path, res)
    return out


def g645_keeps_limits_and_passes_faster_than_the_cap(mfile: str, body: str) -> None:
    """The heuristic on the program ``body`` (F5000, SOFT) under G64 and G645 on machine
    ``mfile``: both keep every limit of their bound set (check_profile); on the default
    machine the transition is rounded, the planned speed inside the rounding stays above
    G64's curvature-jump cap and the program is faster than under G64; on the LinuxCNC
    machine the jump is allowed at the programmed speed, which the trace names."""
    from reference.core.geometry import KIND_CODES
    from reference.machine import load_machine
    from test_rounding_g645 import reasons

    out = planned_under_g64_and_g645(load_machine(mfile), "G17 G90 {mode} SOFT F5000\n",
                                     body)
    path, res = out["G645"]
    t = path.rounding
    if mfile == "default":
        assert t.inserted.all()
        k = np.flatnonzero(path.kind == KIND_CODES.index("rounding"))
        s = np.linspace(path.s_breaks[k[0]], path.s_breaks[k[-1] + 1], 200)
        v = res.profile.state(res.profile.time_at(s))[1]
        assert v.min() > t.v_g64[0]
        assert res.profile.duration < out["G64"][1].profile.duration
    else:
        assert reasons(path) == ["G64 passes the curvature jump without reduction"]
