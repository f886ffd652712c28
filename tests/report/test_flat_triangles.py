"""report.flat_triangles: each triangle filled in its one colour, later over earlier, neighbours without a seam."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.report.flat_triangles import FlatTriangles, add_triangles
from tests.helpers.pixels import drawn_pixels

#: 8-bit colour channels: a flat fill is exact up to the renderer's rounding of the interpolated corners.
CHANNEL_ATOL = 2
RED, BLUE = (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)


def _canvas(draw) -> np.ndarray:
    """RGB pixels (rows from the top) of a 200 x 200 px axes spanning data (0, 1) x (0, 1) on white."""
    return drawn_pixels(draw, 2.0, (0.0, 1.0))


def _pixel(image: np.ndarray, x: float, y: float) -> np.ndarray:
    """The pixel at data (x, y) of a :func:`_canvas` image."""
    rows, columns = image.shape[:2]
    return image[int((1.0 - y) * rows), int(x * columns)]


def test_a_triangle_is_filled_with_its_colour_and_nothing_outside_it():
    image = _canvas(lambda ax: add_triangles(ax, [[[0.1, 0.1], [0.9, 0.1], [0.1, 0.9]]], [RED]))
    np.testing.assert_allclose(_pixel(image, 0.3, 0.3), [255, 0, 0], atol=CHANNEL_ATOL)
    np.testing.assert_array_equal(_pixel(image, 0.8, 0.8), [255, 255, 255])  # beyond the hypotenuse


def test_later_triangles_cover_earlier_ones_painter_order():
    first = [[0.1, 0.1], [0.9, 0.1], [0.5, 0.9]]
    second = [[0.1, 0.9], [0.9, 0.9], [0.5, 0.1]]
    image = _canvas(lambda ax: add_triangles(ax, [first, second], [RED, BLUE]))
    np.testing.assert_allclose(_pixel(image, 0.5, 0.5), [0, 0, 255], atol=CHANNEL_ATOL)  # in both: the later
    np.testing.assert_allclose(_pixel(image, 0.2, 0.15), [255, 0, 0], atol=CHANNEL_ATOL)  # in the first only


def test_neighbours_of_one_colour_meet_without_a_lighter_seam():
    # a square split along its diagonal: an antialiased fill of each half leaves the diagonal's pixels part
    # background (the seam the polygons' stroked edges used to hide); these must be the faces' colour throughout
    square = [[[0.2, 0.2], [0.8, 0.2], [0.8, 0.8]], [[0.2, 0.2], [0.8, 0.8], [0.2, 0.8]]]
    image = _canvas(lambda ax: add_triangles(ax, square, [BLUE, BLUE]))
    diagonal = np.array([_pixel(image, t, t) for t in np.linspace(0.25, 0.75, 41)])
    np.testing.assert_allclose(diagonal, np.tile([0, 0, 255], (41, 1)), atol=CHANNEL_ATOL)


def test_set_data_replaces_the_triangles_and_an_rgba_colour_is_kept():
    def draw(ax):
        artist = add_triangles(ax, [[[0.1, 0.1], [0.9, 0.1], [0.1, 0.9]]], [RED])
        artist.set_data([[[0.9, 0.9], [0.1, 0.9], [0.9, 0.1]]], [(0.0, 0.0, 1.0, 1.0)])

    image = _canvas(draw)
    np.testing.assert_array_equal(_pixel(image, 0.2, 0.2), [255, 255, 255])  # the old triangle is gone
    np.testing.assert_allclose(_pixel(image, 0.8, 0.8), [0, 0, 255], atol=CHANNEL_ATOL)


@pytest.mark.parametrize(
    ("triangles", "colours", "message"),
    [
        (np.zeros((2, 4, 2)), np.zeros((2, 3)), r"triangles: expected an \(n, 3, 2\) array"),
        (np.zeros((2, 3, 2)), np.zeros((3, 3)), r"colours: expected \(2, 3\) or \(2, 4\)"),
        (np.zeros((2, 3, 2)), np.zeros((2, 5)), r"colours: expected \(2, 3\) or \(2, 4\)"),
    ],
)
def test_shapes_that_do_not_fit_are_refused(triangles, colours, message):
    with pytest.raises(ValueError, match=message):
        FlatTriangles(triangles, colours)
