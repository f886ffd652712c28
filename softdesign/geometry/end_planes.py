"""The plane of each end of a vessel surface (a flat cap or an open end's loop) and its tilt to the path's end.

The body is cut square to the centerline's end tangent at the centerline's
end.  A vessel whose flat cap, or clipped opening, is tilted by an angle
theta to that tangent has its rim up to ``r tan(theta)`` past the body's
square end on one side and as far short of it on the other (r the vessel's
radius there): over that length the body does not follow the wall.  This
module finds each end's plane and measures theta and ``r tan(theta)``; it
changes nothing (the fit already drops the points past the end, see
:mod:`softdesign.fitting.selection`); :mod:`softdesign.geometry.end_cut`
decides whether the body's end is cut at this plane instead (``fit.end_cut``).

Detection, per end (the path's end point ``e`` and outward tangent ``t``):

open end
    a boundary loop (chained edges of one face each); its plane is the least
    squares plane of the loop's vertices (the SVD's least singular vector),
    its flatness the RMS distance of those vertices from it.
flat cap
    a connected region of faces whose neighbours' normals differ by less than
    ``FLAT_ANGLE_DEG`` (a capper's flat fan: float32 STL round-off leaves its
    triangles a fraction of a degree apart, so exact coplanarity is not
    asked); its rim is the region's boundary, its plane the rim's least
    squares plane as for a loop.

A candidate is the end's when its rim's centroid lies within
``END_SEARCH_RADII`` inscribed radii of ``e``, its rim's mean distance
from the axis (``e``, ``t``) is at least ``RIM_MIN_FRACTION`` of the
inscribed radius, the rim goes all round the axis (a vertex in each of
``RIM_SECTORS`` equal sectors: a flat patch of the wall beside the end does
not), its vertices lie within ``MAX_FLATNESS_FRACTION`` of that radius (RMS)
of one plane (a flat region of a finely tessellated wall that spans both
rims is no plane) and its normal is within ``MAX_TILT_DEG`` of ``t``; the
nearest such centroid wins.
A rounded VMTK dome has no plane: that end is reported as None (null).
Without inscribed radii nothing is measured (their size scale is what tells
a cap from a patch).  Not in the papers: the seeds fit the wall only.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from softdesign.geometry.edges import EdgeTable, corner_planes, run_starts, unit_normal_rows
from softdesign.geometry.end_cut import MAX_CUT_TILT_DEG
from softdesign.types import FloatArray, IntArray, Points

#: A rim whose centroid is farther than this many inscribed radii from the path's end is not that end's.
END_SEARCH_RADII = 1.0
#: A rim whose mean distance from the end's axis is below this fraction of the inscribed radius is no cap.
RIM_MIN_FRACTION = 0.5
#: Neighbouring faces whose normals differ by less than this belong to one flat cap, degrees.
FLAT_ANGLE_DEG = 1.0
#: A rim must have a vertex in each of this many equal sectors around the end's axis.
RIM_SECTORS = 8
#: A rim farther from its least squares plane than this fraction of its radius (RMS) lies in no plane.
MAX_FLATNESS_FRACTION = 0.05
#: A plane tilted more than this to the end tangent is a wall facet, not an end, degrees.
MAX_TILT_DEG = 60.0
#: The rim past the body's square end that the build warns about, mm (a tenth of a 2.5 mm vessel's radius).
RIM_GAP_TOLERANCE_MM = 0.25


@dataclass(frozen=True)
class EndPlane:
    """The plane found at one end of the path and how it sits against the body's square end.

    Attributes
    ----------
    kind : "open_end" (a boundary loop) or "flat_cap" (a flat region of faces)
    normal : (3,) unit normal of the plane, pointing out of the vessel along the end tangent
    point : (3,) mm, the rim's centroid (a point of the plane)
    tilt_deg : angle between the normal and the path's end tangent, degrees
    radius_mm : mean distance of the rim's vertices from the end's axis, mm
    rim_gap_mm : ``radius_mm * tan(tilt)``, how far the rim reaches past the body's square end, mm
    axis_offset_mm : where the plane crosses the end's axis, along the outward tangent from the path's end, mm
    flatness_mm : RMS distance of the rim's vertices from the plane, mm
    """

    kind: str
    normal: FloatArray
    point: FloatArray
    tilt_deg: float
    radius_mm: float
    rim_gap_mm: float
    axis_offset_mm: float
    flatness_mm: float

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready figures (mm, degrees)."""
        return {
            "kind": self.kind,
            "normal": [float(x) for x in self.normal],
            "point_mm": [float(x) for x in self.point],
            "tilt_deg": self.tilt_deg,
            "radius_mm": self.radius_mm,
            "rim_gap_mm": self.rim_gap_mm,
            "axis_offset_mm": self.axis_offset_mm,
            "flatness_mm": self.flatness_mm,
        }


def end_planes(
    vertices: Points, faces: IntArray, ends: Points, tangents: Points, inscribed_mm: FloatArray,
    table: EdgeTable | None = None, labels: np.ndarray | None = None,
) -> tuple[EndPlane | None, EndPlane | None]:
    """The plane at the path's inlet and at its outlet, or None where no flat cap or open loop is found.

    Parameters
    ----------
    vertices, faces : the vessel surface, mm
    ends : (2, 3) mm, the path's first and last points (the body's ends)
    tangents : (2, 3) unit tangents of the path at those points, in the path's direction
    inscribed_mm : (2,) inscribed-sphere radius at each end, mm
    table : the faces' edge table on ``len(vertices)`` vertices, when the caller has it (else made here)
    labels : (F,) :func:`flat_labels` of the surface, when the caller has them (else found here)
    """
    vertices, faces = np.asarray(vertices, float), np.asarray(faces, np.int64)
    ends, inscribed_mm = np.asarray(ends, float), np.asarray(inscribed_mm, float)
    edges = table if table is not None and table.n_vertices == len(vertices) else EdgeTable.of(faces, len(vertices))
    rims = [("open_end", loop) for loop in _boundary_loops(edges)]
    # a cap's faces lie within its rim, whose centre is within END_SEARCH_RADII inscribed radii of the end
    reach = (END_SEARCH_RADII + 1.0 / np.cos(np.radians(MAX_TILT_DEG))) * inscribed_mm
    near = _faces_near(vertices, faces, ends, reach)
    if labels is None or len(labels) != len(faces):
        labels = flat_labels(vertices, faces, edges)
    rims += [("flat_cap", _region_rim(faces, f, len(vertices))) for f in _flat_regions(labels, near)]
    # a flat region with no boundary of its own (a closed flat shell) has no rim; each rim's centre serves both ends
    points = [(kind, vertices[ids]) for kind, ids in rims if len(ids) >= 3]
    candidates = [(kind, rim, rim.mean(axis=0)) for kind, rim in points]
    out = []
    for k, outward in ((0, -1.0), (1, 1.0)):
        out.append(_end_plane(candidates, np.asarray(ends[k], float),
                              outward * np.asarray(tangents[k], float), float(inscribed_mm[k])))
    return out[0], out[1]


def rim_gap_warnings(planes: dict[str, dict[str, Any] | None]) -> list[str]:
    """One line per end whose rim reaches more than ``RIM_GAP_TOLERANCE_MM`` past the body's square end."""
    what = {"flat_cap": "flat cap", "open_end": "open end"}
    return [
        f"the vessel's {what[p['kind']]} at the {name} is tilted {p['tilt_deg']:.1f} deg to the centerline's end "
        f"tangent, but the body's {name} is cut square to that tangent: the vessel's rim (radius "
        f"{p['radius_mm']:.3f} mm) reaches {p['rim_gap_mm']:.3f} mm past the body's end on one side and stops as "
        f"far short of it on the other (more than {RIM_GAP_TOLERANCE_MM:g} mm), and the body does not follow the "
        "wall there; clip that end of the surface square to the centerline (e.g. vmtksurfaceclipper) and re-cap it "
        f"if the end must match (fit.end_cut: auto cuts the body at a plane tilted up to {MAX_CUT_TILT_DEG:g} deg)"
        for name, p in planes.items() if p is not None and p["rim_gap_mm"] > RIM_GAP_TOLERANCE_MM
    ]


def _end_plane(
    rims: list[tuple[str, Points, FloatArray]], end: FloatArray, tangent: FloatArray, inscribed: float
) -> EndPlane | None:
    """The nearest of ``rims`` (kind, rim vertices, their centroid) that passes for this end's plane, or None."""
    tangent = tangent / np.linalg.norm(tangent)
    best: tuple[float, EndPlane] | None = None
    for kind, rim, centre in rims:
        distance = float(np.linalg.norm(centre - end))
        if distance > END_SEARCH_RADII * inscribed:
            continue
        offset = rim - end
        radial = offset - np.outer(offset @ tangent, tangent)
        radius = float(np.mean(np.linalg.norm(radial, axis=1)))
        if radius < RIM_MIN_FRACTION * inscribed or not _all_round(radial, tangent):
            continue
        normal = np.linalg.svd(rim - centre, full_matrices=False)[2][-1]
        normal = normal if normal @ tangent >= 0 else -normal
        tilt = float(np.arccos(np.clip(normal @ tangent, -1.0, 1.0)))
        flatness = float(np.sqrt(np.mean(((rim - centre) @ normal) ** 2)))
        if np.degrees(tilt) > MAX_TILT_DEG or flatness > MAX_FLATNESS_FRACTION * radius:
            continue
        plane = EndPlane(
            kind, normal, centre, float(np.degrees(tilt)), radius, radius * float(np.tan(tilt)),
            float((centre - end) @ normal / (normal @ tangent)), flatness,
        )
        if best is None or distance < best[0]:
            best = (distance, plane)
    return None if best is None else best[1]


def _boundary_loops(edges: EdgeTable) -> list[IntArray]:
    """Vertex ids of each chain of boundary edges (edges of one face), as connected components."""
    import trimesh

    boundary = edges.single_edges()
    if len(boundary) == 0:
        return []
    return [np.asarray(c, np.int64) for c in trimesh.graph.connected_components(boundary, min_len=3)]


def _all_round(radial: Points, tangent: FloatArray) -> bool:
    """True when the rim's radial offsets (perpendicular to ``tangent``) have a vertex in every sector."""
    u = np.cross(tangent, np.eye(3)[int(np.argmin(np.abs(tangent)))])
    u /= np.linalg.norm(u)
    angle = np.arctan2(radial @ np.cross(tangent, u), radial @ u)
    sector = np.minimum((np.mod(angle, 2.0 * np.pi) * (RIM_SECTORS / (2.0 * np.pi))).astype(int), RIM_SECTORS - 1)
    return len(np.unique(sector)) == RIM_SECTORS


def _faces_near(vertices: Points, faces: IntArray, ends: Points, reach: FloatArray) -> np.ndarray:
    """Bool per face: its centre (trimesh's ``triangles_center``) lies within ``reach[k]`` of ``ends[k]``.

    Centres are computed only for faces that have no axis on which all three vertices lie more than that
    reach (padded by a relative 1e-6, far above round-off) to one side of the end: their centres are too far.
    Each vertex's sides of both ends are one 16-bit word (end k's six bits from bit 8 k), so the faces'
    corners are gathered once, from coordinate rows.
    """
    near = np.zeros(len(faces), bool)
    rows = np.ascontiguousarray(np.asarray(vertices, float).T)
    side = np.zeros(len(vertices), np.uint16)
    for k, (end, within) in enumerate(zip(ends, reach, strict=True)):
        pad = within + 1e-6 * (within + np.abs(end))
        for axis in range(3):  # bit axis: below the end's reach on that axis, bit 3 + axis: above it
            side |= (rows[axis] < end[axis] - pad[axis]).astype(np.uint16) << np.uint16(8 * k + axis)
            side |= (rows[axis] > end[axis] + pad[axis]).astype(np.uint16) << np.uint16(8 * k + 3 + axis)
    corners = side[faces.T]  # (3, F)
    common = corners[0] & corners[1]
    common &= corners[2]  # a side all three corners are on
    for k, (end, within) in enumerate(zip(ends, reach, strict=True)):
        candidates = np.flatnonzero((common >> np.uint16(8 * k)) & np.uint16(0xFF) == 0)
        centres = vertices[faces[candidates]].mean(axis=1)
        near[candidates[np.linalg.norm(centres - end, axis=1) <= within]] = True
    return near


def flat_labels(vertices: Points, faces: IntArray, edges: EdgeTable) -> np.ndarray:
    """(F,) int32: each face's flat region, the connected faces whose neighbours' normals differ by less than
    ``FLAT_ANGLE_DEG``, numbered in the order of their smallest face id.

    The whole surface's work of :func:`end_planes` that does not depend on the path (normals, angles and one
    connected-components pass over 1M faces): the ingest finds it beside its other checks of the surface.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    vertices, faces = np.asarray(vertices, float), np.asarray(faces, np.int64)
    pairs = edges.face_pairs()
    pairs = pairs[_pair_angles(_face_normals(vertices, faces), pairs) < np.radians(FLAT_ANGLE_DEG)]
    count = len(faces)
    graph = coo_matrix((np.ones(len(pairs), np.int8), (pairs[:, 0], pairs[:, 1])), shape=(count, count))
    return connected_components(graph, directed=False)[1]


def _flat_regions(labels: np.ndarray, near: np.ndarray) -> list[IntArray]:
    """Face ids of each flat region of two or more faces (``labels``: :func:`flat_labels`) that holds a face of
    ``near`` (bool per face), in the order of their smallest face id."""
    sizes = np.bincount(labels)
    wanted = np.zeros(len(sizes), bool)
    wanted[labels[near]] = True
    wanted &= sizes >= 2
    members = np.flatnonzero(wanted[labels])  # only the wanted regions' faces are sorted by region
    by_label = members[np.argsort(labels[members], kind="stable")]
    starts = np.concatenate(([0], np.cumsum(sizes[wanted])))
    return [by_label[starts[k]:starts[k + 1]] for k in range(int(np.count_nonzero(wanted)))]


def _face_normals(vertices: Points, faces: IntArray) -> FloatArray:
    """(3, F) unit normals, x, y and z rows, as trimesh's ``face_normals`` makes them (zero for a degenerate face):
    :func:`~softdesign.geometry.edges.unit_normal_rows`, the same numbers bit for bit in about a third of
    trimesh's time on 1M faces, which gathered (F, 3, 3) corners and strode across their coordinates."""
    return unit_normal_rows(*corner_planes(vertices, faces))[0]


def _pair_angles(normals: FloatArray, pairs: IntArray) -> FloatArray:
    """(P,) angle between the unit normals (3, F) of each face pair (P, 2), rad: trimesh's ``vector_angle``
    (the dot product clipped to [-1, 1], its arccos) on coordinate rows."""
    a, b = np.take(normals, pairs[:, 0], axis=1), np.take(normals, pairs[:, 1], axis=1)
    dots = a[0] * b[0]
    dots += a[1] * b[1]
    dots += a[2] * b[2]
    return np.abs(np.arccos(np.clip(dots, -1.0, 1.0, out=dots)))


def _region_rim(faces: IntArray, facet: IntArray, n_vertices: int) -> IntArray:
    """Sorted vertex ids of the edges used once by the region's faces (its boundary).

    Only the region's own 3 F edges are grouped (not a mask over the whole mesh's edges): the cost
    follows the region's size, which matters on a million-triangle wall with hundreds of flat pairs.
    """
    ids = np.sort(EdgeTable.of(faces[facet], n_vertices).single_edges(), axis=None)
    # np.unique, sorted; numpy 2.4's np.unique hashes integers first, ten times slower at these sizes
    return ids[run_starts(ids)]
