"""Path preparation: segments per block, zero-length blocks kept, stop rules."""

from __future__ import annotations

import numpy as np
import pytest

from reference.core.errors import MachineDataError, PathError
from reference.machine import load_machine
from reference.nc.program import Block, Program
from reference.prepare import prepare, require_axes, restrict_to_machine, unmodelled_features

AX = ("X", "Y", "Z")


def _prog(specs, axes=AX) -> Program:
    """Blocks from (motion, end, extra-kwargs) with start = previous end."""
    blocks, pos = [], (0.0,) * len(axes)
    for i, (motion, end, kw) in enumerate(specs):
        end = pos if end is None else tuple(float(x) for x in end)
        kw = dict(kw)
        kw.setdefault("feed_mm_s", 10.0)
        blocks.append(Block.make(index=i, line=i + 1, source=f"line {i + 1}", label=f"N{i + 1}",
                            motion=motion, start=pos, end=end, **kw))
        pos = end
    return Program(file="t.mpf", dialect="sinumerik", axes=axes,
                   rotary=tuple(a in "ABC" for a in axes), blocks=tuple(blocks))


def test_lines_and_arc_lengths_and_block_spans():
    p = prepare(_prog([
        ("G1", (10, 0, 0), {}),
        ("G3", (10, 10, 0), {"center": (10, 5, 0)}),   # half circle r = 5, CCW via x = 15
        ("G1", (0, 10, 0), {}),
    ]))
    assert p.n_segments == 3
    np.testing.assert_allclose(p.length, [10, 5 * np.pi, 10])
    q = p.evaluate(np.array([10 + 2.5 * np.pi]))[0][0]
    np.testing.assert_allclose(q, [15, 5, 0], atol=1e-12)
    assert [b.block for b in p.blocks] == [0, 1, 2]
    assert p.stop_reason[0] == "start" and p.stop_reason[-1] == "end"
    assert not p.stop[1:-1].any()


def test_full_circle_and_helix_turns():
    p = prepare(_prog([
        ("G2", (0, 0, -3), {"center": (5, 0, 0), "turns": 1}),   # 2 turns, 3 mm down
    ]))
    assert p.length[0] == pytest.approx(np.hypot(2 * 2 * np.pi * 5, 3))


def test_zero_length_blocks_are_kept_without_segments():
    p = prepare(_prog([
        ("G1", (10, 0, 0), {}),
        ("G1", (10, 0, 0), {}),                       # no motion: no segment
        (None, None, {"aux": (("M", 3.0),)}),          # executes: stop here
        (None, None, {}),                              # calculation only: no stop
        ("G1", (20, 0, 0), {}),
    ]))
    assert p.n_segments == 2
    assert len(p.blocks) == 5
    zero = [b for b in p.blocks if b.n_segments == 0]
    assert [b.block for b in zero] == [1, 2, 3]
    assert all(b.s_start == b.s_end == 10.0 for b in zero)
    assert p.stop_reason[1] == "block without path motion (M3)"


@pytest.mark.parametrize("kw, reason", [
    ({"exact_stop_here": True, "continuous_mode": "G60"}, "exact stop G60"),
    ({"exact_stop_here": True}, "exact stop G9"),
    ({"aux": (("M", 0.0),)}, "M0 programmed stop"),
])
def test_stops_at_block_end(kw, reason):
    p = prepare(_prog([("G1", (10, 0, 0), kw), ("G1", (20, 0, 0), {})]))
    assert p.stop_reason[1] == reason and p.stop[1]
    assert p.blocks[0].stop_reason == reason


def test_dwell_and_tool_change_stops():
    p = prepare(_prog([("G1", (10, 0, 0), {}), (None, None, {"dwell_s": 0.5}),
                       ("G1", (20, 0, 0), {"aux": (("M", 6.0), ("T", 2.0))}),
                       ("G1", (30, 0, 0), {"aux": (("M", 6.0),)})]))
    assert p.stop_reason[1] == "dwell G4 0.5 s"
    assert p.blocks[1].dwell_s == 0.5
    assert p.stop_reason[2] == "M6 tool change"     # aux output before motion
    assert p.stop_reason[1] != "" and p.stop_reason[3] == "end"


def test_ngc_exact_path_stops_only_at_kinks():
    p = prepare(_prog([("G1", (10, 0, 0), {"continuous_mode": "G61"}),
                       ("G1", (20, 0, 0), {"continuous_mode": "G61"}),
                       ("G1", (20, 10, 0), {"continuous_mode": "G61"})]))
    assert p.stop_reason[1] == ""                       # collinear
    assert p.stop_reason[2] == "exact path G61 corner"  # 90 degree kink


def test_g0_is_rapid_without_feed_cap():
    p = prepare(_prog([("G0", (10, 0, 0), {"feed_mm_s": None}), ("G1", (20, 0, 0), {})]))
    assert p.rapid.tolist() == [True, False]
    assert p.feed[0] == np.inf and p.feed[1] == 10.0


def test_rotary_only_move_uses_degrees_as_path_length():
    p = prepare(_prog([("G1", (0, 0, 0, 90), {})], axes=("X", "Y", "Z", "A")))
    assert p.length[0] == pytest.approx(90.0)
    p = prepare(_prog([("G1", (3, 4, 0, 90), {})], axes=("X", "Y", "Z", "A")))
    assert p.length[0] == pytest.approx(5.0)
    np.testing.assert_allclose(p.d[0], [0.6, 0.8, 0, 18.0])


def test_arc_radius_mismatch_names_file_and_line():
    with pytest.raises(PathError, match=r"t\.mpf:1: arc start radius 5 mm and end radius 6 mm"):
        prepare(_prog([("G2", (11, 0, 0), {"center": (5, 0, 0)})]))


def test_machine_without_a_moved_axis_names_the_line():
    m = load_machine()
    p = prepare(_prog([("G1", (1, 0, 0, 0), {}), ("G1", (1, 0, 0, 5), {})],
                      axes=("X", "Y", "Z", "U")))
    with pytest.raises(MachineDataError, match=r"t\.mpf:2: the program moves axis U"):
        require_axes(p, m.limits)
    # named but never moved: dropped silently
    p = prepare(_prog([("G1", (1, 0, 0, 0), {})], axes=("X", "Y", "Z", "U")))
    assert restrict_to_machine(p, m.limits).axes == AX


def test_trc_and_tangential_control_are_no_longer_unmodelled():
    # both are stages of build_path now (reference/trc.py, reference/tangential.py)
    w = unmodelled_features(_prog([("G1", (1, 0, 0), {"tool_compensation": "G41"}),
                                   ("G1", (2, 0, 0), {"tool_compensation": "G41"})]))
    assert w == ()
