"""The morph-fold check before any fit (issue 20, kinds 1 and 3): r * kappa over every blended shape.

Known answers: a tube of radius r around a circular arc of radius R has r * kappa = r / R; the
intrinsic blend of a straight line and a curve has curvature q kappa_f(l), so its reach never
exceeds the q = 1 shape's; the linear blend of a straight line and a half turn of the same length
folds back on itself at q = 1/2 (the two halves cancel across the turn).
"""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.geometry.blend import blend_shapes
from softdesign.geometry.curves import CurveOptions, smooth_curve_from_polyline
from softdesign.geometry.initial import build_initial_shape
from softdesign.geometry.morph_fold import MORPH_REACH_LIMIT, morph_reach
from softdesign.geometry.network import SelectedPath
from softdesign.pipeline.blend_choice import choose_blend
from tests.helpers.robust_vessels import stub_turn_axis, u_turn_axis

#: r * kappa of the smoothed, resampled centerline against r / R of the drawn arc (smoothing 0.1 mm
#: and the 0.25 mm polyline steps move the spline's curvature by well under this).
ARC_REACH_RTOL = 0.03
#: The same at a U-turn, whose curvature jumps from 0 to 1/R where the leads meet the turn: the
#: smoothing spline overshoots that step by a few percent.
JUNCTION_REACH_RTOL = 0.05
#: The intrinsic blend's reach over the q = 1 shape's (Magnus step and quintic resampling round-off).
INTRINSIC_RTOL = 1e-3
RADIUS = 3.0


def shapes(points: np.ndarray, end_straight_mm: float = 2.0):
    """Initial (straight) and final shapes with the default resampling; an arc to its ends keeps them curved."""
    options = CurveOptions(spacing_mm=0.5, smoothing_mm=0.1, end_straight_mm=end_straight_mm)
    final = smooth_curve_from_polyline(points, options)
    same = CurveOptions(spacing_mm=0.5, count=len(final.l_grid), smoothing_mm=0.1, end_straight_mm=end_straight_mm)
    return build_initial_shape(final, options=same), final


def profile(final):
    return np.array([0.0, 1.0]), np.full(2, RADIUS)


def test_the_linear_blend_of_a_half_turn_folds_mid_morph_and_the_intrinsic_one_never_exceeds_the_final_shape():
    initial, final = shapes(u_turn_axis(bend_mm=10.0)[0])
    linear = morph_reach(blend_shapes(initial, final, mode="linear"), *profile(final))
    assert linear.final_reach == pytest.approx(RADIUS / 10.0, rel=JUNCTION_REACH_RTOL)
    assert linear.blend_folds and linear.reach > 1.0 and 0.4 < linear.q < 0.6
    intrinsic = morph_reach(blend_shapes(initial, final, mode="intrinsic"), *profile(final))
    assert not intrinsic.blend_folds
    assert intrinsic.reach <= intrinsic.final_reach * (1.0 + INTRINSIC_RTOL)


def test_a_gentle_arc_does_not_fold_under_the_linear_blend():
    t = np.linspace(0.0, np.pi / 3, 200)
    initial, final = shapes(40.0 * np.column_stack([1 - np.cos(t), np.sin(t), 0 * t]), end_straight_mm=0.0)
    reach = morph_reach(blend_shapes(initial, final, mode="linear"), *profile(final))
    assert not reach.blend_folds and reach.reach < MORPH_REACH_LIMIT
    assert reach.final_reach == pytest.approx(RADIUS / 40.0, rel=ARC_REACH_RTOL)


def path_of(points: np.ndarray, radius: float) -> SelectedPath:
    return SelectedPath(points, np.full(len(points), radius), 0)


def test_auto_uses_intrinsic_where_linear_folds_and_says_why():
    points = u_turn_axis(bend_mm=10.0)[0]
    initial, final = shapes(points)
    choice = choose_blend(initial, final, (), "auto", "rmf", path_of(points, RADIUS))
    assert choice.shape.mode == "intrinsic" and choice.warning is None
    assert choice.linear_reach is not None and choice.linear_reach.blend_folds
    assert choice.reason.startswith("intrinsic (auto: the linear blend folds mid-morph: at q = ")
    asked = choose_blend(initial, final, (), "linear", "rmf", path_of(points, RADIUS))
    assert asked.shape.mode == "linear" and asked.warning is not None and "use blend: intrinsic" in asked.warning


def test_auto_is_linear_where_linear_does_not_fold():
    t = np.linspace(0.0, np.pi / 3, 200)
    points = 40.0 * np.column_stack([1 - np.cos(t), np.sin(t), 0 * t])
    initial, final = shapes(points, end_straight_mm=0.0)
    choice = choose_blend(initial, final, (), "auto", "rmf", path_of(points, RADIUS))
    assert choice.shape.mode == "linear" and choice.linear_reach is None and choice.warning is None


def test_a_centerline_turning_tighter_than_the_inscribed_radius_is_warned_about_not_refused():
    # a 6 mm vessel: a 4.5 mm straight stub, then 60 degrees within half a radius (bend radius 3 mm); issue 29:
    # the inscribed radius is no bound of the fitted wall on a bend's flatter inner side, the fit decides
    points = stub_turn_axis(4.5, 3.0, 60.0, 30.0)[0]
    initial, final = shapes(points)
    choice = choose_blend(initial, final, (), "auto", "rmf", path_of(points, 6.0))
    assert choice.reach is not None and choice.reach.final_reach >= 1.0
    assert choice.warning is not None and "turns tighter than the inscribed radius" in choice.warning
    assert "l = 0." in choice.warning and "the fit tests whether the fitted body folds" in choice.warning
