"""Initial shapes and blends: known answers for straight -> arc, then keyframes, invariants and errors."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from scipy.integrate import quad

from softdesign.errors import ConfigError, GeometryError
from softdesign.geometry.blend import blend_shapes
from softdesign.geometry.curves import CurveOptions, smooth_curve_from_polyline, smooth_curve_from_samples
from softdesign.geometry.frames import base_normal_from_tangent, frame_from_tangent
from softdesign.geometry.initial import (
    InitialSpec,
    arc_initial_shape,
    build_initial_shape,
    initial_shape_from_polyline,
    straight_initial_shape,
)
from softdesign.geometry.se3 import rotation_from_rotvec

#: Exact compositions (coefficient blends, rigid moves) agree to rounding of ~100 mm coordinates.
ROUND_MM = 1e-11
#: A quintic through samples every 0.5 mm of a circle of radius >= 20 mm: ~1e-8 mm interpolation error.
SPLINE_MM = 1e-7

RADIUS, LENGTH = 30.0, 60.0
BASE = np.array([5.0, -2.0, 7.0])
TANGENT = np.array([0.3, -0.4, 0.866])
TANGENT = TANGENT / np.linalg.norm(TANGENT)


def analytic_arc(s: np.ndarray, radius: float, towards: np.ndarray) -> np.ndarray:
    return BASE + np.outer(radius * np.sin(s / radius), TANGENT) + np.outer(radius * (1 - np.cos(s / radius)), towards)


@pytest.fixture(scope="module")
def frame0() -> np.ndarray:
    return frame_from_tangent(TANGENT, base_normal_from_tangent(TANGENT))


@pytest.fixture(scope="module")
def final(frame0):
    """An arc of radius 30 mm, 60 mm long, from BASE along TANGENT, bending towards B0 (phi = pi/2)."""
    s = np.linspace(0, LENGTH, 3001)
    options = CurveOptions(spacing_mm=0.5, smoothing_mm=0.0)
    return smooth_curve_from_polyline(analytic_arc(s, RADIUS, frame0[:, 1]), options)


def test_straight_initial_shape_is_registered_and_as_long_as_final(final):
    straight = straight_initial_shape(final)
    assert np.array_equal(straight.spline.t, final.spline.t)
    l = np.linspace(0, 1, 11)
    # registered to the final spline's own base point and tangent (its end tangent is within 1e-10 of TANGENT)
    base, tangent = final.points([0.0])[0], final.tangents([0.0])[0]
    np.testing.assert_allclose(straight.points(l), base + np.outer(l * final.length, tangent), rtol=0, atol=ROUND_MM)
    shorter = straight_initial_shape(final, length_mm=40.0)
    np.testing.assert_allclose(shorter.length, 40.0, rtol=0, atol=ROUND_MM)


def test_arc_initial_shape_bends_in_the_plane_measured_from_the_base_normal(final, frame0):
    phi, radius = 0.6, 45.0
    arc = arc_initial_shape(final, bend_radius_mm=radius, bend_plane_rad=phi)
    towards = np.cos(phi) * frame0[:, 0] + np.sin(phi) * frame0[:, 1]
    l = np.linspace(0, 1, 13)
    np.testing.assert_allclose(arc.points(l), analytic_arc(l * final.length, radius, towards), rtol=0, atol=SPLINE_MM)
    np.testing.assert_allclose(arc.curvature(arc.dense_l()), 1 / radius, rtol=1e-6, atol=0)
    # the final shape of this module is the phi = pi/2 arc of radius 30: the same builder reproduces it
    again = arc_initial_shape(final, bend_radius_mm=RADIUS, bend_plane_rad=np.pi / 2)
    np.testing.assert_allclose(again.points(l), final.points(l), rtol=0, atol=SPLINE_MM)
    with pytest.raises(ConfigError, match="turns more than once.*bend_radius_mm >= 9.549"):
        arc_initial_shape(final, bend_radius_mm=5.0)


def test_initial_shape_from_a_polyline_is_registered_with_roll(final):
    rng = np.random.default_rng(8)
    z = np.linspace(0, 50, 200)
    drawn = np.column_stack([0.01 * z**2, np.zeros_like(z), z])  # bends towards +x, tangent +z at the start
    moved = drawn @ rotation_from_rotvec(rng.normal(size=3)).T + rng.normal(scale=30, size=3)
    options = CurveOptions(smoothing_mm=0.0)
    shape = initial_shape_from_polyline(final, moved, options)
    assert np.array_equal(shape.spline.t, final.spline.t)
    np.testing.assert_allclose(shape.points([0.0])[0], final.points([0.0])[0], rtol=0, atol=ROUND_MM)
    np.testing.assert_allclose(shape.tangents([0.0])[0], final.tangents([0.0])[0], rtol=0, atol=1e-12)
    # rolling it turns its initial bending direction about the base tangent by the roll angle
    rolled = initial_shape_from_polyline(final, moved, options, roll_rad=0.5)
    k0, k1 = shape.curvature_vectors([0.0])[0], rolled.curvature_vectors([0.0])[0]
    roll = rotation_from_rotvec(0.5 * final.tangents([0.0])[0])
    np.testing.assert_allclose(k1, roll @ k0, rtol=0, atol=1e-12)
    as_drawn = initial_shape_from_polyline(final, moved, options, align_base=False)
    np.testing.assert_allclose(as_drawn.points([0.0])[0], moved[0], rtol=0, atol=ROUND_MM)
    via_spec = build_initial_shape(final, InitialSpec(kind="file", points=moved), options)
    np.testing.assert_allclose(via_spec.points(final.l_grid), shape.points(final.l_grid), rtol=0, atol=0)


def test_linear_blend_is_the_seed_formula_exactly_at_any_l(final):
    straight = straight_initial_shape(final)
    shape = blend_shapes(straight, final)
    l = np.random.default_rng(1).uniform(0, 1, 200)
    for q in (0.0, 0.3, 1.0):
        expected = (1 - q) * straight.points(l) + q * final.points(l)
        np.testing.assert_allclose(shape.smooth_curve_at(q).points(l), expected, rtol=0, atol=ROUND_MM)


def test_linear_blend_shortens_and_intrinsic_keeps_the_length(final, frame0):
    straight = straight_initial_shape(final)
    linear, intrinsic = blend_shapes(straight, final), blend_shapes(straight, final, mode="intrinsic")

    # independent length of (1 - q) straight + q arc by adaptive quadrature on the analytic derivative
    def analytic_length(q: float) -> float:
        def speed(s):
            d = (1 - q) * TANGENT + q * (np.cos(s / RADIUS) * TANGENT + np.sin(s / RADIUS) * frame0[:, 1])
            return np.linalg.norm(d)
        return quad(speed, 0, LENGTH, epsabs=1e-12, epsrel=1e-13)[0]

    np.testing.assert_allclose(linear.smooth_curve_at(0.5).length, analytic_length(0.5), rtol=0, atol=SPLINE_MM)
    shortening = linear.shortening()
    # by symmetry of |(1 - q) a + q b| the shortest shape is at q = 1/2 for equal lengths
    np.testing.assert_allclose(shortening.q_at_min, 0.5, rtol=0, atol=1e-4)
    np.testing.assert_allclose(shortening.ratio, 1 - analytic_length(0.5) / LENGTH, rtol=0, atol=1e-8)
    assert shortening.ratio > 0.05
    # intrinsic: length (1 - q) L0 + q Lf = L at every q, and the shape at q is the arc of radius R / q
    assert intrinsic.shortening().ratio < 1e-12
    for q in (0.25, 0.5, 0.75):
        curve = intrinsic.smooth_curve_at(q)
        np.testing.assert_allclose(curve.length, LENGTH, rtol=0, atol=SPLINE_MM)
        l = np.linspace(0, 1, 17)
        np.testing.assert_allclose(curve.points(l), analytic_arc(l * LENGTH, RADIUS / q, frame0[:, 1]),
                                   rtol=0, atol=1e-6)  # Magnus steps of 0.0625 mm + two interpolations
        stats = intrinsic.stats_at(q)
        np.testing.assert_allclose([stats.stretch_min, stats.stretch_max], 1.0, rtol=0, atol=1e-6)
        np.testing.assert_allclose(stats.curvature_max_per_mm, q / RADIUS, rtol=1e-5, atol=0)
    linear_stats = linear.stats_at(0.5)
    assert linear_stats.stretch_min < 1 - shortening.ratio < linear_stats.stretch_max


def test_intrinsic_reproduces_its_key_shapes(final):
    straight = straight_initial_shape(final)
    intrinsic = blend_shapes(straight, final, mode="intrinsic")
    l = final.dense_l()
    np.testing.assert_allclose(intrinsic.smooth_curve_at(1.0).points(l), final.points(l), rtol=0, atol=1e-7)
    np.testing.assert_allclose(intrinsic.smooth_curve_at(0.0).points(l), straight.points(l), rtol=0, atol=1e-9)


def test_keyframes_are_reached_and_blended_piecewise(final):
    straight = straight_initial_shape(final)
    key = arc_initial_shape(final, bend_radius_mm=50.0, bend_plane_rad=-1.0)
    shape = blend_shapes(straight, final, keyframes=((0.4, key),))
    l = np.linspace(0, 1, 31)
    np.testing.assert_allclose(shape.smooth_curve_at(0.4).points(l), key.points(l), rtol=0, atol=ROUND_MM)
    np.testing.assert_allclose(shape.smooth_curve_at(0.2).points(l), 0.5 * (straight.points(l) + key.points(l)),
                               rtol=0, atol=ROUND_MM)
    np.testing.assert_allclose(shape.smooth_curve_at(0.7).points(l), 0.5 * (key.points(l) + final.points(l)),
                               rtol=0, atol=ROUND_MM)
    intrinsic = blend_shapes(straight, final, keyframes=((0.4, key),), mode="intrinsic")
    np.testing.assert_allclose(intrinsic.smooth_curve_at(0.4).points(l), key.points(l), rtol=0, atol=1e-7)


def test_base_frame_is_the_same_at_every_q(final):
    # linear: exact; intrinsic: the spline through the integrated samples has its end tangent
    # right to the interpolation error at an end (~1e-11 here), so the base frame to 1e-9
    for mode, tol in (("linear", 1e-12), ("intrinsic", 1e-9)):
        shape = blend_shapes(straight_initial_shape(final), final, mode=mode)
        poses = np.array([shape.curve_at(q).poses([0.0])[0] for q in np.linspace(0, 1, 6)])
        np.testing.assert_allclose(poses, np.broadcast_to(poses[-1], poses.shape), rtol=0, atol=tol)
        steps = [shape.curve_at(q).max_frame_step for q in np.linspace(0, 1, 6)]
        assert max(steps) < 0.01  # no flips: 0.0625 mm steps on curvature <= 1/30 /mm


def test_blend_errors_say_what_to_do(final):
    straight = straight_initial_shape(final)
    other_grid = smooth_curve_from_samples(straight.points(np.linspace(0, 1, 50)))
    with pytest.raises(GeometryError, match=r"q = 0 has 50 samples, the final shape 121.*final shape's count"):
        blend_shapes(other_grid, final)
    with pytest.raises(ConfigError, match="blend must be one of linear, intrinsic, got 'cubic'"):
        blend_shapes(straight, final, mode="cubic")
    with pytest.raises(ConfigError, match=r"strictly between 0 and 1"):
        blend_shapes(straight, final, keyframes=((1.0, straight),))
    with pytest.raises(ConfigError, match=r"q must lie in \[0, 1\], got 1.5"):
        blend_shapes(straight, final).curve_at(1.5)


@pytest.mark.parametrize(
    ("spec", "words"),
    [
        (InitialSpec(kind="arc"), "kind: arc needs initial.bend_radius_mm"),
        (InitialSpec(kind="file"), "kind: file needs initial.centerline"),
        (InitialSpec(kind="file", points=np.arange(12.0).reshape(4, 3), length_mm=10.0),
         "initial.length_mm = 10 applies to kind straight or arc"),
        (InitialSpec(kind="straight", length_mm=-1.0), "initial.length_mm must be > 0 mm, got -1"),
        (InitialSpec(kind="coil"), "initial.kind must be one of straight, arc, file, got 'coil'"),
    ],
)
def test_initial_spec_errors_name_the_field(final, spec, words):
    with pytest.raises(ConfigError, match=words):
        build_initial_shape(final, spec)


def test_stats_over_a_range_shorter_than_a_dense_step(final):
    shape = blend_shapes(straight_initial_shape(final), final)
    stats = shape.stats_at(1.0, (0.5, 0.5001))
    np.testing.assert_allclose(stats.length_mm, 0.0001 * final.length, rtol=1e-9, atol=0)
    np.testing.assert_allclose(stats.curvature_max_per_mm, 1 / RADIUS, rtol=1e-6, atol=0)


@pytest.mark.parametrize("mode", ["linear", "intrinsic"])
def test_the_links_stats_at_once_are_each_links_own_bit_for_bit(final, mode):
    # kinematics asks for every link's figures at one q in one call: the same numbers as one call per link
    shape = blend_shapes(straight_initial_shape(final), final, mode=mode)
    breaks = np.array([0.0, 0.1234, 0.3, 0.5001, 0.5002, 1.0])  # a link shorter than a dense step too
    for q in (0.0, 0.37, 1.0):
        together = shape.stats_of_links(q, breaks)
        own = [shape.stats_at(q, (float(lo), float(hi))) for lo, hi in zip(breaks[:-1], breaks[1:], strict=True)]
        assert together == own


def test_a_kept_curve_is_the_one_curve_at_returns(final):
    # a stage's worker processes build the curves; the build process keeps them instead of building them again
    straight = straight_initial_shape(final)
    built = blend_shapes(straight, final).curve_at(0.3)
    shape = blend_shapes(straight, final)
    shape.keep_curve(0.3, pickle.loads(pickle.dumps(built)))
    kept = shape.curve_at(0.3)
    assert shape.smooth_curve_at(0.3) is kept.curve
    l = np.linspace(0.0, 1.0, 7)
    assert np.array_equal(kept.frames(l), built.frames(l)) and np.array_equal(kept.points(l), built.points(l))
    shape.keep_curve(0.3, built)  # the first one kept stays
    assert shape.curve_at(0.3) is kept
