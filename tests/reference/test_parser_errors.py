"""Every NCSyntaxError of the parser: message, 1-based line and column, both dialects."""

from __future__ import annotations

from pathlib import Path

import pytest

from reference.core.errors import NCSyntaxError
from reference.nc import parse_file, parse_text

SIN, NGC = "sinumerik", "ngc"

CASES = [
    # --- words and numbers ------------------------------------------------------------
    ("G1 X10 F100\nG1 Y1O\n", SIN, 2, 5, r"invalid number '1O' after address Y"),
    ("G1 X10 F100\nG1 Y1O\n", NGC, 2, 5, r"invalid number '1O' after address Y"),
    ("G1 X1. Y2..5 F10\n", SIN, 1, 9, r"invalid number '2\.\.5' after address Y"),
    ("G1 X1 F1\nX2 Q\n", NGC, 2, 4, r"number expected after address Q, found 'end of line'"),
    ("R1\n", SIN, 1, 1, r"R parameter needs '=' \(R1=10\)"),
    ("G77 X1\n", NGC, 1, 1, r"unknown G code G77"),
    ("N10 G1 G999 X1\n", SIN, 1, 8, r"unknown G code G999"),
    ("G1 X1 X2 F100\n", SIN, 1, 7,
     r"X is programmed twice in this block with different values \(X1 and X2\)"),
    ("G1 X1 F1 x2\n", NGC, 1, 10, r"X is programmed twice in this block"),
    ("G0 G1 X1 F1\n", NGC, 1, 4, r"G0 and G1 are in the same modal group"),
    ("G90 G91 X1\n", SIN, 1, 5, r"G90 and G91 are in the same modal group"),
    ("(unclosed comment\n", NGC, 1, 1, r"comment '\(' is not closed with '\)'"),
    # --- feed ----------------------------------------------------------------------------
    ("G1 X10\n", SIN, 1, 1, r"G1 with no feed: program F before or in this block"),
    ("G0 X1\n  Y2 G1\n", NGC, 2, 6, r"G1 with no feed: program F before or in this block"),
    ("G93 G1 X1 F1\n", NGC, 1, 1, r"inverse-time feed \(G93\) is not supported"),
    ("G1 X1 F1\nG1 G93 X2 F1\n", NGC, 2, 4, r"inverse-time feed \(G93\) is not supported"),
    ("G1 X1 F-5\n", SIN, 1, 7, r"negative feed F-5"),
    ("G4\n", SIN, 1, 1, r"G4 needs F \(seconds\) or S \(spindle revolutions\)"),
    ("G4\n", NGC, 1, 1, r"G4 needs P \(dwell time in seconds\)"),
    # --- arcs ----------------------------------------------------------------------------
    ("G1 X0 Y0 F100\nG2 X10 Y0 R4\n", NGC, 2, 11,
     r"arc radius 4 mm cannot reach the end point: the chord is 10 mm, so the radius must "
     r"be at least 5 mm \(1 mm more\)"),
    ("G1 X0 Y0 F100\nG3 X10 Y0 CR=4\n", SIN, 2, 11, r"arc radius 4 mm cannot reach"),
    ("G1 X0 Y0 F100\nG2 X10 Y1 I5 J0\n", SIN, 2, 1,
     r"arc start radius 5 mm and end radius 5\.09902 mm differ by 0\.099 mm"),
    ("G1 X0 Y0 F100\nG2 X10 Y1 I5 J0\n", NGC, 2, 1, r"end radius 5\.09902 mm differ"),
    ("G1 X10 Y0 F100\nG2 X0 Y0\n", SIN, 2, 1, r"G2 needs a centre \(I, J\) or a radius \(CR=\)"),
    ("G18 G1 X10 F100\nG3 X0 Z0\n", NGC, 2, 1, r"G3 needs a centre \(K, I\) or a radius \(R\)"),
    ("G1 X10 Y0 F100\nG2 X10 Y0 I0 J0\n", SIN, 2, 1, r"arc with zero radius"),
    ("G1 X10 Y0 F100\nG2 X20 Y0 CR=0\n", SIN, 2, 11, r"arc radius is zero"),
    ("G1 X0 Y0 F100\nG2 X0 Y0 CR=5\n", SIN, 2, 10,
     r"a full circle cannot be programmed with a radius"),
    ("G1 X10 Y0 F100\nG3 X10 Y0 I-10 P0\n", NGC, 2, 16,
     r"arc P0 must be a whole number of turns >= 1"),
    ("G1 X10 Y0 F100\nG3 X10 Y0 I-10 TURN=-1\n", SIN, 2, 16,
     r"TURN=-1 must be a whole number >= 0"),
    ("N5 X1\n", NGC, 1, 4, r"axis move without a motion command"),
    # --- expressions and variables --------------------------------------------------------
    ("R1=0\nG1 X=5/R1 F10\n", SIN, 2, 7, r"division by zero"),
    ("#1=0\nG1 X[5/#1] F10\n", NGC, 2, 7, r"division by zero"),
    ("G1 X=5 MOD 0 F1\n", SIN, 1, 8, r"division by zero"),
    ("G1 X=foo F100\n", SIN, 1, 6, r"unknown variable FOO"),
    ("G1 X#<nope> F100\n", NGC, 1, 5, r"unknown variable #<NOPE>"),
    ("G1 X=SQRT(-1) F1\n", SIN, 1, 6, r"SQRT\(-1\) is undefined"),
    ("G1 X=(1+2 F100\n", SIN, 1, 11, r"missing '\)'"),
    ("G1 X[1+2 F100\n", NGC, 1, 10, r"missing '\]'"),
    ("G1 X=1+2) F1\n", SIN, 1, 9, r"unexpected '\)'"),
    ("G1 X[1+2]] F1\n", NGC, 1, 10, r"unexpected '\]'"),
    ("G1 X=\n", SIN, 1, 6, r"expression expected"),
    # --- conditions that need a machine ---------------------------------------------------
    ("IF $AA_IM[X] > 1\nENDIF\n", SIN, 1, 4,
     r"system variable \$AA_IM needs a real control and cannot be evaluated here"),
    ("WHILE $P_SEARCH\nENDWHILE\n", SIN, 1, 7, r"system variable \$P_SEARCH needs a real"),
    ("IF UNKNOWNVAR > 1\nENDIF\n", SIN, 1, 4, r"unknown variable UNKNOWNVAR"),
    # --- control flow ---------------------------------------------------------------------
    ("IF 1==1\nG1 X1 F100\n", SIN, 1, 1, r"IF is never closed \(missing ENDIF\)"),
    ("WHILE 1\nG1 X1 F100\n", SIN, 1, 1, r"WHILE is never closed \(missing ENDWHILE\)"),
    ("ELSE\n", SIN, 1, 1, r"ELSE without IF"),
    ("ENDWHILE\n", SIN, 1, 1, r"ENDWHILE without WHILE"),
    ("o1 if [1]\nG1 X1 F1\n", NGC, 1, 1, r"o1 if is never closed"),
    ("o1 while [1]\n", NGC, 1, 1, r"o1 while is never closed"),
    ("GOTOF NOWHERE\n", SIN, 1, 1, r"GOTOF NOWHERE: no label NOWHERE after this line"),
    ("G1 X1 F1\nGOTOB NOWHERE\n", SIN, 2, 1, r"GOTOB NOWHERE: no label NOWHERE before"),
    ("o9 call\n", NGC, 1, 1, r"o9 call: no subroutine o9 in this file"),
    # --- unsupported features that would change the path ------------------------------------
    ("G1 X1 F1\nROT A30\n", SIN, 2, 5, r"ROT A: rotations are about the geometry axes X, Y and Z"),
    ("G81 X1 Y1 Z-1 R1 F1\n", NGC, 1, 1, r"canned cycle G81 is not supported"),
    ("G95 G1 X1 F1\n", NGC, 1, 1, r"feed per revolution \(G95\) is not supported"),
    ("DISC=120\n", SIN, 1, 1, r"DISC=120 must be between 0 and 100"),
    ("G1 X0 Y0 F1\nG2 X10 Y0 AR=90\n", SIN, 2, 11, r"arcs by opening angle \(AR=\) are not "
     r"supported"),
]


@pytest.mark.parametrize("text, dialect, line, col, match", CASES,
                         ids=[f"{c[1][:3]}-{i}" for i, c in enumerate(CASES)])
def test_error_message_line_and_column(text, dialect, line, col, match):
    with pytest.raises(NCSyntaxError, match=match) as info:
        parse_text(text, "prog.nc", dialect)
    err = info.value
    assert (err.file, err.line, err.column) == ("prog.nc", line, col)
    assert str(err).startswith(f"prog.nc:{line}:{col}: ")


def test_errors_are_value_errors_with_one_line_messages():
    with pytest.raises(ValueError) as info:
        parse_text("G1 X10\n", "a.mpf", "sinumerik")
    assert "\n" not in str(info.value)


def test_unknown_extension_names_it_and_the_dialect_option(tmp_path: Path):
    f = tmp_path / "part.gcode"
    f.write_text("G1 X1 F60\n")
    with pytest.raises(NCSyntaxError, match=r"unknown program extension '\.gcode'.*--dialect") \
            as info:
        parse_file(f)
    assert (info.value.line, info.value.column) == (1, 1)
    assert parse_file(f, dialect="ngc").blocks[0].end[0] == 1.0


@pytest.mark.parametrize("name, dialect", [("a.MPF", SIN), ("a.spf", SIN), ("a.ngc", NGC),
                                           ("a.NC", NGC), ("a.tap", NGC)])
def test_dialect_from_extension_any_case(tmp_path: Path, name, dialect):
    f = tmp_path / name
    f.write_bytes(b"G1 X1 F60\r\n")
    assert parse_file(f).dialect == dialect


def test_file_encoding_utf8_and_latin1(tmp_path: Path):
    f = tmp_path / "u.mpf"
    f.write_bytes("; Ma\u00dfe in mm\nG1 X1 F60\n".encode("utf-8"))
    assert parse_file(f).blocks[0].end[0] == 1.0
    f.write_bytes("; Ma\u00dfe in mm\nG1 X2 F60\n".encode("latin-1"))
    assert parse_file(f).blocks[0].end[0] == 2.0


def test_unknown_dialect():
    with pytest.raises(NCSyntaxError, match=r"unknown dialect 'fanuc'"):
        parse_text("G1 X1\n", "p", "fanuc")
