"""The chamber/feed layout: angles, l-ranges, and the analytic walls of a round section."""

from __future__ import annotations

import numpy as np

from softdesign.meshing.chambers.layout import ActuationSpec, analytic_walls, chamber_angles, offset_points, plan_layout

TOL = 1e-12
SPEC = ActuationSpec(distance_mm=2.0, diameter_mm=0.8, feed_diameter_mm=0.4, end_wall_mm=1.0, first_angle_deg=90.0)


def test_angles_interleave_sections_on_one_ring() -> None:
    angles = np.rad2deg(chamber_angles(SPEC, 4))
    np.testing.assert_allclose(angles[0], [90, 210, 330], rtol=0, atol=TOL)
    np.testing.assert_allclose(angles[1] - angles[0], 30.0, rtol=0, atol=TOL)
    wrapped = np.sort(np.mod(angles.reshape(-1), 360.0))
    np.testing.assert_allclose(np.diff(wrapped), 30.0, rtol=0, atol=1e-9)  # 12 distinct angles, 30 deg apart


def test_l_ranges_keep_end_walls_on_a_uniform_body() -> None:
    l = np.linspace(0.0, 1.0, 101)
    layout = plan_layout(SPEC, [0.0, 0.25, 0.5, 0.75, 1.0], l, 40.0 * l)  # a 40 mm body, 10 mm sections
    first = layout.section_chambers(0)[0]
    np.testing.assert_allclose([first.l_start, first.l_end], [1.0 / 40.0, 9.0 / 40.0], rtol=0, atol=TOL)
    assert len(layout.chambers) == 12 and len(layout.feeds) == 12
    assert len(layout.feeds_through(0)) == 9 and len(layout.feeds_through(3)) == 0
    feed = layout.feeds[-1]
    assert feed.l_start == 0.0
    np.testing.assert_allclose(feed.l_end, (31.0 + 0.4) / 40.0, rtol=0, atol=TOL)


def test_analytic_walls_of_a_round_section() -> None:
    walls = analytic_walls(SPEC, 4, 0, radius_mm=2.9)
    d, big, small = 2.0, 0.8, 0.4
    np.testing.assert_allclose(walls.chamber_skin, 2.9 - d - big / 2, rtol=0, atol=TOL)
    np.testing.assert_allclose(walls.chamber_chamber, 2 * d * np.sin(np.pi / 3) - big, rtol=0, atol=TOL)
    chord = 2 * d * np.sin(np.deg2rad(15.0))  # neighbours on the ring are 30 degrees apart
    np.testing.assert_allclose(walls.chamber_feed, chord - (big + small) / 2, rtol=0, atol=TOL)
    np.testing.assert_allclose(walls.feed_feed, chord - small, rtol=0, atol=TOL)
    last = analytic_walls(SPEC, 4, 3, radius_mm=2.9)
    assert np.isinf(last.chamber_feed) and np.isinf(last.feed_feed)


def test_offset_points_on_a_straight_line() -> None:
    centers = np.column_stack([np.zeros(3), np.zeros(3), np.arange(3.0)])
    frames = np.repeat(np.eye(3)[None], 3, axis=0)
    points = offset_points(centers, frames, 2.0, np.pi / 2)
    np.testing.assert_allclose(points[:, :2], [[0.0, 2.0]] * 3, rtol=0, atol=TOL)
