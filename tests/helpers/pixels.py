"""Pixels of something drawn on a bare matplotlib axes, for tests of the report's drawing primitives."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from softdesign.report.plotting import DPI, new_figure


def drawn_pixels(draw: Callable[[Any], Any], size_in: float, limits: tuple[float, float]) -> np.ndarray:
    """RGB pixels (int, rows from the top) of a square axes filling a ``size_in`` figure, both axes at ``limits``.

    ``draw(ax)`` adds the artists; the axes has no frame or ticks and the background is white.
    """
    figure = new_figure((size_in, size_in), fixed=True)
    ax = figure.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_axis_off()
    draw(ax)
    ax.set_xlim(*limits)
    ax.set_ylim(*limits)
    figure.canvas.draw()
    pixels = np.asarray(figure.canvas.buffer_rgba())[:, :, :3].astype(int)
    assert pixels.shape[:2] == (round(size_in * DPI),) * 2
    return pixels
