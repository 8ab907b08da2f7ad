"""Corner rounding (reference/rounding.py): every documented property against hand geometry.

The rounding is a tangent arc (first version, reference/core/rounding.py). For a corner
with deflection angle theta and tangent distance d, by hand: radius R = d / tan(theta/2),
arc length R theta, deviation of the rounded path from the corner R (1/cos(theta/2) - 1).
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from reference.core.constraints import BOUND_SETS, check_profile
from reference.core.geometry import KIND_CODES
from reference.core.rounding import ROUNDING_REASONS
from reference.machine import load_machine, machine_from_dict
from reference.nc import parse_text
from reference.planner import plan
from reference.prepare import build_path

BASE = {
    "machine": {"name": "t", "ipo_cycle_ms": 4.0},
    "channel": {"lookahead_blocks": 50, "acceleration_mode": "BRISK"},
    "axis": {ax: {"MAX_AX_VELO": 30000.0, "MAX_AX_ACCEL": 2.0, "MAX_AX_JERK": 40.0,
                  "MAX_ACCEL_OVL_FACTOR": 1.2, "LOOKAH_FREQUENCY": 20.0,
                  "COMPRESS_POS_TOL": 0.01}
             for ax in "XYZ"},
}
ROUNDING = KIND_CODES.index("rounding")


def machine(ovl: float = 1.2, velo: float = 30000.0, **channel):
    """The test machine; ``ovl = 1.0`` makes G64 stop at every corner; ``velo``:
    MAX_AX_VELO, mm/min (the G0 speed).

    A stop costs its braking and acceleration ramps; a rounding passed at the programmed
    speed costs nothing and shortens the path, so where the feed (or, for G0, the axis
    velocity) is below the rounding's own speed every parameterised corner is rounded
    and a test sees the geometry alone (5.2: rounding only where it does not slow the
    program down)."""
    d = copy.deepcopy(BASE)
    d["channel"].update(channel)
    for ax in d["axis"].values():
        ax["MAX_ACCEL_OVL_FACTOR"] = ovl
        ax["MAX_AX_VELO"] = velo
    return machine_from_dict(d)


def square(mode: str, extra: str = "") -> str:
    return (f"G17 G90 {mode} {extra} F3000\nG1 X0 Y0\nG1 X50\nG1 Y50\nG1 X0\nG1 Y0\n")


def rounded(text: str, mach=None):
    """Program, machine (default: G64 stops, the geometry alone decides) and its path."""
    prog = parse_text(text)
    mach = mach or machine(ovl=1.0)
    return prog, mach, build_path(prog, mach)


def reasons(path) -> list[str]:
    t = path.rounding
    return [t.reason_text(i) for i in range(t.n)]


def _check_tangent_continuity(path) -> None:
    """Positions meet and tangents agree at every break next to a rounding segment."""
    for k in range(path.n_segments - 1):
        if ROUNDING not in (path.kind[k], path.kind[k + 1]):
            continue
        a, b = path.segment(k), path.segment(k + 1)
        np.testing.assert_allclose(a.end, b.start, atol=1e-12)
        np.testing.assert_allclose(a.end_tangent, b.start_tangent, atol=1e-12)


# ------------------------------------------------------------------ G642 tolerances
def test_g642_axis_deviation_is_compress_pos_tol_by_hand():
    """spec 5.4: "The maximum deviation for G642/G643 is set per axis in MD33100
    COMPRESS_POS_TOL". 90 degree corner, tol 0.01 mm on X and Y: the corner moves by
    0.01 mm on each axis, |C - M| = 0.01 sqrt(2), d = |C - M| / tan(22.5 deg)."""
    prog, mach, path = rounded(square("G642"))
    t = path.rounding
    assert list(t.inserted) == [True] * 3
    dev = 0.01 * math.sqrt(2.0)
    d = dev / math.tan(math.pi / 8)
    R = d / math.tan(math.pi / 4)
    np.testing.assert_allclose(t.deviation_mm, dev, rtol=1e-12)
    np.testing.assert_allclose(t.distance_mm, d, rtol=1e-12)
    np.testing.assert_allclose(t.radius_mm, R, rtol=1e-12)
    np.testing.assert_allclose(t.length_mm, R * math.pi / 2, rtol=1e-12)
    # the geometry itself: the arc's midpoint and its nearest approach to the corner
    k = int(np.flatnonzero(path.kind == ROUNDING)[0])
    seg = path.segment(k)
    mid = seg.evaluate(seg.length / 2)[0][0]
    np.testing.assert_allclose(np.abs(mid[:2] - [50.0, 0.0]), [0.01, 0.01], rtol=1e-9)
    q = seg.evaluate(np.linspace(0, seg.length, 2001))[0]
    assert np.min(np.linalg.norm(q[:, :2] - [50.0, 0.0], axis=1)) == pytest.approx(dev, rel=1e-6)
    # starts d before the corner on the first line and ends d after it on the second
    np.testing.assert_allclose(seg.start[:2], [50.0 - d, 0.0], atol=1e-12)
    np.testing.assert_allclose(seg.end[:2], [50.0, d], atol=1e-12)
    _check_tangent_continuity(path)
    assert path.total_length == pytest.approx(200.0 - 3 * (2 * d - R * math.pi / 2), rel=1e-12)


def test_ctol_sets_the_contour_deviation():
    """spec 5.7: CTOL overrides MD/SD values and applies to all rounding types except
    G641, G644: with CTOL=0.05 the corner deviates by exactly 0.05 mm."""
    _, _, path = rounded(square("G642", "CTOL=0.05"))
    np.testing.assert_allclose(path.rounding.deviation_mm, 0.05, rtol=1e-12)
    # G644 ignores CTOL (spec 5.6): MD33100 per axis
    _, _, p644 = rounded(square("G644", "CTOL=0.05"))
    np.testing.assert_allclose(p644.rounding.deviation_mm, 0.01 * math.sqrt(2), rtol=1e-12)


def test_smoothing_mode_tens_digit_one_uses_smooth_contur_tol():
    """spec 5.4 table: tens digit 1 of MD20480: "contour tolerance SD42465" for G642."""
    _, _, path = rounded(square("G642"), machine(1.0, SMOOTHING_MODE=10,
                                                       SMOOTH_CONTUR_TOL=0.03))
    np.testing.assert_allclose(path.rounding.deviation_mm, 0.03, rtol=1e-12)


# ------------------------------------------------------------------ G641 distances
def test_g641_rounding_starts_adis_before_the_corner():
    """spec 5.3: "ADIS ... the earliest point before the block end where rounding may
    start, and the latest point after it where rounding must be finished"."""
    _, _, path = rounded(square("G641", "ADIS=0.5"))
    t = path.rounding
    np.testing.assert_allclose(t.distance_mm, 0.5)
    k = int(np.flatnonzero(path.kind == ROUNDING)[0])
    seg = path.segment(k)
    np.testing.assert_allclose(seg.start[:2], [49.5, 0.0], atol=1e-12)
    np.testing.assert_allclose(seg.end[:2], [50.0, 0.5], atol=1e-12)
    np.testing.assert_allclose(t.radius_mm, 0.5, rtol=1e-12)          # tan(45 deg) = 1
    _check_tangent_continuity(path)


def test_g641_clamp_to_half_the_shorter_block():
    """G644 excerpt: "The rounding distance cannot exceed half the length of the original
    participating blocks." (spec 5.3 model: d = min(ADIS, 0.5 L_k, 0.5 L_k+1))."""
    text = "G90 G641 ADIS=2 F3000\nG1 X0 Y0\nG1 X50\nG1 Y1\nG1 X0\n"
    _, _, path = rounded(text)
    t = path.rounding
    np.testing.assert_allclose(t.distance_mm, [0.5, 0.5])
    assert list(t.clamped) == [True, True]
    # the 1 mm block is used up by its two roundings: only the two arcs remain of it
    span = next(s for s in path.blocks if s.line == 4)
    assert span.n_segments == 1 and path.kind[span.first_segment] == ROUNDING
    _check_tangent_continuity(path)


def test_adispos_for_g0_and_the_smaller_distance_for_mixed_blocks():
    """spec 5.3: "ADISPOS is the same for G0"; "If only one of the two blocks is G0,
    the smaller distance applies"."""
    text = "G90 G641 ADIS=0.5 ADISPOS=0.2 F60\nG0 X0 Y0\nG0 X50\nG0 Y50\nG1 X0\n"
    # G0 at 60 mm/min: below the speed of the 0.2 mm roundings (see ``machine``)
    _, _, path = rounded(text, machine(1.0, velo=60.0))
    np.testing.assert_allclose(path.rounding.distance_mm[:2], [0.2, 0.2])


# ------------------------------------------------------------------ no rounding block
NO_ROUNDING = [
    # 5.2 group 1 "the axes stop between the blocks anyway"
    ("G90 G641 ADIS=0.5 F3000\nG1 X0 Y0\nG1 X50 G9\nG1 Y50\n", "stop between the blocks"),
    ("G90 G641 ADIS=0.5 F3000\nG1 X0 Y0\nG1 X50\nR1=5\nG1 Y50\n",
     "block without path motion between"),
    ("G90 G641 ADIS=0.5 F3000\nG1 X0 Y0\nG1 X50\nSOFT G1 Y50\n",
     "acceleration mode change (BRISK/SOFT)"),
    # 5.2 group 3 "rounding is not parameterised: G641 with ADIS = 0"
    ("G90 G641 F3000\nG1 X0 Y0\nG1 X50\nG1 Y50\n", "rounding not parameterised (ADIS = 0)"),
    ("G90 G641 ADIS=0.5 F3000\nG0 X0 Y0\nG0 X50\nG0 Y50\n",
     "rounding not parameterised (ADISPOS = 0)"),
    # 5.2 group 2 "when G64 can pass the transition without a velocity reduction":
    # a 0.5 degree kink (the FB1 excerpt's example) at F3000
    ("G90 G641 ADIS=0.5 F3000\nG1 X0 Y0\nG1 X50\nG1 X100 Y0.436330\n",
     "G64 passes the corner without reduction (overload factor)"),
    ("G90 G641 ADIS=0.0000005 F3000\nG1 X0 Y0\nG1 X50\nG1 Y50\n",
     "rounding distance too small"),
    ("G90 G641 ADIS=0.5 F3000\nG1 X0 Y0\nG1 X50\nG1 X60\n", "tangential transition"),
    # model limit: two arcs in different planes (XY into ZX)
    ("G90 G641 ADIS=0.5 F3000\nG1 X0 Y0\nG17 G2 X10 Y0 I5 J0\nG18 G2 X15 Z5 I0 K5\n",
     "corner next to a helix or spiral, or out of the arc's plane: rounding not modelled "
     "yet"),
]


@pytest.mark.parametrize("text, why", NO_ROUNDING)
def test_no_rounding_block_and_why(text, why):
    """spec 5.2 "When no rounding block is inserted": each case, named per corner, in the
    planner trace, and the path keeps the sharp corner."""
    prog, mach, path = rounded(text, machine())
    assert reasons(path) == [why]
    assert not np.any(path.kind == ROUNDING)
    note = dict((e.stage, e.note) for e in plan(prog, mach, path=path).trace)["rounding"]
    assert why in note


#: A machine with a rotary A axis beside X, Y, Z (the test machine's limits).
def machine_a(**channel):
    d = copy.deepcopy(BASE)
    d["channel"].update(channel)
    d["axis"]["A"] = dict(d["axis"]["X"])
    return machine_from_dict(d)


# each case: program, machine, the decision per recorded corner (block before it ->
# words), so that every documented "no rounding block" reason of spec 5.2 appears in the
# trace and the block rows, not only in the path
NO_ROUNDING_CASES = {
    # 5.2 group 1: "geometry axes move in one block but not in the other" (A alone
    # between two X/Y blocks: both corners)
    "geometry in one block": ("G90 G641 ADIS=0.5 F3000\nG1 X0 Y0\nG1 X50\nG1 A30\nG1 Y50\n",
                              machine_a, {2: "geometry axes move in one block only",
                                          3: "geometry axes move in one block only"}),
    # 5.2 group 1: "auxiliary function output before the motion in the next block"
    # (M6 rests at the start of its block, reference.prepare)
    "aux before motion": ("G90 G641 ADIS=0.5 F3000\nG1 X0 Y0\nG1 X50\nG1 Y50 M6\n",
                          machine, {2: "stop between the blocks"}),
    # 5.2 group 1: "an axis changes from positioning axis to path axis"; the parser
    # takes POS only in a block of its own, so the geometry rule names it first
    "positioning axis": ("G90 G641 ADIS=0.5 F3000\nG1 X0 Y0\nG1 X50\nPOS[A]=10\nG1 Y50\n",
                         machine_a, {2: "geometry axes move in one block only",
                                     3: "geometry axes move in one block only"}),
    # 5.2 group 3: "a tolerance of 0"
    "tolerance 0": ("G90 G642 CTOL=0 F3000\nG1 X0 Y0\nG1 X50\nG1 Y50\n", machine,
                    {2: "rounding not parameterised (tolerance 0)"}),
    # model limit, named: a rotary axis moving through the corner
    "other axes": ("G90 G641 ADIS=0.5 F3000\nG1 X0 Y0\nG1 X50 A10\nG1 Y50 A20\n", machine_a,
                   {2: "non-geometry axes move: rounding not modelled yet"}),
}


@pytest.mark.parametrize("case", sorted(NO_ROUNDING_CASES))
def test_more_no_rounding_cases_are_named(case):
    """spec 5.2 "When no rounding block is inserted": group 1 "geometry axes move in one
    block but not in the other", "auxiliary function output before the motion in the
    next block", "an axis changes from positioning axis to path axis"; group 3 "a
    tolerance of 0"; and the model's own limit (other axes moving at the corner), each
    named per corner in the table, the trace and the plan's block rows."""
    from reference.planner.export import iter_json_rows
    text, mk, want = NO_ROUNDING_CASES[case]
    prog, mach, path = rounded(text, mk())
    assert not np.any(path.kind == ROUNDING)
    t = path.rounding
    assert {int(t.block[i]): t.reason_text(i) for i in range(t.n)} == want
    res = plan(prog, mach, path=path)
    note = dict(res.trace)["rounding"]
    rows = {r["block"]: r.get("rounding") for r in iter_json_rows(res)}
    for blk, why in want.items():
        assert why in note
        assert rows[blk] == "none: " + why
    # blocks whose end is no corner in a rounding mode carry no rounding field
    assert {b for b, v in rows.items() if v is not None} == set(want)


def test_block_rows_name_every_reason_of_the_parametrised_cases():
    """The block rows of :func:`test_no_rounding_block_and_why`'s programs name the
    same reason as the trace (issue 13: "each named in the trace and in the block
    rows")."""
    from reference.planner.export import iter_json_rows
    for text, why in NO_ROUNDING:
        prog, mach, path = rounded(text, machine())
        rows = [r for r in iter_json_rows(plan(prog, mach, path=path)) if "rounding" in r]
        assert [r["rounding"] for r in rows] == ["none: " + why], text


def test_the_mode_of_the_block_ending_at_the_corner_governs_it():
    """spec 8: per transition k -> k+1 "if mode == G64: v_j = v64": the group-10 mode in
    force for block k decides its end corner. G64 into a G642 block is a G64 corner (not
    recorded, no rounding); a G642 block into a G64 block is rounded."""
    g64_first = "G90 G64 CTOL=0.05 F3000\nG1 X0 Y0\nG1 X50\nG642 G1 Y50\nG1 X0\n"
    _, _, path = rounded(g64_first)
    t = path.rounding
    assert t.block.tolist() == [3] and t.inserted.tolist() == [True]
    g642_first = "G90 G642 CTOL=0.05 F3000\nG1 X0 Y0\nG1 X50\nG64 G1 Y50\nG1 X0\n"
    _, _, path = rounded(g642_first)
    t = path.rounding
    assert t.block.tolist() == [2] and t.inserted.tolist() == [True]


def test_ignore_ovl_factor_for_adis_rounds_even_a_small_kink():
    """spec 4.3: "Setting MD20490 IGNORE_OVL_FACTOR_FOR_ADIS = TRUE makes G641/G642
    behave like G643 here (always round)"."""
    text = "G90 G641 ADIS=0.5 F3000\nG1 X0 Y0\nG1 X50\nG1 X100 Y0.436330\n"
    _, _, path = rounded(text, machine(IGNORE_OVL_FACTOR_FOR_ADIS=True))
    assert reasons(path) == ["rounded"]


def test_g643_ignores_the_overload_factor():
    """spec 5.5: G643 "The overload factor is never taken into account"."""
    text = "G90 G643 CTOL=0.05 F3000\nG1 X0 Y0\nG1 X50\nG1 X100 Y0.436330\n"
    _, _, path = rounded(text, machine())
    assert reasons(path) == ["rounded"]


def test_every_reason_is_reachable_words():
    assert len(set(ROUNDING_REASONS)) == len(ROUNDING_REASONS)


# ------------------------------------------------------------------ consequences
def test_rows_list_every_block_once_and_the_rounding_belongs_to_the_corner_block():
    prog, mach, path = rounded(square("G642", "CTOL=0.05"))
    assert [s.block for s in path.blocks] == [b.index for b in prog.blocks]
    res = plan(prog, mach, path=path)
    assert [r.block for r in res.blocks] == [b.index for b in prog.blocks]
    for k in np.flatnonzero(path.kind == ROUNDING):
        span = next(s for s in path.blocks if s.block == path.block[k])
        assert span.first_segment <= k < span.first_segment + span.n_segments
        # the corner is the end of that block's programmed line
        assert span.n_segments == 2 and k == span.first_segment + 1


@pytest.mark.parametrize("mode", ["G642 CTOL=0.05", "G641 ADIS=0.5"])
def test_rounded_contour_is_faster_than_g64_and_keeps_the_limits(mode):
    """Issue 13 item 3: with rounding, a contour is faster than under G64 and the
    heuristic never breaks its own limits on the rounded path (check_profile)."""
    prog64, mach, _ = rounded(square("G64"), machine())
    r64 = plan(prog64, mach)
    prog, _, path = rounded(square(mode), mach)
    assert path.rounding.inserted.all()
    res = plan(prog, mach, path=path)
    assert res.time_s < r64.time_s
    rep = check_profile(path, mach.limits, res.profile)
    assert rep.ok(BOUND_SETS[res.bound_set]), rep


def test_overload_factor_one_rounds_where_g64_must_stop():
    """With MAX_ACCEL_OVL_FACTOR = 1.0 G64 stops at every corner; G641 rounds it."""
    d = copy.deepcopy(BASE)
    for ax in d["axis"].values():
        ax["MAX_ACCEL_OVL_FACTOR"] = 1.0
    mach = machine_from_dict(d)
    prog64 = parse_text(square("G64"))
    prog = parse_text(square("G641", "ADIS=0.5"))
    path = build_path(prog, mach)
    assert path.rounding.inserted.all()
    assert plan(prog, mach, path=path).time_s < plan(prog64, mach).time_s


def test_g64_programs_are_unchanged():
    prog = parse_text(square("G64"))
    mach = load_machine()
    assert build_path(prog, mach).rounding is None


# ------------------------------------------------------------------ RND / RNDM
def test_rnd_inserts_a_tangent_arc_of_the_programmed_radius():
    """spec 5.1: rounding "does not replace RND/RNDM"; RND (non-modal) rounds the corner
    at the end of its block with a tangent arc of the programmed radius (issue 13)."""
    text = "G90 G64 F3000\nG1 X0 Y0\nG1 X50 RND=2\nG1 Y50\nG1 X0\n"
    _, _, path = rounded(text)
    t = path.rounding
    assert t.mode == ("RND",) and list(t.inserted) == [True]
    np.testing.assert_allclose(t.radius_mm, 2.0, rtol=1e-12)
    np.testing.assert_allclose(t.distance_mm, 2.0, rtol=1e-12)       # 2 tan(45 deg)
    np.testing.assert_allclose(t.deviation_mm, 2.0 * (math.sqrt(2) - 1), rtol=1e-12)
    _check_tangent_continuity(path)


def test_rndm_is_modal_until_rndm_0():
    text = ("G90 G64 F3000\nG1 X0 Y0 RNDM=1\nG1 X50\nG1 Y50\nG1 X0 RNDM=0\nG1 Y0\n"
            "G1 X-10\n")
    _, _, path = rounded(text)
    t = path.rounding
    assert t.mode == ("RNDM", "RNDM") and list(t.inserted) == [True, True]
    # a 60 degree deflection: d = R tan(30 deg)
    text = "G90 F3000\nG1 X0 Y0 RNDM=1\nG1 X50\nG1 X75 Y43.30127018922193\n"
    _, _, path = rounded(text)
    np.testing.assert_allclose(path.rounding.distance_mm, math.tan(math.pi / 6), rtol=1e-9)


def test_negative_rnd_is_bad_input():
    from reference.core.errors import NCSyntaxError
    with pytest.raises(NCSyntaxError, match="RND=-1"):
        parse_text("G1 X10 RND=-1\n")


# ------------------------------------------------------------------ seeded polylines
@pytest.mark.parametrize("seed", range(6))
def test_seeded_polylines_round_into_a_continuous_path(seed):
    """Random corners (1..179 degrees, some reversals and G0 blocks), every mode: the
    rounded path is continuous in position and tangent at every rounding, each block
    keeps one span, no line is shortened by more than its length, and the rounded path
    is never longer than the programmed one."""
    rng = np.random.default_rng(seed)
    modes = ["G641 ADIS=0.3 ADISPOS=0.6", "G642", "G642 CTOL=0.1", "G643", "G645",
             "G644", "G64 RNDM=0.4"]
    lines = [f"G90 BRISK {modes[seed % len(modes)]} F5000", "G1 X0 Y0 Z0"]
    x = y = z = 0.0
    for _ in range(60):
        x, y = x + rng.uniform(-3, 3), y + rng.uniform(-3, 3)
        if rng.random() < 0.1:
            z += rng.uniform(-1, 1)
        word = "G0" if rng.random() < 0.15 else "G1"
        lines.append(f"{word} X{x:.4f} Y{y:.4f} Z{z:.4f}")
    prog = parse_text("\n".join(lines) + "\n")
    mach = machine(IGNORE_OVL_FACTOR_FOR_ADIS=True)
    path = build_path(prog, mach)
    programmed = build_path(parse_text("\n".join(lines).replace(modes[seed % len(modes)],
                                                                "G64") + "\n"), mach)
    assert [s.block for s in path.blocks] == [b.index for b in prog.blocks]
    _check_tangent_continuity(path)
    for k in range(path.n_segments - 1):
        np.testing.assert_allclose(path.segment(k).end, path.segment(k + 1).start,
                                   atol=1e-9)
    assert path.total_length <= programmed.total_length + 1e-9
    t = path.rounding
    assert t is not None and t.n > 0
    assert t.inserted.any() and np.all(t.distance_mm[t.inserted] > 0)


def test_small_adis_caps_the_speed_at_one_ipo_cycle_per_rounding_block():
    """spec 5.3: "every block, the rounding block included, needs at least one
    interpolation point, so the path velocity is limited to about ADIS / T_ipo". A 20
    degree corner, ADIS = 0.01 mm: R = 0.01 / tan(10 deg), the rounding is R * 20 deg =
    0.0198 mm long, so at most 0.0198 mm / 4 ms = 4.95 mm/s inside it (the centripetal
    limit, sqrt(0.75 * 2000 * R), is near 9 mm/s and does not bind)."""
    d = copy.deepcopy(BASE)
    for ax in d["axis"].values():
        ax["MAX_ACCEL_OVL_FACTOR"] = 1.0          # G64 would stop: the rounding is taken
    mach = machine_from_dict(d)
    y = 50.0 * math.tan(math.radians(20.0))
    prog = parse_text(f"G90 G641 ADIS=0.01 BRISK F3000\nG1 X0 Y0\nG1 X50\nG1 X100 Y{y!r}\n")
    path = build_path(prog, mach)
    assert list(path.rounding.inserted) == [True]
    R = 0.01 / math.tan(math.radians(10.0))
    length = R * math.radians(20.0)
    assert path.rounding.length_mm[0] == pytest.approx(length, rel=1e-9)
    k = int(np.flatnonzero(path.kind == ROUNDING)[0])
    res = plan(prog, mach, path=path)
    s = np.linspace(path.s_breaks[k], path.s_breaks[k + 1], 201)
    v = res.profile.state(res.profile.time_at(s))[1]
    assert v.max() <= length / 0.004 * (1 + 1e-9)
    assert v.max() == pytest.approx(length / 0.004, rel=1e-6)


@pytest.mark.parametrize("mode, smoothing, expect", [
    # spec 5.6 "1xxx: the rounding distance (ADIS/ADISPOS) is given", "5xxx: like
    # 1xxx, but the distance is fully used where possible": at F3000 the 3xxx rounding
    # (d = 1.667 mm, test_g644_digits_0_1_use_the_limit_only_where_the_dynamics_need_it)
    # is larger than ADIS, so both use it
    ("G644 ADIS=0.4", 1000, ("distance", 0.4)),
    ("G644 ADIS=0.4", 5000, ("distance", 0.4)),
    # "0xxx: keep each axis within MD33100 COMPRESS_POS_TOL", "4xxx: like 0xxx, but the
    # tolerance is fully used": the same reason
    ("G644 ADIS=0.4", 0, ("deviation", 0.01 * math.sqrt(2))),
    ("G644 ADIS=0.4", 4000, ("deviation", 0.01 * math.sqrt(2))),
    # 6xxx..9xxx are not documented: named
    ("G644 ADIS=0.4", 6000, ("reason", "G644 SMOOTHING_MODE digit not documented")),
    # spec 5.4 table, value 4 [M]: "rounding distance from ADIS/ADISPOS, as for G641"
    ("G642 ADIS=0.3", 40, ("distance", 0.3)),
    ("G643 ADIS=0.3", 4, ("distance", 0.3)),
    # units digit configures G643, tens digit G642: 10 leaves G643 on MD33100
    ("G643", 10, ("deviation", 0.01 * math.sqrt(2))),
])
def test_smoothing_mode_digits(mode, smoothing, expect):
    """spec 5.9 "MD20480 SMOOTHING_MODE digit map": G643 by the units digit, G642 by the
    tens digit, G644 by the thousands digit."""
    _, _, path = rounded(square(mode), machine(1.0, SMOOTHING_MODE=smoothing))
    t = path.rounding
    what, value = expect
    if what == "reason":
        assert reasons(path) == [value] * 3
    elif what == "distance":
        np.testing.assert_allclose(t.distance_mm, value, rtol=1e-12)
    else:
        np.testing.assert_allclose(t.deviation_mm, value, rtol=1e-12)


@pytest.mark.parametrize("digit, expect_d", [
    (0, "dyn"), (4, "tol"), (1, "dyn"), (5, "adis"), (3, "dyn")])
def test_g644_digits_0_1_use_the_limit_only_where_the_dynamics_need_it(digit, expect_d):
    """spec 5.6 (MD20480 thousands digit): "0xxx: Keep each axis within MD33100
    COMPRESS_POS_TOL; if the dynamics allow, the tolerance is not fully used"; "4xxx:
    Like 0xxx, but the tolerance is fully used where possible (the axis then stays
    below its maximum dynamics)"; "1xxx: The rounding distance (ADIS/ADISPOS) is
    given"; "5xxx: Like 1xxx, but the distance is fully used where possible"; 5.8:
    "0xxx: same T_i [as 3xxx, the minimum dynamic time], but reduce v until e_i(T_i) <=
    tol_i. The tolerance is then usually not fully used ... 4xxx: ... use the full
    tolerance, with lower acceleration ... 1xxx / 5xxx: as 0xxx/4xxx, but the
    constraint is the rounding distance". So 0xxx/1xxx round as 3xxx where that is
    within the tolerance / ADIS, 4xxx/5xxx always use it.

    By hand, BRISK, the 90 degree corners of the square at F60 (v = 1 mm/s, T_ipo =
    4 ms, A = 2000 mm/s^2): the 3xxx arc is R = max(v^2 / (0.75 A), v T_ipo / theta) =
    max(6.7e-4, 0.004 / (pi/2)) = 2.546e-3 mm (its one IPO cycle binds), d = R
    tan(45 deg) = R, deviating by d tan(22.5 deg) = 1.05e-3 mm per corner, below the
    tolerance (|C - M| = 0.01 sqrt(2), d = 0.0341 mm) and ADIS = 0.4 mm. 0xxx, 1xxx and
    3xxx give the dynamic rounding, 4xxx the tolerance's, 5xxx ADIS."""
    text = square("G644 ADIS=0.4").replace("F3000", "F60")
    _, _, path = rounded(text, machine(1.0, SMOOTHING_MODE=1000 * digit))
    t = path.rounding
    assert t.inserted.all()
    r_dyn = max(1.0 / (0.75 * 2000.0), 0.004 / (math.pi / 2))
    assert r_dyn == pytest.approx(2.546e-3, rel=1e-3)
    d = {"dyn": r_dyn, "tol": 0.01 * math.sqrt(2) / math.tan(math.pi / 8),
         "adis": 0.4}[expect_d]
    np.testing.assert_allclose(t.distance_mm, d, rtol=1e-12)
    if expect_d == "dyn":
        assert (t.deviation_mm < 0.01 * math.sqrt(2) / 10).all()    # not fully used


# the hand numbers of the G644 2xxx/3xxx tests: the test machine at F3000 round a 90
# degree XY corner (t1 = X, t2 = Y: plane weights rho_X = rho_Y = 1)
V_F3000 = 50.0                  # mm/s
A_TEST, J_TEST = 2000.0, 40000.0  # MAX_AX_ACCEL 2 m/s^2, MAX_AX_JERK 40 m/s^3


@pytest.mark.parametrize("accel", ["BRISK", "SOFT"])
def test_g644_3xxx_rounds_with_the_maximum_dynamics_at_the_path_velocity(accel):
    """B1 excerpt (G644, thousands digit 3xxx): "Any axis that has a velocity jump at a
    corner traverses around the corner with the maximum possible dynamic response
    (maximum acceleration and maximum jerk). SOFT: The jerk is limited. BRISK: ... only
    the acceleration is limited ... neither the maximum deviations nor the rounding
    distance are checked. The resulting deviations or rounding distances are determined
    exclusively by the dynamic limits of the respective axis and the current path
    velocity." By hand, with the shares the heuristic grants a curved segment (0.75 of
    A for the centripetal part, 0.5 of J for the jerk): BRISK arc R = v^2 / (0.75 A);
    SOFT clothoid pair of pieces L = max(theta v^2 / (0.75 A), sqrt(theta sqrt(1 +
    theta^2) v^3 / (0.5 J))). The tolerance (MD33100 0.01 mm) and ADIS are ignored; the
    rounding is crossed at the programmed speed."""
    from reference.core.geometry import clothoid_pair_shape
    theta = math.pi / 2
    _, _, path = rounded(square("G644 ADIS=0.1", accel), machine(1.0, SMOOTHING_MODE=3000))
    t = path.rounding
    assert t.inserted.all()
    if accel == "BRISK":
        R = V_F3000 ** 2 / (0.75 * A_TEST)
        np.testing.assert_allclose(t.radius_mm, R, rtol=1e-12)
        np.testing.assert_allclose(t.distance_mm, R * math.tan(theta / 2), rtol=1e-12)
    else:
        L = max(theta * V_F3000 ** 2 / (0.75 * A_TEST),
                math.sqrt(theta * math.sqrt(1 + theta ** 2) * V_F3000 ** 3 / (0.5 * J_TEST)))
        assert L == pytest.approx(4.2757, abs=1e-4)        # the jerk decides
        np.testing.assert_allclose(t.length_mm, 2 * L, rtol=1e-12)
        d_1, _ = clothoid_pair_shape(np.array([theta]))
        np.testing.assert_allclose(t.distance_mm, L * d_1[0], rtol=1e-12)
    assert (t.deviation_mm > 0.01 * math.sqrt(2)).all()    # the tolerance is not checked
    np.testing.assert_allclose(t.v_round, V_F3000, rtol=1e-12)


@pytest.mark.parametrize("accel", ["BRISK", "SOFT"])
def test_g644_2xxx_rounding_lasts_one_period_of_the_lowest_frequency(accel):
    """B1 excerpt (G644, 2xxx): "Input the maximum possible frequencies of each axis in
    the rounding area using ... MD32440 LOOKAH_FREQUENCY. The rounding area is defined so
    that no frequencies in excess of the specified maximum can occur while the rounding
    motion is in progress ... the rounding distance is limited to a minimum value, which
    results from the maximum permissible excitation frequency and the current path
    velocity"; spec 5.8 "2xxx: T_i >= 1/f_i". By hand: X at 20 Hz, Y at 10 Hz (Z at 1 Hz
    has no velocity jump at an XY corner and does not count): the rounding lasts 1/10 s
    at F3000, 5 mm of path, whatever the shape."""
    d = copy.deepcopy(BASE)
    d["channel"].update(acceleration_mode=accel, SMOOTHING_MODE=2000)
    for ax in d["axis"].values():
        ax["MAX_ACCEL_OVL_FACTOR"] = 1.0
    d["axis"]["Y"]["LOOKAH_FREQUENCY"] = 10.0
    d["axis"]["Z"]["LOOKAH_FREQUENCY"] = 1.0
    _, _, path = rounded(square("G644"), machine_from_dict(d))
    t = path.rounding
    assert t.inserted.all()
    np.testing.assert_allclose(t.length_mm, V_F3000 / 10.0, rtol=1e-12)
    assert t.g2.all() == (accel == "SOFT")


def test_g644_2xxx_and_3xxx_keep_the_half_block_clamp():
    """B1 excerpt: "Any further limitations are also effective in addition to this
    rounding distance limitation. The rounding distance cannot exceed half the length of
    the original participating blocks." On the 50 mm square both are cut to 25 mm: 3xxx
    at F30000 (arc R = v^2 / (0.75 A) = 166.7 mm), 2xxx at F3000 with every axis at 1 Hz
    (50 mm of arc, d = 50 / (pi/2) = 31.8 mm)."""
    slow = copy.deepcopy(BASE)
    slow["channel"].update(SMOOTHING_MODE=2000)
    for ax in slow["axis"].values():
        ax.update(MAX_ACCEL_OVL_FACTOR=1.0, LOOKAH_FREQUENCY=1.0)
    for text, mach in ((square("G644").replace("F3000", "F30000"),
                        machine(1.0, SMOOTHING_MODE=3000)),
                       (square("G644"), machine_from_dict(slow))):
        _, _, path = rounded(text, mach)
        t = path.rounding
        assert t.clamped.all()
        np.testing.assert_allclose(t.distance_mm, 25.0, rtol=1e-12)


def test_g0_tolerance_factor_widens_the_g642_tolerance():
    """spec 5.7 "G0 blocks use a tolerance multiplied by MD20560 G0_TOLERANCE_FACTOR (e.g.
    factor 3 x COMPRESS_POS_TOL)"."""
    text = "G90 G642 F60\nG0 X0 Y0\nG0 X50\nG0 Y50\nG1 X0\n"
    # G0 at 60 mm/min: below the speed of the roundings (see ``machine``)
    _, _, path = rounded(text, machine(1.0, velo=60.0, G0_TOLERANCE_FACTOR=3.0))
    np.testing.assert_allclose(path.rounding.deviation_mm[0], 3 * 0.01 * math.sqrt(2),
                               rtol=1e-12)
    np.testing.assert_allclose(path.rounding.deviation_mm[1], 0.01 * math.sqrt(2), rtol=1e-12)


def test_the_rounding_speed_estimate_uses_the_planner_default_centripetal_share():
    from reference.planner.parameters import DEFAULT_PARAMETERS
    from reference.rounding import CENTRIPETAL_SHARE, JERK_VELOCITY_SHARE
    assert CENTRIPETAL_SHARE == DEFAULT_PARAMETERS.arc_centripetal_share
    assert JERK_VELOCITY_SHARE == DEFAULT_PARAMETERS.arc_jerk_velocity_share


def test_soft_corner_with_a_faster_but_longer_rounding_stays_sharp_on_the_bundled_machine(
        monkeypatch):
    """spec 5.2 group 2 "Rounding would slow the program down", on the bundled SOFT
    machine (A = 2 m/s^2, J = 40 m/s^3, overload factor 1.2, T_ipo = 4 ms): a 90 degree
    G642 CTOL=0.05 corner at F3000. G64 passes it at the axis jump A (1.2 - 1) T_ipo =
    1.6 mm/s (96 mm/min); the clothoid pair that deviates by 0.05 mm (pieces L =
    0.05 / e_1(pi/2)) is crossed faster, at the jerk limit cbrt(0.5 J / |q3|), |q3| =
    theta sqrt(1 + theta^2) / L^2 (5.15 mm/s, 309 mm/min), but over 0.28 mm, and both
    ramp almost the same way down from 50 mm/s. Reported as a suspected bug of the
    decision; planned both ways by the heuristic, the rounded contour is the slower one
    (0.04 s per corner), so leaving the corners sharp is right."""
    from reference import rounding as rounding_stage
    from reference.core.geometry import clothoid_pair_shape
    text = square("G642", "CTOL=0.05").replace("G17", "G17 SOFT")
    prog = parse_text(text)
    mach = load_machine()
    path = build_path(prog, mach)
    t = path.rounding
    assert reasons(path) == ["rounding would be slower than G64"] * 3
    theta = math.pi / 2
    np.testing.assert_allclose(t.v_g64, 2000.0 * 0.2 * 0.004, rtol=1e-9)
    _, e_1 = clothoid_pair_shape(np.array([theta]))
    L = 0.05 / e_1[0]
    v_jerk = (0.5 * 40000.0 * L * L / (theta * math.sqrt(1 + theta * theta))) ** (1 / 3)
    assert v_jerk == pytest.approx(309.0 / 60.0, rel=1e-3)
    np.testing.assert_allclose(t.v_round, v_jerk, rtol=1e-9)
    # the same corners rounded (the stage told that the rounding costs nothing; even a
    # G64 stop would cost less than this rounding) and planned: slower than sharp
    loss = rounding_stage.corner_time_loss
    monkeypatch.setattr(rounding_stage, "corner_time_loss", lambda *a: np.where(
        np.asarray(a[7]) > 0, -np.inf, loss(*a)))
    forced = build_path(prog, mach)
    assert forced.rounding.inserted.all()
    np.testing.assert_allclose(forced.rounding.deviation_mm, 0.05, rtol=1e-9)
    t_sharp = plan(prog, mach, path=path).time_s
    t_round = plan(prog, mach, path=forced).time_s
    assert t_round > t_sharp + 3 * 0.03


def test_a_marginal_rounding_that_would_lose_time_is_not_inserted():
    """spec 5.2 group 2 "Rounding would slow the program down": BRISK, MD33100 0.01 mm,
    90 degree corners at F3000: the arc (R = 0.034 mm) is crossed at sqrt(0.75 * 2000 *
    R) = 7.2 mm/s against 1.6 mm/s by G64, yet crawling 0.054 mm at 7.2 mm/s costs more
    than it saves. Planned both ways, G64 is the faster, and that is what is kept."""
    mach = machine()
    prog = parse_text(square("G642"))
    path = build_path(prog, mach)
    assert reasons(path) == ["rounding would be slower than G64"] * 3
    # the same roundings, inserted (as on a machine where G64 must stop) and planned on
    # this machine: slower than the sharp corners
    t_sharp = plan(prog, mach, path=path).time_s
    rounded_path = build_path(prog, machine(ovl=1.0))
    assert rounded_path.rounding.inserted.all()
    assert plan(prog, mach, path=rounded_path).time_s > t_sharp


@pytest.mark.parametrize("mode", ["G641 ADIS=0.05", "G642", "G645"])
def test_ignore_ovl_factor_for_adis_rounds_where_rounding_loses_time(mode):
    """spec 4.3: "A transition is rounded only if it cannot be passed at G64 speed
    without a reduction. Rounding would otherwise lengthen the program. ... This check
    applies to G641/G642 only. G643 ignores the overload factor. Setting MD20490
    IGNORE_OVL_FACTOR_FOR_ADIS = TRUE makes G641/G642 behave like G643 here (always
    round)"; 5.8: "Insert the rounding only if v_corner_G64 < min(F, v_round), unless
    MD20490 = TRUE or the mode is G643" (G645 "at corners rounds like G642", 5.7). The
    corners of the previous test (not worth rounding on this machine) are rounded with
    MD20490 = TRUE, and the program is then longer in time, as 4.3 says it would be:
    the 90 degree arcs deviate by MD33100 per axis (|C - M| = 0.01 sqrt(2)) or, G641,
    start ADIS = 0.05 mm before the corner."""
    prog = parse_text(square(mode))
    sharp = build_path(prog, machine())
    assert not sharp.rounding.inserted.any()
    forced = build_path(prog, machine(IGNORE_OVL_FACTOR_FOR_ADIS=True))
    assert reasons(forced) == ["rounded"] * 3
    t = forced.rounding
    if mode.startswith("G641"):
        np.testing.assert_allclose(t.distance_mm, 0.05, rtol=1e-12)
    else:
        np.testing.assert_allclose(t.deviation_mm, 0.01 * math.sqrt(2), rtol=1e-12)
    mach = machine(IGNORE_OVL_FACTOR_FOR_ADIS=True)
    assert plan(prog, mach, path=forced).time_s > plan(prog, mach, path=sharp).time_s


def test_g643_rounds_where_rounding_loses_time():
    """spec 5.5 (G643): "The overload factor is never taken into account"; 5.8: "...
    unless MD20490 = TRUE or the mode is G643": the corners G642 leaves sharp on this
    machine (previous tests) are rounded by G643 with the same tolerance (MD33100, the
    units digit 0: |C - M| = 0.01 sqrt(2) on the 90 degree corners)."""
    _, _, path = rounded(square("G643"), machine())
    assert reasons(path) == ["rounded"] * 3
    np.testing.assert_allclose(path.rounding.deviation_mm, 0.01 * math.sqrt(2), rtol=1e-12)


@pytest.mark.parametrize("mode, spanned", [("G641 ADIS=0.5", None), ("G642", 8)])
def test_ignore_ovl_keeps_no_rounding_block_between_two_very_short_blocks(mode, spanned):
    """spec 5.2 group 2: "Rounding would slow the program down: between two very short
    blocks (each block costs at least one IPO cycle, so an extra block could double the
    time)"; 5.8 "If the blocks are too short (... less than one IPO cycle per block),
    fall back to G64 [S1]" -- not waived by MD20490, which waives the overload check
    only. By hand: 0.01 mm blocks at F3000 (50 mm/s) take 0.2 ms, less than one 4 ms
    IPO cycle, so both blocks beside the corner are very short: G641 (one-block clamp,
    d = 0.005 mm) keeps the corner sharp and names it. G642's window reaches across
    the short blocks (d = 0.0341 mm, 8 blocks: spanned ones are not interpolated, one
    rounding block replaces six), so no block is added and it is rounded."""
    steps = ("G17 G90 {} F3000\nG1 X0 Y0\n" + "\n".join(
        [f"X{0.01 * i:.2f}" for i in range(1, 11)] + [f"Y{0.01 * i:.2f}" for i in range(1, 11)])
        + "\n")
    _, _, path = rounded(steps.format(mode), machine(IGNORE_OVL_FACTOR_FOR_ADIS=True))
    t = path.rounding
    corner = [i for i in range(t.n) if t.reason_text(i) != "tangential transition"]
    assert len(corner) == 1
    i = corner[0]
    assert 0.01 <= 50.0 * 0.004
    if spanned is None:
        assert t.reason_text(i) == (
            "rounding would slow the program down (between two very short blocks)")
    else:
        assert t.reason_text(i) == "rounded" and t.blocks_spanned[i] == spanned
