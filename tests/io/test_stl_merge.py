"""The binary STL reader merges vertices exactly as trimesh's merge_vertices did: the same arrays, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from softdesign.geometry.rows import rows_in_first_order
from softdesign.io.formats import _merge_digits, _merged_as_trimesh_merges, read_mesh
from softdesign.meshing.checks import written_defects
from tests.helpers.paths import REPO


def _trimesh_merged(vertices: np.ndarray, faces: np.ndarray, digits: int) -> tuple[np.ndarray, np.ndarray]:
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    mesh.merge_vertices(digits_vertex=digits)
    return np.asarray(mesh.vertices, np.float64), np.asarray(mesh.faces, np.int64)


def _assert_same(found: tuple[np.ndarray, np.ndarray], expected: tuple[np.ndarray, np.ndarray]) -> None:
    for mine, theirs in zip(found, expected, strict=True):
        assert mine.dtype == theirs.dtype and mine.shape == theirs.shape
        assert mine.tobytes() == theirs.tobytes()


@pytest.mark.parametrize("scale_to_mm", [1.0, 1000.0])
def test_near_duplicates_unused_vertices_and_negative_zero_merge_as_trimesh_merges(scale_to_mm):
    rng = np.random.default_rng(3)
    base = rng.normal(size=(300, 3)) * 20.0
    base[:5] = 0.0
    base[5:10] = -0.0
    jitter = rng.choice([0.0, 1e-12, 4e-9, 3e-8], size=(900, 1)) * rng.choice([-1.0, 1.0], size=(900, 3))
    vertices = base[rng.integers(0, 300, size=900)] + jitter / scale_to_mm
    faces = rng.integers(0, 850, size=(400, 3))  # vertices 850-899 unused: dropped as trimesh drops them
    digits = _merge_digits(scale_to_mm)
    _assert_same(_merged_as_trimesh_merges(vertices, faces, digits), _trimesh_merged(vertices, faces, digits))


def test_the_demo_surface_reads_as_trimesh_merged_it():
    path = REPO / "data" / "demo" / "surface.stl"
    loaded = trimesh.exchange.stl.load_stl_binary(path.open("rb"))
    expected = _trimesh_merged(np.asarray(loaded["vertices"], np.float64), loaded["faces"], _merge_digits(1.0))
    _assert_same(read_mesh(path), expected)


def test_groups_in_first_order_are_trimesh_s_and_survive_a_hash_collision(monkeypatch):
    rng = np.random.default_rng(5)
    rows = rng.integers(-4, 4, size=(2000, 3))
    first, inverse = trimesh.grouping.unique_rows(rows, keep_order=True)
    found = rows_in_first_order(rows)
    np.testing.assert_array_equal(found[0], first)
    np.testing.assert_array_equal(found[1], inverse)
    from softdesign.geometry import rows as module

    monkeypatch.setattr(module, "_MIXERS", (0, 0, 0, 0))  # every row one hash: the check falls back to sorting
    collided = rows_in_first_order(rows)
    np.testing.assert_array_equal(collided[0], first)
    np.testing.assert_array_equal(collided[1], inverse)


def test_written_defects_count_coincident_vertices_as_one():
    # two triangles sharing an edge through distinct but float32-equal vertices, and a third on the same edge
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 0], [1 + 1e-9, 0, 0], [0, -1, 0], [0, 0, 1]], float)
    faces = np.array([[0, 1, 2], [3, 5, 4], [0, 6, 1]])
    assert written_defects(vertices, faces) == (0, 1)  # edge 0-1 shared by three faces once merged
    assert written_defects(vertices[:3], faces[:1]) == (0, 0)


def test_rows_all_distinct_says_what_the_groups_say_and_survives_a_hash_collision(monkeypatch):
    from softdesign.geometry import rows as module
    from softdesign.geometry.rows import rows_all_distinct

    rng = np.random.default_rng(6)
    distinct = rng.permutation(np.array(np.meshgrid(*[np.arange(-6, 6)] * 3)).reshape(3, -1).T).astype(float)
    cases = {
        "distinct": (distinct, True),
        "one repeated": (np.vstack([distinct, distinct[17:18]]), False),
        "-0.0 against 0.0": (np.array([[0.0, 1.0, 2.0], [-0.0, 1.0, 2.0]]), False),
        "NaN rows never equal": (np.array([[np.nan, 1.0, 2.0], [np.nan, 1.0, 2.0]]), True),
        "float32": (distinct.astype(np.float32), True),
        "one row": (distinct[:1], True),
    }
    for name, (rows, expected) in cases.items():
        assert rows_all_distinct(rows) is expected, name
        assert (len(rows_in_first_order(rows)[0]) == len(rows)) is expected, name
    monkeypatch.setattr(module, "_MIXERS", (0, 0, 0, 0))  # every row one hash: settled by the groups
    for name, (rows, expected) in cases.items():
        assert rows_all_distinct(rows) is expected, name


def _two_workers(task, items):
    from softdesign.pipeline.parallel import jobs_for_build, map_items

    with jobs_for_build(2):
        return map_items(task, items)


@pytest.mark.parametrize("mapper", ["serial", "two workers"])
def test_the_groups_split_by_parity_on_a_mapper_are_the_groups_of_one_pass(mapper):
    from softdesign.fitting.mapping import serial_map
    from softdesign.geometry.rows import SPLIT_ROWS

    run = serial_map if mapper == "serial" else _two_workers
    rng = np.random.default_rng(8)
    rows = rng.integers(-300, 300, size=(SPLIT_ROWS + 1001, 3))
    rows[1::3] = rows[rng.integers(0, len(rows), size=len(rows[1::3]))]  # about a third repeat an earlier or later row
    for case in (rows, 2 * rows, 2 * rows + 1):  # both halves, every row even, every row odd (one half empty)
        one, split = rows_in_first_order(case), rows_in_first_order(case, run)
        for mine, theirs in zip(split, one, strict=True):
            assert mine.dtype == theirs.dtype and mine.tobytes() == theirs.tobytes()


def test_a_hash_collision_in_a_half_falls_back_to_sorting_every_row(monkeypatch):
    from softdesign.fitting.mapping import serial_map
    from softdesign.geometry import rows as module

    rng = np.random.default_rng(9)
    rows = rng.integers(-4, 4, size=(3000, 3))
    first, inverse = trimesh.grouping.unique_rows(rows, keep_order=True)
    monkeypatch.setattr(module, "SPLIT_ROWS", 100)
    monkeypatch.setattr(module, "_MIXERS", (0, 0, 0, 0))  # every row one hash: each half's check fails
    found = rows_in_first_order(rows, serial_map)
    np.testing.assert_array_equal(found[0], first)
    np.testing.assert_array_equal(found[1], inverse)


def test_the_demo_surface_read_with_its_merge_split_is_trimesh_s_merge(monkeypatch):
    from softdesign.fitting.mapping import serial_map
    from softdesign.geometry import rows as module
    from softdesign.io.surface import read_surface

    path = REPO / "data" / "demo" / "surface.stl"
    loaded = trimesh.exchange.stl.load_stl_binary(path.open("rb"))
    expected = _trimesh_merged(np.asarray(loaded["vertices"], np.float64), loaded["faces"], _merge_digits(1.0))
    monkeypatch.setattr(module, "SPLIT_ROWS", 1000)  # the demo's 50k corners split too
    _assert_same(read_surface(path, 1.0, serial_map), expected)


@pytest.mark.parametrize("scale_to_mm", [1.0, 1000.0])
def test_float32_corners_merged_a_block_at_a_time_are_trimesh_s_merge_of_them_widened(monkeypatch, scale_to_mm):
    # a binary STL's corners stay float32 until merged; the keys are made a few rows at a time
    from softdesign.io import formats

    monkeypatch.setattr(formats, "MERGE_BLOCK_ROWS", 7)  # blocks that split faces and the last one short
    rng = np.random.default_rng(11)
    base = (rng.normal(size=(200, 3)) * 20.0 / scale_to_mm).astype(np.float32)
    corners = base[rng.integers(0, 200, size=600)]  # 200 faces, their corners in order
    faces = np.arange(600, dtype=np.int64).reshape(-1, 3)
    digits = _merge_digits(scale_to_mm)
    expected = _trimesh_merged(corners.astype(np.float64), faces, digits)
    _assert_same(_merged_as_trimesh_merges(corners, faces, digits, in_order=True), expected)
    _assert_same(_merged_as_trimesh_merges(corners.astype(np.float64), faces, digits), expected)
