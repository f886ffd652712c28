"""Joints at any l: a grid uniform on each piece with every break a sample (issue 35 item 4, ``blend: pcc``).

Known answer: a chain of three constant-curvature sections in different planes (seed 003), its breaks off
the uniform grid.  Splined on the joint grid, the rotation-minimizing frames at the breaks give each
section's closed-form HTM; the one quintic through the uniform grid rounds the corners.
"""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import GeometryError
from softdesign.geometry.curve_joints import checked_grid, grid_with_joints
from softdesign.geometry.curves import DEGREE, smooth_curve_from_samples
from softdesign.geometry.frames import framed_curve
from softdesign.kinematics import pcc
from softdesign.kinematics.links import link_transforms
from softdesign.kinematics.pcc_chain import chain_points_at

#: Issue 35 item 4's target for a link's end frame against its section's: rad and mm.
JOINT_TOL_RAD = 1e-4
JOINT_TOL_MM = 1e-4
#: Three sections (1/mm, rad, mm): straight, then bends of 0.8 and 1.2 rad in two other planes.
KAPPA, PHI, LENGTH = np.array([0.0, 0.08, 0.12]), np.array([0.0, 0.5, -2.0]), np.array([12.3, 10.0, 10.0])
#: Samples of the uniform grid over the 32.3 mm chain: 0.5 mm apart, none of the breaks on it.
COUNT = 66


def rotation_angle(a: np.ndarray, b: np.ndarray) -> float:
    """Angle of the rotation between two 3x3 rotations, rad."""
    return float(np.arccos(np.clip(0.5 * (np.trace(a.T @ b) - 1.0), -1.0, 1.0)))


def chain_curve(joint_grid: bool):
    """The chain's centerline splined on the joint grid (or through the uniform grid), l proportional to arc length."""
    breaks = np.concatenate([[0.0], np.cumsum(LENGTH)]) / LENGTH.sum()
    if joint_grid:
        l_grid, joints = grid_with_joints(breaks, COUNT, DEGREE)
    else:
        l_grid, joints = np.linspace(0.0, 1.0, COUNT), ()
    w = np.column_stack([KAPPA * np.cos(PHI), KAPPA * np.sin(PHI)])
    samples = chain_points_at(np.eye(4), w, LENGTH, l_grid * LENGTH.sum())
    curve = smooth_curve_from_samples(samples, joints, l_grid if joint_grid else None)
    return curve, breaks


def worst_link_error(joint_grid: bool) -> tuple[float, float]:
    """Largest rotation (rad) and translation (mm) between the links' S_T_E and the sections' HTMs."""
    curve, breaks = chain_curve(joint_grid)
    measured = link_transforms(framed_curve(curve, "rmf", base_normal=[1.0, 0.0, 0.0]), breaks)  # the base's N
    exact = pcc.transform_from_arc(KAPPA, PHI, LENGTH)
    angle = max(rotation_angle(m[:3, :3], e[:3, :3]) for m, e in zip(measured, exact, strict=True))
    return angle, float(np.max(np.linalg.norm(measured[:, :3, 3] - exact[:, :3, 3], axis=1)))


def test_the_grid_keeps_every_break_as_a_sample_and_is_uniform_on_each_piece():
    breaks = np.array([0.0, 0.3141, 0.3141 + 2e-3, 0.77, 1.0])  # a piece far shorter than a spacing
    l_grid, joints = grid_with_joints(breaks, 101, DEGREE)
    assert l_grid[0] == 0.0 and l_grid[-1] == 1.0 and np.all(np.diff(l_grid) > 0.0)
    assert [l_grid[j] for j in joints] == breaks[1:-1].tolist()  # bit for bit
    bounds = [0, *joints, len(l_grid) - 1]
    for a, b in zip(bounds[:-1], bounds[1:], strict=True):
        steps = np.diff(l_grid[a : b + 1])
        assert b - a >= DEGREE and np.ptp(steps) <= 1e-15 and steps.max() <= 1.0 / 100 + 1e-15


def test_a_chain_of_arcs_keeps_each_sections_transform_at_its_joints():
    curve, breaks = chain_curve(joint_grid=True)
    dense = curve.dense_l()
    assert set(breaks.tolist()) <= set(dense.tolist())  # no Taylor chord of the frames crosses a joint
    assert np.all(np.diff(dense) > 0.0) and (dense[1] - dense[0]) * curve.length <= 0.05 + 1e-12
    assert curve.length == pytest.approx(LENGTH.sum(), rel=1e-10)  # quintics through 0.5 mm samples of arcs
    angle, distance = worst_link_error(joint_grid=True)
    assert angle <= JOINT_TOL_RAD and distance <= JOINT_TOL_MM
    # the one spline through the uniform grid rounds the corners: the test can tell the two apart
    rounded_angle, rounded_distance = worst_link_error(joint_grid=False)
    assert rounded_angle > 10 * JOINT_TOL_RAD and rounded_distance > 10 * JOINT_TOL_MM


def test_a_uniform_curve_keeps_its_dense_grid():
    curve, _ = chain_curve(joint_grid=False)
    assert curve.uniform
    assert np.array_equal(curve.dense_l(), np.linspace(0.0, 1.0, len(curve.dense_l())))


@pytest.mark.parametrize(("grid", "count"), [(np.linspace(0.0, 1.0, 9), 10), (np.linspace(0.1, 1.0, 10), 10),
                                             (np.array([0.0, 0.5, 0.4, 1.0]), 4)], ids=["count", "start", "order"])
def test_a_bad_grid_is_refused(grid, count):
    with pytest.raises(GeometryError, match="strictly increasing from 0 to 1"):
        checked_grid(grid, count)
