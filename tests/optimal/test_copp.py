"""The jerk oracle against copp (TOPP3-SOCP, the ``copp-py`` package), issue 11 item 4.

copp is an independent jerk-limited TOPP solver (Wang et al., IJMTM 215, 2026): a
sequence of SOCPs in the node profile ``(s'^2, s'')``, its jerk rows linearised around
the last round. It returns a KKT point of its own discretisation, not a bound: its limits
hold at the nodes only. So its time is a number with an error, and the error is measured
here, never guessed: the same path at ``N`` and ``2N`` base nodes; copp converges from
above at first order (measured exponent 1.03-1.1 on the paths below, 250 to 4,000 nodes),
so ``e = |T_N - T_2N|`` estimates the error of ``T_2N`` and :data:`COPP_ERR_FACTOR`
times it bounds it with room for an exponent down to 0.58.

The wrapper (``copp_cases.py``) and what it models:

* rest to rest without the rulebook's end steps (copp cannot take an acceleration step
  at rest), so on the default machine copp solves a *restriction* (slower by the end
  steps, 7.6 ms on a line) and only ``UB <= copp`` and ``LB <= copp`` are asked there;
* at curvature jumps the rulebook's step: the centripetal part capped by
  :func:`reference.core.rules.curvature_jump_speed_cap`, the tangential part held by
  jerk rows over one IPO cycle at the cap speed. Exact where the break is crossed at the
  cap and the tangent and the curvature jump lie on different axes (every break here).

For a sharp comparison the same paths are solved on the default machine with the IPO
cycle shortened 1000-fold and PATH_TRANS_JERK_LIM raised 1000-fold (:func:`no_end_steps`):
the break allowance ``PATH_TRANS_JERK_LIM T_ipo`` is unchanged (copp's problem does not
change at all), the end steps ``J T_ipo`` shrink to 0.16 mm/s^2. There the oracle and
copp solve the same problem, and both bounds are held against copp's time.

References: ruckig (Berscheid & Kroeger 2021) for straight lines, which validates the
wrapper on its own; the hand value ``sqrt(PATH_TRANS_JERK_LIM T_ipo R)`` of the speed at
a line/arc joint.

Measured when this was written (copp 0.2.3; the oracle at 300 initial intervals, about
600 points; copp's limit extrapolated from 250-4,000 nodes, first order):

============= ============= ============= ============= ============= ==================
path          copp 500 /    copp limit    oracle LB     oracle UB     oracle UB, no end
              1000 nodes, s (extrapol.)   (default)     (default)     steps
============= ============= ============= ============= ============= ==================
stadium       1.72981 /     1.72466       1.55772       1.71903       1.72662
              1.72712
S-bends       1.64383 /     1.63551       1.40133       1.62982       1.63744
              1.63951
line into arc 0.68669 /     0.68615       0.59522       0.67868       0.68630
              0.68642
============= ============= ============= ============= ============= ==================

The lower bound is 10-15 % below copp (the jerk lower bound on curved paths is still the
acc relaxation's); the upper bound without end steps is 0.02-0.12 % above copp's
extrapolated limit at about 600 points, inside copp's error at 1,000 nodes.

Machines: the default (SOFT, jerk-limited). ``linuxcnc_xyz.toml`` has an effectively
unbounded jerk, where copp's nodal model is no reference (the wrapper refuses it; see
the last test).
"""

from __future__ import annotations

from dataclasses import replace
from functools import lru_cache
from pathlib import Path as FsPath

import numpy as np
import pytest

import optimal
from reference.core import MachineLimits
from reference.machine import load_machine

pytest.importorskip("copp_py")
ruckig = pytest.importorskip("ruckig")

from copp_cases import (BREAK_PAIR, line_into_arc, s_bends, solve_copp,  # noqa: E402
                        stadium)
from oracle_cases import line_path, ruckig_line_time  # noqa: E402

pytestmark = pytest.mark.xdist_group("copp")

MACHINES = FsPath(__file__).resolve().parents[2] / "reference" / "machines"

#: copp's error estimate ``|T_N - T_2N|`` times this bounds the error of ``T_2N`` for any
#: monotone convergence of order >= log2(1.5) = 0.58 (measured: 1.03-1.1).
COPP_ERR_FACTOR = 2.0
#: Base node counts of copp on the curved paths (error estimate from N and 2N): 500 and
#: 1,000 nodes take about 1 and 2 s, with an estimated error of 0.15-0.3 %.
N_CURVED = 500
#: ... and on single lines (errors of 1e-5 relative at 250 nodes).
N_LINE = 250
#: Largest error estimate accepted on a line, relative (see the test).
LINE_ERR_REL = 2e-3
#: Initial NLP intervals of the oracle here (the issue's default is 1,000; 300 keeps the
#: test fast, and the upper bound is 0.07-0.1 % higher than at 1,000).
N_ORACLE = 300
#: Requested gap of the oracle (the issue's default for jerk).
TOL = 1e-2
#: Shrink factor of the IPO cycle in :func:`no_end_steps`.
END_STEP_SHRINK = 1e-3
#: Relative margin on a speed cap that copp meets as a first-order row (Clarabel's
#: feasibility tolerance is 1e-8 in the scaled problem).
CAP_RTOL = 1e-6


def default_limits() -> MachineLimits:
    return load_machine().limits


def no_end_steps(limits: MachineLimits) -> MachineLimits:
    """The machine with ``T_ipo`` times :data:`END_STEP_SHRINK` and PATH_TRANS_JERK_LIM
    divided by it: the step allowance at curvature jumps is unchanged, the end steps
    ``J T_ipo`` (and steps at breaks without a curvature jump) all but vanish."""
    axes = tuple(replace(a, path_trans_jerk=a.path_trans_jerk / END_STEP_SHRINK)
                 for a in limits.axes)
    return MachineLimits(axes, limits.t_ipo_s * END_STEP_SHRINK, limits.name)


PATHS = {"stadium": stadium, "s_bends": s_bends, "line_into_arc": line_into_arc}


@lru_cache(maxsize=None)
def copp_time(name: str, n: int) -> tuple[float, float]:
    """copp's time at ``2n`` base nodes and its error bound (module docstring), s."""
    lim = default_limits()
    t1 = solve_copp(PATHS[name](), lim, n).time_s
    t2 = solve_copp(PATHS[name](), lim, 2 * n).time_s
    return t2, COPP_ERR_FACTOR * abs(t1 - t2)


@lru_cache(maxsize=None)
def oracle(name: str, end_steps: bool):
    lim = default_limits() if end_steps else no_end_steps(default_limits())
    return optimal.solve(PATHS[name](), lim, bounds="jerk", tol=TOL,
                         initial_intervals=N_ORACLE)


# ------------------------------------------------------------ the wrapper, independently
@pytest.mark.parametrize("end", [[100.0, 0, 0], [60.0, 30.0, 20.0], [2.0, 0, 0]],
                         ids=["x100", "diagonal", "short2"])
def test_copp_on_a_line_matches_ruckig(end):
    """A straight rest-to-rest move is ruckig's 1-D move with the path limits
    ``min_i X_i / |t_i|`` (formulation note 2.2). Covers the scaling, three moving axes
    with their own limits (on the diagonal X binds all three path limits) and the ramp
    node when the ramp ends at ``A`` (100 mm) and when the move is too short to reach
    ``A`` or ``V`` (2 mm)."""
    lim = default_limits()
    p = line_path([[0.0, 0.0, 0.0], end])
    t = np.abs(np.asarray(end, float)) / np.linalg.norm(end)
    a = lim.for_axes(p.axes)
    on = t > 0
    exact = ruckig_line_time(float(np.linalg.norm(end)), float(np.min(a.v_max[on] / t[on])),
                        float(np.min(a.a_max[on] / t[on])), float(np.min(a.j_max[on] / t[on])))
    t1 = solve_copp(p, lim, N_LINE).time_s
    r2 = solve_copp(p, lim, 2 * N_LINE)
    err = COPP_ERR_FACTOR * abs(t1 - r2.time_s)
    assert abs(r2.time_s - exact) <= err, (r2.time_s, exact, err)
    # the estimate means something: measured 1.9e-5 of the time on 100 mm, 1.2e-3 on
    # 2 mm (no phase at constant acceleration, where copp's c = s'''/s' is exact)
    assert err <= LINE_ERR_REL * exact


def test_without_the_ramp_node_copp_underuses_the_jerk_near_rest():
    """The issue's pitfall, kept visible: without a node at the end of the first jerk
    ramp copp is measurably slow on a line (the intervals after its stationary one
    have ``s'''`` proportional to ``s'``), and the finer grid does not help."""
    lim = default_limits()
    p = line_path([[0.0, 0.0, 0.0], [100.0, 0.0, 0.0]])
    exact = ruckig_line_time(100.0, 500.0, 2000.0, 40000.0)
    with_node = solve_copp(p, lim, 2 * N_LINE).time_s
    without = solve_copp(p, lim, 2 * N_LINE, ramp_nodes=False).time_s
    assert with_node - exact < 1e-4 * exact
    assert without - exact > 2e-3 * exact


def test_linearisation_rounds_never_get_slower_and_hold_at_the_nodes():
    """Each TOPP3 round is feasible at the nodes (the tangent of ``J/sqrt(a)`` lies
    below it) and contains the last round's profile, so times never increase and copp's
    own audit of the nonlinear rows is clean."""
    r = solve_copp(stadium(), default_limits(), N_CURVED)
    rounds = np.asarray(r.round_times_s[1:])
    assert r.rounds >= 2
    assert np.all(np.diff(rounds) <= 1e-9 * rounds[0])
    assert max(r.exceed) <= 1e-8


def test_curvature_jump_speed_is_the_rulebook_cap():
    """At a line/arc joint the axis acceleration steps by ``v^2 / R`` on the normal
    axis; the rulebook holds it to ``PATH_TRANS_JERK_LIM T_ipo``, so ``v <= sqrt(PTJ
    T_ipo R)`` = 63.25 mm/s for R = 25 mm on the default machine (hand value). copp
    meets it at both nodes of the break, and it binds (copp does not stop there)."""
    lim = default_limits()
    R = 25.0
    v_hand = np.sqrt(40000.0 * 0.004 * R)
    r = solve_copp(line_into_arc(R=R), lim, N_CURVED)
    at = np.abs(r.s - 60.0) < 1e-3
    assert at.sum() == 4
    assert np.all(r.v[at] <= v_hand * (1 + CAP_RTOL))
    assert np.all(r.v[at] >= v_hand * (1 - 1e-3))


def test_step_treatment_is_faster_than_a_continuous_acceleration():
    """With the jerk rows across the break kept (``"pair"``) copp allows no tangential
    acceleration step there; the rulebook's step (default ``"step"``) is worth time."""
    lim = default_limits()
    step = solve_copp(stadium(), lim, N_CURVED).time_s
    pair = solve_copp(stadium(), lim, N_CURVED, breaks=BREAK_PAIR).time_s
    assert step < pair


# ------------------------------------------------------------ the oracle against copp
@pytest.mark.parametrize("name", list(PATHS))
def test_bounds_at_most_copp_on_the_default_machine(name):
    """Issue 11 item 4: UB <= copp and LB <= copp (plus copp's error). copp takes no end
    steps here, so it is slower than the rulebook's optimum and this is the weaker of the
    two comparisons (see :func:`test_bounds_against_copp_without_end_steps`)."""
    t_copp, err = copp_time(name, N_CURVED)
    sol = oracle(name, True)
    assert sol.lower_bound_s <= t_copp + err, (sol.lower_bound_s, t_copp, err)
    assert sol.upper_bound_s <= t_copp + err, (sol.upper_bound_s, t_copp, err)


@pytest.mark.parametrize("name", list(PATHS))
def test_bounds_against_copp_without_end_steps(name):
    """The same problem on both sides (module docstring): the oracle's upper bound is
    not above copp's time (plus its error), and its lower bound is not above it either."""
    t_copp, err = copp_time(name, N_CURVED)
    sol = oracle(name, False)
    assert sol.lower_bound_s <= t_copp + err, (sol.lower_bound_s, t_copp, err)
    assert sol.upper_bound_s <= t_copp + err, (sol.upper_bound_s, t_copp, err)


def test_unsupported_paths_are_named():
    """A corner or a stop inside the path has no form in copp's rows: a clear error."""
    corner = line_path([[0, 0, 0], [10, 0, 0], [10, 10, 0]])
    with pytest.raises(ValueError, match="corner at break 1"):
        solve_copp(corner, default_limits(), 50)
    stop = line_path([[0, 0, 0], [10, 0, 0], [20, 0, 0]], stops=("", "G9", ""))
    with pytest.raises(ValueError, match="stop inside the path at break 1"):
        solve_copp(stop, default_limits(), 50)


def test_a_machine_whose_jerk_never_binds_between_nodes_is_refused():
    """On ``linuxcnc_xyz.toml`` (MAX_AX_JERK 1000 m/s^3) the first jerk ramp is 7e-5 mm
    long: copp's nodal rows no longer hold its profile between the nodes (measured: 2 %
    below ruckig's exact time, no convergence over node counts; ``copp_cases``
    docstring), so the wrapper says so instead of returning a number."""
    lim = load_machine(MACHINES / "linuxcnc_xyz.toml").limits
    p = line_path([[0.0, 0.0, 0.0], [100.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match="end jerk ramp"):
        solve_copp(p, lim, N_LINE)
