"""Hostile and unusual NC input (issue 9): a precise error at file:line:col, a warning
where the control accepts the line with another meaning, or the feature implemented
(tools by name, positioning axes, tilted frames). Positions are checked against hand
geometry, never against the parser itself.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from reference.core.errors import NCSyntaxError
from reference.nc import parse_text
from reference.nc.expr import MAX_EXPR_DEPTH, NGC_MAX_PARAMETER
from reference.nc.state import MAX_COORDINATE_MM, MAX_DWELL_S, MAX_FEED_MM_MIN
from reference.prepare import prepare

SIN, NGC = "sinumerik", "ngc"


def _err(text: str, dialect: str, line: int, col: int, match: str) -> NCSyntaxError:
    with pytest.raises(NCSyntaxError, match=match) as info:
        parse_text(text, "p", dialect)
    assert (info.value.line, info.value.column) == (line, col), str(info.value)
    assert str(info.value).startswith(f"p:{line}:{col}: ")
    return info.value


def _ends(text: str, dialect: str = SIN) -> list[tuple[float, ...]]:
    return [b.end for b in parse_text(text, "p", dialect).blocks]


# ----------------------------------------------------------------- nesting depth
@pytest.mark.parametrize("text, dialect, col", [
    ("G1 F1000 X=" + "(" * 500 + "1" + ")" * 500 + "\n", SIN, 12 + MAX_EXPR_DEPTH),
    ("G1 F1000 X" + "[" * 500 + "1" + "]" * 500 + "\n", NGC, 11 + MAX_EXPR_DEPTH),
    ("G1 F1000 X=" + "-" * 3000 + "1\n", SIN, 12 + MAX_EXPR_DEPTH),
    ("G1 F1000 X" + "#" * 3000 + "1\n", NGC, 11 + MAX_EXPR_DEPTH),
])
def test_deep_nesting_is_an_error_at_the_column(text, dialect, col):
    _err(text, dialect, 1, col, rf"expression nested too deeply \(more than "
                                rf"{MAX_EXPR_DEPTH} levels")


def test_a_long_operator_chain_is_an_error_not_a_recursion_error():
    text = "R1=" + "+".join(["1"] * 3000) + "\nG1 F100 X=R1\n"
    _err(text, SIN, 1, 4 + 2 * MAX_EXPR_DEPTH, r"nested too deeply")


@pytest.mark.parametrize("dialect, open_, close, lead", [(SIN, "(", ")", "X="),
                                                         (NGC, "[", "]", "X")])
def test_nesting_just_below_the_limit_parses_and_evaluates(dialect, open_, close, lead):
    n = MAX_EXPR_DEPTH - 1            # the innermost number is one more level
    text = f"G1 F100 {lead}" + open_ * n + "7" + close * n + "\n"
    assert _ends(text, dialect)[0][0] == 7.0


# ----------------------------------------------------------------- feed F0
def test_f0_in_the_moving_block_is_an_error_at_the_f_word():
    _err("G1 X5 F0\n", SIN, 1, 7, r"G1 with feed F0: the move would never end")


@pytest.mark.parametrize("dialect", [SIN, NGC])
def test_f0_set_before_is_an_error_at_the_move(dialect):
    _err("F0\nG1 X5\n", dialect, 2, 1, r"G1 with feed F0")


def test_f0_with_rapid_moves_is_fine():
    assert _ends("F0\nG0 X5\n")[-1] == (5.0, 0.0, 0.0)


def test_f0_on_an_arc_is_an_error():
    _err("G1 F100 X10\nG2 X0 I-5 F0\n", SIN, 2, 11, r"G2 with feed F0")


# ----------------------------------------------------------------- coordinates
def test_a_coordinate_beyond_the_limit_is_an_error_at_the_word():
    _err("G1 F1000 X123456789012345678901234567890\n", SIN, 1, 10,
         r"position X = 1\.23457e\+29 mm is beyond \+-1e\+06 mm")


@pytest.mark.parametrize("dialect", [SIN, NGC])
def test_a_number_that_overflows_is_an_error_at_the_word(dialect):
    _err("G1 F1000 X" + "9" * 400 + "\n", dialect, 1, 10, r"the value of X is too large to "
                                                          r"be a number \(inf\)")


def test_incremental_moves_that_add_up_beyond_the_limit_are_an_error_at_that_line():
    _err("G91 G1 F100\nX900000\nX900000\n", SIN, 3, 1, r"position X = 1\.8e\+06 mm")


def test_the_limit_itself_is_accepted():
    lim = MAX_COORDINATE_MM
    assert _ends(f"G1 F100 X{lim:.0f} Y-{lim:.0f}\n")[0][:2] == (lim, -lim)


def test_an_arc_centre_beyond_the_limit_is_an_error():
    _err("G1 F100 X0\nG2 X0 Y0 I2000000 J0 TURN=0\n", SIN, 2, 10,
         r"arc centre X = 2e\+06 mm is beyond")


def test_an_overflowing_spindle_or_tool_word_is_an_error_not_a_crash():
    _err("G1 F100 X1 S" + "9" * 400 + "\n", SIN, 1, 12, r"the value of S is too large")
    _err("T" + "9" * 400 + "\n", SIN, 1, 1, r"the value of T is too large")


@pytest.mark.parametrize("dialect", [SIN, NGC])
def test_an_absurd_feed_is_an_error_at_the_f_word(dialect):
    _err("G1 F" + "9" * 300 + " X10\n", dialect, 1, 4, r"feed F1e\+300 is above 1e\+09 mm/min")


def test_a_feed_at_the_limit_and_a_usual_rapid_feed_are_accepted():
    p = parse_text(f"G1 F{MAX_FEED_MM_MIN:.0f} X10\nG1 F99999 X20\n", "p", SIN)
    assert p.blocks[0].feed_mm_s == pytest.approx(MAX_FEED_MM_MIN / 60.0)


def test_an_inch_feed_is_checked_in_mm_per_min():
    # 5e8 inch/min = 1.27e10 mm/min: above the limit although the number is below it
    _err("G20 G1 F500000000 X1\n", NGC, 1, 8, r"feed F5e\+08 is above 1e\+09 mm/min")


def test_an_absurd_dwell_is_an_error_at_the_line():
    _err("G1 F100 X1\nG4 F" + "9" * 300 + "\n", SIN, 2, 1, r"dwell time 1e\+300 s is above "
                                                          r"1e\+06 s")
    assert parse_text(f"G4 F{MAX_DWELL_S:.0f}\n", "p", SIN).blocks[0].dwell_s == MAX_DWELL_S


@pytest.mark.parametrize("text, dialect, col, word", [
    ("G1 F100 X10\nG2 X0 CR=1EX300\n", SIN, 7, r"CR=1e\+300"),
    ("G1 F100 X10\nG2 X0 R" + "9" * 300 + "\n", NGC, 7, r"R1e\+300"),
])
def test_an_absurd_arc_radius_is_an_error_at_the_radius_word(text, dialect, col, word):
    _err(text, dialect, 2, col, rf"arc radius {word} is beyond 1e\+06 mm")


# ----------------------------------------------------------------- SINUMERIK exponents
def test_python_exponent_is_an_error_not_an_axis_e():
    _err("G1 F1000 X1e308\n", SIN, 1, 12, r"'E308' glued to a number: SINUMERIK writes "
                                          r"exponents with EX")


def test_python_exponent_in_an_expression_is_an_error():
    _err("G1 F1000\nS=1e400\n", SIN, 2, 4, r"'E400' glued to a number")


def test_sinumerik_ex_exponent_is_read():
    # 1.5EX1 = 15; 2EX-1 * 10 = 2; R1 = 1EX2 = 100
    ends = _ends("G1 F100 X1.5EX1 Y=2EX-1*10\nR1=1EX2\nG1 X=R1\n")
    assert ends[0] == pytest.approx((15.0, 2.0, 0.0))
    assert ends[2] == pytest.approx((100.0, 2.0, 0.0))


def test_an_axis_e_separated_by_a_blank_stays_an_axis():
    p = parse_text("G1 F100 X1 E5\n", "p", SIN)
    assert "E" in p.axes and p.blocks[0].end[p.axes.index("E")] == 5.0


def test_ngc_exponent_letter_is_an_unknown_address():
    _err("G1 F100 X1e3\n", NGC, 1, 11, r"unknown address E")


# ----------------------------------------------------------------- splines
@pytest.mark.parametrize("word", ["BSPLINE", "ASPLINE", "CSPLINE", "POLY", "CIP"])
def test_unsupported_motion_keywords_are_errors_at_the_line(word):
    _err(f"G1 F1000 X1\n{word} X10 Y5\nG1 X20\n", SIN, 2, 1,
         rf"{word} \(.*\) is not supported: its points would not be on the modelled path")


def test_bspline_alone_is_an_error_too():
    _err("G1 F1000 X1\nN20 BSPLINE\nX10 Y5\n", SIN, 2, 5, r"BSPLINE \(B spline\)")


# ----------------------------------------------------------------- NGC specifics
def test_ngc_g64_negative_p_is_no_tolerance_with_a_warning():
    p = parse_text("G64 P-1\nG1 F100 X10\nM2\n", "p", NGC)
    assert p.blocks[1].modal.contour_tol_mm is None
    assert any(w.line == 1 and "negative tolerance means no tolerance" in w.message
               for w in p.warnings)


def test_ngc_g64_positive_p_is_the_tolerance():
    p = parse_text("G64 P0.05\nG1 F100 X10\nM2\n", "p", NGC)
    assert p.blocks[1].modal.contour_tol_mm == pytest.approx(0.05)
    assert not p.warnings


def test_ngc_m98_without_the_subprogram_is_an_error_at_p():
    _err("G1 F100 X1\nM98 P1000\nM2\n", NGC, 2, 5, r"M98 P1000: there is no subprogram "
                                                   r"O1000 in this file")


def test_ngc_m98_with_the_subprogram_is_not_supported():
    _err("G1 F100 X1\nM98 P1000\nM2\nO1000\nG1 X5\nM99\n", NGC, 2, 1,
         r"Fanuc-style subprogram calls \(M98/M99\) are not supported")


@pytest.mark.parametrize("text, line, col, num", [
    ("G1 F100 X#99999\nM2\n", 1, 10, 99999),
    ("#1=99999\nG1 F100 X#[#1]\nM2\n", 2, 10, 99999),
    ("#[10*10000]=5\nG1 F100 X1\nM2\n", 1, 1, 100000),
    ("#0=5\nM2\n", 1, 1, 0),
])
def test_ngc_parameter_number_out_of_range(text, line, col, num):
    _err(text, NGC, line, col, rf"parameter number #{num} is out of range \(LinuxCNC has "
                               rf"#1\.\.#{NGC_MAX_PARAMETER}")


def test_ngc_highest_parameter_is_fine():
    assert _ends(f"#{NGC_MAX_PARAMETER}=4\nG1 F100 X#{NGC_MAX_PARAMETER}\nM2\n", NGC)[1] == (
        4.0, 0.0, 0.0)


# ----------------------------------------------------------------- tools by name
def test_tool_by_name_is_a_forced_stop_like_a_tool_number():
    text = 'G1 F1000 X1\nT="Drill 8.5"\nM6\nG1 X20\n'
    p = parse_text(text, "p", SIN)
    blk = p.blocks[1]
    assert blk.aux == (("T", "Drill 8.5"),)           # the name as written, case kept
    assert p.blocks[3].modal.tool == "Drill 8.5"
    path = prepare(p)
    assert path.blocks[1].stop_reason == 'block without path motion (T="Drill 8.5")'
    numbered = prepare(parse_text("G1 F1000 X1\nT1\nM6\nG1 X20\n", "p", SIN))
    assert path.stop_reason == numbered.stop_reason[:1] + path.stop_reason[1:]
    assert [bool(r) for r in path.stop_reason] == [bool(r) for r in numbered.stop_reason]


def test_tool_by_name_in_a_moving_block_is_output_during_motion():
    p = parse_text('G1 F1000 X1 T="MILL_10"\n', "p", SIN)
    assert p.blocks[0].aux == (("T", "MILL_10"),) and p.blocks[0].end == (1.0, 0.0, 0.0)


def test_tool_name_without_closing_quote_is_an_error():
    _err('T="DRILL\n', SIN, 1, 3, r"tool name: missing closing")


# ----------------------------------------------------------------- positioning axes
def test_pos_axis_is_its_own_rapid_block_with_stops_before_and_after():
    text = "G1 F1000 X10\nPOS[A]=90\nPOS[A]=IC(-30)\nG1 X20\n"
    p = parse_text(text, "p", SIN)
    assert p.axes == ("X", "Y", "Z", "A")
    ends = [b.end for b in p.blocks]
    assert ends == [(10.0, 0.0, 0.0, 0.0), (10.0, 0.0, 0.0, 90.0), (10.0, 0.0, 0.0, 60.0),
                    (20.0, 0.0, 0.0, 60.0)]
    assert [b.motion for b in p.blocks] == ["G1", "G0", "G0", "G1"]   # G1 stays modal
    path = prepare(p)
    assert path.n_segments == 4
    assert path.length.tolist() == pytest.approx([10.0, 90.0, 30.0, 10.0])
    assert [bool(s) for s in path.stop] == [True, True, True, True, True]
    assert path.stop_reason[1] == "positioning axis POS[A]"


@pytest.mark.parametrize("text", ["FA[A]=3600\nPOS[A]=90\n", "POS[A]=90 FA[A]=3600\n"])
def test_pos_axis_with_fa_moves_at_that_feed(text):
    p = parse_text("G1 F1000 X10\n" + text + "G1 X20\n", "p", SIN)
    pos = next(b for b in p.blocks if b.end[3] == 90.0 and b.start[3] == 0.0)
    assert pos.motion == "G1" and pos.feed_mm_s == pytest.approx(60.0)   # 3600 deg/min
    assert p.blocks[-1].feed_mm_s == pytest.approx(1000.0 / 60.0)        # path feed kept
    path = prepare(p)
    assert path.feed.tolist() == pytest.approx([1000.0 / 60.0, 60.0, 1000.0 / 60.0])


def test_fa_must_be_positive():
    _err("FA[A]=0\n", SIN, 1, 1, r"FA\[A\]=0: the positioning feed must be > 0")


def test_pos_axis_with_path_motion_in_the_same_block_is_an_error():
    _err("G1 F1000 X10 POS[A]=90\n", SIN, 1, 10, r"POS\[A\] with path motion in the same "
                                                 r"block is not supported")


def test_pos_of_a_non_axis_is_an_error():
    _err("POS[R1]=5\n", SIN, 1, 1, r"'R1' is not an axis name")


# ----------------------------------------------------------------- tilted frames
def test_rot_y_minus_90_maps_x_onto_z():
    # R = Ry(-90): (x, y, z) -> (-z, y, x)
    ends = _ends("ROT Y-90\nG1 F1000 X10\nG1 Y10\nG1 Z3\nROT\nG1 X0 Y0 Z0\n")
    assert ends[1] == pytest.approx((0.0, 0.0, 10.0))
    assert ends[2] == pytest.approx((0.0, 10.0, 10.0))
    assert ends[3] == pytest.approx((-3.0, 10.0, 10.0))
    assert ends[5] == pytest.approx((0.0, 0.0, 0.0))


def test_rot_angles_follow_rpy_order_z_then_y_then_x():
    # R = Rz(90) Rx(90): program X -> machine Y, program Y -> machine Z
    ends = _ends("ROT X90 Z90\nG1 F1000 X10\nG1 X0 Y10\n")
    assert ends[1] == pytest.approx((0.0, 10.0, 0.0))
    assert ends[2] == pytest.approx((0.0, 0.0, 10.0))


def test_arot_x_follows_a_z_rotation():
    ends = _ends("ROT Z90\nAROT X90\nG1 F1000 X10\nG1 X0 Y10\n")
    assert ends[2] == pytest.approx((0.0, 10.0, 0.0))
    assert ends[3] == pytest.approx((0.0, 0.0, 10.0))


def test_atrans_in_a_tilted_frame_moves_along_the_tilted_axes():
    ends = _ends("ROT Y-90\nATRANS Z5\nG1 F1000 X0 Y0 Z0\n")
    assert ends[2] == pytest.approx((-5.0, 0.0, 0.0))


def test_incremental_moves_in_a_tilted_and_shifted_frame():
    # machine = R (program + shift), R = Ry(-90): program +X is machine +Z
    ends = _ends("ROT Y-90\nATRANS X3 Y4 Z5\nG1 F1000 X0 Y0 Z0\nG91 X1\nY2\n")
    assert ends[2] == pytest.approx((-5.0, 4.0, 3.0))
    assert ends[3] == pytest.approx((-5.0, 4.0, 4.0))
    assert ends[4] == pytest.approx((-5.0, 6.0, 4.0))


def test_g17_arc_in_a_tilted_frame_lies_in_the_tilted_plane():
    p = parse_text("ROT Y-90\nG1 F1000 X10 Y10\nG2 X0 Y0 I-5 J-5\n", "p", SIN)
    arc = p.blocks[2]
    assert arc.end == pytest.approx((0.0, 0.0, 0.0))
    assert arc.center == pytest.approx((0.0, 5.0, 5.0))
    e1, e2 = arc.plane_basis
    assert e1 == pytest.approx((0.0, 0.0, 1.0)) and e2 == pytest.approx((0.0, 1.0, 0.0))
    path = prepare(p)
    r = math.hypot(5.0, 5.0)
    assert path.length[-1] == pytest.approx(math.pi * r)   # a half circle of radius 5*sqrt2
    # every point of the arc lies in the machine plane X = 0 (program plane Z = 0), at
    # distance r from the centre (0, 5, 5)
    s0 = path.total_length - path.length[-1]
    q = path.evaluate(s0 + path.length[-1] * np.array([0.1, 0.3, 0.5, 0.9]))[0]
    assert np.abs(q[:, 0]).max() < 1e-9
    assert np.hypot(q[:, 1] - 5.0, q[:, 2] - 5.0) == pytest.approx(np.full(4, r))


def test_helix_in_a_tilted_frame_rises_along_the_tilted_axis():
    # program: half turn clockwise about (5, 0) from (0, 0, 0) to (10, 0, 5); the
    # midpoint is (5, 5, 2.5), in the machine R (5, 5, 2.5) = (-2.5, 5, 5)
    p = parse_text("ROT Y-90\nG1 F1000 X0 Y0 Z0\nG2 X10 Y0 Z5 I5 J0\n", "p", SIN)
    assert p.blocks[-1].end == pytest.approx((-5.0, 0.0, 10.0))
    path = prepare(p)
    assert path.length[-1] == pytest.approx(math.hypot(math.pi * 5.0, 5.0))
    s_mid = path.total_length - 0.5 * path.length[-1]
    assert path.evaluate(s_mid)[0][0] == pytest.approx([-2.5, 5.0, 5.0])


def test_rotation_about_a_rotary_axis_is_an_error():
    _err("ROT A30\n", SIN, 1, 5, r"ROT A: rotations are about the geometry axes X, Y and Z")
