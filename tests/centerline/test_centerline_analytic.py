"""Centerlines of surfaces whose axis and radius are known: a straight tube, a torus section, a Y, a noisy tube."""

from __future__ import annotations

import numpy as np

from softdesign.centerline.extract import SMOOTHING_REL, CenterlineOptions, extract_centerlines
from tests.helpers.vessels import straight_tube, torus_section, y_bifurcation

EDGE = 0.6  # mm, the test surfaces' edge length
#: Axis error allowed on a clean tube: the smoothing spline may keep SMOOTHING_REL edges RMS from the Voronoi
#: path, so that, not the Voronoi vertices' own spread (O(edge^2 / R), about 0.1 um here), is the bound.
AXIS_TOL = SMOOTHING_REL * EDGE
#: Radius error allowed on a clean tube, relative: the distance to the nearest vertex is R on the axis and
#: grows by at most AXIS_TOL^2 / (2R) off it; 1 % also covers the polygon's sagitta (R (1 - cos(pi/32)) = 0.5 %).
RADIUS_RTOL = 0.01


def _axial_window(s: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Points at least one radius from either end of the path (where VMTK's and our end conventions differ)."""
    return (s > radius[0]) & (s < s[-1] - radius[-1])


def _arc(points: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])


def test_straight_tube_axis_and_radius():
    vertices, faces = straight_tube(radius=3.0, length=40.0, edge=EDGE)
    result = extract_centerlines(vertices, faces)
    assert result.endpoints == "openings" and len(result.paths) == 1
    points, radius = result.paths[0], result.radii[0]
    keep = _axial_window(_arc(points), radius)
    np.testing.assert_allclose(points[keep, :2], 0.0, rtol=0, atol=AXIS_TOL)
    np.testing.assert_allclose(radius[keep], 3.0, rtol=RADIUS_RTOL, atol=0)
    assert points[0, 2] < points[-1, 2]  # the two openings are equal: the first (lowest vertex) is the inlet
    # it runs from opening centre to opening centre (issue 29): the Voronoi path stops at the poles, one
    # inscribed radius inside, and each end is continued straight by that radius, which the result states
    np.testing.assert_allclose(points[[0, -1]], [[0.0, 0.0, 0.0], [0.0, 0.0, 40.0]], rtol=0, atol=AXIS_TOL)
    np.testing.assert_allclose(result.continued_mm[0], [3.0, 3.0], rtol=0, atol=0.5)
    assert result.short_mm[0] == (0.0, 0.0)
    # the continued runs hold the last inscribed sphere's radius, not the distance to the rim they approach
    np.testing.assert_allclose(radius[[0, -1]], 3.0, rtol=RADIUS_RTOL, atol=0)


def test_torus_section_axis_and_radius():
    bend, tube = 20.0, 3.0
    vertices, faces = torus_section(bend=bend, radius=tube, angle=np.pi / 2, edge=EDGE)
    result = extract_centerlines(vertices, faces)
    points, radius = result.paths[0], result.radii[0]
    keep = _axial_window(_arc(points), radius)
    np.testing.assert_allclose(np.linalg.norm(points[keep, :2], axis=1), bend, rtol=0, atol=AXIS_TOL)
    np.testing.assert_allclose(points[keep, 2], 0.0, rtol=0, atol=AXIS_TOL)
    np.testing.assert_allclose(radius[keep], tube, rtol=RADIUS_RTOL, atol=0)


def test_inlet_option_picks_the_other_opening():
    vertices, faces = straight_tube(radius=3.0, length=40.0, edge=EDGE)
    result = extract_centerlines(vertices, faces, CenterlineOptions(inlet=np.array([0.0, 0.0, 45.0])))
    assert result.paths[0][0, 2] > result.paths[0][-1, 2]
    np.testing.assert_allclose(result.inlet, [0.0, 0.0, 40.0], rtol=0, atol=1e-9)


def test_a_given_outlet_inside_the_vessel_is_not_continued():
    vertices, faces = straight_tube(radius=3.0, length=40.0, edge=EDGE)
    given = np.array([0.0, 0.0, 25.0])  # inside, 15 mm from the far opening: no opening to reach
    result = extract_centerlines(vertices, faces, CenterlineOptions(outlets=(given,)))
    assert result.endpoints == "given"
    assert result.continued_mm[0][1] == 0.0 and result.short_mm[0] == (0.0, 0.0)
    assert result.continued_mm[0][0] > 2.0  # the inlet is still its opening's centre
    assert abs(result.paths[0][-1, 2] - 25.0) < 4.0  # the pole nearest the point, about one radius from it


def test_y_bifurcation_axes_radii_and_caps():
    trunk, branch, length = 4.0, 3.0, 30.0
    vertices, faces, axes = y_bifurcation(trunk, branch, length, np.radians(30.0), EDGE)
    result = extract_centerlines(vertices, faces)
    assert result.endpoints == "planar caps" and len(result.paths) == 2
    np.testing.assert_allclose(result.inlet, [0.0, 0.0, -length], rtol=0, atol=1e-6)  # the largest cap
    # away from the junction (2 trunk radii: there the medial axis of a union of cylinders leaves both axes)
    # and from the ends; 0.1 mm: AXIS_TOL plus the facets of a 42-gon trunk cut by the branches
    y_axis_tol, y_radius_rtol = 0.1, 0.02  # radius: the 42-gon's flat faces are R cos(pi/42) = 0.997 R away
    for points, radius, branch_axis in zip(result.paths, result.radii, axes[1:], strict=True):
        for axis, nominal in ((axes[0], trunk), (branch_axis, branch)):
            along = points @ axis
            keep = (along > 2 * trunk) & (along < length - nominal)
            assert keep.sum() > 20
            off_axis = np.linalg.norm(points[keep] - along[keep, None] * axis, axis=1)
            np.testing.assert_allclose(off_axis, 0.0, rtol=0, atol=y_axis_tol)
            np.testing.assert_allclose(radius[keep], nominal, rtol=y_radius_rtol, atol=0)
        # and each path reaches its flat caps' centres (issue 29)
        np.testing.assert_allclose(points[0], length * axes[0], rtol=0, atol=y_axis_tol)
        np.testing.assert_allclose(points[-1], length * branch_axis, rtol=0, atol=y_axis_tol)


def test_noisy_tube_stays_near_the_axis():
    radius_mm, jitter = 3.0, 0.05
    vertices, faces = straight_tube(radius=radius_mm, length=40.0, edge=EDGE)
    rng = np.random.default_rng(7)
    direction = rng.normal(size=vertices.shape)
    noisy = vertices + jitter * radius_mm * direction / np.linalg.norm(direction, axis=1, keepdims=True)
    result = extract_centerlines(noisy, faces)
    points, radius = result.paths[0], result.radii[0]
    keep = _axial_window(_arc(points), radius)
    # the axis moves by less than the jitter itself; the radius, the distance to the nearest (jittered)
    # vertex, is biased low by up to the jitter, so it may be two jitters off
    np.testing.assert_allclose(points[keep, :2], 0.0, rtol=0, atol=jitter * radius_mm)
    np.testing.assert_allclose(radius[keep], radius_mm, rtol=2 * jitter, atol=0)
