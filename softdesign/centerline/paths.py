"""Paths of least cost 1/R through the internal Voronoi graph, then smoothed and resampled.

VMTK (Antiga et al.) defines a centerline as the path between two endpoints
that minimises the integral of 1/R along it, R the maximum inscribed sphere
radius: it keeps as far from the wall as it can.  Here the integral is taken
along the Voronoi edges (each edge costs its length times the mean of 1/R at
its ends) and minimised exactly by Dijkstra's algorithm (scipy.sparse.csgraph)
from the inlet, once for every outlet; VMTK solves the same Eikonal problem by
fast marching over the Voronoi faces and backtraces by steepest descent.
Both give a polyline through the medial axis's neighbourhood; the project's
smoothing spline (:func:`softdesign.geometry.curves.smooth_curve_from_polyline`)
removes the edge graph's zig-zag, and the radius is then measured again at
each resampled point as its distance to the nearest surface point (the
empty-sphere radius VMTK reports at Voronoi vertices, taken where the point
now is).

Each path starts at the *pole* of the inlet (the internal Voronoi vertex
farthest from the surface point nearest the inlet's centre) and ends at the
pole of its outlet, as VMTK's Voronoi paths do: about one radius short of the
opening.  :mod:`.ends` then continues each end straight to its opening's
centre, as VMTK appends its seeds.

No files, no printing: numpy and scipy only.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from scipy.sparse.csgraph import dijkstra
from scipy.spatial import cKDTree

from softdesign.centerline.voronoi import VoronoiGraph
from softdesign.errors import GeometryError
from softdesign.geometry.curves import CurveOptions, smooth_curve_from_polyline
from softdesign.types import FloatArray, IntArray, Points

#: A path between graph extremities keeps the vertices at least this many of their radii from each tip.
TIP_RADII = 2.0


def edge_costs(graph: VoronoiGraph) -> FloatArray:
    """Cost of each Voronoi edge (k,): its length times the mean of 1/R at its ends (dimensionless)."""
    i, j = graph.edges[:, 0], graph.edges[:, 1]
    length = np.linalg.norm(graph.points[i] - graph.points[j], axis=1)
    # a zero cost would read as "no edge" in the sparse matrix; two coincident vertices get a tiny one
    return np.maximum(length * 0.5 * (1.0 / graph.radius[i] + 1.0 / graph.radius[j]), 1e-12)


def pole_of(graph: VoronoiGraph, surface_vertex: int) -> int:
    """The internal Voronoi vertex whose sphere touches ``surface_vertex`` with the largest radius, or -1."""
    touching = np.flatnonzero(np.any(graph.tets == surface_vertex, axis=1))
    if len(touching) == 0:
        return -1
    return int(touching[np.argmax(graph.radius[touching])])


def seed_vertex(graph: VoronoiGraph, surface_vertices: FloatArray, point: FloatArray) -> int:
    """The Voronoi vertex a path starts or ends at for an endpoint ``point`` (3,), mm.

    The pole of the nearest surface vertex; when no internal sphere touches that vertex (a spike), the
    Voronoi vertex nearest ``point``.
    """
    nearest = int(cKDTree(surface_vertices).query(point)[1])
    pole = pole_of(graph, nearest)
    return pole if pole >= 0 else int(cKDTree(graph.points).query(point)[1])


def bridge_components(graph: VoronoiGraph, seeds: list[int]) -> VoronoiGraph:
    """The graph with edges added so that every seed's piece joins the first seed's, where balls overlap.

    The internal-tetrahedron test drops some circumcentres at sharp creases (the crotch of a branch
    grafted onto a tube), which can cut the Voronoi graph there although the lumen is open.  VMTK's fast
    marching crosses such gaps through the Voronoi faces; here a vertex of a seed's piece is joined to
    its nearest vertex of another piece when one of the two centres lies inside the other's empty sphere
    (the segment between them then lies inside the lumen).  Only pieces holding a seed are bridged.
    """
    from scipy.sparse.csgraph import connected_components

    _, label = connected_components(graph.adjacency(np.ones(len(graph.edges))), directed=False)
    added: list[IntArray] = []
    for seed in seeds[1:]:
        piece = np.flatnonzero(label == label[seed])
        if label[seed] == label[seeds[0]]:
            continue
        rest = np.flatnonzero(label != label[seed])
        distance, nearest = cKDTree(graph.points[rest]).query(graph.points[piece])
        other = rest[nearest]
        overlap = distance < np.maximum(graph.radius[piece], graph.radius[other])
        added.append(np.stack([piece[overlap], other[overlap]], axis=1))
        label[label == label[seed]] = label[seeds[0]] if overlap.any() else label[seed]
    if not added:
        return graph
    edges = np.concatenate([graph.edges, *added])
    return VoronoiGraph(graph.points, graph.radius, graph.tets, edges)


def least_cost_paths(graph: VoronoiGraph, source: int, targets: list[int]) -> list[IntArray]:
    """Voronoi vertex ids of the least-cost path from ``source`` to each target, source first.

    Raises
    ------
    GeometryError
        A target is not connected to the source inside the surface (a vessel pinched shut, or an
        endpoint outside it).
    """
    costs, previous_rows = dijkstra(graph.adjacency(edge_costs(graph)), indices=np.array([source]),
                                    return_predecessors=True)
    cost, previous = costs[0], previous_rows[0]
    paths = []
    for k, target in enumerate(targets):
        if not np.isfinite(cost[target]):
            raise GeometryError(
                f"outlet {k + 1}: no path inside the surface from the inlet to it (at "
                f"{np.array2string(graph.points[target], precision=2)} mm); the vessel may be pinched shut "
                "between them - check the segmentation there, or give the endpoints with --inlet/--outlet"
            )
        path = [target]
        while path[-1] != source:
            path.append(int(previous[path[-1]]))
        paths.append(np.asarray(path[::-1], np.int64))
    return paths


def farthest_vertex(graph: VoronoiGraph, sources: npt.ArrayLike) -> tuple[int, float]:
    """The Voronoi vertex farthest (along the graph, mm) from any of ``sources``, and that distance."""
    lengths = np.linalg.norm(graph.points[graph.edges[:, 0]] - graph.points[graph.edges[:, 1]], axis=1)
    distance = dijkstra(graph.adjacency(np.maximum(lengths, 1e-12)), indices=np.atleast_1d(sources), min_only=True)
    distance = np.where(np.isfinite(distance), distance, -1.0)
    far = int(np.argmax(distance))
    return far, float(distance[far])


def smooth_path(
    points: Points, surface_tree: cKDTree, spacing_mm: float, smoothing_mm: float
) -> tuple[Points, FloatArray]:
    """Resample a Voronoi path by arc length and smooth it; the radius at each new point.

    Parameters
    ----------
    points : (n, 3) float, mm -- Voronoi vertices, proximal first
    surface_tree : KD-tree of the (closed) surface's vertices, mm
    spacing_mm : arc-length spacing of the output (the actual one is <= it)
    smoothing_mm : RMS distance the spline may keep from the Voronoi vertices

    Returns
    -------
    (m, 3) float mm, and (m,) float mm: the distance from each point to the nearest surface vertex.
    """
    curve = smooth_curve_from_polyline(points, CurveOptions(spacing_mm=spacing_mm, smoothing_mm=smoothing_mm))
    samples = curve.points(curve.l_grid)
    radius = np.asarray(surface_tree.query(samples)[0], float)
    return samples, radius


def trim_rounded_ends(ids: IntArray, graph: VoronoiGraph) -> IntArray:
    """Drop the Voronoi vertices whose empty sphere reaches past either end of the path (ids, proximal first).

    A path between graph extremities runs into the tips of rounded ends, where the medial axis frays and
    the radius falls to nothing, and where the tip lies off the axis (most segmented domes), the path
    curls towards it.  Keeping only the vertices at least TIP_RADII of their own radii (along the path)
    from each end drops the curl: one radius is where the last sphere touches the tip (where a pole stops
    a path at an opening); the second is the dome itself, over which the sphere's centre leaves the axis
    (on the VMTK aorta's capped top, up to 6 mm at one radius from the tip, 0.1 mm at two).
    """
    points = graph.points[ids]
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    keep = (s >= TIP_RADII * graph.radius[ids]) & (s[-1] - s >= TIP_RADII * graph.radius[ids])
    return ids[keep] if keep.sum() >= 4 else ids


def check_path_length(points: Points, index: int) -> None:
    """A path needs four distinct Voronoi vertices for the spline; say which outlet is too close to the inlet."""
    if len(points) < 4:
        raise GeometryError(
            f"outlet {index + 1}: its path from the inlet passes only {len(points)} Voronoi vertices; the outlet is "
            "too close to the inlet - give other endpoints with --inlet/--outlet"
        )
