"""Rounding never slows a program down (issue 13 item 3, spec 4.3 and 5.2 group 2).

spec 4.3: "A transition is rounded only if it cannot be passed at G64 speed without a
reduction. Rounding would otherwise lengthen the program." spec 5.2 group 2: no rounding
block where "rounding would slow the program down". The issue: "a G642 contour is faster
than the same contour under G64". The rounding stage decides per corner by an estimate
(:func:`reference.rounding.corner_time_loss`); the heuristic then plans the contour. The
reference here is the heuristic's own plan of the same program under G64: on seeded
CAM-like polylines and on the corpus programs that have corners, converted to SINUMERIK
syntax, on every bundled machine, under BRISK and SOFT, the rounded program is never
slower, and strictly faster wherever a corner was rounded.

Also: the estimate by hand, and the SOFT planning units, which must not impose a short
curved segment's dynamics on the lines beside it (the cause of a G642 program planned
50 % slower than under G64 before).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from corpus_sinumerik import corpus_in_mode
from seeded_programs import polyline
from reference.core.geometry import KIND_CODES
from reference.machine import load_machine
from reference.nc import parse_text
from reference.planner import plan
from reference.prepare import build_path
from reference.rounding import corner_time_loss

MACHINES = ("default", "linuxcnc_xyz")
ROUNDING = KIND_CODES.index("rounding")


def n_rounded(res) -> int:
    tab = res.path.rounding
    return int(tab.inserted.sum()) if tab is not None else 0


def assert_not_slower(text_64: str, text: str, machine, what: str) -> int:
    """Plan both programs; the rounded one is not slower (strictly faster if it rounds
    at all), both keep their limits. Returns the number of roundings."""
    r64 = plan(parse_text(text_64, "t.mpf"), machine)
    r = plan(parse_text(text, "t.mpf"), machine)
    assert r64.ok and r.ok, what
    k = n_rounded(r)
    if k:
        assert r.time_s < r64.time_s, (what, k, r.time_s, r64.time_s)
    else:
        assert r.time_s == pytest.approx(r64.time_s, rel=1e-12), what
    return k


# ------------------------------------------------------------------ whole programs
@pytest.mark.parametrize("name", MACHINES)
@pytest.mark.parametrize("accel", ("BRISK", "SOFT"))
@pytest.mark.parametrize("seed", (13, 7))
def test_rounded_polyline_is_not_slower_than_g64(name, accel, seed):
    """The benchmark's CAM-like polyline (600 blocks, two seeds) under G641, G642, G644
    and G645 against G64, on each bundled machine, BRISK and SOFT. (Not G643: it rounds
    whatever G64 would cost, spec 4.3 and 5.8, :func:`test_g643_rounds_every_corner_of_
    the_polyline`.)"""
    body = polyline(600, seed)
    m = load_machine(name)
    head = f"G90 {{}} {accel} F6000\nG1 X0 Y0\nG1 "
    total = 0
    for mode in ("G641 ADIS=0.2", "G642", "G642 CTOL=0.02", "G645 CTOL=0.02", "G644"):
        total += assert_not_slower(head.format("G64") + body, head.format(mode) + body, m,
                                   f"{name} {accel} {mode}")
    assert total > 0                        # the case rounds somewhere


@pytest.mark.parametrize("name", MACHINES)
def test_g643_rounds_every_corner_of_the_polyline(name):
    """spec 4.3: "G643 ignores the overload factor"; 5.8: "Insert the rounding only if
    v_corner_G64 < min(F, v_round), unless MD20490 = TRUE or the mode is G643". On the
    polyline (turns of 5..120 degrees, blocks of 0.5..5 mm, none crossed in one IPO
    cycle at F6000) every corner is rounded, and the plan keeps
    its limits, whatever it costs against G64."""
    m = load_machine(name)
    r = plan(parse_text("G90 G643 F6000\nG1 X0 Y0\nG1 " + polyline(600, 13), "t.mpf"), m)
    tab = r.path.rounding
    assert r.ok and tab.n == 599 and tab.inserted.all()


#: Corpus programs with corners that the SINUMERIK parser reads once converted (the
#: others use G10 L2, G80 or axes the bundled machines lack).
CORPUS = ("lcnc_corner_decel.ngc", "lcnc_naive_cam_corner1.ngc", "lcnc_square.ngc",
          "lcnc_test_12mmflat.ngc", "lcnc_arc_arc_sawtooth.ngc", "lcnc_tangent_helix.ngc",
          "lcnc_short_segments_0.001.ngc", "sin_cead_loop.mpf", "sin_cead_arc.mpf")


@pytest.mark.parametrize("program", CORPUS)
def test_rounded_corpus_program_is_not_slower_than_g64(program):
    """Each corpus program under G641/G642/G645 (with and without CTOL) against itself
    under G64, on each bundled machine, with the machine's acceleration mode, BRISK and
    SOFT. (G643 and G644 skip the overload check by definition, spec 4.3: they round
    kinks that G64 passes without reduction, and may cost time there.)"""
    for name in MACHINES:
        m = load_machine(name)
        for accel in ("", "BRISK", "SOFT"):
            g64 = corpus_in_mode(program, f"G64 {accel}")
            for mode in ("G641 ADIS=0.05", "G642", "G642 CTOL=0.05", "G645 CTOL=0.05"):
                assert_not_slower(g64, corpus_in_mode(program, f"{mode} {accel}"), m,
                                  f"{program} {name} {accel} {mode}")


def test_corpus_programs_with_corners_are_rounded_somewhere():
    """The corpus check above is not vacuous: the programs with sharp corners get
    roundings under G642 CTOL (BRISK, default machine) and are then faster."""
    m = load_machine()
    for program in ("lcnc_corner_decel.ngc", "lcnc_square.ngc", "lcnc_test_12mmflat.ngc",
                    "sin_cead_loop.mpf"):
        r = plan(parse_text(corpus_in_mode(program, "G642 CTOL=0.05 BRISK"), program), m)
        assert n_rounded(r) > 0, program


# ------------------------------------------------------------------ the estimate
def test_corner_time_loss_by_hand_brisk():
    """BRISK: a side ramping from v to its programmed speed v_i with acceleration a_i
    takes (v_i - v)/a_i and covers (v_i + v)/2 of that at the average speed, so it costs
    T dv / (2 v_i) beyond the programmed speed; a rounding of length l adds l/v and
    removes d of each line, passed at v_i."""
    v_in, v_out, v, a_in, a_out = 100.0, 40.0, 10.0, 2000.0, 500.0
    l, d = 0.3, 0.2
    hand = ((v_in - v) ** 2 / (2 * a_in * v_in) + (v_out - v) ** 2 / (2 * a_out * v_out)
            + l / v - d / v_in - d / v_out)
    got = corner_time_loss(np.array([v_in]), np.array([v_out]), np.array([v]),
                           np.array([a_in]), np.array([a_out]), np.array([np.inf]),
                           np.array([np.inf]), np.array([l]), np.array([d]))
    assert got[0] == pytest.approx(hand, rel=1e-14)
    # the corner speed is at most the programmed speeds
    capped = corner_time_loss(np.array([v_in]), np.array([v_out]), np.array([70.0]),
                              np.array([a_in]), np.array([a_out]), np.array([np.inf]),
                              np.array([np.inf]), 0.0, 0.0)
    assert capped[0] == pytest.approx((v_in - v_out) ** 2 / (2 * a_in * v_in), rel=1e-14)


def test_corner_time_loss_by_hand_soft_and_a_stop():
    """SOFT: the ramp lasts dv/a + a/j where it reaches a (dv >= a^2/j), else
    2 sqrt(dv/j) (spec 5.8, SOFT variant). A stop (G64 with overload factor 1.0) costs
    its two ramps, a finite time; a rounding passed at no speed would never end."""
    a, j = 2000.0, 40000.0
    for v_p in (500.0, 50.0):                        # reaches a / stays jerk-limited
        T = v_p / a + a / j if v_p >= a * a / j else 2 * math.sqrt(v_p / j)
        got = corner_time_loss(np.array([v_p]), np.array([v_p]), np.array([0.0]),
                               np.array([a]), np.array([a]), np.array([j]), np.array([j]),
                               0.0, 0.0)
        assert got[0] == pytest.approx(T, rel=1e-14)
    never = corner_time_loss(np.array([50.0]), np.array([50.0]), np.array([0.0]),
                             np.array([a]), np.array([a]), np.array([j]), np.array([j]),
                             np.array([0.3]), np.array([0.2]))
    assert never[0] == np.inf


def test_corner_time_loss_counts_a_shortened_block_capped_by_its_ipo_cycle_by_hand():
    """spec 5.3: "every block, the rounding block included, needs at least one
    interpolation point". The part of a block the rounding leaves is still a block: a
    0.0254 mm block cut to half (0.0127 mm) at T_ipo = 4 ms runs at most at 3.175 mm/s,
    below the 6.35 mm/s of the whole block and below the 4.36 mm/s of a rounding
    (BRISK, a = 2000 mm/s^2, l = 0.02 mm, d = 0.0127 mm). A ramp from there reaches
    sqrt(3.175^2 + 2 a r) = 7.8 mm/s over the piece, so its cap binds: both pieces are
    crossed at 3.175 mm/s, each side ramps 6.35 <-> 3.175, the rounding at 4.36 mm/s
    (reached from 3.175 by its middle: sqrt(3.175^2 + a l) = 7.1 mm/s), and d + r of
    each block is replaced. By hand; and a piece whose cap is above the block's speed
    (1 ms: 12.7 mm/s) changes nothing. (lcnc_short_segments_0.001.ngc under G641
    ADIS=0.05, default machine, BRISK: estimated 0.9 ms faster per corner without the
    pieces, planned 3.9 ms slower.)"""
    v_c, v_r, acc, l, d, r, t_ipo = 6.35, 4.36, 2000.0, 0.02, 0.0127, 0.0127, 0.004
    cap = r / t_ipo
    assert cap == pytest.approx(3.175) and math.sqrt(cap ** 2 + 2 * acc * r) > cap
    hand = (2 * ((v_c - cap) ** 2 / (2 * acc * v_c) - (d + r) / v_c) + 2 * r / cap
            + l / v_r)
    one = np.array([1.0])
    args = (v_c * one, v_c * one, v_r * one, acc * one, acc * one, np.inf * one,
            np.inf * one, l * one, d * one, None)
    got = corner_time_loss(*args, r * one, r * one, t_ipo)
    assert got[0] == pytest.approx(hand, rel=1e-14)
    plain = (2 * ((v_c - v_r) ** 2 / (2 * acc * v_c) - d / v_c) + l / v_r)
    assert corner_time_loss(*args)[0] == pytest.approx(plain, rel=1e-14)
    assert corner_time_loss(*args, r * one, r * one, 0.001)[0] == pytest.approx(plain,
                                                                                 rel=1e-14)
    assert got[0] > plain


def test_a_g0_into_a_slow_feed_counts_the_rapid_side_at_rapid_speed():
    """The rounding runs at the lower feed; the stretch of the G0 it replaces would have
    been passed at rapid speed (per side, not at the lower of the two): a G0 into a
    plunge at F100 is then not rounded where the estimate with the lower speed on both
    sides said it would save time (lcnc_corner_decel, 0.03 s slower under G642)."""
    m = load_machine()
    text = corpus_in_mode("lcnc_corner_decel.ngc", "G642")
    r = plan(parse_text(text), m)
    tab = r.path.rounding
    lines = text.splitlines()
    prog = parse_text(text)
    seen = 0
    for i in range(tab.n):
        before = lines[prog.blocks[tab.block[i]].line - 1]
        if before.startswith("G0 X"):                       # the rapid into the plunge
            assert tab.reason_text(i) == "rounding would be slower than G64"
            seen += 1
    assert seen == 1


# ------------------------------------------------------------------ SOFT units
#: Seven blocks of the benchmark polyline (seed 13, blocks 7642..7648), from 0.
STRETCH = ("G1 X0 Y0\nG1 X3.2088 Y2.9953\nX4.5323 Y-0.4629\nX5.2591 Y-3.0922\n"
           "X1.7970 Y-3.4130\nX1.2364 Y-1.9186\nX5.3320 Y-1.5703\nM30\n")


def test_soft_lines_beside_a_clothoid_pair_ramp_with_their_own_jerk():
    """A clothoid pair at its speed cap has little jerk left for speeding up (the
    centripetal part uses it): 792 mm/s^3 here against the lines' 4e4. Planned as one
    unit with the lines, that jerk slowed the lines too and the G642 program took 1.14 s
    against 0.76 s under G64. The lines must ramp with their own path jerk, by hand
    min_i J_i / |t_i| (J = 40 m/s^3 on every axis of the default mill), and the program
    be faster than under G64."""
    m = load_machine()
    r = plan(parse_text("G90 G642 CTOL=0.02 SOFT F6000\n" + STRETCH), m)
    r64 = plan(parse_text("G90 G64 SOFT F6000\n" + STRETCH), m)
    p, prof = r.path, r.profile
    k = np.flatnonzero(p.kind == ROUNDING)
    assert k.size == 2 and r.ok
    seg = p.segment_index(0.5 * (prof.s[:-1] + prof.s[1:]))
    J = 40000.0
    for line in (k[0] - 1, k[-1] + 1):
        hand = J / np.abs(p.d[line]).max()
        assert np.abs(prof.j[seg == line]).max() == pytest.approx(hand, rel=1e-9)
    assert r.time_s < r64.time_s


def quarter_arcs(n: int, r: float) -> str:
    """``n`` tangent quarter arcs of radius ``r`` curving alternately (``n - 1`` S-bends),
    from the origin heading +x (body only)."""
    out, x, y, heading, side = ["G1 X0 Y0"], 0.0, 0.0, 0.0, 1.0
    for _ in range(n):
        cx, cy = x - side * r * math.sin(heading), y + side * r * math.cos(heading)
        heading += side * math.pi / 2
        nx, ny = cx + side * r * math.sin(heading), cy - side * r * math.cos(heading)
        out.append(f"{'G3' if side > 0 else 'G2'} X{nx:.9f} Y{ny:.9f} "
                   f"I{cx - x:.9f} J{cy - y:.9f}")
        x, y, side = nx, ny, -side
    return "\n".join(out) + "\nM30\n"


def with_trans_tol(name: str, tol_mm: float):
    """The bundled machine ``name`` with PATH_TRANS_POS_TOL = ``tol_mm`` on every axis."""
    import tomllib
    from importlib import resources
    from reference.machine import machine_from_dict
    d = tomllib.loads(resources.files("reference.machines").joinpath(f"{name}.toml")
                      .read_text())
    for ax in d["axis"].values():
        ax["PATH_TRANS_POS_TOL"] = tol_mm
    return machine_from_dict(d)


@pytest.mark.parametrize("feed", (6000, 7000))
def test_three_s_bends_under_g645_are_not_slower_than_g64(feed):
    """spec 5.8 "Insert only if this beats the non-rounded limit of 6.3", 5.2 group 2.
    Three S-bends between quarter arcs of R = 100 mm (MD33120 = 0.01 mm), SOFT: G645
    rounds all three, and the S pieces' path jerk (0.4-0.7 of the arcs') made the whole
    program one planning unit that ramped from and to rest with it (7000 mm/min: 5.74 s
    against 5.53 s under G64; 6000: 6.404 s against 6.394 s). The reference is the G64
    plan of the same program: the first arc ramps from rest exactly as there (the same
    segment, planned with its own jerk: the largest jerk of the start ramp equals the
    G64 plan's), and the rounded program is faster."""
    m = with_trans_tol("default", 0.01)
    body = quarter_arcs(4, 100.0)
    r64 = plan(parse_text(f"G17 G90 G64 SOFT F{feed}\n" + body, "t.mpf"), m)
    r = plan(parse_text(f"G17 G90 G645 SOFT F{feed}\n" + body, "t.mpf"), m)
    assert r.ok and r64.ok
    assert n_rounded(r) == 3
    assert r.time_s < r64.time_s

    def start_jerk(res):
        prof = res.profile
        ramp = prof.s[1:] <= 5.0                       # the start ramp: its first 5 mm
        return np.abs(prof.j[ramp]).max()

    assert start_jerk(r) == pytest.approx(start_jerk(r64), rel=1e-12)


@pytest.mark.parametrize("name", MACHINES)
@pytest.mark.parametrize("accel", ("BRISK", "SOFT"))
def test_rounded_s_bend_chain_is_not_slower_than_g64(name, accel):
    """spec 4.3 / 5.2 group 2 on a seeded chain of S-bends (tangent arcs of 20..200 mm
    curving alternately, MD33120 = 0.05 mm so that G645 rounds most of them), at three
    feeds: never slower than the same program under G64, strictly faster where rounded
    (under SOFT on the default mill it rounds some; under BRISK a curvature jump is
    allowed, and the LinuxCNC machine's PATH_TRANS_JERK_LIM passes them: none)."""
    from seeded_programs import s_bend_chain
    m = with_trans_tol(name, 0.05)
    body = s_bend_chain(30, 3)
    rounded = 0
    for feed in (3000, 8000, 15000):
        head = f"G17 G90 {{}} {accel} F{feed}\n"
        rounded += assert_not_slower(head.format("G64") + body, head.format("G645") + body,
                                     m, f"{name} {accel} F{feed}")
    assert (rounded > 0) == (accel == "SOFT" and name == "default")


def test_units_cut_at_their_cruise_are_planned_as_a_full_replan(monkeypatch):
    """After the cut (reference.planner.lookahead.cruise_splits) only the units that
    changed are planned again; the reference is planning every unit again: the same
    profile, bit for bit. The program: a line to an exact stop (a unit the cut leaves
    as it was), then the three S-bends (cut)."""
    import reference.planner.engine as engine
    m = with_trans_tol("default", 0.01)
    prog = parse_text("G17 G90 G645 SOFT F7000\nG1 X-80 Y0\nG1 X-40 Y0 G9\n"
                      + quarter_arcs(4, 100.0), "t.mpf")
    cuts, replanned = [], []
    real_cuts, real_replan = engine.cruise_splits, engine._replan

    def counted(*args):
        out = real_cuts(*args)
        cuts.append(int(out.sum()))
        return out

    def replan(units, idx, v):
        replanned.append((idx.size, units.n_units))
        return real_replan(units, idx, v)

    monkeypatch.setattr(engine, "cruise_splits", counted)
    monkeypatch.setattr(engine, "_replan", replan)
    r = plan(prog, m)
    assert cuts[0] > 0 and 0 < replanned[0][0] < replanned[0][1]
    monkeypatch.setattr(engine, "_plan_changed",
                        lambda units, v, *old: engine._plan_all(units, v))
    full = plan(prog, m)
    assert cuts[0] > 0
    for name in ("t", "s", "v", "a", "j"):
        np.testing.assert_array_equal(getattr(r.profile, name), getattr(full.profile, name))
    assert r.time_s == full.time_s


def test_small_soft_roundings_cost_time_on_the_default_machine_by_hand(monkeypatch):
    """Issue 13 item 5: on the default SOFT machine (A = 2 m/s^2, J = 40 m/s^3, overload
    factor 1.2, T_ipo = 4 ms) the seeded polyline under G641 ADIS=0.2 gets no rounding.
    Spec 5.8's "G642 is much faster than G64 at sharp corners" is its BRISK example
    (``v <= sqrt(8 tol A) / |dt_i|``); with this jerk every ramp at F6000 is jerk-limited
    (A^2 / J = 100 mm/s = the feed), lasting about 2 sqrt(v / J) = 0.1 s whatever the
    corner speed, so the corner speed buys little and the rounding's crawl costs much.

    By hand, in the spec's own SOFT model (5.8, "each axis changes velocity by dv_i = v
    |dt_i| with jerk J_i ... T_i = 2 sqrt(dv_i / J_i)", one common T, d = v T / 2), a 90
    degree corner at F6000 (v_p = 100 mm/s, |dt_i| = 1), the full axis jerk: a ramp by
    dv costs T dv / (2 v_p) = sqrt(dv^3 / J) / v_p against the programmed speed.

    * G64: v = A (1.2 - 1) T_ipo = 1.6 mm/s, two ramps by 98.4 mm/s: 97.6 ms;
    * rounding of distance d: entry speed v_r = (d^2 J)^(1/3) (T = 2 sqrt(v_r / J) =
      2 d / v_r), two ramps by 100 - v_r, the rounding in 2 d / v_r instead of 2 d /
      v_p: ADIS = 0.2 mm gives v_r = 11.7 mm/s and 113.2 ms, 15.6 ms slower; it pays
      only from d = 0.80 mm on (ADIS = 2 mm: 64.6 ms).

    The model agrees at ADIS = 0.2 ("rounding would be slower than G64"; its clothoid
    pair, crossed at its jerk limit, 5.8 mm/s, slower than the axis-wise model's entry
    speed), and so does its plan of the rounded corner. (The oracle's time-optimal
    motion on the same paths: G64 0.5827 s, rounded at most 0.5987 s.)"""
    from reference import rounding as rounding_stage
    J, v_p = 40000.0, 100.0

    def ramp(dv):
        return math.sqrt(dv ** 3 / J) / v_p

    def rounded(d):
        v_r = (d * d * J) ** (1.0 / 3.0)
        assert 2 * math.sqrt(v_r / J) == pytest.approx(2 * d / v_r, rel=1e-12)
        return 2 * ramp(v_p - v_r) + 2 * d / v_r - 2 * d / v_p

    g64 = 2 * ramp(v_p - 1.6)
    assert g64 == pytest.approx(0.0976, abs=1e-4)
    assert (0.2 * 0.2 * J) ** (1 / 3) == pytest.approx(11.70, abs=0.01)
    assert rounded(0.2) - g64 == pytest.approx(0.0156, abs=1e-4)
    assert rounded(2.0) == pytest.approx(0.0646, abs=1e-4)
    lo, hi = 0.2, 2.0                               # the break-even distance
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if rounded(mid) > g64 else (lo, mid)
    assert lo == pytest.approx(0.80, abs=0.005)
    m = load_machine()
    prog = parse_text("G90 G641 ADIS=0.2 SOFT F6000\nG1 X0 Y0\nG1 X20\nY20\n")
    path = build_path(prog, m)
    t = path.rounding
    assert t.reason_text(0) == "rounding would be slower than G64"
    assert t.v_g64[0] == pytest.approx(1.6, rel=1e-9)
    assert t.v_round[0] < (0.2 * 0.2 * J) ** (1 / 3)
    loss = rounding_stage.corner_time_loss
    monkeypatch.setattr(rounding_stage, "corner_time_loss", lambda *a, **k: np.where(
        np.asarray(a[7]) > 0, -np.inf, loss(*a, **k)))
    forced = build_path(prog, m)
    assert forced.rounding.inserted.all()
    assert plan(prog, m, path=forced).time_s > plan(prog, m, path=path).time_s
