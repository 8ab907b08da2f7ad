"""Tangential control (reference/tangential.py): TANG/TANGON/TANGOF/TLIFT.

The tangent angles the tests expect are computed from the sampled X/Y positions by
finite differences (or written down by hand), never from the stage. Documented
properties: sinumerik-model section 10 and the T3 excerpt
(manual-excerpts/t3-802dsl-tangential-control.txt).
"""

from __future__ import annotations

import copy
import math
import tomllib
from importlib import resources

import numpy as np
import pytest

from reference import build_path, parse_text, plan
from reference.core.errors import MachineDataError, PathError
from reference.core.geometry import KIND_CODES
from reference.machine import load_machine, machine_from_dict
from reference.prepare import path_stages

TANG = "TANG(C, X, Y, {k})\nTANGON(C, {off})\n"


def _machine(eps: float | None = None):
    d = copy.deepcopy(tomllib.loads(resources.files("reference.machines")
                                    .joinpath("default.toml").read_text()))
    if eps is not None:
        d["axis"]["C"]["EPS_TLIFT_TANG_STEP"] = eps
    return machine_from_dict(d)


def _path(text: str, machine=None):
    prog = parse_text(text, "t.mpf")
    return prog, build_path(prog, machine or load_machine())


def _c(path) -> int:
    return path.axes.index("C")


def _ends(path, i):
    q0 = path.evaluate(path.s_breaks[i], segment=np.array([i]))[0][0]
    q1 = path.evaluate(path.s_breaks[i + 1], segment=np.array([i]))[0][0]
    return q0, q1


def _segs(prog, path, line):
    idx = {b.index for b in prog.blocks if b.line == line}
    return [i for i in range(path.n_segments) if int(path.block[i]) in idx]


def _kind(path, i) -> str:
    return KIND_CODES[int(path.kind[i])]


def test_on_lines_the_axis_reaches_each_tangent_by_the_end_of_the_block():
    """Without TLIFT "the following axis reaches its new alignment synchronously with the
    target position of the leading axes" (T3): at every block end C = tangent angle."""
    prog, path = _path(TANG.format(k=1, off=0) + "G1 X10 Y0 F3000\nX10 Y10\nX0 Y20\n"
                       "X-10 Y20\nM30\n")
    c = _c(path)
    expect = {3: 0.0, 4: 90.0, 5: 135.0, 6: 180.0}          # atan2 of each move, by hand
    for line, angle in expect.items():
        (i,) = _segs(prog, path, line)
        assert _ends(path, i)[1][c] == pytest.approx(angle, abs=1e-9)
    assert "tlift" not in [_kind(path, i) for i in range(path.n_segments)]
    # the axis moves linearly over the block after each corner (a linear component)
    (i,) = _segs(prog, path, 5)
    assert path.d[i, c] == pytest.approx(45.0 / path.length[i])


@pytest.mark.parametrize("k, off", [(1.0, 0.0), (2.0, 15.0), (-1.0, 90.0)])
def test_on_an_arc_the_axis_follows_the_tangent_linearly_in_s(k, off):
    """10: "the following axis tracks the path tangent ... including arcs"; on an arc in
    the leading plane phi is linear in s, so C is too. Checked against the tangent of
    the sampled X/Y points (central differences), with coupling and offset."""
    prog, path = _path(TANG.format(k=k, off=off) + "TLIFT(C)\nG1 X20 Y0 F3000\n"
                       "G3 X20 Y20 Z-4 I0 J10\nG1 X0 Y20\nM30\n")
    c = _c(path)
    (arc,) = [i for i in _segs(prog, path, 5) if path.radius[i] > 0]
    s = np.linspace(path.s_breaks[arc], path.s_breaks[arc + 1], 4001)
    q = path.evaluate(s, segment=np.full(s.size, arc))[0]
    dx, dy = np.gradient(q[:, 0]), np.gradient(q[:, 1])
    phi = np.degrees(np.unwrap(np.arctan2(dy, dx)))
    want = k * phi + off
    want += 360.0 * np.round((q[0, c] - want[0]) / 360.0)      # the axis' branch
    assert np.max(np.abs(q[1:-1, c] - want[1:-1])) < 1e-5       # central differences: O(h^2)
    # exact slope: k * (1/R) in rad/mm -> deg/mm
    assert path.d[arc, c] == pytest.approx(k * math.degrees(1.0 / 10.0) / math.hypot(
        1.0, 4.0 / (10.0 * math.pi)), rel=1e-12)


def test_tlift_inserts_a_block_where_the_path_stops_and_the_axis_turns_alone():
    """T3: "an intermediate block is inserted at any corner whose angle is greater than
    MD37400 ... the rotary axis is moved ... the path velocity of the leading axes is
    zero" -- segment kind tlift, the geometry axes at rest, stops at both ends."""
    prog, path = _path(TANG.format(k=1, off=0) + "TLIFT(C)\nG1 X10 Y0 F3000\nY10\nX0\n"
                       "M30\n")
    c = _c(path)
    segs = _segs(prog, path, 5)
    assert [_kind(path, i) for i in segs] == ["tlift", "line"]
    t = segs[0]
    q0, q1 = _ends(path, t)
    assert np.allclose(q0[:3], q1[:3]) and (q0[c], q1[c]) == pytest.approx((0.0, 90.0))
    assert path.length[t] == pytest.approx(90.0)             # s runs in degrees there
    assert path.stop[t] and path.stop[t + 1]
    assert "TLIFT" in path.stop_reason[t + 1]
    assert np.isinf(path.feed[t])                            # only the axis limits


@pytest.mark.parametrize("eps, tlift", [(5.0, False), (2.0, True)])
def test_tlift_only_above_eps_tlift_tang_step(eps, tlift):
    """MD37400 EPS_TLIFT_TANG_STEP: a 3 degree corner gets a block only below it."""
    a = math.radians(3.0)
    prog, path = _path(TANG.format(k=1, off=0) + "TLIFT(C)\nG1 X10 Y0 F3000\n"
                       f"X{10 + 10 * math.cos(a):.12f} Y{10 * math.sin(a):.12f}\nM30\n",
                       _machine(eps))
    kinds = [_kind(path, i) for i in _segs(prog, path, 5)]
    assert ("tlift" in kinds) == tlift


def test_no_tlift_block_with_g641_rounding():
    """T3: "In blocks with G641 rounding, no intermediate block is generated for the
    following axis with TLIFT"; sinumerik-model 12.5: "TLIFT with G641: no stop at the
    corner"."""
    prog, st = None, None
    text = (TANG.format(k=1, off=0) + "TLIFT(C)\nG641 ADIS=1 G1 X10 Y0 F3000\nY10\nX0\n"
            "M30\n")
    prog = parse_text(text, "t.mpf")
    st = path_stages(prog, load_machine())
    path = st.path
    assert "tlift" not in [_kind(path, i) for i in range(path.n_segments)]
    (i,) = _segs(prog, path, 6)
    assert not path.stop[i]                                  # no stop at the corner
    assert any("rounding" in c.action for c in st.tangential.corners)
    # the same program in G64 stops there
    _, p64 = _path(text.replace("G641 ADIS=1", "G64"))
    assert "tlift" in [_kind(p64, j) for j in range(p64.n_segments)]


def test_hidden_corner_behind_an_infeed_gets_its_block_before_the_next_plane_move():
    """T3 "Hidden corner in space": the projection onto the leading plane counts; "an
    intermediate block is inserted before the block causing the tangential jump". The
    Z move has no tangent in X/Y: the axis keeps its angle there."""
    prog, path = _path(TANG.format(k=1, off=0) + "TLIFT(C)\nG1 X10 Y0 F3000\nZ-5\nY10\n"
                       "M30\n")
    c = _c(path)
    (z,) = _segs(prog, path, 5)
    assert _kind(path, z) == "line" and path.d[z, c] == 0.0
    assert [_kind(path, i) for i in _segs(prog, path, 6)] == ["tlift", "line"]


def test_hidden_corner_of_steep_lines_is_found_in_the_projection():
    """Two steep lines 8 degrees apart in space whose X/Y projections are 90 degrees
    apart: the tangential axis sees the 90 degree step (T3: the projection is
    relevant)."""
    prog, path = _path(TANG.format(k=1, off=0) + "TLIFT(C)\nG1 X1 Z-10 F3000\n"
                       "Y1 Z-20\nM30\n")
    t_in = np.array([1.0, 0.0, -10.0]) / math.sqrt(101.0)
    t_out = np.array([0.0, 1.0, -10.0]) / math.sqrt(101.0)
    assert math.degrees(math.acos(t_in @ t_out)) < 8.1
    assert [_kind(path, i) for i in _segs(prog, path, 5)] == ["tlift", "line"]


def test_tangof_leaves_the_axis_where_it_is():
    prog, path = _path(TANG.format(k=1, off=0) + "G1 X10 Y10 F3000\nTANGOF(C)\nX20 Y10\n"
                       "C10\nM30\n")
    c = _c(path)
    (i,) = _segs(prog, path, 5)
    assert _ends(path, i)[0][c] == pytest.approx(45.0) and path.d[i, c] == 0.0
    (j,) = _segs(prog, path, 6)                 # a programmed position: from 45 to 10
    assert (_ends(path, j)[0][c], _ends(path, j)[1][c]) == pytest.approx((45.0, 10.0))


def test_a_machine_without_the_following_axis_is_bad_input_naming_it():
    prog = parse_text(TANG.format(k=1, off=0) + "G1 X10 F3000\n", "t.mpf")
    with pytest.raises(MachineDataError, match=r"axis\.C.*t\.mpf:2: tangential control "
                                               r"turns axis C.*no limits"):
        build_path(prog, load_machine("linuxcnc_xyz"))


def test_an_arc_outside_the_leading_plane_is_refused_with_its_line():
    with pytest.raises(PathError, match=r"t\.mpf:4: tangential control follows the tangent"):
        _path(TANG.format(k=1, off=0) + "G1 X10 F3000\nG18 G2 X20 Z0 CR=5\nM30\n")


def test_tang_arguments_are_expressions():
    prog = parse_text("R1=2 R2=30\nTANG(C, X, Y, R1)\nTANGON(C, R2/2)\nG1 X1 F60\n", "t.mpf")
    tg = prog.blocks[-1].tangential
    assert (tg.coupling, tg.offset_deg) == (2.0, 15.0)


def test_the_tangential_axis_limits_the_path_speed_on_a_small_arc():
    """The following axis is a real axis of the path: on a circle of radius rho it turns
    at v / rho rad/s, so v <= C_vmax rho (MAX_AX_VELO of C: 50 rev/min = 300 deg/s).
    The heuristic's peak speed on the circle is that cap, by hand: 300 * 2 * pi / 180."""
    m = load_machine()
    prog = parse_text(TANG.format(k=1, off=0) + "G1 X20 Y0 F6000\nG3 X20 Y0 I0 J2 TURN=3\n"
                      "G1 X40\nM30\n", "t.mpf")
    path = build_path(prog, m)
    res = plan(prog, m, path=path)
    cap = 300.0 * 2.0 * math.pi / 180.0
    (row,) = [r for r in res.blocks if r.line == 4]
    assert row.v_peak <= cap * (1 + 1e-6)
    assert row.v_peak >= 0.95 * cap                          # and it runs at it
    assert row.time_s >= row.length_mm / cap


def test_without_tlift_the_corner_speed_accounts_for_the_following_axis():
    """10: without TLIFT "FAxis is a path-synchronous axis: its velocity jump enters the
    G64 overload check". A 90 degree corner before a 10 mm line: C turns 90 degrees over
    that line (9 deg/mm), so crossing the corner at v steps C's velocity by 9 v deg/s;
    the allowance A (ovl - 1) T_ipo of C is 720 deg/s^2 * 0.2 * 0.004 s = 0.576 deg/s,
    hence v <= 0.064 mm/s; without tangential control X and Y allow 1.6 mm/s (by hand,
    default machine: 2 m/s^2, 1.2, 4 ms)."""
    m = load_machine()
    body = "G1 X10 Y0 F3000\nX10 Y10\nM30\n"
    for text, cap in ((TANG.format(k=1, off=0) + body, 0.576 / 9.0), (body, 1.6)):
        prog = parse_text(text, "t.mpf")
        res = plan(prog, m, path=build_path(prog, m))
        (first,) = [r for r in res.blocks if r.line == text.splitlines().index(
            "G1 X10 Y0 F3000") + 1]
        assert first.v_exit == pytest.approx(cap, rel=1e-6)
