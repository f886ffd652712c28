"""Capped walls of the generated vessels: swept tubes with elliptical, turning sections.

The sample vessel's wall is two swept tubes (trunk, side branch) joined by a
boolean union, so it is one closed, capped surface like ``vmtksurfacecapper``
output, at a resolution comparable with VMTK surfaces (edges of about
0.5-0.9 mm).  The benchmark tube is one swept tube at a chosen triangle
count: a grid of ``rings`` x ``angles`` vertices gives ``2 * rings * angles``
triangles (wall and caps), the counts chosen so that edges are about as long
around as along the vessel.
"""

from __future__ import annotations

import math

import numpy as np

from softdesign.geometry.curves import CurveOptions, smooth_curve_from_polyline
from softdesign.geometry.frames import FramedSpline, framed_curve
from softdesign.meshing.solids import checked, manifold_from_mesh
from softdesign.meshing.tessellate import TubeSections, sweep_from_sections, tessellate
from softdesign.meshing.volume import angle_grid
from softdesign.samples.sample_vessel import SampleVessel
from softdesign.samples.synthetic_vessel import SyntheticVessel
from softdesign.types import FloatArray, IntArray

#: Ring spacing along the sample vessel and ring count around it.
SAMPLE_RING_SPACING_MM = 0.6
SAMPLE_ANGULAR_COUNT = 40
#: Fewest angles around the benchmark tube (coarser sections would not look like a vessel).
MIN_ANGLES = 16


def elliptical_rho(radius: FloatArray, ellipticity: float, major_angle: FloatArray, angles: FloatArray) -> FloatArray:
    """Polar radius (n, na) of ellipses with semi-axes r(1 + e), r(1 - e), major axis at ``major_angle``."""
    a = (radius * (1.0 + ellipticity))[:, None]
    b = (radius * (1.0 - ellipticity))[:, None]
    phase = angles[None, :] - major_angle[:, None]
    return a * b / np.sqrt((b * np.cos(phase)) ** 2 + (a * np.sin(phase)) ** 2)


def framed_polyline(points: FloatArray, label: str) -> FramedSpline:
    """The smooth curve through ``points`` (n, 3) mm with rotation-minimizing frames."""
    curve = smooth_curve_from_polyline(points, CurveOptions(spacing_mm=0.5, smoothing_mm=0.0))
    return framed_curve(curve, "rmf", label=label)


def swept_tube(
    framed: FramedSpline, rings: int, angles: int, radius: FloatArray, ellipticity: float, major_angle: FloatArray
) -> tuple[FloatArray, IntArray]:
    """Vertices (V, 3) mm and faces (F, 3) of a capped tube swept along ``framed``.

    ``radius`` and ``major_angle`` (m,) are given at m points evenly spaced in
    l and interpolated to ``rings`` rings of ``angles`` vertices each.
    """
    l = np.linspace(0.0, 1.0, rings)
    u = np.linspace(0.0, 1.0, len(radius))
    rho = elliptical_rho(np.interp(l, u, radius), ellipticity, np.interp(l, u, major_angle), angle_grid(angles))
    sections = TubeSections(q=1.0, l=l, centers=framed.points(l), frames=framed.frames(l), rho=rho)
    mesh = tessellate(sweep_from_sections(sections))
    return mesh.vertices, mesh.faces


def _sample_tube(points: FloatArray, radius: FloatArray, ellipticity: float, major_angle: FloatArray):
    framed = framed_polyline(points, "sample vessel")
    rings = int(np.ceil(framed.length / SAMPLE_RING_SPACING_MM)) + 1
    vertices, faces = swept_tube(framed, rings, SAMPLE_ANGULAR_COUNT, radius, ellipticity, major_angle)
    return manifold_from_mesh(vertices, faces, "sample vessel tube")[0]


def sample_surface(vessel: SampleVessel) -> tuple[FloatArray, IntArray]:
    """Vertices (V, 3) mm and faces (F, 3) of the capped sample vessel wall."""
    trunk = vessel.trunk_count()
    main = _sample_tube(vessel.main, vessel.main_radius, vessel.ellipticity, vessel.major_angle)
    limb = vessel.branch[trunk - 1 :]
    # the limb starts at the junction, inside the trunk, already with its own radius
    limb_radius = np.concatenate([vessel.branch_radius[trunk : trunk + 1], vessel.branch_radius[trunk:]])
    branch = _sample_tube(limb, limb_radius, 0.0, np.zeros(len(limb)))
    union = checked(main + branch, "sample vessel union").to_mesh64()
    return np.asarray(union.vert_properties, float)[:, :3], np.asarray(union.tri_verts, np.int64)


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
    """Vertices (V, 3) mm and faces (F, 3) of the benchmark tube's capped wall, F >= ``triangles`` (within one ring)."""
    framed = framed_polyline(vessel.points, "synthetic vessel")
    rings, angles = grid_counts(framed.length, float(np.mean(vessel.radius)), triangles)
    return swept_tube(framed, rings, angles, vessel.radius, vessel.ellipticity, vessel.major_angle)
