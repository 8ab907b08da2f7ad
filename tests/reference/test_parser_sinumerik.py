"""SINUMERIK dialect: words, modal state, arcs, units, frames, tolerances, TRC, TANG, aux.

Every expected value is derived by hand in the comment next to it.
"""

from __future__ import annotations

import math

import pytest

from reference.nc import parse_text


def sin(text: str):
    return parse_text(text, "t.mpf", "sinumerik")


def moves(prog):
    return [b for b in prog.blocks if b.motion is not None]


# ----------------------------------------------------------------- lexical forms
def test_unspaced_lowercase_tabs_leading_blanks_and_trailing_dots():
    p = sin("g1x10y5f600\n\t  G1\tX1. Y-2.  Z.5\n")
    assert [b.end for b in p.blocks] == [(10.0, 5.0, 0.0), (1.0, -2.0, 0.5)]
    assert p.blocks[0].feed_mm_s == pytest.approx(10.0)          # 600 mm/min


def test_line_ends_crlf_cr_and_mixed():
    p = sin("G1 X1 F60\r\nX2\rX3\nX4\r\n")
    assert [b.end[0] for b in p.blocks] == [1.0, 2.0, 3.0, 4.0]
    assert [b.line for b in p.blocks] == [1, 2, 3, 4]


def test_percent_header_comments_blank_lines_and_block_numbers():
    p = sin("%_N_PART_MPF\n;$PATH=/_N_MPF_DIR\n\n; a comment\nN10\nN20 G1 X1 F60 ; go\n")
    assert [b.line for b in p.blocks] == [5, 6]              # comment/blank lines: no block
    assert p.blocks[0].label == "N10" and p.blocks[0].motion is None
    assert p.blocks[1].label == "N20" and p.blocks[1].comment == "go"


def test_block_delete_and_skip_levels_execute_with_the_switch_off():
    p = sin("/G1 X1 F60\n/1 X2\n")
    assert [b.end[0] for b in moves(p)] == [1.0, 2.0]


def test_labels_are_kept_on_the_block():
    p = sin("START: G1 X1 F60\nN30 LA2: X2\n")
    assert [b.label for b in p.blocks] == ["START", "LA2"]


# ----------------------------------------------------------------- modal state
def test_defaults_at_program_start():
    b = sin("G1 X1 F60\n").blocks[0]
    assert (b.plane, b.continuous_mode, b.exact_stop_criterion, b.tool_compensation,
            b.trc_corner, b.accel_mode, b.exact_stop_here) == (
        "G17", "G64", "G601", "G40", "G450", None, False)
    assert b.contour_tol_mm is None and b.tool is None and b.tangential is None


def test_modal_continuation_of_motion_feed_and_absolute_incremental():
    p = sin("G0 X5\nG1 X10 F1200\nY5\nG91 X1 Y1\nG90 X=IC(2) Y=AC(0)\nX0\n")
    assert [b.motion for b in p.blocks] == ["G0", "G1", "G1", "G1", "G1", "G1"]
    assert [b.end[:2] for b in p.blocks] == [(5, 0), (10, 0), (10, 5), (11, 6), (13, 0),
                                             (0, 0)]
    assert p.blocks[0].feed_mm_s is None                       # G0 before any F
    assert all(b.feed_mm_s == pytest.approx(20.0) for b in p.blocks[1:])


def test_non_motion_blocks_keep_start_equal_end():
    p = sin("G1 X3 Y4 F60\nM8\nR1=5\n")
    for b in p.blocks[1:]:
        assert b.motion is None and b.start == b.end == (3.0, 4.0, 0.0)


def test_group10_g60_modal_g9_non_modal_and_g64_family_exclusive():
    p = sin("G1 X1 F60\nG9 X2\nX3\nG60 G602 X4\nX5\nG641 X6\nG642 X7\nG643 X8\nG644 X9\n"
            "G645 X10\nG64 G603 X11\n")
    b = moves(p)
    assert [x.exact_stop_here for x in b] == [False, True, False, True, True, False, False,
                                              False, False, False, False]
    assert [x.continuous_mode for x in b] == ["G64", "G64", "G64", "G60", "G60", "G641",
                                              "G642", "G643", "G644", "G645", "G64"]
    assert b[3].exact_stop_criterion == "G602" and b[10].exact_stop_criterion == "G603"


def test_rounding_distances_and_tolerances():
    p = sin("G641 ADIS=0.5 ADISPOS=2\nG642 CTOL=0.02 OTOL=0.5 ATOL[X]=0.01 ATOL[C]=0.1\n"
            "CTOL=-1 ATOL[X]=-1\n")
    b = p.blocks
    assert (b[0].adis_mm, b[0].adispos_mm) == (0.5, 2.0)
    assert (b[1].contour_tol_mm, b[1].orientation_tol_deg) == (0.02, 0.5)
    assert dict(b[1].axis_tol) == {"X": 0.01, "C": 0.1}
    assert b[2].contour_tol_mm is None                          # negative deletes
    assert dict(b[2].axis_tol) == {"C": 0.1} and b[2].orientation_tol_deg == 0.5


def test_accel_modes_and_tool_radius_compensation():
    p = sin("BRISK\nSOFT G41 G451 DISC=30\nDRIVE G42 G450\nG40\n")
    b = p.blocks
    assert [x.accel_mode for x in b] == ["BRISK", "SOFT", "DRIVE", "DRIVE"]
    assert [x.tool_compensation for x in b] == ["G40", "G41", "G42", "G40"]
    assert [x.trc_corner for x in b] == ["G450", "G451", "G450", "G450"]
    assert b[1].disc == 30.0 and b[3].disc == 30.0             # DISC is modal


def test_tangential_control_lifecycle():
    p = sin('TANG(C, X, Y, 2, "B")\nTANGON(C, 15)\nG1 X1 F60\nTLIFT(C)\nX2\nTANGOF(C)\n'
            "X3\nTANGDEL(C)\n")
    b = moves(p)
    assert b[0].tangential.axis == "C" and b[0].tangential.leading == ("X", "Y")
    assert (b[0].tangential.coupling, b[0].tangential.offset_deg) == (2.0, 15.0)
    assert not b[0].tangential.tlift and b[1].tangential.tlift
    assert b[2].tangential is None
    assert "C" in p.axes


def test_aux_words_tool_and_offset():
    p = sin("T5 D2\nM3 S12000\nG1 X1 F60 M8\n")
    b = p.blocks
    assert b[0].aux == (("T", 5.0), ("D", 2.0)) and (b[0].tool, b[0].tool_offset) == (5, 2)
    assert b[1].aux == (("M", 3.0), ("S", 12000.0)) and b[1].tool == 5
    assert b[2].aux == (("M", 8.0),) and p.warnings == ()


def test_msg_and_comment():
    p = sin('MSG("roughing; pass 1") ; why\nMSG()\n')
    assert p.blocks[0].message == "roughing; pass 1" and p.blocks[0].comment == "why"
    assert p.blocks[1].message == ""


def test_dwell_seconds_and_revolutions():
    p = sin("G1 X1 F300\nG4 F2.5\nS600 M3\nG4 S10\nX2\n")
    b = p.blocks
    assert b[1].dwell_s == 2.5 and b[1].motion is None
    assert b[3].dwell_s == pytest.approx(1.0)                  # 10 rev at 600 rpm = 1 s
    assert b[4].feed_mm_s == pytest.approx(5.0)                # G4 F is no feed: 300 mm/min
    p = sin("G4 S10\n")                                         # no spindle speed known
    assert p.blocks[0].dwell_s is None and p.blocks[0].kept_unmodelled == ("G4 S10",)
    assert "G4 S10" in p.warnings[0].message and p.warnings[0].line == 1


def test_program_end_m30_m2_m17():
    for end in ("M30", "M2", "M17"):
        p = sin(f"G1 X1 F60\n{end}\nX5\n")
        assert [b.end[0] for b in moves(p)] == [1.0]
        assert p.blocks[-1].aux == (("M", float(end[1:])),)


# ----------------------------------------------------------------- units
def test_g70_inch_lengths_keep_metric_feed_g700_converts_feed():
    p = sin("G70 G1 X1 F254\nG71 X1\nG700 X1 F10\nG710 X2\n")
    b = moves(p)
    assert b[0].end[0] == pytest.approx(25.4) and b[1].end[0] == 1.0
    assert b[0].feed_mm_s == pytest.approx(254 / 60)           # G70: F stays mm/min
    assert b[2].end[0] == pytest.approx(25.4)
    assert b[2].feed_mm_s == pytest.approx(254 / 60)           # G700: 10 in/min
    assert p.source_units == "inch"


def test_inch_does_not_scale_rotary_axes():
    p = sin("G70 G1 X1 A=90 F60\n")
    assert p.blocks[0].end == pytest.approx((25.4, 0, 0, 90.0))
    assert p.rotary == (False, False, False, True)


# ----------------------------------------------------------------- axes
def test_extra_axes_in_first_use_order_and_padding():
    p = sin("G1 X1 F60\nC=90 A=10\nELX=3\n")
    assert p.axes == ("X", "Y", "Z", "C", "A", "ELX")
    assert p.rotary == (False, False, False, True, True, False)
    assert p.blocks[0].start == (0.0,) * 6 and p.blocks[0].end == (1, 0, 0, 0, 0, 0)
    assert p.blocks[2].end == (1, 0, 0, 90, 10, 3)


# ----------------------------------------------------------------- arcs
def test_arc_centre_ijk_is_incremental_and_ac_is_absolute():
    p = sin("G1 X10 Y0 F60\nG3 X0 Y10 I-10 J0\nG2 X10 Y0 I=AC(0) J=AC(0)\n")
    b = moves(p)
    assert b[1].center[:2] == (0.0, 0.0) and b[1].plane == "G17"
    assert b[2].center[:2] == (0.0, 0.0) and b[2].motion == "G2"


def test_arc_omitted_centre_word_means_zero_offset():
    p = sin("G1 X10 Y10 F60\nG2 X20 Y10 I5\n")                # J0 implied
    assert moves(p)[1].center[:2] == (15.0, 10.0)


@pytest.mark.parametrize("cr, centre", [
    ("5", (5.0, 0.0)),                       # half circle: centre on the chord
    ("7.0710678", (5.0, -5.0)),              # G2 <= 180 deg: centre right of the chord
    ("-7.0710678", (5.0, 5.0)),              # negative: > 180 deg, centre on the left
])
def test_cr_radius_form_and_negative_radius(cr, centre):
    p = sin(f"G1 X0 Y0 F60\nG2 X10 Y0 CR={cr}\n")
    assert moves(p)[1].center[:2] == pytest.approx(centre, abs=1e-6)


def test_g18_arc_in_the_zx_plane_with_k_and_i():
    # from (X0, Z10) to (X10, Z0) around the origin: K-10 (Z), I0 (X)
    p = sin("G18 G1 X0 Z10 F60\nG2 X10 Z0 K-10 I0\n")
    b = moves(p)[1]
    assert b.plane == "G18" and (b.center[0], b.center[2]) == (0.0, 0.0)
    p = sin("G18 G1 X0 Z0 F60\nG3 Z10 X0 CR=5\n")            # half circle in Z
    assert (moves(p)[1].center[0], moves(p)[1].center[2]) == pytest.approx((0.0, 5.0))


def test_g19_arc_uses_j_and_k():
    p = sin("G19 G1 Y10 Z0 F60\nG3 Y0 Z10 J-10 K0\n")
    b = moves(p)[1]
    assert (b.center[1], b.center[2]) == (0.0, 0.0) and b.plane == "G19"


def test_helix_and_turn():
    p = sin("G1 X10 Y0 F60\nG3 X10 Y0 Z-5 I-10 J0 TURN=2\n")
    b = moves(p)[1]
    assert b.turns == 2 and b.end == (10.0, 0.0, -5.0) and b.center[:2] == (0.0, 0.0)


def test_full_circle_by_centre():
    p = sin("G1 X10 Y0 F60\nG2 I-10\n")
    b = moves(p)[1]
    assert b.start == b.end and b.center[:2] == (0.0, 0.0) and b.moves


def test_arc_radius_tolerance_accepts_last_digit_rounding():
    # start radius 10, end radius 10.0015: within max(0.002, 1e-3 * 10) = 0.01 mm
    p = sin("G1 X10 Y0 F60\nG3 X0 Y10.0015 I-10 J0\n")
    assert moves(p)[1].center[:2] == (0.0, 0.0)


# ----------------------------------------------------------------- frames
def test_trans_is_absolute_atrans_adds_and_bare_trans_resets():
    p = sin("G1 X0 F60\nTRANS X10\nX1\nATRANS X5\nX1\nTRANS Y2\nX1\nTRANS\nX1\n")
    assert [b.end[:2] for b in moves(p)] == [(0, 0), (11, 0), (16, 0), (1, 0), (1, 0)]
    # after TRANS Y2 the unprogrammed Y keeps its machine position (0); X1 -> machine 1


def test_rot_rotates_about_z_and_atrans_follows_the_rotation():
    p = sin("G1 X0 F60\nROT RPL=90\nX10\nROT Z90\nATRANS X5\nX10\nAROT RPL=-90\nX1\n")
    e = [tuple(round(v, 9) for v in b.end[:2]) for b in moves(p)]
    assert e[1] == (0.0, 10.0)                                   # X10 rotated 90 deg
    assert e[2] == (0.0, 15.0)                                   # origin moved to (0, 5)
    # AROT -90: axes parallel to the machine again, origin still (0, 5); X1 moves X to
    # 1 and the unprogrammed Y keeps its machine position 15
    assert e[3] == (1.0, 15.0)


def test_rotated_frame_turns_arcs_and_their_centres():
    p = sin("G1 X0 Y0 F60\nROT RPL=90\nG3 X0 Y10 CR=5\n")
    b = moves(p)[1]
    assert b.end[:2] == pytest.approx((-10.0, 0.0))
    assert b.center[:2] == pytest.approx((-5.0, 0.0)) and b.plane_basis is None


def test_supa_and_g53_suppress_the_frame_for_one_block():
    p = sin("G1 X0 F60\nTRANS X100\nSUPA X1\nX1\nG53 X2\n")
    assert [b.end[0] for b in moves(p)] == [0.0, 1.0, 101.0, 2.0]
    assert {w.line for w in p.warnings} == {3, 5}


# ----------------------------------------------------------------- kept with warnings
def test_cycles_system_variables_and_subprogram_calls_are_kept_with_a_warning():
    p = sin('CYCLE800(0,"TABLE",100000)\nCYCLE832(0.01,1,1)\n$AA_OVR[X]=50\nL100\n'
            "MY_SUB\nG1 X1 F60\n")
    assert [b.kept_unmodelled != () for b in p.blocks] == [True, True, True, True, True,
                                                            False]
    assert [w.line for w in p.warnings] == [1, 2, 3, 4, 5]
    assert "CYCLE832" in p.warnings[1].message


def test_path_changing_words_that_are_not_modelled_warn():
    p = sin("G1 X1 F60 OFFN=2\nX2 Y1\n")
    assert [w.line for w in p.warnings] == [1] and "OFFN=2" in p.warnings[0].message


def test_rnd_is_non_modal_and_rndm_modal():
    # RND and RNDM are modelled (reference/rounding.py): carried, not warned about
    p = sin("G1 X1 F60 RND=2\nX2 Y1 RNDM=0.5\nX3\nX4 RNDM=0\n")
    assert p.warnings == () or list(p.warnings) == []
    assert [b.rnd_mm for b in p.blocks] == [2.0, 0.0, 0.0, 0.0]
    assert [b.rndm_mm for b in p.blocks] == [0.0, 0.5, 0.5, 0.0]


def test_settable_work_offsets_warn_and_harmless_words_do_not():
    p = sin("G54\nG1 X1 F60 S1000 M3 M8\n")
    assert [w.line for w in p.warnings] == [1] and "G54" in p.warnings[0].message


def test_warning_in_a_loop_is_reported_once_per_line():
    p = sin("DEF INT i=0\nWHILE i<3\nCYCLE832(0.01,1,1)\ni=i+1\nENDWHILE\n")
    assert len(p.warnings) == 1 and p.warnings[0].line == 3
    assert sum(1 for b in p.blocks if b.kept_unmodelled) == 3


def test_arc_direction_sign_convention_matches_the_chord_side():
    # G3 from (0,0) to (10,0) with CR=7.07: centre left of the chord (y > 0)
    p = sin("G1 X0 Y0 F60\nG3 X10 Y0 CR=7.0710678\n")
    c = moves(p)[1].center
    assert c[1] == pytest.approx(5.0, abs=1e-6)
    assert math.hypot(c[0], c[1]) == pytest.approx(7.0710678, abs=1e-6)
