"""Grid refinement: halving and quartering marked intervals (optimal.grid)."""

from __future__ import annotations

import numpy as np
import pytest

from optimal.grid import grid_from_counts, subdivide
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
