"""Smooth curves by arc length: known answers (circle, helix, line), then smoothing, end handling, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import ConfigError, GeometryError
from softdesign.geometry.curves import (
    TORSION_KAPPA_FLOOR,
    CurveOptions,
    l_from_points,
    measure_deviation,
    smooth_curve_from_polyline,
    smooth_curve_from_samples,
)

#: Interpolating a dense, exact polyline (smoothing 0): positions agree to far below a micrometre.
EXACT_MM = 1e-8
#: Relative accuracy of curvature/torsion from a spline through exact samples every 0.5 mm.
EXACT_REL = 1e-4
#: The issue's bound for the helix.
HELIX_REL = 5e-3


def circle_points(radius: float, length: float, count: int) -> np.ndarray:
    s = np.linspace(0.0, length, count)
    return np.column_stack([radius * np.cos(s / radius), radius * np.sin(s / radius), np.zeros_like(s)])


def helix_points(a: float, b: float, length: float, count: int) -> np.ndarray:
    c = np.hypot(a, b)
    s = np.linspace(0.0, length, count)
    return np.column_stack([a * np.cos(s / c), a * np.sin(s / c), b * s / c])


def test_circle_has_curvature_one_over_radius_and_its_arc_length():
    radius, length = 12.0, 60.0
    curve = smooth_curve_from_polyline(circle_points(radius, length, 2001), CurveOptions(smoothing_mm=0.0))
    l = curve.dense_l()
    np.testing.assert_allclose(curve.length, length, rtol=0, atol=EXACT_MM * 100)
    np.testing.assert_allclose(curve.curvature(l), 1.0 / radius, rtol=EXACT_REL, atol=0)
    np.testing.assert_allclose(curve.torsion(l), 0.0, rtol=0, atol=EXACT_REL / radius)
    # l is normalized arc length: the point at l is the circle point at s = l * length
    expected = circle_points(radius, length, 2001)[::40]
    np.testing.assert_allclose(curve.points(np.linspace(0, 1, 51)), expected, rtol=0, atol=1e-7)


def test_helix_curvature_and_torsion_within_half_a_percent():
    a, b = 10.0, 3.0
    c2 = a * a + b * b
    # VMTK-like input: a point every 0.375 mm
    curve = smooth_curve_from_polyline(helix_points(a, b, 150.0, 401), CurveOptions(spacing_mm=0.5, smoothing_mm=0.0))
    l = curve.dense_l()
    np.testing.assert_allclose(curve.curvature(l), a / c2, rtol=HELIX_REL, atol=0)
    np.testing.assert_allclose(curve.torsion(l), b / c2, rtol=HELIX_REL, atol=0)
    report = curve.report()
    np.testing.assert_allclose(report.length_mm, 150.0, rtol=0, atol=1e-6)
    np.testing.assert_allclose(report.max_curvature_per_mm, a / c2, rtol=HELIX_REL, atol=0)
    np.testing.assert_allclose(report.max_abs_torsion_per_mm, b / c2, rtol=HELIX_REL, atol=0)


def test_straight_line_has_zero_curvature_and_undefined_torsion():
    z = np.linspace(0.0, 30.0, 7)
    curve = smooth_curve_from_polyline(np.column_stack([z, 2 * z, -z]), CurveOptions(smoothing_mm=0.0))
    l = curve.dense_l()
    np.testing.assert_allclose(curve.curvature(l), 0.0, rtol=0, atol=1e-12)
    assert np.all(np.isnan(curve.torsion(l)))  # no binormal on a straight line, hence no torsion
    report = curve.report()
    assert report.max_abs_torsion_per_mm is None and report.max_abs_torsion_l is None
    assert report.torsion_defined_fraction == 0.0


@pytest.mark.parametrize("radius, defined", [(0.5 / TORSION_KAPPA_FLOOR, True), (2.0 / TORSION_KAPPA_FLOOR, False)])
def test_torsion_is_reported_only_where_curvature_exceeds_the_floor(radius, defined):
    # arcs of 500 mm and 2 m radius (kappa twice and half the floor), 100 mm long
    curve = smooth_curve_from_polyline(circle_points(radius, 100.0, 201), CurveOptions(smoothing_mm=0.0))
    l = curve.dense_l()
    tau, report = curve.torsion(l), curve.report()
    if defined:
        np.testing.assert_allclose(tau, 0.0, rtol=0, atol=EXACT_REL / radius)  # a plane curve
        assert report.torsion_defined_fraction == 1.0 and report.max_abs_torsion_per_mm < EXACT_REL / radius
    else:
        assert np.all(np.isnan(tau))
        assert report.max_abs_torsion_per_mm is None and report.torsion_defined_fraction == 0.0


def test_resampling_count_spacing_and_uniform_speed():
    points = circle_points(12.0, 60.0, 301)
    by_count = smooth_curve_from_polyline(points, CurveOptions(count=37, smoothing_mm=0.0))
    assert len(by_count.l_grid) == 37
    by_spacing = smooth_curve_from_polyline(points, CurveOptions(spacing_mm=0.7, smoothing_mm=0.0))
    # ceil(60 / 0.7) = 86 intervals: the spacing actually used is <= the one asked for
    assert len(by_spacing.l_grid) == 87
    assert by_spacing.report().spacing_mm <= 0.7
    # l is arc length up to the interpolation error: |dc/dl| equals the length
    np.testing.assert_allclose(by_spacing.speed(by_spacing.dense_l()), by_spacing.length, rtol=1e-6, atol=0)


def test_same_count_gives_the_same_knots_so_blends_are_exact():
    one = smooth_curve_from_polyline(circle_points(12.0, 60.0, 301), CurveOptions(count=50, smoothing_mm=0.0))
    other = smooth_curve_from_polyline(helix_points(5.0, 1.0, 40.0, 301), CurveOptions(count=50, smoothing_mm=0.0))
    np.testing.assert_array_equal(one.spline.t, other.spline.t)
    mixed = smooth_curve_from_samples(0.3 * one.points(one.l_grid) + 0.7 * other.points(other.l_grid))
    np.testing.assert_allclose(mixed.spline.c, 0.3 * one.spline.c + 0.7 * other.spline.c, rtol=0, atol=1e-12)


def test_smoothing_keeps_rms_deviation_within_the_allowed_mm_and_removes_noise():
    radius, noise, allowed = 20.0, 0.05, 0.1
    truth = circle_points(radius, 100.0, 251)
    rng = np.random.default_rng(7)
    noisy = truth + rng.normal(scale=noise, size=truth.shape)
    curve = smooth_curve_from_polyline(noisy, CurveOptions(smoothing_mm=allowed))
    deviation = measure_deviation(curve, noisy)
    assert np.sqrt(np.mean(deviation**2)) <= allowed
    assert measure_deviation(curve, truth).max() < 3 * allowed
    l = curve.dense_l()
    inner = (l > 0.1) & (l < 0.9)
    # interior curvature within 5 % with noise 1/400 of the radius; the last 10 % at each end is
    # where any smoothing spline is least constrained (the reason for end_straight_mm)
    np.testing.assert_allclose(curve.curvature(l[inner]), 1.0 / radius, rtol=0.05, atol=0)
    raw = smooth_curve_from_polyline(noisy, CurveOptions(smoothing_mm=0.0))
    assert raw.curvature(l[inner]).max() > 10.0 / radius  # unsmoothed noise: curvature spikes


def test_end_straight_keeps_length_and_makes_the_ends_straight():
    radius, length, end = 12.0, 60.0, 3.0
    points = circle_points(radius, length, 2001)
    plain = smooth_curve_from_polyline(points, CurveOptions(spacing_mm=0.25, smoothing_mm=0.0))
    trimmed = smooth_curve_from_polyline(points, CurveOptions(spacing_mm=0.25, smoothing_mm=0.0, end_straight_mm=end))
    # the samples keep the arc length exactly; the spline through them rounds the curvature jump
    # at each trim point (h = 0.25 mm, jump 1/12 /mm) and loses about 1.5e-6 mm there
    np.testing.assert_allclose(trimmed.length, plain.length, rtol=0, atol=1e-5)
    # the first sample is the trim point moved back along its tangent by end_straight_mm
    s_trim = end / length
    theta = end / radius
    trim_point = np.array([radius * np.cos(theta), radius * np.sin(theta), 0.0])
    trim_tangent = np.array([-np.sin(theta), np.cos(theta), 0.0])
    np.testing.assert_allclose(trimmed.points([0.0])[0], trim_point - end * trim_tangent, rtol=0, atol=1e-9)
    np.testing.assert_allclose(trimmed.points([s_trim])[0], trim_point, rtol=0, atol=1e-6)
    # well inside the straight part the curvature vanishes; away from the ends it is the circle's
    l = trimmed.dense_l()
    straight = l < 0.5 * s_trim
    assert trimmed.curvature(l[straight]).max() < 0.02 / radius
    middle = (l > 2 * s_trim) & (l < 1 - 2 * s_trim)
    np.testing.assert_allclose(trimmed.curvature(l[middle]), 1.0 / radius, rtol=1e-4, atol=0)


def test_foot_points_of_points_off_a_circle_are_known():
    radius, length = 12.0, 60.0
    curve = smooth_curve_from_polyline(circle_points(radius, length, 2001), CurveOptions(smoothing_mm=0.0))
    s = np.random.default_rng(4).uniform(0, length, 50)
    offset = np.random.default_rng(5).uniform(-3, 3, 50)
    # points on the circle's normal lines (radially in or out, plus a z offset): the foot is s itself
    points = np.column_stack([(radius + offset) * np.cos(s / radius), (radius + offset) * np.sin(s / radius), offset])
    np.testing.assert_allclose(l_from_points(curve, points), s / length, rtol=0, atol=1e-9)
    np.testing.assert_allclose(measure_deviation(curve, points), np.sqrt(2) * np.abs(offset), rtol=0, atol=1e-7)
    # beyond the ends the foot is clamped to the end
    before = circle_points(radius, length, 2)[0] - np.array([0.0, 5.0, 0.0])
    np.testing.assert_allclose(l_from_points(curve, before[None]), [0.0], rtol=0, atol=0)


def test_duplicates_are_skipped_and_deviation_of_exact_data_is_nil():
    points = circle_points(12.0, 30.0, 61)
    doubled = np.repeat(points, 2, axis=0)
    curve = smooth_curve_from_polyline(doubled, CurveOptions(smoothing_mm=0.0))
    assert measure_deviation(curve, points).max() < 1e-6
    assert np.array_equal(doubled, np.repeat(points, 2, axis=0))  # input untouched


@pytest.mark.parametrize(
    ("points", "options", "error", "words"),
    [
        (np.zeros((3, 3)), CurveOptions(), GeometryError, ["at least 4 distinct points", "got 1"]),
        (np.full((10, 3), np.nan), CurveOptions(), GeometryError, ["finite (n, 3)"]),
        (np.zeros((10, 2)), CurveOptions(), GeometryError, ["(n, 3)", "(10, 2)"]),
        (circle_points(5, 20, 50), CurveOptions(count=5), ConfigError, ["resample.count", ">= 6", "got 5"]),
        (circle_points(5, 20, 50), CurveOptions(spacing_mm=0), ConfigError, ["spacing_mm", "> 0", "got 0"]),
        (circle_points(5, 20, 50), CurveOptions(smoothing_mm=-1), ConfigError, ["smoothing_mm", "got -1"]),
        (circle_points(5, 20, 50), CurveOptions(end_straight_mm=10), ConfigError, ["end_straight_mm = 10", "half"]),
    ],
)
def test_bad_input_names_the_field_and_the_value(points, options, error, words):
    with pytest.raises(error) as caught:
        smooth_curve_from_polyline(points, options)
    for word in words:
        assert word in str(caught.value)


def test_l_outside_unit_interval_is_refused():
    curve = smooth_curve_from_polyline(circle_points(12.0, 30.0, 61), CurveOptions(smoothing_mm=0.0))
    with pytest.raises(ConfigError, match=r"in \[0, 1\].*1\.5"):
        curve.points([0.2, 1.5])


# -- joints: a link break at a curvature jump (issue 35 item 4) ---------------------------------------------
def corner_points(spacing: float = 0.5) -> tuple[np.ndarray, float]:
    """A 20 mm straight run, then a quarter of a 10 mm circle in the x-z plane: curvature 0 -> 0.1 /mm at z = 20.

    Returns the vertices (every ``spacing`` mm of arc, the corner among them) and the corner's l.
    """
    line = np.column_stack([np.zeros(40), np.zeros(40), np.arange(40) * spacing])
    angle = np.arange(0, int(round(5 * np.pi / spacing)) + 1) * spacing / 10.0
    arc = np.column_stack([10.0 * (1 - np.cos(angle)), np.zeros_like(angle), 20.0 + 10.0 * np.sin(angle)])
    return np.concatenate([line, arc]), 20.0 / (20.0 + angle[-1] * 10.0)


def test_a_joint_is_a_knot_of_full_multiplicity_and_each_side_keeps_its_own_curvature():
    points, corner = corner_points()
    length = 20.0 + 10.0 * (len(points) - 41) * 0.05
    options = CurveOptions(spacing_mm=length / (len(points) - 1), smoothing_mm=0.0, end_straight_mm=0.0)
    curve = smooth_curve_from_polyline(points, options, [0.0, corner, 1.0])
    assert curve.joints == (40,)
    l_joint = curve.l_grid[40]
    assert np.count_nonzero(curve.spline.t == l_joint) == curve.spline.k + 1
    np.testing.assert_allclose(curve.points([l_joint])[0], [0.0, 0.0, 20.0], rtol=0, atol=EXACT_MM)
    step = 1e-9
    before, after = curve.curvature([l_joint - step, l_joint + step])
    assert before <= 1e-6 and abs(after - 0.1) <= 1e-6  # the jump is kept, not smoothed over
    # the tangent is continuous at the joint (both sides interpolate their own exact data)
    t_before, t_after = curve.tangents([l_joint - step, l_joint + step])
    assert np.linalg.norm(t_before - t_after) <= 1e-6
    smoothed = smooth_curve_from_polyline(points, options)
    assert smoothed.joints == () and smoothed.curvature([l_joint - step])[0] > 1e-3  # what it was


def test_a_break_off_every_vertex_or_off_the_grid_is_smoothed_over_as_before():
    points, corner = corner_points()
    options = CurveOptions(spacing_mm=0.5, smoothing_mm=0.0, end_straight_mm=0.0)
    plain = smooth_curve_from_polyline(points, options)
    for breaks in ([0.0, 0.3, 1.0], [0.0, corner + 1e-3, 1.0]):
        curve = smooth_curve_from_polyline(points, options, breaks)
        assert curve.joints == ()
        assert np.array_equal(curve.spline.c, plain.spline.c) and np.array_equal(curve.spline.t, plain.spline.t)


def test_samples_rebuilt_with_their_joints_give_the_same_spline():
    points, corner = corner_points()
    length = 20.0 + 10.0 * (len(points) - 41) * 0.05
    options = CurveOptions(spacing_mm=length / (len(points) - 1), smoothing_mm=0.0, end_straight_mm=0.0)
    curve = smooth_curve_from_polyline(points, options, [corner])
    again = smooth_curve_from_samples(curve.points(curve.l_grid), curve.joints)
    np.testing.assert_allclose(again.spline.c, curve.spline.c, rtol=0, atol=1e-12)
    assert np.array_equal(again.spline.t, curve.spline.t)
    with pytest.raises(GeometryError, match="fewer than 6 samples"):
        smooth_curve_from_samples(curve.points(curve.l_grid), (3,))


@pytest.mark.parametrize("smoothing_mm", [0.05, CurveOptions().smoothing_mm])
def test_a_smoothed_path_keeps_its_joint_sharp_and_through_the_vertex(smoothing_mm):
    points, corner = corner_points()
    options = CurveOptions(spacing_mm=0.5, smoothing_mm=smoothing_mm, end_straight_mm=0.0)
    curve = smooth_curve_from_polyline(points, options, [0.0, corner, 1.0])
    assert curve.joints == (40,)
    l_joint, step = curve.l_grid[40], 1e-9
    assert np.count_nonzero(curve.spline.t == l_joint) == curve.spline.k + 1
    # both pieces are pinned at the joint's vertex: the joint is the data's corner, not an average of two ends
    np.testing.assert_allclose(curve.points([l_joint])[0], [0.0, 0.0, 20.0], rtol=0, atol=EXACT_MM)
    before, after = curve.curvature([l_joint - step, l_joint + step])
    # the straight piece is smoothed on its own (exactly straight); the quarter circle as one quintic within the
    # smoothing's allowance: its curvature within 0.5 %, its start tangent within 3e-4 rad (the smoothing's own
    # error on a 1.55 rad turn, not the corner's: the whole-path smoothing below is 100 times further off)
    assert before <= 1e-9 and abs(after - 0.1) <= 5e-4
    t_before, t_after = curve.tangents([l_joint - step, l_joint + step])
    assert np.linalg.norm(t_before - t_after) <= 3e-4
    smoothed = smooth_curve_from_polyline(points, options)
    assert smoothed.joints == () and 0.03 <= smoothed.curvature([l_joint])[0] <= 0.07  # what it was: rounded
    assert np.linalg.norm(smoothed.points([l_joint])[0] - [0.0, 0.0, 20.0]) > 0.02


def test_a_break_near_a_noisy_vertex_is_smoothed_over_as_before():
    """Noise (0.05 mm) moves the corner vertex's arc length along the path by far more than a joint's 1e-4 spacings:
    a break at the clean corner's l, or at no vertex, is smoothed over with the rest (same knots, same coefficients)."""
    points, corner = corner_points()
    noisy = points + np.random.default_rng(7).normal(0.0, 0.05, points.shape)
    options = CurveOptions(spacing_mm=0.5, smoothing_mm=0.1, end_straight_mm=0.0)
    plain = smooth_curve_from_polyline(noisy, options)
    for breaks in ([0.0, 0.3, 1.0], [0.0, corner, 1.0]):
        curve = smooth_curve_from_polyline(noisy, options, breaks)
        assert curve.joints == ()
        assert np.array_equal(curve.spline.c, plain.spline.c) and np.array_equal(curve.spline.t, plain.spline.t)
