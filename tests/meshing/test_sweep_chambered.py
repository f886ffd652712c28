"""Issue 31's layout on five or more sections in the swept mesher: every section's chambers and feeds in the one
cross-section, neighbouring sections' chambers ``2 d sin(60 deg / n) - D`` apart (0.032 mm at five sections on the
defaults), resolved by grading the circles' nodes; the narrowest gap refused before meshing."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import ConfigError
from softdesign.geometry.blend import blend_shapes
from softdesign.geometry.curves import CurveOptions, smooth_curve_from_polyline
from softdesign.geometry.initial import straight_initial_shape
from softdesign.meshing.chambers.layout import ActuationSpec, plan_layout
from softdesign.meshing.topology import mesh_topology
from softdesign.meshing.volume import BodySpec
from softdesign.meshing.volume_mesh.cross_section import Circle
from softdesign.meshing.volume_mesh.section_gaps import pair_gaps, resolve_circles, unresolved
from softdesign.meshing.volume_mesh.sweep_body import place_mesh, plan_mesh
from softdesign.meshing.volume_mesh.tet_quality import boundary_faces
from tests.fitting.test_fit_strain import _constant_field

RADIUS_MM, BEND_RADIUS_MM, NA, SECTION_MM = 3.3, 60.0, 48, 8.0
#: the issue's bounds: each cavity's surface within 1 % of its analytic volume
CHAMBER_RTOL = 0.01


def _body(sections: int):
    length = SECTION_MM * sections
    s = np.linspace(0.0, length, 4001)
    arc = np.column_stack([BEND_RADIUS_MM * (1 - np.cos(s / BEND_RADIUS_MM)), np.zeros_like(s),
                           BEND_RADIUS_MM * np.sin(s / BEND_RADIUS_MM)])
    final = smooth_curve_from_polyline(arc, CurveOptions(spacing_mm=0.25, smoothing_mm=0.0))
    return blend_shapes(straight_initial_shape(final), final, mode="intrinsic"), _constant_field(RADIUS_MM,
                                                                                                  RADIUS_MM), length


def _layout(shape, sections: int, diameter: float, feed: float):
    curve0 = shape.curve_at(0.0)
    l = curve0.curve.dense_l()
    spec = ActuationSpec(distance_mm=2.0, diameter_mm=diameter, feed_diameter_mm=feed, end_wall_mm=1.0,
                         first_angle_deg=0.0)
    return plan_layout(spec, np.linspace(0.0, 1.0, sections + 1), l, curve0.curve.arc_length(l))


def _volumes(points, tets):
    p = points[tets]
    return np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]) / 6.0


def _keys(faces):
    return sorted(map(tuple, np.sort(faces, axis=1).tolist()))


# five sections at the defaults (diameter 0.8, feed 0.4: the widest the layout's 0.2 mm walls allow there);
# six and eight at the widest chambers the layout's walls allow at d = 2 mm
@pytest.mark.parametrize(("sections", "diameter", "feed"), [(5, 0.8, 0.4),
                                                              pytest.param(6, 0.6, 0.3, marks=pytest.mark.slow),
                                                              pytest.param(8, 0.4, 0.2, marks=pytest.mark.slow)])
def test_many_sections_mesh_with_every_cavity_closed(sections, diameter, feed):
    shape, field, length = _body(sections)
    layout = _layout(shape, sections, diameter, feed)
    spec = BodySpec()
    mesh, ref = plan_mesh(shape.curve_at(0.0), field, np.linspace(0.0, 1.0, int(length) + 1), spec, NA,
                          2.0, layout)
    rest = place_mesh(mesh, ref, shape.curve_at(0.0), field, 0.0, spec, NA)
    moved = place_mesh(mesh, ref, shape.curve_at(1.0), field, 1.0, spec, NA)
    assert _volumes(rest, mesh.tets).min() > 0 and _volumes(moved, mesh.tets).min() > 0
    # every boundary face named exactly once
    assert _keys(mesh.faces) == _keys(boundary_faces(mesh.tets))
    assert len(mesh.face_group) == len(mesh.faces) and mesh.face_group.min() >= 0
    # the solid's volume: the rest body's cylinder less every cavity (a straight body at q = 0)
    cavities = 0.0
    for chamber in layout.chambers:
        name = f"s{chamber.section + 1}_c{chamber.index + 1}"
        assert f"{name}_wall" in mesh.groups and f"{name}_feed_inlet" in mesh.lids
        topology = mesh_topology(rest, mesh.cavity_surface(name))
        assert topology.watertight and topology.winding_consistent
        feed_line = next(f for f in layout.feeds if (f.section, f.chamber) == (chamber.section, chamber.index))
        expected = np.pi * (chamber.diameter_mm / 2) ** 2 * (chamber.l_end - chamber.l_start) * length + np.pi * (
            feed_line.diameter_mm / 2) ** 2 * chamber.l_start * length
        np.testing.assert_allclose(topology.volume, expected, rtol=CHAMBER_RTOL)
        cavities += topology.volume
        # the wall's nodes on the chamber's exact circle about its axis, straight and bent (rigid core)
        wall = np.unique(mesh.group_faces(f"{name}_wall"))
        hole = next(h for h in mesh.holes if h.name == name)
        l = mesh.reference_points()[wall, 2]
        for q, points in ((0.0, rest), (1.0, moved)):
            curve = shape.curve_at(q)
            frames = curve.frames(l)
            axis = curve.points(l) + chamber.distance_mm * (np.cos(chamber.angle) * frames[:, :, 0]
                                                            + np.sin(chamber.angle) * frames[:, :, 1])
            radii = np.linalg.norm(points[wall] - axis, axis=1)
            np.testing.assert_allclose(radii, chamber.diameter_mm / 2 * hole.circle.node_radius(hole.circle.nodes)
                                       / hole.circle.radius, rtol=1e-9)
    solid = mesh_topology(rest, mesh.faces)  # the solid's boundary, chambers included, as one closed surface
    assert solid.watertight
    np.testing.assert_allclose(_volumes(rest, mesh.tets).sum(), solid.volume, rtol=1e-9)


def test_graded_circles_keep_their_area_and_make_gabriel_edges():
    """Two chambers 0.01 section radii apart: more nodes, gathered at the gap; every edge's diametral disk
    empty of the other circle's nodes (so Delaunay keeps it); each polygon keeps its circle's area."""
    circles = [Circle((0.0, 0.0), 0.12, 16, True), Circle((0.25, 0.0), 0.12, 16, True)]
    assert unresolved(circles) is None
    graded = resolve_circles(circles)
    nodes = []
    for c in graded:
        angles = np.asarray(c.angles)
        assert len(angles) > 16
        steps = np.diff(np.append(angles, angles[0] + 2 * np.pi))
        radius = c.node_radius(len(angles))
        np.testing.assert_allclose(0.5 * radius**2 * np.sum(np.sin(steps)), np.pi * c.radius**2, rtol=1e-12)
        nodes.append(np.asarray(c.center) + radius * np.column_stack([np.cos(angles), np.sin(angles)]))
        assert steps.max() > 3 * steps.min()  # graded, not refined all round
    for own, other in ((nodes[0], nodes[1]), (nodes[1], nodes[0])):
        a, b = own, np.roll(own, -1, axis=0)
        distance = np.linalg.norm(0.5 * (a + b)[:, None] - other[None], axis=-1).min(axis=1)
        assert np.all(distance > 0.5 * np.linalg.norm(b - a, axis=1))
    assert float(pair_gaps(graded)[0, 1]) > 0


def test_crossing_chambers_refused_before_meshing():
    """Eight sections of 0.6 mm chambers at d = 2 mm: neighbouring sections' chambers (0.522 mm apart) cross in
    the one cross-section; refused with the keys and a fix, before any meshing."""
    shape, field, length = _body(8)
    layout = _layout(shape, 8, 0.6, 0.2)
    with pytest.raises(ConfigError) as err:
        plan_mesh(shape.curve_at(0.0), field, np.linspace(0.0, 1.0, int(length / 0.5) + 1), BodySpec(), NA, 2.0,
                  layout)
    text = str(err.value)
    assert "cross" in text and "actuation.diameter_mm <=" in text and "links.count <=" in text
    assert "mesher: ftetwild" in text


def test_graded_mesh_same_bytes_twice():
    """Five sections at the defaults (graded circles): the same section, tetrahedra and names on a second run."""
    from softdesign.meshing.volume_mesh.sweep_layout import check_resolvable, layout_holes
    from softdesign.meshing.volume_mesh.sweep_mesh import swept_disk

    shape, _, _ = _body(5)
    layout = _layout(shape, 5, 0.8, 0.4)
    runs = []
    for _ in range(2):
        holes = check_resolvable(layout, layout_holes(layout, RADIUS_MM, 2.0), RADIUS_MM)
        assert any(h.circle.angles for h in holes)
        runs.append(swept_disk(NA, holes, 2.0 / RADIUS_MM, np.linspace(0.0, 1.0, 11)))
    first, second = runs
    assert first.section.points.tobytes() == second.section.points.tobytes()
    assert first.tets.tobytes() == second.tets.tobytes() and first.groups == second.groups
    assert first.faces.tobytes() == second.faces.tobytes()
