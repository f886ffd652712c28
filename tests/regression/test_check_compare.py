"""Mesh-to-mesh figures (softdesign.meshing.compare), mesh folders in every format, pose differences."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from softdesign.errors import MeshError
from softdesign.io.formats import MESH_FORMATS, write_mesh
from softdesign.meshing.compare import compare_meshes, surface_samples
from softdesign.regression import CheckOptions, compare_mesh_folders, mesh_names, pose_difference

#: Rounding of double-precision sums over a few thousand terms of size ~1e3, mm, mm^2 or relative.
EXACT_TOL = 1e-9
#: Box half-extent, mm.
HALF = 10.0


def box() -> tuple[np.ndarray, np.ndarray]:
    """A (20 mm)^3 cube centred on the origin, 12 outward triangles."""
    mesh = trimesh.creation.box(extents=[2 * HALF] * 3)
    return np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64)


def rotation_about(axis, angle: float) -> np.ndarray:
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def test_translated_box_distance_is_the_shift_and_rms_is_shift_over_sqrt3():
    v, f = box()
    shift = 0.01
    diff = compare_meshes(v + [shift, 0.0, 0.0], f, v, f)
    np.testing.assert_allclose(diff.distance_max_mm, shift, rtol=0, atol=EXACT_TOL)
    # The two faces normal to the shift (1/3 of the area) are `shift` away; the other four move within
    # themselves except a sliver of width `shift`, so RMS^2 = shift^2 / 3 up to O(shift / HALF) = 1e-3
    # relative, plus the +-1 sample per face of systematic sampling: 2e-3 relative covers both.
    np.testing.assert_allclose(diff.distance_rms_mm, shift / np.sqrt(3.0), rtol=0, atol=2e-3 * shift)
    np.testing.assert_allclose(diff.volume_rel_change, 0.0, rtol=0, atol=EXACT_TOL)
    assert diff.watertight and diff.reference_watertight


def test_scaled_box_volume_and_area_change_are_cube_and_square_of_the_scale():
    v, f = box()
    scale = 1.002
    diff = compare_meshes(v * scale, f, v, f)
    np.testing.assert_allclose(diff.volume_rel_change, scale**3 - 1.0, rtol=0, atol=EXACT_TOL)
    np.testing.assert_allclose(diff.area_rel_change, scale**2 - 1.0, rtol=0, atol=EXACT_TOL)
    # A scaled corner lies (scale - 1) * HALF outside three faces at once: sqrt(3) times that from the old corner.
    np.testing.assert_allclose(diff.distance_max_mm, np.sqrt(3.0) * HALF * (scale - 1.0), rtol=0, atol=EXACT_TOL)


def test_identical_meshes_have_zero_difference_and_figures_repeat_exactly():
    mesh = trimesh.creation.icosphere(subdivisions=3, radius=5.0)
    v, f = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    first = compare_meshes(v, f, v, f)
    np.testing.assert_allclose(first.distance_max_mm, 0.0, rtol=0, atol=EXACT_TOL)
    assert compare_meshes(v, f, v, f).as_dict() == first.as_dict()
    moved = compare_meshes(v + 0.003, f, v, f)
    assert compare_meshes(v + 0.003, f, v, f).as_dict() == moved.as_dict()


def test_samples_lie_on_the_surface_and_follow_area():
    v, f = box()
    count = 6000
    points = surface_samples(v, f, count)
    assert points.shape == (count, 3)
    on_face = np.isclose(np.abs(points), HALF, rtol=0, atol=EXACT_TOL)
    assert np.all(on_face.sum(axis=1) >= 1), "every sample lies on one of the box faces"
    # Systematic sampling gives each triangle its area share to within one point; a side has two triangles.
    per_side = [np.count_nonzero(np.isclose(points[:, axis] * sign, HALF, atol=EXACT_TOL) & (on_face.sum(axis=1) == 1))
                for axis in range(3) for sign in (-1, 1)]
    np.testing.assert_allclose(per_side, count / 6, rtol=0, atol=2)


def test_samples_split_unequal_triangles_by_area():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 2, 0], [10, 0, 0], [13, 0, 0], [10, 6, 0]], float)
    faces = np.array([[0, 1, 2], [3, 4, 5]])  # areas 1 and 9, apart along x
    points = surface_samples(vertices, faces, 1000)
    in_small = np.count_nonzero(points[:, 0] < 5.0)
    # Systematic sampling: each face gets its area share of the points to within one.
    np.testing.assert_allclose([in_small, len(points) - in_small], [100, 900], rtol=0, atol=1)
    small = points[points[:, 0] < 5.0]
    assert np.all(small[:, 0] / 1.0 + small[:, 1] / 2.0 <= 1.0 + EXACT_TOL), "points stay inside their triangle"


def test_samples_cover_a_triangle_evenly_in_both_directions():
    a, b, c = np.eye(3)
    count = 1200
    points = surface_samples(np.array([a, b, c]), np.array([[0, 1, 2]]), count)
    # The midpoints cut the triangle into four of equal area: the corner ones hold a coordinate > 1/2.
    corner_counts = [np.count_nonzero(points[:, axis] > 0.5) for axis in range(3)]
    middle = count - sum(corner_counts)
    # No worse than independent uniform points at three standard deviations, sqrt(n p (1 - p)) with p = 1/4.
    np.testing.assert_allclose(corner_counts + [middle], count / 4, rtol=0, atol=3 * np.sqrt(count * 3 / 16))


@pytest.mark.parametrize(
    "edit, expected",
    [
        (lambda v, f: (v, f), True),
        (lambda v, f: (v, f[1:]), False),  # one face removed: a hole
        (lambda v, f: (v, np.vstack([f[:1, ::-1], f[1:]])), False),  # one face flipped: inconsistent winding
        (lambda v, f: (v[f].reshape(-1, 3), np.arange(3 * len(f)).reshape(-1, 3)), False),  # unmerged soup
    ],
)
def test_watertight_means_closed_manifold_and_consistently_oriented(edit, expected):
    diff = compare_meshes(*edit(*box()), *box())
    assert diff.watertight is expected and diff.reference_watertight


def test_a_mesh_without_faces_is_refused_with_its_shapes():
    v, f = box()
    with pytest.raises(MeshError, match=r"reference mesh: no faces"):
        compare_meshes(v, f, v, np.zeros((0, 3), np.int64))
    with pytest.raises(MeshError, match=r"face indices must lie in \[0, 7\], got \[0, 8\]"):
        compare_meshes(v, np.vstack([f, [[0, 1, 8]]]), v, f)


@pytest.mark.parametrize("fmt", MESH_FORMATS)
def test_mesh_folders_are_compared_in_every_format(tmp_path, fmt):
    v, f = box()
    shift = 0.004  # within check's default 0.01 mm
    for folder, moved in (("build", shift), ("reference", 0.0)):
        (tmp_path / folder / "meshes").mkdir(parents=True)
        write_mesh(tmp_path / folder / "meshes" / f"q_0.000.{fmt}", v + [moved, 0.0, 0.0], f)
    assert mesh_names(tmp_path / "build") == {f"meshes/q_0.000.{fmt}"}
    figures = compare_mesh_folders(tmp_path / "build", tmp_path / "reference", CheckOptions(samples=2000), {})
    by_name = {figure.figure: figure for figure in figures}
    assert set(by_name) == {"distance_max_mm", "distance_rms_mm", "volume_rel_change", "area_rel_change", "watertight",
                            "zero_area_faces", "nonmanifold_edges"}
    assert by_name["zero_area_faces"].build == 0 and by_name["nonmanifold_edges"].build == 0
    assert all(figure.passed for figure in figures) and by_name["watertight"].build is True
    # float32 files (STL, glTF) round the box's corners by ~1e-6 mm
    np.testing.assert_allclose(by_name["distance_max_mm"].change, shift, rtol=0, atol=1e-5)


def test_pose_difference_known_translation_and_angles():
    pose = np.eye(4)
    pose[:3, :3] = rotation_about([1, 2, 3], 0.7)
    pose[:3, 3] = [1.0, 2.0, 3.0]
    moved = pose.copy()
    moved[:3, 3] += [0.0, 3.0, 4.0]
    moved[:3, :3] = pose[:3, :3] @ rotation_about([0, 1, 1], 0.25)
    translation, angle = pose_difference(moved, pose)
    np.testing.assert_allclose(translation, 5.0, rtol=0, atol=EXACT_TOL)
    np.testing.assert_allclose(angle, 0.25, rtol=0, atol=EXACT_TOL)
    tiny = pose.copy()
    tiny[:3, :3] = pose[:3, :3] @ rotation_about([0, 0, 1], 1e-8)
    # atan2 resolves 1e-8 rad to rounding; acos((trace - 1) / 2) would give 0 or ~1.5e-8.
    np.testing.assert_allclose(pose_difference(tiny, pose)[1], 1e-8, rtol=0, atol=1e-14)


def test_check_counts_what_a_slicer_sees_in_the_build(tmp_path):
    """Issue 43: a mesh whose two vertices fold to one in float32 is flagged, whatever the reference holds."""
    v, f = box()
    for folder in ("build", "reference"):
        (tmp_path / folder / "meshes").mkdir(parents=True)
        write_mesh(tmp_path / folder / "meshes" / "q_0.000.stl", v, f)
    # the build's box with one face split at a point 1e-9 mm from its corner: apart in float64, one in float32
    corner = v[f[0, 0]] + 1e-9 * (v[f[0, 1]] - v[f[0, 0]])
    split_v = np.vstack([v, corner])
    n = len(v)
    a, b, c = f[0]
    split_f = np.vstack([f[1:], [[a, n, c], [n, b, c]]])
    other = [k for k in range(1, len(f)) if {a, b} <= set(f[k])]
    assert other  # the face across edge (a, b) is split at the same point, so the float64 mesh stays closed
    g = split_f[other[0] - 1]
    d = next(x for x in g if x not in (a, b))
    split_f = np.vstack([np.delete(split_f, other[0] - 1, axis=0), [[b, n, d], [n, a, d]]])
    from softdesign.meshing.checks import written_defects
    from softdesign.meshing.topology import mesh_topology

    assert mesh_topology(split_v, split_f).watertight and written_defects(split_v, split_f)[0] == 2
    write_mesh(tmp_path / "build" / "meshes" / "q_0.000.stl", split_v, split_f)
    figures = {fig.figure: fig for fig in compare_mesh_folders(tmp_path / "build", tmp_path / "reference",
                                                              CheckOptions(samples=2000), {})}
    got = (figures["zero_area_faces"].build, figures["nonmanifold_edges"].build)
    # the two folded faces, and their edges to c and to d, each now shared by three faces
    assert got == (2, 2) and not figures["zero_area_faces"].passed and not figures["nonmanifold_edges"].passed, got
