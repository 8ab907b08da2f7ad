"""Variables, expressions and control flow of both dialects (evaluated without a machine)."""

from __future__ import annotations

import pytest

from reference.core.errors import NCSyntaxError
from reference.nc import parse_text


def sin(text: str):
    return parse_text(text, "t.mpf", "sinumerik")


def ngc(text: str):
    return parse_text(text, "t.ngc", "ngc")


def xs(prog):
    return [b.end[0] for b in prog.blocks if b.motion is not None]


def sin_value(expr: str, setup: str = "") -> float:
    """Value of a SINUMERIK expression, read back through an axis word."""
    return xs(sin(f"{setup}R99={expr}\nG1 X=R99 F60\n"))[-1]


def ngc_value(expr: str, setup: str = "") -> float:
    return xs(ngc(f"{setup}G1 X[{expr}] F60\n"))[-1]


# ----------------------------------------------------------------- SINUMERIK expressions
@pytest.mark.parametrize("expr, value", [
    ("2+3*4", 14.0), ("10-6/2", 7.0), ("(2+3)*4", 20.0), ("-2+3", 1.0), ("2*-3", -6.0),
    ("7 DIV 2", 3.0), ("-7 DIV 2", -3.0), ("7 MOD 4", 3.0), ("2+6 DIV 4", 3.0),
    ("SIN(30)", 0.5), ("COS(60)", 0.5), ("TAN(45)", 1.0), ("ASIN(0.5)", 30.0),
    ("ACOS(0.5)", 60.0), ("ATAN2(1,1)", 45.0), ("ATAN2(1,-1)", 135.0), ("SQRT(16)", 4.0),
    ("ABS(-2.5)", 2.5), ("POT(3)", 9.0), ("TRUNC(2.7)", 2.0), ("TRUNC(-2.7)", -2.0),
    ("ROUND(2.5)", 3.0), ("ROUND(-2.5)", -3.0), ("EXP(0)", 1.0), ("LN(1)", 0.0),
    ("MINVAL(3,4)", 3.0), ("MAXVAL(3,4)", 4.0),
    ("6 B_AND 3", 2.0), ("6 B_OR 3", 7.0), ("6 B_XOR 3", 5.0),
    ("1 OR 0 AND 0", 1.0),                 # AND binds tighter than OR
    ("NOT 0", 1.0), ("3 >= 2", 1.0), ("3 <> 3", 0.0),
    ("0 == 1 AND 0 == 1", 1.0),            # manual priority: 0 == (1 AND 0) == 1 -> TRUE
    ("(0 == 1) AND (0 == 1)", 0.0),
])
def test_sinumerik_operators_functions_and_priorities(expr, value):
    assert sin_value(expr) == pytest.approx(value)


def test_r_parameters_def_variables_and_assignment_forms():
    p = sin("R1=10 R[2]=R1/4\nDEF REAL a, b=2\nDEF INT n=3\nDEF BOOL ok=TRUE\n"
            "a = b*R2\nG1 X=a+n Y=R[2] Z=ok F=R1*6\n")
    b = p.blocks[-1]
    assert b.end == (8.0, 2.5, 1.0) and b.feed_mm_s == pytest.approx(1.0)


def test_undeclared_assignment_is_a_variable_with_a_warning():
    p = sin("MY_SCALE = 2\nG1 X=3*MY_SCALE F60\n")
    assert xs(p) == [6.0]
    assert p.warnings[0].line == 1 and "MY_SCALE" in p.warnings[0].message


def test_if_else_endif():
    p = sin("R1=2\nIF R1>1\nG1 X1 F60\nELSE\nG1 X2 F60\nENDIF\nIF R1==0\nX3\nENDIF\nX4\n")
    assert xs(p) == [1.0, 4.0]


def test_while_for_repeat_and_loop_with_goto():
    p = sin("DEF INT i=0\nWHILE i<3\nG1 X=i F60\ni=i+1\nENDWHILE\n"
            "FOR i=5 TO 6\nX=i\nENDFOR\n"
            "REPEAT\ni=i+1\nX=i\nUNTIL i>=9\n"
            "LOOP\ni=i+1\nIF i>10 GOTOF OUT\nX=i\nENDLOOP\nOUT: X99\n")
    assert xs(p) == [0.0, 1.0, 2.0, 5.0, 6.0, 8.0, 9.0, 10.0, 99.0]


def test_goto_forms_labels_and_block_numbers():
    p = sin("GOTOF SKIP\nG1 X1 F60\nSKIP: G1 X2 F60\nR1=0\nBACK: R1=R1+1\n"
            "IF R1<3 GOTOB BACK\nX=R1\nGOTO N50\nX7\nN50 X8\nGOTOC NOWHERE\nX9\n")
    assert xs(p) == [2.0, 3.0, 8.0, 9.0]


def test_case_dispatch():
    text = ("R1={v}\nCASE R1 OF 1 GOTOF ONE 2 GOTOF TWO DEFAULT GOTOF OTHER\n"
            "ONE: G1 X1 F60\nGOTOF END\nTWO: G1 X2 F60\nGOTOF END\nOTHER: G1 X3 F60\nEND: M30\n")
    assert xs(sin(text.format(v=2))) == [2.0]
    assert xs(sin(text.format(v=7))) == [3.0]


def test_control_flow_lines_are_not_blocks_and_loops_repeat_blocks():
    # declarations and control flow make no block; each executed line makes one
    p = sin("DEF INT i=0\nWHILE i<2\nG1 X=i F60\ni=i+1\nENDWHILE\n")
    assert [b.line for b in p.blocks] == [3, 4, 3, 4]
    assert [b.index for b in p.blocks] == [0, 1, 2, 3]


def test_sinumerik_loop_guard_names_the_loop():
    with pytest.raises(NCSyntaxError, match=r"loop does not terminate within 1000000 blocks"
                       r".*jumps back here from line 3") as info:
        sin("G1 X0 F60\nLOOP\nENDLOOP\n")
    assert (info.value.line, info.value.column) == (2, 1)


# ----------------------------------------------------------------- NGC expressions
@pytest.mark.parametrize("expr, value", [
    ("2+3*4", 14.0), ("2**3", 8.0), ("2**3**2", 64.0),       # left to right
    ("7 MOD 4", 3.0), ("-[2]+3", 1.0), ("SIN[30]", 0.5), ("COS[60]", 0.5),
    ("ATAN[1]/[1]", 45.0), ("ATAN[1]/[-1]", 135.0), ("SQRT[4]", 2.0), ("ABS[-1]", 1.0),
    ("FIX[2.7]", 2.0), ("FIX[-2.7]", -3.0), ("FUP[2.1]", 3.0), ("ROUND[2.5]", 3.0),
    ("EXP[0]", 1.0), ("LN[1]", 0.0), ("ASIN[1]", 90.0), ("ACOS[1]", 0.0),
    ("1 EQ 1 AND 2 EQ 2", 1.0), ("1 OR 0 AND 0", 0.0),        # AND OR XOR: one level
    ("3 GT 2", 1.0), ("2 LE 1", 0.0), ("1 XOR 1", 0.0), ("2 NE 3", 1.0),
])
def test_ngc_operators_and_functions(expr, value):
    assert ngc_value(expr) == pytest.approx(value)


def test_ngc_assignments_take_effect_after_the_line():
    # RS274/NGC: all values of a line are read before any parameter is set
    p = ngc("#1=1\n#1=2 #2=#1 G1 X#1 F60\nG1 Y#2 Z#1\n")
    assert p.blocks[1].end[0] == 1.0 and p.blocks[2].end[1:] == (1.0, 2.0)


def test_ngc_numbered_and_named_parameters():
    p = ngc("#1=2\n#<depth>=[#1*3]\n#[#1+1]=7\n#<_global>=1\n"
            "G1 X#1 Y-[#<depth>] Z#3 A#<_GLOBAL> F[60*#1]\n")
    b = p.blocks[-1]
    assert b.end == (2.0, -6.0, 7.0, 1.0) and b.feed_mm_s == pytest.approx(2.0)
    assert xs(ngc("G1 X#5 F60\n")) == [0.0]                  # unset numbered params are 0


def test_ngc_if_elseif_else():
    text = ("#1={v}\no10 if [#1 EQ 1]\nG1 X1 F60\no10 elseif [#1 EQ 2]\nG1 X2 F60\n"
            "o10 else\nG1 X3 F60\no10 endif\n")
    assert [xs(ngc(text.format(v=v))) for v in (1, 2, 5)] == [[1.0], [2.0], [3.0]]


def test_ngc_loops_break_and_continue():
    p = ngc("#1=0\no1 while [#1 LT 3]\nG1 X#1 F60\n#1=[#1+1]\no1 endwhile\n"
            "o2 do\n#1=[#1+1]\nG1 X#1\no2 while [#1 LT 5]\n"
            "o3 repeat [2]\nG1 Y1\nG1 Y0\no3 endrepeat\n"
            "#2=0\no4 while [1]\n#2=[#2+1]\no5 if [#2 EQ 2]\no4 continue\no5 endif\n"
            "G1 Z#2\no6 if [#2 GE 3]\no4 break\no6 endif\no4 endwhile\n")
    b = [blk for blk in p.blocks if blk.motion is not None]
    assert [x.end[0] for x in b[:5]] == [0.0, 1.0, 2.0, 4.0, 5.0]
    assert [x.end[1] for x in b[5:9]] == [1.0, 0.0, 1.0, 0.0]
    assert [x.end[2] for x in b[9:]] == [1.0, 3.0]            # 2 skipped by continue


def test_ngc_subroutines_with_arguments_and_return():
    p = ngc("o100 sub\nG1 X#1 Y#2 F60\no100 endsub\n"
            "o<side> sub\nG1 Z#1\no<side> return\nG1 Z99\no<side> endsub\n"
            "o100 call [1] [2]\no<side> call [3]\no100 call [4] [5]\nM2\n")
    e = [b.end for b in p.blocks if b.motion is not None]
    assert e == [(1.0, 2.0, 0.0), (1.0, 2.0, 3.0), (4.0, 5.0, 3.0)]


def test_ngc_loop_guard():
    with pytest.raises(NCSyntaxError, match=r"loop does not terminate within 1000000 blocks"):
        ngc("o1 while [1]\no1 endwhile\n")
