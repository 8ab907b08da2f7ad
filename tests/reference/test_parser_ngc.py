"""RS274/NGC (LinuxCNC) dialect: lexical forms, modal state, arcs, units, offsets, O-words.

Every expected value is derived by hand in the comment next to it.
"""

from __future__ import annotations

import math

import pytest

from reference.nc import parse_text

IN = 25.4


def ngc(text: str):
    return parse_text(text, "t.ngc", "ngc")


def moves(prog):
    return [b for b in prog.blocks if b.motion is not None]


# ----------------------------------------------------------------- lexical forms
def test_comments_messages_percent_program_number_and_blank_lines():
    p = ngc("%\nO1000 (part 7)\n\n(only a comment)\nN5 G1 X1 F60 (cut) ; tail\n"
            "(MSG, Check the clamp)\n%\n")
    assert [b.line for b in p.blocks] == [2, 5, 6]
    assert p.blocks[0].label == "O1000" and p.blocks[0].comment == "part 7"
    assert p.blocks[1].label == "N5" and p.blocks[1].comment == "cut tail"
    assert p.blocks[2].message == "Check the clamp" and p.blocks[2].motion is None


def test_blanks_anywhere_tabs_lowercase_and_glued_words():
    p = ngc("g1\tx 1 0 . 5 y-2f60\n\tX\t0.001\nG64P.005Q.001\n")
    assert p.blocks[0].end == (10.5, -2.0, 0.0) and p.blocks[1].end[0] == 0.001
    assert p.blocks[2].contour_tol_mm == 0.005 and p.blocks[2].naive_cam_tol_mm == 0.001


def test_block_delete_line_executes_with_the_switch_off():
    assert ngc("/G1 X1 F60\n").blocks[0].end[0] == 1.0


# ----------------------------------------------------------------- modal state
def test_defaults_and_modal_continuation():
    p = ngc("G1 X1 F120\nY2\n  X3 Y3\n")
    assert [b.end[:2] for b in p.blocks] == [(1, 0), (1, 2), (3, 3)]
    assert all(b.feed_mm_s == pytest.approx(2.0) for b in p.blocks)
    b = p.blocks[0]
    assert (b.plane, b.continuous_mode, b.tool_compensation) == ("G17", "G64", "G40")
    assert b.contour_tol_mm is None and b.naive_cam_tol_mm is None


def test_incremental_g91_and_back():
    p = ngc("G1 X1 F60\nG91 X1 Y1\nX1\nG90 X0\n")
    assert [b.end[:2] for b in p.blocks] == [(1, 0), (2, 1), (3, 1), (0, 1)]


def test_g61_g61_1_and_g64_p_q():
    p = ngc("G61 G1 X1 F60\nG61.1 X2\nG64 P0.01 X3\nG64 P0.02 Q0 X4\nG64 X5\n")
    b = moves(p)
    assert [x.continuous_mode for x in b] == ["G61", "G60", "G64", "G64", "G64"]
    assert [x.exact_stop_here for x in b] == [False, True, False, False, False]
    assert (b[2].contour_tol_mm, b[2].naive_cam_tol_mm) == (0.01, 0.01)    # Q defaults to P
    assert (b[3].contour_tol_mm, b[3].naive_cam_tol_mm) == (0.02, 0.0)
    assert (b[4].contour_tol_mm, b[4].naive_cam_tol_mm) == (None, None)    # machine value


def test_inch_units_convert_positions_tolerances_and_feeds():
    p = ngc("G20 G64 P0.001\nG1 X1 F10\nG21 X1 F600\n")
    b = p.blocks
    assert b[0].contour_tol_mm == pytest.approx(0.0254) and p.source_units == "inch"
    assert b[1].end[0] == pytest.approx(IN) and b[1].feed_mm_s == pytest.approx(10 * IN / 60)
    assert b[2].end[0] == 1.0 and b[2].feed_mm_s == pytest.approx(10.0)


def test_dwell_tool_and_offsets():
    p = ngc("T3 M6\nG43 H3\nG4 P1.5\nG41 D3\nG40\n")
    b = p.blocks
    assert b[0].tool == 3 and b[0].aux == (("T", 3.0), ("M", 6.0))
    assert b[1].tool_offset == 3 and "tool length" in p.warnings[0].message
    assert b[2].dwell_s == 1.5
    assert b[3].tool_compensation == "G41" and b[4].tool_compensation == "G40"


def test_program_end_and_m99():
    assert len(moves(ngc("G1 X1 F60\nM30\nX2\n"))) == 1
    p = ngc("G1 X1 F60\nM99\nX2\n")
    assert len(moves(p)) == 1 and "M99" in p.warnings[0].message


# ----------------------------------------------------------------- arcs
def test_ijk_incremental_by_default_and_g90_1_absolute():
    p = ngc("G1 X10 Y0 F60\nG3 X0 Y10 I-10 J0\n")
    assert moves(p)[1].center[:2] == (0.0, 0.0)
    p = ngc("G90.1\nG1 X10 Y5 F60\nG3 X0 Y15 I0 J5\nG91.1\nG2 X10 Y5 I0 J-10\n")
    assert moves(p)[1].center[:2] == (0.0, 5.0)
    assert moves(p)[2].center[:2] == (0.0, 5.0)


@pytest.mark.parametrize("r, motion, centre", [
    ("7.0710678", "G2", (5.0, -5.0)),        # <= 180 deg clockwise: centre right of chord
    ("-7.0710678", "G2", (5.0, 5.0)),        # negative radius: the long way round
    ("7.0710678", "G3", (5.0, 5.0)),
    ("5", "G3", (5.0, 0.0)),
])
def test_radius_form(r, motion, centre):
    p = ngc(f"G1 X0 Y0 F60\n{motion} X10 Y0 R{r}\n")
    assert moves(p)[1].center[:2] == pytest.approx(centre, abs=1e-6)


def test_g18_arc_with_i_and_k_and_radius():
    p = ngc("G18\nG1 X0 Z10 F60\nG2 X10 Z0 I0 K-10\n")
    b = moves(p)[1]
    assert b.plane == "G18" and (b.center[0], b.center[2]) == (0.0, 0.0)
    p = ngc("G18 G1 X0 Z0 F60\nG2 X10 R5\n")
    b = moves(p)[1]
    assert (b.center[0], b.center[2]) == pytest.approx((5.0, 0.0))


def test_helix_p_is_the_number_of_turns():
    p = ngc("G1 X10 Y0 F60\nG3 X10 Y0 Z-6 I-10 J0 P3\nG2 X0 Y10 Z-7 R10\n")
    b = moves(p)
    assert b[1].turns == 2 and b[1].end == (10.0, 0.0, -6.0)    # P3 = 2 extra turns
    assert b[2].turns == 0 and b[2].end[2] == -7.0


def test_full_turn_helix_with_omitted_end_point():
    # LinuxCNC tangent_helix: "G2 Z1.68 J-1" ends where it started in XY
    p = ngc("G20 G1 X1 Y0 Z0 F100\nG2 Z1.5 J-1\n")
    b = moves(p)[1]
    assert b.start[:2] == b.end[:2] == pytest.approx((IN, 0.0))
    assert b.center[:2] == pytest.approx((IN, -IN)) and b.end[2] == pytest.approx(1.5 * IN)


# ----------------------------------------------------------------- coordinate systems
def test_g10_l2_rotation_applies_to_lines_and_tilts_yz_arcs():
    p = ngc("G20 G90\nG10 L2 P0 X-2 Y1 R60\nF10000\nG0 X0 Y0 Z0\nG0 Y1.5 Z.5\n"
            "G19\nG2 Y.5 Z1.5 K1\n")
    c, s = math.cos(math.radians(60)), math.sin(math.radians(60))

    def mach(x, y, z):                               # rotate about Z, then offset, in mm
        return ((c * x - s * y - 2) * IN, (s * x + c * y + 1) * IN, z * IN)

    b = moves(p)
    assert b[0].end == pytest.approx(mach(0, 0, 0))
    assert b[1].end == pytest.approx(mach(0, 1.5, 0.5))
    assert b[2].end == pytest.approx(mach(0, 0.5, 1.5))
    assert b[2].center == pytest.approx(mach(0, 1.5, 1.5))
    u, v = b[2].plane_basis                          # rotated Y, and Z
    assert u == pytest.approx((-s, c, 0.0)) and v == pytest.approx((0.0, 0.0, 1.0))
    assert b[2].feed_mm_s == pytest.approx(10000 * IN / 60)
    assert any(w.line == 2 and "G10 L2" in w.message for w in p.warnings)


def test_work_offsets_selected_by_g54_g55():
    p = ngc("G10 L2 P2 X100\nG1 X1 F60\nG55 X1\nG54 X1\nG56\n")
    assert [b.end[0] for b in moves(p)] == [1.0, 101.0, 1.0]
    # G54 and G56 were never set here: their offsets live in the control (taken as zero)
    assert [w.line for w in p.warnings if "taken as zero" in w.message] == [4, 5]


def test_g92_offsets_and_cancel():
    p = ngc("G1 X5 F60\nG92 X0\nX1\nG92.1\nX1\n")
    assert [b.end[0] for b in moves(p)] == [5.0, 6.0, 1.0]


def test_g53_moves_in_machine_coordinates_for_one_block():
    p = ngc("G10 L2 P1 X10\nG1 X0 F60\nG53 X0\nX1\n")
    assert [b.end[0] for b in moves(p)] == [10.0, 0.0, 11.0]


# ----------------------------------------------------------------- extra axes
def test_abc_uvw_axes():
    p = ngc("G20 G1 X1 A90 W1 F60\n")
    assert p.axes == ("X", "Y", "Z", "A", "W")
    assert p.blocks[0].end == pytest.approx((IN, 0, 0, 90.0, IN))
    assert p.rotary == (False, False, False, True, False)
