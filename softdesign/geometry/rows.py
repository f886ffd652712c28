"""The distinct rows of a 2-D array, as ``np.unique(rows, axis=0)`` gives them, in a fraction of its time.

``np.unique`` with ``axis=0`` views each row as one structured element and sorts those with a generic
field-by-field comparison: about 6 s of CPU for the 3M corners of a 1M-triangle STL.  A stable
lexicographic sort of the columns (``np.lexsort``) puts the rows in the same order (first column first,
equal rows in their input order, as ``np.unique``'s stable sort does when it returns first indices), so
the distinct rows, first indices, inverse and counts are the same arrays, element for element, in about
40 % of the time.  Rows are equal when every column compares equal (``-0.0 == 0.0``; a NaN never equals
anything), as in ``np.unique``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.types import Mapper

#: Integer rows from which :func:`rows_in_first_order` given a mapper groups its two halves there (a 1M-triangle
#: STL's 3M corners: 0.65 s of hashing and sorting in one process); fewer are grouped here.
SPLIT_ROWS = 1 << 20


@dataclass(frozen=True)
class DistinctRows:
    """The distinct rows of an (n, k) array and how the input maps onto them.

    Attributes
    ----------
    rows : (m, k) the distinct rows, in lexicographic order (first column first), the input's dtype
    first : (m,) int, the input index of each distinct row's first occurrence
    inverse : (n,) int, the distinct row of each input row (``rows[inverse]`` is the input)
    counts : (m,) int, how many input rows each distinct row stands for
    """

    rows: np.ndarray
    first: np.ndarray
    inverse: np.ndarray
    counts: np.ndarray


def distinct_rows(values: npt.ArrayLike) -> DistinctRows:
    """The distinct rows of ``values`` (n, k), equal to ``np.unique(values, axis=0, return_index=True,
    return_inverse=True, return_counts=True)`` (the inverse 1-D, as numpy >= 2.0.1 returns it with an axis).

    Raises
    ------
    ValueError
        ``values`` is not 2-D.
    """
    array = np.asarray(values)
    if array.ndim != 2:
        raise ValueError(f"distinct_rows expects an (n, k) array, got shape {array.shape}")
    n = len(array)
    if n == 0 or array.shape[1] == 0:
        index = np.zeros(min(n, 1), np.intp)
        return DistinctRows(array[:1], index, np.zeros(n, np.intp), np.full(min(n, 1), n, np.intp))
    order = np.lexsort(array.T[::-1])  # the last key sorts first: column 0 is the primary key
    ordered = array[order]
    starts = np.empty(n, bool)
    starts[0] = True
    np.any(ordered[1:] != ordered[:-1], axis=1, out=starts[1:])
    inverse = np.empty(n, np.intp)
    inverse[order] = np.cumsum(starts) - 1
    start_at = np.flatnonzero(starts)
    return DistinctRows(ordered[start_at], order[start_at], inverse, np.diff(np.append(start_at, n)))


#: Odd 64-bit multipliers that mix each column's bits into a row's hash (any odd constants would do: a hash only
#: brings equal rows together, and a collision is detected and handled, see :func:`rows_in_first_order`).
_MIXERS = (0x9E3779B97F4A7C15, 0xC2B2AE3D27D4EB4F, 0x165667B19E3779F9, 0x27D4EB2F165667C5)


def rows_in_first_order(values: npt.ArrayLike, mapper: Mapper | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Groups of equal rows of ``values`` (n, k), numbered in the order of their first occurrence.

    Returns ``first`` (m,) int, the input index of each group's first row, increasing, and ``inverse`` (n,)
    int, each row's group (``values[first][inverse]`` is ``values``): what trimesh's
    ``grouping.unique_rows(..., keep_order=True)`` gives for integer rows, and, whatever the method, the only
    numbering in first-occurrence order.  Rows are equal as in :func:`distinct_rows` (``-0.0 == 0.0``; NaN never).

    The rows are hashed to one 64-bit key each and sorted by it (one stable sort of (n,) keys, not k); every
    row is then compared with the first of its key's run, so a hash collision or a NaN is seen, and those
    inputs are grouped by :func:`distinct_rows` instead: the same groups either way.  With a ``mapper`` and at
    least :data:`SPLIT_ROWS` integer rows, the rows whose first column is even and those whose first column is odd
    are hashed and sorted as two tasks of the mapper (:func:`_split_hashed_groups`): equal rows share their first
    column, so no group straddles the halves, and the numbering by first occurrence makes the same arrays.
    """
    array = np.asarray(values)
    if array.ndim != 2:
        raise ValueError(f"rows_in_first_order expects an (n, k) array, got shape {array.shape}")
    n = len(array)
    if n == 0:
        return np.zeros(0, np.intp), np.zeros(0, np.intp)
    if array.dtype.kind == "f":
        array = array + 0.0  # -0.0 becomes 0.0: equal values, equal bits
    hashable = array.dtype.itemsize <= 8 and array.shape[1] <= len(_MIXERS)
    if hashable and mapper is not None and array.dtype.kind in "iu" and n >= SPLIT_ROWS:
        joined = _split_hashed_groups(array, mapper)
        if joined is not None:
            return joined
        found = None
    else:
        found = _hashed_groups(array) if hashable else None
    if found is None:
        distinct = distinct_rows(array)
        found = distinct.first, distinct.inverse
    return _in_first_order(*found)


def _in_first_order(first: np.ndarray, inverse: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The groups (``first`` (m,) distinct first indices, ``inverse`` (n,) each row's group) numbered anew in
    increasing order of their first index: the only such numbering."""
    order = np.argsort(first, kind="stable")
    rank = np.empty(len(first), np.intp)
    rank[order] = np.arange(len(first))
    return first[order], rank[inverse]


def rows_all_distinct(values: npt.ArrayLike) -> bool:
    """True when no two rows of ``values`` (n, k) are equal (as in :func:`distinct_rows`: ``-0.0 == 0.0``, a NaN
    never equal): ``len(rows_in_first_order(values)[0]) == n``, in about a third of its time.

    Equal rows have equal hash keys (:func:`_row_keys`): when the sorted keys are all different, so are the
    rows; a repeated key (equal rows, or a collision) is settled by :func:`rows_in_first_order`.
    """
    array = np.asarray(values)
    if array.ndim != 2:
        raise ValueError(f"rows_all_distinct expects an (n, k) array, got shape {array.shape}")
    if len(array) < 2:
        return True
    if array.dtype.kind == "f":
        array = array + 0.0  # -0.0 becomes 0.0: equal values, equal bits
    if array.dtype.itemsize <= 8 and array.shape[1] <= len(_MIXERS):
        key = np.sort(_row_keys(array))
        if not np.any(key[1:] == key[:-1]):
            return True
    return len(rows_in_first_order(array)[0]) == len(array)


def _row_keys(array: np.ndarray) -> np.ndarray:
    """(n,) uint64 hash of each row of ``array`` (n, k), k <= 4 columns of at most 8 bytes: equal bits, equal key."""
    # 8-byte columns are read as they are (no copy); each step's product or shift into one buffer: the same bits
    bits = np.ascontiguousarray(array).view(f"u{array.dtype.itemsize}").astype(np.uint64, copy=False)
    key = np.zeros(len(array), np.uint64)
    term = np.empty_like(key)
    for column, mixer in zip(bits.T, _MIXERS, strict=False):
        key ^= np.multiply(column, np.uint64(mixer), out=term)
        np.left_shift(key, np.uint64(29), out=term)  # rotate, so that columns do not cancel by position
        key >>= np.uint64(35)
        key |= term
    return key


def _hashed_groups(array: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """(first index, group) of each run of equal rows after a stable sort by hash; None on a collision or NaN."""
    key = _row_keys(array)
    # not a stable sort (a third of its time on 3M keys): a run's rows come in any order, and its first is its
    # smallest index, which the stable sort put first; the same groups, numbered by key as before
    order = np.argsort(key)
    ordered_key = key[order]
    starts = np.empty(len(array), bool)
    starts[0] = True
    np.not_equal(ordered_key[1:], ordered_key[:-1], out=starts[1:])
    # each row of a run against the one before it (equality is transitive), a column at a time: a collision, or
    # a NaN (never equal), leaves a pair unequal; gathering whole rows and the runs' rows cost 2.5x as much
    for column in array.T:
        ordered = np.take(column, order)
        if not np.all((ordered[1:] == ordered[:-1]) | starts[1:]):
            return None
    group = np.cumsum(starts) - 1
    inverse = np.empty(len(array), np.intp)
    inverse[order] = group
    return np.minimum.reduceat(order, np.flatnonzero(starts)), inverse


def _split_hashed_groups(array: np.ndarray, mapper: Mapper) -> tuple[np.ndarray, np.ndarray] | None:
    """:func:`rows_in_first_order` of the integer rows (n, k), by :func:`_hashed_groups` of the rows with an even
    first column and of those with an odd one as two tasks of ``mapper``, joined; None on a collision in either half
    (the caller then groups every row by :func:`distinct_rows`).

    Each half comes back numbered in first-occurrence order (its renumbering done beside the other's), so its
    first rows are increasing here too, and :func:`_in_first_order`'s stable sort merges the two runs.
    """
    parts = mapper(lambda odd: _half_groups(array, odd), [0, 1])
    if any(part is None for part in parts):
        return None
    odd_rows = (array[:, 0] & 1).astype(bool)
    halves = (np.flatnonzero(~odd_rows), np.flatnonzero(odd_rows))  # increasing: a half's first row is its group's
    joined = np.concatenate([rows[first] for rows, (first, _) in zip(halves, parts, strict=True)])
    inverse = np.empty(len(array), np.intp)
    offset = 0
    for rows, (first, group) in zip(halves, parts, strict=True):
        inverse[rows] = offset + group  # the groups of the joined list
        offset += len(first)
    return _in_first_order(joined, inverse)


def _half_groups(array: np.ndarray, odd: int) -> tuple[np.ndarray, np.ndarray] | None:
    """:func:`_hashed_groups` of the rows of ``array`` whose first column's parity is ``odd``, numbered in their
    first-occurrence order (indices into those rows); None on a collision."""
    half = array[(array[:, 0] & 1) == odd]
    if len(half) == 0:
        return np.zeros(0, np.intp), np.zeros(0, np.intp)
    found = _hashed_groups(half)
    return None if found is None else _in_first_order(*found)
