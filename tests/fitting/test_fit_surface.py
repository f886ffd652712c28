"""rho(l, a) recovered from analytic tubes, joints, the penalty's role, and failures that must be loud."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import ConfigError, FitError
from softdesign.fitting import bspline_basis as bb
from softdesign.fitting.bspline_surface import (
    FitSettings,
    RadiusSpline,
    fit_radius_surface,
    intervals_per_link,
    split_at_breaks,
)
from softdesign.fitting.metrics import measure_fit
from softdesign.fitting.projection import project_points
from softdesign.fitting.surface_system import design_and_gram, design_matrix
from tests.helpers.analytic import Arc, Helix, Line, grid_parameters, tube_points

#: Shapes inside the spline space come back to rounding plus the projection's 1e-10 mm Newton tolerance.
EXACT_TOL_MM = 1e-6
#: The split links reproduce the whole spline; knot insertion is a few flops per coefficient.
SPLIT_TOL_MM = 1e-12
#: Value and slope jumps at joints: rounding of O(5 mm) values.
JOINT_TOL = 1e-11
#: The Gram matrix by blocks adds the sparse product's terms in another order: rounding of sums of O(1) terms.
GRAM_TOL = 1e-12


def _ellipse(l, angle, major=4.0, minor=3.0, turn=np.pi / 2):
    """Radius of an ellipse whose major axis turns by ``turn`` from l = 0 to 1, mm."""
    theta = angle - turn * l
    return major * minor / np.sqrt((minor * np.cos(theta)) ** 2 + (major * np.sin(theta)) ** 2)


def _cubic_bound(intervals: int) -> float:
    """(5/384) h^4 max|d^4 rho / da^4| of the ellipse: the cubic interpolation error bound, mm."""
    theta = np.linspace(0.0, 2 * np.pi, 20001)
    step = theta[1] - theta[0]
    fourth = np.abs(np.diff(_ellipse(0.0, theta), 4)).max() / step**4
    return 5.0 / 384.0 * (2 * np.pi / intervals) ** 4 * fourth


def _polar(curve, rho_of, n_l=60, n_a=40, seed=1):
    rng = np.random.default_rng(seed)
    l, angle = grid_parameters(n_l, n_a, rng)
    return project_points(curve, tube_points(curve, l, angle, rho_of(l, angle)))


def test_torus_with_radius_growing_along_l_is_recovered_exactly():
    # rho linear in arc length has no thin-plate energy: the default penalty leaves it exact.
    curve = Arc(30.0, 1.5)
    polar = _polar(curve, lambda l, a: 3.0 + 1.0 * l)
    fit = fit_radius_surface(polar, curve.length, FitSettings(breaks=(0.0, 0.3, 0.7, 1.0)))
    assert measure_fit(curve, fit.whole, polar).max_mm <= EXACT_TOL_MM
    l = np.linspace(0.0, 1.0, 41)
    expected = np.repeat((3.0 + l)[:, None], 9, axis=1)
    np.testing.assert_allclose(fit.whole.evaluate_grid(l, np.linspace(0, 6, 9)), expected, rtol=0, atol=EXACT_TOL_MM)


def test_helix_tube_inside_the_spline_space_is_recovered_exactly():
    curve = Helix(8.0, 3.0, 1.2)  # kappa = 0.11 /mm, rho <= 2.8 mm: rho kappa <= 0.31
    settings = FitSettings(knot_spacing_mm=4.0, angular_intervals=12, smoothing=0.0, breaks=(0.0, 0.5, 1.0))
    knots = bb.open_knots(settings.breaks, intervals_per_link(curve.length, settings))
    rng = np.random.default_rng(5)
    truth = RadiusSpline(knots, 2.5 + 0.3 * rng.uniform(-1, 1, (len(knots) - 4, settings.angular_intervals)))
    polar = _polar(curve, truth.evaluate, n_l=90, n_a=36)
    fit = fit_radius_surface(polar, curve.length, settings)
    np.testing.assert_allclose(fit.whole.coefficients, truth.coefficients, rtol=0, atol=EXACT_TOL_MM)
    assert measure_fit(curve, fit.whole, polar).max_mm <= EXACT_TOL_MM


def test_straight_tube_with_turning_elliptical_section():
    curve = Line(40.0)
    polar = _polar(curve, _ellipse)
    bound = _cubic_bound(FitSettings().angular_intervals)  # 2.1 um for M = 24
    plain = fit_radius_surface(polar, curve.length, FitSettings(smoothing=0.0))
    l, a = np.meshgrid(np.linspace(0.05, 0.95, 37), np.linspace(-np.pi, np.pi, 97), indexing="ij")
    # Least squares may exceed the interpolation bound by the projector's max-norm (< 2 for uniform cubics).
    assert np.abs(plain.whole.evaluate(l, a) - _ellipse(l, a)).max() <= 2 * bound
    default = fit_radius_surface(polar, curve.length, FitSettings())
    # The default penalty adds a bias of the same order as the approximation error (measured 0.7 um).
    assert measure_fit(curve, default.whole, polar).max_mm <= 3 * bound


def test_links_split_from_one_fit_match_it_and_join_in_value_and_slope():
    curve = Helix(8.0, 3.0, 1.2)
    breaks = (0.0, 0.21, 0.5, 0.77, 1.0)
    polar = _polar(curve, lambda l, a: _ellipse(l, a, 2.6, 2.2))
    fit = fit_radius_surface(polar, curve.length, FitSettings(breaks=breaks))
    assert len(fit.links) == 4 and fit.joint_value_jump_mm.shape == (3,)
    assert fit.joint_value_jump_mm.max() <= JOINT_TOL
    assert fit.joint_slope_jump.max() <= JOINT_TOL
    a = np.linspace(-np.pi, np.pi, 50)
    for link, (lo, hi) in zip(fit.links, zip(breaks[:-1], breaks[1:], strict=True), strict=True):
        assert link.domain == (lo, hi)
        l = np.linspace(lo, hi, 30)
        np.testing.assert_allclose(link.evaluate_grid(l, a), fit.whole.evaluate_grid(l, a), rtol=0, atol=SPLIT_TOL_MM)
    again = split_at_breaks(fit.whole, breaks)
    np.testing.assert_array_equal(again[2].coefficients, fit.links[2].coefficients)


def test_values_and_slopes_in_one_pass_are_the_separate_evaluations():
    polar = _polar(Line(30.0), lambda l, a: _ellipse(l, a))
    spline = fit_radius_surface(polar, 30.0, FitSettings()).whole
    rng = np.random.default_rng(5)
    l, a = rng.random(300), rng.uniform(-10.0, 10.0, 300)
    together = spline.evaluate_with_slopes(l, a)
    alone = (spline.evaluate(l, a), spline.evaluate(l, a, dl=1), spline.evaluate(l, a, da=1))
    # the same products summed in another order: rounding of ~100 (mm per unit l)
    for t, s in zip(together, alone, strict=True):
        np.testing.assert_allclose(t, s, rtol=0, atol=SPLIT_TOL_MM)


def test_a_wall_with_a_hole_stays_bounded_thanks_to_the_penalty():
    curve = Line(40.0)
    polar = _polar(curve, _ellipse)
    hole = (polar.l > 0.35) & (polar.l < 0.65) & (np.mod(polar.angle, 2 * np.pi) < np.pi / 2)  # 12 mm x 90 deg
    kept = polar.subset(~hole)
    with pytest.raises(FitError, match=r"smoothing is 0 .* l = 0\.3.*\.\.0\.6.*set fit\.smoothing > 0"):
        fit_radius_surface(kept, curve.length, FitSettings(smoothing=0.0))
    fit = fit_radius_surface(kept, curve.length, FitSettings())
    l, a = np.meshgrid(np.linspace(0.35, 0.65, 31), np.linspace(0.0, np.pi / 2, 31), indexing="ij")
    inside = fit.whole.evaluate(l, a)
    # Bounded: within the true section's 3..4 mm, and within 0.4 mm of the hidden truth
    # (the thin plate spans the hole more flatly than the ellipse; measured 0.31 mm).
    assert 3.0 <= inside.min() and inside.max() <= 4.0
    assert np.abs(inside - _ellipse(l, a)).max() <= 0.4


def test_a_surface_beside_the_path_is_refused():
    curve = Line(40.0)
    rng = np.random.default_rng(2)
    l, a = grid_parameters(40, 30, rng)
    beside = tube_points(curve, l, a, np.full_like(l, 3.0)) + np.array([10.0, 0.0, 0.0])
    with pytest.raises(FitError, match=r"surround only 0% of the path .* check final\.surface, final\.path and units"):
        fit_radius_surface(project_points(curve, beside), curve.length, FitSettings())


def test_too_few_points_and_bad_settings_are_refused():
    curve = Line(20.0)
    polar = _polar(curve, lambda l, a: np.full_like(l, 2.0), n_l=5, n_a=10)
    with pytest.raises(FitError, match="50 wall points kept, expected at least 96"):
        fit_radius_surface(polar, curve.length, FitSettings())
    with pytest.raises(ConfigError, match="knot_spacing_mm must be > 0 mm, got -2"):
        FitSettings(knot_spacing_mm=-2)
    with pytest.raises(ConfigError, match="angular_intervals must be an integer >= 4, got 3"):
        FitSettings(angular_intervals=3)
    with pytest.raises(ConfigError, match="breaks must rise strictly"):
        FitSettings(breaks=(0.0, 0.6, 0.4, 1.0))


def test_the_fit_scales_with_the_case():
    # The penalty is dimensionless: the same case in units 10x larger gives rho 10x larger.
    curve, big = Arc(20.0, 1.5), Arc(200.0, 1.5)
    polar = _polar(curve, lambda l, a: _ellipse(l, a, 3.0, 2.5))
    polar_big = _polar(big, lambda l, a: 10.0 * _ellipse(l, a, 3.0, 2.5))
    fit = fit_radius_surface(polar, curve.length, FitSettings(knot_spacing_mm=2.0, smoothing=1e-3))
    fit_big = fit_radius_surface(polar_big, big.length, FitSettings(knot_spacing_mm=20.0, smoothing=1e-3))
    # Relative rounding of the two solves, times the 25 mm coefficients.
    np.testing.assert_allclose(fit_big.whole.coefficients, 10.0 * fit.whole.coefficients, rtol=0, atol=1e-9)


def test_the_gram_by_blocks_is_the_sparse_product_of_the_design_matrix():
    # points in every span along and around, repeated spans, the wrap and the clamped ends
    rng = np.random.default_rng(3)
    l = np.concatenate([rng.random(5000), [0.0, 1.0, 0.5, 0.5]])
    angle = np.concatenate([rng.uniform(-np.pi, np.pi, 5000), [np.pi, -np.pi, 0.0, 2 * np.pi]])
    knots = bb.open_knots([0.0, 0.4, 1.0], [7, 9])
    design, gram = design_and_gram(knots, 6, l, angle)
    assert (design != design_matrix(knots, 6, l, angle)).nnz == 0
    assert gram.shape == (design.shape[1], design.shape[1])
    np.testing.assert_allclose(gram.toarray(), (design.T @ design).toarray(), rtol=0, atol=GRAM_TOL)
