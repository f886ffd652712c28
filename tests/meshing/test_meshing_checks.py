"""Mesh checks on meshes with known answers: cube, nested void, torus, bow-tie, sliver, wrong volume."""

from __future__ import annotations

import json

import numpy as np
import pytest

from softdesign.errors import MeshError
from softdesign.meshing.checks import Expectation, check_solid, inspect_mesh
from softdesign.meshing.tessellate import sweep_from_sections, tessellate
from softdesign.meshing.volume import integrate_body, polygon_area_ratio
from tests.helpers.bodies import Body, straight_line

#: Sums over a few faces of exact coordinates, mm^3 or mm^2.
ROUNDOFF = 1e-12

CUBE_VERTICES = np.array([[x, y, z] for x in (0.0, 2.0) for y in (0.0, 2.0) for z in (0.0, 2.0)])
# counter-clockwise seen from outside; vertex index = 4 x + 2 y + z (coordinates / 2)
CUBE_FACES = np.array(
    [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
     [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]
)  # fmt: skip


def _torus_grid(n: int = 12, m: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """A closed quad-grid torus (genus 1), R = 5, r = 1."""
    u, v = np.meshgrid(2 * np.pi * np.arange(n) / n, 2 * np.pi * np.arange(m) / m, indexing="ij")
    vertices = np.stack([(5 + np.cos(v)) * np.cos(u), (5 + np.cos(v)) * np.sin(u), np.sin(v)], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    a, b, c, d = i * m + j, ((i + 1) % n) * m + j, ((i + 1) % n) * m + (j + 1) % m, i * m + (j + 1) % m
    return vertices, np.stack([a, b, c, a, c, d], -1).reshape(-1, 3)


def test_cube_known_answers():
    report = inspect_mesh(CUBE_VERTICES, CUBE_FACES)
    assert (report.watertight, report.winding_consistent, report.vertex_manifold) == (True, True, True)
    assert (report.shells, report.bodies, report.voids, report.euler, report.degenerate_faces) == (1, 1, 0, 2, 0)
    np.testing.assert_allclose([report.volume, report.area], [8.0, 24.0], rtol=0, atol=ROUNDOFF)
    check_solid(CUBE_VERTICES, CUBE_FACES, Expectation(volume=8.0))


def test_open_mesh_is_not_watertight_and_is_refused():
    report = inspect_mesh(CUBE_VERTICES, CUBE_FACES[:-1])
    assert not report.watertight and not report.winding_consistent
    with pytest.raises(MeshError, match="not watertight"):
        check_solid(CUBE_VERTICES, CUBE_FACES[:-1], label="q=0.250")


def test_one_flipped_face_breaks_winding():
    faces = CUBE_FACES.copy()
    faces[3] = faces[3, ::-1]
    report = inspect_mesh(CUBE_VERTICES, faces)
    assert report.watertight and not report.winding_consistent
    with pytest.raises(MeshError, match="inconsistent winding"):
        check_solid(CUBE_VERTICES, faces)


def test_inside_out_mesh_has_negative_volume_and_is_refused():
    report = inspect_mesh(CUBE_VERTICES, CUBE_FACES[:, ::-1])
    assert (report.bodies, report.voids) == (0, 1)
    np.testing.assert_allclose(report.volume, -8.0, rtol=0, atol=ROUNDOFF)
    with pytest.raises(MeshError, match=r"volume -8 mm\^3, expected > 0"):
        check_solid(CUBE_VERTICES, CUBE_FACES[:, ::-1])


def test_two_separate_cubes_are_two_bodies():
    vertices = np.vstack([CUBE_VERTICES, CUBE_VERTICES + 5.0])
    faces = np.vstack([CUBE_FACES, CUBE_FACES + 8])
    assert inspect_mesh(vertices, faces).bodies == 2
    with pytest.raises(MeshError, match=r"2 bodies \(2 shells\), expected 1.*Euler characteristic 4, expected 2"):
        check_solid(vertices, faces)


def test_cube_with_an_inward_wound_cube_inside_is_one_body_with_a_void():
    """Outer and inner shell are two spheres: Euler 2 + 2 = 4; one body, one void, volume 8 - 1."""
    vertices = np.vstack([CUBE_VERTICES, 0.5 + CUBE_VERTICES / 2])
    faces = np.vstack([CUBE_FACES, CUBE_FACES[:, ::-1] + 8])
    report = check_solid(vertices, faces, Expectation(volume=7.0, euler=4))
    assert (report.shells, report.bodies, report.voids) == (2, 1, 1)
    np.testing.assert_allclose(report.volume, 7.0, rtol=0, atol=ROUNDOFF)


def test_torus_has_euler_characteristic_zero():
    vertices, faces = _torus_grid()
    report = inspect_mesh(vertices, faces)
    assert (report.watertight, report.winding_consistent, report.euler, report.bodies) == (True, True, 0, 1)


def test_bow_tie_vertex_is_not_manifold():
    """Two tetrahedra sharing one vertex: every edge has two faces, but the shared vertex has two fans."""
    tet = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    tet_faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    vertices = np.vstack([tet, -tet[1:]])
    faces = np.vstack([tet_faces, np.where(tet_faces == 0, 0, tet_faces + 3)])
    report = inspect_mesh(vertices, faces)
    assert report.watertight and report.winding_consistent and not report.vertex_manifold
    with pytest.raises(MeshError, match="separate fans"):
        check_solid(vertices, faces, Expectation(euler=report.euler, bodies=2))


def test_zero_area_sliver_is_counted():
    """A tetrahedron whose edge 0-1 is split by its midpoint m with the sliver (0, 1, m) closing the gap."""
    vertices = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [0.5, 0, 0]])
    # bottom face (0, 2, 1) split into (0, 2, m), (2, 1, m); the sliver (1, 0, m) pairs with (0, 1, 3)
    faces = np.array([[0, 2, 4], [2, 1, 4], [1, 0, 4], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    report = inspect_mesh(vertices, faces)
    assert report.watertight and report.winding_consistent and report.degenerate_faces == 1
    with pytest.raises(MeshError, match="1 degenerate"):
        check_solid(vertices, faces)


def test_volume_check_catches_a_mesh_one_percent_too_large():
    """A tube tessellated 0.5% too wide in radius (1% in volume) against the integral of the true tube."""
    body = Body(straight_line(30.0), 3.0)
    expected = integrate_body(body.field(96), [0, 1]).volume
    good = tessellate(sweep_from_sections(body.sections(11, 96)))
    report = check_solid(good.vertices, good.faces, Expectation(volume=expected))
    np.testing.assert_allclose(report.volume_rel_error, polygon_area_ratio(96) - 1, rtol=0, atol=1e-12)
    wide = tessellate(sweep_from_sections(Body(straight_line(30.0), 3.0 * 1.005).sections(11, 96)))
    with pytest.raises(MeshError, match=r"differs from the integrated .* by \+0\.93\d%, expected within 0\.5%"):
        check_solid(wide.vertices, wide.faces, Expectation(volume=expected), label="q=1.000")


def test_report_is_json_ready():
    data = inspect_mesh(CUBE_VERTICES, CUBE_FACES, 8.0).as_dict()
    assert json.loads(json.dumps(data))["volume_rel_error"] == pytest.approx(0.0, abs=ROUNDOFF)


def test_edge_shared_by_four_faces_is_not_watertight():
    """Two cubes sharing one edge: every half-edge has a reverse, but that edge has four faces."""
    second = CUBE_VERTICES + [2.0, 2.0, 0.0]  # its edge x = y = 0 lies on the first cube's edge x = y = 2
    vertices = np.vstack([CUBE_VERTICES, second])
    faces = np.vstack([CUBE_FACES, CUBE_FACES + 8])
    shared = {0: 6, 1: 7}  # second cube's (0, 0, z) are the first cube's (2, 2, z)
    faces[len(CUBE_FACES):] = np.vectorize(lambda i: shared.get(i - 8, i))(faces[len(CUBE_FACES):])
    report = inspect_mesh(vertices, faces)
    assert not report.watertight and not report.winding_consistent and report.shells == 1
    with pytest.raises(MeshError, match="not watertight"):
        check_solid(vertices, faces)


def test_a_repeated_face_is_not_watertight():
    faces = np.vstack([CUBE_FACES, CUBE_FACES[:1]])
    assert not inspect_mesh(CUBE_VERTICES, faces).watertight


def _reference_topology(faces: np.ndarray, n_vertices: int) -> tuple[bool, bool, bool, int, int]:
    """watertight, winding consistent, vertex manifold, shells, Euler characteristic, straight from the definitions."""
    half = [(int(f[p]), int(f[(p + 1) % 3])) for f in faces for p in range(3)]
    undirected = {}
    for a, b in half:
        undirected[min(a, b), max(a, b)] = undirected.get((min(a, b), max(a, b)), 0) + 1
    watertight = len(half) > 0 and all(c == 2 for c in undirected.values())
    consistent = watertight and len(set(half)) == len(half)
    manifold = False
    if consistent:
        manifold = True
        for v in {int(i) for i in faces.ravel()}:
            around = [f for f in faces if v in f]
            # faces around v are one fan when sharing an edge through v joins them all
            reached, todo = {0}, [0]
            while todo:
                f = set(map(int, around[todo.pop()]))
                for k, g in enumerate(around):
                    if k not in reached and len(f & set(map(int, g))) == 2:
                        reached.add(k)
                        todo.append(k)
            manifold &= len(reached) == len(around)
    parent = list(range(n_vertices))

    def root(i):
        while parent[i] != i:
            i = parent[i]
        return i

    for a, b in half:
        parent[root(a)] = root(b)
    used = {int(i) for i in faces.ravel()}
    shells = len({root(i) for i in used})
    return watertight, consistent, manifold, shells, len(used) - len(undirected) + len(faces)


@pytest.mark.parametrize("fault", ["none", "drop", "flip", "repeat", "merge", "two_shells", "unused", "shuffle"])
def test_topology_checks_agree_with_their_definitions(fault):
    """Seeded faults on a torus: each check against a direct count from the module's definitions."""
    rng = np.random.default_rng(7)
    vertices, faces = _torus_grid(8, 6)
    for _ in range(5):
        f, v = faces.copy(), vertices.copy()
        if fault == "drop":
            f = np.delete(f, rng.integers(len(f), size=2), axis=0)
        elif fault == "flip":
            i = rng.integers(len(f), size=2)
            f[i] = f[i, ::-1]
        elif fault == "repeat":
            f = np.vstack([f, f[rng.integers(len(f), size=1)]])
        elif fault == "merge":
            a, b = rng.choice(len(v), size=2, replace=False)
            f[f == a] = b  # a pinched vertex (or, for neighbours, collapsed faces)
        elif fault == "two_shells":
            f, v = np.vstack([f, f[:, ::-1] + len(v)]), np.vstack([v, 0.5 * v])
        elif fault == "unused":
            perm = rng.permutation(len(v) + 3)
            v = np.vstack([v, np.zeros((3, 3))])[np.argsort(perm)]
            f = perm[f]
        elif fault == "shuffle":
            f = np.roll(f[rng.permutation(len(f))], 1, axis=1)
        report = inspect_mesh(v, f)
        got = (report.watertight, report.winding_consistent, report.vertex_manifold, report.shells, report.euler)
        assert got == _reference_topology(f, len(v))


def test_a_face_folded_by_single_precision_is_counted_and_welded():
    """Issue 43: a vertex 1e-9 mm from another is the same point in float32; the check counts the folded faces
    and the non-manifold edges a slicer sees, and welding collapses that edge into a closed 2-manifold."""
    from softdesign.meshing.checks import written_defects
    from softdesign.meshing.solids import welded_as_written

    # the cube 200 mm from the origin, as a patient's coordinates are (float32 keeps about 1.5e-5 mm there);
    # split its edge 0-1 at a point 1e-9 mm from vertex 0: faces [0, 1, 3] and [0, 5, 1] become four
    n = len(CUBE_VERTICES)
    cube = CUBE_VERTICES + 200.0
    vertices = np.vstack([cube, cube[0] + 1e-9 * (cube[1] - cube[0])])
    faces = np.vstack([CUBE_FACES[[1, 2, 3, 4, 6, 7, 8, 9, 10, 11]],
                       [[0, n, 3], [n, 1, 3], [0, 5, n], [n, 5, 1]]])
    report = inspect_mesh(vertices, faces)
    assert report.watertight and report.vertex_manifold and report.degenerate_faces == 0  # sound in float64
    # as written: [0, n, 3] and [0, 5, n] fold; edges 0-3 and 0-5 are then shared by three faces each
    assert written_defects(vertices, faces) == (2, 2)
    # known watertight in float64 does not skip the count when float32 merges vertices (issue 46's shortcut)
    assert written_defects(vertices, faces, watertight=True) == (2, 2)
    assert written_defects(cube, CUBE_FACES, watertight=True) == written_defects(cube, CUBE_FACES) == (0, 0)
    assert (report.zero_area_faces, report.nonmanifold_edges) == (2, 2)
    with pytest.raises(MeshError, match="2 zero-area faces, 2 non-manifold edges"):
        check_solid(vertices, faces)
    welded = welded_as_written(vertices, faces, np.arange(len(faces), dtype=np.int8))
    assert len(welded[1]) == len(faces) - 2 and welded[2].tolist() == [*range(10), 11, 13]
    checked = check_solid(welded[0], welded[1], Expectation(volume=8.0))
    assert (checked.zero_area_faces, checked.nonmanifold_edges, checked.euler) == (0, 0, 2)
