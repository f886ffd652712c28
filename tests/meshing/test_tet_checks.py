"""Checks of a tetrahedral mesh: the volume, an empty chamber, inverted tetrahedra; points inside a closed surface."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import trimesh

from softdesign.errors import MeshError
from softdesign.meshing.enclosed import points_inside
from softdesign.meshing.volume_mesh.tet_checks import TET_VOLUME_RTOL, check_tet_mesh, expected_tets
from softdesign.meshing.volume_mesh.tet_quality import tet_volumes

#: Sums of 162 exact sixths: float64 rounding only.
EXACT = 1e-12


def block_tets(n: int = 3) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """An n x n x n block of unit cubes, six positive tetrahedra each; also each tetrahedron's cube index (i, j, k)."""
    grid = np.array(list(itertools.product(range(n + 1), repeat=3)), float)
    index = {tuple(p): i for i, p in enumerate(grid.astype(int).tolist())}
    tets, cubes = [], []
    for cube in itertools.product(range(n), repeat=3):
        for order in itertools.permutations(range(3)):
            corner = [np.array(cube)]
            for axis in order:
                corner.append(corner[-1] + np.eye(3, dtype=int)[axis])
            t = [index[tuple(c.tolist())] for c in corner]
            a, b, c = (grid[t[k]] - grid[t[0]] for k in (1, 2, 3))
            tets.append(t if np.dot(a, np.cross(b, c)) > 0 else [t[0], t[2], t[1], t[3]])
            cubes.append(cube)
    return grid, np.array(tets, np.int64), np.array(cubes)


def middle_chamber() -> tuple[np.ndarray, np.ndarray]:
    """The closed surface of the middle unit cube of a 3-block, shrunk by 1e-3 (off the grid's faces), outwards."""
    box = trimesh.creation.box(extents=[1 - 2e-3] * 3)
    box.apply_translation([1.5, 1.5, 1.5])
    return np.asarray(box.vertices), np.asarray(box.faces, np.int64)


def test_a_full_block_passes_and_its_figures_are_known():
    points, tets, _ = block_tets()
    figures = check_tet_mesh(points, tets, 27.0, None, "block")
    assert figures["tets"] == 162 and figures["chamber_centroids_inside"] is None
    np.testing.assert_allclose(figures["volume_mm3"], 27.0, rtol=0, atol=EXACT)
    assert abs(figures["volume_rel_error"]) <= EXACT
    # Kuhn's tetrahedra: dihedral angles of 45, 60 and 90 degrees; circumradius sqrt(3)/2 over an edge of 1
    np.testing.assert_allclose([figures["min_dihedral_deg"], figures["max_dihedral_deg"]], [45.0, 90.0], atol=1e-9)
    np.testing.assert_allclose(figures["max_radius_edge"], np.sqrt(3) / 2, rtol=0, atol=EXACT)
    assert figures["boundary_watertight"] and figures["boundary_shells"] == 1 and figures["boundary_euler"] == 2


def test_a_volume_off_by_more_than_the_tolerance_is_refused():
    points, tets, _ = block_tets()
    body = 27.0 / (1.0 + 1.5 * TET_VOLUME_RTOL)
    with pytest.raises(MeshError, match=r"block: the tetrahedra hold 27.00 mm3, \+1.50 % of the body's .* within 1 %"):
        check_tet_mesh(points, tets, body, None, "block")
    # within the tolerance it passes
    check_tet_mesh(points, tets, 27.0 / (1.0 + 0.5 * TET_VOLUME_RTOL), None, "block")


def test_tetrahedra_in_the_chamber_are_found_and_an_empty_chamber_passes():
    points, tets, cubes = block_tets()
    middle = np.all(cubes == 1, axis=1)
    with pytest.raises(MeshError, match="6 of 162 tetrahedra have their centroid inside the chamber"):
        check_tet_mesh(points, tets, 27.0, middle_chamber(), "block")
    hollow = tets[~middle]
    figures = check_tet_mesh(points, hollow, 26.0, middle_chamber(), "hollow block")
    assert figures["chamber_centroids_inside"] == 0
    # the boundary: the outer box and the chamber's, two shells (Euler 2 + 2)
    assert figures["boundary_shells"] == 2 and figures["boundary_euler"] == 4


def test_an_inverted_tetrahedron_is_refused():
    points, tets, _ = block_tets(1)
    flipped = tets.copy()
    flipped[0, [0, 1]] = flipped[0, [1, 0]]
    assert tet_volumes(points, flipped)[0] < 0
    with pytest.raises(MeshError, match=r"a tetrahedron has volume -0.167 mm3 \(inverted or flat\)"):
        check_tet_mesh(points, flipped, 2.0 / 3.0, None, "cube")


def test_expected_tets_of_a_regular_tetrahedron():
    # one regular tetrahedron of edge s has volume s^3 / (6 sqrt 2)
    s = 2.0
    assert expected_tets(s**3 / (6 * np.sqrt(2)), s) == pytest.approx(1.0, rel=1e-12)


def test_points_inside_a_sphere_and_an_open_surface_refused():
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=10.0)
    vertices, faces = np.asarray(sphere.vertices), np.asarray(sphere.faces)
    rng = np.random.default_rng(7)
    points = rng.uniform(-12.0, 12.0, (2000, 3))
    r = np.linalg.norm(points, axis=1)
    # away from the faceted surface (inscribed radius of the 1280-face icosphere > 9.9 mm)
    clear = (r < 9.8) | (r > 10.1)
    got = points_inside(points[clear], vertices, faces, "sphere")
    np.testing.assert_array_equal(got, r[clear] < 9.8)
    with pytest.raises(MeshError, match="open: the surface is not closed"):
        points_inside(points, vertices, faces[1:], "open")


def test_a_size_asking_for_too_many_tetrahedra_is_refused_with_the_smallest_that_fits():
    from softdesign.errors import ConfigError
    from softdesign.limits.volume import MAX_VOLUME_TETS
    from softdesign.pipeline.stages.volume_mesh import _check_count

    volume = 4313.0  # the demo's body, mm^3
    with pytest.raises(ConfigError, match=r"size_mm: 0.1 mm asks for about 3.66e\+07 tetrahedra .* >= 0.333 mm"):
        _check_count(volume, 0.1, 0.0)
    # the size it names fits
    least = 0.333
    assert expected_tets(volume, least) <= MAX_VOLUME_TETS
    _check_count(volume, least, 0.0)
