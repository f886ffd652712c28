"""Small structured tetrahedral meshes for the finite-element tests: a quarter tube, hexahedra split into tets.

Each hexahedron of an (i, j, k) grid is split into the six tetrahedra of
Kuhn's triangulation (all along the diagonal from corner 000 to 111), which
is conforming between neighbours because every hexahedron is split the same
way in index space; elements the mapping turns over are re-wound.
"""

from __future__ import annotations

import itertools

import numpy as np

from softdesign.mechanics.section import SectionMesh
from softdesign.mechanics.tets import boundary_faces
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


def symmetric_disc_with_holes(radius: float, distance: float, hole_radius: float, first_angle: float, size: float,
                              ring_turn: float = 0.0, ring_count: int = 0) -> tuple[FloatArray, IntArray, IntArray]:
    """A disc triangulated with three-fold symmetry, three holes at ``first_angle + 0, 120, 240`` rad.

    One 120-degree sector's nodes (outer circle, its hole's circle and centre,
    a hexagonal lattice of edge ``size`` kept half an edge clear of the circles, jittered by a tenth of it)
    are rotated twice; node 0 is the centre and node ``1 + 3 k + s`` the k-th
    node of sector s, so any order of nodes by index is the same in every
    sector.  The Delaunay triangulation of this point set is checked to map onto
    itself under the rotation.  Returns points (P, 2) mm, triangles (T, 3)
    counter-clockwise, and each triangle's hole (T,), -1 for material.  ``ring_turn`` turns each hole's
    nodes by that fraction of their spacing: off the sector's mirror line, so that a coarse lattice (few
    jittered nodes between the circles) has no four co-circular nodes for Delaunay to split either way.
    ``ring_count`` nodes on each hole (0: by ``size``, at least 8).
    """
    from scipy.spatial import Delaunay

    hole = distance * np.array([np.cos(first_angle), np.sin(first_angle)])
    count = 3 * max(4, int(np.ceil(2 * np.pi * radius / size / 3)))
    outer = radius * _unit(first_angle - np.pi / 3 + (np.arange(count // 3) + 0.5) * 2 * np.pi / count)
    ring_count = ring_count or max(8, int(np.ceil(2 * np.pi * hole_radius / size)))
    ring = hole + hole_radius * _unit(first_angle + 2 * np.pi * (np.arange(ring_count) + ring_turn) / ring_count)
    span = np.arange(-int(radius / size) - 2, int(radius / size) + 3)
    i, j = (g.ravel() for g in np.meshgrid(span, span, indexing="ij"))
    lattice = size * np.stack([i + 0.5 * j, j * np.sqrt(3) / 2], axis=1)
    r = np.hypot(lattice[:, 0], lattice[:, 1])
    angle = np.mod(np.arctan2(lattice[:, 1], lattice[:, 0]) - (first_angle - np.pi / 3 + 1e-7), 2 * np.pi)
    keep = (r > 0.5 * size) & (r < radius - 0.5 * size) & (angle < 2 * np.pi / 3)
    keep &= np.abs(np.hypot(*(lattice - hole).T) - hole_radius) > 0.5 * size
    # a fixed jitter of the lattice: a regular lattice has co-circular nodes, whose Delaunay triangles are a tie
    jitter = 0.1 * size * np.random.default_rng(0).uniform(-1, 1, (int(keep.sum()), 2))
    sector = np.concatenate([outer, ring, hole[None], lattice[keep] + jitter])
    copies = [sector @ _rotation(2 * np.pi * s / 3).T for s in range(3)]
    points = np.concatenate([np.zeros((1, 2)), np.stack(copies, axis=1).reshape(-1, 2)])
    triangles = Delaunay(points).simplices.astype(np.int64)
    e1, e2 = points[triangles[:, 1]] - points[triangles[:, 0]], points[triangles[:, 2]] - points[triangles[:, 0]]
    flip = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] < 0
    triangles[flip] = triangles[flip][:, [0, 2, 1]]
    _check_three_fold(triangles)
    centroids = points[triangles].mean(axis=1)
    labels = np.full(len(triangles), -1, np.int64)
    for h in range(3):
        centre = _rotation(2 * np.pi * h / 3) @ hole
        labels[np.hypot(*(centroids - centre).T) < hole_radius] = h
    return points, triangles, labels


def _unit(angles: FloatArray) -> FloatArray:
    return np.stack([np.cos(angles), np.sin(angles)], axis=1)


def _rotation(angle: float) -> FloatArray:
    return np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])


def _check_three_fold(triangles: IntArray) -> None:
    """Raise when the triangulation does not map onto itself, or a triangle holds two copies of one node."""
    copy_of = np.where(triangles == 0, -1, (triangles - 1) // 3)
    turned = np.where(triangles == 0, 0, 1 + 3 * copy_of + ((triangles - 1) % 3 + 1) % 3)
    if {tuple(t) for t in np.sort(turned, axis=1)} != {tuple(t) for t in np.sort(triangles, axis=1)}:
        raise AssertionError("the Delaunay triangulation is not three-fold symmetric")
    for a, b in ((0, 1), (1, 2), (0, 2)):
        if np.any((copy_of[:, a] == copy_of[:, b]) & (copy_of[:, a] >= 0)):
            raise AssertionError("a triangle holds two rotated copies of one node")


def extrude(points2: FloatArray, triangles: IntArray, z: FloatArray, alternate: bool = False
            ) -> tuple[FloatArray, IntArray]:
    """Points (P (n+1), 3) and tets (3 T n, 4) of the triangles swept through the levels ``z`` (n+1,).

    Each prism splits into three tetrahedra by its corners' global order (the
    diagonal of each side runs from the lower-numbered bottom corner to the
    higher-numbered top one), so neighbouring prisms share their diagonals.
    Tets are ordered level by level, triangle by triangle.
    """
    P = len(points2)
    points = np.concatenate([np.column_stack([points2, np.full(P, zk)]) for zk in z])
    ordered = np.sort(triangles, axis=1)
    tets = []
    for level in range(len(z) - 1):
        # odd levels split by the reversed order: the split of a prism is chiral, alternating it halves the
        # bending-twist coupling a one-handed mesh carries
        a, b, c = (ordered if level % 2 == 0 or not alternate else ordered[:, ::-1]).T
        lo, hi = level * P, (level + 1) * P
        tets.append(np.stack([
            np.stack([a + lo, b + lo, c + lo, c + hi], axis=1),
            np.stack([a + lo, b + lo, b + hi, c + hi], axis=1),
            np.stack([a + lo, a + hi, b + hi, c + hi], axis=1),
        ], axis=1).reshape(-1, 4))
    return points, oriented(points, np.concatenate(tets))


def three_chamber_section(radius: float, distance: float, chamber_diameter: float, length: float,
                          end_wall: float, size: float, first_angle: float = np.pi / 2,
                          axial_size: float | None = None, ring_turn: float = 0.0, ring_count: int = 0
                          ) -> SectionMesh:
    """A straight section (cylinder along +z) with closed cylindrical chambers, as a SectionMesh.

    The chambers' axes are at ``distance`` mm from the centerline at ``first_angle`` + 0, 120, 240 degrees;
    each runs from ``end_wall`` to ``length - end_wall``.  ``size`` is the target
    edge, mm (cross-section, and levels unless ``axial_size`` is given); ``ring_turn`` and ``ring_count`` as in
    :func:`symmetric_disc_with_holes`.  For the tests only: the pipeline's sections come from the parametric
    volume mesher.
    """
    angles = first_angle + np.array([0.0, 2 * np.pi / 3, 4 * np.pi / 3])
    p2, tri, labels = symmetric_disc_with_holes(radius, distance, chamber_diameter / 2, first_angle, size, ring_turn,
                                                ring_count)
    stops = [0.0, end_wall, length - end_wall, length]
    step = size if axial_size is None else axial_size
    runs = [np.linspace(a, b, max(2, round((b - a) / step) + 1)) for a, b in zip(stops[:-1], stops[1:], strict=True)]
    z = np.unique(np.concatenate(runs))
    points, tets = extrude(p2, tri, z)
    level_mid = 0.5 * (z[:-1] + z[1:])
    inside = (level_mid > end_wall) & (level_mid < length - end_wall)
    hollow = np.repeat(((labels[None, :] >= 0) & inside[:, None]).ravel(), 3)  # tets: level, triangle, 3 each
    kept = tets[~hollow]
    used = np.unique(kept)
    renumber = np.full(len(points), -1, np.int64)
    renumber[used] = np.arange(len(used))
    points, kept = points[used], renumber[kept]
    faces = boundary_faces(kept)
    walls = faces[~_outer_skin(points, faces, radius, length)][:, [0, 2, 1]]
    centroid = points[walls].mean(axis=1)[:, :2]
    centres = distance * _unit(angles)
    chamber = np.argmin(np.linalg.norm(centroid[:, None, :] - centres[None], axis=2), axis=1)
    centerline = np.column_stack([np.zeros(len(z)), np.zeros(len(z)), z])
    return SectionMesh(points, kept, np.isclose(points[:, 2], 0.0), walls, chamber.astype(np.int64),
                       centerline, points[:, 2].copy(), angles, np.full(3, chamber_diameter / 2))


def _outer_skin(points: FloatArray, faces: IntArray, radius: float, length: float) -> np.ndarray:
    """Faces (F,) bool on the body's outside: all corners on the outer circle, or on an end plane."""
    corners = points[faces]
    on_circle = np.all(np.hypot(corners[..., 0], corners[..., 1]) > radius - 1e-9, axis=1)
    on_end = np.all(np.isclose(corners[..., 2], 0.0), axis=1) | np.all(np.isclose(corners[..., 2], length), axis=1)
    return on_circle | on_end
