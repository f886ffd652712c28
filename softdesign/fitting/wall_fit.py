"""Step 4 of the method on one path, in one call: project, select, fit, measure, check, blend.

This is the whole fit stage without files or printing, for the pipeline to
call with the case's settings and to record :meth:`WallFit.summary` in the
manifest.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import numpy.typing as npt

from softdesign.errors import FitError, FoldError
from softdesign.fitting import bspline_basis as bb
from softdesign.fitting.bspline_surface import (
    FitSettings,
    RadiusSpline,
    SurfaceFit,
    fit_radius_surface,
    intervals_per_link,
)
from softdesign.fitting.coverage import WallCoverage, measure_coverage
from softdesign.fitting.end_checks import end_radii, negative_radius_cause
from softdesign.fitting.end_hold import negative_end
from softdesign.fitting.end_prior import end_prior
from softdesign.fitting.local_cap import LocalCap, fold_advice, fold_stretches, surface_capped_locally
from softdesign.fitting.mapping import Job, Mapper, map_together, serial_map
from softdesign.fitting.metrics import (
    FitMetrics,
    HoldoutJob,
    HoldoutReport,
    HoldoutSettings,
    MeasuredDistances,
    choose_knot_spacing,
    distances_job,
    holdout_plan,
)
from softdesign.fitting.projection import PROJECT_BLOCK, PolarPoints, project_points
from softdesign.fitting.radius_field import (
    FOLD_SPACING_MM,
    FoldReport,
    RadiusField,
    capped,
    check_self_folding,
    fold_margin,
)
from softdesign.fitting.selection import NetworkContext, SelectionSettings, WallSelection, select_wall_points
from softdesign.fitting.thinning import even_subset
from softdesign.limits.fit import MAX_FIT_POINTS
from softdesign.types import FloatArray, FramedCurve

#: The steps of :func:`fit_wall`, told to ``WallFitOptions.progress`` as each ends.
FIT_STEPS = ("projection", "selection", "spline", "distances", "hold-out", "fold check", "coverage")


@dataclass(frozen=True)
class WallFitOptions:
    """Everything the fit stage is told.

    Attributes
    ----------
    fit : spline space, penalty and link breaks (its spacing is ignored when ``auto_spacing``)
    auto_spacing : choose the knot spacing by hold-out (``knot_spacing_mm: auto``)
    selection : thresholds of the point selection
    holdout : folds, the spacings ``auto`` tries, and the most points the hold-out uses
    initial_radius_mm : constant rho0; None for the axially symmetric mean of the fit
    fold_limit : the largest rho * kappa allowed at q = 1
    end_margin_mm : kept points within this arc length of either end are left out of the fit, mm
    max_radius_mm : the fitted rho held at most this (:func:`~softdesign.fitting.radius_field.capped`), mm;
        None: as fitted
    local_caps : the fitted rho held at most a radius over stretches of the path only
        (:mod:`softdesign.fitting.local_cap`)
    progress : told the name of each of :data:`FIT_STEPS` as it ends (None: nobody)
    fit_points : the most kept points the spline is fitted to (an even subset above it; every figure of the
        fit is still measured on the kept points)
    mapper : runs independent pieces (the hold-out's folds, the projection's and the metrics' blocks of
        points), perhaps on other processes; the same figures for any
    with_field : more work on the fitted radius field, ``field -> (task, items)`` (each item its own), run in the
        hold-out's call of the mapper, where its items keep a worker busy while the folds' last fits run; its
        results, in the order of its items, are ``WallFit.field_results`` (None: no such work)
    known_projection : rows of the vertices (a slice) already projected on the curve fitted around, and their
        projection (:func:`~softdesign.fitting.projection.project_points`' ``known``): not projected again
    """

    fit: FitSettings = field(default_factory=FitSettings)
    auto_spacing: bool = False
    selection: SelectionSettings = field(default_factory=SelectionSettings)
    holdout: HoldoutSettings = field(default_factory=HoldoutSettings)
    initial_radius_mm: float | None = None
    fold_limit: float = 1.0
    end_margin_mm: float = 0.0
    max_radius_mm: float | None = None
    local_caps: tuple[LocalCap, ...] = ()
    mapper: Mapper = serial_map
    progress: Callable[[str], None] | None = None
    fit_points: int = MAX_FIT_POINTS
    with_field: Callable[[RadiusField], Job] | None = None
    known_projection: tuple[slice, PolarPoints] | None = None


@dataclass(frozen=True)
class WallFit:
    """The fit stage's results (all points, selection, splines, metrics, checks, radius field)."""

    polar: PolarPoints
    selection: WallSelection
    settings: FitSettings
    spacing_scores: dict[float, float]
    surface: SurfaceFit
    metrics: FitMetrics
    holdout: HoldoutReport
    folding: FoldReport
    field: RadiusField
    ends: dict[str, dict[str, float]] = dataclasses.field(default_factory=dict)
    #: (n,) mm per surface vertex: the true distance of each measured kept point (the metrics' points), else NaN
    distance: FloatArray = dataclasses.field(default_factory=lambda: np.zeros(0))
    #: the fit against all of the path's own wall, and where it saw none (None: not measured)
    coverage: WallCoverage | None = None
    #: (n,) mm per surface vertex: rho - rho(1, l, a) of ``field`` (empty when not measured)
    residual: FloatArray = dataclasses.field(default_factory=lambda: np.zeros(0))
    #: the results of ``WallFitOptions.with_field``'s work on ``field``, in its items' order (empty without it)
    field_results: tuple[Any, ...] = ()

    def summary(self) -> dict[str, Any]:
        """JSON-ready figures for the manifest (mm, rad; snake_case keys)."""
        return {
            "points": dict(self.selection.counts),
            "settings": {"knot_spacing_mm": self.settings.knot_spacing_mm,
                         "angular_intervals": self.settings.angular_intervals,
                         "smoothing": self.settings.smoothing, "breaks": list(self.settings.breaks)},
            "knot_spacing_scores_mm": {f"{k:g}": v for k, v in self.spacing_scores.items()},
            "distance": self.metrics.as_dict(),
            "holdout_rms_mm": self.holdout.rms_mm,
            "holdout_fold_rms_mm": self.holdout.fold_rms_mm.tolist(),
            "holdout_points": self.holdout.points,
            "radial_rms_mm": self.surface.radial_rms_mm,
            "joint_value_jump_mm": self.surface.joint_value_jump_mm.tolist(),
            "joint_slope_jump": self.surface.joint_slope_jump.tolist(),
            "max_rho_kappa": self.folding.max_rho_kappa,
            "max_rho_kappa_at": {"l": self.folding.l, "arc_mm": self.folding.arc_mm, "angle": self.folding.angle},
            "min_rho_mm": self.folding.min_rho_mm,
            "end_prior": {} if self.settings.prior is None else self.settings.prior.ends,
            "ends": self.ends,
        } | ({} if self.coverage is None else self.coverage.as_dict())


def _fit_kept(curve: FramedCurve, kept: PolarPoints, options: WallFitOptions,
              reference: tuple[FloatArray, FloatArray] | None, rng: np.random.Generator):
    """The end prior, the knot spacing (``auto``), the surface fitted to ``kept``, held at ``max_radius_mm``.

    Above ``options.fit_points`` points the surface is fitted to an even subset of them
    (:func:`~softdesign.fitting.thinning.even_subset`); the prior and the spacing's hold-out see them all.
    """
    settings, scores = options.fit, dict[float, float]()
    prior = end_prior(kept, curve.length, settings.knot_spacing_mm, settings.angular_intervals, reference)
    settings = replace(settings, prior=prior)
    if options.auto_spacing:
        spacing, scores = choose_knot_spacing(curve, kept, settings, rng, options.holdout)
        settings = replace(settings, knot_spacing_mm=spacing)
    fitted = kept if len(kept) <= options.fit_points else kept.subset(
        even_subset(kept, sum(intervals_per_link(curve.length, settings)), settings.angular_intervals,
                    options.fit_points))
    surface = surface_capped_locally(fit_radius_surface(fitted, curve.length, settings), options.local_caps,
                                     curve.length, settings.breaks)
    if options.max_radius_mm is not None:  # every figure after is of the body built
        cap = options.max_radius_mm
        surface = replace(surface, whole=capped(surface.whole, cap), links=tuple(capped(s, cap) for s in surface.links))
    return settings, scores, prior, surface


def fit_body(curve: FramedCurve, vertices: npt.ArrayLike, network: NetworkContext, options: WallFitOptions,
             polar: PolarPoints | None = None) -> RadiusField:
    """The radius field alone, as :func:`fit_wall` fits it, for a quick look at the body before the fit stage.

    The same projection, selection, end margin, end prior, caps and end hold; no hold-out (``auto_spacing``
    keeps the settings' spacing), no metrics, no fold check (the caller judges the body).  ``blend: auto``
    judges its morph on it (:mod:`softdesign.pipeline.blend_body`).  ``polar``: the vertices' projection on
    ``curve`` when the caller has it (:func:`~softdesign.fitting.projection.project_points`).
    """
    if polar is None:
        polar = project_points(curve, vertices, options.mapper)
    selection = select_wall_points(polar, curve.length, network, options.selection)
    kept_index = np.flatnonzero(selection.keep)
    kept = polar.subset(kept_index[np.argsort(polar.l[kept_index], kind="stable")])
    margin = options.end_margin_mm / curve.length
    kept = kept.subset((kept.l >= margin) & (kept.l <= 1.0 - margin))
    reference = None if network.inscribed_l is None or network.inscribed_radius is None else (
        np.asarray(network.inscribed_l, float), np.asarray(network.inscribed_radius, float))
    quick = replace(options, auto_spacing=False)
    settings, _, _, surface = _fit_kept(curve, kept, quick, reference, np.random.default_rng(0))
    hold = negative_end(surface.whole, curve.length, settings.knot_spacing_mm)
    if hold is not None:
        settings, _, _, surface = _fit_kept(curve, kept.subset(hold.keeps(kept.l)), quick, reference,
                                            np.random.default_rng(0))
    return RadiusField.from_links(settings.breaks, surface.links, options.initial_radius_mm)


def fit_wall(
    curve: FramedCurve,
    vertices: npt.ArrayLike,
    network: NetworkContext,
    options: WallFitOptions,
    rng: np.random.Generator,
) -> WallFit:
    """Fit the wall of one path: rho(l, a) per link, its quality, and the radius field rho(q).

    Parameters
    ----------
    curve : the path's smooth framed centerline at q = 1
    vertices : (n, 3) float, mm, the surface's vertices
    network : the path's polyline, the other polylines, inscribed radii
    options : settings of every step
    rng : draws the hold-out folds

    Raises
    ------
    FitError
        The wall does not surround the path, the solve fails, or the tube folds at q = 1.
    """
    tell = options.progress or (lambda name: None)
    polar = project_points(curve, vertices, options.mapper, options.known_projection)
    tell("projection")
    selection = select_wall_points(polar, curve.length, network, options.selection)
    tell("selection")
    # in order along the path: every later evaluation then reads the splines' pieces in turn
    kept_index = np.flatnonzero(selection.keep)
    kept_index = kept_index[np.argsort(polar.l[kept_index], kind="stable")]
    kept = polar.subset(kept_index)
    margin = options.end_margin_mm / curve.length
    inside = (kept.l >= margin) & (kept.l <= 1.0 - margin)
    if not inside.all():
        kept, kept_index = kept.subset(inside), kept_index[inside]
    reference = None if network.inscribed_l is None or network.inscribed_radius is None else (
        np.asarray(network.inscribed_l, float), np.asarray(network.inscribed_radius, float))
    settings, scores, prior, surface = _fit_kept(curve, kept, options, reference, rng)
    hold = negative_end(surface.whole, curve.length, settings.knot_spacing_mm)
    if hold is not None:  # rho <= 0 at an end: held at the inscribed radius there, fitted again
        keep = hold.keeps(kept.l)
        kept, kept_index = kept.subset(keep), kept_index[keep]
        settings, scores, prior, surface = _fit_kept(curve, kept, options, reference, rng)
    tell("spline")
    measured, folds = _distances_and_folds(curve, surface.whole, kept, settings, options, rng)
    tell("distances")
    radius = RadiusField.from_links(settings.breaks, surface.links, options.initial_radius_mm)
    extra = None if options.with_field is None else options.with_field(radius)
    holdout, residual, field_results = _holdout_and_residual(folds, polar, radius, options.mapper, extra)
    tell("hold-out")
    metrics = measured.metrics
    try:
        folding = check_self_folding(curve, radius, q=1.0, limit=options.fold_limit)
    except FoldError as err:  # the stretches that fold, each with a cap of its own, before the whole path's
        stretches = fold_stretches(curve, radius, 1.0)
        refusal = FoldError(fold_advice(str(err), stretches))
        refusal.stretches = stretches
        raise refusal from err
    except FitError as err:
        report = fold_margin(curve, radius, 1.0)
        if report.min_rho_mm > 0.0:
            raise
        l = np.linspace(0.0, 1.0, max(int(np.ceil(curve.length / FOLD_SPACING_MM)), 16) + 1)
        rho = radius.evaluate_grid(1.0, l, np.linspace(0.0, 2.0 * np.pi, 96, endpoint=False)).min(axis=1)
        raise FitError(f"{str(err).split('; ')[0]}; {negative_radius_cause(prior, curve.length, l[np.argmin(rho)])}"
                       ) from err
    tell("fold check")
    ends = end_radii(radius, reference) | {"margin": {"mm": options.end_margin_mm, "points": float((~inside).sum())}}
    if hold is not None:
        ends[f"{hold.end}_held"] = hold.as_dict(curve.length)
    distance = np.full(len(polar), np.nan)
    distance[kept_index[measured.sample]] = measured.distance
    coverage = measure_coverage(curve, surface.whole, polar, selection, kept_index, settings.knot_spacing_mm,
                                reference, {} if prior is None else prior.ends, options.mapper,
                                tuple(c.span_mm for c in options.local_caps),
                                known=(kept_index[measured.sample], measured.distance),
                                known_max=metrics.max_mm)
    tell("coverage")
    return WallFit(polar, selection, settings, scores, surface, metrics, holdout, folding, radius, ends, distance,
                   coverage, residual, tuple(field_results))


def _distances_and_folds(
    curve: FramedCurve, spline: RadiusSpline, kept: PolarPoints, settings: FitSettings, options: WallFitOptions,
    rng: np.random.Generator,
) -> tuple[MeasuredDistances, HoldoutJob]:
    """The kept points' true distances (:func:`~softdesign.fitting.metrics.measure_distances`), and the hold-out's
    folds, dealt from the measured points, each to start from its closest point.

    The search's blocks of points, the exact max's residuals of the points outside its sample and the folds'
    assemblies run in one call of the mapper (each item its own; the draws in the order of ``measure_distances``
    then ``holdout_rms``): the shorter items fill a worker the search's last blocks leave idle, where each was a
    pool of its own.
    """
    measuring = distances_job(curve, spline, kept, rng)
    plan = holdout_plan(curve, kept.subset(measuring.sample), settings, rng, options.holdout)
    pieces, fitted, parts = map_together(options.mapper, (measuring.closest.task, measuring.closest.items),
                                         (measuring.bounds.task, measuring.bounds.items), (plan.assemble, plan.rows))
    measured = measuring.finish(pieces, fitted)
    return measured, plan.job(parts, measured.start)


def _holdout_and_residual(job: HoldoutJob, polar: PolarPoints, radius: RadiusField, mapper: Mapper,
                          extra: Job | None = None) -> tuple[HoldoutReport, FloatArray, list[Any]]:
    """The hold-out's report, every point's radial residual against ``radius`` at q = 1 (n,) mm, and the results of
    ``extra`` (:attr:`WallFitOptions.with_field`'s work; empty without it), in one call of the mapper.

    The residual's blocks of ``PROJECT_BLOCK`` points keep a worker busy while the folds' last fits run (five
    folds on two workers leave one idle for a fold's time); each block's values are its points' own, so the
    residual is that of one ``evaluate_pairs`` over every point, the hold-out that of ``holdout_rms``.
    """
    def fitted(rows: slice) -> FloatArray:
        return radius.evaluate_pairs(1.0, polar.l[rows], polar.angle[rows])

    jobs: list[Job] = [(job.task, job.folds), (fitted, bb.chunks(len(polar), PROJECT_BLOCK))]
    distances, rho, *more = map_together(mapper, *jobs, *([] if extra is None else [extra]))
    return job.report(distances), polar.rho - np.concatenate(rho), more[0] if more else []
