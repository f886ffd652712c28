"""Ingest of the real VMTK aorta (../shared/data/vmtk-aorta): counts, radii, orientation, branch split."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.geometry.network import Orientation, assemble_path, select_path
from softdesign.io.centerline import read_centerline_network
from softdesign.io.surface import read_surface
from softdesign.meshing.topology import describe_surface

#: Inserted tract-joint points must lie on the original polyline to float32 precision (VMTK stores float32).
ON_SEGMENT_TOL_MM = 1e-4


def test_both_polylines_read_with_their_stored_counts_and_radius(aorta_dir):
    network = read_centerline_network(aorta_dir / "aorta-centerline.vtp")
    assert [len(p.points) for p in network.polylines] == [211, 198]
    assert not network.branch_split
    radius = np.concatenate([p.radius for p in network.polylines])
    # README: MaximumInscribedSphereRadius 2.8 to 7.6 mm
    assert 2.7 < radius.min() < 2.8 and 7.5 < radius.max() < 7.6


def test_duplicate_removed_with_a_note_and_inlet_first(aorta_dir):
    network = read_centerline_network(aorta_dir / "aorta-centerline.vtp")
    path0 = select_path(network, 0)
    assert len(path0.points) == 210
    assert any("removed 1 consecutive duplicate" in n for n in path0.notes)
    path1 = select_path(network, 1)
    assert len(path1.points) == 198
    # both paths start at the shared aortic inlet and end at different iliac outlets
    np.testing.assert_allclose(path0.points[0], path1.points[0], rtol=0, atol=0)
    assert np.linalg.norm(path0.points[-1] - path1.points[-1]) > 20.0
    # the file stores polyline 0 outlet-to-inlet by point id (210 -> 0): the shared end is its first point
    np.testing.assert_array_equal(path0.points[0], network.polylines[0].points[0])


def test_inlet_point_and_reverse_override_the_orientation(aorta_dir):
    network = read_centerline_network(aorta_dir / "aorta-centerline.vtp")
    outlet = select_path(network, 0).points[-1]
    towards = select_path(network, 0, Orientation(inlet=outlet + 1.0))
    np.testing.assert_array_equal(towards.points[0], outlet)
    flipped = select_path(network, 0, Orientation(reverse=True))
    np.testing.assert_array_equal(flipped.points[0], outlet)


@pytest.mark.parametrize("index", [0, 1])
def test_branch_split_file_gives_the_same_path_plus_joint_points(aorta_dir, index):
    whole = select_path(read_centerline_network(aorta_dir / "aorta-centerline.vtp"), index).points
    split_net = read_centerline_network(aorta_dir / "aorta-centerline-branches.vtp")
    assert split_net.branch_split and split_net.path_ids() == [0, 1]
    split = select_path(split_net, index).points
    # every original point appears, in the same order
    match = [int(np.argmin(np.linalg.norm(split - p, axis=1))) for p in whole]
    assert np.all(np.diff(match) > 0)
    np.testing.assert_allclose(split[match], whole, rtol=0, atol=1e-9)
    extra = np.setdiff1d(np.arange(len(split)), match)
    assert 1 <= len(extra) <= 4  # the branch extractor inserts a point or two at each tract joint
    for k in extra:
        a, b = whole[np.searchsorted(match, k) - 1], whole[np.searchsorted(match, k)]
        t = np.clip(np.dot(split[k] - a, b - a) / np.dot(b - a, b - a), 0, 1)
        assert np.linalg.norm(a + t * (b - a) - split[k]) < ON_SEGMENT_TOL_MM


def test_tracts_are_assembled_in_tract_order(aorta_dir):
    split_net = read_centerline_network(aorta_dir / "aorta-centerline-branches.vtp")
    points, radius = assemble_path(split_net, 1)
    tracts = [p for p in split_net.polylines if p.cell_data["CenterlineIds"] == 1]
    assert len(points) == sum(len(t.points) for t in tracts) and radius is not None


def test_capped_and_open_surfaces_both_read(aorta_dir):
    capped = describe_surface(*read_surface(aorta_dir / "aorta-surface.stl"))
    assert capped.capped and (capped.vertices, capped.faces) == (6468, 12932)
    opened = describe_surface(*read_surface(aorta_dir / "aorta-surface-open-ends.stl"))
    assert not opened.capped and opened.boundary_loops == 3  # inlet and two iliac outlets
    as_vtp = describe_surface(*read_surface(aorta_dir / "aorta-surface.vtp"))
    assert as_vtp.capped and as_vtp.faces == 12932


def test_the_description_from_the_end_planes_edge_table_is_the_one_sorted_afresh(aorta_dir):
    import trimesh

    from softdesign.geometry.edges import EdgeTable

    # the open aorta (boundary loops), and an open tube with a face repeated (a non-manifold edge)
    tube = trimesh.creation.cylinder(radius=3.0, height=4.0, sections=24)
    side = np.asarray(tube.faces)[np.abs(np.abs(tube.triangles_center[:, 2]) - 2.0) > 1e-9]
    for vertices, faces in (read_surface(aorta_dir / "aorta-surface-open-ends.stl"),
                            (np.asarray(tube.vertices), np.concatenate([side, side[:1]]))):
        table = EdgeTable.of(np.asarray(faces, np.int64), len(vertices))
        with_table, afresh = describe_surface(vertices, faces, table), describe_surface(vertices, faces)
        assert with_table.as_dict() == afresh.as_dict()
        assert afresh.boundary_loops >= 2
    assert afresh.nonmanifold_edges == 2  # the repeated face's two edges in the wall (its rim edge: two faces now)
