"""The swept tetrahedral mesh in the parameter domain: conforming, positive, named once, cavities closed."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.meshing.topology import mesh_topology
from softdesign.meshing.volume import polygon_area_ratio
from softdesign.meshing.volume_mesh.cross_section import Circle, cross_section
from softdesign.meshing.volume_mesh.sweep_mesh import Hole, layer_grid, sweep_mesh, swept_disk

#: Sums of many float64 products: relative round-off well under this.
SUM_RTOL = 1e-9
NA = 32


def _polygon_area(radius: float, count: int) -> float:
    return np.pi * radius**2 * polygon_area_ratio(count)


def _tet_volumes(points, tets):
    p = points[tets]
    return np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]) / 6.0


def _three_chambers() -> list[Hole]:
    """A synthetic layout: three chambers at 120 degrees over the middle, each fed from the base."""
    holes = []
    for k in range(3):
        a = 2.0 * np.pi * k / 3.0
        holes.append(Hole(f"s0_c{k}", Circle((0.5 * np.cos(a), 0.5 * np.sin(a)), 0.2), (0.2, 0.8)))
        b = a + np.pi / 3.0
        holes.append(Hole(f"s0_feed{k}", Circle((0.55 * np.cos(b), 0.55 * np.sin(b)), 0.07), (0.0, 0.8),
                          cavity=f"s0_c{k}"))
    return holes


@pytest.mark.parametrize("size", [0.1, 0.3, 0.8])
def test_disk_section_tiles_the_polygon(size):
    section = cross_section(NA, [], size)
    area = section.triangle_areas()
    assert np.all(area > 0)
    np.testing.assert_allclose(area.sum(), _polygon_area(1.0, NA), rtol=SUM_RTOL)
    assert section.min_angle_deg() > 10.0


def test_holes_are_conformed_and_their_triangles_tile_them():
    circles = [Circle((0.0, 0.0), 0.6, NA), Circle((0.0, 0.0), 0.15, NA)]
    section = cross_section(NA, circles, 0.3)
    area = section.triangle_areas()
    for k, c in enumerate(circles):
        np.testing.assert_allclose(area[section.inside[:, k]].sum(), _polygon_area(c.radius, NA), rtol=SUM_RTOL)


def test_layer_grid_puts_hole_ends_in_without_slivers():
    grid = layer_grid(np.linspace(0, 1, 11), [Hole("c", Circle((0, 0), 0.5), (0.21, 0.75))])
    assert {0.21, 0.75} <= set(grid.tolist())
    assert 0.2 not in grid  # 0.01 from an end: dropped
    assert np.min(np.diff(grid)) >= 0.3 * 0.1 - 1e-12


def test_solid_sweep_positive_and_named_exactly_once():
    mesh = swept_disk(NA, [], 0.3, np.linspace(0.0, 1.0, 21))
    volumes = _tet_volumes(mesh.reference_points(), mesh.tets)
    assert volumes.min() > 0
    np.testing.assert_allclose(volumes.sum(), _polygon_area(1.0, NA), rtol=SUM_RTOL)
    assert mesh.groups == ("skin", "base", "tip")
    assert len(mesh.group_faces("skin")) == 2 * NA * 20
    topology = mesh_topology(mesh.reference_points(), mesh.faces)
    assert topology.watertight and topology.winding_consistent
    np.testing.assert_allclose(topology.volume, volumes.sum(), rtol=SUM_RTOL)
    np.testing.assert_array_equal(mesh.base_nodes(), np.flatnonzero(mesh.reference_points()[:, 2] == 0.0))


def test_prism_split_conforms():
    """Every interior face is shared by exactly two tetrahedra: no face of three or more, and the faces of
    one tetrahedron are exactly the named boundary (a non-conforming split would leave unnamed inner faces)."""
    mesh = swept_disk(NA, _three_chambers(), 0.3, np.linspace(0.0, 1.0, 11))
    t = mesh.tets
    faces = np.sort(np.concatenate([t[:, [1, 2, 3]], t[:, [0, 3, 2]], t[:, [0, 1, 3]], t[:, [0, 2, 1]]]), axis=1)
    _, counts = np.unique(faces, axis=0, return_counts=True)
    assert counts.max() == 2
    assert np.sum(counts == 1) == len(mesh.faces)


def test_hollow_with_port_cavity_closed_with_its_volume():
    holes = [Hole("chamber", Circle((0.0, 0.0), 0.6, NA), (0.1, 0.9)),
             Hole("port", Circle((0.0, 0.0), 0.15, NA), (0.0, 0.1), cavity="chamber")]
    mesh = swept_disk(NA, holes, 0.3, np.linspace(0.0, 1.0, 21))
    points = mesh.reference_points()
    volumes = _tet_volumes(points, mesh.tets)
    assert volumes.min() > 0
    cavity = mesh.cavity_surface("chamber")
    topology = mesh_topology(points, cavity)
    assert topology.watertight and topology.winding_consistent
    expected = 0.8 * _polygon_area(0.6, NA) + 0.1 * _polygon_area(0.15, NA)
    np.testing.assert_allclose(topology.volume, expected, rtol=SUM_RTOL)  # normals out of the cavity: > 0
    np.testing.assert_allclose(volumes.sum(), _polygon_area(1.0, NA) - expected, rtol=SUM_RTOL)
    assert set(mesh.groups) == {"skin", "base", "tip", "chamber_wall", "chamber_cap", "port_wall"}
    assert set(mesh.lids) == {"port_inlet"}


def test_three_chambers_with_feeds():
    holes = _three_chambers()
    mesh = swept_disk(NA, holes, 0.3, np.linspace(0.0, 1.0, 11))
    points = mesh.reference_points()
    assert _tet_volumes(points, mesh.tets).min() > 0
    section = mesh.section
    area = section.triangle_areas()
    for k in range(3):
        chamber, feed = holes[2 * k], holes[2 * k + 1]
        topology = mesh_topology(points, mesh.cavity_surface(chamber.name))
        assert topology.watertight and topology.winding_consistent
        expected = 0.6 * area[section.inside[:, 2 * k]].sum() + 0.8 * area[section.inside[:, 2 * k + 1]].sum()
        np.testing.assert_allclose(topology.volume, expected, rtol=SUM_RTOL)
        assert f"{feed.name}_inlet" in mesh.lids


def test_same_input_same_mesh():
    a = swept_disk(NA, _three_chambers(), 0.3, np.linspace(0.0, 1.0, 6))
    b = swept_disk(NA, _three_chambers(), 0.3, np.linspace(0.0, 1.0, 6))
    np.testing.assert_array_equal(a.tets, b.tets)
    np.testing.assert_array_equal(a.reference_points(), b.reference_points())


def test_hole_count_must_match_section():
    section = cross_section(NA, [], 0.3)
    with pytest.raises(ValueError, match="holes"):
        sweep_mesh(section, np.linspace(0, 1, 3), [Hole("c", Circle((0, 0), 0.5), (0.2, 0.8))])
