"""The reach envelope of the ``jerk`` set (optimal.jerk.lower step 7): speed caps out of
every break that the ``jerk+freq`` turn programme takes as node bounds.

Independent references:

* the closed form of the jerk ramp from rest (``v = J t^2 / 2``, ``s = J t^3 / 6`` up to
  ``a = A``, then constant ``A``): the cap from rest with no allowance is that ramp's
  speed at the distance, to round-off;
* ruckig's time-optimal straight move: its speed never exceeds the cap at its position,
  from either end;
* random jerk-limited motions integrated in closed form (piecewise-constant jerk, the
  acceleration held inside ``[-A, A]``), with start speeds and accelerations anywhere
  inside the break's bounds, including a dip before the rise: none exceeds the cap.
"""

from __future__ import annotations

import numpy as np
import pytest

from optimal.jerk.lower import (REACH_ROUNDOFF_REL, _reach_side, reach_distance,
                                reach_speed_caps, segment_envelope, speed_bounds)
from oracle_cases import line_path, ruckig_line_time

J, A = 40000.0, 2000.0
#: ruckig's speed at the end of its move is round-off (3.6e-14 mm/s) where the cap is 0.
RUCKIG_ROUNDOFF_MM_S = 1e-9


def ramp_speed_at(y: float) -> float:
    """Speed of the jerk ramp from rest with zero acceleration at distance ``y``, mm/s."""
    t1 = A / J
    s1, v1 = J * t1 ** 3 / 6, J * t1 ** 2 / 2
    if y <= s1:
        t = (6 * y / J) ** (1 / 3)
        return J * t * t / 2
    tau = (-v1 + np.sqrt(v1 * v1 + 2 * A * (y - s1))) / A
    return v1 + A * tau


def _caps(y, vb=0.0, a_s=0.0):
    y = np.atleast_1d(np.asarray(y, dtype=np.float64))
    n = y.size
    return _reach_side(y, np.full(n, vb), np.full(n, a_s), np.full(n, A), np.full(n, J),
                       0.0, 1.0)


def test_from_rest_the_cap_is_the_jerk_ramp():
    ys = np.array([1e-5, 1e-3, 0.05, 0.5, A ** 3 / (6 * J * J), 1.0, 10.0, 300.0])
    ref = np.array([ramp_speed_at(y) for y in ys])
    caps = _caps(ys)
    assert np.all(caps >= ref)
    np.testing.assert_allclose(caps, ref, rtol=REACH_ROUNDOFF_REL + 1e-12)


def test_distance_is_the_acc_one_where_the_jerk_does_not_bind():
    # with the acceleration available at once (alpha >= A^2) D is (p^2 - vb^2) / 2A
    p, vb = np.array([10.0, 100.0, 1000.0]), np.array([1.0, 5.0, 50.0])
    d = reach_distance(p, vb, np.full(3, A * A), np.full(3, A), np.full(3, J))
    np.testing.assert_allclose(d, (p * p - vb * vb) / (2 * A), rtol=1e-12)


@pytest.mark.parametrize("vb,a_s", [(0.0, 0.0), (0.0, 300.0), (5.0, 0.0), (20.0, 800.0)])
def test_random_jerk_limited_motions_stay_below(vb, a_s):
    rng = np.random.default_rng(7)
    pos, speed = [], []
    for _ in range(200):
        s, v = 0.0, rng.uniform(0.0, vb)
        a = rng.uniform(-a_s, a_s) if v > 0 else rng.uniform(0.0, a_s)
        for _ in range(60):
            j = rng.choice([-J, 0.0, J, rng.uniform(-J, J)])
            h = rng.uniform(1e-4, 0.02)
            # hold the acceleration inside [-A, A]: end the piece where it gets there
            if j > 0:
                h = min(h, (A - a) / j)
            elif j < 0:
                h = min(h, (-A - a) / j)
            tau = np.linspace(0.0, h, 9)[1:]
            vv = v + a * tau + j * tau ** 2 / 2
            # the bound is for forward motion: v >= 0 over the whole piece (its least
            # value is at an end or where the acceleration a + j tau is zero)
            t_star = -a / j if j != 0 else -1.0
            v_min = min(vv[-1], v + a * t_star + j * t_star ** 2 / 2
                        if 0.0 < t_star < h else np.inf)
            if v_min < 0:
                continue
            ss = s + v * tau + a * tau ** 2 / 2 + j * tau ** 3 / 6
            pos.append(ss)
            speed.append(vv)
            s, v, a = ss[-1], vv[-1], a + j * h
    pos, speed = np.concatenate(pos), np.concatenate(speed)
    caps = _caps(pos, vb, a_s)
    bad = speed > caps
    assert not np.any(bad), (pos[bad][:5], speed[bad][:5], caps[bad][:5])
    assert np.max(speed / np.maximum(caps, 1e-300)) > 0.5   # near it: not a vacuous cap


def test_ruckig_moves_stay_below_the_caps_of_a_line():
    """A straight rest-to-rest move (the default machine's X, Y, Z as on the bundled
    machine): ruckig's time-optimal motion under the same V, A, J and the start
    allowance of the path end never exceeds the caps out of either end."""
    ruckig = pytest.importorskip("ruckig")
    from reference.machine import load_machine
    m = load_machine()
    path = line_path([[0.0, 0.0, 0.0], [60.0, 0.0, 0.0]], feed=500.0)
    lim = m.limits.for_axes(path.axes)
    t_ipo = m.limits.t_ipo_s
    _, b_break, b_seg = speed_bounds(path, lim, t_ipo, np.linspace(0, 60.0, 121))
    env = segment_envelope(path, lim, t_ipo, b_break, b_seg)
    V, Ap, Jp = 500.0, float(env.A[0]), float(env.J[0])
    a_s = float(env.a_out[0])
    otg = ruckig.Ruckig(1)
    inp = ruckig.InputParameter(1)
    traj = ruckig.Trajectory(1)
    inp.current_position, inp.target_position = [0.0], [60.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [V], [Ap], [Jp]
    inp.current_acceleration, inp.target_acceleration = [a_s], [-a_s]
    otg.calculate(inp, traj)
    t = np.linspace(0.0, traj.duration, 2001)
    pos, vel = [], []
    for tk in t:
        p, v, _ = traj.at_time(tk)
        pos.append(p[0])
        vel.append(v[0])
    pos, vel = np.clip(np.array(pos), 0.0, 60.0), np.array(vel)
    caps = reach_speed_caps(path, env, pos, traj.duration)
    assert np.all(vel <= caps + RUCKIG_ROUNDOFF_MM_S)
    # it binds: ruckig's rise out of rest comes within 1 % of the cap somewhere early
    early = (pos > 0.0) & (pos < 2.0)
    assert np.max(vel[early] / caps[early]) > 0.99
    assert ruckig_line_time(60.0, V, Ap, Jp, a_s) == pytest.approx(traj.duration)


def test_fast_break_and_short_distance_keep_the_acc_reach():
    """A break passed at speed with the whole acceleration available at once (``a_s = A``):
    the cap is the ``acc`` reach ``sqrt(vb^2 + 2 A y)``, to round-off, even a micrometre
    from the break at 1 m/s (the distance is not lost to cancellation)."""
    vb = 1000.0
    ys = np.array([1e-9, 1e-6, 1e-3, 1.0])
    caps = _caps(ys, vb, A)
    ref = np.sqrt(vb * vb + 2 * A * ys)
    assert np.all(caps >= ref)
    np.testing.assert_allclose(caps, ref, rtol=REACH_ROUNDOFF_REL + 1e-12)


@pytest.mark.parametrize("L", [5.0, 30.0, 200.0])
def test_turn_programme_with_the_caps_stays_below_ruckig_on_a_line(L):
    """The ``jerk+freq`` turn programme with the reach caps (the oracle's grid and caps)
    on a rest-to-rest line of the default machine's X: never above ruckig's time-optimal
    move with the path ends' allowance (its two phases last far more than ``1/f``, so it
    is a motion of the set: an upper reference), and well above the programme on the
    ``acc`` envelope alone (the caps bind)."""
    pytest.importorskip("ruckig")
    import optimal
    from optimal.freq.humps import humps_piece_bounds
    from optimal.freq.oracle import _reach_grid
    from optimal.grid import grid_on
    from reference.machine import load_machine
    m = load_machine()
    path = line_path([[0.0, 0.0, 0.0], [L, 0.0, 0.0]], feed=1000.0)
    work = path.restricted(path.moving_axes())
    lim = m.limits.for_axes(work.axes)
    t_ipo = m.limits.t_ipo_s
    acc = optimal.solve(path, m.limits, bounds="acc")
    _, b_break, b_seg = speed_bounds(work, lim, t_ipo, np.asarray(acc.grid))
    env = segment_envelope(work, lim, t_ipo, b_break, b_seg)
    t_ref = ruckig_line_time(L, float(env.V[0]), float(env.A[0]), float(env.J[0]),
                             float(env.a_out[0]))
    plain = humps_piece_bounds(work, lim, grid_on(work, acc.grid), t_ref).sum()
    grid, caps = _reach_grid(work, lim, t_ipo, acc.grid, t_ref)
    capped = humps_piece_bounds(work, lim, grid, t_ref, node_caps=caps).sum()
    assert capped <= t_ref
    assert capped >= plain + 0.02 * t_ref
