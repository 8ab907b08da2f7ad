"""Rounding across several short blocks (issue 13 item 4; reference/rounding.py
``_across_blocks``), checked against hand geometry.

The model: with G642/G645 the tolerance fixes the rounding distance d (spec 5.4), and a
rounding "replaces the area near the original angular transition" (FB1 excerpt, spec
5.1), so where the blocks beside a corner are shorter than d the window runs on along
the straight chain of blocks before and after it; the clamp "half the length of the
original participating blocks" (G644 excerpt) applies to the chain. G641 ("the rounding
area is also limited by the block lengths", spec 5.3), G643 (inside the blocks, 5.5) and
G644 keep the one-block clamp.
"""

from __future__ import annotations

import math
from pathlib import Path as FsPath

import numpy as np
import pytest

from reference.core.constraints import BOUND_SETS, check_profile
from reference.core.geometry import KIND_CODES
from reference.machine import load_machine
from corpus_sinumerik import short_segments_g642
from reference.nc import parse_text
from reference.planner import plan
from reference.prepare import build_path
from rounding_machines import rounding_machine

ROOT = FsPath(__file__).resolve().parents[2]
SHORT = short_segments_g642     # the corpus program converted at test time
ROUNDING = KIND_CODES.index("rounding")
MEET_MM = 1e-9           # consecutive segments meet to this (test_path_continuity)



def machine(**channel):
    return rounding_machine(**channel)


def steps(mode: str, n: int = 10, step: float = 0.01, feed: str = "F3000") -> str:
    """``n`` blocks of ``step`` mm along X, then ``n`` along Y: one 90 degree corner at
    X = n step between two straight chains of short blocks. Blocks: 0 the mode line,
    1 G1 X0 Y0 (no motion), 2 .. n+1 along X, n+2 .. 2n+1 along Y."""
    xs = [f"X{step * i:.6f}" for i in range(1, n + 1)]
    ys = [f"Y{step * i:.6f}" for i in range(1, n + 1)]
    return f"G17 G90 {mode} {feed}\nG1 X0 Y0\n" + "\n".join(xs + ys) + "\n"


def assert_continuous(path) -> None:
    for k in range(path.n_segments - 1):
        np.testing.assert_allclose(path.segment(k).end, path.segment(k + 1).start,
                                   atol=MEET_MM)


def test_g642_window_reaches_across_short_blocks_by_hand():
    """90 degree corner, COMPRESS_POS_TOL 0.01 mm on X and Y (spec 5.4): the corner point
    moves by 0.01 mm per axis, |C - M| = 0.01 sqrt(2), d = |C - M| / tan(22.5 deg) =
    0.03414 mm, more than three 0.01 mm blocks; the chains are 0.1 mm, so the clamp
    0.5 * 0.1 mm does not bind. The window starts at X = 0.1 - d = 0.06586 (inside the
    block X0.06 -> X0.07, block 8) and ends at Y = d (inside Y0.03 -> Y0.04, block 15);
    blocks 9, 10, 11 and 12, 13, 14 are covered whole."""
    prog = parse_text(steps("G642"))
    path = build_path(prog, machine())
    t = path.rounding
    r = int(np.flatnonzero(t.inserted)[0])
    assert int(t.inserted.sum()) == 1
    d = 0.01 * math.sqrt(2.0) / math.tan(math.pi / 8)
    assert t.distance_mm[r] == pytest.approx(d, rel=1e-12)
    assert not t.clamped[r]
    assert (t.block[r], t.next_block[r]) == (11, 12)
    assert (t.first_block[r], t.last_block[r]) == (8, 15)
    assert t.blocks_spanned[r] == 8
    assert t.radius_mm[r] == pytest.approx(d / math.tan(math.pi / 4), rel=1e-12)
    spans = {s.block: s for s in path.blocks}
    for k in (9, 10, 12, 13, 14):                       # covered whole: no segment left
        assert spans[k].n_segments == 0 and spans[k].length == 0.0
    assert spans[11].n_segments == 1                     # the rounding, attributed to it
    assert path.kind[spans[11].first_segment] == ROUNDING
    assert spans[8].length == pytest.approx(0.1 - d - 0.06, abs=1e-12)
    assert spans[15].length == pytest.approx(0.04 - d, abs=1e-12)
    k = spans[11].first_segment
    np.testing.assert_allclose(path.segment(k).start[:2], [0.1 - d, 0.0], atol=1e-12)
    np.testing.assert_allclose(path.segment(k).end[:2], [0.1, d], atol=1e-12)
    assert_continuous(path)
    assert [s.block for s in path.blocks] == [b.index for b in prog.blocks]


def test_the_clamp_applies_to_the_straight_chain():
    """G644 excerpt: "The rounding distance cannot exceed half the length of the original
    participating blocks". Across short blocks the participating stretch is the straight
    chain: 4 blocks of 0.005 mm = 0.02 mm, so d = 0.5 * 0.02 = 0.01 mm (below the
    tolerance's 0.03414 mm), covering two blocks on each side."""
    prog = parse_text(steps("G642", n=4, step=0.005))
    path = build_path(prog, machine())
    t = path.rounding
    r = int(np.flatnonzero(t.inserted)[0])
    assert t.clamped[r]
    assert t.distance_mm[r] == pytest.approx(0.01, rel=1e-12)
    assert (t.first_block[r], t.last_block[r]) == (4, 7)
    assert_continuous(path)


@pytest.mark.parametrize("mode", ["G641 ADIS=0.5", "G643", "G644"])
def test_g641_g643_g644_keep_the_one_block_clamp(mode):
    """spec 5.3 (G641): "The rounding area is also limited by the block lengths"; 5.5
    (G643): "the rounding is carried out inside the original blocks"; G644 excerpt: the
    distance "cannot exceed half the length of the original participating blocks". d is
    cut to half of one 0.01 mm block. (G644 with SMOOTHING_MODE 4xxx, the tolerance
    "fully used" (spec 5.6): with 0xxx at F60 the axes' dynamic rounding, d = 2.5e-3 mm,
    is smaller than the clamp, test_rounding.py.)"""
    # F60: below the speed of a 0.005 mm rounding (5.2: it must not slow the program)
    prog = parse_text(steps(mode, feed="F60"))
    path = build_path(prog, machine(SMOOTHING_MODE=4000))
    t = path.rounding
    r = int(np.flatnonzero(t.inserted)[0])
    assert t.distance_mm[r] == pytest.approx(0.005, rel=1e-12)
    assert (t.first_block[r], t.last_block[r]) == (t.block[r], t.next_block[r])
    assert t.blocks_spanned[r] == 2


@pytest.mark.parametrize("breaker, first", [
    ("F2000", 9),              # a feed change at block 9 ends the chain before it
    ("G9", 9),                 # an exact stop at the end of block 8
])
def test_the_window_stops_where_the_chain_does(breaker, first):
    """A window covers only blocks that continue the straight line with nothing else
    changing: block 9 programs a new feed (or block 8 an exact stop, spec 3), so the
    window starts at the beginning of block 9 at the earliest (X = 0.07), and the chain
    of 3 blocks, 0.03 mm, clamps d to 0.015 mm."""
    lines = steps("G642").splitlines()
    at = 9 if breaker.startswith("F") else 8
    lines[at] += " " + breaker
    path = build_path(parse_text("\n".join(lines) + "\n"), machine())
    t = path.rounding
    r = int(np.flatnonzero(t.inserted)[0])
    assert t.distance_mm[r] == pytest.approx(0.015, rel=1e-9)
    assert t.first_block[r] == 10
    assert_continuous(path)


def test_one_interpolation_cycle_per_rounding_block_not_per_covered_block():
    """spec 5.3: "every block, the rounding block included, needs at least one
    interpolation point"; the covered blocks are no longer interpolated, so inside the
    rounding the speed may exceed a short block's cap (0.01 mm / 4 ms = 2.5 mm/s) up to
    the rounding's own, R pi/2 / 4 ms = 13.4 mm/s (R = d = 0.03414 mm; the centripetal
    limit sqrt(0.75 * 2000 * R) = 7.2 mm/s binds first). The short blocks outside the
    window stay capped at 2.5 mm/s."""
    prog = parse_text(steps("G642", n=40))
    mach = machine()
    path = build_path(prog, mach)
    res = plan(prog, mach, path=path)
    k = int(np.flatnonzero(path.kind == ROUNDING)[0])
    s = np.linspace(path.s_breaks[k], path.s_breaks[k + 1], 401)
    v = res.profile.state(res.profile.time_at(s))[1]
    R = 0.01 * math.sqrt(2.0) / math.tan(math.pi / 8)
    v_round = min(R * math.pi / 2 / 0.004, math.sqrt(0.75 * 2000.0 * R))
    assert v.max() > 2.5 * 1.5
    assert v.max() <= v_round * (1 + 1e-9)
    s_line = np.linspace(0.0, path.s_breaks[k - 1], 401)
    assert res.profile.state(res.profile.time_at(s_line))[1].max() <= 2.5 * (1 + 1e-9)
    rep = check_profile(path, mach.limits, res.profile)
    assert rep.ok(BOUND_SETS[res.bound_set]), rep


@pytest.mark.parametrize("name", [None, "linuxcnc_xyz"])
def test_short_segments_program_under_g642(name):
    """The corpus program lcnc_short_segments_0.001.ngc converted to SINUMERIK syntax
    with G642 (converted by tests/reference/corpus_sinumerik.py): 3000 collinear 0.001 in blocks with
    two 90 degree corners. The tangential transitions are not rounded (spec 5.2 lists
    rounding only at angular transitions; G645's tangential rounding needs a curvature
    jump, 5.7), so every 0.0254 mm block stays one interpolated block; the path stays
    continuous, the plan keeps every limit, and it is no slower than G64. Where the
    corners are rounded (the LinuxCNC machine, the next test) each window covers the
    short blocks within d; on the default machine (SOFT, 4 ms) they are not: the
    blocks run at 0.0254 mm / 4 ms = 6.35 mm/s, G64 passes at 1.6 mm/s and the
    clothoid pair at 2.2 mm/s (jerk), so crawling its 0.08 mm costs more than the
    shorter ramps save, and the plan of the rounded path says the same (12.185 s
    against 12.063 s)."""
    mach = load_machine(name) if name else load_machine()
    prog = parse_text(SHORT(), "short_segments_g642.mpf")
    path = build_path(prog, mach)
    t = path.rounding
    tangential = [t.reason_text(i) == "tangential transition" for i in range(t.n)]
    assert sum(tangential) == t.n - 2
    assert_continuous(path)
    assert [s.block for s in path.blocks] == [b.index for b in prog.blocks]
    res = plan(prog, mach, path=path)
    assert res.report.ok(BOUND_SETS[res.bound_set])
    prog64 = parse_text(SHORT().replace("G642 G17", "G64 G17"))
    assert build_path(prog64, mach).rounding is None
    assert res.time_s <= plan(prog64, mach).time_s * (1 + 1e-9)
    corners = [i for i in range(t.n) if not tangential[i]]
    if name is None:
        assert [t.reason_text(i) for i in corners] == [
            "rounding would be slower than G64"] * 2
    else:
        assert t.inserted[corners].all()
    for i in np.flatnonzero(t.inserted):
        d = t.distance_mm[i]
        assert t.blocks_spanned[i] == 2 * math.ceil(d / 0.0254 - 1e-9)


def test_short_segments_corners_pay_on_the_linuxcnc_machine_by_hand():
    """Issue 13 item 4, "show the effect": the same program on the LinuxCNC machine
    (BRISK, T_ipo = 1 ms, MAX_AX_ACCEL 0.762 m/s^2 on X, Y and Z, MAX_ACCEL_OVL_FACTOR
    1.0, MD33100 0.01 mm by default). Spec 4.3: "A transition is rounded only if it
    cannot be passed at G64 speed without a reduction"; 5.2 group 2: none where
    "rounding would slow the program down"; 5.3: "every block ... needs at least one
    interpolation point", so the 0.0254 mm blocks run at v_c = 0.0254 mm / 1 ms =
    25.4 mm/s (not at the 203 mm/s of MAX_AX_VELO, which the decision used to ramp
    from, and then estimated the rounding 0.4 ms slower per corner). By hand, per 90
    degree corner (t1, t2 along two axes, plane weights 1):

    * G64 stops (overload factor 1: no velocity jump): braking and accelerating at
      a = 762 mm/s^2 cost v_c / (2 a) each, 33.333 ms;
    * G642: d = 0.01 sqrt(2) / tan(22.5 deg) = 0.034142 mm (spec 5.4, 5.8; the arc
      deviates by 0.01 mm per axis), R = d / tan(45 deg) = d, crossed at
      v_r = sqrt(0.75 a R) = 4.4173 mm/s (the centripetal share); the ramps v_c <-> v_r
      cost (v_c - v_r)^2 / (2 a v_c) each, the arc R pi / 2 at v_r less the 2 d it
      replaces at v_c: 32.200 ms.

    So each corner saves 1.1330 ms; the windows reach into the second block on each
    side (d > 0.0254 mm: 4 blocks), and the plan is shorter than G64's by exactly the
    two savings."""
    mach = load_machine("linuxcnc_xyz")
    prog = parse_text(SHORT(), "short_segments_g642.mpf")
    path = build_path(prog, mach)
    t = path.rounding
    ins = np.flatnonzero(t.inserted)
    assert ins.size == 2
    d = 0.01 * math.sqrt(2.0) / math.tan(math.pi / 8)
    np.testing.assert_allclose(t.distance_mm[ins], d, rtol=1e-12)
    assert t.blocks_spanned[ins].tolist() == [4, 4]
    v_c, acc = 0.0254 / 0.001, 762.0
    v_r = math.sqrt(0.75 * acc * d)
    np.testing.assert_allclose(t.v_round[ins], v_r, rtol=1e-12)
    g64 = 2 * v_c / (2 * acc)
    rounded = 2 * (v_c - v_r) ** 2 / (2 * acc * v_c) + d * math.pi / 2 / v_r - 2 * d / v_c
    assert g64 - rounded == pytest.approx(1.1330e-3, abs=1e-7)
    t_round = plan(prog, mach, path=path).time_s
    t_g64 = plan(parse_text(SHORT().replace("G642 G17", "G64 G17")), mach).time_s
    assert t_g64 - t_round == pytest.approx(2 * (g64 - rounded), rel=1e-9)


def test_every_span_lies_on_its_segments_after_rounding():
    """Spans before the first rounding are kept as they are, the others move: either
    way each span must start and end at the path position of its own segments (the
    invariant every per-block number relies on) and the segments must be the block's.
    A G64 prefix (unchanged spans), then G642 windows across short blocks (the first
    reaching back into blocks before its corner), then RND."""
    text = ("G17 G90 G64 F3000\nG1 X0 Y0\nX5\nY5\nX10\nG642\nX10.01\nX10.02\nX10.03\n"
            "Y10\nX20 RND=1\nY20\nX20.01\nX20.02\nY25\n")
    prog = parse_text(text)
    path = build_path(prog, machine())
    assert int(path.rounding.inserted.sum()) >= 3
    assert int(np.max(path.rounding.blocks_spanned)) > 2
    sb = path.s_breaks
    for sp in path.blocks:
        assert sp.s_start == sb[sp.first_segment]
        assert sp.s_end == sb[sp.first_segment + sp.n_segments]
        segs = range(sp.first_segment, sp.first_segment + sp.n_segments)
        assert all(path.block[k] == sp.block for k in segs)
    assert sum(sp.n_segments for sp in path.blocks) == path.n_segments
    assert_continuous(path)
