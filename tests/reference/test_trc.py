"""Tool radius compensation (reference/trc.py) against hand geometry.

Every distance here is computed by the test itself (point to segment, point to arc, a
2x2 linear solve for line intersections), never by the stage's own helpers. The
documented properties quoted are sinumerik-model section 9, the 840C MD6 excerpt
(manual-excerpts/840c-md6-trc-intersection.txt) and LinuxCNC's rs274ngc cutter
compensation (convert_straight_comp1/2, convert_arc_comp2).
"""

from __future__ import annotations

import copy
import math
import tomllib
from importlib import resources

import numpy as np
import pytest

from reference import build_path, parse_text
from reference.core.errors import PathError
from reference.core.geometry import KIND_CODES
from reference.machine import load_machine, machine_from_dict
from reference.prepare import path_stages

R = 5.0          # tool radius of most cases, mm
TOL = 1e-9       # geometric agreement, mm (float64 on coordinates of 100 mm: 1e-14)
HEADER = "$TC_DP6[1,1]=5\nT1 D1\n"


def _machine(**channel):
    d = tomllib.loads(resources.files("reference.machines").joinpath("default.toml")
                      .read_text())
    d = copy.deepcopy(d)
    d["channel"].update(channel)
    return machine_from_dict(d)


def _path(text: str, machine=None, dialect: str | None = None, name: str = "t.mpf"):
    prog = parse_text(text, name, dialect=dialect) if dialect else parse_text(text, name)
    return prog, build_path(prog, machine or load_machine())


def _stages(text: str, machine=None, dialect: str | None = None, name: str = "t.mpf"):
    prog = parse_text(text, name, dialect=dialect) if dialect else parse_text(text, name)
    return prog, path_stages(prog, machine or load_machine())


def _segments_of_lines(prog, path, lines) -> list[int]:
    want = {b.index for b in prog.blocks if b.line in set(lines)}
    return [i for i in range(path.n_segments) if int(path.block[i]) in want]


def _sample(path, segs, n=400) -> np.ndarray:
    """Points (N, n_axes) along the given segments, ends included."""
    pts = []
    for i in segs:
        s = np.linspace(path.s_breaks[i], path.s_breaks[i + 1], n)
        pts.append(path.evaluate(s, segment=np.full(n, i))[0])
    return np.vstack(pts)


def _dist_to_segments(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of points p (N, 2) to the union of segments a[k] -> b[k] (K, 2)."""
    d = b - a
    t = np.clip(np.einsum("nkj,kj->nk", p[:, None, :] - a[None], d) / np.sum(d * d, axis=1),
                0.0, 1.0)
    foot = a[None] + t[..., None] * d[None]
    return np.min(np.linalg.norm(p[:, None, :] - foot, axis=2), axis=1)


def _kinds(path, segs) -> list[str]:
    return [KIND_CODES[int(path.kind[i])] for i in segs]


def _continuous(path) -> bool:
    q0 = path.evaluate(path.s_breaks[:-1], segment=np.arange(path.n_segments))[0]
    q1 = path.evaluate(path.s_breaks[1:], segment=np.arange(path.n_segments))[0]
    return bool(np.all(np.abs(q0[1:] - q1[:-1]) <= TOL))


RECT = [(50, 0), (100, 0), (100, 50), (0, 50), (0, 0), (60, 0)]   # once round, overlapping


def _rect_program(mode: str, side: str = "G42", extra: str = "") -> str:
    moves = "\n".join(f"G1 X{x} Y{y}" for x, y in RECT[1:])
    return (HEADER + f"G0 X50 Y-20\n{side} {mode} {extra} G1 X50 Y0 F3000\n{moves}\n"
            "G40 G1 X50 Y-20\nM30\n")


def _rect_distance(p: np.ndarray) -> np.ndarray:
    v = np.array([(0, 0), (100, 0), (100, 50), (0, 50)], float)
    return _dist_to_segments(p, v, np.roll(v, -1, axis=0))


# ============================================================= the rectangle
def test_rectangle_g42_g450_every_point_is_exactly_r_from_the_contour():
    """Issue 14 item 2 and sinumerik-model 9 (G450: "the tool centre travels on a
    transition circle with the tool radius around the corner")."""
    prog, path = _path(_rect_program("G450"))
    contour_lines = range(5, 10)           # the five contour blocks (approach 4, retract 10)
    segs = _segments_of_lines(prog, path, contour_lines)
    d = _rect_distance(_sample(path, segs)[:, :2])
    assert np.max(np.abs(d - R)) <= TOL
    # G42 on a counter-clockwise rectangle: the tool is outside, one circle per corner
    assert _kinds(path, segs).count("trc") == 4
    assert _continuous(path)


def test_rectangle_g42_g451_is_never_nearer_than_r_and_reaches_the_intersection():
    """G451: "moves to the intersection of the two equidistant paths"; at 90 degree
    corners (below CUTCOM_CORNER_LIMIT = 100) the tool centre is r sqrt 2 from the
    corner and nowhere nearer than r to the contour."""
    prog, path = _path(_rect_program("G451"))
    segs = _segments_of_lines(prog, path, range(5, 10))
    pts = _sample(path, segs)[:, :2]
    d = _rect_distance(pts)
    assert d.min() >= R - TOL
    assert d.max() == pytest.approx(R * math.sqrt(2), abs=TOL)
    assert "trc" not in _kinds(path, segs)
    corners = np.array([(100, 0), (100, 50), (0, 50), (0, 0)], float)
    for c in corners:           # each corner's intersection point is on the path
        apex = c + R * np.sign(c - (50, 25))
        assert np.min(np.linalg.norm(pts - apex, axis=1)) <= TOL


def test_g41_inside_the_rectangle_takes_the_intersections_of_inside_corners():
    """Inside corners: always the intersection of the equidistants (sinumerik-model 9)."""
    prog, path = _path(_rect_program("G450", side="G41"))
    segs = _segments_of_lines(prog, path, range(5, 10))
    pts = _sample(path, segs)[:, :2]
    assert np.max(np.abs(_rect_distance(pts) - R)) <= TOL     # inside: exactly r as well
    assert "trc" not in _kinds(path, segs)
    for apex in [(95, 5), (95, 45), (5, 45), (5, 5)]:
        assert np.min(np.linalg.norm(pts - np.array(apex), axis=1)) <= TOL


# ============================================================= arcs
def test_arcs_stay_arcs_with_radius_r_plus_or_minus_tool_radius():
    """Offsets are exact: "arcs stay arcs with R +- r" (issue item 2). A stadium of two
    lines and two half circles of radius 20 around (0,0) and (60,0), counter-clockwise:
    G41 is inside (R - r), G42 outside (R + r); every point r from the contour."""
    contour = "G1 X60 Y-20\nG3 X60 Y20 CR=20\nG1 X0 Y20\nG3 X0 Y-20 CR=20\nG1 X30 Y-20\n"

    def stadium_distance(p):
        seg = _dist_to_segments(p, np.array([[0.0, 0.0]]), np.array([[60.0, 0.0]]))
        return np.abs(seg - 20.0)

    for side, radius in (("G41", 15.0), ("G42", 25.0)):
        prog, path = _path(HEADER + f"G0 X30 Y0\n{side} G1 X30 Y-20 F2000\n{contour}"
                           "G40 G1 X30 Y0\n")
        segs = _segments_of_lines(prog, path, range(5, 10))
        arcs = [i for i in segs if path.radius[i] > 0]
        assert len(arcs) == 2 and np.allclose(path.radius[arcs], radius, atol=TOL)
        assert np.max(np.abs(stadium_distance(_sample(path, segs)[:, :2]) - R)) <= TOL
        assert _continuous(path)


def test_a_helix_keeps_its_pitch_and_centre_on_the_offset_radius():
    prog, path = _path(HEADER + "G0 X0 Y-20\nG41 G1 X0 Y0 F2000\nG1 X20\n"
                       "G3 X20 Y0 Z-6 I0 J20 TURN=1\nG1 X40\nG40 G1 X40 Y-20\n")
    (h,) = [i for i in range(path.n_segments) if path.radius[i] > 0]
    assert path.radius[h] == pytest.approx(15.0, abs=TOL)          # 20 - 5 (inside)
    sweep = abs(path.omega[h] * path.length[h])
    assert sweep == pytest.approx(4 * math.pi, abs=1e-9)           # TURN=1: two turns
    assert path.length[h] == pytest.approx(math.hypot(15.0 * 4 * math.pi, 6.0), abs=1e-9)
    pts = _sample(path, [h])
    assert np.allclose(np.hypot(pts[:, 0] - 20.0, pts[:, 1] - 20.0), 15.0, atol=TOL)
    assert pts[0, 2] == pytest.approx(0.0) and pts[-1, 2] == pytest.approx(-6.0)


def test_an_arc_smaller_than_the_tool_on_the_inside_is_the_collision_alarm():
    text = HEADER + "G0 X0 Y-20\nG41 G1 X0 Y0 F2000\nG1 X10\nG3 X14 Y4 CR=4\nG1 Y30\nG40 X-20\n"
    with pytest.raises(PathError, match=r"t\.mpf:6: the arc \(radius 4 mm\) is not larger "
                                        r"than the tool radius 5 mm on the inside"):
        _path(text)
    # the same arc with the tool outside (G42) fits: radius 4 + 5
    _, path = _path(text.replace("G41", "G42"))
    assert np.any(np.isclose(path.radius, 9.0))


def test_a_bottleneck_that_reverses_the_compensated_element_names_its_line():
    """A 2 mm step between two inside corners: the offset of the step would run
    backwards (a contour reversal of the tool centre path); the control stops with its
    collision alarm."""
    text = HEADER + "G0 X0 Y-20\nG41 G1 X0 Y0 F2000\nG1 X20\nY2\nX40\nY30\nG40 X-20\n"
    with pytest.raises(PathError, match=r"t\.mpf:6: the compensated path of this block "
                                        r"would vanish or run backwards \(contour reversal\)"):
        _path(text)


def test_a_programmed_reversal_goes_around_the_end_point():
    """A 180 degree reversal is an outside corner: a half circle of radius r around the
    end point, never nearer than r to the contour."""
    prog, path = _path(HEADER + "G0 X0 Y-20\nG41 G1 X0 Y0 F2000\nG1 X30\nX10\n"
                       "G40 G1 X10 Y-20\n")
    segs = _segments_of_lines(prog, path, (5, 6))
    pts = _sample(path, segs)[:, :2]
    d = _dist_to_segments(pts, np.array([[0.0, 0.0]]), np.array([[30.0, 0.0]]))
    assert np.max(np.abs(d - R)) <= TOL
    # round the end point: the apex x = 35 (sampled: 400 points on the half circle miss
    # it by at most r (1 - cos(pi / 798)) = 4e-5 mm)
    assert pts[:, 0].max() == pytest.approx(35.0, abs=5e-5)
    assert _kinds(path, segs).count("trc") == 1


# ============================================================= corner switches
def _corner_program(mode: str, angle_deg: float, extra: str = "", side: str = "G42") -> str:
    """A line along +X to (50, 0), then a line turning left by ``angle_deg`` (with G42
    the tool is right of the path: a left turn is an outside corner)."""
    a = math.radians(angle_deg)
    x, y = 50 + 40 * math.cos(a), 40 * math.sin(a)
    return (HEADER + f"G0 X0 Y-20\n{side} {mode} {extra} G1 X0 Y0 F2000\nG1 X50 Y0\n"
            f"G1 X{x:.12f} Y{y:.12f}\nG40 G1 X{x:.12f} Y-30\n")


def _offset_intersection(angle_deg: float) -> np.ndarray:
    """The intersection of the two right-hand offsets (a 2x2 solve, independent)."""
    a = math.radians(angle_deg)
    t1, t2 = np.array([1.0, 0.0]), np.array([math.cos(a), math.sin(a)])
    n1, n2 = np.array([t1[1], -t1[0]]), np.array([t2[1], -t2[0]])     # right normals
    lam = np.linalg.solve(np.column_stack([t1, -t2]), np.array([50.0, 0.0]) + R * n2 - R * n1)
    return R * n1 + lam[0] * t1


@pytest.mark.parametrize("angle, limit, expect", [
    (90.0, 100.0, "intersection"),       # below MD20210: G451 as programmed
    (135.0, 100.0, "circle"),            # "very pointed": switched to G450
    (135.0, 150.0, "intersection"),      # a larger CUTCOM_CORNER_LIMIT keeps G451
])
def test_g451_switches_to_the_circle_above_cutcom_corner_limit(angle, limit, expect):
    """sinumerik-model 9: "For very pointed outside corners the control switches
    automatically from G451 to G450 ... MD20210 CUTCOM_CORNER_LIMIT"."""
    prog, st = _stages(_corner_program("G451", angle), _machine(CUTCOM_CORNER_LIMIT=limit))
    path = st.path
    segs = _segments_of_lines(prog, path, (5, 6))
    pts = _sample(path, segs)[:, :2]
    if expect == "intersection":
        assert "trc" not in _kinds(path, segs)
        X = _offset_intersection(angle)
        assert np.min(np.linalg.norm(pts - X, axis=1)) <= TOL
    else:
        trc = [i for i in segs if KIND_CODES[int(path.kind[i])] == "trc"]
        assert len(trc) == 1
        arc = _sample(path, trc)[:, :2]
        assert np.max(np.abs(np.linalg.norm(arc - (50, 0), axis=1) - R)) <= TOL
    (corner,) = [c for c in st.trc.corners if c.side == "outside"]
    assert corner.action.startswith(expect) and corner.deflection_deg == pytest.approx(angle)


@pytest.mark.parametrize("limit, inserted", [(10.0, False), (0.0, True)])
def test_below_cutcom_curve_insert_limit_g450_takes_the_intersection(limit, inserted):
    """sinumerik-model 9, MD20230: "max. angle for which the intersection is calculated
    instead of inserting circles"; 0 turns it off."""
    prog, path = _path(_corner_program("G450", 5.0), _machine(CUTCOM_CURVE_INSERT_LIMIT=limit))
    segs = _segments_of_lines(prog, path, (5, 6))
    assert ("trc" in _kinds(path, segs)) == inserted
    pts = _sample(path, segs)[:, :2]
    if not inserted:
        assert np.min(np.linalg.norm(pts - _offset_intersection(5.0), axis=1)) <= TOL


@pytest.mark.parametrize("disc", [0, 25, 50])
def test_disc_puts_the_apex_where_the_model_says(disc):
    """sinumerik-model 9: "DISC: apex distance = r + (DISC/100) r (1/cos(theta/2) - 1)";
    the transition stays tangent to both offsets (G1 continuous)."""
    angle = 90.0
    prog, path = _path(_corner_program("G450", angle, extra=f"DISC={disc}"),
                       _machine(CUTCOM_MAX_DISC=50))
    segs = _segments_of_lines(prog, path, (6,))
    trc = [i for i in segs if KIND_CODES[int(path.kind[i])] == "trc"]
    pts = _sample(path, trc, 2001)[:, :2]
    apex = np.max(np.linalg.norm(pts - (50, 0), axis=1))
    want = R + disc / 100 * R * (1 / math.cos(math.radians(angle) / 2) - 1)
    assert apex == pytest.approx(want, abs=1e-6)
    first = _segments_of_lines(prog, path, (5,))[-1]
    for a, b in zip([first] + segs[:-1], segs):       # tangents equal at every junction
        ta = path.evaluate(path.s_breaks[a + 1], segment=np.array([a]))[1][0]
        tb = path.evaluate(path.s_breaks[b], segment=np.array([b]))[1][0]
        assert np.allclose(ta, tb, atol=1e-12)


def test_disc_above_cutcom_max_disc_names_the_line():
    with pytest.raises(PathError, match=r"t\.mpf:6: DISC=80 is above MD20220 "
                                        r"CUTCOM_MAX_DISC = 50"):
        _path(_corner_program("G450", 90.0, extra="DISC=80"))


# ============================================================= 840C MD6
def _line_arc_program(mode: str, kink_deg: float) -> str:
    """A line along +X to (50, 0), then a counter-clockwise arc of radius 20 whose start
    tangent is turned left by ``kink_deg``: with G42 an outside corner with an arc."""
    a = math.radians(kink_deg)
    t2 = np.array([math.cos(a), math.sin(a)])
    c = np.array([50.0, 0.0]) + 20.0 * np.array([-t2[1], t2[0]])     # centre to the left
    end = c + 20.0 * np.array([math.cos(a), math.sin(a)])               # 90 degrees on
    return (HEADER + f"G0 X0 Y-20\nG42 {mode} G1 X0 Y0 F2000\nG1 X50 Y0\n"
            f"G3 X{end[0]:.12f} Y{end[1]:.12f} I{c[0] - 50:.12f} J{c[1]:.12f}\n"
            f"G40 G1 X{end[0]:.12f} Y{end[1] - 30:.12f}\n")


@pytest.mark.parametrize("mode, md6, expect, n_trc", [
    ("G450", 10.0, "intersection (840C: AC < MD6)", 0),     # AC = 2 r sin(10) = 1.74
    ("G451", 1.0, "circle (840C: G451 -> G450, AC < 2 MD6)", 1),
    ("G451", 0.5, "tangent lines (840C)", 2),
    ("G450", 0.5, "circle (840C)", 1),
])
def test_840c_md6_switches_by_the_distance_ac(mode, md6, expect, n_trc):
    """840C excerpt: "If the distance from A to C is smaller than MD6, the intersection of
    the two blocks is traversed (G450 and G451) ... smaller than 2 MD6, the control
    switches from G451 ... to G450"; otherwise G451 inserts intermediate blocks."""
    kink = 20.0
    prog, st = _stages(_line_arc_program(mode, kink), _machine(CUTCOM_840C_MD6=md6))
    (corner,) = [c for c in st.trc.corners if c.side == "outside"]
    assert corner.action == expect
    segs = _segments_of_lines(prog, st.path, (6,))
    assert _kinds(st.path, segs).count("trc") == n_trc
    if expect.startswith("tangent lines"):
        # the two lines meet where the tangents at A = (50, -5) and C intersect:
        # A + r tan(kink/2) (1, 0)
        apex = np.array([50.0 + R * math.tan(math.radians(kink) / 2), -R])
        end_of_first = st.path.evaluate(st.path.s_breaks[segs[0] + 1],
                                        segment=np.array([segs[0]]))[0][0, :2]
        assert np.allclose(end_of_first, apex, atol=TOL)
    assert _continuous(st.path)


@pytest.mark.parametrize("kink, mode, expect", [
    (5.0, "G450", "joined (840C: AC < MD6, 170..180 degrees, contour error)"),
    (20.0, "G450", "circle (840C: AC < MD6, no usable intersection)"),
    (20.0, "G451", "tangent lines (840C: AC < MD6, no usable intersection)"),
])
def test_840c_md6_where_the_intersection_is_too_far(monkeypatch, kink, mode, expect):
    """840C excerpt: "If there is no intersection or the intersection is located too far
    from the contour (> 1.5 tool radius), intermediate blocks are again inserted in the
    angular range 90 < alpha < 170 ... In the angular range 170 < alpha < 180 the normal
    circular block is approached ... The correct compensation is not reached until the
    end (E) of the block." Arc corners keep their intersection within 1.5 r, so the
    reach is set to 0 here to take that branch."""
    import reference.trc as trc
    monkeypatch.setattr(trc, "MD6_INTERSECTION_REACH", 0.0)
    prog, st = _stages(_line_arc_program(mode, kink), _machine(CUTCOM_840C_MD6=10.0))
    (corner,) = [c for c in st.trc.corners if c.side == "outside"]
    assert corner.action == expect
    assert _continuous(st.path)
    if expect.startswith("joined"):
        # the arc starts at A = (50, -5), the end of the line's offset, and ends on its
        # offset circle (radius 25): a spiral, no inserted block
        (arc,) = _segments_of_lines(prog, st.path, (6,))
        q = st.path.evaluate(st.path.s_breaks[arc], segment=np.array([arc]))[0][0, :2]
        assert np.allclose(q, (50.0, -R), atol=TOL) and st.path.dradius[arc] != 0


def test_without_md6_the_same_corner_is_a_g450_circle():
    prog, st = _stages(_line_arc_program("G450", 20.0))
    (corner,) = [c for c in st.trc.corners if c.side == "outside"]
    assert corner.action == "circle"


# ============================================================= approach, retract
def test_norm_approach_and_retract_are_straight_lines_to_the_perpendicular_points():
    """SINUMERIK NORM: the approach block ends perpendicular to the start of the contour;
    the G40 block starts perpendicular to the end of the last element."""
    prog, path = _path(HEADER + "G0 X-30 Y-30\nG41 G1 X0 Y0 F2000\nG1 X40\n"
                       "G40 G1 X70 Y-30\n")
    (ap,) = _segments_of_lines(prog, path, (4,))
    (rt,) = _segments_of_lines(prog, path, (6,))
    q = lambda i, end: path.evaluate(path.s_breaks[i + end], segment=np.array([i]))[0][0, :2]
    assert np.allclose(q(ap, 0), (-30, -30)) and np.allclose(q(ap, 1), (0, R), atol=TOL)
    assert np.allclose(q(rt, 0), (40, R), atol=TOL) and np.allclose(q(rt, 1), (70, -30))
    assert path.radius[ap] == 0 and path.radius[rt] == 0


def test_compensation_selected_on_an_arc_is_an_error():
    with pytest.raises(PathError, match=r"t\.mpf:4: G41 is selected in an arc block"):
        _path(HEADER + "G0 X0 Y-20\nG41 G2 X10 Y-10 CR=10 F2000\nG1 X20\nG40 X-20\n")
    with pytest.raises(PathError, match=r"t\.mpf:6: G40 deselects compensation in an arc"):
        _path(HEADER + "G0 X0 Y-20\nG41 G1 X0 Y0 F2000\nG1 X20\nG40 G2 X30 Y10 CR=10\n")


def test_an_infeed_without_plane_motion_stays_at_the_compensated_point():
    """Blocks between two contour elements that do not move in the plane run at the
    intermediate point (sinumerik-model 9, P*): here the end of the previous element."""
    prog, path = _path(HEADER + "G0 X0 Y-20\nG41 G1 X0 Y0 F2000\nG1 Z-5\nG1 X20\n"
                       "Z-10\nY20\nG40 G0 Z50\n")
    (z1,) = _segments_of_lines(prog, path, (5,))
    (z2,) = _segments_of_lines(prog, path, (7,))
    q = lambda i, end: path.evaluate(path.s_breaks[i + end], segment=np.array([i]))[0][0]
    assert np.allclose(q(z1, 0)[:2], (0, R)) and np.allclose(q(z1, 1), (0, R, -5))
    assert np.allclose(q(z2, 0), (20 - R, R, -5), atol=TOL)      # the inside corner point
    assert np.allclose(q(z2, 1), (20 - R, R, -10), atol=TOL)
    assert _continuous(path)


# ============================================================= tool data
def test_tool_radius_from_the_machine_table_by_number_and_by_name():
    d = tomllib.loads(resources.files("reference.machines").joinpath("default.toml")
                      .read_text())
    d["tools"] = {"2": {"D1": 3.0, "D2": 4.0}, "END MILL": 6.0}
    m = machine_from_dict(d)
    text = "G0 X0 Y-20\n{sel}\nG41 G1 X0 Y0 F2000\nG1 X40\nG40 G1 X40 Y-20\n"
    for sel, r in (("T2 D2", 4.0), ("T2", 3.0), ('T="END MILL" D1', 6.0)):
        prog, path = _path(text.format(sel=sel), m)
        (seg,) = _segments_of_lines(prog, path, (4,))
        assert path.origin[seg][1] == pytest.approx(r)
    # the program's own $TC_DP6 wins over the table
    prog, path = _path("$TC_DP6[2,2]=1.5\n" + text.format(sel="T2 D2"), m)
    (seg,) = _segments_of_lines(prog, path, (5,))
    assert path.origin[seg][1] == pytest.approx(1.5)


def test_a_missing_tool_radius_names_the_line():
    with pytest.raises(PathError, match=r"t\.mpf:3: G41: tool T3 D2 has no radius"):
        _path("T3 D2\nG0 X0 Y-20\nG41 G1 X0 Y0 F2000\nG1 X40\nG40 X0\n")
    with pytest.raises(PathError, match=r"t\.mpf:2: G42 needs a tool radius, but no tool"):
        _path("G0 X0 Y-20\nG42 G1 X0 Y0 F2000\nG1 X40\nG40 X0\n")


def test_a_negative_radius_compensates_on_the_other_side_and_d0_not_at_all():
    """LinuxCNC convert_cutter_compensation_on: "switch side & make radius positive if
    radius negative"; D0 selects no tool offset."""
    text = "$TC_DP6[1,1]={r}\nT1 D{d}\nG0 X0 Y-20\nG41 G1 X0 Y0 F2000\nG1 X40\nG40 X40 Y-20\n"
    prog, path = _path(text.format(r=-5, d=1))
    (seg,) = _segments_of_lines(prog, path, (5,))
    assert path.origin[seg][1] == pytest.approx(-5.0)            # right of +X, as G42
    prog, path = _path(text.format(r=5, d=0))
    (seg,) = _segments_of_lines(prog, path, (5,))
    assert path.origin[seg][1] == pytest.approx(0.0)


def test_switching_sides_or_radius_during_compensation_is_refused_with_the_line():
    with pytest.raises(PathError, match=r"t\.mpf:5: G41 -> G42 without G40"):
        _path(HEADER + "G0 X0 Y-20\nG41 G1 X0 Y0 F2000\nG42 X20\nG40 X-20\n")
    with pytest.raises(PathError, match=r"t\.mpf:6: the tool radius changes"):
        _path(HEADER + "$TC_DP6[1,2]=3\nG0 X0 Y-20\nG41 G1 X0 Y0 F2000\nD2 X20\n"
                       "G40 X-20\n")


# ============================================================= LinuxCNC
NGC_HEAD = "G21 G90 G17\nG10 L1 P1 R5\nT1 M6\n"


def test_ngc_entry_move_ends_perpendicular_to_itself_and_outside_corners_get_arcs():
    """LinuxCNC convert_straight_comp1: the entry ends r from its end point,
    perpendicular to the move; convert_straight_comp2: "If there is a convex corner,
    insert an arc to go around the corner"."""
    prog, path = _path(NGC_HEAD + "G0 X0 Y-20\nG41 G1 X0 Y0 F1000\nG1 X20\nY20\nG40 X-20\n",
                       dialect="ngc", name="t.ngc")
    (ap,) = _segments_of_lines(prog, path, (5,))
    q = lambda i, end: path.evaluate(path.s_breaks[i + end], segment=np.array([i]))[0][0, :2]
    assert np.allclose(q(ap, 1), (-R, 0), atol=TOL)        # left of the +Y entry move
    segs = _segments_of_lines(prog, path, (6, 7))
    assert _kinds(path, segs)[0] == "trc"                   # around (0, 0), outside
    arc = _sample(path, segs[:1])[:, :2]
    assert np.max(np.abs(np.linalg.norm(arc, axis=1) - R)) <= TOL
    pts = _sample(path, segs)[:, :2]
    contour = _dist_to_segments(pts, np.array([[0.0, -20], [0, 0], [20, 0]]),
                                np.array([[0.0, 0], [20, 0], [20, 20]]))
    assert np.max(np.abs(contour - R)) <= TOL


def test_ngc_g0_outside_corner_is_a_straight_chord():
    """convert_straight_comp2: "no arc is inserted for a G0 move"."""
    prog, path = _path(NGC_HEAD + "G0 X0 Y-20\nG42 G1 X0 Y0 F1000\nG1 X20\nG0 Y20\n"
                       "G40 X-30\n", dialect="ngc", name="t.ngc")
    segs = _segments_of_lines(prog, path, (7,))
    assert _kinds(path, segs) == ["trc", "line"] and path.radius[segs[0]] == 0
    q = lambda i, end: path.evaluate(path.s_breaks[i + end], segment=np.array([i]))[0][0, :2]
    assert np.allclose(q(segs[0], 0), (20, -R)) and np.allclose(q(segs[0], 1), (20 + R, 0))


def test_ngc_corner_below_tolerance_concave_corner_gets_no_arc():
    """LinuxCNC TOLERANCE_CONCAVE_CORNER = 0.01 rad: a smaller convex corner is joined."""
    a = 0.005
    prog, st = _stages(NGC_HEAD + f"G0 X0 Y-20\nG42 G1 X0 Y0 F1000\nG1 X20\n"
                       f"G1 X{20 + 20 * math.cos(a):.12f} Y{20 * math.sin(a):.12f}\nG40 X-30\n",
                       dialect="ngc", name="t.ngc")
    (corner,) = [c for c in st.trc.corners if c.side == "outside"]
    assert corner.action.startswith("joined")
    assert "trc" not in _kinds(st.path, range(st.path.n_segments))
    assert _continuous(st.path)


def test_ngc_dynamic_compensation_and_entry_length():
    """G41.1 D<diameter>; LinuxCNC refuses an entry move not longer than the radius."""
    prog, path = _path("G21\nG0 X0 Y-20\nG41.1 D8 G1 X0 Y0 F1000\nG1 X20\nG40 X20 Y-20\n",
                       dialect="ngc", name="t.ngc")
    seg = _segments_of_lines(prog, path, (4,))[-1]
    assert path.origin[seg][1] == pytest.approx(4.0)
    with pytest.raises(PathError, match=r"t\.ngc:3: length of the cutter compensation "
                                        r"entry move is not greater than the tool radius"):
        _path("G21\nG0 X0 Y-3\nG41.1 D8 G1 X0 Y0 F1000\nG1 X20\nG40 X20 Y-20\n",
              dialect="ngc", name="t.ngc")
    with pytest.raises(PathError, match=r"t\.ngc:4: length of the cutter compensation "):
        _path("G21\nG0 X0 Y-20\nG41.1 D8\nG1 Z-5 F1000\nG1 X20\nG40 X20 Y-20\n",
              dialect="ngc", name="t.ngc")          # a plunge as the entry move
    with pytest.raises(PathError, match=r"t\.ngc:3: cutter compensation in the YZ plane"):
        _path("G21 G19\nG0 Y0 Z-20\nG41.1 D8 G1 Y0 Z0 F1000\nG1 Y20\nG40 Z-20\n",
              dialect="ngc", name="t.ngc")


def test_ngc_tool_number_in_the_d_word_selects_the_tool():
    prog, path = _path("G21\nG10 L1 P3 R2\nG10 L1 P4 R7\nT3 M6\nG0 X0 Y-20\n"
                       "G41 D4 G1 X0 Y0 F1000\nG1 X30\nG40 X30 Y-20\n", dialect="ngc",
                       name="t.ngc")
    seg = _segments_of_lines(prog, path, (7,))[-1]
    assert path.origin[seg][1] == pytest.approx(7.0)


def test_g18_compensation_offsets_in_the_zx_plane():
    """G18: the plane is Z->X (viewed from +Y); G41 is left of the motion there."""
    prog, path = _path(HEADER + "G18 G0 X0 Z-20\nG41 G1 X0 Z0 F2000\nG1 Z40\n"
                       "G40 G1 X-20 Z40\n")
    (seg,) = _segments_of_lines(prog, path, (5,))
    # along +Z (the first plane axis) the left normal is +X (the second)
    assert path.origin[seg][0] == pytest.approx(R) and path.origin[seg][1] == 0.0


def test_programs_without_compensation_keep_their_path_object():
    prog = parse_text("G1 X10 F100\nY10\n", "p.mpf")
    st = path_stages(prog, load_machine())
    assert st.trc.path is not None and not st.trc.blocks and not st.trc.corners


# ============================================================= seeded random contours
def _random_contour(rng) -> tuple[str, list[tuple]]:
    """A random contour of lines and arcs (CR form, sweeps below 180 degrees) and the
    programmed elements: ("line", p0, p1) or ("arc", centre, radius)."""
    x, y, heading = 0.0, 0.0, 0.0
    lines, elements = [], []
    for _ in range(int(rng.integers(3, 9))):
        heading += math.radians(rng.uniform(-150, 150)) if rng.random() < 0.6 else 0.0
        if rng.random() < 0.5:
            L = rng.uniform(5, 20)
            nx, ny = x + L * math.cos(heading), y + L * math.sin(heading)
            lines.append(f"G1 X{nx!r} Y{ny!r}")          # full precision: exact elements
            elements.append(("line", (x, y), (nx, ny)))
        else:
            rad, sweep = rng.uniform(3, 30), math.radians(rng.uniform(10, 170))
            ccw = rng.random() < 0.5
            sgn = 1.0 if ccw else -1.0
            cx = x - sgn * rad * math.sin(heading)
            cy = y + sgn * rad * math.cos(heading)
            a0 = math.atan2(y - cy, x - cx)
            a1 = a0 + sgn * sweep
            nx, ny = cx + rad * math.cos(a1), cy + rad * math.sin(a1)
            lines.append(f"{'G3' if ccw else 'G2'} X{nx!r} Y{ny!r} CR={rad!r}")
            elements.append(("arc", (cx, cy), rad))
            heading += sgn * sweep
        x, y = nx, ny
    return "\n".join(lines), elements


@pytest.mark.parametrize("seed", range(40))
def test_random_contours_offset_every_element_by_exactly_r_or_name_the_line(seed):
    """Seeded invariant: each compensated contour block's own segment lies exactly r from
    its programmed element (distance to the line, or |distance to the centre - R|), each
    transition circle r from the corner; the path is continuous; or the program is
    refused with a PathError naming file and line (the tool does not fit)."""
    rng = np.random.default_rng(seed)
    body, elements = _random_contour(rng)
    side = "G41" if rng.random() < 0.5 else "G42"
    mode = ["G450", "G451", "G450 DISC=40"][int(rng.integers(0, 3))]
    r = 1.0
    text = (f"$TC_DP6[1,1]={r}\nT1 D1\nG0 X-10 Y-10\n{side} {mode} G1 X0 Y0 F3000\n"
            f"{body}\nG40 G1 X-20 Y-20\nM30\n")
    prog = parse_text(text, "t.mpf")
    try:
        st = path_stages(prog, load_machine())
    except PathError as exc:
        assert str(exc).startswith("t.mpf:") and str(exc).split(":")[1].isdigit()
        return
    path = st.path
    assert _continuous(path)
    for k, el in enumerate(elements):
        segs = _segments_of_lines(prog, path, (5 + k,))
        main = [i for i in segs if KIND_CODES[int(path.kind[i])] != "trc"]
        assert len(main) == 1
        p = _sample(path, main, 200)[:, :2]
        if el[0] == "line":
            a, b = np.array(el[1]), np.array(el[2])
            t = (b - a) / np.linalg.norm(b - a)
            d = np.abs((p - a) @ np.array([-t[1], t[0]]))
        else:
            d = np.abs(np.linalg.norm(p - np.array(el[1]), axis=1) - el[2])
        # 1e-7 mm: the parser's centre from CR and the end points carries the round-off
        # of coordinates of up to 100 mm through a square root
        assert np.max(np.abs(d - r)) <= 1e-7, (seed, k, el[0])
    for c in st.trc.corners:
        if c.action == "circle":
            blk = prog.blocks[c.next_block]
            trc = [i for i in range(path.n_segments) if int(path.block[i]) == blk.index
                   and KIND_CODES[int(path.kind[i])] == "trc"]
            corner = np.array(blk.start[:2])
            q = _sample(path, trc, 100)[:, :2]
            assert np.max(np.abs(np.linalg.norm(q - corner, axis=1) - r)) <= 1e-7
