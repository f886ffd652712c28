"""The binary STL writer gives trimesh's exporter's bytes, degenerate faces and an empty mesh included."""

from __future__ import annotations

import numpy as np
import trimesh

from softdesign.io.formats import mesh_bytes, read_mesh
from softdesign.io.stl_bytes import binary_stl_bytes
from tests.helpers.paths import REPO


def _trimesh_stl(vertices, faces) -> bytes:
    mesh = trimesh.Trimesh(np.asarray(vertices, float), np.asarray(faces, np.int64), process=False)
    return bytes(trimesh.exchange.export.export_mesh(mesh, file_obj=None, file_type="stl"))


def test_the_bytes_are_trimeshs_on_the_demo_surface():
    vertices, faces = read_mesh(REPO / "data" / "demo" / "surface.stl")
    assert len(faces) > 10_000
    assert binary_stl_bytes(vertices, faces) == _trimesh_stl(vertices, faces) == mesh_bytes(vertices, faces, "stl")


def test_degenerate_faces_get_zero_normals_as_trimesh_gives_them():
    rng = np.random.default_rng(5)
    vertices = rng.normal(size=(30, 3)) * 50.0 + 200.0
    faces = rng.integers(0, 30, size=(40, 3))
    faces[:5] = [[0, 0, 1], [2, 3, 2], [4, 4, 4], [5, 6, 7], [8, 9, 10]]
    vertices[7] = vertices[5] + (vertices[6] - vertices[5]) * 0.5  # a collinear, zero-area face
    data = binary_stl_bytes(vertices, faces)
    assert data == _trimesh_stl(vertices, faces)
    records = np.frombuffer(data[84:], dtype=[("n", "<f4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])
    assert np.all(records["n"][:3] == 0.0)


def test_an_empty_mesh_is_its_header():
    empty = np.zeros((0, 3)), np.zeros((0, 3), np.int64)
    assert binary_stl_bytes(*empty) == _trimesh_stl(*empty) == bytes(84)


def test_a_face_too_small_for_a_normal_gets_plus_zeros_whatever_the_signs_of_its_cross_product():
    rng = np.random.default_rng(11)
    vertices = rng.normal(size=(60, 3)) * 20.0
    faces = np.arange(60).reshape(20, 3)
    # corners 1e-15 mm apart: cross products of about 1e-30, far below trimesh's 1e-13, of either sign
    vertices[1::3] = vertices[0::3] + rng.normal(size=(20, 3)) * 1e-15
    vertices[2::3] = vertices[0::3] + rng.normal(size=(20, 3)) * 1e-15
    data = binary_stl_bytes(vertices, faces)
    assert data == _trimesh_stl(vertices, faces)
    normals = np.frombuffer(data[84:], dtype=[("n", "<u4", (3,)), ("v", "<f4", (3, 3)), ("a", "<u2")])["n"]
    assert np.all(normals == 0)  # the bits of +0.0, not -0.0
