"""Centerlines of 2-point segments (gmsh's export of VMTK centerlines) read as VMTK's layout, in three containers."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import InputDataError
from softdesign.io.centerline import read_centerline_network
from tests.helpers.segment_files import segments_of, write_segments


def _distinct(points: np.ndarray) -> np.ndarray:
    keep = np.concatenate([[True], np.linalg.norm(np.diff(points, axis=0), axis=1) > 1e-9])
    return points[keep]


@pytest.mark.parametrize("suffix", [".vtk", ".vtu", ".vtp"])
@pytest.mark.parametrize("with_radius", [False, True])
def test_vmtk_aorta_as_segments_reads_as_vmtk_paths(aorta_dir, tmp_path, suffix, with_radius):
    vmtk = read_centerline_network(aorta_dir / "aorta-centerline.vtp").polylines
    points, segments = segments_of([p.points for p in vmtk])
    radius = np.concatenate([p.radius for p in vmtk]) if with_radius else None
    network = read_centerline_network(write_segments(tmp_path / f"cl{suffix}", points, segments, radius))
    assert len(network.polylines) == 2
    for ours, theirs in zip(network.polylines, vmtk, strict=True):
        expected = _distinct(theirs.points)  # VMTK ends path 0 with a repeated point, which joining merges
        assert ours.points.shape == expected.shape
        np.testing.assert_allclose(ours.points, expected, rtol=0, atol=1e-6)  # legacy ASCII keeps 11 digits
        assert (ours.radius is not None) == with_radius
        if with_radius:
            np.testing.assert_allclose(ours.radius, _distinct_radius(theirs), rtol=0, atol=1e-6)
    assert len(network.notes) == 1 and "joined into 2 path(s)" in network.notes[0]


def _distinct_radius(line) -> np.ndarray:
    keep = np.concatenate([[True], np.linalg.norm(np.diff(line.points, axis=0), axis=1) > 1e-9])
    return line.radius[keep]


def test_vmtk_polylines_are_read_as_before(aorta_dir):
    network = read_centerline_network(aorta_dir / "aorta-centerline.vtp")
    assert [len(p.points) for p in network.polylines] == [211, 198] and network.notes == ()


def test_segments_that_join_into_no_path_are_refused(tmp_path):
    points = np.array([[0, 0, 0], [0, 0, 1], [5, 0, 0], [5, 0, 1], [9, 0, 0], [9, 0, 2]], float)
    path = write_segments(tmp_path / "bits.vtk", points, np.array([[0, 1], [2, 3], [4, 5]]))
    with pytest.raises(InputDataError, match=r"3 line cells are short segments that join into no path of 4 points "
                                             r"or more \(the longest joins 2\)"):
        read_centerline_network(path)
