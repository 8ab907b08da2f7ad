"""The jerk relaxation (:mod:`optimal.jerk.relaxation`) against motions it must admit.

A lower bound holds when every jerk-feasible motion is feasible for the relaxation. The
motions here come from elsewhere: the heuristic planner's SOFT profiles (an independent
planner, accepted by the checker under the ``jerk`` bound set) on the bundled examples
and corpus programs, and ruckig's time-optimal rest-to-rest moves on straight lines.
Each motion's node values (speed, the accelerations just after and just before every
node, the time per interval) are put into the relaxation's variables and every
equality, inequality and cone is evaluated; and the relaxation's bound is compared with
the motions' times.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import optimal
import reference
from oracle_cases import line_path
from optimal.bounds import lower_bound
from optimal.jerk.lower import grid_on, jerk_lower_bound
from optimal.jerk.relaxation import build_relaxation_problem, jerk_relaxation
from optimal.jerk.upper import profile_times_at
from reference.core import AxisLimits, MachineLimits, Profile
from reference.core.constraints import BOUND_SETS, check_profile
from reference.machine import load_machine
from shared_inputs import CORPUS, corpus_param

ROOT = Path(__file__).resolve().parents[2]
# the corpus lives beside the repository: without it those cases are skipped, saying so
PROGRAMS = [str(ROOT / p) for p in ("examples/demo.mpf", "examples/slot.ngc")] + [
    corpus_param(n, str(CORPUS / n))
    for n in ("lcnc_square.ngc", "sin_cead_arc.mpf", "lcnc_arc_arc_sawtooth.ngc",
              "lcnc_tangent_helix.ngc",
              # arcs whose end radius differs from the start: spirals (step 6 on them)
              "lcnc_sam_tolerance_issue.ngc")]

#: The time offset at which a motion's acceleration is read on each side of a node:
#: far below any interval, far above float resolution of the knot times.
SIDE_S = 1e-9


def _without_holds(prof: Profile) -> Profile:
    """The motion with its hold intervals (s constant, time passing) removed."""
    h = np.diff(prof.t)
    hold = (np.diff(prof.s) == 0) & (h > 0)
    if not np.any(hold):
        return prof
    keep = ~hold
    knots = np.concatenate(([True], keep))
    return Profile(t=np.concatenate(([0.0], np.cumsum(h[keep]))), s=prof.s[knots],
                   v=prof.v[knots], a=prof.a[keep], j=prof.j[keep], block=prof.block[keep])


def _node_values(prof: Profile, s: np.ndarray):
    """``(v^2, a just after, a just before, time per interval)`` of a motion at nodes."""
    tn = profile_times_at(prof, s)

    def at(t):
        k = np.clip(np.searchsorted(prof.t, t, side="right") - 1, 0, prof.n_intervals - 1)
        tau = t - prof.t[k]
        return (prof.v[k] + tau * (prof.a[k] + tau * prof.j[k] / 2),
                prof.a[k] + prof.j[k] * tau)

    v, _ = at(tn)
    _, a0 = at(tn[:-1] + SIDE_S)
    _, a1 = at(tn[1:] - SIDE_S)
    return v ** 2, a0, a1, np.diff(tn)


def _relaxation_inputs(path, limits, points=None):
    moving = path.moving_axes()
    work = path.restricted(moving) if 0 < moving.size < path.n_axes else path
    lim = limits.for_axes(work.axes)
    acc = optimal.solve(work, limits)
    grid = grid_on(work, acc.grid if points is None else points(work))
    _, t_acc, _, b_hat = lower_bound(work, lim, grid)
    _, a_seg, j_seg = jerk_lower_bound(work, lim, limits.t_ipo_s, acc.grid)
    return work, lim, grid, b_hat, t_acc, np.maximum(a_seg, j_seg)


@pytest.mark.parametrize("program", PROGRAMS, ids=lambda p: Path(p).name)
def test_every_row_holds_for_the_heuristic_soft_motion(program):
    """The heuristic's SOFT profile keeps the jerk bound set (checked here), so it must
    satisfy every row and cone of the relaxation on the oracle's grid."""
    machine = load_machine()
    prog = reference.parse_file(program)
    path = reference.build_path(prog, machine)
    plan = reference.plan(prog, machine, path=path)
    assert check_profile(path, machine.limits, plan.profile).ok(BOUND_SETS["jerk"])
    work, lim, grid, b_hat, t_acc, floor = _relaxation_inputs(path, machine.limits)
    prob = build_relaxation_problem(work, lim, machine.limits.t_ipo_s, grid, b_hat, t_acc,
                                    floor)
    motion = _without_holds(plan.profile)
    x = prob.point(*_node_values(motion, grid.s))
    viol = prob.violation(x)
    # equalities: acceleration continuity read SIDE_S before and after a node, so up to
    # J * 2 SIDE_S in scaled units (8e-8 on the default mill); rows and cones: round-off
    assert viol["equality"] <= 1e-7, viol
    assert viol["inequality"] <= 1e-9 and viol["cone"] <= 1e-9, viol
    # and so the bound is below the motion's time
    res = jerk_relaxation(work, lim, machine.limits.t_ipo_s, grid, b_hat, t_acc, floor)
    assert res.ok
    assert res.lower_bound_s <= motion.duration


def _ruckig_line(L, V, A, J, a_s=0.0):
    """ruckig's time-optimal straight move, starting and ending with acceleration
    ``a_s`` (the rulebook's one-cycle step at the path ends: the surroundings rest)."""
    ruckig = pytest.importorskip("ruckig")
    inp = ruckig.InputParameter(1)
    inp.current_position, inp.target_position = [0.0], [L]
    inp.current_acceleration, inp.target_acceleration = [a_s], [-a_s]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [V], [A], [J]
    traj = ruckig.Trajectory(1)
    assert ruckig.Ruckig(1).calculate(inp, traj) in (ruckig.Result.Working,
                                                     ruckig.Result.Finished)
    T = traj.duration
    t = np.linspace(0.0, T, 20001)
    pos = np.array([traj.at_time(x)[0][0] for x in t])
    vel = np.array([traj.at_time(x)[1][0] for x in t])
    acc = np.array([traj.at_time(x)[2][0] for x in t])
    return T, t, pos, vel, acc


@pytest.mark.parametrize("L", [0.5, 5.0, 60.0])
def test_ruckig_line_is_feasible_and_bounds_the_relaxation(L):
    """A straight rest-to-rest move at ruckig's optimum under the rulebook (the
    acceleration may step by ``J T_ipo`` at both path ends, where the outside rests):
    its node values satisfy every row (read off ruckig's own trajectory), and the
    relaxation's bound lies below its duration and within the relaxation's first-order
    discretisation of it."""
    V, A, J, t_ipo = 200.0, 1500.0, 30000.0, 0.004
    T, t, pos, vel, acc = _ruckig_line(L, V, A, J, a_s=J * t_ipo)
    lims = MachineLimits(tuple(AxisLimits(n, V * (1 if n == "X" else 10), A, J, 1.2)
                               for n in ("X", "Y", "Z")), t_ipo)
    path = line_path([[0.0, 0, 0], [L, 0, 0]])
    work, lim, grid, b_hat, t_acc, floor = _relaxation_inputs(path, lims)
    # the node values from ruckig's samples (acceleration continuous inside)
    tn = np.interp(grid.s, pos, t)
    an = np.interp(tn, t, acc)
    vn = np.interp(tn, t, vel)
    prob = build_relaxation_problem(work, lim, lims.t_ipo_s, grid, b_hat, t_acc, floor)
    x = prob.point(vn ** 2, an[:-1], an[1:], np.diff(tn))
    viol = prob.violation(x)
    # sampled at 20,001 points: interpolation error of the node values ~ (T / 2e4)^2 J
    assert viol["equality"] <= 1e-9 and viol["cone"] <= 1e-6, viol
    assert viol["inequality"] <= 1e-4, viol
    res = jerk_relaxation(work, lim, lims.t_ipo_s, grid, b_hat, t_acc, floor)
    assert res.ok
    assert res.lower_bound_s <= T * (1 + 1e-9)
    assert res.lower_bound_s >= 0.95 * T
