"""Figures of a tetrahedral mesh: signed volumes, dihedral angles, radius-edge ratios, boundary faces.

A tetrahedron is four vertex indices ``(i, j, k, m)`` in VTK's and Gmsh's
order: seen from the fourth vertex, the first three turn counter-clockwise,
so ``det[pj - pi, pk - pi, pm - pi] / 6`` is its volume and is positive.
The quality figures are the two usual ones for finite elements (Shewchuk,
"What is a good linear finite element?", 2002): the smallest dihedral angle
(a regular tetrahedron has arccos(1/3) = 70.53 degrees everywhere; a sliver
tends to 0) and the radius-edge ratio, circumradius over shortest edge
(sqrt(6)/4 = 0.612 for the regular tetrahedron, the smallest possible; a
needle or a cap grows it without bound).  numpy only, no I/O.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.types import FloatArray, IntArray

#: The face opposite each vertex of a tetrahedron, wound outwards for a positive tetrahedron.
OPPOSITE_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]], np.int64)
#: For each of the 6 edges, the two faces (by opposite vertex) that meet on it: edge (i, j) joins the
#: faces opposite the two other vertices.
_EDGE_FACES = np.array([[2, 3], [1, 3], [1, 2], [0, 3], [0, 2], [0, 1]], np.int64)
_EDGES = np.array([[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]], np.int64)


@dataclass(frozen=True)
class TetQuality:
    """The figures of a tetrahedral mesh.

    Attributes
    ----------
    tets : number of tetrahedra
    volume_mm3 : sum of the signed volumes, mm^3
    min_tet_volume_mm3 : the smallest signed volume (> 0 for a valid mesh), mm^3
    min_dihedral_deg, max_dihedral_deg : extreme dihedral angles over all tetrahedra, degrees
    max_radius_edge : largest circumradius / shortest edge (0.612 for a regular tetrahedron)
    mean_edge_mm : mean edge length, mm (for comparing with the target size)
    """

    tets: int
    volume_mm3: float
    min_tet_volume_mm3: float
    min_dihedral_deg: float
    max_dihedral_deg: float
    max_radius_edge: float
    mean_edge_mm: float


def _corners(vertices: npt.ArrayLike, tets: npt.ArrayLike) -> FloatArray:
    v = np.asarray(vertices, float)
    t = np.asarray(tets, np.int64)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices must be (V, 3), got {v.shape}")
    if t.ndim != 2 or t.shape[1] != 4:
        raise ValueError(f"tets must be (T, 4), got {t.shape}")
    if t.size and (t.min() < 0 or t.max() >= len(v)):
        raise ValueError(f"tets index vertices outside 0..{len(v) - 1}")
    return v[t]


def tet_volumes(vertices: npt.ArrayLike, tets: npt.ArrayLike) -> FloatArray:
    """Signed volume of each tetrahedron, mm^3: (T,), positive in VTK's order."""
    c = _corners(vertices, tets)
    a, b, d = c[:, 1] - c[:, 0], c[:, 2] - c[:, 0], c[:, 3] - c[:, 0]
    return np.einsum("ij,ij->i", a, np.cross(b, d)) / 6.0


def dihedral_angles(vertices: npt.ArrayLike, tets: npt.ArrayLike) -> FloatArray:
    """The six interior dihedral angles of each tetrahedron, radians: (T, 6), edges 01 02 03 12 13 23.

    The angle on an edge is pi minus the angle between the outward normals
    of the two faces that meet there.
    """
    c = _corners(vertices, tets)
    f = c[:, OPPOSITE_FACES]  # (T, 4 faces, 3 corners, 3)
    n = np.cross(f[:, :, 1] - f[:, :, 0], f[:, :, 2] - f[:, :, 0])
    # outward: away from the vertex the face is opposite to (whatever the tetrahedron's orientation)
    away = np.einsum("tfk,tfk->tf", n, f[:, :, 0] - c)
    n = n * np.sign(away)[:, :, None]
    n /= np.linalg.norm(n, axis=2, keepdims=True)
    cos = -np.einsum("tek,tek->te", n[:, _EDGE_FACES[:, 0]], n[:, _EDGE_FACES[:, 1]])
    return np.arccos(np.clip(cos, -1.0, 1.0))


def edge_lengths(vertices: npt.ArrayLike, tets: npt.ArrayLike) -> FloatArray:
    """The six edge lengths of each tetrahedron, mm: (T, 6), edges 01 02 03 12 13 23."""
    c = _corners(vertices, tets)
    return np.linalg.norm(c[:, _EDGES[:, 1]] - c[:, _EDGES[:, 0]], axis=2)


def radius_edge_ratios(vertices: npt.ArrayLike, tets: npt.ArrayLike) -> FloatArray:
    """Circumradius over shortest edge of each tetrahedron: (T,), sqrt(6)/4 for a regular one.

    The circumcentre relative to corner 0 is
    (|a|^2 (b x d) + |b|^2 (d x a) + |d|^2 (a x b)) / (2 a . (b x d))
    with a, b, d the edges from corner 0; a flat tetrahedron gives inf.
    """
    c = _corners(vertices, tets)
    a, b, d = c[:, 1] - c[:, 0], c[:, 2] - c[:, 0], c[:, 3] - c[:, 0]
    num = ((a * a).sum(1)[:, None] * np.cross(b, d) + (b * b).sum(1)[:, None] * np.cross(d, a)
           + (d * d).sum(1)[:, None] * np.cross(a, b))
    den = 2.0 * np.einsum("ij,ij->i", a, np.cross(b, d))
    with np.errstate(divide="ignore", invalid="ignore"):
        radius = np.where(den != 0.0, np.linalg.norm(num, axis=1) / np.abs(den), np.inf)
    return radius / edge_lengths(vertices, tets).min(axis=1)


def _cross(u: list[FloatArray], v: list[FloatArray]) -> list[FloatArray]:
    return [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]


def _dot(u: list[FloatArray], v: list[FloatArray]) -> FloatArray:
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]


def tet_measures(vertices: npt.ArrayLike, tets: npt.ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray,
                                                                         FloatArray]:
    """:func:`tet_volumes`, each tetrahedron's least and largest dihedral angle (rad) and
    :func:`radius_edge_ratios`, each (T,), in one pass on coordinate components (numpy's (T, 3) cross products
    and norms are several times slower; the values agree with those functions' to round-off).

    The outward face normals (area vectors) are ``d x b``, ``a x d``, ``b x a`` opposite vertices 1, 2, 3 of a
    positive tetrahedron, with a, b, d its edges from vertex 0, and minus their sum opposite vertex 0 (all inward
    for a negative one, which leaves the angles as they are).  The angle on an edge is pi minus the angle between
    the normals of the two faces meeting there; the circumradius is as :func:`radius_edge_ratios` has it, its
    cross products being ``-n1``, ``-n2``, ``-n3``.
    """
    c = _corners(vertices, tets)
    a, b, d = ([c[:, k, i] - c[:, 0, i] for i in range(3)] for k in (1, 2, 3))
    n1, n2, n3 = _cross(d, b), _cross(a, d), _cross(b, a)
    triple = -_dot(a, n1)  # a . (b x d)
    normals = [[-(n1[i] + n2[i] + n3[i]) for i in range(3)], n1, n2, n3]
    lengths = [np.sqrt(_dot(n, n)) for n in normals]
    cosines = [-_dot(normals[k], normals[m]) / (lengths[k] * lengths[m]) for k, m in _EDGE_FACES.tolist()]
    angles = np.arccos(np.clip(np.stack(cosines, axis=1), -1.0, 1.0))
    squares = [_dot(e, e) for e in (a, b, d, [b[i] - a[i] for i in range(3)], [d[i] - a[i] for i in range(3)],
                                    [d[i] - b[i] for i in range(3)])]
    centre = [squares[0] * n1[i] + squares[1] * n2[i] + squares[2] * n3[i] for i in range(3)]
    with np.errstate(divide="ignore", invalid="ignore"):
        radius = np.where(triple != 0.0, np.sqrt(_dot(centre, centre)) / np.abs(2.0 * triple), np.inf)
    shortest = np.sqrt(np.minimum.reduce(squares))
    return triple / 6.0, angles.min(axis=1), angles.max(axis=1), radius / shortest


def tet_centroids(vertices: npt.ArrayLike, tets: npt.ArrayLike) -> FloatArray:
    """The centroid of each tetrahedron, mm: (T, 3)."""
    return _corners(vertices, tets).mean(axis=1)


def boundary_faces(tets: npt.ArrayLike) -> IntArray:
    """The faces that belong to one tetrahedron only, wound outwards for positive tetrahedra: (B, 3).

    Sorted (by their sorted vertex triple), so the result does not depend on the order of ``tets``.
    """
    t = np.asarray(tets, np.int64)
    faces = t[:, OPPOSITE_FACES].reshape(-1, 3)
    key = np.sort(faces, axis=1)
    _, first, counts = np.unique(key, axis=0, return_index=True, return_counts=True)
    return faces[first[counts == 1]]


def tet_quality(vertices: npt.ArrayLike, tets: npt.ArrayLike) -> TetQuality:
    """Every figure of :class:`TetQuality` for a mesh of at least one tetrahedron."""
    volumes = tet_volumes(vertices, tets)
    if volumes.size == 0:
        raise ValueError("a tetrahedral mesh needs at least one tetrahedron, got none")
    angles = np.degrees(dihedral_angles(vertices, tets))
    return TetQuality(
        tets=int(volumes.size),
        volume_mm3=float(volumes.sum()),
        min_tet_volume_mm3=float(volumes.min()),
        min_dihedral_deg=float(angles.min()),
        max_dihedral_deg=float(angles.max()),
        max_radius_edge=float(radius_edge_ratios(vertices, tets).max()),
        mean_edge_mm=float(edge_lengths(vertices, tets).mean()),
    )
