"""Mesh topology on analytic bodies: cube, tetrahedron, open box, two disjoint cubes, a flipped face, a void."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.meshing.topology import (
    describe_surface,
    drop_unused_vertices,
    edge_uses,
    face_areas,
    is_watertight,
    is_winding_consistent,
    mesh_topology,
    signed_volume,
    surface_area,
)

#: Sums over a few faces whose terms are exact in binary (cube) or one rounding each (tetrahedron).
ROUNDOFF = 1e-14

# counter-clockwise seen from outside; vertex index = 4 x + 2 y + z of the unit cube's corners
CUBE_VERTICES = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])
CUBE_FACES = np.array(
    [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
     [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]
)  # fmt: skip
#: The two faces of the cube's top (z = 1: vertices 1, 3, 5, 7).
TOP = [10, 11]
TETRA_VERTICES = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
TETRA_FACES = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def cube(size: float = 1.0, origin=(0.0, 0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    return CUBE_VERTICES * size + np.asarray(origin, float), CUBE_FACES.copy()


def joined(*meshes: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """One mesh of several, vertices renumbered."""
    offsets = np.cumsum([0] + [len(v) for v, _ in meshes])
    faces = [f + o for (_, f), o in zip(meshes, offsets[:-1], strict=True)]
    return np.concatenate([v for v, _ in meshes]), np.concatenate(faces)


def test_cube_volume_area_edges_and_flags():
    v, f = cube(2.0)
    topology = mesh_topology(v, f)
    assert (topology.vertices, topology.faces, topology.edges) == (8, 12, 18)
    assert topology.watertight and topology.winding_consistent and topology.vertex_manifold
    assert (topology.shells, topology.bodies, topology.voids, topology.euler) == (1, 1, 0, 2)
    np.testing.assert_allclose([topology.volume, signed_volume(v, f)], 8.0, rtol=0, atol=ROUNDOFF)
    np.testing.assert_array_equal(face_areas(v, f), np.full(12, 2.0))  # every term is exact in binary
    assert topology.area == surface_area(v, f) == 24.0
    assert is_watertight(f) and is_winding_consistent(f)


def test_tetrahedron_volume_and_area():
    topology = mesh_topology(TETRA_VERTICES, TETRA_FACES)
    assert (topology.edges, topology.euler, topology.shells) == (6, 2, 1)
    np.testing.assert_allclose(topology.volume, 1.0 / 6.0, rtol=0, atol=ROUNDOFF)
    # three right triangles of legs 1 and the equilateral face of side sqrt(2)
    np.testing.assert_allclose(topology.area, 1.5 + np.sqrt(3.0) / 2.0, rtol=0, atol=ROUNDOFF)
    np.testing.assert_allclose(signed_volume(TETRA_VERTICES, TETRA_FACES[:, ::-1]), -1.0 / 6.0, rtol=0, atol=ROUNDOFF)


def test_open_box_has_one_boundary_loop_and_is_not_watertight():
    v, f = cube()
    open_box = np.delete(f, TOP, axis=0)
    topology = mesh_topology(v, open_box)
    assert not topology.watertight and not topology.winding_consistent and not topology.vertex_manifold
    assert (topology.edges, topology.area) == (17, 5.0)  # the top's diagonal is gone, its four sides stay
    assert not is_watertight(open_box) and not is_winding_consistent(open_box)
    edges, uses = edge_uses(open_box, len(v))
    assert len(edges) == 17 and np.all(edges[:, 0] < edges[:, 1])
    assert sorted(map(tuple, edges[uses == 1].tolist())) == [(1, 3), (1, 5), (3, 7), (5, 7)]
    info = describe_surface(v, open_box)
    assert (info.boundary_edges, info.boundary_loops, info.nonmanifold_edges, info.capped) == (4, 1, 0, False)
    np.testing.assert_array_equal(info.bounds, [[0, 0, 0], [1, 1, 1]])


def test_two_disjoint_cubes_are_two_bodies():
    v, f = joined(cube(), cube(2.0, origin=(5.0, 0.0, 0.0)))
    topology = mesh_topology(v, f)
    assert topology.watertight and topology.winding_consistent and topology.vertex_manifold
    assert (topology.shells, topology.bodies, topology.voids, topology.euler) == (2, 2, 0, 4)
    np.testing.assert_allclose(topology.shell_volumes, [1.0, 8.0], rtol=0, atol=ROUNDOFF)  # by lowest vertex
    np.testing.assert_allclose(topology.volume, 9.0, rtol=0, atol=ROUNDOFF)
    assert topology.area == 30.0
    info = describe_surface(v, f)
    assert info.capped and info.boundary_loops == 0 and info.vertices == 16


def test_a_cube_with_an_inward_wound_cube_inside_is_a_body_with_a_void():
    inner_v, inner_f = cube(1.0, origin=(0.5, 0.5, 0.5))
    v, f = joined(cube(2.0), (inner_v, inner_f[:, ::-1]))
    topology = mesh_topology(v, f)
    assert (topology.shells, topology.bodies, topology.voids, topology.euler) == (2, 1, 1, 4)
    np.testing.assert_allclose(topology.shell_volumes, [8.0, -1.0], rtol=0, atol=ROUNDOFF)
    np.testing.assert_allclose(topology.volume, 7.0, rtol=0, atol=ROUNDOFF)
    assert topology.area == 30.0


def test_one_flipped_face_is_watertight_but_not_consistently_wound():
    v, f = cube()
    f[3] = f[3, ::-1]
    topology = mesh_topology(v, f)
    assert topology.watertight and not topology.winding_consistent and not topology.vertex_manifold
    assert is_watertight(f) and not is_winding_consistent(f)
    assert topology.edges == 18 and topology.area == 6.0


def test_cubes_sharing_a_corner_are_not_vertex_manifold():
    v, f = joined(cube(), cube(origin=(1.0, 1.0, 1.0)))
    f = np.where(f == 8, 7, f)  # the second cube's corner 0 is the first cube's corner 7
    topology = mesh_topology(v, f)
    assert topology.watertight and topology.winding_consistent and not topology.vertex_manifold
    # one shell (joined at the corner) of two cubes' volume; V - E + F = 15 - 36 + 24
    assert (topology.vertices, topology.shells, topology.bodies, topology.euler) == (15, 1, 1, 3)
    np.testing.assert_allclose(topology.volume, 2.0, rtol=0, atol=ROUNDOFF)


def test_unmerged_triangle_soup_is_open_and_three_faces_on_an_edge_are_non_manifold():
    v, f = cube()
    soup = np.arange(3 * len(f)).reshape(-1, 3)
    assert not is_watertight(soup) and not describe_surface(v[f].reshape(-1, 3), soup).capped
    # a fin: a third face on the edge 0-1, out to a new vertex
    with_fin, fin = np.vstack([v, [[0.0, -1.0, 0.5]]]), np.vstack([f, [[0, 1, 8]]])
    info = describe_surface(with_fin, fin)
    assert (info.nonmanifold_edges, info.boundary_edges, info.boundary_loops, info.capped) == (1, 2, 1, False)
    assert not mesh_topology(with_fin, fin).watertight


def test_unused_vertices_are_not_counted_and_bad_arrays_are_refused():
    v, f = cube()
    padded = np.vstack([[[100.0, 100.0, 100.0]], v])
    topology = mesh_topology(padded, f + 1)
    assert (topology.vertices, topology.euler, topology.shells) == (8, 2, 1)
    np.testing.assert_allclose(topology.volume, 1.0, rtol=0, atol=ROUNDOFF)
    with pytest.raises(ValueError, match=r"expected vertices \(V, 3\) and faces \(F, 3\), got \(8, 2\)"):
        mesh_topology(v[:, :2], f)
    with pytest.raises(ValueError, match="faces refer to vertices that do not exist"):
        mesh_topology(v, f + 1)


def test_dropping_unused_vertices_keeps_the_faces_on_the_same_points():
    v, f = cube()
    padded = np.vstack([[[9.0, 9.0, 9.0]], v[:4], [[8.0, 8.0, 8.0]], v[4:]])
    renumbered = np.where(f < 4, f + 1, f + 2)
    kept, faces = drop_unused_vertices(padded, renumbered)
    np.testing.assert_array_equal(kept, v)
    np.testing.assert_array_equal(faces, f)


def _row_cross(u, v):
    """The (F, 3) cross product the figures were first computed with: np.cross's products in its order."""
    return np.stack([u[:, j] * v[:, k] - u[:, k] * v[:, j] for j, k in ((1, 2), (2, 0), (0, 1))], axis=-1)


def test_volume_area_and_edge_scale_keep_the_bits_of_the_row_wise_formulas():
    """On (3, F) coordinate rows, the figures are those of (F, 3, 3) corners and np.einsum, to the last bit."""
    from softdesign.geometry.edges import corner_planes
    from softdesign.meshing.checks import _mean_squared_edge

    rng = np.random.default_rng(11)
    vertices, faces = joined(*[cube(rng.uniform(0.5, 3.0), rng.normal(0.0, 40.0, 3)) for _ in range(40)])
    vertices = vertices + rng.normal(0.0, 0.01, vertices.shape)  # rounding in every term
    found = mesh_topology(vertices, faces)
    corners = vertices[faces]
    centered = (vertices - vertices.mean(axis=0))[faces]
    tet = np.einsum("ij,ij->i", centered[:, 0], _row_cross(centered[:, 1], centered[:, 2])) / 6.0
    assert found.shell_volumes.tobytes() == np.bincount(np.repeat(np.arange(40), 12), weights=tet).tobytes()
    normal = _row_cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    assert found.face_areas.tobytes() == (0.5 * np.sqrt(np.sum(normal * normal, axis=-1))).tobytes()
    edges = np.stack([np.sum((corners[:, b] - corners[:, a]) ** 2, axis=-1) for a, b in ((0, 1), (1, 2), (2, 0))], -1)
    assert _mean_squared_edge(*corner_planes(vertices, faces)) == float(np.mean(edges))
