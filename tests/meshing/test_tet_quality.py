"""Tetrahedral mesh figures on known answers: the regular tetrahedron, a cube cut into six, a sliver, orientation."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from softdesign.meshing.topology import mesh_topology, signed_volume
from softdesign.meshing.volume_mesh.tet_quality import (
    boundary_faces,
    dihedral_angles,
    radius_edge_ratios,
    tet_measures,
    tet_quality,
    tet_volumes,
)

#: Closed-form figures computed in float64: a few ulps of their magnitude.
EXACT = 1e-12

REGULAR = np.array([[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]])


def positive(points: np.ndarray) -> np.ndarray:
    """The tetrahedron (0, 1, 2, 3), or (0, 2, 1, 3) when that is the positive order."""
    a, b, c = points[1] - points[0], points[2] - points[0], points[3] - points[0]
    return np.array([[0, 1, 2, 3]] if np.dot(a, np.cross(b, c)) > 0 else [[0, 2, 1, 3]])


def cube_tets() -> tuple[np.ndarray, np.ndarray]:
    """The unit cube as six tetrahedra around its diagonal 0-7 (Kuhn's triangulation), each made positive."""
    corners = np.array(list(itertools.product((0.0, 1.0), repeat=3)))
    tets = []
    for order in itertools.permutations(range(3)):
        path = [0]
        for axis in order:
            path.append(path[-1] + (4, 2, 1)[axis])
        t = np.array(path)
        tets.append(t[positive(corners[t])[0]])
    return corners, np.array(tets)


def test_regular_tetrahedron_known_answers():
    tets = positive(REGULAR)
    edge = np.sqrt(8.0)
    np.testing.assert_allclose(tet_volumes(REGULAR, tets), [edge**3 / (6 * np.sqrt(2))], rtol=0, atol=EXACT)
    np.testing.assert_allclose(dihedral_angles(REGULAR, tets), np.full((1, 6), np.arccos(1 / 3)), rtol=0, atol=EXACT)
    np.testing.assert_allclose(radius_edge_ratios(REGULAR, tets), [np.sqrt(6) / 4], rtol=0, atol=EXACT)


def test_right_corner_tetrahedron_angles():
    points = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    angles = np.degrees(dihedral_angles(points, positive(points)))[0]
    # edges from the right corner meet at 90 degrees; the other three at arccos(1/sqrt(3))
    np.testing.assert_allclose(angles, [90, 90, 90, *[np.degrees(np.arccos(1 / np.sqrt(3)))] * 3], rtol=0, atol=1e-10)
    # circumradius sqrt(3)/2 (half the cube diagonal), shortest edge 1
    np.testing.assert_allclose(radius_edge_ratios(points, positive(points)), [np.sqrt(3) / 2], rtol=0, atol=EXACT)


def test_cube_volumes_and_boundary():
    corners, tets = cube_tets()
    volumes = tet_volumes(corners, tets)
    np.testing.assert_allclose(volumes, np.full(6, 1 / 6), rtol=0, atol=EXACT)
    faces = boundary_faces(tets)
    topology = mesh_topology(corners, faces)
    assert len(faces) == 12 and topology.watertight and topology.winding_consistent
    np.testing.assert_allclose(signed_volume(corners, faces), 1.0, rtol=0, atol=EXACT)
    # the order of the tetrahedra does not change the boundary
    np.testing.assert_array_equal(boundary_faces(tets[::-1]), faces)


def test_a_flipped_tetrahedron_has_negative_volume_and_the_same_angles():
    tets = positive(REGULAR)
    flipped = tets[:, [1, 0, 2, 3]]
    assert tet_volumes(REGULAR, flipped)[0] < 0
    np.testing.assert_allclose(dihedral_angles(REGULAR, flipped), dihedral_angles(REGULAR, tets), rtol=0, atol=EXACT)
    assert tet_quality(REGULAR, flipped).min_tet_volume_mm3 < 0


def test_a_sliver_shows_in_the_angles_and_not_in_the_radius_edge_ratio():
    # four nearly coplanar points: a square lifted alternately by +-h; why both figures are reported
    h = 1e-3
    points = np.array([[0.0, 0, h], [1, 0, -h], [1, 1, h], [0, 1, -h]])
    q = tet_quality(points, positive(points))
    assert q.min_dihedral_deg < 1.0 and q.max_dihedral_deg > 179.0
    # circumradius about the square's half diagonal sqrt(2)/2, shortest edge about 1 (h^2 terms: rel 1e-3)
    assert q.max_radius_edge == pytest.approx(np.sqrt(2) / 2, rel=1e-3)


def test_a_needle_has_a_large_radius_edge_ratio():
    # the right-corner tetrahedron with its apex pulled to within e of the corner along the diagonal
    e = 1e-3
    points = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [e, e, e]])
    assert radius_edge_ratios(points, positive(points))[0] > 0.5 / (np.sqrt(3) * e)


def test_bad_shapes_are_refused():
    with pytest.raises(ValueError, match=r"tets must be \(T, 4\)"):
        tet_volumes(REGULAR, np.array([[0, 1, 2]]))
    with pytest.raises(ValueError, match="outside"):
        tet_volumes(REGULAR, np.array([[0, 1, 2, 4]]))
    with pytest.raises(ValueError, match="at least one"):
        tet_quality(REGULAR, np.zeros((0, 4), np.int64))


def test_the_one_pass_measures_are_the_separate_figures():
    """tet_measures (the swept mesher's figures) against tet_volumes, dihedral_angles and radius_edge_ratios on
    random tetrahedra of either orientation, a regular one, slivers and needles: the same to round-off; a flat
    one gives an infinite radius-edge ratio, as radius_edge_ratios does."""
    rng = np.random.default_rng(7)
    points = np.concatenate([rng.normal(size=(400, 3)), REGULAR, [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]],
                             [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 1e-6]], [[0, 0, 0], [1e-3, 0, 0], [0, 1e-3, 0],
                                                                               [0, 0, 50.0]]])
    tets = np.arange(len(points)).reshape(-1, 4)
    volumes, least, largest, ratio = tet_measures(points, tets)
    with np.errstate(invalid="ignore"):  # the flat one's normals are 0 there
        angles = dihedral_angles(points, tets)
    np.testing.assert_allclose(volumes, tet_volumes(points, tets), rtol=1e-12, atol=1e-15)
    finite = np.abs(volumes) > 1e-12
    # arccos near 1 amplifies the cosine's round-off to about 1e-16 / angle: 1e-10 rad for the 1e-6 rad sliver
    np.testing.assert_allclose(least[finite], angles.min(axis=1)[finite], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(largest[finite], angles.max(axis=1)[finite], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(ratio[finite], radius_edge_ratios(points, tets)[finite], rtol=1e-9)
    assert (volumes < 0).any() and (volumes > 0).any()
    assert np.isinf(ratio[~finite]).all() and np.isinf(radius_edge_ratios(points, tets)[~finite]).all()
    np.testing.assert_allclose(least[100], np.arccos(1 / 3), rtol=0, atol=EXACT)  # the regular one
