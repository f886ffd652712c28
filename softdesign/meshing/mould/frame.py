"""The parting plane of a two-part mould and the frame the mould is built in.

A straight body at q = 0 is a line: any plane containing it parts it, and the
plane through its axis and the base normal N0 is taken (so the section
vertices at a = 0 and a = pi, which lie on N0's line, lie on the parting line
and no facet straddles it).  A curved one (``initial.kind: arc`` or ``file``)
is parted by the plane of best fit of its centerline (least squares: the
normal is the singular vector of the smallest singular value of the centred
points); how far the centerline leaves that plane is reported.

The mould frame: origin at the centerline's centroid, x along the first
principal direction (base to tip), z the plane's normal (the pull of half A;
half B is pulled along -z), y = z x x.  Coordinates are mm.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.types import FloatArray

#: A centerline within this distance of its chord line everywhere is straight, mm (a straight q = 0 shape
#: is built exactly straight: its deviation is rounding, ~1e-12 mm).
STRAIGHT_TOL_MM = 1e-6


@dataclass(frozen=True)
class PartingFrame:
    """Where the mould is built.

    Attributes
    ----------
    origin : (3,) float, mm, world coordinates of the frame's origin
    axes : (3, 3) float, rows x, y, z (z the parting plane's normal, half A's pull)
    straight : bool, whether the centerline is straight (within STRAIGHT_TOL_MM)
    out_of_plane_mm : float, largest distance of the centerline from the parting plane
    """

    origin: FloatArray
    axes: FloatArray
    straight: bool
    out_of_plane_mm: float

    def frame_from_world(self) -> FloatArray:
        """(3, 4) affine map of world points into the mould frame (manifold3d's transform layout)."""
        return np.column_stack([self.axes, -self.axes @ self.origin])

    def world_from_frame(self) -> FloatArray:
        """(3, 4) affine map of mould-frame points back to the world."""
        return np.column_stack([self.axes.T, self.origin])

    def to_frame(self, points: npt.ArrayLike) -> FloatArray:
        """Points (..., 3) in the mould frame."""
        return (np.asarray(points, float) - self.origin) @ self.axes.T

    def direction_to_frame(self, vectors: npt.ArrayLike) -> FloatArray:
        """Directions (..., 3) in the mould frame."""
        return np.asarray(vectors, float) @ self.axes.T


def parting_frame(centerline: npt.ArrayLike, base_frame: npt.ArrayLike) -> PartingFrame:
    """The parting plane of the body whose q = 0 centerline is ``centerline``.

    Parameters
    ----------
    centerline : (n, 3) float, mm, base to tip
    base_frame : (3, 3) float, the base frame's columns (N, B, T)

    Returns
    -------
    PartingFrame
        Straight: the plane of T and N0 (normal B0).  Curved: the plane of best
        fit, its normal oriented along B0 where it can be.
    """
    points = np.asarray(centerline, float)
    frame = np.asarray(base_frame, float)
    if points.ndim != 2 or points.shape[1] != 3 or len(points) < 2:
        raise ValueError(f"centerline must be (n >= 2, 3), got {points.shape}")
    origin = points.mean(axis=0)
    centred = points - origin
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    x = vt[0] if (points[-1] - points[0]) @ vt[0] >= 0 else -vt[0]
    off_line = centred - np.outer(centred @ x, x)
    straight = bool(np.max(np.linalg.norm(off_line, axis=1)) <= STRAIGHT_TOL_MM)
    if straight:
        z = frame[:, 1] - (frame[:, 1] @ x) * x
    else:
        z = vt[2] if vt[2] @ frame[:, 1] >= 0 else -vt[2]
    z = z / np.linalg.norm(z)
    y = np.cross(z, x)
    axes = np.vstack([x, y, z])
    return PartingFrame(origin, axes, straight, float(np.max(np.abs(centred @ z))))
