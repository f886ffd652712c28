"""The series channels of a single-supply device: their course, and the rod model's cavity where they run."""

from __future__ import annotations

import numpy as np

from softdesign.kinematics.rod import strains
from softdesign.kinematics.rod_channels import ChannelCourse, series_courses, station_cavities
from softdesign.kinematics.rod_sizing import Limits, Problem, size_single, stations_along

#: Linear interpolation and means of exact samples: rounding only.
EXACT_ATOL = 1e-12
#: The midpoint rule's mean over a station (256 samples): (angle step)^2 / 12 relative at most.
MEAN_ATOL_MM = 1e-5

E = 120.0
ANGLES = 64
LIMITS = Limits(wall_mm=0.5, feed_diameter_mm=0.3, thread_diameter_mm=0.2, max_pressure_kpa=2000.0)


def test_a_course_turns_the_short_way_between_the_two_chambers_axes():
    ends = np.array([[1.0, 9.0], [12.0, 20.0]])
    (course,) = series_courses(ends, np.deg2rad([170.0, -170.0]), np.array([[1.5, 1.4], [1.2, 1.3]]), 0.3)
    assert isinstance(course, ChannelCourse) and course.between == (9.0, 12.0)
    np.testing.assert_allclose(course.s, [9.0 - 0.3, 9.0 + 0.075, 12.0 - 0.075, 12.0 + 0.3], rtol=0, atol=EXACT_ATOL)
    # 20 degrees across the 180-degree line, not 340 the long way
    np.testing.assert_allclose(np.rad2deg(course.angle[2] - course.angle[1]), 20.0, rtol=0, atol=1e-9)
    # on the first chamber's axis at its distal end, on the second's at its proximal end
    np.testing.assert_allclose(course.ring, [1.4, 1.4, 1.2, 1.2], rtol=0, atol=EXACT_ATOL)
    mean_ring = 1.3
    expected = np.arctan2(np.hypot(mean_ring * np.deg2rad(20.0), 0.2), 3.0 - 0.15)
    np.testing.assert_allclose(course.slant_max(), expected, rtol=0, atol=EXACT_ATOL)


def test_a_straight_course_is_one_circle_at_its_ring_in_every_end_wall_station():
    ends = np.array([[1.0, 9.0], [12.0, 20.0]])
    courses = series_courses(ends, np.array([0.5, 0.5]), np.array([[1.5, 1.5], [1.5, 1.5]]), 0.3)
    lower = np.array([0.0, 1.0, 9.0, 10.5, 12.0])
    upper = np.array([1.0, 9.0, 10.5, 12.0, 20.0])
    inside = np.array([True, False, True, True, False])  # station 0 is an end wall before the first chamber
    centres, radii = station_cavities(courses, lower, upper, inside)
    np.testing.assert_allclose(radii[:, 0], [0.0, 0.0, 0.15, 0.15, 0.0], rtol=0, atol=EXACT_ATOL)
    np.testing.assert_allclose(centres[2:4, 0], [[1.5 * np.cos(0.5), 1.5 * np.sin(0.5)]] * 2, rtol=0,
                               atol=EXACT_ATOL)


def test_a_turning_course_loads_a_station_at_its_mean_centre():
    ends = np.array([[0.0, 9.0], [12.0, 20.0]])
    (course,) = series_courses(ends, np.array([0.0, np.pi / 2]), np.full((2, 2), 1.5), 0.2)
    lower, upper = np.array([9.0, 10.5]), np.array([10.5, 12.0])
    centres, _ = station_cavities([course], lower, upper, np.array([True, True]))
    # the angle runs linearly from 0 at s = 9.05 to pi/2 at s = 11.95; the exact mean of 1.5 (cos, sin) over each
    s0, s1 = course.s[1], course.s[2]
    rate = (np.pi / 2) / (s1 - s0)

    def mean(a: float, b: float) -> np.ndarray:
        held = (s0 - a) if a < s0 else 0.0  # at angle 0 before the turn starts
        ta, tb = max(a, s0), min(b, s1)
        turned = np.array([np.sin(rate * (tb - s0)) - np.sin(rate * (ta - s0)),
                           np.cos(rate * (ta - s0)) - np.cos(rate * (tb - s0))]) / rate
        after = (b - s1) if b > s1 else 0.0  # at pi/2 after it
        return 1.5 * (held * np.array([1.0, 0.0]) + turned + after * np.array([0.0, 1.0])) / (b - a)

    np.testing.assert_allclose(centres[:, 0], [mean(9.0, 10.5), mean(10.5, 12.0)], rtol=0, atol=MEAN_ATOL_MM)


def test_a_sized_device_counts_its_channels_in_the_end_walls_and_still_turns_each_section_as_designed():
    lengths = np.array([18.0, 22.0, 20.0])
    kappa, phi = np.array([0.04, 0.02, 0.05]), np.array([0.3, 2.2, -1.4])
    w = np.stack([kappa * np.cos(phi), kappa * np.sin(phi)], axis=1)
    stations = stations_along(lengths, 30, 1.5)
    outlines = np.full((len(stations.ds), ANGLES), 3.2)
    problem = Problem(stations, outlines, w, E, "inextensible", LIMITS)
    device = size_single(problem, 300.0)
    assert len(device.channels) == 2
    walls = ~stations.chamber
    area = np.pi * 0.15**2
    # every end wall between two chambers holds exactly one channel's area per kPa; the first wall the supply line
    force = device.body.force[:, 0]
    between = walls & (stations.s > stations.s[stations.chamber][0])
    between &= stations.s < stations.s[stations.chamber][-1]
    np.testing.assert_allclose(force[between], area, rtol=0, atol=EXACT_ATOL)
    eps0, bend, _ = strains(device.body, [300.0])
    assert np.all(np.hypot(*bend[between].T) > 0)  # the channels bend the end walls they cross
    for i in range(3):  # the chambers make up for it: each section turns through its designed angle
        at = stations.section == i
        turn = np.sum(stations.ds[at, None] * bend[at], axis=0)
        np.testing.assert_allclose(turn, w[i] * lengths[i], rtol=0, atol=1e-9)
