"""Check a vessel surface for centerline extraction and close its openings.

VMTK's ``vmtkcenterlines`` caps an open surface before it tetrahedralises it
(``vtkvmtkCapPolyData``, a fan from each boundary loop's barycentre); so does
:func:`close_surface`, and the barycentres are the openings' centres, the
endpoints the centerlines run between.  What VMTK leaves to the user is
checked here first, each with a message that says what to do: a surface in
several pieces, edges shared by more than two triangles (a surface that is
not closed yet has no openings), faces wound against their neighbours.  A
closed surface wound inwards (negative volume: many STL exports) is flipped,
and the result says so.

No files, no printing: numpy and scipy only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.errors import InputDataError
from softdesign.meshing.topology import mesh_topology, signed_volume
from softdesign.types import FloatArray, IntArray

#: Fewest triangles of a vessel surface (a coarse tube of 8 around by 2 along already has 32).
MIN_TRIANGLES = 32
#: Most triangles accepted, so that extraction stays within the 2 GiB memory budget. Peak RSS of `softdesign
#: centerline` on straight tubes (64 or 128 around): 100,000 triangles 0.39 GB in 19 s, 250,000 0.65 GB in 70 s,
#: 500,000 1.25 GB in 245 s; 999,000 took 5.3 GB and 320 s (issue 45). A VMTK aorta has about 13,000.
MAX_TRIANGLES = 500_000


@dataclass(frozen=True)
class Opening:
    """One boundary loop of an open surface (or one cap of a closed one), mm.

    Attributes
    ----------
    centre : (3,) float -- barycentre of the loop's vertices (VMTK's profile barycentre)
    area : float, mm^2 -- area of the fan from the centre over the loop (or of the cap's faces)
    """

    centre: FloatArray
    area: float

    @property
    def radius(self) -> float:
        """Radius of the disc of the same area, mm."""
        return float(np.sqrt(self.area / np.pi))


@dataclass(frozen=True)
class ClosedSurface:
    """A closed, outward-wound surface and what was done to get it.

    Attributes
    ----------
    vertices : (V, 3) float, mm -- the input's vertices, then one centre per opening
    faces : (F, 3) int -- counter-clockwise seen from outside
    openings : the boundary loops that were capped, in the order found (lowest vertex first)
    centre_ids : (len(openings),) int -- the vertex index of each opening's centre
    notes : what was changed (flipped winding)
    """

    vertices: FloatArray
    faces: IntArray
    openings: tuple[Opening, ...]
    centre_ids: IntArray
    notes: tuple[str, ...] = ()


def close_surface(vertices: npt.ArrayLike, faces: npt.ArrayLike, where: str = "surface") -> ClosedSurface:
    """Check ``(vertices, faces)`` and cap every boundary loop with a fan from its barycentre.

    Parameters
    ----------
    vertices : (V, 3) float, mm
    faces : (F, 3) int
    where : the file or field named in messages

    Raises
    ------
    InputDataError
        Too few or too many triangles, several pieces, non-manifold edges, inconsistent winding.
    """
    vertices = np.asarray(vertices, float)
    faces = np.asarray(faces, np.int64)
    check_size(faces, where)
    topology = mesh_topology(vertices, faces)
    if topology.shells != 1:
        raise InputDataError(
            f"{where}: the surface is in {topology.shells} separate pieces, expected one connected vessel wall; "
            "keep the vessel's piece only (e.g. 3D Slicer's Islands tool, or vmtksurfaceconnectivity)"
        )
    loops = boundary_loops(faces, where)
    closed_faces = [faces]
    closed_vertices = [vertices]
    openings = []
    for k, loop in enumerate(loops):
        centre = vertices[loop].mean(axis=0)
        centre_id = len(vertices) + k
        # a boundary edge a->b of the surface is b->a in the cap, so the cap keeps the surface's winding
        fan = np.stack([np.roll(loop, -1), loop, np.full(len(loop), centre_id)], axis=1)
        closed_faces.append(fan)
        closed_vertices.append(centre[None])
        area = 0.5 * np.linalg.norm(np.cross(vertices[fan[:, 0]] - centre, vertices[fan[:, 1]] - centre), axis=1)
        openings.append(Opening(centre, float(area.sum())))
    all_vertices = np.concatenate(closed_vertices)
    all_faces = np.concatenate(closed_faces)
    notes: list[str] = []
    if signed_volume(all_vertices, all_faces) < 0.0:
        all_faces = all_faces[:, ::-1].copy()
        notes.append(f"{where}: its faces are wound inwards (negative volume); read with the winding reversed")
    return ClosedSurface(
        all_vertices,
        all_faces,
        tuple(openings),
        np.arange(len(vertices), len(vertices) + len(loops), dtype=np.int64),
        tuple(notes),
    )


def check_size(faces: IntArray, where: str) -> None:
    """Refuse a surface with fewer than MIN_TRIANGLES or more than MAX_TRIANGLES triangles, before any work."""
    if not MIN_TRIANGLES <= len(faces) <= MAX_TRIANGLES:
        raise InputDataError(
            f"{where}: {len(faces)} triangles, expected {MIN_TRIANGLES} to {MAX_TRIANGLES:,}; "
            + ("decimate it (e.g. vmtksurfacedecimation or 3D Slicer's Surface Toolbox)" if len(faces) > MAX_TRIANGLES
               else "give the vessel wall, not a fragment")
        )


def boundary_loops(faces: IntArray, where: str = "surface") -> list[IntArray]:
    """Vertex ids of each boundary loop, in the order of its faces' edges (a->b of a face).

    Raises
    ------
    InputDataError
        An edge shared by three or more faces, a boundary vertex where two loops touch, or faces wound
        against their neighbours.
    """
    half = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    n = int(faces.max()) + 1
    forward = half[:, 0] * n + half[:, 1]
    unique, counts = np.unique(forward, return_counts=True)
    undirected = np.unique(np.sort(half, axis=1)[:, 0] * n + np.sort(half, axis=1)[:, 1], return_counts=True)[1]
    if np.any(undirected > 2):
        raise InputDataError(
            f"{where}: {int(np.sum(undirected > 2))} edge(s) are shared by three or more triangles, so the surface "
            "is neither closed nor open at clean openings; repair it (e.g. vmtksurfacecleaner, MeshLab's "
            "'Repair non-manifold edges') and clip the vessel's ends open or cap them"
        )
    if np.any(counts > 1):
        raise InputDataError(
            f"{where}: neighbouring triangles are wound in opposite directions ({int(np.sum(counts > 1))} edges); "
            "make the normals consistent (e.g. vmtksurfacenormals, or MeshLab's 'Re-Orient all faces coherently')"
        )
    reverse = half[:, 1] * n + half[:, 0]
    boundary = half[~np.isin(reverse, unique)]
    if len(boundary) == 0:
        return []
    if len(np.unique(boundary[:, 0])) != len(boundary):
        raise InputDataError(
            f"{where}: two openings touch at a vertex; the boundary does not split into separate loops - "
            "clip the vessel's ends apart or cap them"
        )
    following = dict(zip(boundary[:, 0].tolist(), boundary[:, 1].tolist(), strict=True))
    loops, seen = [], set()
    for start in sorted(following):  # each loop starts at its lowest vertex: the same file gives the same order
        if start in seen:
            continue
        loop = [start]
        while following[loop[-1]] != start:
            loop.append(following[loop[-1]])
        seen.update(loop)
        loops.append(np.asarray(loop, np.int64))
    return loops
