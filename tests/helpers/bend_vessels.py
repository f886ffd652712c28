"""Synthetic bends whose lumen is no circle (issue 29): the inner side of a tight turn is flatter.

The centerline is a straight stub, a constant-curvature turn and a straight tail in the xy plane
(:func:`tests.helpers.robust_vessels.stub_turn_axis`), written with ``MaximumInscribedSphereRadius``; the
wall is an open tube whose radius towards the centre of the turn is cut down, smoothly, on the turn:

    rho(s, a) = r (1 - f(s) ((1 + cos a) / 2) ** 4),   a measured from the turn's inner normal,

with f rising from 0 to ``flatten`` over ``ramp_mm`` before the turn and falling back after it.
So ``rho * kappa_n`` there is at most ``r kappa (1 - flatten) `` at a = 0, and a little more off it
(:func:`inner_reach` gives the exact largest value).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tests.helpers.robust_vessels import EDGE_MM, stub_turn_axis

#: Beyond each end the wall runs on straight this far past the centerline, as a VMTK surface does, mm.
WALL_PAST_END_MM = 2.0


def flattening(s: np.ndarray, turn_from: float, turn_to: float, flatten: float, ramp_mm: float) -> np.ndarray:
    """f(s): ``flatten`` on [turn_from, turn_to], a C1 ramp to 0 over ``ramp_mm`` on each side."""
    t = np.clip(1.0 - np.maximum(turn_from - s, s - turn_to) / ramp_mm, 0.0, 1.0)
    return flatten * t * t * (3.0 - 2.0 * t)


def section_radius(radius: float, f: np.ndarray, a: np.ndarray) -> np.ndarray:
    """rho at angle a (from the inner normal) where the flattening is f: (len(f), len(a)) mm."""
    return radius * (1.0 - f[:, None] * ((1.0 + np.cos(a)[None, :]) / 2.0) ** 4)


def inner_reach(radius: float, kappa: float, flatten: float) -> float:
    """The largest ``rho * kappa_n`` of the flattened section on the turn (a fine sweep over a)."""
    a = np.linspace(-np.pi, np.pi, 20001)
    return float(np.max(section_radius(radius, np.array([flatten]), a)[0] * np.cos(a) * kappa))


def write_flat_bend_vessel(folder: Path, radius: float, reach: float, turn_deg: float, flatten: float,
                           lead_mm: float = 20.0, ramp_mm: float = 3.0) -> tuple[Path, Path, np.ndarray]:
    """The bend vessel: centerline .vtp (inscribed radius ``radius``) and open surface .stl, in mm.

    The turn's curvature is ``reach / radius`` (so ``r * kappa = reach`` on the inscribed radius), it turns
    ``turn_deg`` between two straight leads ``lead_mm`` long.  Returns the files and the centerline points.
    """
    import trimesh

    from softdesign.io.polylines_vtp import write_polylines_vtp

    bend = radius / reach
    points, _ = stub_turn_axis(lead_mm, bend, turn_deg, lead_mm)
    folder.mkdir(parents=True, exist_ok=True)
    centerline = folder / "centerline.vtp"
    write_polylines_vtp(centerline, [points], {"MaximumInscribedSphereRadius": [np.full(len(points), radius)]})
    vertices, faces = _flat_bend_wall(points, radius, lead_mm, lead_mm + bend * np.radians(turn_deg), flatten,
                                      ramp_mm)
    surface = folder / "surface.stl"
    trimesh.Trimesh(vertices, faces, process=False).export(surface)
    return centerline, surface, points


def _flat_bend_wall(points: np.ndarray, radius: float, turn_from: float, turn_to: float, flatten: float,
                    ramp_mm: float) -> tuple[np.ndarray, np.ndarray]:
    """Rings about the centerline (continued straight past both ends), the inner side flattened on the turn."""
    t0 = (points[1] - points[0]) / np.linalg.norm(points[1] - points[0])
    t1 = (points[-1] - points[-2]) / np.linalg.norm(points[-1] - points[-2])
    step = EDGE_MM * np.sqrt(3) / 2
    extra = np.arange(step, WALL_PAST_END_MM + step / 2, step)[:, None]
    axis = np.concatenate([points[0] - extra[::-1] * t0, points, points[-1] + extra * t1])
    s_axis = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(axis, axis=0), axis=1))])
    s = np.arange(0.0, s_axis[-1], step)
    centres = np.column_stack([np.interp(s, s_axis, axis[:, k]) for k in range(3)])
    tangent = np.gradient(centres, axis=0)
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    inner = np.cross(tangent, [0.0, 0.0, 1.0])  # the turn goes from +y towards +x: its centre is on T x z
    up = np.cross(tangent, inner)  # B = T x N, as tube_along: faces wound outwards
    around = int(np.ceil(2 * np.pi * radius / EDGE_MM))
    a = 2 * np.pi * (np.arange(around)[None, :] + 0.5 * (np.arange(len(s))[:, None] % 2)) / around
    f = flattening(s - extra[-1, 0], turn_from, turn_to, flatten, ramp_mm)
    rho = radius * (1.0 - f[:, None] * ((1.0 + np.cos(a)) / 2.0) ** 4)
    rings = centres[:, None, :] + rho[..., None] * (np.cos(a)[..., None] * inner[:, None, :]
                                                    + np.sin(a)[..., None] * up[:, None, :])
    ids = np.arange(len(s) * around).reshape(len(s), around)
    faces = []
    for i in range(len(s) - 1):
        p, q = ids[i], ids[i + 1]
        p1, q1 = np.roll(p, -1), np.roll(q, -1)
        if i % 2 == 0:
            faces += [np.stack([p, p1, q], 1), np.stack([p1, q1, q], 1)]
        else:
            faces += [np.stack([p, q1, q], 1), np.stack([p, p1, q1], 1)]
    return rings.reshape(-1, 3), np.concatenate(faces)


def write_takeoff_vessel(folder: Path, trunk_radius: float = 6.0, branch_radius: float = 2.5,
                         branch_at_mm: float = 3.0, bend_mm: float = 3.0, turn_deg: float = 120.0,
                         length_mm: float = 40.0) -> tuple[Path, Path]:
    """A wide straight trunk along +z, capped flat at both ends, with a branch taking off near its inlet.

    Path 1 (VMTK-style, from the inlet) runs up the trunk's axis for ``branch_at_mm``, turns ``turn_deg``
    towards +x on an arc of radius ``bend_mm`` and runs 30 mm straight on: the branch, a tube of radius
    ``branch_radius`` about the arc and the straight part.  Its inscribed radius is the trunk's on the stub,
    falls linearly to the branch's over the arc, and is the branch's after.  Path 0 is the trunk.  The wall
    is the boolean union of the two sample-generator tubes: a path that turns from a wide trunk into a branch
    tighter than the trunk is wide (``trunk_radius / bend_mm`` > 1).
    """
    from softdesign.io.formats import write_mesh
    from softdesign.io.polylines_vtp import write_polylines_vtp
    from softdesign.meshing.solids import checked
    from tests.helpers.robust_vessels import capped_tube, segment

    plane, _ = stub_turn_axis(branch_at_mm, bend_mm, turn_deg, 30.0, step=0.25)
    path = plane[:, [0, 2, 1]]  # the stub along +z, turning towards +x
    trunk = segment(np.zeros(3), np.array([0.0, 0.0, length_mm]), 0.25)
    limb = path[path[:, 2] >= branch_at_mm - 1e-9]
    mesh = checked(capped_tube(trunk, trunk_radius, "trunk") + capped_tube(limb, branch_radius, "branch"),
                   "trunk and branch").to_mesh64()
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))])
    arc_end = branch_at_mm + bend_mm * np.radians(turn_deg)
    radius = np.interp(s, [branch_at_mm, arc_end], [trunk_radius, branch_radius])
    folder.mkdir(parents=True, exist_ok=True)
    centerline = write_polylines_vtp(folder / "centerline.vtp", [trunk, path],
                                     {"MaximumInscribedSphereRadius": [np.full(len(trunk), trunk_radius), radius]})
    surface = write_mesh(folder / "surface.stl", np.asarray(mesh.vert_properties, float)[:, :3],
                         np.asarray(mesh.tri_verts, np.int64))
    return centerline, surface


def write_elliptical_bend_vessel(folder: Path, radius: float, ellipticity: float, bend_mm: float, turn_deg: float,
                                 lead_mm: float = 10.0) -> tuple[Path, Path]:
    """A capped tube of elliptical section (semi-axes r(1 + e) in the turn's plane, r(1 - e) across it) about a
    straight lead, a turn of ``turn_deg`` on radius ``bend_mm`` and a straight tail; the centerline's inscribed
    radius is the minor semi-axis r(1 - e), as VMTK's is on such a lumen.
    """
    from softdesign.io.formats import write_mesh
    from softdesign.io.polylines_vtp import write_polylines_vtp
    from softdesign.samples.surfaces import framed_polyline, swept_tube

    points, _ = stub_turn_axis(lead_mm, bend_mm, turn_deg, lead_mm, step=0.25)
    framed = framed_polyline(points, "elliptical bend")
    rings = int(np.ceil(framed.length / EDGE_MM)) + 1
    around = int(np.ceil(2 * np.pi * radius * (1 + ellipticity) / EDGE_MM))
    # the major axis a quarter turn from the sweep's N: in the turn's plane (B is the plane's normal)
    vertices, faces = swept_tube(framed, rings, around, np.full(2, radius), ellipticity, np.full(2, np.pi / 2))
    folder.mkdir(parents=True, exist_ok=True)
    minor = np.full(len(points), radius * (1.0 - ellipticity))
    centerline = write_polylines_vtp(folder / "centerline.vtp", [points], {"MaximumInscribedSphereRadius": [minor]})
    return centerline, write_mesh(folder / "surface.stl", vertices, faces)
