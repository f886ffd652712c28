"""Synthetic vessels that reproduce the failure kinds of real trees (issue 20), written VMTK-style.

Each is a tube of known radius swept along a known centerline (tests/helpers/vessels.tube_along),
with the centerline written with ``MaximumInscribedSphereRadius`` and the open surface as STL.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tests.helpers.vessels import tube_along

EDGE_MM = 0.5


def u_turn_axis(bend_mm: float = 10.0, lead_mm: float = 10.0, step: float = 0.25) -> tuple[np.ndarray, np.ndarray]:
    """A straight lead, a half turn of radius ``bend_mm`` in the xy plane, a straight return: points and normals."""
    lead = np.arange(0.0, lead_mm, step)
    turn = np.arange(0.0, np.pi, step / bend_mm)
    tail = np.arange(0.0, lead_mm + step / 2, step)
    points = np.concatenate([
        np.column_stack([np.zeros_like(lead), lead - lead_mm, np.zeros_like(lead)]),
        np.column_stack([bend_mm * (1 - np.cos(turn)), bend_mm * np.sin(turn), np.zeros_like(turn)]),
        np.column_stack([np.full_like(tail, 2 * bend_mm), -tail, np.zeros_like(tail)]),
    ])
    return points, np.tile([0.0, 0.0, 1.0], (len(points), 1))


def stub_turn_axis(stub_mm: float, bend_mm: float, turn_deg: float, tail_mm: float,
                   step: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """A straight stub, a turn of ``turn_deg`` with radius ``bend_mm`` in the xy plane, a straight tail."""
    angle = np.radians(turn_deg)
    stub = np.arange(0.0, stub_mm, step)
    turn = np.arange(0.0, angle, step / bend_mm)
    end = np.array([bend_mm * (1 - np.cos(angle)), stub_mm + bend_mm * np.sin(angle), 0.0])
    direction = np.array([np.sin(angle), np.cos(angle), 0.0])
    tail = np.arange(0.0, tail_mm + step / 2, step)
    points = np.concatenate([
        np.column_stack([np.zeros_like(stub), stub, np.zeros_like(stub)]),
        np.column_stack([bend_mm * (1 - np.cos(turn)), stub_mm + bend_mm * np.sin(turn), np.zeros_like(turn)]),
        end + tail[:, None] * direction,
    ])
    return points, np.tile([0.0, 0.0, 1.0], (len(points), 1))


def write_tube_vessel(folder: Path, points: np.ndarray, normals: np.ndarray, radius: float) -> tuple[Path, Path]:
    """Centerline .vtp (radius ``radius`` everywhere) and the open tube's surface .stl, in mm."""
    import trimesh

    from softdesign.io.polylines_vtp import write_polylines_vtp

    folder.mkdir(parents=True, exist_ok=True)
    centerline = folder / "centerline.vtp"
    write_polylines_vtp(centerline, [points], {"MaximumInscribedSphereRadius": [np.full(len(points), radius)]})
    # the wall runs a little past both ends of the centerline, as a VMTK surface does
    t0 = points[1] - points[0]
    t1 = points[-1] - points[-2]
    t0, t1 = t0 / np.linalg.norm(t0), t1 / np.linalg.norm(t1)
    extra = np.arange(1, 5)[:, None] * EDGE_MM
    wall_axis = np.concatenate([points[0] - extra[::-1] * t0, points, points[-1] + extra * t1])
    wall_normals = np.concatenate([np.repeat(normals[:1], 4, 0), normals, np.repeat(normals[-1:], 4, 0)])
    ring_step = EDGE_MM * np.sqrt(3) / 2
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(wall_axis, axis=0), axis=1))])
    keep = np.searchsorted(s, np.arange(0.0, s[-1], ring_step))
    around = int(np.ceil(2 * np.pi * radius / EDGE_MM))
    vertices, faces = tube_along(wall_axis[keep], wall_normals[keep], radius, around)
    surface = folder / "surface.stl"
    trimesh.Trimesh(vertices, faces, process=False).export(surface)
    return centerline, surface


def capped_tube(axis: np.ndarray, radius: float, label: str):
    """A capped tube of constant ``radius`` swept along ``axis`` (n, 3) by the sample generators, as a Manifold."""
    from softdesign.meshing.solids import manifold_from_mesh
    from softdesign.samples.surfaces import framed_polyline, swept_tube

    framed = framed_polyline(axis, label)
    rings = int(np.ceil(framed.length / EDGE_MM)) + 1
    around = int(np.ceil(2 * np.pi * radius / EDGE_MM))
    vertices, faces = swept_tube(framed, rings, around, np.full(2, radius), 0.0, np.zeros(2))
    return manifold_from_mesh(vertices, faces, label)[0]


def segment(a: np.ndarray, b: np.ndarray, step: float = 0.25) -> np.ndarray:
    """Points from ``a`` to ``b`` about ``step`` mm apart."""
    count = max(2, int(np.ceil(np.linalg.norm(b - a) / step)) + 1)
    return a + np.linspace(0.0, 1.0, count)[:, None] * (b - a)


def write_elbow_vessel(folder: Path, radius: float, stub_mm: float, turn_deg: float,
                       tail_mm: float) -> tuple[Path, Path, np.ndarray]:
    """A capped elbow: a straight stub, then a turn of ``turn_deg`` within half a radius of arc, then a tail.

    The wall is what a vessel of radius ``radius`` is there: two capped cylinders whose axes meet at the
    corner, joined by a ball at the corner (boolean union, as the sample vessel's trunk and branch are);
    the centerline (``stub_turn_axis``, bend radius = half the radius / turn) cuts the corner inside it.
    Returns the centerline .vtp, the surface .stl and the centerline points.
    """
    import manifold3d as m3

    from softdesign.io.formats import write_mesh
    from softdesign.io.polylines_vtp import write_polylines_vtp
    from softdesign.meshing.solids import checked

    angle = np.radians(turn_deg)
    bend = 0.5 * radius / angle
    points, _ = stub_turn_axis(stub_mm, bend, turn_deg, tail_mm)
    corner = np.array([0.0, stub_mm + bend * np.tan(angle / 2), 0.0])
    wall = (capped_tube(segment(points[0], corner), radius, "elbow stub")
            + capped_tube(segment(corner, points[-1]), radius, "elbow tail")
            + m3.Manifold.sphere(radius, int(np.ceil(2 * np.pi * radius / EDGE_MM))).translate(tuple(corner)))
    mesh = checked(wall, "elbow").to_mesh64()
    folder.mkdir(parents=True, exist_ok=True)
    centerline = folder / "centerline.vtp"
    write_polylines_vtp(centerline, [points], {"MaximumInscribedSphereRadius": [np.full(len(points), radius)]})
    surface = write_mesh(folder / "surface.stl", np.asarray(mesh.vert_properties, float)[:, :3],
                         np.asarray(mesh.tri_verts, np.int64))
    return centerline, surface, points


def wall_to_body_mm(wall: np.ndarray, body: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """Exact distance, mm, from each wall point (n, 3) to the body mesh (vertices, faces)."""
    from softdesign.meshing.compare import squared_distances

    return np.sqrt(squared_distances(np.asarray(wall, float), *body))


def write_outlet_seeded_sample(folder: Path) -> tuple[Path, Path, np.ndarray]:
    """The project's sample vessel with its centerlines as VMTK writes them when seeded at the branch's outlet.

    Both polylines start at the side branch's outlet (radius 2 mm) and share the branch up to the junction:
    0 runs on through the trunk to the vessel's inlet (radius 3.7 mm), 1 turns into the main vessel's
    outlet.  Returns the centerline .vtp, the capped surface .stl and the vessel's true inlet point.
    """
    from softdesign.io.formats import write_mesh
    from softdesign.io.polylines_vtp import write_polylines_vtp
    from softdesign.samples.sample_vessel import make_sample_vessel
    from softdesign.samples.surfaces import sample_surface

    vessel = make_sample_vessel()
    junction = vessel.trunk_count() - 1
    branch_radius, main_radius = vessel.inscribed_radius("branch"), vessel.inscribed_radius("main")
    limb = vessel.branch[junction + 1:][::-1]
    lines = [np.concatenate([limb, vessel.main[: junction + 1][::-1]]),
             np.concatenate([limb, vessel.main[junction:]])]
    radii = [np.concatenate([branch_radius[junction + 1:][::-1], main_radius[: junction + 1][::-1]]),
             np.concatenate([branch_radius[junction + 1:][::-1], main_radius[junction:]])]
    folder.mkdir(parents=True, exist_ok=True)
    centerline = write_polylines_vtp(folder / "centerline.vtp", lines, {"MaximumInscribedSphereRadius": radii})
    surface = write_mesh(folder / "surface.stl", *sample_surface(vessel))
    return centerline, surface, vessel.main[0]


def write_tilted_cap_vessel(folder: Path, radius: float, length_mm: float, tilt_deg: float) -> tuple[Path, Path]:
    """A straight capped vessel along +z whose inlet cap is flat but tilted ``tilt_deg`` to the end tangent.

    The wall is a sample-generator tube from z = -radius to ``length_mm`` (capped square there) cut by the
    plane through the origin whose normal leans ``tilt_deg`` from +z towards +x; the centerline runs from
    the origin (the cap's centre) to ``length_mm`` along z, as VMTK's does from a cap's centre.
    """
    from softdesign.io.formats import write_mesh
    from softdesign.io.polylines_vtp import write_polylines_vtp
    from softdesign.meshing.solids import checked

    tilt = np.radians(tilt_deg)
    tube = capped_tube(segment(np.array([0.0, 0.0, -radius]), np.array([0.0, 0.0, length_mm])), radius, "tilted")
    cut = checked(tube.trim_by_plane((-np.sin(tilt), 0.0, np.cos(tilt)), 0.0), "tilted cap").to_mesh64()
    folder.mkdir(parents=True, exist_ok=True)
    z = np.arange(0.0, length_mm + 1e-9, 0.25)
    points = np.column_stack([np.zeros_like(z), np.zeros_like(z), z])
    centerline = write_polylines_vtp(folder / "centerline.vtp", [points],
                                     {"MaximumInscribedSphereRadius": [np.full(len(z), radius)]})
    surface = write_mesh(folder / "surface.stl", np.asarray(cut.vert_properties, float)[:, :3],
                         np.asarray(cut.tri_verts, np.int64))
    return centerline, surface


def write_branch_near_inlet_vessel(folder: Path, radius: float = 6.0, branch_radius: float = 3.0,
                                   branch_at_mm: float = 4.0, length_mm: float = 50.0) -> tuple[Path, Path]:
    """A wide straight trunk along +z, capped flat at both ends, with a side branch leaving near its inlet.

    The branch (radius ``branch_radius``) leaves the trunk's axis at ``branch_at_mm`` at 60 degrees towards
    +x and runs 30 mm; the wall is the boolean union of the two sample-generator tubes.  Path 0 is the
    trunk, path 1 the trunk's first ``branch_at_mm`` then the branch, both from the inlet (VMTK-style).
    Near the trunk's inlet the branch's mouth takes a side of the wall away: the kept points are one-sided.
    """
    from softdesign.io.formats import write_mesh
    from softdesign.io.polylines_vtp import write_polylines_vtp
    from softdesign.meshing.solids import checked

    step = 0.25
    trunk = segment(np.zeros(3), np.array([0.0, 0.0, length_mm]), step)
    fork = np.array([0.0, 0.0, branch_at_mm])
    direction = np.array([np.sin(np.pi / 3), 0.0, np.cos(np.pi / 3)])
    limb = segment(fork, fork + 30.0 * direction, step)
    wall = (capped_tube(trunk, radius, "trunk") + capped_tube(limb, branch_radius, "branch"))
    mesh = checked(wall, "trunk and branch").to_mesh64()
    head = trunk[trunk[:, 2] < branch_at_mm - 1e-9]
    lines = [trunk, np.concatenate([head, limb])]
    radii = [np.full(len(trunk), radius),
             np.concatenate([np.full(len(head), radius), np.full(len(limb), branch_radius)])]
    folder.mkdir(parents=True, exist_ok=True)
    centerline = write_polylines_vtp(folder / "centerline.vtp", lines, {"MaximumInscribedSphereRadius": radii})
    surface = write_mesh(folder / "surface.stl", np.asarray(mesh.vert_properties, float)[:, :3],
                         np.asarray(mesh.tri_verts, np.int64))
    return centerline, surface
