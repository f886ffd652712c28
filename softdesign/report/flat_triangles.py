"""Flat-shaded triangles for the report's shaded bodies, filled by the renderer in one call, in the order given.

A :class:`matplotlib.collections.PolyCollection` of a shaded body makes a
``Path`` per triangle in Python and strokes every edge as well (in the face's
colour, to close the hairline seams antialiasing leaves between neighbours):
about a quarter of the report's drawing time went on the demo's 180,000
triangles.  :class:`FlatTriangles` hands all of them to the renderer's
documented ``draw_gouraud_triangles`` in one call, with the same colour at a
triangle's three corners, so each is filled flat.  The order is kept (painter's
algorithm: pass them far to near), and Agg widens each Gouraud triangle by half
a pixel, so neighbours meet without a seam and nothing is stroked.

matplotlib is imported with this module: import it where a figure is drawn.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from matplotlib.artist import Artist


class FlatTriangles(Artist):
    """Triangles (n, 3, 2) in data coordinates, each one colour (n, 3) RGB or (n, 4) RGBA, drawn first to last."""

    def __init__(self, triangles: npt.ArrayLike, colours: npt.ArrayLike) -> None:
        super().__init__()
        self._triangles = np.zeros((0, 3, 2))
        self._corner_colours = np.zeros((0, 3, 4))
        self.set_data(triangles, colours)

    def set_data(self, triangles: npt.ArrayLike, colours: npt.ArrayLike) -> None:
        """Replace the triangles and their colours (one per triangle, RGB or RGBA in [0, 1])."""
        tri = np.asarray(triangles, float)
        rgba = np.asarray(colours, float)
        if tri.ndim != 3 or tri.shape[1:] != (3, 2):
            raise ValueError(f"triangles: expected an (n, 3, 2) array, got shape {tri.shape}")
        if rgba.ndim != 2 or rgba.shape[0] != len(tri) or rgba.shape[1] not in (3, 4):
            raise ValueError(f"colours: expected ({len(tri)}, 3) or ({len(tri)}, 4), got shape {rgba.shape}")
        if rgba.shape[1] == 3:
            rgba = np.column_stack([rgba, np.ones(len(rgba))])
        self._triangles = np.ascontiguousarray(tri)
        self._corner_colours = np.ascontiguousarray(np.repeat(rgba[:, None, :], 3, axis=1))
        self.stale = True

    def draw(self, renderer) -> None:
        if not self.get_visible() or not len(self._triangles):
            return
        gc = renderer.new_gc()
        if self.get_clip_on():
            gc.set_clip_rectangle(self.get_clip_box())
            gc.set_clip_path(self.get_clip_path())
        renderer.draw_gouraud_triangles(gc, self._triangles, self._corner_colours, self.get_transform().frozen())
        gc.restore()
        self.stale = False


def add_triangles(ax, triangles: npt.ArrayLike, colours: npt.ArrayLike) -> FlatTriangles:
    """Add :class:`FlatTriangles` to ``ax`` in data coordinates; the data limits take in every corner."""
    artist = FlatTriangles(triangles, colours)
    ax.add_artist(artist)  # in data coordinates, clipped to the axes
    ax.update_datalim(np.asarray(triangles, float).reshape(-1, 2))
    return artist
