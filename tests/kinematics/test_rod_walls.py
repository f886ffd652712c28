"""The walls of a single-supply cross-section and the gap to the axis thread, on circles placed by hand."""

from __future__ import annotations

import numpy as np

from softdesign.kinematics.rod_walls import THREAD_GAP_DIAMETERS, cavity_walls, thread_gap_mm, thread_gaps

#: Distances between circles placed exactly: rounding only.
EXACT_ATOL = 1e-12


def test_the_thread_gap_rule_is_two_thread_diameters():
    assert THREAD_GAP_DIAMETERS == 2.0
    np.testing.assert_allclose(thread_gap_mm(0.3), 0.6, rtol=0, atol=EXACT_ATOL)


def test_walls_and_the_thread_gap_of_two_circles():
    # a chamber of radius 0.5 at (2, 0) and a feed of radius 0.2 at (0, 1.5) in a skin of radius 3; a 0.3 mm thread
    centers = np.array([[[2.0, 0.0], [0.0, 1.5]]])
    radii = np.array([[0.5, 0.2]])
    walls, kinds = cavity_walls(np.array([3.0]), centers, radii, ["chamber", "feed"])
    between = 2.5 - 0.7  # centres 2.5 apart
    np.testing.assert_allclose(walls, [min(3.0 - 2.5, 3.0 - 1.7, between)], rtol=0, atol=EXACT_ATOL)
    assert kinds == ["chamber-skin"]
    np.testing.assert_allclose(thread_gaps(centers, radii, 0.3), [min(2.0 - 0.5, 1.5 - 0.2) - 0.15], rtol=0,
                               atol=EXACT_ATOL)
    # a gap measured elsewhere (a series channel's course) counts when it is smaller
    np.testing.assert_allclose(thread_gaps(centers, radii, 0.3, np.array([0.9])), [0.9], rtol=0, atol=EXACT_ATOL)


def test_a_station_without_cavities_has_no_wall_and_no_gap():
    walls, _ = cavity_walls(np.array([3.0]), np.zeros((1, 1, 2)), np.zeros((1, 1)), ["chamber"])
    assert np.isinf(walls[0]) and np.isinf(thread_gaps(np.zeros((1, 1, 2)), np.zeros((1, 1)), 0.3)[0])
