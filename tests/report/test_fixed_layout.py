"""plotting.fixed_figure: the axes sit where the margins and gaps (inches) put them."""

from __future__ import annotations

import numpy as np

from softdesign.report.plotting import fixed_figure

#: Axes positions are floats in figure fractions; in inches they agree to rounding.
POSITION_ATOL_IN = 1e-9


def test_fixed_figure_places_a_grid_at_the_given_margins_and_gaps():
    size, margins, gaps = (12.0, 7.0), (0.75, 0.25, 0.45, 0.3), (0.85, 0.75)
    figure = fixed_figure(size, margins, gaps, (2, 3))
    axes = figure.subplots(2, 3)
    # by hand: 3 columns share 12 - 0.75 - 0.25 - 2 * 0.85 = 9.3 in, 2 rows share 7 - 0.45 - 0.3 - 0.75 = 5.5 in
    width, height = 9.3 / 3, 5.5 / 2
    for row in range(2):
        for column in range(3):
            box = axes[row, column].get_position()
            x0 = 0.75 + column * (width + 0.85)
            y0 = 0.45 + (1 - row) * (height + 0.75)
            got = np.array([box.x0 * size[0], box.y0 * size[1], box.width * size[0], box.height * size[1]])
            np.testing.assert_allclose(got, [x0, y0, width, height], atol=POSITION_ATOL_IN)
    assert figure.get_layout_engine() is None  # nothing moves the axes at draw time


def test_fixed_figure_grid_with_width_ratios_keeps_the_outer_margins():
    size, margins = (12.0, 4.2), (0.7, 0.2, 0.5, 0.35)
    figure = fixed_figure(size, margins, (0.8, 0.0), (1, 3))
    grid = figure.add_gridspec(1, 3, width_ratios=(1.2, 1.4, 0.8))
    boxes = [figure.add_subplot(grid[k]).get_position() for k in range(3)]
    assert abs(boxes[0].x0 * size[0] - 0.7) < POSITION_ATOL_IN
    assert abs((1.0 - boxes[-1].x1) * size[0] - 0.2) < POSITION_ATOL_IN
    assert abs(boxes[0].y0 * size[1] - 0.5) < POSITION_ATOL_IN
    assert abs((1.0 - boxes[0].y1) * size[1] - 0.35) < POSITION_ATOL_IN
    widths = np.array([b.width for b in boxes])
    np.testing.assert_allclose(widths / widths.sum(), np.array([1.2, 1.4, 0.8]) / 3.4, atol=1e-12)
