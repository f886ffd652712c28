"""The inscribed radius of a centerline file that has none, measured on ``final.surface``.

gmsh's export of VMTK centerlines, CSV and NPY files of three columns, and
many hand-made centerlines carry no ``MaximumInscribedSphereRadius``.  When
the case gives the vessel's surface, each point's inscribed radius is taken
as its exact distance to the surface (the radius of the largest sphere about
that point inside the wall, which is VMTK's definition at a point of the
medial axis), and the ingest notes say so.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from softdesign.geometry.network import CenterlineNetwork, Polyline
from softdesign.types import UNIT_SCALE_TO_MM

if TYPE_CHECKING:  # only annotations
    from softdesign.config import Case


def with_surface_radius(case: Case, network: CenterlineNetwork) -> CenterlineNetwork:
    """``network`` (mm) with each polyline's missing radius measured on ``case.final.surface``.

    Unchanged when every polyline has its radius, or when the case has no surface.
    """
    missing = [p.radius is None for p in network.polylines]
    if not any(missing) or case.final.surface is None:
        return network
    from softdesign.io.surface import read_surface
    from softdesign.meshing.compare import squared_distances

    units = case.final.surface_units or case.units
    vertices, faces = read_surface(case.final.surface, UNIT_SCALE_TO_MM[units])
    polylines = tuple(
        Polyline(p.points, np.sqrt(squared_distances(p.points, vertices, faces)), p.cell_data) if lacks else p
        for p, lacks in zip(network.polylines, missing, strict=True)
    )
    measured = np.concatenate([p.radius for p, lacks in zip(polylines, missing, strict=True)
                               if lacks and p.radius is not None])
    note = (f"{network.source}: no MaximumInscribedSphereRadius in {sum(missing)} of {len(missing)} polyline(s); "
            f"their inscribed radius is each point's distance to final.surface {case.final.surface.name} "
            f"({measured.min():.3g} to {measured.max():.3g} mm)")
    return CenterlineNetwork(polylines, network.source, network.notes + (note,))
