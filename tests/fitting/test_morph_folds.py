"""The fitted body's fold test at every q of the morph's search (issue 29, item 0)."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.fitting.morph_folds import Q_XTOL, fold_over_morph
from tests.fitting.test_fit_radius_field import _round_field
from tests.helpers.analytic import Arc

RHO = 5.0
GRID = np.linspace(0.0, 1.0, 41)


def test_a_morph_bending_steadily_reaches_its_largest_rho_kappa_at_q_1_and_is_not_warned_about():
    # arcs of length 10 mm bending to a 20 mm radius at q = 1: rho * kappa = rho / R(q), largest at q = 1
    found = fold_over_morph(lambda q: Arc(20.0 / max(q, 1e-3), 0.5 * max(q, 1e-3)),
                            _round_field(lambda l: np.full_like(l, RHO)), GRID)
    assert found.q == 1.0 and found.report.max_rho_kappa == pytest.approx(RHO / 20.0, abs=1e-9)
    assert found.warning() is None and found.as_dict()["q_samples"] == 41


def test_a_body_folding_between_the_grid_q_is_found_and_warned_about():
    # curvature 4 q (1 - q) / 4 mm: the body of radius 5 mm folds mid-morph, worst at q = 0.5, between grid values
    def shape(q: float) -> Arc:
        kappa = max(4.0 * q * (1.0 - q), 1e-3) / 4.0
        return Arc(1.0 / kappa, 10.0 * kappa)

    found = fold_over_morph(shape, _round_field(lambda l: np.full_like(l, RHO)), np.linspace(0.0, 1.0, 8))
    assert found.q == pytest.approx(0.5, abs=10 * Q_XTOL)
    assert found.report.max_rho_kappa == pytest.approx(RHO / 4.0, rel=1e-4)
    warning = found.warning()
    assert warning is not None and "folds mid-morph: at q = 0.5" in warning and "fit.max_radius_mm" in warning
    # issue 43: the blend in use is never the advice; intrinsic is offered only to a linear morph
    assert "blend: intrinsic" in warning
    on_intrinsic = found.warning("intrinsic")
    assert on_intrinsic is not None and "blend:" not in on_intrinsic and "fit.local_max_radius" in on_intrinsic


def test_the_grid_on_two_worker_processes_gives_the_same_fold():
    from softdesign.pipeline.parallel import jobs_for_build, map_items

    def shape(q: float) -> Arc:
        kappa = max(4.0 * q * (1.0 - q), 1e-3) / 4.0
        return Arc(1.0 / kappa, 10.0 * kappa)

    field = _round_field(lambda l: np.full_like(l, RHO))
    with jobs_for_build(2):
        forked = fold_over_morph(shape, field, GRID, map_items)
    assert forked == fold_over_morph(shape, field, GRID)


def test_the_reports_around_curves_built_here_are_kept_for_a_later_stage_and_only_for_those_curves():
    from softdesign.fitting.radius_field import fold_margin, known_fold_margin
    from softdesign.pipeline.parallel import jobs_for_build, map_items

    curves = {q: Arc(20.0 / max(q, 1e-3), 0.5 * max(q, 1e-3)) for q in GRID.tolist()}
    built = {q: curves[q] for q in GRID.tolist()[::2]}  # the curves "built already": every other q
    field = _round_field(lambda l: np.full_like(l, RHO))
    with jobs_for_build(2):  # the reports come back from the workers
        fold_over_morph(curves.__getitem__, field, GRID, map_items, built=built.get)
    for q, curve in curves.items():
        kept = known_fold_margin(curve, field, q)
        assert kept == fold_margin(curve, field, q)  # kept or computed, the same report
        assert (kept is field.__dict__["_fold_cache"].get(q, (None, None))[1]) == (q in built)
    other = Arc(10.0, 0.5)  # another curve at a kept q is computed, not answered from the kept report
    answer = known_fold_margin(other, field, 0.0)
    assert answer == fold_margin(other, field, 0.0) != fold_margin(curves[0.0], field, 0.0)



def test_a_framed_curves_fold_grid_is_made_once_and_the_same_for_every_field():
    # the blend's look at the body and the fit check the same curves with different fields: the curve's part of
    # the grid is kept on it (and travels with it from a worker), the reports the same as a fresh curve's
    import pickle

    from softdesign.fitting.radius_field import fold_grid, fold_margin
    from softdesign.geometry.blend import blend_shapes
    from softdesign.geometry.curves import CurveOptions, smooth_curve_from_polyline
    from softdesign.geometry.initial import arc_initial_shape, straight_initial_shape

    def shape():
        line = np.column_stack([np.zeros(50), np.zeros(50), np.linspace(0, 60, 50)])
        final = arc_initial_shape(smooth_curve_from_polyline(line, CurveOptions(count=121, smoothing_mm=0.0)),
                                  bend_radius_mm=25.0, bend_plane_rad=0.7)
        return blend_shapes(straight_initial_shape(final), final)

    thin, thick = _round_field(lambda l: np.full_like(l, 1.0)), _round_field(lambda l: np.full_like(l, RHO))
    curve = pickle.loads(pickle.dumps(shape().curve_at(0.6)))  # as a worker hands it back
    first = fold_grid(curve, thin)
    again = fold_grid(pickle.loads(pickle.dumps(curve)), thick)  # made once: kept, and carried by the pickle
    assert np.shares_memory(first[0], curve.kept(("fold_grid", len(first[0])), lambda: None)[0])
    for mine, other in zip(first[::2], again[::2], strict=True):
        np.testing.assert_array_equal(mine, other)
    fresh = shape().curve_at(0.6)
    for field in (thin, thick):
        assert fold_margin(curve, field, 0.6) == fold_margin(fresh, field, 0.6)
