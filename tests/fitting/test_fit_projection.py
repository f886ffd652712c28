"""Projection p -> (l, a, rho) on analytic framed curves whose answers are known exactly."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import InputDataError
from softdesign.fitting import projection
from softdesign.fitting.projection import NEWTON_TOL_MM, project_points
from tests.helpers.analytic import Arc, Helix, Line, tube_points
from tests.helpers.workers import two_worker_mapper

#: Newton stops at NEWTON_TOL_MM of arc; 100x leaves room for rounding in c(l) at ~100 mm coordinates.
ARC_TOL_MM = 100 * NEWTON_TOL_MM
#: Angle and rho follow from the foot point; rounding of O(10 mm) coordinates.
ANGLE_TOL = 1e-9
RHO_TOL_MM = 1e-9

CURVES = [Line(30.0), Arc(20.0, 2.0), Helix(8.0, 3.0, 1.2)]


@pytest.mark.parametrize("curve", CURVES, ids=lambda c: type(c).__name__)
def test_points_built_on_the_frames_are_recovered(curve):
    rng = np.random.default_rng(11)
    n = 500
    l = rng.uniform(0.01, 0.99, n)
    angle = rng.uniform(-np.pi, np.pi, n)
    # rho below the radius of curvature (8 mm for the arc's 20 mm, helix kappa = 0.11/mm), so the foot is unique.
    rho = rng.uniform(0.5, 5.0, n)
    polar = project_points(curve, tube_points(curve, l, angle, rho))
    np.testing.assert_allclose(polar.l * curve.length, l * curve.length, rtol=0, atol=ARC_TOL_MM)
    np.testing.assert_allclose(np.angle(np.exp(1j * (polar.angle - angle))), 0.0, rtol=0, atol=ANGLE_TOL)
    np.testing.assert_allclose(polar.rho, rho, rtol=0, atol=RHO_TOL_MM)
    assert not polar.end_side.any()


def test_points_beyond_the_ends_are_clamped_and_flagged():
    curve = Line(30.0)
    points = np.array([[1.0, 0.0, -2.0], [0.0, 3.0, 33.0], [0.0, 2.0, 15.0]])
    polar = project_points(curve, points)
    np.testing.assert_array_equal(polar.end_side, [-1, 1, 0])
    np.testing.assert_allclose(polar.l, [0.0, 1.0, 0.5], rtol=0, atol=ARC_TOL_MM / curve.length)
    np.testing.assert_allclose(polar.rho, [np.sqrt(5.0), np.sqrt(18.0), 2.0], rtol=0, atol=RHO_TOL_MM)


def test_foot_point_is_the_nearest_one_where_several_exist():
    # A point at the arc's centre side but near the arc: the nearest foot, not a far one.
    curve = Arc(10.0, 1.5 * np.pi)
    point = np.array([[7.0 * np.cos(0.4), 7.0 * np.sin(0.4), 0.0]])
    polar = project_points(curve, point)
    np.testing.assert_allclose(polar.l * curve.sweep, [0.4], rtol=0, atol=ANGLE_TOL)
    np.testing.assert_allclose(polar.rho, [3.0], rtol=0, atol=RHO_TOL_MM)
    np.testing.assert_allclose(polar.angle, [0.0], rtol=0, atol=ANGLE_TOL)  # towards the centre: +N


def test_input_is_not_modified_and_bad_input_is_refused():
    curve = Line(10.0)
    points = np.array([[1.0, 0.0, 5.0], [0.0, 1.0, 2.0]])
    before = points.copy()
    project_points(curve, points)
    np.testing.assert_array_equal(points, before)
    with pytest.raises(InputDataError, match=r"\(n, 3\)"):
        project_points(curve, np.zeros((4, 2)))
    with pytest.raises(InputDataError, match="finite"):
        project_points(curve, np.array([[np.nan, 0.0, 1.0]]))


def test_blocks_on_worker_processes_give_the_same_bits(monkeypatch):
    # the build hands a large surface's blocks of points to its worker processes (map_items)
    curve = Helix(8.0, 3.0, 1.2)
    rng = np.random.default_rng(5)
    n = 2000
    points = tube_points(curve, rng.uniform(-0.02, 1.02, n), rng.uniform(-np.pi, np.pi, n), rng.uniform(0.5, 5.0, n))
    whole = project_points(curve, points)
    monkeypatch.setattr(projection, "SPLIT_POINTS", 200)
    mapper, blocks = two_worker_mapper()
    # an even number of equal blocks of at most PROJECT_BLOCK (2000 points: 8 of 250), or halves below twice that
    for block, count in ((300, 8), (1500, 2)):
        monkeypatch.setattr(projection, "PROJECT_BLOCK", block)
        split = project_points(curve, points, mapper)
        assert blocks[-1] == count
        for name in ("points", "l", "angle", "rho", "end_side"):
            np.testing.assert_array_equal(getattr(split, name), getattr(whole, name))
        assert split.end_side.dtype == np.int8 and split.end_side.any()
    monkeypatch.setattr(projection, "SPLIT_POINTS", n)  # up to SPLIT_POINTS: here in one go
    project_points(curve, points, mapper)
    assert len(blocks) == 2
