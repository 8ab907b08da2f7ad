"""NC parser: features of both dialects, arc conventions, expressions, control flow, errors."""

from __future__ import annotations

import numpy as np
import pytest

from reference.core.errors import NCSyntaxError
from reference.nc import parse_file, parse_text
from shared_inputs import NO_CORPUS, corpus_listing


def sin(text):
    return parse_text(text, "t.mpf", "sinumerik")


def ngc(text):
    return parse_text(text, "t.ngc", "ngc")


def moves(prog):
    return [b for b in prog.blocks if b.motion is not None]


def end(prog, i=-1):
    return np.array(moves(prog)[i].end[:3])


# ------------------------------------------------------------------------ basics
def test_modal_words_absolute_incremental_and_feed():
    p = sin("G90 G1 X10 Y5 F600\nX20\nG91 X5 Y5\nG90 X=IC(1) Y=AC(2)\n")
    assert [b.end[:2] for b in moves(p)] == [(10, 5), (20, 5), (25, 10), (26, 2)]
    assert moves(p)[0].feed_mm_s == pytest.approx(10.0)
    assert all(b.motion == "G1" for b in moves(p))


def test_crlf_tabs_lowercase_and_unspaced_words():
    p = ngc("g21 g90\r\nG1X1.5y2\tF60\rG64P.005Q.01\nG1 X3\n")
    assert end(p, 0)[:2].tolist() == [1.5, 2.0]
    blk = moves(p)[-1]
    assert blk.continuous_mode == "G64" and blk.contour_tol_mm == pytest.approx(0.005)
    assert blk.naive_cam_tol_mm == pytest.approx(0.01)


def test_inch_units_convert_positions_and_feed():
    p = ngc("G20 G90\nG1 X1 F10\n")
    assert end(p)[0] == pytest.approx(25.4)
    assert moves(p)[0].feed_mm_s == pytest.approx(254.0 / 60)
    assert p.source_units == "inch"
    p = sin("G70\nG1 X2 F10\nG71 X2\n")
    assert end(p, 0)[0] == pytest.approx(50.8) and end(p)[0] == pytest.approx(2.0)


def test_comments_messages_and_block_numbers():
    p = ngc("N10 G1 X1 F100 (move) ; tail\n(MSG, hello world)\n")
    assert p.blocks[0].label == "N10" and "move" in p.blocks[0].comment
    assert p.blocks[1].message == "hello world"
    p = sin('N5 MSG("check <b>tool</b>") ; c\nG1 X1 F100\n')
    assert p.blocks[0].message == "check <b>tool</b>" and p.blocks[0].comment == "c"


# ------------------------------------------------------------------------ arcs
def test_sinumerik_arc_ijk_incremental_and_ac():
    p = sin("G1 X10 Y0 F100\nG3 X0 Y10 I-10 J0\nG2 X10 Y0 I=AC(0) J=AC(0)\n")
    b = moves(p)[1]
    assert b.center[:2] == (0.0, 0.0) and b.motion == "G3"
    assert moves(p)[2].center[:2] == (0.0, 0.0)


def test_ngc_arc_centre_modes():
    p = ngc("G1 X10 Y0 F100\nG3 X0 Y10 I-10 J0\n")
    assert moves(p)[1].center[:2] == (0.0, 0.0)
    p = ngc("G90.1\nG1 X10 Y0 F100\nG3 X0 Y10 I0 J0\n")
    assert moves(p)[1].center[:2] == (0.0, 0.0)


@pytest.mark.parametrize("text, dialect, centre", [
    ("G1 X0 Y0 F100\nG2 X10 Y0 CR=5\n", "sinumerik", (5.0, 0.0)),
    ("G1 X0 Y0 F100\nG3 X10 Y0 CR=7.0710678\n", "sinumerik", (5.0, 5.0)),
    ("G1 X0 Y0 F100\nG3 X10 Y0 CR=-7.0710678\n", "sinumerik", (5.0, -5.0)),
    ("G1 X0 Y0 F100\nG2 X10 Y0 R7.0710678\n", "ngc", (5.0, -5.0)),
    ("G1 X0 Y0 F100\nG2 X10 Y0 R-7.0710678\n", "ngc", (5.0, 5.0)),
])
def test_radius_programming_and_negative_radius(text, dialect, centre):
    p = parse_text(text, "t", dialect)
    np.testing.assert_allclose(moves(p)[1].center[:2], centre, atol=1e-6)


def test_g18_arc_uses_k_and_i_in_zx_plane():
    p = ngc("G18\nG1 X0 Z10 F100\nG2 X10 Z0 I0 K-10\n")
    b = moves(p)[1]
    assert b.plane == "G18" and b.center[0] == 0.0 and b.center[2] == 0.0


def test_helix_turns_and_full_circle():
    p = ngc("G1 X10 Y0 F100\nG3 X10 Y0 Z-5 I-10 J0 P3\n")
    b = moves(p)[1]
    assert b.turns == 2 and b.end[2] == -5
    p = sin("G1 X10 Y0 F100\nG2 X10 Y0 I-10 TURN=1\n")
    assert moves(p)[1].turns == 1


# ------------------------------------------------------------- modes and words
def test_group10_exact_stop_and_criteria():
    p = sin("G1 X1 F100\nG9 X2\nX3\nG60 G602 X4\nG64 X5\nG641 ADIS=0.5 X6\n")
    b = moves(p)
    assert [x.exact_stop_here for x in b] == [False, True, False, True, False, False]
    assert b[3].continuous_mode == "G60" and b[3].exact_stop_criterion == "G602"
    assert b[5].continuous_mode == "G641" and b[5].adis_mm == 0.5
    p = ngc("G61.1 G1 X1 F10\nG61 X2\nG64 X3\n")
    assert [x.continuous_mode for x in moves(p)] == ["G60", "G61", "G64"]
    assert moves(p)[0].exact_stop_here


def test_brisk_soft_trc_tolerances_and_aux():
    p = sin("SOFT G42 G451 DISC=50 CTOL=0.02 OTOL=1 ATOL[X]=0.01\nT3 D1 M6\n"
            "G1 X1 F100 M8 S12000\nBRISK G40 X2\n")
    b = p.blocks
    assert b[0].accel_mode == "SOFT" and b[0].tool_compensation == "G42"
    assert b[0].trc_corner == "G451" and b[0].disc == 50 and b[0].contour_tol_mm == 0.02
    assert b[0].axis_tol == (("X", 0.01),)
    assert b[1].tool == 3 and b[1].tool_offset == 1 and ("M", 6.0) in b[1].aux
    assert b[2].aux == (("M", 8.0), ("S", 12000.0))
    assert b[3].accel_mode == "BRISK" and b[3].tool_compensation == "G40"


def test_dwell_both_dialects():
    assert sin("G4 F2.5\n").blocks[0].dwell_s == 2.5
    assert ngc("G4 P0.5\n").blocks[0].dwell_s == 0.5
    # a dwell's F is not a feed
    p = sin("G1 X1 F100\nG4 F3\nX2\n")
    assert moves(p)[1].feed_mm_s == pytest.approx(100 / 60)


def test_tangential_control():
    p = sin("TANG(C, X, Y, 1)\nTANGON(C, 90)\nTLIFT(C)\nG1 X10 F100\nTANGOF(C)\nG1 X20\n")
    b = moves(p)
    assert b[0].tangential is not None and b[0].tangential.axis == "C"
    assert b[0].tangential.offset_deg == 90 and b[0].tangential.tlift
    assert b[1].tangential is None


def test_extra_axes_and_rotary():
    p = sin("G1 X1 A=10 B=-1.5 C=90. ELX=3 F100\n")
    assert p.axes == ("X", "Y", "Z", "A", "B", "C", "ELX")
    assert p.rotary == (False, False, False, True, True, True, False)
    assert p.blocks[0].end == (1.0, 0.0, 0.0, 10.0, -1.5, 90.0, 3.0)


# --------------------------------------------------- expressions, control flow
def test_sinumerik_variables_and_functions():
    p = sin("DEF REAL a=2, b\nR1=10\nb=a*3\nG1 X=R1/a+b F=R1*60\nY=SIN(30)*2 Z=5 DIV 2\n"
            "X=POT(3) Y=ATAN2(1,1) Z=7 MOD 4\n")
    b = moves(p)
    assert b[0].end[0] == pytest.approx(11.0) and b[0].feed_mm_s == pytest.approx(10.0)
    assert b[1].end[1] == pytest.approx(1.0) and b[1].end[2] == 2.0
    assert b[2].end == pytest.approx((9.0, 45.0, 3.0))


def test_ngc_parameters_and_expressions():
    p = ngc("#1=2\n#<depth>=[#1*3]\nG1 X[#1+1] Y-[#<depth>] Z[SIN[30]*2] F[100*#1]\n"
            "G1 X[ATAN[1]/[1]] Y[2**3] Z[7 MOD 4]\n")
    b = moves(p)
    assert b[0].end == pytest.approx((3.0, -6.0, 1.0))
    assert b[1].end == pytest.approx((45.0, 8.0, 3.0))


def test_sinumerik_if_else_while_for_goto():
    p = sin("DEF INT i=0\nWHILE i<3\nG1 X=i F100\ni=i+1\nENDWHILE\n"
            "IF i==3\nY1\nELSE\nY2\nENDIF\n"
            "FOR i=1 TO 2\nZ=i\nENDFOR\n"
            "GOTOF SKIP\nX99\nSKIP: X7\n")
    e = [b.end for b in moves(p)]
    assert [x[0] for x in e[:3]] == [0.0, 1.0, 2.0]
    assert e[3][1] == 1.0
    assert [x[2] for x in e[4:6]] == [1.0, 2.0]
    assert e[-1][0] == 7.0 and all(x[0] != 99 for x in e)


def test_ngc_o_words_if_while_sub():
    p = ngc("#1=0\no100 while [#1 LT 3]\nG1 X#1 F100\n#1=[#1+1]\no100 endwhile\n"
            "o200 if [#1 EQ 3]\nG1 Y1\no200 else\nG1 Y2\no200 endif\n"
            "o300 sub\nG1 Z#1\no300 endsub\no300 call [5]\nM2\n")
    e = [b.end for b in moves(p)]
    assert [x[0] for x in e[:3]] == [0.0, 1.0, 2.0]
    assert e[3][1] == 1.0 and e[4][2] == 5.0


def test_loop_guard():
    with pytest.raises(NCSyntaxError, match=r"does not end within 1000000 lines executed again"):
        sin("L1: G1 X1 F100\nGOTOB L1\n")


def test_program_end_stops_execution():
    p = ngc("G1 X1 F100\nM2\nG1 X5\n")
    assert len(moves(p)) == 1


def test_cycles_and_system_variables_are_kept_with_a_warning():
    p = sin("CYCLE800(1,\"TC1\",0)\n$AA_IW[X]=1\nG1 X1 F100\n")
    assert len(p.blocks) == 3
    assert p.blocks[0].kept_unmodelled and p.blocks[0].motion is None
    assert [w.line for w in p.warnings] == [1, 2]
    assert "CYCLE800" in p.warnings[0].message


# ------------------------------------------------------------------------ errors
@pytest.mark.parametrize("text, dialect, line, col, match", [
    ("G1 X10 F100\nG1 Y1O\n", "sinumerik", 2, 5, r"invalid number '1O' after address Y"),
    ("G1 X10 F100\nG1 Y1O\n", "ngc", 2, 5, r"invalid number '1O' after address Y"),
    ("G1 X10\n", "sinumerik", 1, 1, r"G1 with no feed: program F before or in this block"),
    ("G2 X10 Y0 F100\n", "ngc", 1, 1, r"G2 needs a centre \(I, J\) or a radius \(R\)"),
    ("G1 X0 Y0 F100\nG2 X10 Y0 R4\n", "ngc", 2, 11,
     r"arc radius 4 mm cannot reach the end point: the chord is 10 mm"),
    ("G1 X0 Y0 F100\nG2 X10 Y1 I5 J0\n", "sinumerik", 2, 1,
     r"arc start radius 5 mm and end radius 5\.09902 mm differ by 0\.099 mm"),
    ("G77 X1\n", "ngc", 1, 1, r"unknown G code G77"),
    ("G93 G1 X1 F1\n", "ngc", 1, 1, r"inverse-time feed \(G93\) is not supported"),
    ("X=1/0\n", "sinumerik", 1, 4, r"division by zero"),
    ("G1 X=foo F100\n", "sinumerik", 1, 6, r"unknown variable FOO"),
    ("IF 1==1\nG1 X1 F100\n", "sinumerik", 1, 1, r"IF is never closed \(missing ENDIF\)"),
    ("GOTOF NOWHERE\n", "sinumerik", 1, 1, r"GOTOF NOWHERE: no label NOWHERE after this line"),
    ("G1 X[1+2 F100\n", "ngc", 1, 10, r"missing '\]'"),
    ("IF $AA_IM[X] > 1\nENDIF\n", "sinumerik", 1, 4, r"system variable \$AA_IM needs a real control"),
    ("G1 X0 Y0 F100\nG2 X0 Y0 CR=5\n", "sinumerik", 2, 10, r"a full circle cannot be programmed with a radius"),
    ("(unclosed comment\n", "ngc", 1, 1, r"comment '\(' is not closed"),
])
def test_error_messages(text, dialect, line, col, match):
    with pytest.raises(NCSyntaxError, match=match) as info:
        parse_text(text, "prog", dialect)
    err = info.value
    assert (err.file, err.line) == ("prog", line)
    assert err.column == col
    assert str(err).startswith(f"prog:{line}:{col}: ")


def test_unknown_extension(tmp_path):
    f = tmp_path / "a.gcode"
    f.write_text("G1 X1 F1\n")
    with pytest.raises(NCSyntaxError, match=r"unknown program extension '\.gcode'.*--dialect"):
        parse_file(f)
    assert parse_file(f, dialect="ngc").blocks[0].end[0] == 1.0


# ------------------------------------------------------------------------ corpus
CORPUS_FILES = corpus_listing("*.*")


@pytest.mark.skipif(not CORPUS_FILES, reason=NO_CORPUS)
def test_corpus_counts():
    progs = {f.name: parse_file(f) for f in CORPUS_FILES if f.suffix != ".md"}
    assert len(moves(progs["lcnc_short_segments_0.001.ngc"])) >= 3000
    raster = moves(progs["sin_cead_loop.mpf"])
    ys = {round(b.end[1], 6) for b in raster}
    assert {950.0, 1050.0} <= ys and len(ys) >= 100          # 1 mm rows from 950 to 1050
    helix = [b for b in moves(progs["lcnc_tangent_helix.ngc"]) if b.is_arc][0]
    assert helix.end[:2] == helix.start[:2]                      # full turn in XY
