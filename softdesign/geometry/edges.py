"""A triangle mesh's edges grouped by vertex pair, by one sort of integer keys.

Edge 3 f + p of face f joins ``faces[f, p]`` and ``faces[f, (p + 1) % 3]``
(trimesh's ``faces_to_edges`` order); its key ``min V + max`` (V vertices,
int64 up to V = 3e9) is the same for both directions.  Sorted, the keys put
the face edges of one vertex pair next to each other: the mesh checks
(:mod:`softdesign.meshing.topology`) and the end planes
(:mod:`softdesign.geometry.end_planes`) read boundaries, adjacency and edge
counts from them instead of trimesh's row grouping, which hashes and sorts
the 3 F rows again for each question.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdesign.types import FloatArray, IntArray


def edge_keys(faces: IntArray, n_vertices: int) -> IntArray:
    """(3 F,) int64: the key ``min V + max`` of each face edge, in the order 3 f + p."""
    start, end = faces.ravel(), faces[:, [1, 2, 0]].ravel()
    return np.minimum(start, end) * n_vertices + np.maximum(start, end)


def run_starts(values: IntArray) -> IntArray:
    """Where each run of equal values of the sorted ``values`` begins (their first positions), (G,) int64."""
    first = np.ones(len(values), bool)
    first[1:] = values[1:] != values[:-1]
    return np.flatnonzero(first)


@dataclass(frozen=True)
class EdgeTable:
    """The faces' edges (3 f + p, :func:`edge_keys`), grouped by vertex pair.

    Attributes
    ----------
    n_vertices : V, the vertex count the keys are made with
    keys : (3 F,) int64, the edges' keys, sorted
    order : (3 F,) int64, the edge (3 f + p) at each position of ``keys``
    starts : (G,) int64, where each group of equal keys begins in ``keys``
    uses : (G,) int64, the group's size: how many face edges join that vertex pair
    """

    n_vertices: int
    keys: IntArray
    order: IntArray
    starts: IntArray
    uses: IntArray

    @classmethod
    def of(cls, faces: IntArray, n_vertices: int) -> EdgeTable:
        """The table of ``faces`` (F, 3) on ``n_vertices`` vertices."""
        key = edge_keys(faces, n_vertices)
        order = np.argsort(key, kind="stable")  # a tessellation's keys come in long sorted runs
        keys = key[order]
        starts = run_starts(keys)
        return cls(n_vertices, keys, order, starts, np.diff(np.append(starts, len(keys))))

    def edges(self) -> IntArray:
        """(G, 2) vertex ids, smaller first, of every edge once, in key order (:attr:`uses` counts each)."""
        return self._pairs(self.keys[self.starts])

    def single_edges(self) -> IntArray:
        """(B, 2) vertex ids, smaller first, of the edges used by one face edge only, in key order."""
        return self._pairs(self.keys[self.starts[self.uses == 1]])

    def _pairs(self, keys: IntArray) -> IntArray:
        """(n, 2) the vertex ids, smaller first, of edge ``keys`` (n,) (:func:`edge_keys`)."""
        return np.column_stack((keys // self.n_vertices, keys % self.n_vertices))

    def face_pairs(self) -> IntArray:
        """(P, 2) the two faces on each edge that exactly two face edges use, when the faces are distinct:
        trimesh's ``face_adjacency`` up to the order of the pairs and within them."""
        twice = self.starts[self.uses == 2]
        pairs = self.order[np.column_stack((twice, twice + 1))] // 3
        return pairs[pairs[:, 0] != pairs[:, 1]]


def corner_planes(vertices: FloatArray, faces: IntArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The first, second and third corner of every face as (3, F) arrays, mm: x, y and z each contiguous.

    Per-face geometry on whole coordinate rows runs on contiguous memory, where (F, 3, 3) corners
    made every operation stride across the other coordinates; the numbers are the same.
    """
    corners = np.take(np.ascontiguousarray(vertices.T), np.ascontiguousarray(faces.T), axis=1)  # (3, 3, F)
    return corners[:, 0], corners[:, 1], corners[:, 2]


#: A face whose edges' cross product is no longer than this is degenerate, its normal zero (trimesh's
#: ``util.TOL_ZERO``, 100 float64 resolutions).
TRIMESH_TOL_ZERO = 1e-13


def unit_normal_rows(p0: FloatArray, p1: FloatArray, p2: FloatArray) -> tuple[FloatArray, np.ndarray]:
    """(3, F) unit normals of the faces with corners ``p0``, ``p1``, ``p2`` (3, F) mm (:func:`corner_planes`), and
    (F,) bool, the faces long enough for one: trimesh's ``face_normals`` (zero for a degenerate face), bit for bit.

    trimesh's arithmetic on coordinate rows: the cross product of p1 - p0 and p2 - p1 with ``np.cross``'s products
    in its order, its length from the squares added x + y, then + z, as trimesh's ``np.dot`` with ones adds them,
    zero below ``TRIMESH_TOL_ZERO``, and the reciprocal length multiplied in (tests/geometry/test_end_planes.py
    and tests/io/test_stl_bytes.py compare them with trimesh's).
    """
    normals = row_cross(p1 - p0, p2 - p1)
    squares = normals * normals
    length = squares[0] + squares[1]
    length += squares[2]
    np.sqrt(length, out=length)
    valid = length > TRIMESH_TOL_ZERO
    scale = np.zeros_like(length)
    np.divide(1.0, length, out=scale, where=valid)
    normals *= scale
    normals[:, ~valid] = 0.0  # not -0.0 where a tiny negative component met the zero scale: trimesh pads zeros
    return normals, valid


def row_cross(u: FloatArray, v: FloatArray) -> FloatArray:
    """``u x v`` (3, F) of vectors held as coordinate rows (3, F): ``np.cross``'s products in its order, component
    by component (``u[j] v[k] - u[k] v[j]``), the same numbers on contiguous rows."""
    cross = np.empty_like(u)
    for i, (j, k) in enumerate(((1, 2), (2, 0), (0, 1))):
        np.multiply(u[j], v[k], out=cross[i])
        cross[i] -= u[k] * v[j]
    return cross
