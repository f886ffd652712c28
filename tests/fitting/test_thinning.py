"""The even subset the surface is fitted to above MAX_FIT_POINTS: every knot cell its share, the same every time."""

from __future__ import annotations

import numpy as np

from softdesign.fitting.projection import PolarPoints
from softdesign.fitting.selection import NetworkContext
from softdesign.fitting.thinning import even_subset
from softdesign.fitting.wall_fit import WallFitOptions, fit_wall
from softdesign.limits.fit import MAX_FIT_POINTS
from tests.fitting.test_fit_wall import EXACT_TOL_MM, _capped_torus
from tests.helpers.analytic import Arc


def _polar(l, angle):
    n = len(l)
    return PolarPoints(np.zeros((n, 3)), np.asarray(l, float), np.asarray(angle, float), np.ones(n),
                       np.zeros(n, np.int8))


def test_few_points_are_all_kept():
    polar = _polar(np.linspace(0, 1, 50), np.zeros(50))
    np.testing.assert_array_equal(even_subset(polar, 4, 8, 50), np.arange(50))


def test_every_cell_keeps_its_share_spread_along_it_and_the_same_points_every_time():
    rng = np.random.default_rng(7)
    # uneven density: three times as many points on the first half of the path, and a dense strip around a = 0
    l = np.concatenate([rng.uniform(0, 0.5, 30_000), rng.uniform(0.5, 1, 10_000), rng.uniform(0, 1, 8_000)])
    angle = np.concatenate([rng.uniform(-np.pi, np.pi, 40_000), rng.uniform(-0.1, 0.1, 8_000)])
    polar, along, around, count = _polar(l, angle), 10, 12, 12_000
    kept = even_subset(polar, along, around, count)
    assert len(kept) == count and np.all(np.diff(kept) > 0)
    np.testing.assert_array_equal(kept, even_subset(polar, along, around, count))

    def cells(index):
        row = np.minimum((l[index] * along).astype(int), along - 1)
        column = np.minimum((np.mod(angle[index], 2 * np.pi) / (2 * np.pi) * around).astype(int), around - 1)
        return np.bincount(row * around + column, minlength=along * around)

    share = cells(np.arange(len(l))) * count / len(l)
    assert np.max(np.abs(cells(kept) - share)) <= 1.0  # evenly spaced ranks: each cell's share to within one
    # along a cell, the kept points spread over its length: the dense first half's cells keep points in both halves
    first = kept[(l[kept] < 0.1) & (np.mod(angle[kept], 2 * np.pi) < 2 * np.pi / around)]
    assert l[first].min() < 0.02 and l[first].max() > 0.08


def test_a_wall_fitted_to_a_quarter_of_its_points_is_still_exact():
    curve = Arc(40.0, 1.2)
    vertices, wall_count = _capped_torus(curve, np.random.default_rng(3))
    path = curve.points(np.linspace(0.0, 1.0, 49))
    network = NetworkContext(path, (), np.linspace(0.0, 1.0, 49), 2.5 + 0.5 * np.linspace(0.0, 1.0, 49))
    options = WallFitOptions(fit_points=wall_count // 4)
    result = fit_wall(curve, vertices, network, options, np.random.default_rng(0))
    assert result.surface.point_count == wall_count // 4 < result.selection.counts["kept"] == wall_count
    # the figures are of every kept point, and the subset still pins the exact surface
    assert result.metrics.count == wall_count and result.metrics.max_mm <= EXACT_TOL_MM
    assert wall_count < MAX_FIT_POINTS  # the default fits them all
    assert fit_wall(curve, vertices, network, WallFitOptions(), np.random.default_rng(0)).surface.point_count == (
        wall_count)
