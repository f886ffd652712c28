"""matplotlib without pyplot: Agg figures, fixed styling, reproducible PNG bytes.

Figures are made with :class:`matplotlib.figure.Figure` on an Agg canvas, so
nothing depends on a display, a backend setting or pyplot's global state.
A PNG's pixel size is its figure size in inches times :data:`DPI` (no tight
bounding box), so the page can state every image's size in advance.  PNG
metadata carries no software version or time: the same build gives the same
bytes.
"""

from __future__ import annotations

import io
from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # matplotlib is imported when a figure is drawn
    from matplotlib.typing import RcKeyType

#: Resolution of every PNG, dots per inch.
DPI = 100
#: rcParams for every figure: fixed font and sizes, a fixed SVG hash salt (reproducible if ever saved as SVG).
STYLE: dict[RcKeyType, Any] = {
    "font.family": "DejaVu Sans",
    "font.size": 8.5,
    "axes.titlesize": 9.5,
    # titles sit at the axes' top (plus axes.titlepad) instead of being moved above whatever the axes draw there:
    # no figure puts ticks or labels above its axes, and measuring them for every title took a third of some
    # figures' drawing time.  Tick labels are whole values, never an offset written above the y axis (1.0002, not
    # "+1" and 0.0002), so no offset text can meet a title either
    "axes.titley": 1.0,
    "axes.formatter.useoffset": False,
    "axes.labelsize": 8.5,
    "legend.fontsize": 7.5,
    "xtick.labelsize": 7.5,
    "ytick.labelsize": 7.5,
    "svg.hashsalt": "softdesign-report",
    "path.simplify": True,
    "figure.dpi": DPI,
}
#: zlib level of the PNGs: 3 encodes about twice as fast as Pillow's default 6 for about 5 % more bytes.
PNG_COMPRESS_LEVEL = 3
#: Colours of the frame axes in triads: N, B, T as red, green, blue (x, y, z by habit).
TRIAD_COLOURS = ("#d62728", "#2ca02c", "#1f77b4")
#: Link colours (up to six links; more take evenly spaced colours of "plasma"): kept apart from the triads'.
LINK_PALETTE = ("#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#bcbd22", "#17becf")


@dataclass(frozen=True)
class Picture:
    """One rendered image for the page.

    Attributes
    ----------
    name : file name inside ``report/`` (``morph.png``)
    data : the encoded image
    size : (width, height) in pixels
    title, caption : what the page says above and below it
    """

    name: str
    data: bytes
    size: tuple[int, int]
    title: str
    caption: str


def new_figure(size_in: tuple[float, float], fixed: bool = False):
    """An empty Agg figure of ``size_in`` inches (width, height) with :data:`STYLE` applied.

    Its layout is matplotlib's constrained one, or none when ``fixed`` (see :func:`fixed_figure`).
    """
    import matplotlib
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    with matplotlib.rc_context(STYLE):
        figure = Figure(figsize=size_in, dpi=DPI, layout=None if fixed else "constrained")
    FigureCanvasAgg(figure)
    return figure


def fixed_figure(size_in: tuple[float, float], margins_in: tuple[float, float, float, float],
                 gaps_in: tuple[float, float], grid: tuple[int, int]):
    """An Agg figure like :func:`new_figure` but with a fixed layout instead of matplotlib's constrained one.

    For a plain grid of ``grid`` (rows, columns) axes: ``margins_in`` (left, right, bottom, top) and ``gaps_in``
    (between columns, between rows) in inches, sized for the tick labels, axis labels and titles the figure
    draws.  Solving the constrained layout measures every tick label twice (about half of a plain figure's
    drawing time); a fixed grid costs nothing.
    """
    figure = new_figure(size_in, fixed=True)
    (width, height), (rows, columns) = size_in, grid
    left, right, bottom, top = margins_in
    axes_w = (width - left - right - gaps_in[0] * (columns - 1)) / columns
    axes_h = (height - bottom - top - gaps_in[1] * (rows - 1)) / rows
    figure.subplots_adjust(left=left / width, right=1.0 - right / width, bottom=bottom / height, top=1.0 - top / height,
                           wspace=gaps_in[0] / axes_w, hspace=gaps_in[1] / axes_h)
    return figure


def styled():
    """Context manager applying :data:`STYLE` while artists are created and drawn."""
    import matplotlib

    return matplotlib.rc_context(STYLE)


def pixel_size(size_in: tuple[float, float]) -> tuple[int, int]:
    """Pixel (width, height) of a PNG of a figure of ``size_in`` inches at :data:`DPI`."""
    return int(round(size_in[0] * DPI)), int(round(size_in[1] * DPI))


def png_bytes(figure) -> bytes:
    """The figure as PNG bytes, without software or time metadata (reproducible)."""
    buffer = io.BytesIO()
    with styled():
        figure.savefig(buffer, format="png", dpi=DPI, metadata={"Software": None},
                       pil_kwargs={"compress_level": PNG_COMPRESS_LEVEL})
    return buffer.getvalue()


def picture(name: str, figure, size_in: tuple[float, float], title: str, caption: str) -> Picture:
    """Render ``figure`` to a :class:`Picture`.

    The figure is left to the garbage collector: ``Figure.clear`` would rebuild every axes (ticks included) only to
    drop them, a tenth of a figure's drawing time.
    """
    data = png_bytes(figure)
    return Picture(name, data, pixel_size(size_in), title, caption)


def link_colours(count: int) -> list[tuple[float, float, float, float]]:
    """One distinct colour per link, none of them the triads' red, green or blue."""
    import matplotlib

    if count <= len(LINK_PALETTE):
        return [matplotlib.colors.to_rgba(c) for c in LINK_PALETTE[:count]]
    cmap = matplotlib.colormaps["plasma"]
    return [cmap(v) for v in np.linspace(0.0, 0.9, count)]


def grid_shape(count: int, max_columns: int = 4) -> tuple[int, int]:
    """(rows, columns) of a near-square grid of ``count`` panels, at most ``max_columns`` wide."""
    columns = min(max(count, 1), max_columns)
    return int(np.ceil(max(count, 1) / columns)), columns


def panels(figure, count: int, max_columns: int = 4, **kwargs) -> Iterator:
    """``count`` axes in a :func:`grid_shape` grid, in reading order; unused cells stay empty."""
    rows, columns = grid_shape(count, max_columns)
    for k in range(count):
        yield figure.add_subplot(rows, columns, k + 1, **kwargs)
