"""G643: rounding inside the original blocks (issue 13 item 3; reference/rounding.py
``_inside_the_blocks``, reference/core/rows.py ``interpolation_lengths``).

spec 5.5 (G643, [S2][S5][S1]): "Same tolerance sources as G642 (units digit of MD20480).
No separate rounding block is inserted; the rounding is carried out inside the original
blocks. The overload factor is never taken into account." Spec 2: "Block-internal
rounding (no separate block)". Spec 5.3 / 1: "every block, the rounding block included,
needs at least one IPO cycle". So the rounding is part of the two blocks beside the
corner: no row of its own, no one-IPO-cycle cap of its own (its block's). Not modelled
(spec 5.5 "Model [I]: each axis gets its own transition window"): the per-axis windows;
the rounding keeps the common shape of G642 (tangent arc under BRISK, clothoid pair
under SOFT), which keeps every axis within MD33100.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from reference.core.geometry import KIND_CODES
from reference.nc import parse_text
from reference.planner import plan
from reference.prepare import build_path
from rounding_machines import rounding_machine

ROUNDING = KIND_CODES.index("rounding")


def machine(tol: float = 0.01, **channel):
    return rounding_machine(tol, **channel)


def square(mode: str, accel: str = "BRISK") -> str:
    return f"G17 G90 {mode} {accel} F3000\nG1 X0 Y0\nG1 X50\nG1 Y50\nG1 X0\n"


@pytest.mark.parametrize("accel", ["BRISK", "SOFT"])
def test_g643_rounds_inside_the_blocks_by_hand(accel):
    """The 90 degree corners of the square (C = (50, 0), (50, 50)), MD33100 0.01 mm: the
    rounding deviates by 0.01 mm per axis (|C - M| = 0.01 sqrt(2)), as with G642, but the
    block boundary moves from the corner to the rounding's middle M, the point nearest
    to C: M = C + 0.01 (-1, 1) on the first corner. Under BRISK the tangent arc (d =
    |C - M| / tan(22.5 deg), R = d) is cut into two arcs of R pi / 4; block 2 is its line
    X0 -> X50 - d and the first half, block 3 the second half, its line and the first
    half of the next corner. The plan's rows are the blocks' (no rounding row), and the
    trace and inspect name each corner's rounding."""
    prog = parse_text(square("G643", accel))
    path = build_path(prog, machine())
    t = path.rounding
    assert t.inserted.all() and t.internal.all()
    np.testing.assert_allclose(t.deviation_mm, 0.01 * math.sqrt(2), rtol=1e-12)
    spans = {sp.block: sp for sp in path.blocks}
    k = spans[2].first_segment + spans[2].n_segments - 1
    assert path.kind[k] == ROUNDING and path.kind[k + 1] == ROUNDING
    np.testing.assert_allclose(path.segment(k).end[:2], [49.99, 0.01], atol=1e-12)
    assert spans[3].first_segment == k + 1
    assert [path.block[j] for j in (k, k + 1)] == [2, 3]
    if accel == "BRISK":
        d = 0.01 * math.sqrt(2) / math.tan(math.pi / 8)
        assert spans[2].length == pytest.approx(50 - d + d * math.pi / 4, rel=1e-12)
        assert spans[3].length == pytest.approx(50 - 2 * d + d * math.pi / 2, rel=1e-12)
        np.testing.assert_allclose(path.length[[k, k + 1]], d * math.pi / 4, rtol=1e-12)
    for j in range(path.n_segments - 1):
        a, b = path.segment(j), path.segment(j + 1)
        np.testing.assert_allclose(a.end, b.start, atol=1e-12)
        np.testing.assert_allclose(a.end_tangent, b.start_tangent, atol=1e-12)
    res = plan(prog, machine(), path=path)
    assert res.ok
    rows = list(res.blocks)
    assert [r.block for r in rows] == [b.index for b in prog.blocks]
    assert all(r.kind != "rounding" for r in rows)
    note = dict(res.trace)["rounding"]
    assert "3 inside the blocks (G643)" not in note and "2 inside the blocks (G643)" in note


def test_g643_has_no_ipo_cycle_cap_of_its_own():
    """spec 5.3: "every block, the rounding block included, needs at least one
    interpolation point, so the path velocity is limited to about ADIS / T_ipo"; 5.5:
    G643 inserts no block. MD33100 = 1e-4 mm on a 90 degree corner, BRISK: d = 1e-4
    sqrt(2) / tan(22.5 deg) = 3.414e-4 mm = R, arc R pi / 2 = 5.36e-4 mm. Under G642 the
    rounding is a block of its own: at most 5.36e-4 mm / 4 ms = 0.134 mm/s through it.
    Under G643 its halves are part of the 50 mm blocks (their cap 12.5 m/s does not
    bind): the centripetal limit sqrt(0.75 A R) = 0.716 mm/s is reached. (G642 with
    MD20490 = TRUE, which rounds it however slowly, spec 4.3; G643 always does.)"""
    mach = machine(1e-4, IGNORE_OVL_FACTOR_FOR_ADIS=True)
    R = 1e-4 * math.sqrt(2) / math.tan(math.pi / 8)
    caps = {"G642": R * math.pi / 2 / 0.004, "G643": math.sqrt(0.75 * 2000.0 * R)}
    assert caps["G642"] == pytest.approx(0.134, abs=1e-3)
    assert caps["G643"] == pytest.approx(0.716, abs=1e-3)
    for mode, cap in caps.items():
        prog = parse_text(square(mode))
        path = build_path(prog, mach)
        assert path.rounding.inserted.all()
        res = plan(prog, mach, path=path)
        k = np.flatnonzero(path.kind == ROUNDING)
        s = np.concatenate([np.linspace(path.s_breaks[j], path.s_breaks[j + 1], 51)
                            for j in k])
        v = res.profile.state(res.profile.time_at(s))[1]
        assert v.max() == pytest.approx(cap, rel=1e-6), mode
        assert res.ok
