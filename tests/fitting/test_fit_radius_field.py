"""rho(q, l, a): the blend, the initial radius choices, storage as arrays, and the self-folding check."""

from __future__ import annotations

import io
import pickle

import numpy as np
import pytest

from softdesign.errors import FitError, FoldError
from softdesign.fitting import bspline_basis as bb
from softdesign.fitting import radius_field, radius_rows
from softdesign.fitting.bspline_surface import RadiusSpline, split_at_breaks
from softdesign.fitting.radius_field import (
    FOLD_ANGLES_PER_INTERVAL,
    RadiusField,
    axisymmetric,
    check_self_folding,
    constant_like,
    fold_margin,
)
from softdesign.fitting.radius_rows import SlopeRows
from tests.helpers.analytic import Arc, Helix

#: Spline evaluations of O(5 mm) values.
VALUE_TOL_MM = 1e-12


def _random_links(breaks=(0.0, 0.4, 1.0), intervals=12, seed=0):
    rng = np.random.default_rng(seed)
    links = []
    for lo, hi in zip(breaks[:-1], breaks[1:], strict=True):
        knots = bb.open_knots([lo, hi], [5])
        links.append(RadiusSpline(knots, 3.0 + 0.4 * rng.uniform(-1, 1, (len(knots) - 4, intervals))))
    return tuple(links)


def test_axisymmetric_initial_is_the_mean_around_each_l():
    final = _random_links()[0]
    l = np.linspace(0.0, 0.4, 9)
    angle = np.linspace(0.0, 2 * np.pi, 4001)[:-1]
    mean_around = final.evaluate_grid(l, angle).mean(axis=1)  # the rectangle rule is exact for periodic splines
    np.testing.assert_allclose(axisymmetric(final).evaluate_grid(l, angle[:7]), np.repeat(mean_around[:, None], 7, 1),
                               rtol=0, atol=VALUE_TOL_MM)


def test_constant_initial_and_the_blend_between_shapes():
    final = _random_links()
    field = RadiusField.from_links((0.0, 0.4, 1.0), final, radius_mm=2.0)
    l, angle = np.linspace(0.0, 1.0, 21), np.linspace(-np.pi, np.pi, 11)
    np.testing.assert_allclose(field.evaluate_grid(0.0, l, angle), 2.0, rtol=0, atol=VALUE_TOL_MM)
    rho_f = field.evaluate_grid(1.0, l, angle)
    blend = field.evaluate_grid(0.25, l, angle)
    np.testing.assert_allclose(blend, 0.75 * 2.0 + 0.25 * rho_f, rtol=0, atol=VALUE_TOL_MM)
    first = l <= 0.4 - 1e-12
    np.testing.assert_allclose(rho_f[first], final[0].evaluate_grid(l[first], angle), rtol=0, atol=VALUE_TOL_MM)
    with pytest.raises(FitError, match="radius_mm must be > 0 mm, got -1"):
        constant_like(final[0], -1.0)


def test_field_round_trips_through_npz():
    field = RadiusField.from_links((0.0, 0.4, 1.0), _random_links())
    buffer = io.BytesIO()
    np.savez(buffer, **field.to_arrays())
    buffer.seek(0)
    with np.load(buffer) as stored:
        back = RadiusField.from_arrays(stored)
    l, angle = np.linspace(0.0, 1.0, 31), np.linspace(-np.pi, np.pi, 13)
    for q in (0.0, 0.6, 1.0):
        np.testing.assert_array_equal(back.evaluate_grid(q, l, angle), field.evaluate_grid(q, l, angle))


def test_initial_on_other_knots_is_refused():
    final = _random_links()
    other = _random_links(intervals=8)
    with pytest.raises(FitError, match="link 0: the initial surface's knots differ"):
        RadiusField(np.array([0.0, 0.4, 1.0]), final, other)


def _round_field(radius_at, breaks=(0.0, 1.0), intervals=16):
    """Round sections with a radius linear in l, ``radius_at(l)`` (exact: coefficients at the Greville points)."""
    knots = bb.open_knots(breaks, [4] * (len(breaks) - 1))
    greville = np.array([knots[i + 1 : i + 4].mean() for i in range(len(knots) - 4)])
    spline = RadiusSpline(knots, np.repeat(radius_at(greville)[:, None], intervals, axis=1))
    return RadiusField.from_links(breaks, split_at_breaks(spline, breaks))


def test_fold_margin_of_a_torus_is_r_over_R_on_the_inner_side():
    curve = Arc(20.0, 2.0)
    report = fold_margin(curve, _round_field(lambda l: np.full_like(l, 5.0), breaks=(0.0, 0.3, 1.0)))
    assert report.max_rho_kappa == pytest.approx(5.0 / 20.0, abs=1e-12)
    assert report.angle == 0.0  # +N points to the torus axis: the inner side
    assert report.min_rho_mm == pytest.approx(5.0, abs=VALUE_TOL_MM)


def test_fold_margin_of_a_helix_tube_is_rho_kappa():
    curve = Helix(8.0, 3.0, 1.2)
    report = fold_margin(curve, _round_field(lambda l: np.full_like(l, 2.0)))
    # The grid's angle step 2 pi / (8 * 16) may miss the inner side by half a step: 1 - cos(pi / 128) = 3e-4.
    step = 2 * np.pi / (FOLD_ANGLES_PER_INTERVAL * 16)
    assert 2.0 * curve.curvature * np.cos(step / 2) <= report.max_rho_kappa <= 2.0 * curve.curvature + 1e-12


def test_a_tube_that_folds_names_the_place_and_the_fix():
    curve = Arc(20.0, 2.0)
    growing = _round_field(lambda l: 10.0 + 12.0 * l)  # rho kappa = 0.5 at the inlet, 1.1 at the tip
    with pytest.raises(FitError) as err:
        check_self_folding(curve, growing, q=1.0)
    message = str(err.value)
    # issue 29: the fix offered is the body radius that fits, 0.7 x the 20 mm radius of curvature
    for part in ("q = 1", "rho * kappa = 1.100", "expected < 1", "l = 1.0000 (40.0 mm from the inlet)", "angle 0 deg",
                 "radius of curvature of 20.000 mm", "rho 22.000 mm", "set fit.max_radius_mm: 14.00"):
        assert part in message
    assert isinstance(err.value, FoldError)
    # Within the limit: the report gives the maximum, 15 mm / 20 mm at the tip.
    report = check_self_folding(curve, _round_field(lambda l: 10.0 + 5.0 * l))
    assert report.max_rho_kappa == pytest.approx(0.75, abs=1e-12)
    with pytest.raises(FitError, match="rho reaches -2 mm"):
        check_self_folding(curve, _round_field(lambda l: 2.0 - 4.0 * l))


def test_the_body_radius_offered_for_a_fold_brings_the_capped_body_to_the_stated_reach():
    curve = Arc(20.0, 2.0)
    growing = _round_field(lambda l: 10.0 + 12.0 * l)
    cap = radius_field.fold_fix_radius(curve, growing)
    assert cap == pytest.approx(radius_field.FOLD_FIX_REACH * 20.0, abs=0.01)
    held = RadiusField(growing.breaks, tuple(radius_field.capped(s, cap) for s in growing.final),
                       tuple(radius_field.capped(s, cap) for s in growing.initial))
    report = check_self_folding(curve, held)
    assert report.max_rho_kappa <= radius_field.FOLD_FIX_REACH + 1e-12  # round-off of 0.7 / (1 / 20) * (1 / 20)
    # below the cap the body is the fitted one: capping never raises rho
    l = np.linspace(0.0, 1.0, 101)
    a = np.linspace(0.0, 2 * np.pi, 24, endpoint=False)
    np.testing.assert_array_less(held.evaluate_grid(1.0, l, a), growing.evaluate_grid(1.0, l, a) + 1e-12)
    assert radius_field.fold_fix_radius(curve, _round_field(lambda l: np.full_like(l, 5.0))) == np.inf


def test_an_initial_surface_fitted_with_the_final_layout_blends_with_it():
    # rho0 from another surface: fit it on its own curve but with the final path's length and settings,
    # so both share knots; then rho(q) blends the two fitted shapes.
    from softdesign.fitting.bspline_surface import FitSettings, fit_radius_surface
    from softdesign.fitting.projection import project_points
    from tests.helpers.analytic import Line, grid_parameters, tube_points

    final_curve, initial_curve = Arc(20.0, 2.0), Line(35.0)
    settings = FitSettings(breaks=(0.0, 0.4, 1.0))
    l, a = grid_parameters(50, 30, np.random.default_rng(2))
    final = fit_radius_surface(project_points(final_curve, tube_points(final_curve, l, a, 3.0 + l)),
                               final_curve.length, settings)
    initial = fit_radius_surface(project_points(initial_curve, tube_points(initial_curve, l, a, 2.0 + 0 * l)),
                                 final_curve.length, settings)
    field = RadiusField(np.array(settings.breaks), final.links, initial.links)
    grid_l = np.linspace(0.0, 1.0, 11)
    # Both shapes have no penalty energy, so both fits are exact (to the projection's 1e-10 mm Newton
    # tolerance); the blend at q = 0.5 is (2 + 3 + l) / 2.
    expected = np.repeat((2.5 + grid_l / 2)[:, None], 2, axis=1)
    np.testing.assert_allclose(field.evaluate_grid(0.5, grid_l, [0.0, 2.0]), expected, rtol=0, atol=1e-9)


def test_grid_evaluation_adds_as_the_sparse_basis_product_does():
    """Dense local sums give the bits of ``B (P C^T)^T`` with sparse basis matrices, derivatives included."""
    rng = np.random.default_rng(4)
    for intervals in (4, 7, 24):
        knots = bb.open_knots([0.0, 0.3, 1.0], [3, 5])
        spline = RadiusSpline(knots, rng.normal(3.0, 0.5, (len(knots) - 4, intervals)))
        l, angle = np.append(rng.uniform(0, 1, 30), [0.0, 0.3, 1.0]), rng.uniform(-7, 7, 17)
        for dl, da in ((0, 0), (1, 0), (2, 1), (0, 2)):
            left = bb.open_basis_matrix(knots, l, dl)
            right = bb.periodic_basis_matrix(intervals, angle, da)
            np.testing.assert_array_equal(spline.evaluate_grid(l, angle, dl, da),
                                          left @ (right @ spline.coefficients.T).T)


def test_blend_grid_is_the_blend_of_the_end_grids_cached_or_not(monkeypatch):
    field = RadiusField.from_links((0.0, 0.4, 1.0), _random_links())
    l, angle = np.linspace(0.0, 1.0, 41), np.linspace(0.0, 2 * np.pi, 16, endpoint=False)
    for dl in (0, 1):
        # blending values instead of coefficients: equal up to rounding of O(5 mm) (or O(50 mm/l)) values
        np.testing.assert_allclose(field.blend_grid(0.3, l, angle, dl), field.evaluate_grid(0.3, l, angle, dl),
                                   rtol=0, atol=10 * VALUE_TOL_MM)
    cached = field.blend_grid(0.7, l, angle, dl=1)
    fresh = RadiusField.from_arrays(field.to_arrays())
    np.testing.assert_array_equal(fresh.blend_grid(0.7, l, angle, dl=1), cached)
    initial, final = field.end_grids(l, angle)
    assert not initial.flags.writeable and not final.flags.writeable
    np.testing.assert_array_equal(initial, field.evaluate_grid(0.0, l, angle))
    # the cache stays within its budget (least recently used first out) and out of pickles
    monkeypatch.setattr("softdesign.fitting.radius_field.GRID_CACHE_BYTES", 2 * initial.nbytes * 2)
    for count in range(5, 9):
        field.end_grids(np.linspace(0.0, 1.0, count), angle)
    field.end_grids(l, angle)
    assert sum(g.nbytes for g in field._grid_cache.values()) <= 4 * initial.nbytes
    assert "_grid_cache" not in pickle.loads(pickle.dumps(field)).__dict__


def test_slope_rows_give_the_bits_of_the_grid_evaluations_in_any_block_and_order(monkeypatch):
    """rho, rho_l and rho_a a block of rows at a time: the numbers of evaluate_grid, unsorted l included."""
    field = RadiusField.from_links((0.0, 0.4, 1.0), _random_links())
    rng = np.random.default_rng(5)
    angle = rng.uniform(-7, 7, 13)
    for l in (np.linspace(0.0, 1.0, 37), np.append(rng.uniform(0, 1, 30), [0.0, 0.4, 1.0])):
        whole = [field.evaluate_grid(0.3, l, angle, dl, da) for dl, da in ((0, 0), (1, 0), (0, 1))]
        rows = SlopeRows(field, 0.3, l, angle)
        for step in (1, 7, len(l)):
            blocks = [rows(start, start + step) for start in range(0, len(l), step)]
            for k in range(3):
                assert np.concatenate([b[k] for b in blocks]).tobytes() == whole[k].tobytes()
        values = SlopeRows(field, 0.3, l, angle, slopes=False)
        assert np.concatenate([values.values(s, s + 5) for s in range(0, len(l), 5)]).tobytes() == whole[0].tobytes()
        with pytest.raises(ValueError, match="slopes=False"):
            values(0, 5)
        with pytest.raises(ValueError, match="slopes=False"):
            values.along(0, 5)
        along = SlopeRows(field, 0.3, l, angle, angular=False)  # rho and rho_l only
        blocks = [along.along(start, start + 7) for start in range(0, len(l), 7)]
        for k in range(2):
            assert np.concatenate([b[k] for b in blocks]).tobytes() == whole[k].tobytes()
        with pytest.raises(ValueError, match="angular=False"):
            along(0, 5)
    # the bases along l are kept per l (read-only, within their budget, out of pickles)
    l = np.linspace(0.0, 1.0, 37)
    assert field.along_bases(l) is field.along_bases(l.copy())
    assert not field.along_bases(l)[0][3].flags.writeable
    monkeypatch.setattr(radius_field, "BASIS_CACHE_BYTES", 1)
    field.along_bases(np.linspace(0.0, 1.0, 5))
    assert len(field._basis_cache) == 1
    assert "_basis_cache" not in pickle.loads(pickle.dumps(field)).__dict__


def test_fold_margin_in_blocks_of_rows_is_the_whole_grid_s(monkeypatch):
    """The folding check scans a few rows at a time: the same maximum, place and smallest radius."""
    field = RadiusField.from_links((0.0, 0.4, 1.0), _random_links())
    curve = Helix(8.0, 3.0, 1.2)
    monkeypatch.setattr(radius_rows, "BLOCK_POINTS", 10**9)
    whole = fold_margin(curve, field, 0.6)
    monkeypatch.setattr(radius_rows, "BLOCK_POINTS", 7 * FOLD_ANGLES_PER_INTERVAL * 12)
    assert fold_margin(curve, field, 0.6) == whole
