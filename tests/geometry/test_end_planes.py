"""Each end's flat cap or open loop, its tilt to the path's end tangent and the rim's gap past the body's square end.

Known answers: the tilted-cap vessel of the robust-build tests (a straight tube of radius r along +z whose
inlet cap is the plane through the origin tilted ``theta`` from +z, squarely capped at its far end) has
tilt theta at the inlet and 0 at the outlet, and a rim gap of r tan(theta).  The sample tube is a polygon of
``around`` sides: the rim points where the tilted cap cuts its faces lie on chords, up to the sagitta
r (1 - cos(pi / around)) inside the circle, which bounds how far below r the measured radius may be.
"""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.geometry.end_planes import RIM_GAP_TOLERANCE_MM, end_planes, rim_gap_warnings
from softdesign.io.surface import read_surface
from tests.helpers.robust_vessels import EDGE_MM, write_tilted_cap_vessel

RADIUS, LENGTH = 3.0, 40.0
#: The STL stores float32 coordinates: the plane through them is off by ~1e-7 rad; 1e-4 degrees is ample.
TILT_TOL_DEG = 1e-4
#: The polygon's chords lie inside its circle by up to this fraction of the radius (module notes).
SAGITTA = 1.0 - np.cos(np.pi / int(np.ceil(2 * np.pi * RADIUS / EDGE_MM)))
#: float32 coordinates of points ~40 mm from the origin: ~5e-6 mm each.
COORD_TOL_MM = 1e-5
ENDS = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, LENGTH]])
TANGENTS = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
INSCRIBED = np.full(2, RADIUS)


def tilted(tmp_path, tilt_deg):
    _, surface = write_tilted_cap_vessel(tmp_path / f"tilt_{tilt_deg}", RADIUS, LENGTH, tilt_deg)
    return read_surface(surface, 1.0)


def assert_rim_gap(plane, tilt_deg):
    expected = RADIUS * np.tan(np.radians(tilt_deg))
    assert abs(plane.tilt_deg - tilt_deg) < TILT_TOL_DEG
    assert RADIUS * (1.0 - SAGITTA) - COORD_TOL_MM <= plane.radius_mm <= RADIUS + COORD_TOL_MM
    assert expected * (1.0 - SAGITTA) - COORD_TOL_MM <= plane.rim_gap_mm <= expected + COORD_TOL_MM


@pytest.mark.parametrize("tilt_deg", [3.0, 8.0, 14.0])
def test_a_tilted_flat_cap_is_found_with_its_tilt_and_the_rim_gap_r_tan_tilt(tmp_path, tilt_deg):
    inlet, outlet = end_planes(*tilted(tmp_path, tilt_deg), ENDS, TANGENTS, INSCRIBED)
    assert inlet is not None and inlet.kind == "flat_cap"
    assert_rim_gap(inlet, tilt_deg)
    # the normal points out of the vessel (-z at the inlet), leaning towards +x as the cap was cut
    theta = np.radians(tilt_deg)
    np.testing.assert_allclose(inlet.normal, [np.sin(theta), 0.0, -np.cos(theta)], rtol=0, atol=1e-6)
    # the cap's plane passes through the path's end (the cap's centre), as the vessel was made
    assert abs(inlet.axis_offset_mm) < COORD_TOL_MM and inlet.flatness_mm < COORD_TOL_MM
    # the far end is capped square: no tilt, no gap
    assert outlet is not None and outlet.kind == "flat_cap"
    assert outlet.tilt_deg < TILT_TOL_DEG and outlet.rim_gap_mm < COORD_TOL_MM
    np.testing.assert_allclose(outlet.normal, [0.0, 0.0, 1.0], rtol=0, atol=1e-6)


def test_a_square_cap_has_no_tilt_and_no_gap(tmp_path):
    inlet, outlet = end_planes(*tilted(tmp_path, 0.0), ENDS, TANGENTS, INSCRIBED)
    for plane in (inlet, outlet):
        assert plane is not None and plane.kind == "flat_cap"
        assert plane.tilt_deg < TILT_TOL_DEG and plane.rim_gap_mm < COORD_TOL_MM


def test_an_open_end_is_found_by_its_boundary_loop_with_the_same_tilt(tmp_path):
    vertices, faces = tilted(tmp_path, 8.0)
    theta = np.radians(8.0)
    on_cap = np.abs(vertices @ np.array([-np.sin(theta), 0.0, np.cos(theta)])) < COORD_TOL_MM
    open_faces = faces[~on_cap[faces].all(axis=1)]
    assert len(open_faces) < len(faces)
    inlet, outlet = end_planes(vertices, open_faces, ENDS, TANGENTS, INSCRIBED)
    assert inlet is not None and inlet.kind == "open_end" and outlet is not None and outlet.kind == "flat_cap"
    assert_rim_gap(inlet, 8.0)
    assert inlet.flatness_mm < COORD_TOL_MM


def test_an_end_the_surface_does_not_reach_has_no_plane(tmp_path):
    # the path's ends moved 3 radii inside the vessel: no cap or loop is within a radius of them
    vertices, faces = tilted(tmp_path, 8.0)
    inner = ENDS + np.array([[0.0, 0.0, 3 * RADIUS], [0.0, 0.0, -3 * RADIUS]])
    assert end_planes(vertices, faces, inner, TANGENTS, INSCRIBED) == (None, None)


def test_the_warning_names_the_end_the_tilt_and_the_gap_only_above_the_tolerance(tmp_path):
    inlet, outlet = end_planes(*tilted(tmp_path, 14.0), ENDS, TANGENTS, INSCRIBED)
    assert inlet is not None and outlet is not None
    planes = {"inlet": inlet.as_dict(), "outlet": outlet.as_dict()}
    (line,) = rim_gap_warnings(planes)
    assert line.startswith("the vessel's flat cap at the inlet is tilted 14.0 deg")
    assert f"reaches {inlet.rim_gap_mm:.3f} mm past the body's end" in line and "vmtksurfaceclipper" in line
    small = end_planes(*tilted(tmp_path, 3.0), ENDS, TANGENTS, INSCRIBED)[0]
    assert small is not None and small.rim_gap_mm < RIM_GAP_TOLERANCE_MM
    assert rim_gap_warnings({"inlet": small.as_dict(), "outlet": None}) == []


def test_the_vmtk_aorta_open_ends_are_flat_loops_and_its_rounded_caps_have_no_plane(aorta_dir):
    from softdesign.geometry.curves import smooth_curve_from_polyline
    from softdesign.geometry.inlet import end_radii
    from softdesign.geometry.network import Orientation, select_path
    from softdesign.io.centerline import read_centerline_network

    path = select_path(read_centerline_network(aorta_dir / "aorta-centerline.vtp", 1.0), 0, Orientation())
    curve = smooth_curve_from_polyline(path.points)
    ends, tangents = curve.points([0.0, 1.0]), curve.tangents([0.0, 1.0])
    inscribed = np.array(end_radii(path.points, path.radius))
    opened = end_planes(*read_surface(aorta_dir / "aorta-surface-open-ends.stl", 1.0), ends, tangents, inscribed)
    for plane, radius in zip(opened, inscribed, strict=True):
        # vmtksurfaceclipper cuts each end with a plane: the loop lies in it up to float32 round-off
        assert plane is not None and plane.kind == "open_end" and plane.flatness_mm < COORD_TOL_MM
        # the opening is the vessel's own: its rim is about as wide as the inscribed sphere there
        assert 0.5 * radius < plane.radius_mm < 2.0 * radius
    # the capped surface's caps are rounded domes: no flat region spans the vessel there
    assert end_planes(*read_surface(aorta_dir / "aorta-surface.stl", 1.0), ends, tangents, inscribed) == (None, None)


def test_a_rounded_dome_has_no_plane():
    import trimesh

    # a capsule: hemispherical caps on a short tube, finely tessellated (neighbours 0.5 degrees apart around)
    capsule = trimesh.creation.capsule(height=4.0, radius=RADIUS, count=[720, 16])
    ends = np.array([[0.0, 0.0, -2.0], [0.0, 0.0, 2.0]])  # where the domes begin
    assert end_planes(capsule.vertices, capsule.faces, ends, TANGENTS, INSCRIBED) == (None, None)


def test_a_flat_band_of_wall_spanning_both_rims_is_not_taken_for_an_end_plane():
    import trimesh

    # an open tube 4 mm long whose wall is one flat-connected band (neighbours 0.5 degrees apart): its rim is both
    # loops, its centroid between them, nearer the path's ends than either loop; it lies in no plane
    tube = trimesh.creation.cylinder(radius=RADIUS, height=4.0, sections=720)
    side = np.abs(np.abs(tube.triangles_center[:, 2]) - 2.0) > 1e-9
    ends = np.array([[0.0, 0.0, -0.5], [0.0, 0.0, 0.5]])
    inlet, outlet = end_planes(tube.vertices, tube.faces[side], ends, TANGENTS, INSCRIBED)
    for plane in (inlet, outlet):
        assert plane is not None and plane.kind == "open_end"
        assert abs(plane.axis_offset_mm - 1.5) < COORD_TOL_MM and plane.tilt_deg < TILT_TOL_DEG


def test_the_faces_near_an_end_are_those_whose_centres_lie_within_reach():
    import trimesh

    from softdesign.geometry.end_planes import _faces_near

    # the vertex box that spares most centres must not drop one: a lumpy sphere far from the origin, reaches
    # that end exactly on a face's centre, and none
    rng = np.random.default_rng(3)
    sphere = trimesh.creation.icosphere(subdivisions=4, radius=RADIUS)
    vertices = sphere.vertices * rng.uniform(0.9, 1.1, (len(sphere.vertices), 1)) + [200.0, -50.0, 10.0]
    centres = vertices[sphere.faces].mean(axis=1)
    ends = vertices[rng.choice(len(vertices), 2, replace=False)]
    exact = np.linalg.norm(centres[7] - ends[0])
    for reach in ([0.5, 2.0], [exact, 1e-9], [0.0, 0.0], [3.0 * RADIUS, 3.0 * RADIUS]):
        expected = np.any(np.linalg.norm(centres[:, None] - ends[None], axis=2) <= reach, axis=1)
        assert np.array_equal(_faces_near(vertices, sphere.faces, ends, np.array(reach)), expected)


def test_the_edge_table_pairs_faces_and_finds_boundary_edges_as_trimesh_does():
    import trimesh

    from softdesign.geometry.edges import EdgeTable

    # an open tube with a duplicated face (edges of 3 and 4 face edges), degenerate faces (one on an edge of the
    # wall, one whose only edge a-c no other face has, used twice by it alone) and faces in shuffled order
    tube = trimesh.creation.cylinder(radius=RADIUS, height=4.0, sections=24)
    faces = np.asarray(tube.faces)[np.abs(np.abs(tube.triangles_center[:, 2]) - 2.0) > 1e-9]
    a, b = faces[5, 0], faces[5, 1]
    c = next(v for v in np.unique(faces) if v != a and not np.any(np.isin(faces, [a, v]).sum(axis=1) >= 2))
    faces = np.concatenate([faces, faces[:1], [[a, b, a], [a, c, a]]])
    faces = faces[np.random.default_rng(0).permutation(len(faces))]
    mesh = trimesh.Trimesh(tube.vertices, faces, process=False)
    table = EdgeTable.of(faces, len(mesh.vertices))
    assert {tuple(sorted(p)) for p in table.face_pairs().tolist()} == {tuple(p) for p in mesh.face_adjacency.tolist()}
    once = mesh.edges_sorted[trimesh.grouping.group_rows(mesh.edges_sorted, require_count=1)]
    assert sorted(map(tuple, table.single_edges().tolist())) == sorted(map(tuple, once.tolist()))


def test_the_face_normals_and_pair_angles_are_trimeshs_bit_for_bit(aorta_dir):
    import trimesh

    from softdesign.geometry.edges import EdgeTable
    from softdesign.geometry.end_planes import _face_normals, _pair_angles

    # the VMTK aorta as read, and a lumpy sphere with a degenerate face, one whose cross product is just above
    # trimesh's zero (1e-13) and one just below it
    rng = np.random.default_rng(5)
    sphere = trimesh.creation.icosphere(subdivisions=4, radius=RADIUS)
    vertices = np.concatenate([sphere.vertices * rng.uniform(0.9, 1.1, (len(sphere.vertices), 1)),
                               [[0.0, 0.0, 0.0], [1e-6, 0.0, 0.0], [0.0, 2e-7, 0.0], [0.0, 5e-8, 0.0]]])
    n = len(sphere.vertices)
    faces = np.concatenate([sphere.faces, [[0, 1, 0], [n, n + 1, n + 2], [n, n + 1, n + 3]]])
    for v, f in (read_surface(aorta_dir / "aorta-surface.stl", 1.0), (vertices, faces)):
        v, f = np.asarray(v, float), np.asarray(f, np.int64)
        unit, valid = trimesh.triangles.normals(v[f])
        expected = np.zeros((len(f), 3))
        expected[valid] = unit
        normals = _face_normals(v, f)
        assert np.array_equal(normals.T, expected)
        pairs = EdgeTable.of(f, len(v)).face_pairs()
        assert np.array_equal(_pair_angles(normals, pairs), trimesh.geometry.vector_angle(expected[pairs]))
    assert not valid[-1] and valid[-2] and not valid[-3]  # the test has faces on both sides of the zero


def test_the_flat_labels_given_find_the_planes_found_without_them(tmp_path):
    from softdesign.geometry.edges import EdgeTable
    from softdesign.geometry.end_planes import flat_labels

    vertices, faces = tilted(tmp_path, 8.0)
    table = EdgeTable.of(np.asarray(faces, np.int64), len(vertices))
    labels = flat_labels(vertices, faces, table)
    assert len(labels) == len(faces) and labels[0] == 0  # numbered from the smallest face id
    found = end_planes(vertices, faces, ENDS, TANGENTS, INSCRIBED, table, labels)
    alone = end_planes(vertices, faces, ENDS, TANGENTS, INSCRIBED)
    assert found[0] is not None and found[1] is not None
    assert [p.as_dict() for p in found] == [p.as_dict() for p in alone]  # the same floats, not only close ones
