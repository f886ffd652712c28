"""Frames along smooth curves: rmf against the helix's analytic RMF, Frenet, base normal, flips, errors."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import ConfigError, GeometryError
from softdesign.geometry.curves import CurveOptions, smooth_curve_from_polyline, smooth_curve_from_samples
from softdesign.geometry.frames import (
    accumulate_rotations,
    adjacent_rotation_angles,
    base_normal_from_tangent,
    check_no_flips,
    framed_curve,
    frenet_frames,
)
from softdesign.geometry.se3 import rotation_from_rotvec

#: Frames are orthonormal to rounding.
ORTHONORMAL_TOL = 1e-12
#: rmf against the analytic RMF of a helix sampled exactly: the issue's ~1e-9 rad on smooth curves.
RMF_TOL_RAD = 1e-9

A, B = 10.0, 3.0
C = np.hypot(A, B)
KAPPA, TAU = A / C**2, B / C**2


def helix(s: np.ndarray) -> np.ndarray:
    return np.column_stack([A * np.cos(s / C), A * np.sin(s / C), B * s / C])


def helix_frenet(s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t = np.column_stack([-A * np.sin(s / C), A * np.cos(s / C), np.full_like(s, B)]) / C
    n = np.column_stack([-np.cos(s / C), -np.sin(s / C), np.zeros_like(s)])
    return n, np.cross(t, n), t


def angle_between(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return np.arctan2(np.linalg.norm(np.cross(u, v), axis=1), np.einsum("ij,ij->i", u, v))


@pytest.fixture(scope="module")
def helix_curve():
    length = 150.0
    options = CurveOptions(spacing_mm=0.1, smoothing_mm=0.0)
    return smooth_curve_from_polyline(helix(np.linspace(0, length, 6001)), options)


def test_rmf_on_a_helix_matches_the_analytic_rotation_minimizing_frame(helix_curve):
    framed = framed_curve(helix_curve)
    l = np.sort(np.random.default_rng(3).uniform(0, 1, 500))  # arbitrary l, not the dense samples
    frames = framed.frames(l)
    s = l * helix_curve.length
    n, b, t = helix_frenet(s)
    # an RMF turns against the Frenet frame at the torsion rate: N_rmf = cos(a) N + sin(a) B, a = a0 - tau s
    n0 = frames[0, :, 0]
    a = np.arctan2(n0 @ b[0], n0 @ n[0]) - TAU * (s - s[0])
    expected = np.cos(a)[:, None] * n + np.sin(a)[:, None] * b
    assert angle_between(frames[:, :, 0], expected).max() < RMF_TOL_RAD
    assert angle_between(frames[:, :, 2], t).max() < RMF_TOL_RAD
    gram = np.swapaxes(frames, 1, 2) @ frames
    np.testing.assert_allclose(gram, np.broadcast_to(np.eye(3), gram.shape), rtol=0, atol=ORTHONORMAL_TOL)
    np.testing.assert_allclose(np.linalg.det(frames), 1.0, rtol=0, atol=ORTHONORMAL_TOL)


def test_frames_between_samples_agree_with_a_finer_chain(helix_curve):
    coarse = framed_curve(helix_curve)
    fine_curve = smooth_curve_from_samples(helix_curve.points(np.linspace(0, 1, 4 * len(helix_curve.l_grid) - 3)))
    fine = framed_curve(fine_curve, base_normal=coarse.dense_frames[0, :, 0])
    l = np.linspace(0, 1, 777)
    assert angle_between(coarse.frames(l)[:, :, 0], fine.frames(l)[:, :, 0]).max() < RMF_TOL_RAD
    # evaluating exactly at a stored sample gives the stored frame
    np.testing.assert_allclose(coarse.frames(coarse.dense_l[[0, 5, -1]]), coarse.dense_frames[[0, 5, -1]],
                               rtol=0, atol=ORTHONORMAL_TOL)


def test_frenet_on_a_helix_is_the_analytic_frenet_frame(helix_curve):
    framed = framed_curve(helix_curve, mode="frenet")
    l = np.linspace(0, 1, 301)
    n, b, t = helix_frenet(l * helix_curve.length)
    frames = framed.frames(l)
    for column, expected in enumerate((n, b, t)):
        np.testing.assert_allclose(frames[:, :, column], expected, rtol=0, atol=1e-9)
    # Frenet turns about T at the torsion rate on top of the bending: its largest step shows it
    step = helix_curve.length * (framed.dense_l[1] - framed.dense_l[0])
    np.testing.assert_allclose(framed.max_frame_step, np.hypot(KAPPA, TAU) * step, rtol=1e-6, atol=0)


def test_base_normal_rule_is_deterministic_and_can_be_overridden():
    np.testing.assert_array_equal(base_normal_from_tangent([0, 0, 1]), [1, 0, 0])
    t = np.array([1.0, 0.2, 0.1]) / np.sqrt(1.05)
    z_off_t = np.array([0.0, 0.0, 1.0]) - t[2] * t  # z is the least aligned axis
    np.testing.assert_allclose(base_normal_from_tangent([1, 0.2, 0.1]), z_off_t / np.linalg.norm(z_off_t),
                               rtol=0, atol=1e-15)
    z = np.linspace(0, 20, 9)
    line = smooth_curve_from_samples(np.column_stack([0 * z, 0 * z, z]))
    assert np.array_equal(framed_curve(line).dense_frames[0, :, 0], [1, 0, 0])
    tilted = framed_curve(line, base_normal=[1, 1, 5])
    np.testing.assert_allclose(tilted.dense_frames[0, :, 0], [1 / np.sqrt(2), 1 / np.sqrt(2), 0], rtol=0, atol=1e-15)
    # a straight line's RMF never turns
    np.testing.assert_allclose(tilted.frames(np.linspace(0, 1, 11)),
                               np.broadcast_to(tilted.dense_frames[0], (11, 3, 3)),
                               rtol=0, atol=ORTHONORMAL_TOL)
    with pytest.raises(GeometryError, match="parallel to the base tangent"):
        framed_curve(line, base_normal=[0, 0, 2])


def test_frenet_on_a_straight_run_names_the_l_range():
    s = np.linspace(0.0, 30.0, 301)
    # straight for 10 mm, then a quarter... of a circle of radius 10 tangent to it
    straight = np.column_stack([np.zeros(101), np.zeros(101), s[:101]])
    theta = (s[101:] - 10.0) / 10.0
    bend = np.column_stack([10.0 * (1 - np.cos(theta)), np.zeros_like(theta), 10.0 + 10.0 * np.sin(theta)])
    curve = smooth_curve_from_polyline(np.vstack([straight, bend]), CurveOptions(spacing_mm=0.1, smoothing_mm=0.0))
    framed_curve(curve)  # rmf is defined on straight parts
    with pytest.raises(GeometryError) as caught:
        framed_curve(curve, mode="frenet", label="q = 0")
    message = str(caught.value)
    assert "q = 0" in message and "frames: rmf" in message
    # the flat range starts at l = 0 and ends before the bend at l = 1/3 (the spline rounds the corner)
    low, high = (float(x) for x in message.split("l in [")[1].split("]")[0].split(", "))
    assert low == 0.0 and 0.25 < high < 1 / 3


def test_rmf_has_no_flip_at_an_inflection_where_frenet_is_undefined():
    x = np.linspace(-10, 10, 801)
    s_curve = np.column_stack([x, 0.02 * x**3, np.zeros_like(x)])  # planar, inflection at x = 0
    curve = smooth_curve_from_polyline(s_curve, CurveOptions(spacing_mm=0.2, smoothing_mm=0.0))
    framed = framed_curve(curve)
    # the base normal rule picks z (least aligned with the base tangent), the plane's normal; a planar
    # curve's RMF keeps it on both sides of the inflection
    normals = framed.dense_frames[:, :, 0]
    np.testing.assert_allclose(normals, np.broadcast_to([0.0, 0.0, 1.0], normals.shape), rtol=0, atol=1e-12)
    assert framed.max_frame_step < 0.01
    with pytest.raises(GeometryError, match="frenet"):
        framed_curve(curve, mode="frenet")


def test_adjacent_rotation_angles_and_flip_check_on_known_rotations():
    steps = np.array([0.1, 0.2, 3.0, 0.05])
    frames = np.array([rotation_from_rotvec([0, 0, a]) for a in np.concatenate([[0.0], np.cumsum(steps)])])
    np.testing.assert_allclose(adjacent_rotation_angles(frames), steps, rtol=0, atol=1e-14)
    l = np.linspace(0, 1, 5)
    assert check_no_flips(frames[:3], l[:3], "test") == pytest.approx(0.2, abs=1e-14)
    with pytest.raises(GeometryError, match=r"l = 0.500000 and 0.750000 differ by 3 rad"):
        check_no_flips(frames, l, "test")


def test_prefix_products_equal_sequential_products():
    rng = np.random.default_rng(11)
    steps = rotation_from_rotvec(rng.normal(size=(37, 3)))
    left, right = accumulate_rotations(steps, "left"), accumulate_rotations(steps, "right")
    seq_left, seq_right = np.eye(3), np.eye(3)
    for i, step in enumerate(steps):
        seq_left, seq_right = step @ seq_left, seq_right @ step
        np.testing.assert_allclose(left[i], seq_left, rtol=0, atol=1e-13)
        np.testing.assert_allclose(right[i], seq_right, rtol=0, atol=1e-13)


def test_unknown_mode_and_frenet_on_a_line_in_the_pure_function():
    z = np.linspace(0, 20, 9)
    line = smooth_curve_from_samples(np.column_stack([0 * z, 0 * z, z]))
    with pytest.raises(ConfigError, match="frames must be one of rmf, frenet, got 'tnb'"):
        framed_curve(line, mode="tnb")
    with pytest.raises(GeometryError, match=r"l in \[0.0000, 1.0000\]"):
        frenet_frames(line, np.linspace(0, 1, 5))


@pytest.mark.parametrize("mode", ["rmf", "frenet"])
def test_frames_and_derivative_are_frames_and_derivative_bit_for_bit(helix_curve, mode):
    from softdesign.geometry.frames import FRAME_CHUNK

    framed = framed_curve(helix_curve, mode)
    l = np.random.default_rng(9).uniform(0.0, 1.0, FRAME_CHUNK + 1000)  # more than one chunk of frames
    frames, d1 = framed.frames_and_derivative(l)
    assert np.array_equal(frames, framed.frames(l)) and np.array_equal(d1, framed.derivative(l, 1))


@pytest.mark.parametrize("mode", ["rmf", "frenet"])
def test_the_dense_jets_framed_curve_keeps_are_the_curves_own_bit_for_bit(helix_curve, mode):
    # rmf: framed_curve keeps the derivatives its frames were made from as dense_jets, not evaluated again
    framed = framed_curve(helix_curve, mode)
    l = framed.dense_l
    tangents, derivatives = framed.dense_jets
    assert np.array_equal(tangents, helix_curve.tangents(l))
    assert len(derivatives) == helix_curve.spline.k
    for order, derivative in enumerate(derivatives, start=1):
        assert np.array_equal(derivative, helix_curve.derivative(l, order))
    # the largest step and where it is, as check_no_flips and adjacent_rotation_angles give them
    assert framed.max_frame_step == check_no_flips(framed.dense_frames, l, "again", fix="")
    assert framed.max_frame_step_l == l[int(np.argmax(adjacent_rotation_angles(framed.dense_frames)))]
