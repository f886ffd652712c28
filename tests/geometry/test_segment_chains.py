"""Segments joined into VMTK's layout (one path from the inlet to each outlet): order, repeats, loops."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import InputDataError
from softdesign.geometry.segment_chains import chain_segments


def _y() -> tuple[np.ndarray, np.ndarray]:
    """A Y: trunk 0-1-2-3 (inlet 0), branches 3-4-5 and 3-6-7, as shuffled, duplicated, reversed segments."""
    points = np.array([[0, 0, 0], [0, 0, 1], [0, 0, 2], [0, 0, 3], [1, 0, 4], [2, 0, 5], [-1, 0, 4], [-2, 0, 5]],
                      float)
    segments = np.array([[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [1, 0], [2, 3], [3, 6], [7, 6]])
    return points, segments


def test_a_y_gives_one_path_per_outlet_from_the_first_point():
    points, segments = _y()
    chains = chain_segments(points, segments, None, "y")
    assert [points[chains.first_ids[p]].tolist() for p in chains.paths] == [
        points[[0, 1, 2, 3, 4, 5]].tolist(), points[[0, 1, 2, 3, 6, 7]].tolist()]
    assert chains.segments == 7  # the repeated and reversed trunk segments count once


def test_repeated_points_are_merged_and_the_widest_end_is_the_inlet_when_the_first_point_is_inside():
    points, segments = _y()
    copies = np.concatenate([points, points[[3]] + 1e-9])  # point 8: a writer's copy of the junction
    segments = np.concatenate([[[2, 1]], segments, [[8, 4]]])  # the file starts inside the trunk
    radius = np.array([5.0, 4.0, 4.0, 4.0, 3.0, 2.0, 3.0, 2.5, 4.0])
    chains = chain_segments(copies, segments, radius, "y")
    assert len(chains.points) == 8
    starts = {tuple(chains.points[p[0]]) for p in chains.paths}
    assert starts == {(0.0, 0.0, 0.0)}  # the widest end, 5 mm
    assert sorted(len(p) for p in chains.paths) == [6, 6]


def test_a_loop_is_refused_with_the_place():
    points = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    with pytest.raises(InputDataError, match="close a loop .* 4 points and 4 segments"):
        chain_segments(points, np.array([[0, 1], [1, 2], [2, 3], [3, 0]]), None, "ring.vtk")


def test_separate_pieces_each_give_their_paths():
    points, segments = _y()
    far = points + 100.0
    chains = chain_segments(np.concatenate([points, far]), np.concatenate([segments, segments + 8]), None, "two")
    assert len(chains.paths) == 4
