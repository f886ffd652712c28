"""The actuator's outer surface at several q on ONE tessellation, for a morphing mesh (``morph.glb``).

The export's solids are tessellated per q (rings about ``spacing_mm`` apart along
the arc length at that q), so their vertex counts differ between q.  A glTF
morph target needs the same vertices at every q: here every q is tessellated on
one l grid, the export's grid at the q whose grid has the most rings (so no q
is coarser than its own export), with the export's angles.  The surface is the
body offset by ``offset_mm`` with planar end caps, the same sweep as the
export's outer skin; a hollow body's chamber and port are not carried (their
tessellation comes from manifold3d's boolean and differs between q).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdesign.errors import MeshError
from softdesign.fitting.radius_field import RadiusField
from softdesign.geometry.blend import BlendedShape
from softdesign.meshing.body.sections import export_l_grid, sections_on_grid
from softdesign.meshing.solids import cut_body
from softdesign.meshing.tessellate import sweep_from_sections
from softdesign.meshing.volume import BodySpec, angle_grid
from softdesign.types import FloatArray, IntArray


@dataclass(frozen=True)
class MorphSurfaces:
    """The outer surface at each q on one tessellation.

    Attributes
    ----------
    q : (m,) the export's q values, ascending as given
    vertices : (m, V, 3) float, mm: the surface at each q, vertex k the same (l, angle) node at every q
    faces : (F, 3) int64, counter-clockwise seen from outside, shared by every q
    l : (n,) the ring parameters
    """

    q: FloatArray
    vertices: FloatArray
    faces: IntArray
    l: FloatArray


def morph_surfaces(shape: BlendedShape, field: RadiusField, q_values: FloatArray, spec: BodySpec,
                   spacing_mm: float, angular_count: int) -> MorphSurfaces:
    """The outer surface S(q) offset by ``spec.offset_mm`` at every q of ``q_values`` on one (l, angle) grid.

    Raises
    ------
    MeshError
        A surface that folds or collapses at some q (as the export raises it), or tessellations that
        disagree between q (a bug: the grid is shared).
    """
    q_values = np.asarray(q_values, float)
    grids = [export_l_grid(shape.curve_at(float(q)), field, spacing_mm) for q in q_values]
    l = max(grids, key=len)
    a = angle_grid(angular_count)
    vertices, faces = [], None
    for q in q_values:
        q = float(q)
        sections = sections_on_grid(shape.curve_at(q), q, l, field.evaluate_grid(q, l, a),
                                    field.evaluate_grid(q, l, a, dl=1))
        sweep = sweep_from_sections(sections, spec.offset_mm, spec.min_radius_mm)
        mesh, _ = cut_body(sweep, spec, f"morph q={q:.3f}")
        if faces is not None and not np.array_equal(faces, mesh.faces):
            raise MeshError(f"morph: the tessellation at q={q:.3f} differs from the one at q={q_values[0]:.3f}")
        faces = mesh.faces
        vertices.append(mesh.vertices)
    assert faces is not None
    return MorphSurfaces(q_values, np.stack(vertices), np.asarray(faces, np.int64), l)
