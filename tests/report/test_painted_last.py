"""projection.painted_last: of the points in a screen cell only the last drawn is kept, and the picture holds."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.report.projection import painted_last
from tests.helpers.pixels import drawn_pixels

#: Share of the painted pixels a drawing of the kept points may change by more than an eighth of full scale
#: (where markers of different colours overlap at a cell's border).
CHANGED_PIXELS_SHARE = 0.02


def test_the_last_point_in_each_cell_is_kept_in_drawing_order():
    points = np.array([[0.1, 0.0], [5.2, 5.0], [0.4, 0.2], [0.2, 0.9], [5.5, 5.1], [9.0, 0.0]])
    # cells of 1 from the lowest corner (0.1, 0): points 0, 2, 3 share (0, 0); 1 and 4 share (5, 5); 5 is alone
    np.testing.assert_array_equal(painted_last(points, 1.0), [3, 4, 5])


def test_every_point_is_kept_when_each_has_a_cell_of_its_own():
    points = np.column_stack([np.arange(10.0), np.zeros(10)])
    np.testing.assert_array_equal(painted_last(points, 0.5), np.arange(10))


def test_no_points_and_a_bad_cell():
    assert len(painted_last(np.zeros((0, 2)), 1.0)) == 0
    with pytest.raises(ValueError, match="cell must be > 0"):
        painted_last(np.ones((3, 2)), 0.0)
    with pytest.raises(ValueError, match="too small for the points' extent"):
        painted_last(np.array([[0.0, 0.0], [1e9, 1e9]]), 1e-9)


def _scatter_pixels(xy: np.ndarray, colours: np.ndarray) -> np.ndarray:
    """RGB pixels of the points as the exclusion map draws them, on a 300 x 300 px axes spanning (-1, 1)."""
    return drawn_pixels(lambda ax: ax.scatter(xy[:, 0], xy[:, 1], s=1.0, c=colours, linewidths=0), 3.0, (-1.0, 1.0))


def test_drawing_only_the_kept_points_leaves_the_picture_as_it_was():
    rng = np.random.default_rng(7)
    xy = rng.normal(0.0, 0.25, (200_000, 2))
    # two classes in patches, as the map's reasons are: colour by the side of a wavy line
    colours = np.where((xy[:, 1] > 0.2 * np.sin(8 * xy[:, 0]))[:, None], [[0.8, 0.8, 0.8, 1]], [[0.9, 0.4, 0.1, 1]])
    cell = 0.5 * 2.0 / 300  # half a pixel of a 300-pixel axes spanning 2
    kept = painted_last(xy, cell)
    assert len(kept) < len(xy) / 2  # it thins
    before, after = _scatter_pixels(xy, colours), _scatter_pixels(xy[kept], colours[kept])
    painted = np.any(before < 255, axis=2) | np.any(after < 255, axis=2)
    changed = np.abs(before - after).max(axis=2) > 32
    assert changed.sum() <= CHANGED_PIXELS_SHARE * painted.sum()
