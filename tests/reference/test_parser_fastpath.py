"""The fast lane for plain word lines gives exactly what the full grammar gives.

Plain ``G0/G1/G2/G3 X Y Z I J K F`` lines (NGC also ``R``) skip the per-word objects;
any line it does not handle, and every error, goes the full way. Turning the fast lane
off must not change a single block.
"""

from __future__ import annotations

import math
import random

import pytest

from reference.core.errors import NCSyntaxError
from reference.nc import interp, parse_text


def _program(dialect: str, seed: int, n: int = 600) -> str:
    rng = random.Random(seed)
    lines = ["G90 G1 X0 Y0 Z0 F1000" if dialect == "sinumerik" else "G21 G90 G1 X0 Y0 F1000"]
    x = y = 0.0
    for i in range(n):
        u = rng.random()
        if u < 0.05:
            lines.append(rng.choice([
                "G18\nG2 I1 K0 Y1\nG17", "G19\nG3 J1 K0 X1\nG17",   # full turns, ZX / YZ
                "G91\nG1 X0 Y0 Z1\nG90", "G64", "G0 Z5", "M8", "G1 F600", "N99",
                "G1 X1 Y1 M8 S9000 M7", "G1 Z1 S0", "G1 Z2 S100 S100",
                "; note" if dialect == "sinumerik" else "(note)"]))
            x = 1.0 if "G19" in lines[-1] or "X1 Y1" in lines[-1] else x   # absolute X1/Y1
            y = 1.0 if "G18" in lines[-1] or "X1 Y1" in lines[-1] else y
        elif u < 0.45:
            x, y = x + rng.uniform(-5, 5), y + rng.uniform(-5, 5)
            lines.append(f"N{i} G1 X{x:.3f} Y{y:.3f}" + (" F1200" if u < 0.1 else ""))
        elif u < 0.55:
            x = rng.uniform(-1, 1)
            lines.append(f"G1 X{x:.3f}\tZ{rng.uniform(-1, 1):.3f}")
            lines.append(f"Y{y:.3f}")                       # modal continuation
        elif u < 0.8 or dialect == "sinumerik":
            g = rng.choice(["G2", "G3"])             # a full turn around a random centre
            lines.append(f"{g} I{rng.uniform(-3, 3):.3f} J{rng.uniform(-3, 3):.3f} "
                         f"K{rng.uniform(-3, 3):.3f} Z{rng.uniform(-2, 2):.3f}")
        else:
            r = rng.uniform(1, 4) * rng.choice([1, -1])
            lines.append(f"{rng.choice(['G2', 'G3'])} X{x + 1:.3f} Y{y + 1:.3f} R{r:.3f}")
            x, y = x + 1, y + 1
    return "\n".join(lines) + "\nM30\n"


def _fields(b):
    return (b.index, b.line, b.label, b.motion, b.start, b.end, b.center, b.turns,
            b.feed_mm_s, b.exact_stop_here, b.modal, b.extra)


@pytest.mark.parametrize("dialect", ["sinumerik", "ngc"])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_fast_lane_equals_full_grammar(dialect, seed, monkeypatch):
    text = _program(dialect, seed)
    fast = parse_text(text, "t", dialect)
    monkeypatch.setattr(interp, "_fast_block", lambda ip, st, words: False)
    full = parse_text(text, "t", dialect)
    assert len(fast.blocks) == len(full.blocks) > 600
    for a, b in zip(fast.blocks, full.blocks):
        assert _fields(a) == _fields(b)
    assert fast.axes == full.axes and fast.warnings == full.warnings


@pytest.mark.parametrize("text, match", [
    ("G1 X1\n", r"G1 with no feed"),                                 # the full path reports
    ("G1 X0 Y0 F60\nG2 X10 Y1 I5 J0\n", r"differ by"),
    ("G1 X0 Y0 F60\nG2 X10 Y0 R4\n", r"cannot reach the end point"),
    ("G1 X1 X2 F60\n", r"programmed twice"),
])
def test_fast_lane_leaves_errors_to_the_full_path(text, match):
    with pytest.raises(NCSyntaxError, match=match):
        parse_text(text, "t", "ngc")


def test_long_program_of_short_moves():
    # a 20 000-line CAM-like program (the 10^5-line speed is measured, not asserted)
    n = 20_000
    text = "G90 G64 F6000\n" + "".join(
        f"N{i} G1 X{math.cos(i / 500) * 50:.3f} Y{math.sin(i / 500) * 50:.3f}\n"
        for i in range(n)) + "M30\n"
    prog = parse_text(text, "bench.mpf", "sinumerik")
    assert len(prog.blocks) == n + 2
    assert all(b.modal is prog.blocks[1].modal for b in prog.blocks[1:-1])  # shared
    assert prog.blocks[-2].end == pytest.approx((math.cos((n - 1) / 500) * 50,
                                                 math.sin((n - 1) / 500) * 50, 0.0), abs=1e-3)
