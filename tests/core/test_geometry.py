"""Exact geometry: derivatives vs finite differences, arc-length consistency (seeded)."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from scipy.integrate import quad

from reference.core.errors import PathError
from reference.core.geometry import (SPAN_COLUMNS, BlockSpan, BlockSpans, arc_segment,
                                     line_segments, path_from_pieces)

AX = ("X", "Y", "Z", "A", "B")
GEO = np.array([True, True, True, False, False])
PLANES = {"G17": (0, 1), "G18": (2, 0), "G19": (1, 2)}


def random_arc(rng, plane, clockwise, turns=0, helix=True):
    u, v = PLANES[plane]
    w = 3 - u - v
    c = rng.uniform(-50, 50, 5)
    r = rng.uniform(0.5, 30)
    a0, a1 = rng.uniform(-np.pi, np.pi, 2)
    start = c.copy()
    start[u] += r * np.cos(a0)
    start[v] += r * np.sin(a0)
    end = c.copy()
    end[u] += r * np.cos(a1)
    end[v] += r * np.sin(a1)
    end[w] = start[w] + (rng.uniform(-20, 20) if helix else 0.0)
    end[3:] = start[3:] + rng.uniform(-90, 90, 2)
    return start, end, c, (u, v), clockwise, turns


def arcs_helices_and_a_spiral(rng):
    """Six arc pieces of blocks 0..5 in G17, turning both ways: three helices, two
    plane arcs and a spiral (its end radius 0.3 mm off)."""
    pieces = []
    for k in range(6):
        start, end, c, pl, cw, turns = random_arc(rng, "G17", bool(k % 2), 0,
                                                  helix=k < 3)
        if k == 5:
            end = end + 0.3 * (end - c) / np.linalg.norm((end - c)[:2]) * GEO
        pieces.append(arc_segment(start, end, c, pl, cw, turns, GEO, k, 1.0))
    return pieces


def fd_check(seg, rng):
    L = seg.length
    s = rng.uniform(0.05 * L, 0.95 * L, 20)
    h = 1e-5 * max(L, 1.0)
    for k in range(3):
        fp = seg.evaluate(s + h)[k]
        fm = seg.evaluate(s - h)[k]
        np.testing.assert_allclose((fp - fm) / (2 * h), seg.evaluate(s)[k + 1],
                                   rtol=1e-5, atol=1e-6 * (1 + np.abs(seg.evaluate(s)[k + 1]).max()))


@pytest.mark.parametrize("plane", ["G17", "G18", "G19"])
@pytest.mark.parametrize("clockwise", [False, True])
def test_arc_and_helix_derivatives_and_length(plane, clockwise):
    rng = np.random.default_rng(hash((plane, clockwise)) % 2**32)
    for _ in range(10):
        start, end, c, pl, cw, turns = random_arc(rng, plane, clockwise, int(rng.integers(0, 2)))
        p = path_from_pieces(AX, [arc_segment(start, end, c, pl, cw, turns, GEO, 0, 1e-6)])
        seg = p.segment(0)
        fd_check(seg, rng)
        np.testing.assert_allclose(seg.start, start, atol=1e-9)
        np.testing.assert_allclose(seg.end, end, atol=1e-7)
        # s is the arc length of the geometry axes: |q'_geo| = 1 everywhere
        s = np.linspace(0, seg.length, 50)
        np.testing.assert_allclose(np.linalg.norm(seg.evaluate(s)[1][:, :3], axis=1), 1.0,
                                   rtol=1e-12)
        integral, _ = quad(lambda x: np.linalg.norm(seg.evaluate(x)[1][0, :3]), 0, seg.length,
                           limit=200)
        assert integral == pytest.approx(seg.length, rel=1e-9)
        q = seg.evaluate(np.linspace(0, seg.length, 20001))[0][:, :3]
        chords = np.sum(np.linalg.norm(np.diff(q, axis=0), axis=1))
        assert chords == pytest.approx(seg.length, rel=1e-6)


@pytest.mark.parametrize("plane", ["G17", "G18", "G19"])
def test_direction_of_rotation(plane):
    u, v = PLANES[plane]
    start = np.zeros(5)
    start[u] = 10.0
    end = np.zeros(5)
    end[v] = 10.0                     # quarter turn counter-clockwise from u to v
    for cw, sweep in ((False, np.pi / 2), (True, 3 * np.pi / 2)):
        seg = path_from_pieces(AX, [arc_segment(start, end, np.zeros(5), (u, v), cw, 0, GEO,
                                                0, 1e-9)]).segment(0)
        assert seg.length == pytest.approx(10 * sweep)
        mid = seg.evaluate(seg.length / 2)[0][0]
        assert (mid[v] < 0) == cw      # the clockwise arc goes the long way through -v


def test_full_circle_and_extra_turns():
    start = np.array([5.0, 0, 0, 0, 0])
    for turns in (0, 2):
        seg = path_from_pieces(AX, [arc_segment(start, start, np.zeros(5), (0, 1), True, turns,
                                                GEO, 0, 1e-9)]).segment(0)
        assert seg.length == pytest.approx(2 * np.pi * 5 * (turns + 1))


def test_lines_with_extra_axes_and_rotary_only_moves():
    rng = np.random.default_rng(7)
    starts = rng.uniform(-10, 10, (20, 5))
    ends = starts + rng.uniform(-5, 5, (20, 5))
    ends[0, :3] = starts[0, :3]                  # only rotary axes move
    p = path_from_pieces(AX, [line_segments(starts, ends, GEO, np.arange(20))])
    np.testing.assert_allclose(p.length[1:], np.linalg.norm((ends - starts)[1:, :3], axis=1))
    assert p.length[0] == pytest.approx(np.linalg.norm(ends[0, 3:] - starts[0, 3:]))
    for i in range(20):
        fd_check(p.segment(i), rng)
        np.testing.assert_allclose(p.segment(i).end, ends[i], atol=1e-12)


def test_arc_radius_mismatch_and_zero_radius():
    s = np.array([10.0, 0, 0, 0, 0])
    e = np.array([0.0, 10.01, 0, 0, 0])
    with pytest.raises(PathError, match=r"start radius 10 mm and end radius 10\.01 mm"):
        arc_segment(s, e, np.zeros(5), (0, 1), False, 0, GEO, 0, 0.002)
    with pytest.raises(PathError, match="zero radius"):
        arc_segment(s, e, s, (0, 1), False, 0, GEO, 0, 0.002)


def test_path_evaluate_sides_at_breaks_and_junction_tangents():
    pts = np.array([[0, 0, 0, 0, 0], [10, 0, 0, 0, 0], [10, 10, 0, 0, 0]], float)
    p = path_from_pieces(AX, [line_segments(pts[:-1], pts[1:], GEO, np.arange(2))])
    left = p.evaluate(np.array([10.0]), side="left")[1][0]
    right = p.evaluate(np.array([10.0]), side="right")[1][0]
    np.testing.assert_allclose(left[:3], [1, 0, 0])
    np.testing.assert_allclose(right[:3], [0, 1, 0])
    t_in, t_out = p.junction_tangents()
    np.testing.assert_allclose(t_in[0, :3], [1, 0, 0])
    np.testing.assert_allclose(t_out[0, :3], [0, 1, 0])
    assert p.block_of(np.array([5.0, 15.0])).tolist() == [0, 1]


def test_tangents_alone_are_the_tangents_of_evaluate_and_the_finite_differences():
    """Path.tangents (the tangent without the other derivatives, as the rounding stage
    and junction_tangents ask for it) on lines, arcs, helices and a spiral: bit for bit
    evaluate's second output, and the central difference of the positions (an
    independent check of the formula)."""
    rng = np.random.default_rng(11)
    pieces = arcs_helices_and_a_spiral(rng)
    pts = rng.uniform(-20, 20, (4, 5))
    pieces.append(line_segments(pts[:-1], pts[1:], GEO, np.arange(6, 9)))
    p = path_from_pieces(AX, pieces)
    assert (p.dradius != 0).any() and (p.kind == p.kind[-1]).sum() == 3
    s = np.sort(rng.uniform(0.0, p.total_length, 400))
    for side in ("left", "right"):
        assert np.array_equal(p.tangents(s, side), p.evaluate(s, side)[1])
    h = 1e-6
    inner = s[(s > h) & (s < p.total_length - h)]
    seg = p.segment_index(inner)
    keep = (p.segment_index(inner - h) == seg) & (p.segment_index(inner + h) == seg)
    fd = (p.evaluate(inner[keep] + h)[0] - p.evaluate(inner[keep] - h)[0]) / (2 * h)
    np.testing.assert_allclose(p.tangents(inner[keep]), fd, atol=1e-6)
    # at the breaks: junction_tangents are the tangents at each segment's two ends
    t_in, t_out = p.junction_tangents()
    at = np.arange(p.n_segments - 1)
    ends = p.s_breaks[1:-1]
    np.testing.assert_allclose(t_in, p.tangents(ends, segment=at), atol=1e-12)
    assert np.array_equal(t_out, p.tangents(ends, segment=at + 1))


def test_junction_derivatives_are_evaluate_at_both_ends_and_the_finite_differences():
    """Path.junction_derivatives (the first two derivatives alone, as the planner's
    corner stage asks for them) on lines, arcs, helices, a spiral and clothoid pairs:
    bit for bit the full evaluation's second and third outputs at each segment's local
    ends (the position and third derivative left out change nothing), evaluate's at
    the global breaks (bit for bit at a segment's start; at its end the global position
    turned local differs by round-off), and the one-sided differences of the tangents
    there (an independent check of the curvature formulas)."""
    from reference.core.geometry import KIND_CODES, _eval_helical, clothoid_pieces
    rng = np.random.default_rng(12)
    pieces = arcs_helices_and_a_spiral(rng)
    # three clothoid pairs (each a rising and a falling piece) in tilted planes
    t1 = rng.normal(size=(3, 5)) * GEO
    t1 /= np.linalg.norm(t1, axis=1)[:, None]
    t2 = rng.normal(size=(3, 5)) * GEO
    t2 /= np.linalg.norm(t2, axis=1)[:, None]
    pieces.append(clothoid_pieces(rng.uniform(-20, 20, (3, 5)), t1, t2,
                                  rng.uniform(0.5, 3.0, 3), np.arange(6, 9),
                                  KIND_CODES.index("rounding")))
    pts = rng.uniform(-20, 20, (4, 5))
    pieces.append(line_segments(pts[:-1], pts[1:], GEO, np.arange(9, 12)))
    p = path_from_pieces(AX, pieces)
    assert (p.dradius != 0).any() and np.count_nonzero(p.sharpness) == 6
    t_in, t_out, k_in, k_out = p.junction_derivatives()
    at = np.arange(p.n_segments - 1)
    cols = (p.origin, p.e1, p.e2, p.d, p.radius, p.omega, p.theta0)
    full_in = _eval_helical(*cols, at, p.length[:-1], p.dradius, p.length, p.sharpness)
    full_out = _eval_helical(*cols, at + 1, np.zeros(at.size), p.dradius, p.length,
                             p.sharpness)
    assert np.array_equal(t_in, full_in[1]) and np.array_equal(k_in, full_in[2])
    assert np.array_equal(t_out, full_out[1]) and np.array_equal(k_out, full_out[2])
    ends = p.s_breaks[1:-1]
    before = p.evaluate(ends, segment=at)
    after = p.evaluate(ends, segment=at + 1)
    np.testing.assert_allclose(t_in, before[1], atol=1e-12)
    np.testing.assert_allclose(k_in, before[2], atol=1e-12)
    assert np.array_equal(t_out, after[1]) and np.array_equal(k_out, after[2])
    h = 1e-6
    fd_in = (before[1] - p.evaluate(ends - h, segment=at)[1]) / h
    fd_out = (p.evaluate(ends + h, segment=at + 1)[1] - after[1]) / h
    scale = 1.0 + np.abs(np.concatenate((k_in, k_out))).max()
    np.testing.assert_allclose(k_in, fd_in, atol=1e-4 * scale)
    np.testing.assert_allclose(k_out, fd_out, atol=1e-4 * scale)


def test_restricted_path_keeps_the_moving_axes_exactly():
    """A 2-D contour on an XYZ path: ``moving_axes`` names X and Y (Z never moves),
    and the restricted path has the same lengths, breaks and the very same X/Y values
    of position, tangent, curvature and third derivative, junction tangents included."""
    from reference.nc import parse_text
    from reference.machine import load_machine
    from reference.prepare import build_path

    text = ("G90 G17 G1 X10 Y0 F3000\nG3 X20 Y10 CR=10\nG1 X20 Y30\n"
            "G2 X10 Y40 CR=10\nG1 X0 Y40\nM30\n")
    path = build_path(parse_text(text, "t.mpf"), load_machine(None))
    mov = path.moving_axes()
    assert [path.axes[i] for i in mov] == ["X", "Y"]
    sub = path.restricted(mov)
    assert sub.axes == ("X", "Y")
    np.testing.assert_array_equal(sub.s_breaks, path.s_breaks)
    s = np.linspace(0.0, path.total_length, 301)
    for full, part in zip(path.evaluate(s), sub.evaluate(s)):
        np.testing.assert_array_equal(part, full[:, mov])
        # the dropped columns are constant (zero derivatives)
    _, dq, ddq, d3 = path.evaluate(s)
    rest = np.setdiff1d(np.arange(path.n_axes), mov)
    assert not np.any(dq[:, rest]) and not np.any(ddq[:, rest]) and not np.any(d3[:, rest])
    for full, part in zip(path.junction_tangents(), sub.junction_tangents()):
        np.testing.assert_array_equal(part, full[:, mov])


# ----------------------------------------------------------------- block spans
SPANS = (BlockSpan(0, 1, "N10", "G1", 0.0, 2.5, 0, 1, 100.0),
         BlockSpan(1, 2, "", "none", 2.5, 2.5, 1, 0, stop_reason="dwell G4 0.5 s",
                   dwell_s=0.5),
         BlockSpan(2, 4, "N30", "G0", 2.5, 7.0, 1, 2, stop_reason="exact stop G9"))


def test_block_spans_are_the_spans_they_were_made_of():
    """``BlockSpans`` (columns) reads back as the very ``BlockSpan`` values, in every
    access: iteration, index (negative too), slice, columns; and a path stores any
    sequence of spans as columns."""
    cols = BlockSpans.of(SPANS)
    fresh = BlockSpans(*(getattr(cols, c) for c in SPAN_COLUMNS))    # no kept objects
    for spans in (cols, fresh):
        assert len(spans) == 3 and bool(spans)
        assert tuple(spans) == SPANS and spans == SPANS
        assert spans[-1] == SPANS[2] and spans[1:] == SPANS[1:]
        assert all(type(getattr(spans[0], f)) is type(getattr(SPANS[0], f))
                   for f in SPAN_COLUMNS)                     # Python numbers, not numpy
        np.testing.assert_array_equal(spans.s_end, [2.5, 2.5, 7.0])
        np.testing.assert_array_equal(spans.length, [2.5, 0.0, 4.5])
        assert spans.kind == ("G1", "none", "G0")
        assert pickle.loads(pickle.dumps(spans)) == SPANS
    with pytest.raises(IndexError):
        fresh[3]
    with pytest.raises(AttributeError):
        cols.s_end = None
    assert not cols.s_end.flags.writeable
    path = path_from_pieces(("X",), [line_segments(np.zeros((1, 1)), np.ones((1, 1)),
                                                   np.array([True]), np.array([0]))])
    assert isinstance(path.blocks, BlockSpans)


def test_block_spans_moved_keeps_everything_but_the_position():
    """``moved`` changes the path range and segment range only."""
    spans = BlockSpans.of(SPANS)
    new = spans.moved(np.array([0.0, 2.0, 2.0]), np.array([2.0, 2.0, 6.0]),
                      np.array([0, 2, 2]), np.array([2, 0, 3]))
    for old, sp in zip(SPANS, new):
        assert (sp.s_start, sp.s_end, sp.first_segment, sp.n_segments) != (
            old.s_start, old.s_end, old.first_segment, old.n_segments)
        assert (sp.block, sp.line, sp.label, sp.kind, sp.feed_mm_s, sp.stop_reason,
                sp.dwell_s) == (old.block, old.line, old.label, old.kind, old.feed_mm_s,
                                old.stop_reason, old.dwell_s)
