"""Building blocks of the frequency oracle's upper bound (optimal.freq.upper), each
against a brute-force evaluation of its definition, and the closed form on lines."""

from __future__ import annotations

import numpy as np
import pytest

from optimal.freq.upper import _passes, _window_min, cone_envelope


@pytest.mark.parametrize("seed", range(4))
def test_cone_envelope_is_its_definition(seed):
    # c(p) = min over q of max(cap(q), |s_p - s_q| / W), by an O(N^2) table
    rng = np.random.default_rng(seed)
    s = np.sort(rng.uniform(0.0, 50.0, 300))
    cap = rng.uniform(0.0, 200.0, 300)
    cap[rng.integers(0, 300, 30)] = rng.uniform(0.0, 5.0, 30)    # a few corners
    W = 0.05
    ref = np.min(np.maximum(cap[None, :], np.abs(s[:, None] - s[None, :]) / W), axis=1)
    got = cone_envelope(s, cap, W)
    np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-9)


@pytest.mark.parametrize("seed", range(4))
def test_window_min_is_the_minimum_of_each_window(seed):
    rng = np.random.default_rng(seed)
    x = rng.normal(size=1000)
    lo = rng.integers(0, 999, 500)
    hi = lo + 1 + rng.integers(0, 1000 - lo)
    np.testing.assert_array_equal(_window_min(x, lo, hi),
                                  [x[a:b].min() for a, b in zip(lo, hi)])


@pytest.mark.parametrize("seed", range(4))
def test_passes_are_the_largest_profile_under_the_caps(seed):
    # forward then backward recursion, one node at a time (the textbook passes)
    rng = np.random.default_rng(seed)
    b = rng.uniform(0.0, 1e4, 400)
    b[[0, -1]] = 0.0
    step = rng.uniform(0.0, 300.0, 399)
    ref = b.copy()
    for i in range(399):
        ref[i + 1] = min(ref[i + 1], ref[i] + step[i])
    for i in range(398, -1, -1):
        ref[i] = min(ref[i], ref[i + 1] + step[i])
    np.testing.assert_allclose(_passes(b, step), ref, rtol=1e-12, atol=1e-9)
