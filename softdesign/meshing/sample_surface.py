"""The wall of the sample vessel: two swept tubes joined by a boolean union.

The main vessel is swept with its slightly elliptical, turning section; the
side branch (circular) starts inside the trunk at the junction and is
united with it, so the result is one closed, capped surface like
``vmtksurfacecapper`` output.  Resolution is comparable with VMTK surfaces
(edges of about 0.5-0.9 mm).
"""

from __future__ import annotations

import numpy as np

from softdesign.geometry.curves import CurveOptions, smooth_curve_from_polyline
from softdesign.geometry.frames import framed_curve
from softdesign.geometry.sample_vessel import SampleVessel
from softdesign.meshing.solids import checked, manifold_from_mesh
from softdesign.meshing.tessellate import TubeSections, sweep_from_sections, tessellate
from softdesign.meshing.volume import angle_grid
from softdesign.types import FloatArray, IntArray

#: Ring spacing along the vessel and ring count around it.
SAMPLE_RING_SPACING_MM = 0.6
SAMPLE_ANGULAR_COUNT = 40


def elliptical_rho(radius: FloatArray, ellipticity: float, major_angle: FloatArray, angles: FloatArray) -> FloatArray:
    """Polar radius (n, na) of ellipses with semi-axes r(1 + e), r(1 - e), major axis at ``major_angle``."""
    a = (radius * (1.0 + ellipticity))[:, None]
    b = (radius * (1.0 - ellipticity))[:, None]
    phase = angles[None, :] - major_angle[:, None]
    return a * b / np.sqrt((b * np.cos(phase)) ** 2 + (a * np.sin(phase)) ** 2)


def _tube(points: FloatArray, radius: FloatArray, ellipticity: float, major_angle: FloatArray):
    curve = smooth_curve_from_polyline(points, CurveOptions(spacing_mm=0.5, smoothing_mm=0.0))
    framed = framed_curve(curve, "rmf", label="sample vessel")
    count = int(np.ceil(curve.length / SAMPLE_RING_SPACING_MM)) + 1
    l = np.linspace(0.0, 1.0, count)
    u = np.linspace(0.0, 1.0, len(points))
    ring_radius = np.interp(l, u, radius)
    ring_angle = np.interp(l, u, major_angle)
    rho = elliptical_rho(ring_radius, ellipticity, ring_angle, angle_grid(SAMPLE_ANGULAR_COUNT))
    sections = TubeSections(q=1.0, l=l, centers=framed.points(l), frames=framed.frames(l), rho=rho)
    mesh = tessellate(sweep_from_sections(sections))
    return manifold_from_mesh(mesh.vertices, mesh.faces, "sample vessel tube")[0]


def sample_surface(vessel: SampleVessel) -> tuple[FloatArray, IntArray]:
    """Vertices (V, 3) mm and faces (F, 3) of the capped sample vessel wall."""
    trunk = vessel.trunk_count()
    main = _tube(vessel.main, vessel.main_radius, vessel.ellipticity, vessel.major_angle)
    limb = vessel.branch[trunk - 1 :]
    # the limb starts at the junction, inside the trunk, already with its own radius
    limb_radius = np.concatenate([vessel.branch_radius[trunk : trunk + 1], vessel.branch_radius[trunk:]])
    branch = _tube(limb, limb_radius, 0.0, np.zeros(len(limb)))
    union = checked(main + branch, "sample vessel union").to_mesh64()
    return np.asarray(union.vert_properties, float)[:, :3], np.asarray(union.tri_verts, np.int64)
