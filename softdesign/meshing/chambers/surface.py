"""The closed surface of a hollow body's chamber, as the export carves it, for a simulator's pressure load.

SOFA's ``SurfacePressureConstraint`` (SoftRobots) inflates a cavity given as
a closed triangle surface with its normals pointing out of the cavity, into
the material.  This is exactly the solid the export subtracts from the body
(:func:`softdesign.meshing.solids.build_solid`: the inward offset by
``wall_mm``, ``wall_mm`` short of each end, capped), without the port: the
port's channel ends inside the chamber, so the closed chamber is the whole
pressurised volume but for the channel's own.
"""

from __future__ import annotations

from softdesign.meshing.solids import cut_chamber
from softdesign.meshing.tessellate import TubeSections, sweep_from_sections
from softdesign.meshing.volume import BodySpec
from softdesign.types import FloatArray, IntArray


def chamber_surface(sections: TubeSections, spec: BodySpec) -> tuple[FloatArray, IntArray]:
    """Vertices (V, 3) mm and faces (F, 3) of the closed chamber, wound with normals out of the chamber.

    Raises
    ------
    ValueError
        ``spec`` has no wall (a solid body has no chamber).
    MeshError
        As :func:`~softdesign.meshing.solids.build_solid` for a wall the body cannot take.
    """
    if spec.wall_mm <= 0:
        raise ValueError(f"a chamber needs wall_mm > 0, got {spec.wall_mm}")
    outer = sweep_from_sections(sections, spec.offset_mm, spec.min_radius_mm)
    _, mesh, _ = cut_chamber(sections, outer, spec, f"q={sections.q:.3f}: chamber")
    return mesh.vertices, mesh.faces
