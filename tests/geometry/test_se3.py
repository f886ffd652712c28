"""SO(3) / SE(3) basics: known answers first, then seeded exp/log round trips, then refusals."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import GeometryError
from softdesign.geometry.se3 import (
    axis_angle_from_rotation,
    check_pose,
    inverse_pose,
    pose_from_twist,
    rotation_from_rotvec,
    rotvec_from_rotation,
    skew_from_vector,
    twist_from_pose,
    vector_from_skew,
)
from tests.helpers.seed_transforms import rot_z

#: Rounding-level agreement of exact compositions.
ROUND_TOL = 1e-12


def test_skew_and_vee_on_known_values():
    w, x = np.array([1.0, -2.0, 3.0]), np.array([0.5, 4.0, -1.0])
    hat = skew_from_vector(w)
    np.testing.assert_array_equal(hat, [[0, -3, -2], [3, 0, -1], [2, 1, 0]])
    np.testing.assert_allclose(hat @ x, np.cross(w, x), rtol=0, atol=ROUND_TOL)
    np.testing.assert_array_equal(vector_from_skew(hat), w)
    # batches: (..., 3) -> (..., 3, 3) and back
    batch = np.arange(12.0).reshape(2, 2, 3)
    assert skew_from_vector(batch).shape == (2, 2, 3, 3)
    np.testing.assert_array_equal(vector_from_skew(skew_from_vector(batch)), batch)


def test_exponentials_on_known_values():
    quarter = rot_z(np.pi / 2)[:3, :3]
    np.testing.assert_allclose(rotation_from_rotvec([0, 0, np.pi / 2]), quarter, rtol=0, atol=ROUND_TOL)
    np.testing.assert_allclose(rotation_from_rotvec([0, 0, 0]), np.eye(3), rtol=0, atol=0)
    # a screw about z: rotation theta and a slide h along the axis
    screw = pose_from_twist([0, 0, 2.0, 0, 0, 0.7])
    expected = rot_z(0.7)
    expected[2, 3] = 2.0
    np.testing.assert_allclose(screw, expected, rtol=0, atol=ROUND_TOL)
    # a pure rotation about the z axis through the point q = (1, 0, 0): v = -omega x q
    about_q = pose_from_twist([0, -np.pi, 0, 0, 0, np.pi])
    np.testing.assert_allclose(about_q[:3, 3], [2, 0, 0], rtol=0, atol=ROUND_TOL)


def test_axis_angle_matches_the_seed_formula_where_it_is_well_conditioned():
    rng = np.random.default_rng(5)
    for rotvec in rng.normal(size=(50, 3)):
        rotvec *= rng.uniform(0.1, 3.0) / np.linalg.norm(rotvec)
        r = rotation_from_rotvec(rotvec)
        axis, angle = axis_angle_from_rotation(r)
        np.testing.assert_allclose(angle, np.arccos((np.trace(r) - 1) / 2), rtol=0, atol=1e-9)
        seed_axis = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]) / (2 * np.sin(angle))
        np.testing.assert_allclose(axis, seed_axis, rtol=0, atol=1e-8)
        np.testing.assert_allclose(axis * angle, rotvec, rtol=0, atol=1e-12)
        np.testing.assert_allclose(rotvec_from_rotation(r), rotvec, rtol=0, atol=1e-12)


def test_se3_exp_log_round_trips_on_random_twists_and_poses():
    rng = np.random.default_rng(17)
    for _ in range(100):
        twist = np.concatenate([rng.normal(scale=20, size=3), rng.normal(size=3)])
        twist[3:] *= rng.uniform(0, np.pi - 1e-3) / np.linalg.norm(twist[3:])
        np.testing.assert_allclose(twist_from_pose(pose_from_twist(twist)), twist, rtol=0, atol=ROUND_TOL)
        pose = pose_from_twist(twist)
        np.testing.assert_allclose(pose_from_twist(twist_from_pose(pose)), pose, rtol=0, atol=ROUND_TOL)
        np.testing.assert_allclose(inverse_pose(pose) @ pose, np.eye(4), rtol=0, atol=ROUND_TOL)


def test_inverse_pose_of_a_batch_inverts_each_pose():
    rng = np.random.default_rng(3)
    poses = np.stack([pose_from_twist(np.concatenate([rng.normal(size=3), rng.normal(size=3)])) for _ in range(5)])
    inverses = inverse_pose(poses)
    assert inverses.shape == (5, 4, 4)
    np.testing.assert_allclose(poses @ inverses, np.broadcast_to(np.eye(4), poses.shape), rtol=0, atol=ROUND_TOL)


def test_a_matrix_that_is_not_a_rotation_is_refused_with_its_figures():
    reflection = np.eye(4)
    reflection[0, 0] = -1.0
    with pytest.raises(GeometryError, match=r"orthonormal matrix with det \+1.*det = -1"):
        check_pose(reflection)
    with pytest.raises(GeometryError, match=r"expected a \(4, 4\) homogeneous transform, got shape \(3, 3\)"):
        twist_from_pose(np.eye(3))
    with pytest.raises(GeometryError, match=r"expected a twist of shape \(6,\)"):
        pose_from_twist(np.zeros(5))
