"""distinct_rows gives np.unique(axis=0)'s arrays exactly: rows, first indices, inverse, counts."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.geometry.rows import distinct_rows


def _assert_as_numpy(values: np.ndarray) -> None:
    rows, first, inverse, counts = np.unique(values, axis=0, return_index=True, return_inverse=True,
                                             return_counts=True)
    found = distinct_rows(values)
    np.testing.assert_array_equal(found.rows, rows)
    assert found.rows.dtype == rows.dtype
    np.testing.assert_array_equal(found.first, first)
    np.testing.assert_array_equal(found.inverse, inverse.reshape(-1))
    np.testing.assert_array_equal(found.counts, counts)
    np.testing.assert_array_equal(found.rows[found.inverse], values)


@pytest.mark.parametrize("seed", range(5))
def test_float_rows_with_repeats_as_numpy(seed):
    rng = np.random.default_rng(seed)
    pool = rng.normal(size=(200, 3))
    pool[::7, 0] = pool[1, 0]  # ties in the first column, decided by the later ones
    pool[::11, :2] = pool[2, :2]
    _assert_as_numpy(pool[rng.integers(0, len(pool), size=1000)])


def test_integer_rows_as_numpy():
    rng = np.random.default_rng(7)
    _assert_as_numpy(rng.integers(-3, 4, size=(500, 2)))


def test_negative_zero_is_zero_and_the_first_occurrence_is_kept():
    values = np.array([[0.0, 1.0], [-0.0, 1.0], [0.0, -0.0], [1.0, 0.0]])
    found = distinct_rows(values)
    assert len(found.rows) == 3
    np.testing.assert_array_equal(found.first, [2, 0, 3])
    np.testing.assert_array_equal(found.counts, [1, 2, 1])
    _assert_as_numpy(values)


def test_one_row_and_no_rows():
    _assert_as_numpy(np.array([[1.0, 2.0, 3.0]]))
    found = distinct_rows(np.zeros((0, 3)))
    assert found.rows.shape == (0, 3) and found.first.size == found.inverse.size == found.counts.size == 0


def test_a_flat_array_is_refused():
    with pytest.raises(ValueError, match=r"expects an \(n, k\) array, got shape \(4,\)"):
        distinct_rows(np.zeros(4))
