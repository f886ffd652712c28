"""Chains of arcs composed from a base frame, and the true distances the design measures (issue 30)."""

from __future__ import annotations

import numpy as np

from softdesign.geometry.se3 import rotation_from_rotvec
from softdesign.kinematics import pcc
from softdesign.kinematics.pcc_chain import (
    chain_points_at,
    dense_chain_points,
    distances_to_polyline,
    feet_on_chain,
    section_poses,
)

#: Brute force on a chain sampled every 1 micrometre: the closest sample is within half of that of the closest point.
BRUTE_TOL_MM = 1e-3
#: Round-off of a few 4x4 products and sinc forms.
EXACT_TOL = 1e-10


def chain() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    base = np.eye(4)
    base[:3, :3] = rotation_from_rotvec([0.2, 0.9, -0.4])
    base[:3, 3] = [1.0, 2.0, -3.0]
    w = np.array([[0.04, 0.03], [0.0, 0.0], [-0.02, 0.09]])  # a straight section in the middle
    return base, w, np.array([20.0, 8.0, 30.0])


def test_sections_start_on_the_previous_tip_and_points_follow_each_arc():
    base, w, length = chain()
    bases, tips = section_poses(base, w, length)
    np.testing.assert_allclose(bases[0], base, rtol=0, atol=EXACT_TOL)
    np.testing.assert_allclose(bases[1:], tips[:-1], rtol=0, atol=EXACT_TOL)
    kappa = np.hypot(w[:, 0], w[:, 1])
    phi = np.arctan2(w[:, 1], w[:, 0])
    expected = base @ pcc.transform_from_arc(kappa[0], phi[0], length[0])  # seed eq. 8 for section 1
    np.testing.assert_allclose(tips[0], expected, rtol=0, atol=EXACT_TOL)
    s = np.array([0.0, 20.0, 24.0, 28.0, 58.0])
    points = chain_points_at(base, w, length, s)
    np.testing.assert_allclose(points[[0, 1, 3, 4]], [base[:3, 3], tips[0][:3, 3], tips[1][:3, 3], tips[2][:3, 3]],
                               rtol=0, atol=EXACT_TOL)
    np.testing.assert_allclose(points[2], tips[0][:3, 3] + 4.0 * tips[0][:3, 2], rtol=0, atol=EXACT_TOL)


def test_feet_on_the_chain_are_the_closest_points_by_brute_force():
    base, w, length = chain()
    bases, _ = section_poses(base, w, length)
    dense, _ = dense_chain_points(base, w, length, 0.001)
    rng = np.random.default_rng(3)
    near = chain_points_at(base, w, length, rng.uniform(-5.0, 63.0, 200)) + rng.normal(0.0, 3.0, (200, 3))
    feet, distance, _ = feet_on_chain(near, bases, w, length)
    brute = np.array([np.min(np.linalg.norm(dense - p, axis=1)) for p in near])
    np.testing.assert_allclose(distance, brute, rtol=0, atol=BRUTE_TOL_MM)
    assert np.all(distance <= brute + EXACT_TOL)  # never more than a point actually on the chain
    np.testing.assert_allclose(np.linalg.norm(feet - near, axis=1), distance, rtol=0, atol=EXACT_TOL)


def test_distance_to_a_polyline_is_exact_against_every_segment():
    rng = np.random.default_rng(5)
    polyline = np.cumsum(rng.normal(0.0, 1.0, (60, 3)), axis=0)
    points = rng.uniform(polyline.min(0) - 3, polyline.max(0) + 3, (300, 3))
    a, b = polyline[:-1], polyline[1:]
    t = np.clip(np.einsum("mni,ni->mn", points[:, None] - a, b - a) / np.sum((b - a) ** 2, axis=1), 0.0, 1.0)
    brute = np.min(np.linalg.norm(points[:, None] - (a + t[..., None] * (b - a)), axis=2), axis=1)
    np.testing.assert_allclose(distances_to_polyline(points, polyline), brute, rtol=0, atol=EXACT_TOL)
