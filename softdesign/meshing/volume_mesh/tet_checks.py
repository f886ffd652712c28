"""Checks of a tetrahedral mesh of the body: every tetrahedron positive, the body's volume, an empty chamber.

The mesher keeps the boundary within an envelope of the body's surface, so
the tetrahedra fill the body's volume up to that envelope: within
:data:`TET_VOLUME_RTOL` (1 %) of the closed surface it was given.  A hollow
body's chamber must stay empty: no tetrahedron's centroid inside the closed
chamber surface (fTetWild fills by winding number, so a chamber wound
inwards stays out; a tetrahedron inside would also show in the volume).
The figures are those of :mod:`softdesign.meshing.volume_mesh.tet_quality`, with the
boundary's topology (the faces of one tetrahedron only).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from softdesign.errors import MeshError
from softdesign.meshing.enclosed import points_inside
from softdesign.meshing.topology import mesh_topology
from softdesign.meshing.volume_mesh.tet_quality import boundary_faces, tet_centroids, tet_quality
from softdesign.types import FloatArray, IntArray

#: The tetrahedra's volume against the body's, relative (issue 16).
TET_VOLUME_RTOL = 0.01
#: A regular tetrahedron of edge s has volume s^3 / (6 sqrt 2): the count of tetrahedra a volume needs at size s.
REGULAR_TET_FACTOR = 6.0 * math.sqrt(2.0)


def expected_tets(volume_mm3: float, size_mm: float) -> float:
    """About how many tetrahedra of edge ``size_mm`` fill ``volume_mm3`` (regular tetrahedra; fTetWild is close)."""
    return volume_mm3 * REGULAR_TET_FACTOR / size_mm**3


def check_tet_mesh(
    points: FloatArray, tets: IntArray, body_volume_mm3: float, chamber: tuple[FloatArray, IntArray] | None, label: str,
) -> dict[str, Any]:
    """The figures of a tetrahedral mesh of the body, raising when a check fails.

    Parameters
    ----------
    points : (P, 3) float, mm
    tets : (T, 4) int, VTK order
    body_volume_mm3 : the volume of the closed surface that was meshed, mm^3
    chamber : the closed chamber surface (vertices, faces) of a hollow body, or None
    label : names the mesh in errors (e.g. ``volume mesh at q=0.000``)

    Raises
    ------
    MeshError
        A tetrahedron of zero or negative volume, a volume off by more than
        TET_VOLUME_RTOL, or a tetrahedron in the chamber; with the figures.
    """
    quality = tet_quality(points, tets)
    rel = quality.volume_mm3 / body_volume_mm3 - 1.0
    inside = 0
    if chamber is not None:
        inside = int(np.count_nonzero(points_inside(tet_centroids(points, tets), *chamber, f"{label}: chamber")))
    boundary = mesh_topology(points, boundary_faces(tets))
    figures: dict[str, Any] = {
        "tets": quality.tets,
        "points": int(len(points)),
        "volume_mm3": quality.volume_mm3,
        "body_volume_mm3": body_volume_mm3,
        "volume_rel_error": rel,
        "volume_rtol": TET_VOLUME_RTOL,
        "min_tet_volume_mm3": quality.min_tet_volume_mm3,
        "min_dihedral_deg": quality.min_dihedral_deg,
        "max_dihedral_deg": quality.max_dihedral_deg,
        "max_radius_edge": quality.max_radius_edge,
        "mean_edge_mm": quality.mean_edge_mm,
        "chamber_centroids_inside": None if chamber is None else inside,
        "boundary_faces": int(boundary.faces),
        "boundary_watertight": boundary.watertight,
        "boundary_winding_consistent": boundary.winding_consistent,
        "boundary_shells": boundary.shells,
        "boundary_euler": boundary.euler,
    }
    failures = []
    if quality.min_tet_volume_mm3 <= 0:
        failures.append(f"a tetrahedron has volume {quality.min_tet_volume_mm3:.3g} mm3 (inverted or flat)")
    if abs(rel) > TET_VOLUME_RTOL:
        failures.append(f"the tetrahedra hold {quality.volume_mm3:.2f} mm3, {100 * rel:+.2f} % of the body's "
                        f"{body_volume_mm3:.2f} mm3 (expected within {100 * TET_VOLUME_RTOL:g} %): lower "
                        "export.volume_mesh.envelope_mm")
    if inside:
        failures.append(f"{inside} of {quality.tets} tetrahedra have their centroid inside the chamber, which must "
                        "stay empty")
    if failures:
        raise MeshError(f"{label}: " + "; ".join(failures))
    return figures
