"""True point-to-surface distances against closed forms, summaries, hold-out and the ``auto`` spacing."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import ConfigError
from softdesign.fitting import closest
from softdesign.fitting.bspline_surface import FitSettings, fit_radius_surface, fold_solver
from softdesign.fitting.closest import CLOSEST_TOL_MM, closest_surface_points, frame_twist_table, surface_points
from softdesign.fitting.metrics import (
    HoldoutSettings,
    choose_knot_spacing,
    fold_labels,
    holdout_rms,
    holdout_sample,
    measure_distances,
    measure_fit,
    summarize_distances,
)
from softdesign.fitting.projection import project_points
from tests.helpers.analytic import Arc, FrenetHelix, Helix, Line, grid_parameters, tube_points
from tests.helpers.workers import two_worker_mapper

#: Gauss-Newton stops at 1e-5 mm steps, past which the distance barely moves: the distances here come out within
#: ~1e-13 mm of the closed forms (the fitted shapes are exact to ~1e-12 mm).
DISTANCE_TOL_MM = 1e-8


def _fitted(curve, rho_of, settings=FitSettings(), grid=(50, 36)):
    rng = np.random.default_rng(4)
    l, a = grid_parameters(*grid, rng)
    polar = project_points(curve, tube_points(curve, l, a, rho_of(l, a)))
    return fit_radius_surface(polar, curve.length, settings)


def _off_surface(curve, rho_of, offset, seed=9):
    rng = np.random.default_rng(seed)
    l, a = rng.uniform(0.1, 0.9, 400), rng.uniform(-np.pi, np.pi, 400)
    return l, a, project_points(curve, tube_points(curve, l, a, rho_of(l, a) + offset(rng, 400)))


@pytest.mark.parametrize("curve", [Line(30.0), Arc(25.0, 1.2)], ids=["cylinder", "torus"])
def test_distance_to_a_round_tube_is_the_radial_offset(curve):
    fit = _fitted(curve, lambda l, a: np.full_like(l, 3.0))
    _, _, polar = _off_surface(curve, lambda l, a: np.full_like(l, 3.0), lambda rng, n: rng.uniform(-1, 1, n))
    distance, _, _ = closest_surface_points(curve, fit.whole, polar)
    np.testing.assert_allclose(distance, np.abs(polar.rho - 3.0), rtol=0, atol=DISTANCE_TOL_MM)


def test_distance_to_a_cone_is_less_than_the_radial_residual():
    # rho = r0 + k s along a line: the meridian is a straight line, distance |rho - r0 - k s| / sqrt(1 + k^2).
    length, r0, k = 30.0, 2.0, 0.1
    curve = Line(length)
    fit = _fitted(curve, lambda l, a: r0 + k * length * l)
    l, _, polar = _off_surface(curve, lambda l, a: r0 + k * length * l, lambda rng, n: rng.uniform(-0.5, 0.5, n))
    exact = np.abs(polar.rho - r0 - k * length * polar.l) / np.sqrt(1.0 + k**2)
    distance, l_closest, _ = closest_surface_points(curve, fit.whole, polar)
    np.testing.assert_allclose(distance, exact, rtol=0, atol=DISTANCE_TOL_MM)
    assert np.all(np.abs(l_closest - polar.l) > 0) and np.all(distance < np.abs(polar.rho - r0 - k * length * polar.l))


def test_frame_twist_is_zero_for_rotation_minimizing_frames_and_the_torsion_for_frenet():
    rmf, frenet = Helix(8.0, 3.0, 1.5), FrenetHelix(8.0, 3.0, 1.5)
    # Central differences of exact frames: ~1e-10 inside, ~1e-5 (one-sided, per unit l) at the ends.
    np.testing.assert_allclose(frame_twist_table(rmf)[1], 0.0, rtol=0, atol=1e-4)
    np.testing.assert_allclose(frame_twist_table(frenet)[1], frenet.torsion * frenet.length, rtol=1e-6, atol=0)


@pytest.mark.parametrize("curve", [Helix(8.0, 3.0, 1.5), FrenetHelix(8.0, 3.0, 1.5)], ids=["rmf", "frenet"])
def test_closest_points_see_the_surface_square_on_around_a_twisting_frame(curve):
    # An oval tube on a helix: at the closest point p - S is normal to the surface (tangents by central
    # differences of S), up to where Gauss-Newton stops (a step under CLOSEST_TOL_MM leaves ~1e-6 mm here).
    # With the Frenet frames' twist left out the residual keeps a 0.018 mm tangential part.
    rho_of = lambda l, a: 2.0 + 0.4 * np.cos(2 * a) + 0.3 * l  # noqa: E731
    fit = _fitted(curve, rho_of, FitSettings(knot_spacing_mm=1.0, smoothing=0.0), grid=(160, 48))
    _, _, polar = _off_surface(curve, rho_of, lambda rng, n: rng.uniform(-0.5, 0.5, n))
    _, l, a = closest_surface_points(curve, fit.whole, polar)
    residual, h = polar.points - surface_points(curve, fit.whole, l, a), 1e-6
    for dl, da in ((h, 0.0), (0.0, h)):
        tangent = surface_points(curve, fit.whole, l + dl, a + da) - surface_points(curve, fit.whole, l - dl, a - da)
        along = np.einsum("ni,ni->n", residual, tangent) / np.linalg.norm(tangent, axis=1)
        np.testing.assert_allclose(along, 0.0, rtol=0, atol=CLOSEST_TOL_MM)


def test_summary_of_known_distances():
    metrics = summarize_distances(np.array([3.0, -4.0]))
    assert metrics.rms_mm == pytest.approx(np.sqrt(12.5), abs=1e-15)
    assert metrics.max_mm == 4.0 and metrics.count == 2
    spread = summarize_distances(np.arange(101.0))
    assert (spread.p95_mm, spread.p99_mm) == (95.0, 99.0)
    assert set(spread.as_dict()) == {"rms_mm", "p95_mm", "p99_mm", "max_mm", "count", "total"}
    assert spread.as_dict()["total"] == 101


def _noisy_tube(sigma=0.05, seed=12, outliers=()):
    """2400 points on a cone with noise; the points at the indices ``outliers`` stand 0.6 mm out."""
    curve = Line(30.0)
    rng = np.random.default_rng(seed)
    l, a = grid_parameters(60, 40, rng)
    rho = 3.0 + 0.5 * l + rng.normal(0, sigma, l.size)
    rho[list(outliers)] += 0.6
    return curve, project_points(curve, tube_points(curve, l, a, rho))


def test_radial_residual_bounds_the_true_distance_from_above():
    # p and S(l_p, a_p) lie on one ray from c(l_p): their distance is |rho_p - rho(l_p, a_p)| >= the least.
    curve, noisy = _noisy_tube(sigma=0.2)
    fit = fit_radius_surface(noisy, curve.length, FitSettings())
    true = closest_surface_points(curve, fit.whole, noisy)[0]
    radial = np.abs(noisy.rho - fit.whole.evaluate(noisy.l, noisy.angle))
    assert np.all(true <= radial + 1e-12)
    assert np.mean(true < radial - 1e-6) > 0.5  # a bound, not the same figure


def test_distances_of_a_large_input_come_from_a_sample_and_the_max_from_every_point():
    # Three outliers where the seeded sample of 400 will not look (the draw depends on the count only).
    missed = np.setdiff1d(np.arange(2400), holdout_sample(2400, 400, np.random.default_rng(0)))[[0, 700, 1900]]
    curve, noisy = _noisy_tube(outliers=missed)
    spline = fit_radius_surface(noisy, curve.length, FitSettings()).whole
    every = closest_surface_points(curve, spline, noisy)[0]
    whole = measure_distances(curve, spline, noisy, np.random.default_rng(0))
    assert whole.metrics == measure_fit(curve, spline, noisy) and len(whole.sample) == len(noisy)
    sampled = measure_distances(curve, spline, noisy, np.random.default_rng(0), max_points=400)
    m = sampled.metrics
    assert (m.count, m.total, len(sampled.distance)) == (400, len(noisy), 400)
    np.testing.assert_array_equal(sampled.distance, every[sampled.sample])
    # The outliers are not in the sample; the maximum is still theirs, exactly.
    assert m.max_mm == every.max() and every.max() > sampled.distance.max() + 0.3
    # RMS over 400 of 2400 points: within ~10 % of the RMS of all points but the outliers.
    assert m.rms_mm == pytest.approx(np.sqrt(np.mean(every[every < 0.4] ** 2)), rel=0.1)
    again = measure_distances(curve, spline, noisy, np.random.default_rng(0), max_points=400)
    np.testing.assert_array_equal(again.sample, sampled.sample)


def test_the_exact_max_with_its_bounds_on_workers_is_the_same(monkeypatch):
    from softdesign.fitting import metrics as fm
    from softdesign.pipeline.parallel import jobs_for_build, map_items

    curve, noisy = _noisy_tube()
    spline = fit_radius_surface(noisy, curve.length, FitSettings()).whole
    sample = np.sort(np.random.default_rng(2).choice(len(noisy), size=400, replace=False))
    first = fm.summarize_distances(np.zeros(400))  # a sample's max of 0: every other point's bound is doubtful
    here = fm.with_exact_max(curve, spline, noisy, sample, first)
    monkeypatch.setattr(fm, "PROJECT_BLOCK", 300)  # the other 2000 points in 7 blocks
    with jobs_for_build(2):
        forked = fm.with_exact_max(curve, spline, noisy, sample, first, map_items)
    assert forked == here and here.max_mm == fm.closest_surface_points(curve, spline, noisy)[0].max()  # every point's


def test_fold_solves_equal_fresh_fits_on_the_other_folds():
    curve, noisy = _noisy_tube()
    labels = fold_labels(len(noisy), 4, np.random.default_rng(3))
    solve = fold_solver(noisy, curve.length, FitSettings(), labels)
    for k in range(4):
        spline = solve(k)
        fresh = fit_radius_surface(noisy.subset(labels != k), curve.length, FitSettings()).whole
        np.testing.assert_array_equal(spline.knots, fresh.knots)
        np.testing.assert_allclose(spline.coefficients, fresh.coefficients, rtol=0, atol=1e-10)


def test_each_folds_rows_assembled_apart_on_workers_give_the_same_solves_to_the_bit():
    from softdesign.fitting.surface_system import design_matrix
    from softdesign.pipeline.parallel import jobs_for_build, map_items

    curve, noisy = _noisy_tube()
    labels = fold_labels(len(noisy), 4, np.random.default_rng(3))
    with jobs_for_build(2):
        forked = fold_solver(noisy, curve.length, FitSettings(), labels, map_items)
    here = fold_solver(noisy, curve.length, FitSettings(), labels)
    # the assembly it replaced: one design matrix of every point, each fold's rows taken from it
    knots = forked(0).knots
    design = design_matrix(knots, FitSettings().angular_intervals, noisy.l, noisy.angle)
    rows = np.flatnonzero(labels == 1)
    alone = design_matrix(knots, FitSettings().angular_intervals, noisy.l[rows], noisy.angle[rows])
    for mine, theirs in zip((alone.data, alone.indices, alone.indptr), (design[rows].data, design[rows].indices,
                                                                         design[rows].indptr), strict=True):
        np.testing.assert_array_equal(mine, theirs)
    for k in range(4):
        np.testing.assert_array_equal(forked(k).coefficients, here(k).coefficients)


def test_folds_are_balanced_and_reproducible_from_the_seed():
    a = fold_labels(103, 5, np.random.default_rng(7))
    b = fold_labels(103, 5, np.random.default_rng(7))
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(np.bincount(a), [21, 21, 21, 20, 20])
    assert not np.array_equal(a, fold_labels(103, 5, np.random.default_rng(8)))
    with pytest.raises(ConfigError, match="holdout_folds must be an integer >= 2, got 1"):
        HoldoutSettings(folds=1)


def test_holdout_of_an_exact_shape_is_zero_and_of_noise_is_the_noise():
    curve = Line(30.0)
    rng = np.random.default_rng(12)
    l, a = grid_parameters(60, 40, rng)
    exact = project_points(curve, tube_points(curve, l, a, 3.0 + 0.5 * l))
    assert holdout_rms(curve, exact, FitSettings(), np.random.default_rng(0)).rms_mm <= DISTANCE_TOL_MM
    sigma = 0.05
    noisy = project_points(curve, tube_points(curve, l, a, 3.0 + 0.5 * l + rng.normal(0, sigma, l.size)))
    report = holdout_rms(curve, noisy, FitSettings(), np.random.default_rng(0))
    trained = measure_fit(curve, fit_radius_surface(noisy, curve.length, FitSettings()).whole, noisy)
    # Held-out error estimates the noise from above: 2400 points, ~520 coefficients -> ~1.1 sigma.
    assert sigma <= report.rms_mm <= 1.3 * sigma
    assert trained.rms_mm < report.rms_mm
    assert report.fold_rms_mm.shape == (5,)


def test_holdout_starts_anywhere_and_samples_only_large_inputs_by_the_seed():
    curve = Line(30.0)
    rng = np.random.default_rng(12)
    l, a = grid_parameters(60, 40, rng)
    noisy = project_points(curve, tube_points(curve, l, a, 3.0 + 0.5 * l + rng.normal(0, 0.05, l.size)))
    full = holdout_rms(curve, noisy, FitSettings(), np.random.default_rng(0))
    assert full.points == len(noisy)
    # Starting from the closest points on the fit to all points changes the steps, not the distances.
    _, l_fit, a_fit = closest_surface_points(curve, fit_radius_surface(noisy, 30.0, FitSettings()).whole, noisy)
    warm = holdout_rms(curve, noisy, FitSettings(), np.random.default_rng(0), start=(l_fit, a_fit))
    np.testing.assert_allclose(warm.fold_rms_mm, full.fold_rms_mm, rtol=0, atol=DISTANCE_TOL_MM)
    # Up to max_points nothing is drawn: the folds, so the figures, are those of every point.
    same = holdout_rms(curve, noisy, FitSettings(), np.random.default_rng(0), HoldoutSettings(max_points=len(noisy)))
    np.testing.assert_array_equal(same.fold_rms_mm, full.fold_rms_mm)
    small = HoldoutSettings(max_points=1200)
    sampled = [holdout_rms(curve, noisy, FitSettings(), np.random.default_rng(seed), small) for seed in (0, 0, 1)]
    assert sampled[0].points == 1200
    np.testing.assert_array_equal(sampled[0].fold_rms_mm, sampled[1].fold_rms_mm)
    assert not np.array_equal(sampled[0].fold_rms_mm, sampled[2].fold_rms_mm)
    # Still bounded below by the noise; 960 points per fit for ~520 coefficients over-fit more (~1.4 sigma),
    # which is why only inputs far denser than the knots are sampled (HOLDOUT_MAX_POINTS).
    assert 0.05 <= sampled[0].rms_mm <= 1.5 * 0.05
    with pytest.raises(ConfigError, match="max_points must be an integer >= 2 x folds"):
        HoldoutSettings(max_points=3)


def test_auto_spacing_rejects_knots_too_coarse_for_the_shape():
    # An axial ripple of 8 mm wavelength: 8 mm knots cannot follow it, 1-2 mm knots can.
    curve = Line(48.0)
    rng = np.random.default_rng(21)
    l, a = grid_parameters(96, 24, rng)
    rho = 3.0 + 0.3 * np.sin(2 * np.pi * 48.0 * l / 8.0) + rng.normal(0, 0.02, l.size)
    polar = project_points(curve, tube_points(curve, l, a, rho))
    holdout = HoldoutSettings(candidates_mm=(1.0, 2.0, 8.0))
    best, scores = choose_knot_spacing(curve, polar, FitSettings(), np.random.default_rng(0), holdout)
    assert set(scores) == {1.0, 2.0, 8.0}
    assert best in (1.0, 2.0)
    assert scores[8.0] > 3 * scores[best]


def test_distances_are_the_same_bits_in_blocks_on_worker_processes(monkeypatch):
    # the build hands the blocks of points to its worker processes (map_items): each point's search is its own
    curve, noisy = _noisy_tube(sigma=0.2)
    spline = fit_radius_surface(noisy, curve.length, FitSettings()).whole
    whole = measure_distances(curve, spline, noisy, np.random.default_rng(0))
    monkeypatch.setattr(closest, "CLOSEST_CHUNK", 500)
    mapper, blocks = two_worker_mapper()
    split = measure_distances(curve, spline, noisy, np.random.default_rng(0), mapper=mapper)
    assert blocks == [5]
    assert split.metrics == whole.metrics
    for name in ("distance", "l", "angle"):
        np.testing.assert_array_equal(getattr(split, name), getattr(whole, name))
    assert split.curve_part is not None and whole.curve_part is not None
    for a, b in zip(split.curve_part.arrays(), whole.curve_part.arrays(), strict=True):
        np.testing.assert_array_equal(a, b)
