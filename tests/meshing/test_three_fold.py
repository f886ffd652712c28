"""A three-fold symmetric layout gives a cross-section and a swept mesh that the 120-degree rotation maps onto
themselves (:mod:`softdesign.meshing.volume_mesh.three_fold`); any other layout is meshed as before."""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from softdesign.meshing.volume_mesh.cross_section import Circle, cross_section
from softdesign.meshing.volume_mesh.sweep_mesh import Hole, swept_disk
from softdesign.types import FloatArray, IntArray
from tests.mechanics.test_section_symmetry import pipeline_section

#: A point's image under the rotation is a node within this (rounding of the rotation), section radii or mm.
IMAGE_TOL = 1e-9


def _turn(points: FloatArray) -> FloatArray:
    """``points`` (n, 2 or 3) turned 120 degrees about the z axis."""
    c, s = np.cos(2 * np.pi / 3), np.sin(2 * np.pi / 3)
    turned = points.copy()
    turned[:, 0], turned[:, 1] = c * points[:, 0] - s * points[:, 1], s * points[:, 0] + c * points[:, 1]
    return turned


def _maps_onto_itself(points: FloatArray, cells: IntArray) -> bool:
    """Whether every node's image is a node and every cell's images are cells (as node sets)."""
    distance, image = cKDTree(points).query(_turn(points))
    if distance.max() > IMAGE_TOL:
        return False
    cell_set = {tuple(c) for c in np.sort(cells, axis=1).tolist()}
    return {tuple(c) for c in np.sort(image[cells], axis=1).tolist()} == cell_set


def _chambers(angle: float, nodes: int) -> list[Circle]:
    return [Circle((0.5 * np.cos(angle + 2 * np.pi * k / 3), 0.5 * np.sin(angle + 2 * np.pi * k / 3)), 0.2, nodes)
            for k in range(3)]


def test_a_symmetric_cross_section_maps_onto_itself() -> None:
    for outer, angle, nodes, size in ((12, np.pi / 2, 8, 0.6), (48, 0.3, 12, 0.2), (96, 0.0, 0, 0.1)):
        section = cross_section(outer, _chambers(angle, nodes), size)
        assert section.corner_order is not None
        assert _maps_onto_itself(section.points, section.triangles)


def test_the_swept_mesh_and_its_prism_split_map_onto_themselves() -> None:
    # the chambers end inside the body (caps), one feed-like hole per chamber opens at the base
    holes = [Hole(f"c{k}", c, (0.25, 0.75)) for k, c in enumerate(_chambers(np.pi / 2, 8))]
    holes += [Hole(f"f{k}", Circle(c.center, 0.08, 8), (0.0, 0.3), f"c{k}")
              for k, c in enumerate(_chambers(np.pi / 2, 8))]
    mesh = swept_disk(24, holes, 0.3, np.linspace(0.0, 1.0, 5))
    assert mesh.section.corner_order is not None
    assert _maps_onto_itself(mesh.reference_points(), mesh.tets)


def test_the_pipelines_section_mesh_maps_onto_itself() -> None:
    section = pipeline_section()
    assert _maps_onto_itself(section.points, section.tets)
    assert _maps_onto_itself(section.points, section.wall_faces)


def test_a_layout_that_is_not_symmetric_keeps_the_general_mesh() -> None:
    circles = _chambers(np.pi / 2, 8)
    for changed in ([circles[0], circles[1]], [*circles[:2], Circle(circles[2].center, 0.19, 8)]):
        section = cross_section(24, changed, 0.3)
        assert section.corner_order is None
        assert not _maps_onto_itself(section.points, section.triangles)
    assert cross_section(25, circles, 0.3).corner_order is None  # the outer circle's nodes are not symmetric
