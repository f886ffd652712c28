"""Views of 3-D geometry on paper: a principal viewing basis, projection, painter order, shading.

Pure numpy.  A view is a rotation ``view2world`` (3, 3) whose columns are the
screen's right (u), up (v) and the direction towards the viewer (w), and an
origin o (3,); a point p appears at ((p - o) . u, (p - o) . v) with depth
(p - o) . w (larger is nearer).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from softdesign.types import FloatArray

#: Light direction in view coordinates (u, v, w): from the upper left, in front of the screen.
LIGHT_VIEW = np.array([-0.35, 0.45, 0.82])
#: Smallest brightness of a face turned away from the light (ambient share).
AMBIENT = 0.3


@dataclass(frozen=True)
class View:
    """A viewing rotation and the names of its screen axes."""

    view2world: FloatArray
    labels: tuple[str, str]
    origin: FloatArray = field(default_factory=lambda: np.zeros(3))

    def coordinates(self, points: npt.ArrayLike) -> FloatArray:
        """View coordinates (n, 3) mm (right, up, towards the viewer) of points (n, 3) mm."""
        return (np.asarray(points, float) - self.origin) @ self.view2world

    def project(self, points: npt.ArrayLike) -> FloatArray:
        """Screen coordinates (n, 2) mm of points (n, 3) mm."""
        return self.coordinates(points)[:, :2]


def axis_views() -> tuple[View, View, View]:
    """The three orthogonal views along the world axes: x-y (from +z), x-z (from -y), y-z (from +x)."""
    eye = np.eye(3)
    return (
        View(np.column_stack([eye[0], eye[1], eye[2]]), ("x (mm)", "y (mm)")),
        View(np.column_stack([eye[0], eye[2], -eye[1]]), ("x (mm)", "z (mm)")),
        View(np.column_stack([eye[1], eye[2], eye[0]]), ("y (mm)", "z (mm)")),
    )


def principal_view(points: npt.ArrayLike, forward: npt.ArrayLike | None = None) -> View:
    """Look along the direction of least spread of ``points`` (n, 3), so the shape shows its broadest side.

    Screen right is the direction of largest spread, pointed along ``forward``
    (e.g. inlet to outlet) when given; the basis is right-handed and the
    origin is ``points[0]`` (the inlet, for a centerline).  Signs are fixed,
    so the same points always give the same view.
    """
    p = np.asarray(points, float)
    centred = p - p.mean(axis=0)
    _, vectors = np.linalg.eigh(centred.T @ centred)  # ascending eigenvalues
    right, up = vectors[:, 2], vectors[:, 1]
    reference = np.asarray(forward, float) if forward is not None else np.ones(3)
    if right @ reference < 0.0:
        right = -right
    if up @ np.array([0.0, 0.0, 1.0]) < 0.0 or (up @ np.array([0.0, 0.0, 1.0]) == 0.0 and up.sum() < 0.0):
        up = -up
    basis = np.column_stack([right, up, np.cross(right, up)])
    return View(basis, ("along the vessel from the inlet (mm)", "across (mm)"), p[0].copy())


class ShadedFaces(NamedTuple):
    """Faces ready for a painter's-algorithm drawing, farthest first."""

    triangles: FloatArray  #: (k, 3, 2) screen coordinates, mm
    brightness: FloatArray  #: (k,) in [AMBIENT, 1], two-sided Lambert shading
    face_index: np.ndarray  #: (k,) the face each triangle came from (degenerate faces are dropped)


def shaded_triangles(vertices: npt.ArrayLike, faces: npt.ArrayLike, view: View, cull: bool = False) -> ShadedFaces:
    """Screen triangles sorted far to near (by mean depth) with their brightness.

    Parameters
    ----------
    vertices : (V, 3) float, mm
    faces : (F, 3) int, counter-clockwise seen from outside when ``cull``
    view : the viewing rotation
    cull : drop faces turned away from the viewer (hidden on a closed, outward-wound surface)
    """
    tri = view.coordinates(vertices)[np.asarray(faces, np.int64)]
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norm = np.linalg.norm(normals, axis=1)
    index = np.flatnonzero((norm > 0.0) & ((normals[:, 2] > 0.0) if cull else True))
    unit = normals[index] / norm[index, None]
    light = LIGHT_VIEW / np.linalg.norm(LIGHT_VIEW)
    brightness = AMBIENT + (1.0 - AMBIENT) * np.abs(unit @ light)
    order = np.argsort(tri[index, :, 2].mean(axis=1), kind="stable")
    return ShadedFaces(tri[index[order], :, :2], brightness[order], index[order])


def painted_last(screen_points: npt.ArrayLike, cell: float) -> np.ndarray:
    """Indices (sorted) of the last point in every square ``cell`` of the screen: what a painter leaves visible.

    ``screen_points`` (n, 2) are in drawing order (far to near); of the points sharing a cell, the last is
    drawn over the others, so drawing only it, at its own position, changes the picture by less than a cell.
    """
    p = np.asarray(screen_points, float).reshape(-1, 2)
    if not len(p):
        return np.zeros(0, np.int64)
    if not cell > 0.0:
        raise ValueError(f"cell must be > 0, got {cell}")
    span = np.floor(np.ptp(p, axis=0) / cell) + 1.0  # cells along x and y
    if span[0] * span[1] > 2.0**62:
        raise ValueError(f"cell {cell} is too small for the points' extent {np.ptp(p, axis=0)}: more than 2^62 cells")
    keys = np.floor((p - p.min(axis=0)) / cell).astype(np.int64)
    flat = keys[:, 0] * int(span[1]) + keys[:, 1]
    _, first_from_end = np.unique(flat[::-1], return_index=True)
    return np.sort(len(flat) - 1 - first_from_end)


def bounding_limits(
    screen_points: list[FloatArray], margin: float = 0.04
) -> tuple[tuple[float, float], tuple[float, float]]:
    """(x, y) limits enclosing every (n, 2) array, widened by ``margin`` of the larger extent on each side."""
    allp = np.concatenate([np.asarray(p, float).reshape(-1, 2) for p in screen_points], axis=0)
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    pad = margin * max(float(np.max(hi - lo)), 1e-9)
    return (lo[0] - pad, hi[0] + pad), (lo[1] - pad, hi[1] + pad)
