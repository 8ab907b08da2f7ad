"""Row-wise reductions over axis columns: the very numbers numpy's reductions give.

The planner's stages call them where they used ``numpy.linalg.norm(x, axis=-1)``,
``x.min(axis=1)`` and the like on (k, n) arrays, so plans stay identical bit for bit; the
reference is numpy's own reduction on seeded data with the values that matter (zeros,
infinities, ties, tiny and huge magnitudes, NaN where the function allows it).
"""

from __future__ import annotations

import numpy as np
import pytest

from reference.core.arrays import (row_any, row_argmin, row_dots, row_max, row_min,
                                   row_norms, row_sums)

COLUMNS = (1, 2, 3, 4, 5, 6, 7, 8, 9, 12)


def data(n: int, seed: int, nan: bool = True) -> np.ndarray:
    rng = np.random.default_rng(seed)
    k = 5000
    x = rng.standard_normal((k, n)) * 10.0 ** rng.uniform(-12, 12, (k, 1))
    x[::13] = 0.0
    x[::17, 0] = np.inf
    x[::19, -1] = -np.inf
    x[::23] = np.round(x[::23])                 # ties inside a row
    x[::29, :] = x[::29, :1]                    # every column equal
    if nan:
        x[::31, n // 2] = np.nan
    return x


@pytest.mark.parametrize("n", COLUMNS)
@pytest.mark.parametrize("seed", range(3))
def test_row_norms_equal_numpy_bit_for_bit(n, seed):
    x = data(n, seed)
    np.testing.assert_array_equal(row_norms(x), np.linalg.norm(x, axis=-1))
    y = x[:, ::-1]                               # not contiguous
    np.testing.assert_array_equal(row_norms(y), np.linalg.norm(y, axis=-1))


@pytest.mark.parametrize("n", COLUMNS)
@pytest.mark.parametrize("seed", range(3))
def test_row_sums_equal_numpy_bit_for_bit(n, seed):
    x = data(n, seed)
    with np.errstate(invalid="ignore"):                   # inf - inf
        np.testing.assert_array_equal(row_sums(x), x.sum(axis=1))
        np.testing.assert_array_equal(row_sums(x[:, ::-1]), x[:, ::-1].sum(axis=1))


@pytest.mark.parametrize("n", COLUMNS)
@pytest.mark.parametrize("seed", range(3))
def test_row_dots_equal_numpy_bit_for_bit(n, seed):
    x, y = data(n, seed), data(n, seed + 10)[::-1]
    with np.errstate(invalid="ignore", over="ignore"):     # inf * 0, huge * huge
        np.testing.assert_array_equal(row_dots(x, y), np.sum(x * y, axis=1))


@pytest.mark.parametrize("n", COLUMNS)
@pytest.mark.parametrize("seed", range(3))
def test_row_min_max_any_equal_numpy(n, seed):
    x = data(n, seed)
    np.testing.assert_array_equal(row_min(x), x.min(axis=1))
    np.testing.assert_array_equal(row_max(x), x.max(axis=1))
    np.testing.assert_array_equal(row_any(x > 1.0), np.any(x > 1.0, axis=1))


@pytest.mark.parametrize("n", COLUMNS)
@pytest.mark.parametrize("seed", range(3))
def test_row_argmin_equals_numpy_without_nan(n, seed):
    x = data(n, seed, nan=False)
    np.testing.assert_array_equal(row_argmin(x), x.argmin(axis=1))


def test_empty_shapes():
    assert row_norms(np.zeros((0, 3))).shape == (0,)
    assert row_min(np.zeros((0, 2))).shape == (0,)
    assert row_any(np.zeros((4, 0), bool)).tolist() == [False] * 4
    np.testing.assert_array_equal(row_norms(np.zeros((3, 0))), np.zeros(3))
