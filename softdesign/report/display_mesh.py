"""Surfaces decimated for display only, with their measured display error.

The report shows the patient's vessel (and the mould's parts) with at most a
few tens of thousands of triangles; the build's files keep every triangle.
The display error is measured, not assumed: the largest distance from an
original vertex to the shown surface, and while it exceeds the tolerance the
shown surface keeps twice the triangles.

Large surfaces (a segmentation's 10^5 to 10^6 triangles) are first clustered
on a grid (VTK's quadric clustering, linear in the triangles), then decimated
(VTK's quadric decimation, whose cost grows faster than the triangles: 6 s a
pass on a 1,000,000-triangle vessel, against 0.3 s for clustering it to 72,000
triangles and 0.3 s for decimating those).  The grid's cells
are a fraction of the tolerance, coarser only where :data:`MAX_CLUSTER_BINS`
cells would not cover the surface's box (VTK keeps a quadric per cell, about
85 bytes: 85 MB at the bound); when the clustered surface alone strays past
the tolerance, the original is decimated instead.
"""

from __future__ import annotations

import numpy as np

from softdesign.types import FloatArray

#: At most this many triangles of the vessel surface are shown (more only to meet the display tolerance), in the
#: 3D view and the surface figure alike.
VESSEL_FACES = 20000
#: The report shows each surface to this distance (mm): a few pixels of a ~100 mm scene 720 px high in the 3D view,
#: one or two of a surface figure's panels; the exported files carry the exact body.
DISPLAY_TOLERANCE_MM = 0.5
#: Surfaces of more than this many times the target triangles are clustered before they are decimated.
CLUSTER_ABOVE = 8
#: The clustering grid's cell, as a fraction of the display tolerance (its error is about a tenth of the cell).
CLUSTER_CELL_FRACTION = 0.5
#: Most cells of the clustering grid (VTK allocates all of them: about 85 bytes each).
MAX_CLUSTER_BINS = 1_000_000
#: Up to this many points, every distance is measured; above, the first batch measured by bound (then doubled).
EXACT_POINTS = 4096
#: The faces, nearest by centroid, whose nearest points bound a point's distance from above.
BOUND_FACES = 2
#: Relative (and mm) slack of a bound against the round-off of VTK's distance (~1e-16 relative).
BOUND_SLACK = 1e-9


def max_distance_to_mesh(points: FloatArray, vertices: FloatArray, faces: np.ndarray) -> float:
    """Largest true distance (mm) from ``points`` (n, 3) to the triangle mesh (vertices, faces).

    VTK's locator (:func:`~softdesign.meshing.compare.squared_distances`) measures the points in order of an
    upper bound of their distance (:func:`distance_bounds`), largest first, until no bound left exceeds the
    largest distance measured: the other points cannot hold the maximum, so it is the same number as over
    every point (on the 1M-triangle bench vessel shown in 20,000 faces, 4,096 of its 500,191 vertices are
    measured: 0.7 s of CPU, not 2.6 s).
    """
    from softdesign.meshing.compare import squared_distances

    points = np.asarray(points, float)
    if len(points) <= EXACT_POINTS:
        return float(np.sqrt(squared_distances(points, vertices, faces).max(initial=0.0)))
    bound = distance_bounds(points, np.asarray(vertices, float), np.asarray(faces, np.int64))
    order = np.argsort(bound)[::-1]
    largest, start, count = 0.0, 0, EXACT_POINTS
    while start < len(order) and bound[order[start]] ** 2 > largest:
        chunk = order[start:start + count]
        largest = max(largest, float(squared_distances(points[chunk], vertices, faces).max()))
        start, count = start + count, 2 * count
    return float(np.sqrt(largest))


def distance_bounds(points: FloatArray, vertices: FloatArray, faces: np.ndarray) -> FloatArray:
    """(n,) mm, at least each point's distance to the mesh: its distance to a point of one of the
    :data:`BOUND_FACES` faces whose centroids are nearest, the foot of the perpendicular on the face's plane
    moved into the face (barycentric coordinates clipped at 0, rescaled to sum 1), plus a relative
    ``BOUND_SLACK`` for round-off against VTK's figures; the true distance wherever that foot lies in the face."""
    from scipy.spatial import cKDTree

    corners = vertices[faces]  # (F, 3, 3)
    _, near = cKDTree(corners.mean(axis=1)).query(points, k=min(BOUND_FACES, len(faces)))
    near = np.asarray(near).reshape(len(points), -1)
    best = np.full(len(points), np.inf)
    for column in near.T:
        a, b, c = (corners[column, k] for k in range(3))
        u, v, w = b - a, c - a, points - a
        uu, uv, vv = (np.einsum("ij,ij->i", x, y) for x, y in ((u, u), (u, v), (v, v)))
        wu, wv = np.einsum("ij,ij->i", w, u), np.einsum("ij,ij->i", w, v)
        det = uu * vv - uv * uv
        with np.errstate(divide="ignore", invalid="ignore"):
            s, t = (vv * wu - uv * wv) / det, (uu * wv - uv * wu) / det
        weights = np.clip(np.column_stack([1.0 - s - t, s, t]), 0.0, None)
        weights = np.where(np.isfinite(weights).all(axis=1, keepdims=True), weights, [1.0, 0.0, 0.0])  # a sliver
        weights /= weights.sum(axis=1, keepdims=True)
        foot = weights[:, :1] * a + weights[:, 1:2] * b + weights[:, 2:] * c
        np.minimum(best, np.linalg.norm(points - foot, axis=1), out=best)
    return best * (1.0 + BOUND_SLACK) + BOUND_SLACK


def decimated_vessel(vertices: FloatArray, faces: np.ndarray, target: int = VESSEL_FACES,
                     tolerance_mm: float = DISPLAY_TOLERANCE_MM):
    """(vertices, faces, error_mm): the vessel surface as the report shows it (:func:`decimated_surface`)."""
    return decimated_surface(vertices, faces, target, tolerance_mm)


def decimated_surface(vertices: FloatArray, faces: np.ndarray, target: int, tolerance_mm: float):
    """(vertices, faces, error_mm): the surface with about ``target`` triangles and its display error.

    The error is the largest distance from an original vertex to the decimated surface (0 when kept whole);
    while it exceeds ``tolerance_mm`` the target doubles (up to the whole surface).
    """
    vertices, faces = np.asarray(vertices, float), np.asarray(faces, np.int64)
    source = (vertices, faces)
    if len(faces) > CLUSTER_ABOVE * target:
        source = clustered(vertices, faces, CLUSTER_CELL_FRACTION * tolerance_mm)
        if len(source[1]) < 4:  # a grid too coarse for the surface left nothing to show: decimate the original
            source = (vertices, faces)
    while len(faces) > target:
        shown = _quadric_decimation(*source, target) if len(source[1]) > target else source
        error = max_distance_to_mesh(vertices, *shown)
        if error <= tolerance_mm:
            return shown[0], shown[1], error
        if shown is source:  # the clustered surface itself strays too far: decimate the original from here
            source = (vertices, faces)
        else:
            target *= 2
    return vertices, faces, 0.0


def clustered(vertices: FloatArray, faces: np.ndarray, cell_mm: float) -> tuple[FloatArray, np.ndarray]:
    """The surface clustered on a grid of cells of ``cell_mm`` (larger when :data:`MAX_CLUSTER_BINS` needs it)."""
    from vtkmodules.vtkFiltersCore import vtkQuadricClustering

    from softdesign.io.vtk_polydata import triangles_from_polydata
    from softdesign.meshing.vtk_triangles import polydata_from_triangles

    extent = np.ptp(vertices, axis=0) + cell_mm
    cell = max(cell_mm, float(np.prod(extent) / MAX_CLUSTER_BINS) ** (1.0 / 3.0))
    divisions = [max(1, int(np.floor(e / cell))) for e in extent]
    cluster = vtkQuadricClustering()
    cluster.SetInputData(polydata_from_triangles(vertices, faces))
    cluster.SetAutoAdjustNumberOfDivisions(False)
    cluster.SetNumberOfDivisions(*divisions)
    cluster.SetUseInputPoints(False)  # each cell's point where its quadric is least: on the surface, not a corner
    cluster.Update()
    return triangles_from_polydata(cluster.GetOutput())


def _quadric_decimation(vertices: FloatArray, faces: np.ndarray, target: int) -> tuple[FloatArray, np.ndarray]:
    from vtkmodules.vtkFiltersCore import vtkQuadricDecimation

    from softdesign.io.vtk_polydata import triangles_from_polydata
    from softdesign.meshing.vtk_triangles import polydata_from_triangles

    decimate = vtkQuadricDecimation()
    decimate.SetInputData(polydata_from_triangles(vertices, faces))
    decimate.SetTargetReduction(1.0 - target / len(faces))
    decimate.Update()
    return triangles_from_polydata(decimate.GetOutput())
