"""The capped acc optimum (optimal.freq.capped): closed forms on lines, and on arcs the
axis accelerations and the phases judged from sampled motion (independent of the
checker)."""

from __future__ import annotations

import numpy as np
import pytest

from oracle_cases import line_path

import optimal
from optimal.freq.capped import capped_optimum
from reference.core import AxisLimits, MachineLimits
from reference.core.constraints import BOUND_SETS, check_profile
from reference.machine import load_machine
from reference.nc import parse_text
from reference.prepare import build_path


def _xyz(v=500.0, a=2000.0, f=10.0):
    return MachineLimits(tuple(AxisLimits(n, v, a, 1e6, 1.2, f) for n in "XYZ"), 0.004)


def _capped(path, lim):
    acc = optimal.solve(path, lim, "acc")
    return acc, capped_optimum(path, lim, acc.profile)


@pytest.mark.parametrize("L, F, a, f, expected", [
    # DESIGN 6: v/A < 1/f -> L/v + 1/f
    (100.0, 100.0, 2000.0, 10.0, 100.0 / 100.0 + 0.1),
    (40.0, 250.0, 3000.0, 15.0, 40.0 / 250.0 + 1.0 / 15.0),
    # v/A > 1/f: the acc optimum (the trapezoid L/v + v/A) passes as it is
    (100.0, 100.0, 200.0, 10.0, 100.0 / 100.0 + 100.0 / 200.0),
    # too short to reach v: two ramps of exactly 1/f (peak L f)
    (1.0, 100.0, 2000.0, 10.0, 0.2),
])
def test_capped_optimum_closed_forms_on_single_lines(L, F, a, f, expected):
    """Rest-to-rest lines: the closed forms of the fastest ``acc+freq`` motion, to the
    acc optimum's own grid (its knots are where the capped motion may bend: the ramp's
    end falls inside an interval, whose acceleration is then lower), and the checker
    accepts the motion as built."""
    path = line_path([[0, 0, 0], [L, 0, 0]], feed=F, stops=("start", "end"))
    lim = _xyz(a=a, f=f)
    acc, prof = _capped(path, lim)
    assert prof is not None
    # never faster than the closed form (which is the optimum), and within the grid's
    # resolution of it: the interval holding the ramp's end lasts at most h / v longer
    h = float(np.max(np.diff(acc.profile.s)))
    assert expected * (1 - 1e-9) <= prof.duration <= expected + 2.0 * h / F + 1e-9
    assert check_profile(path, lim, prof).ok(BOUND_SETS["acc+freq"])


def _sawtooth(n_arcs: int, r_in: float = 0.2) -> str:
    """Arcs of radius ``r_in`` inches alternating G2/G3 between cusps (as the corpus'
    lcnc_arc_arc_sawtooth), F1000 in/min."""
    lines = ["G90 G20 G64 F1000", "G0 X0 Y0 Z0", "G2 X0 Y0.1 R0.2"]
    for k in range(n_arcs):
        x = 0.1 * (k + 1)
        lines.append(f"{'G3' if k % 2 == 0 else 'G2'} X{x:.1f} Y{-0.1 if k % 2 == 0 else 0.1}"
                     f" R{r_in}")
    return "\n".join(lines) + "\nM2\n"


def _sampled_phases(prof, dt):
    """Acceleration phases judged from the motion sampled every ``dt`` (independent of
    reference.core.phases): runs of one sign of the second differences of ``s(t)`` above
    1e-3 of their largest, each with ``D_eff = 2 min(t_c - t_0, t_1 - t_c)``."""
    t = np.arange(0.0, prof.duration, dt)
    s = prof.state(t)[0]
    acc = np.diff(s, 2) / dt ** 2
    tm = t[1:-1]
    sign = np.where(np.abs(acc) > 1e-3 * np.max(np.abs(acc)), np.sign(acc), 0)
    cut = np.flatnonzero(np.diff(sign) != 0) + 1
    out = []
    for run_t, run_a, run_s in zip(np.split(tm, cut), np.split(acc, cut),
                                   np.split(sign, cut)):
        if run_s[0] == 0 or run_t.size < 3:
            continue
        w = np.abs(run_a)
        tc = float(np.sum(run_t * w) / np.sum(w))
        t0, t1 = run_t[0] - dt / 2, run_t[-1] + dt / 2
        out.append(2.0 * min(tc - t0, t1 - tc))
    return np.array(out)


def test_capped_optimum_on_sawtooth_arcs_keeps_the_axes_and_the_rule():
    """Eight arcs of R 5.08 mm between cusps at 1 mm/s on the default machine (20 Hz on X
    and Y): the rises and falls keep their rate while the axes allow it, then follow
    the axes' budget. Judged from sampled axis positions, not by the checker: every axis
    acceleration (second differences) within its limit, every phase at least 1/f;
    and it is faster than the ramp plan, whose constant per arc is taken at its top
    speed."""
    from optimal.freq.ramps import ramp_plan

    m = load_machine()
    path = build_path(parse_text(_sawtooth(8), "saw.ngc", dialect="ngc"), m)
    lim = m.limits
    acc, prof = _capped(path, lim)
    assert prof is not None
    dt = 2e-5
    t = np.arange(0.0, prof.duration, dt)
    s = prof.state(t)[0]
    q = path.evaluate(s)[0]
    a_all = np.abs(np.diff(q, 2, axis=0)) / dt ** 2
    # the cusps are velocity steps the junction rule allows (one IPO cycle): differences
    # touching a sample within 1 um of one are left out
    near = np.min(np.abs(s[:, None] - path.s_breaks[None, 1:-1]), axis=1) <= 1e-3
    near = np.convolve(near, np.ones(3), "valid") > 0
    a_axes = np.max(a_all[~near], axis=0)
    sub = lim.for_axes(path.axes)
    moving = np.ptp(q, axis=0) > 0
    assert np.count_nonzero(near) < 0.05 * near.size      # the cusps alone
    assert np.all(a_axes[moving] <= sub.a_max[moving] * (1 + 2e-3))
    d_eff = _sampled_phases(prof, 1e-4)
    assert d_eff.size >= 2 * 8
    f = float(np.min(sub.frequency_hz[moving]))
    assert np.min(d_eff) >= (1.0 / f) * (1 - 1e-2)
    # the checker agrees, as built
    assert check_profile(path, lim, prof).ok(BOUND_SETS["acc+freq"])
    plan = ramp_plan(path, lim)
    assert sum(p.duration for p in plan.values()) > 1.05 * prof.duration
    assert prof.duration > acc.profile.duration


def test_growing_rates_are_faster_on_sawtooth_arcs_and_keep_every_arc_no_slower(
        monkeypatch):
    """The rates growing from each valley (CAPPED_GROWTH) against the constant rate
    alone on the same eight arcs: every arc no slower (each hump takes the faster shape
    that passes), the whole faster, and the motion still within the axes and the rule by
    sampled positions (the checks of the test above)."""
    import optimal.freq.capped as capped

    m = load_machine()
    path = build_path(parse_text(_sawtooth(8), "saw.ngc", dialect="ngc"), m)
    lim = m.limits
    acc, prof = _capped(path, lim)
    monkeypatch.setattr(capped, "CAPPED_GROWTH", (0.0,))
    flat = capped.capped_optimum(path, lim, acc.profile)
    assert prof is not None and flat is not None
    sb = path.s_breaks
    t_arc = np.diff(np.interp(sb, prof.s, prof.t))
    t_flat = np.diff(np.interp(sb, flat.s, flat.t))
    assert np.all(t_arc <= t_flat * (1 + 1e-12))
    # measured 0.11003 -> 0.10978 s on the inner arcs, 0.9814 -> 0.9791 s in all (0.23 %)
    assert prof.duration < flat.duration * (1 - 1e-3)
    dt = 1e-4
    d_eff = _sampled_phases(prof, dt)
    sub = lim.for_axes(path.axes)
    assert np.min(d_eff) >= (1.0 / float(np.min(sub.frequency_hz[:2]))) * (1 - 1e-2)
