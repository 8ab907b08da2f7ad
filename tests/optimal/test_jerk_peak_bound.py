"""The per-segment peak-speed bound of the jerk oracle (:func:`optimal.jerk.lower.peak_times`)
against ruckig (Berscheid & Kroeger 2021), an independent exact 1-D solver.

The bound claims: every 1-D motion over ``L`` with speed at most ``vb0`` and acceleration
at most ``as0`` in size at its start (``vb1``, ``as1`` at its end), ``|v| <= V``,
``|a| <= A``, ``|j| <= J`` takes at least ``peak_times(...)``. ruckig's time-optimal move
between any boundary states inside those boxes is such a motion, so it can never be
faster; and rest-to-rest, or between boundary states that the optimum uses, the bound is
exact (the optimum is the two fastest rises and a cruise).
"""

from __future__ import annotations

import numpy as np
import pytest

from optimal.jerk import rest_to_rest_time
from optimal.jerk.lower import peak_times, rise

ruckig = pytest.importorskip("ruckig")

#: Relative slack of "bound <= ruckig": the bisections stop within 1e-12 of the answer
#: and ruckig's own times are exact to ~1e-12 relative.
BOUND_SLACK = 1e-9
#: Relative agreement where the bound is exact: its branch and bound resolves the peak
#: speed to 1e-7 of V, which moves the time by less than that.
EXACT_RTOL = 1e-6


def ruckig_move(L, v0, a0, v1, a1, V, A, J) -> float:
    """ruckig's minimum time between the two states, ``inf`` when no motion within the
    limits connects them (the state overshoots ``V`` whatever it does; ruckig raises or,
    from a start state, returns a move above ``V``)."""
    if v0 + max(a0, 0.0) ** 2 / (2 * J) > V or v1 + max(-a1, 0.0) ** 2 / (2 * J) > V:
        return np.inf
    otg = ruckig.Ruckig(1)
    inp = ruckig.InputParameter(1)
    traj = ruckig.Trajectory(1)
    inp.current_position, inp.target_position = [0.0], [L]
    inp.current_velocity, inp.target_velocity = [v0], [v1]
    inp.current_acceleration, inp.target_acceleration = [a0], [a1]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [V], [A], [J]
    try:
        res = otg.calculate(inp, traj)
    except ruckig.RuckigError as exc:
        if "will inevitably have reached a velocity" in str(exc):
            return np.inf
        raise
    assert res in (ruckig.Result.Working, ruckig.Result.Finished), res
    return traj.duration


def one(L, vb0, vb1, as0, as1, V, A, J, eps=0.0) -> float:
    arr = (lambda x: np.array([x], dtype=np.float64))
    return float(peak_times(arr(L), arr(vb0), arr(vb1), arr(as0), arr(as1), arr(V),
                            arr(A), arr(J), eps)[0])


def draws(rng, n):
    L = 10 ** rng.uniform(-2, 2.5, n)
    V, A, J = 10 ** rng.uniform(1, 3, n), 10 ** rng.uniform(2, 4, n), 10 ** rng.uniform(3, 6, n)
    return L, V, A, J


def test_rest_to_rest_is_the_closed_form():
    rng = np.random.default_rng(11)
    n = 200
    L, V, A, J = draws(rng, n)
    a_s = np.where(np.arange(n) % 2 == 1, np.minimum(A, J * 0.004), 0.0)
    zero = np.zeros(n)
    got = peak_times(L, zero, zero, a_s, a_s, V, A, J)
    for i in range(n):
        ref = ruckig_move(L[i], 0.0, a_s[i], 0.0, -a_s[i], V[i], A[i], J[i])
        assert got[i] <= ref * (1 + BOUND_SLACK)
        assert got[i] == pytest.approx(ref, rel=EXACT_RTOL)
        assert got[i] == pytest.approx(rest_to_rest_time(L[i], V[i], A[i], J[i], a_s[i]),
                                       rel=EXACT_RTOL)


def test_never_above_any_move_between_states_in_the_boxes():
    rng = np.random.default_rng(12)
    n = 400
    L, V, A, J = draws(rng, n)
    vb0, vb1 = V * rng.uniform(0, 1, n) ** 2, V * rng.uniform(0, 1, n) ** 2
    as0, as1 = A * rng.uniform(0, 1, n) ** 3, A * rng.uniform(0, 1, n) ** 3
    bound = peak_times(L, vb0, vb1, as0, as1, V, A, J)
    # draws where the optimum surely rises from the box corners to V, cruises and falls:
    # there the bound is exact
    _, d0 = rise(V, vb0, as0, A, J)
    _, d1 = rise(V, vb1, as1, A, J)
    cruise = d0 + d1 <= L
    n_exact = 0
    for i in range(n):
        # boundary states inside the boxes: the corners the optimum tends to use and
        # random ones
        states = [(vb0[i], as0[i], vb1[i], -as1[i]), (vb0[i], 0.0, vb1[i], 0.0)]
        states += [(vb0[i] * rng.uniform(), as0[i] * rng.uniform(-1, 1),
                    vb1[i] * rng.uniform(), as1[i] * rng.uniform(-1, 1)) for _ in range(3)]
        times = [ruckig_move(L[i], *st, V[i], A[i], J[i]) for st in states]
        assert bound[i] <= min(times) * (1 + BOUND_SLACK)
        if cruise[i] and np.isfinite(times[0]):
            assert bound[i] == pytest.approx(times[0], rel=EXACT_RTOL)
            n_exact += 1
    assert n_exact >= 50          # the exact case is exercised (82 of the 400 draws)


def test_acceleration_steps_inside_the_segment_only_loosen_it_by_their_size():
    L, V, A, J = 10.0, 50.0, 2000.0, 40000.0
    exact = one(L, 0.0, 1.6, 160.0, 160.0, V, A, J)
    eps = 1e-8 * J * 0.004
    with_eps = one(L, 0.0, 1.6, 160.0, 160.0, V, A, J, eps)
    assert with_eps <= exact
    assert with_eps == pytest.approx(exact, rel=1e-6)
    # a large step budget is a weaker bound, never a wrong one
    loose = one(L, 0.0, 1.6, 160.0, 160.0, V, A, J, 500.0)
    assert loose < with_eps
    ref = ruckig_move(L, 0.0, 160.0, 1.6, -160.0, V, A, J)
    assert loose <= ref
