"""validate's numpy-only STL corners against the build's reader, and its nearest distances against a KD-tree."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

from softdesign.geometry import plausibility
from softdesign.geometry.plausibility import nearest_distances
from softdesign.io.stl_corners import binary_stl_corners
from softdesign.io.surface import read_surface
from tests.helpers.paths import AORTA_DIR, REPO

#: Both read the same float32 corners into float64: equal exactly.
EXACT = 0.0
#: The expanded |p|^2 - 2 p.v + |v|^2 against the KD-tree's direct differences, mm (points within 100 mm).
DISTANCE_TOL_MM = 1e-9
#: A zero distance through the square root of a rounded square: sqrt(1e4 mm^2 x 2.2e-16) ~ 1.5e-6 mm.
ZERO_TOL_MM = 1e-5


@pytest.mark.parametrize("path", [REPO / "data" / "demo" / "surface.stl", AORTA_DIR / "aorta-surface-open-ends.stl"],
                         ids=["demo", "vmtk-aorta"])
def test_the_distinct_corners_are_the_vertices_the_build_reads(path: Path) -> None:
    if not path.is_file():
        pytest.skip(f"{path} not found (the VMTK data is in ../shared beside the checkout)")
    read = binary_stl_corners(path)
    assert read is not None
    corners, triangles = read
    vertices, faces = read_surface(path)
    assert triangles == len(faces) and len(corners) == len(vertices)
    np.testing.assert_allclose(corners, np.unique(vertices, axis=0), rtol=0, atol=EXACT)


def test_an_ascii_or_truncated_stl_is_left_to_the_full_reader(tmp_path: Path) -> None:
    ascii_stl = tmp_path / "a.stl"
    ascii_stl.write_text("solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                         "endloop\nendfacet\nendsolid a\n")
    assert binary_stl_corners(ascii_stl) is None
    truncated = tmp_path / "t.stl"
    truncated.write_bytes((REPO / "data" / "demo" / "surface.stl").read_bytes()[:-7])
    assert binary_stl_corners(truncated) is None
    empty = tmp_path / "e.stl"
    empty.write_bytes(bytes(80) + (0).to_bytes(4, "little"))
    read = binary_stl_corners(empty)
    assert read is not None and read[0].shape == (0, 3) and read[1] == 0


@pytest.mark.parametrize("brute_force", [True, False])
def test_nearest_distances_are_the_kd_tree_s(brute_force: bool, monkeypatch: pytest.MonkeyPatch) -> None:
    rng = np.random.default_rng(46)
    points, vertices = rng.uniform(-100, 100, (300, 3)), rng.uniform(-100, 100, (5000, 3))
    monkeypatch.setattr(plausibility, "BRUTE_FORCE_PAIRS", 10**9 if brute_force else 0)
    expected = cKDTree(vertices).query(points)[0]
    np.testing.assert_allclose(nearest_distances(points, vertices), expected, rtol=0, atol=DISTANCE_TOL_MM)
    # a point on a vertex is at distance 0 (up to the rounding of the expanded square)
    assert nearest_distances(vertices[:1], vertices)[0] < ZERO_TOL_MM
