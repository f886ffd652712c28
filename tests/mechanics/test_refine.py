"""Red refinement of a section's mesh: volumes, walls, cavities, labels and the base carried exactly."""

from __future__ import annotations

import functools

import numpy as np
import pytest

from softdesign.errors import MeshError
from softdesign.mechanics.quadratic import quadratic_mesh
from softdesign.mechanics.refine import MAX_LEVELS, refine_section, refine_tets
from softdesign.mechanics.section import SectionMesh, check_section
from softdesign.mechanics.tets import boundary_faces, make_tet_mesh
from softdesign.types import FloatArray, IntArray
from tests.helpers.fe_meshes import quarter_tube, three_chamber_section

#: Exact in exact arithmetic; floating point sums of 8 (or 4) terms.
RTOL = 1e-12
SHAPE = {"radius": 5.0, "distance": 2.5, "chamber_diameter": 2.0, "length": 20.0, "end_wall": 1.5}


@functools.cache
def _coarse() -> SectionMesh:
    return three_chamber_section(size=2.0, **SHAPE)


@functools.cache
def _fine() -> SectionMesh:
    return refine_section(_coarse())


def _volumes(points: FloatArray, tets: IntArray) -> FloatArray:
    c = points[tets]
    return np.einsum("ei,ei->e", c[:, 1] - c[:, 0], np.cross(c[:, 2] - c[:, 0], c[:, 3] - c[:, 0])) / 6.0


def _area_vectors(points: FloatArray, faces: IntArray) -> FloatArray:
    c = points[faces]
    return 0.5 * np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0])


def _enclosed(points: FloatArray, faces: IntArray) -> float:
    """Volume enclosed by closed triangles wound out of it, mm^3 (divergence theorem)."""
    c = points[faces]
    return float(np.einsum("fi,fi->", c[:, 0], np.cross(c[:, 1], c[:, 2])) / 6.0)


def _cyclic(faces: IntArray) -> set[tuple[int, ...]]:
    """Each oriented triangle as its rotation starting at its smallest node."""
    start = np.argmin(faces, axis=1)[:, None]
    return {tuple(f) for f in np.take_along_axis(faces, (start + np.arange(3)) % 3, axis=1)}


@pytest.mark.parametrize("mesh", ["section", "quarter tube"])
def test_children_are_positive_and_fill_their_parent_exactly(mesh: str) -> None:
    if mesh == "section":
        points, tets = _coarse().points, _coarse().tets
    else:
        points, tets = quarter_tube(1.0, 2.5, 4.0, (2, 4, 3))
    fine, children, edges = refine_tets(points, tets)
    parent, child = _volumes(points, tets), _volumes(fine, children)
    assert children.shape == (8 * len(tets), 4) and len(fine) == len(points) + len(edges)
    assert child.min() > 0
    np.testing.assert_allclose(child.reshape(-1, 8).sum(axis=1), parent, rtol=RTOL)
    # the corner children are the parent halved: an eighth of its volume each, so the inner four share a half
    np.testing.assert_allclose(child.reshape(-1, 8)[:, :4], np.repeat(parent[:, None] / 8, 4, axis=1), rtol=1e-10)
    make_tet_mesh(fine, children)  # every node used, none degenerate


def test_the_inner_octahedron_is_cut_along_its_shortest_diagonal() -> None:
    points, tets = _coarse().points, _coarse().tets
    fine, children, _ = refine_tets(points, tets)
    inner = children.reshape(-1, 8, 4)[:, 4:]  # (E, 4, 4): the diagonal is the edge all four share
    shared = [set(map(int, e[0])).intersection(*(set(map(int, t)) for t in e[1:])) for e in inner]
    assert all(len(s) == 2 for s in shared)
    chosen = np.array([np.linalg.norm(np.subtract(*fine[sorted(s)])) for s in shared])
    corners = points[tets]
    diagonals = np.stack([np.linalg.norm(0.5 * (corners[:, a] + corners[:, b] - corners[:, c] - corners[:, d]), axis=1)
                          for a, b, c, d in ((0, 1, 2, 3), (0, 2, 1, 3), (0, 3, 1, 2))], axis=1)
    np.testing.assert_allclose(chosen, diagonals.min(axis=1), rtol=1e-12)


def test_walls_keep_area_orientation_chamber_and_cavity_volume() -> None:
    coarse, fine = _coarse(), _fine()
    np.testing.assert_array_equal(fine.face_chamber, np.repeat(coarse.face_chamber, 4))
    parent = _area_vectors(coarse.points, coarse.wall_faces)
    child = _area_vectors(fine.points, fine.wall_faces).reshape(-1, 4, 3)
    # same plane, same winding: each child's area vector is a quarter of its parent's
    np.testing.assert_allclose(child, np.repeat(parent[:, None] / 4, 4, axis=1), rtol=1e-9, atol=1e-12)
    for c in range(coarse.chamber_count):
        area = [np.linalg.norm(_area_vectors(s.points, s.wall_faces[s.face_chamber == c]), axis=1).sum()
                for s in (coarse, fine)]
        cavity = [_enclosed(s.points, s.wall_faces[s.face_chamber == c]) for s in (coarse, fine)]
        assert cavity[0] > 0  # wound out of the chamber: the enclosed volume is positive
        np.testing.assert_allclose(area[1], area[0], rtol=RTOL)
        np.testing.assert_allclose(cavity[1], cavity[0], rtol=RTOL)
    # the refined walls are boundary faces of the refined tets, wound out of the chamber (into the material)
    assert _cyclic(fine.wall_faces[:, [0, 2, 1]]) <= _cyclic(boundary_faces(fine.tets))


def test_base_levels_and_centerline_are_carried() -> None:
    coarse, fine = _coarse(), refine_section(_coarse(), 2)
    check_section(fine)
    # the straight section's base is its z = 0 face and a node's level is its z
    np.testing.assert_array_equal(fine.base, np.isclose(fine.points[:, 2], 0.0, atol=1e-12))
    np.testing.assert_allclose(fine.node_l, fine.points[:, 2], atol=1e-12)
    assert int(fine.base.sum()) > int(coarse.base.sum())
    np.testing.assert_array_equal(fine.centerline, coarse.centerline)
    np.testing.assert_array_equal(fine.chamber_angles, coarse.chamber_angles)
    # one refinement's new nodes are the quadratic mesh's midpoints, in the same order
    np.testing.assert_array_equal(_fine().points, quadratic_mesh(check_section(coarse)).points)


def test_levels_are_bounded_and_foreign_wall_faces_refused() -> None:
    for levels in (0, MAX_LEVELS + 1):
        with pytest.raises(ValueError, match="levels must be"):
            refine_section(_coarse(), levels)
    coarse = _coarse()
    # a wall face at the far end cap (z = 18.5 mm) given a base node (z = 0): no tetrahedron has that side
    far = int(np.argmax(coarse.points[coarse.wall_faces, 2].min(axis=1)))
    faces = coarse.wall_faces.copy()
    faces[far, 2] = int(np.flatnonzero(coarse.base)[0])
    bad = SectionMesh(coarse.points, coarse.tets, coarse.base, faces, coarse.face_chamber, coarse.centerline,
                      coarse.node_l, coarse.chamber_angles)
    with pytest.raises(MeshError, match="no edge of the tetrahedra"):
        refine_section(bad)
