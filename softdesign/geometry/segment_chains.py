"""Join a centerline given as line segments into paths, one from the inlet to each outlet (VMTK's layout).

gmsh writes VMTK-computed centerlines as a mesh of 2-point line cells (legacy
``.vtk`` unstructured grids), and some exporters write polydata the same way.
The segments of a vessel tree form a graph whose ends (degree 1) are the
inlet and the outlets; VMTK's layout is one path from the inlet to each
outlet, the trunk repeated in each.  Here:

1. points that coincide (within ``MERGE_REL`` of the extent) are merged, so a
   writer that repeats a shared point per segment still gives one graph, and
   repeated segments (the trunk written once per path) count once;
2. each connected piece must be a tree: a closed loop has no inlet and no
   outlet, and is refused;
3. the inlet of a piece is the first point of its first segment in the file
   when that is an end (writers keep VMTK's order, inlet first), else the end
   of widest radius when the file has radii, else the first end in the file;
4. one path from the inlet to every other end, in the order the ends appear
   in the file.

No files, no printing: numpy and scipy only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import sparse
from scipy.sparse.csgraph import breadth_first_order, connected_components

from softdesign.errors import InputDataError
from softdesign.types import FloatArray, IntArray, Points

#: Points closer than this fraction of the segments' extent are one point (float32 writers round to 1e-7).
MERGE_REL = 1e-6


@dataclass(frozen=True)
class Chains:
    """Paths through a segment graph.

    Attributes
    ----------
    points : (m, 3) float -- the merged points
    paths : point ids of each path, inlet first
    first_ids : (m,) int -- for each merged point, the id of its first copy in the input (for point arrays)
    segments : how many distinct segments were joined
    """

    points: Points
    paths: tuple[IntArray, ...]
    first_ids: IntArray
    segments: int


def chain_segments(points: Points, segments: IntArray, radius: FloatArray | None, where: str) -> Chains:
    """The paths of a segment graph, one from each piece's inlet to each of its other ends.

    Parameters
    ----------
    points : (n, 3) float
    segments : (k, 2) int -- point ids, in file order
    radius : (n,) float or None -- the inscribed radius at each point, when the file has it
    where : the file named in messages

    Raises
    ------
    InputDataError
        No segments, or a piece of the graph that closes a loop.
    """
    merged, first_ids, inverse = _merge_points(points)
    edges = _distinct_edges(inverse[segments])
    if len(edges) == 0:
        raise InputDataError(f"{where}: its line cells join no two distinct points; expected a centerline")
    m = len(merged)
    graph = sparse.coo_array((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(m, m)).tocsr()
    graph = graph + graph.T
    degree = np.asarray((graph > 0).sum(axis=1)).reshape(-1)
    pieces, components = connected_components(graph, directed=False)
    label = np.asarray(components, np.int64)
    order = _first_appearance(inverse[segments].reshape(-1), m)
    paths: list[IntArray] = []
    for piece in sorted(range(pieces), key=lambda p: order[label == p].min()):
        members = np.flatnonzero(label == piece)
        if len(members) < 2:
            continue
        piece_edges = int(np.isin(edges[:, 0], members).sum())
        if piece_edges != len(members) - 1:
            raise InputDataError(
                f"{where}: its segments close a loop (a piece of {len(members)} points and {piece_edges} segments "
                f"near {np.array2string(merged[members[0]], precision=2)}); a vessel centerline is a tree from the "
                "inlet to the outlets: remove the loop, or compute the centerline again (e.g. softdesign centerline)"
            )
        ends = members[degree[members] == 1]
        ends = ends[np.argsort(order[ends], kind="stable")]
        inlet = _inlet(inverse[segments[0, 0]], ends, label, piece, radius, first_ids)
        _, tree = breadth_first_order(graph, inlet, directed=False, return_predecessors=True)
        predecessors = np.asarray(tree, np.int64)
        paths += [_walk(predecessors, inlet, end) for end in ends if end != inlet]
    return Chains(merged, tuple(paths), first_ids, len(edges))


def _merge_points(points: Points) -> tuple[Points, IntArray, IntArray]:
    """Merged points (m, 3), the first input id of each (m,), and each input point's merged id (n,)."""
    extent = float(np.ptp(points, axis=0).max()) if len(points) else 0.0
    tol = max(MERGE_REL * extent, np.finfo(float).tiny)
    keys = np.round(points / tol).astype(np.int64)
    _, first_ids, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    # merged ids in order of first appearance: the same file gives the same numbering
    rank = np.argsort(np.argsort(first_ids, kind="stable"), kind="stable")
    first_sorted = np.sort(first_ids)
    return points[first_sorted], first_sorted, rank[inverse]


def _distinct_edges(pairs: IntArray) -> IntArray:
    """(e, 2) sorted, distinct, non-degenerate edges, in order of first appearance."""
    pairs = np.sort(pairs, axis=1)
    pairs = pairs[pairs[:, 0] != pairs[:, 1]]
    if len(pairs) == 0:
        return pairs
    _, first = np.unique(pairs, axis=0, return_index=True)
    return pairs[np.sort(first)]


def _first_appearance(ids: IntArray, m: int) -> IntArray:
    """For each merged point id (m,), the position of its first appearance in ``ids``."""
    order = np.full(m, len(ids), np.int64)
    np.minimum.at(order, ids, np.arange(len(ids)))
    return order


def _inlet(
    first_point: int, ends: IntArray, label: IntArray, piece: int, radius: FloatArray | None, first_ids: IntArray
) -> int:
    """The inlet end of one piece (see the module notes, step 3)."""
    if label[first_point] == piece and first_point in ends:
        return int(first_point)
    if radius is not None:
        return int(ends[int(np.argmax(radius[first_ids[ends]]))])
    return int(ends[0])


def _walk(predecessors: IntArray, inlet: int, end: int) -> IntArray:
    """Point ids from ``inlet`` to ``end`` along the breadth-first tree."""
    path = [int(end)]
    while path[-1] != inlet:
        path.append(int(predecessors[path[-1]]))
    return np.asarray(path[::-1], np.int64)
