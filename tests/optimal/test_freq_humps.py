"""The whole-path frequency bound (optimal.freq.humps): its shortest path against an
independent enumeration, a closed form on a flat envelope, and soundness and strength on a
zig-zag against a hand-built motion that meets the rule (issue 12, item 2: a lower bound
with a written proof under the definition of DESIGN 6)."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

import optimal
from oracle_cases import XYZ, line_path
from optimal.freq.humps import Envelope, hump_lower_bound, hump_plan, humps_bound
from optimal.grid import grid_on
from reference.core import AxisLimits, MachineLimits
from reference.core.constraints import BOUND_SETS, check_profile
from reference.core.profile import Profile
from reference.core.tolerances import VEL_TOL_MM_S


def _enumerated(env: Envelope):
    """Step 3/4 of optimal.freq.humps by brute force: every alternating sequence of turn
    cells valley(0) < peak < valley < ... < valley(N-1), no cuts, written out directly.
    Returns the least time and the cost of any given sequence."""
    ds = np.diff(env.s)
    N = ds.size
    # the checker's standstill tolerance is added to every speed bound (step 2)
    hi, lo, g = env.hi + VEL_TOL_MM_S, env.lo + VEL_TOL_MM_S, env.period

    def stretch(a, b, rising):
        cells = range(a + 1, b)
        turn = b if rising else a          # the peak's cell
        t = 0.0
        for k in cells:
            between = range(k + 1, b) if rising else range(a + 1, k)
            ub = min([hi[k], hi[turn]] + [lo[m] for m in between])
            t += ds[k] / ub
        gm = min(g[a:b + 1])
        d = sum(ds[k] for k in cells)
        u = hi[a] if rising else hi[b]     # the valley's cell
        w = hi[turn]
        lt = min(d / u, (d - u * gm / 2) / w + gm / 2)
        return max(gm, t, lt if lt > 0 else 0.0)

    def cost(seq):
        return sum(stretch(a, b, i % 2 == 0) for i, (a, b) in enumerate(zip(seq, seq[1:])))

    best = math.inf
    inner = range(1, N - 1)
    for r in range(1, N - 1):
        for turns in itertools.combinations(inner, r):
            if r % 2 == 0:
                continue                    # valley, peak, ..., peak, valley: odd count
            seq = (0,) + turns + (N - 1,)
            if any(b <= a for a, b in zip(seq, seq[1:])):
                continue
            best = min(best, cost(seq))
    return best, cost


@pytest.mark.parametrize("seed", range(6))
def test_shortest_path_matches_enumeration(seed):
    """With cuts switched off the programme is the enumeration exactly; cuts only add
    paths (pieces of long stretches), so with them it is at most that."""
    rng = np.random.default_rng(seed)
    N = 9
    s = np.concatenate(([0.0], np.cumsum(rng.uniform(0.5, 3.0, N))))
    hi = rng.uniform(5.0, 60.0, N)
    lo = hi * rng.uniform(0.1, 1.0, N)
    env = Envelope(s=s, hi=hi, lo=lo, period=np.full(N, rng.uniform(0.01, 0.2)), accel=0.0)
    ref, cost = _enumerated(env)
    plan = hump_plan(env, chain=1e12)
    assert plan.time_s == pytest.approx(ref, rel=1e-12)
    # its way back is a valid sequence with that cost
    assert plan.valleys[0] == 0 and plan.valleys[-1] == N - 1
    assert plan.valleys.size == plan.peaks.size + 1
    seq = np.empty(plan.valleys.size + plan.peaks.size, np.int64)
    seq[0::2], seq[1::2] = plan.valleys, plan.peaks
    assert np.all(np.diff(seq) > 0)
    assert cost(tuple(seq)) == pytest.approx(ref, rel=1e-12)
    assert hump_lower_bound(env) <= ref * (1 + 1e-12)


@pytest.mark.parametrize("L, V, g", [(10.0, 20.0, 0.1), (1.0, 20.0, 0.1), (50.0, 5.0, 0.05)])
def test_flat_envelope_closed_form(L, V, g):
    """A flat envelope, cells of time ``tau = h / V`` with ``g / tau`` whole: ``n`` stretches
    (``n`` even) leave ``n + 1`` turn cells out and each lasts at least ``g``, so the bound
    is ``min_n max(n g, (N - n - 1) tau)`` (no lost time: a valley may be as fast as V).
    More stretches leave out more cells: this is the discretisation's own slack, one cell
    per turn, which HUMP_CELL_TIME_REL keeps small."""
    N = 400
    s = np.linspace(0.0, L, N + 1)
    # the programme adds the standstill tolerance to every speed bound: V in effect
    Ve = V - VEL_TOL_MM_S
    env = Envelope(s=s, hi=np.full(N, Ve), lo=np.full(N, Ve), period=np.full(N, g), accel=0.0)
    tau = L / N / V
    assert abs(g / tau - round(g / tau)) < 1e-9
    expected = min(max(n * g, (N - n - 1) * tau) for n in range(2, N - 1, 2))
    assert hump_lower_bound(env) == pytest.approx(expected, rel=1e-9)


def _zigzag(n=60, h=0.3, w=0.3):
    x = np.arange(n + 1) * h
    y = np.where(np.arange(n + 1) % 2 == 0, 0.0, w)
    return line_path(np.stack((x, y, np.zeros(n + 1)), axis=1), feed=200.0)


def test_zigzag_bound_is_sound_and_above_acc():
    """A zig-zag of 60 short moves, corners too close for a dip each under 10 Hz.

    Independent motion: a plateau at speed ``v_c`` with linear ramps of exactly 1/f at
    both ends (every phase 1/f long), ``v_c`` the largest speed the checker accepts for
    it (bisection). The bound is below its time, and well above the ``acc`` bound, which
    dips at every corner."""
    f = 10.0
    lim = MachineLimits(tuple(AxisLimits(n, 500.0, 2000.0, 1e6, 1.2, f) for n in XYZ), 0.004)
    path = _zigzag()
    L = path.total_length

    def hand(vc):
        ramp = vc / (2 * f)
        return Profile.from_path_velocity([0.0, ramp, L - ramp, L], [0.0, vc, vc, 0.0])

    lo_v, hi_v = 1e-3, 200.0
    for _ in range(50):
        mid = 0.5 * (lo_v + hi_v)
        if check_profile(path, lim, hand(mid)).ok(BOUND_SETS["acc+freq"]):
            lo_v = mid
        else:
            hi_v = mid
    t_hand = hand(lo_v).duration
    acc = optimal.solve(path, lim, bounds="acc")
    T = humps_bound(path, lim.for_axes(path.axes), grid_on(path, acc.grid), t_hand)
    assert T <= t_hand
    # measured: 8.3 s against 1.4 s (the hand motion: 22.6 s, the oracle's own 12.0 s)
    assert T > 4.0 * acc.lower_bound_s
    sol = optimal.solve(path, lim, bounds="acc+freq")
    assert sol.lower_bound_s >= T
    assert sol.lower_bound_s <= sol.upper_bound_s
