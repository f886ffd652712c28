"""Cases for the 3D view's mould and chamber: a hollow straight tube with a mould, a solid bent tube without."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from tests.helpers.cases import straight_tube, write_case
from tests.helpers.vessels import straight_tube as tube_vertices_faces
from tests.helpers.vessels import torus_section

RADIUS_MM, LENGTH_MM, WALL_MM = 3.0, 40.0, 1.0
#: Edge length of the vessels' open tube surfaces (their vertices lie on the tube), mm.
EDGE_MM = 0.5
#: The solid case's vessel: an arc of this radius (mm) and angle (rad).
BEND_MM, BEND_ANGLE = 30.0, 1.5
#: Export settings of both cases (two meshes, q = 0 and 1).
EXPORT = {"q": [0, 1], "angular_count": 48, "spacing_mm": 1.0}


def hollow_tube_case(folder: Path) -> Path:
    """A straight open tube of radius 3 mm along +z, 40 mm long, built hollow (1 mm wall, a port) with a mould."""
    import trimesh

    centerline, surface = straight_tube(folder, RADIUS_MM, LENGTH_MM)
    trimesh.Trimesh(*tube_vertices_faces(RADIUS_MM, LENGTH_MM, EDGE_MM), process=False).export(surface)
    final = {"centerline": str(centerline), "surface": str(surface)}
    return write_case(folder, "hollow", final=final, links={"count": 2},
                      export={**EXPORT, "wall_mm": WALL_MM, "port_mm": 1.0, "mould": {"margin_mm": 8}})


def bent_solid_case(folder: Path) -> Path:
    """An open tube about a circular arc, solid and without mould: the straight q = 0 shape blends into the arc
    through shorter curves, so the body's length changes over q."""
    import trimesh

    from softdesign.io.polylines_vtp import write_polylines_vtp

    t = np.linspace(0.0, BEND_ANGLE, 121)
    points = BEND_MM * np.column_stack([np.cos(t), np.sin(t), np.zeros_like(t)])
    (folder / "bent").mkdir()
    centerline, surface = folder / "bent" / "centerline.vtp", folder / "bent" / "surface.stl"
    write_polylines_vtp(centerline, [points], {"MaximumInscribedSphereRadius": [np.full(len(t), RADIUS_MM)]})
    trimesh.Trimesh(*torus_section(BEND_MM, RADIUS_MM, BEND_ANGLE, EDGE_MM), process=False).export(surface)
    final = {"centerline": str(centerline), "surface": str(surface)}
    return write_case(folder, "solid", final=final, links={"count": 2}, export=EXPORT)
