"""Grid refinement: halving and quartering marked intervals (optimal.grid)."""

from __future__ import annotations

import numpy as np
import pytest

from optimal.grid import grid_from_counts, subdivide, with_nodes
from oracle_cases import line_arc_line


@pytest.mark.parametrize("pieces", [2, 4, 8])
def test_subdivide_splits_marked_intervals_into_equal_parts(pieces):
    path = line_arc_line(5.0, 20.0)
    g = grid_from_counts(path, np.array([3, 8, 3]))
    rng = np.random.default_rng(pieces)
    mark = rng.random(g.n_intervals) < 0.4
    new = subdivide(g, path, mark, pieces)
    assert new.n_intervals == g.n_intervals + (pieces - 1) * int(mark.sum())
    assert np.all(np.isin(g.s, new.s))                     # old nodes are kept
    for k in range(g.n_intervals):
        inside = new.s[(new.s > g.s[k]) & (new.s < g.s[k + 1])]
        if mark[k]:
            # pieces - 1 new nodes, equally spaced (hand arithmetic)
            expect = g.s[k] + (g.s[k + 1] - g.s[k]) * np.arange(1, pieces) / pieces
            np.testing.assert_allclose(inside, expect, rtol=0, atol=1e-12)
        else:
            assert inside.size == 0
    # every new interval keeps the segment of the interval it came from
    mid = 0.5 * (new.s[:-1] + new.s[1:])
    parent = np.searchsorted(g.s, mid) - 1
    np.testing.assert_array_equal(new.segment, g.segment[parent])
    np.testing.assert_array_equal(new.s[new.break_node], path.s_breaks)


def test_subdivide_rejects_pieces_that_are_not_powers_of_two():
    path = line_arc_line(5.0, 20.0)
    g = grid_from_counts(path, np.array([2, 2, 2]))
    with pytest.raises(ValueError, match="power of two"):
        subdivide(g, path, np.ones(g.n_intervals, bool), 3)


def test_subdivide_takes_pieces_per_interval():
    path = line_arc_line(5.0, 20.0)
    g = grid_from_counts(path, np.array([3, 8, 3]))
    pieces = np.array([1, 2, 4, 8, 1, 1, 2, 1, 1, 8, 1, 4, 1, 2])
    new = subdivide(g, path, pieces > 1, pieces)
    assert new.n_intervals == int(pieces.sum())
    for k in range(g.n_intervals):
        inside = new.s[(new.s > g.s[k]) & (new.s < g.s[k + 1])]
        expect = g.s[k] + (g.s[k + 1] - g.s[k]) * np.arange(1, pieces[k]) / pieces[k]
        np.testing.assert_allclose(inside, expect, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(new.s[new.break_node], path.s_breaks)


def test_refinement_halves_a_spread_gap_and_cuts_a_concentrated_one_finer():
    """The prediction model of ``optimal.oracle._refine_marks`` (an interval cut into
    ``2^l`` pieces keeps ``R^l`` of its gap), worked by hand: an even gap is met by the
    cheapest cuts, halvings; a gap carried by a few intervals by cutting those finer."""
    from optimal.oracle import _refine_marks
    from optimal.tolerances import REFINE_RESIDUAL as R

    path = line_arc_line(5.0, 20.0)
    g = grid_from_counts(path, np.array([20, 40, 20]))
    N = g.n_intervals
    t_lb = np.ones(N)
    # even gap 0.01 s per interval; target: (1 - (1 - R) / 2) of it, met by halving
    # half of the intervals
    d = np.full(N, 0.01)
    pieces = _refine_marks(path, g, t_lb + d, t_lb, 1.0, None, N, d.sum() * (1 + R) / 2)
    assert set(np.unique(pieces)) == {1, 2}
    assert abs(int((pieces == 2).sum()) - N // 2) <= 1
    # two intervals carry nearly all of it: they are cut into 4 or 8, nothing else
    d = np.full(N, 1e-6)
    d[[7, 50]] = 0.5
    pieces = _refine_marks(path, g, t_lb + d, t_lb, 1.0, None, N, 0.15 * d.sum())
    assert pieces[7] >= 4 and pieces[50] >= 4
    assert np.all(pieces[np.setdiff1d(np.arange(N), [7, 50])] == 1)
    # predicted remainder R^l per cut interval meets the target
    lev = np.log2(pieces).astype(int)
    assert float(np.sum(d * R ** lev)) <= 0.15 * d.sum()
    # the budget bounds the new intervals
    pieces = _refine_marks(path, g, t_lb + 0.01, t_lb, 1.0, None, 5, 0.0)
    assert int((pieces - 1).sum()) <= 5


def test_with_nodes_keeps_every_gap_above_the_floor():
    """Hand case: nodes 0, 1, 2 mm, floor 0.01 mm. Kept: 0.5 and 1.5; dropped: -0.5 and
    2.0005 (outside), 0.005 and 1.995 (within the floor of an end), 1.004 (of a node),
    0.503 (of the new 0.5, the first of the two kept), an exact duplicate of 0.5."""
    s = np.array([0.0, 1.0, 2.0])
    new = np.array([1.5, 0.503, 0.5, 0.5, -0.5, 2.0005, 0.005, 1.995, 1.004])
    out = with_nodes(s, new, 0.01)
    np.testing.assert_array_equal(out, [0.0, 0.5, 1.0, 1.5, 2.0])
    assert np.all(np.diff(with_nodes(s, np.linspace(0.0, 2.0, 4001), 0.01)) > 0.01)
    np.testing.assert_array_equal(with_nodes(s, np.zeros(0), 0.01), s)
