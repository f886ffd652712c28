"""The capped wall of the synthetic benchmark vessel at a chosen triangle count.

The tube is swept along the vessel's rotation-minimizing frames with its
elliptical section and closed by planar end caps, so it reads like
``vmtksurfacecapper`` output.  A grid of ``rings`` x ``angles`` vertices
gives ``2 * rings * angles`` triangles (wall and caps); the two counts are
chosen so that edges are about as long around as along the vessel.
"""

from __future__ import annotations

import math

import numpy as np

from softdesign.geometry.curves import CurveOptions, smooth_curve_from_polyline
from softdesign.geometry.frames import framed_curve
from softdesign.geometry.synthetic_vessel import SyntheticVessel
from softdesign.meshing.sample_surface import elliptical_rho
from softdesign.meshing.tessellate import TubeSections, sweep_from_sections, tessellate
from softdesign.meshing.volume import angle_grid
from softdesign.types import FloatArray, IntArray

#: Fewest angles around the tube (coarser sections would not look like a vessel).
MIN_ANGLES = 16


def grid_counts(length_mm: float, mean_radius_mm: float, triangles: int) -> tuple[int, int]:
    """(rings, angles) with ``2 * rings * angles >= triangles`` and nearly square cells.

    Parameters
    ----------
    length_mm : arc length of the tube, mm
    mean_radius_mm : its mean radius, mm
    triangles : the smallest triangle count wanted
    """
    if length_mm <= 0 or mean_radius_mm <= 0 or triangles < 4 * MIN_ANGLES:
        raise ValueError(
            f"need length_mm > 0, mean_radius_mm > 0, triangles >= {4 * MIN_ANGLES}; "
            f"got {length_mm}, {mean_radius_mm}, {triangles}"
        )
    cells = triangles / 2.0
    angles = max(MIN_ANGLES, round(math.sqrt(cells * 2.0 * math.pi * mean_radius_mm / length_mm)))
    rings = max(2, math.ceil(cells / angles))
    return rings, angles


def synthetic_surface(vessel: SyntheticVessel, triangles: int) -> tuple[FloatArray, IntArray]:
    """Vertices (V, 3) mm and faces (F, 3) of the capped wall, F >= ``triangles`` (within one ring)."""
    curve = smooth_curve_from_polyline(vessel.points, CurveOptions(spacing_mm=0.5, smoothing_mm=0.0))
    framed = framed_curve(curve, "rmf", label="synthetic vessel")
    rings, angles = grid_counts(curve.length, float(np.mean(vessel.radius)), triangles)
    l = np.linspace(0.0, 1.0, rings)
    u = np.linspace(0.0, 1.0, len(vessel.points))
    ring_radius = np.interp(l, u, vessel.radius)
    ring_angle = np.interp(l, u, vessel.major_angle)
    rho = elliptical_rho(ring_radius, vessel.ellipticity, ring_angle, angle_grid(angles))
    sections = TubeSections(q=1.0, l=l, centers=framed.points(l), frames=framed.frames(l), rho=rho)
    mesh = tessellate(sweep_from_sections(sections))
    return mesh.vertices, mesh.faces
