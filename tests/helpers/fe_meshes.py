"""Small structured tetrahedral meshes for the finite-element tests: a quarter tube, hexahedra split into tets.

Each hexahedron of an (i, j, k) grid is split into the six tetrahedra of
Kuhn's triangulation (all along the diagonal from corner 000 to 111), which
is conforming between neighbours because every hexahedron is split the same
way in index space; elements the mapping turns over are re-wound.
"""

from __future__ import annotations

import itertools

import numpy as np

from softdesign.types import FloatArray, IntArray

#: Kuhn's six tetrahedra of the unit cube, as corner bit patterns (x, y, z bits).
_KUHN = [[0, 1 << a, (1 << a) | (1 << b), 7] for a, b, _ in itertools.permutations(range(3))]


def grid_tets(shape: tuple[int, int, int]) -> IntArray:
    """Tetrahedra (6 n0 n1 n2, 4) of the node grid ``(n0 + 1, n1 + 1, n2 + 1)`` (C order)."""
    n0, n1, n2 = shape
    index = np.arange((n0 + 1) * (n1 + 1) * (n2 + 1)).reshape(n0 + 1, n1 + 1, n2 + 1)
    i, j, k = (g.ravel() for g in np.meshgrid(np.arange(n0), np.arange(n1), np.arange(n2), indexing="ij"))
    corner = {bits: index[i + (bits & 1), j + ((bits >> 1) & 1), k + ((bits >> 2) & 1)] for bits in range(8)}
    return np.concatenate([np.stack([corner[b] for b in tet], axis=1) for tet in _KUHN])


def oriented(points: FloatArray, tets: IntArray) -> IntArray:
    """``tets`` with every negatively oriented element's last two corners swapped."""
    c = points[tets]
    det = np.linalg.det(np.stack([c[:, 1] - c[:, 0], c[:, 2] - c[:, 0], c[:, 3] - c[:, 0]], axis=-1))
    out = tets.copy()
    out[det < 0, 2], out[det < 0, 3] = tets[det < 0, 3], tets[det < 0, 2]
    return out


def quarter_tube(inner: float, outer: float, height: float, counts: tuple[int, int, int]
                 ) -> tuple[FloatArray, IntArray]:
    """Points (V, 3) mm and tets (E, 4) of the quarter tube ``inner <= r <= outer``, ``0 <= angle <= 90 deg``.

    ``counts`` = (radial, angular, axial) divisions.
    """
    nr, nt, nz = counts
    r = np.linspace(inner, outer, nr + 1)
    t = np.linspace(0.0, np.pi / 2, nt + 1)
    z = np.linspace(0.0, height, nz + 1)
    R, T, Z = np.meshgrid(r, t, z, indexing="ij")
    points = np.stack([R * np.cos(T), R * np.sin(T), Z], axis=-1).reshape(-1, 3)
    return points, oriented(points, grid_tets(counts))
