"""How well a fitted tube matches the wall points, measured as true distances.

The fitted surface at q = 1 is ``S(l, a) = c(l) + rho(l, a) (cos a N(l) + sin a B(l))``.
The distance of a point p to it is ``min |p - S(l, a)|`` (:mod:`softdesign.fitting.closest`): the radial
residual ``rho_p - rho(l_p, a_p)`` over-states the distance wherever the wall
is inclined to the radial direction, so it is never reported as the error.

Large inputs: above ``DISTANCE_SAMPLE_MAX`` kept points, RMS, p95 and p99 are
measured on a seeded uniform sample of that many points, and the maximum is
still exact over every point: the radial residual ``|rho_p - rho(l_p, a_p)|``
is the distance from p to the surface point S(l_p, a_p), so it bounds p's true
distance from above, and only points whose bound exceeds the sample's largest
distance are measured as well.

Hold-out: the kept points are dealt into k folds by a seeded permutation; each
fold is measured against the fit on the other k - 1 folds.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from softdesign.errors import ConfigError
from softdesign.fitting import bspline_basis as bb
from softdesign.fitting.bspline_surface import FitSettings, RadiusSpline, fold_assembly, fold_solver_from
from softdesign.fitting.closest import (
    ClosestJob,
    CurvePart,
    Found,
    SearchStart,
    closest_job,
    closest_surface_points,
    search_start,
)
from softdesign.fitting.mapping import Mapper, mapped, serial_map
from softdesign.fitting.projection import PROJECT_BLOCK, PolarPoints
from softdesign.types import FloatArray, FramedCurve

#: Knot spacings (mm) tried by ``knot_spacing_mm: auto``.
AUTO_SPACINGS_MM = (1.0, 1.5, 2.0, 3.0, 4.0)
#: RMS, p95 and p99 use at most this many points, drawn by the seeded rng from larger inputs: the
#: RMS of a uniform sample of n is then within ~1/sqrt(2n) = 0.22 % (one standard deviation, for
#: near-normal residuals) of that of every point, and the percentiles within a few 1e-3 of their
#: rank; the maximum is exact over every point (see the module docstring).  Enough because the
#: figures judge a fit, not its last digit: on the heavy-tailed residuals of the 1M-triangle
#: benchmark (max 44 x RMS) the standard deviations over 300 draws of 100,000 of its 499,649 points
#: are 2.9 % (RMS), 0.4 % (p95) and 2.0 % (p99), and its seeded sample lands 1.3 %, 0.05 % and
#: -1.3 % off the figures of every point; 200,000 took 0.6 s more CPU there (each sampled point is
#: a closest-point search, and the build's hold-out folds are dealt from them) for 1.7 %, 0.2 % and
#: 1.1 %; its hold-out RMS reads 5 % higher with 100,000 (folds fitted to 80,000 points, not 160,000;
#: fold-to-fold spread 2.5-4 %).  Smaller inputs (the VMTK aorta keeps ~4,000 points) are measured whole.
DISTANCE_SAMPLE_MAX = 100_000
#: A point's radial residual bounds its true distance up to the projection's own error (its foot
#: is found to 1e-10 mm along the tangent); bounds this close below the sample's largest distance
#: are measured too.
BOUND_SLACK_MM = 1e-6
#: The hold-out uses at most this many points, drawn by the seeded rng from larger inputs (the
#: VMTK aorta keeps ~4,000; 200,000 are still ~50 per coefficient on a 240 mm path at 1.5 mm x 24).
#: The fit's own hold-out (:func:`~softdesign.fitting.wall_fit.fit_wall`) is dealt from the points
#: measured for RMS, at most ``DISTANCE_SAMPLE_MAX``, so there each fold fits 4/5 of at most 100,000.
HOLDOUT_MAX_POINTS = 200_000


@dataclass(frozen=True)
class FitMetrics:
    """True point-to-surface distances, mm."""

    rms_mm: float
    p95_mm: float
    p99_mm: float
    max_mm: float
    count: int
    total: int | None = None

    def as_dict(self) -> dict[str, float | int]:
        """JSON-ready dict with snake_case keys; ``total`` is every point, ``count`` those in RMS/p95/p99."""
        return {"rms_mm": self.rms_mm, "p95_mm": self.p95_mm, "p99_mm": self.p99_mm,
                "max_mm": self.max_mm, "count": self.count,
                "total": self.count if self.total is None else self.total}


@dataclass(frozen=True)
class MeasuredDistances:
    """True distances of the measured points (all, or a seeded sample of a large input).

    Attributes
    ----------
    metrics : RMS, p95, p99 of the measured points; max over every point
    sample : (m,) sorted indices of the measured points among the kept ones
    distance, l, angle : (m,) their distances (mm) and closest surface points (l, rad)
    curve_part : the centerline's share of the surface there, for a search that starts from these points
    """

    metrics: FitMetrics
    sample: np.ndarray
    distance: FloatArray
    l: FloatArray
    angle: FloatArray
    curve_part: CurvePart | None = None

    @property
    def start(self) -> SearchStart:
        """The closest points as the start of another search (a nearby surface's, e.g. the hold-out's folds)."""
        return SearchStart(self.l, self.angle, self.curve_part)


@dataclass(frozen=True)
class HoldoutSettings:
    """k-fold hold-out: the number of folds, the knot spacings ``auto`` tries (mm), the most points used."""

    folds: int = 5
    candidates_mm: tuple[float, ...] = AUTO_SPACINGS_MM
    max_points: int = HOLDOUT_MAX_POINTS

    def __post_init__(self) -> None:
        if int(self.folds) != self.folds or self.folds < 2:
            raise ConfigError(f"fit.holdout_folds must be an integer >= 2, got {self.folds}")
        if not self.candidates_mm or min(self.candidates_mm) <= 0:
            raise ConfigError(f"knot spacing candidates must be > 0 mm, got {self.candidates_mm}")
        if int(self.max_points) != self.max_points or self.max_points < 2 * self.folds:
            raise ConfigError(
                f"hold-out max_points must be an integer >= 2 x folds ({2 * self.folds}), got {self.max_points}"
            )


@dataclass(frozen=True)
class HoldoutReport:
    """Hold-out distances: pooled RMS and RMS per fold (mm), and how many points took part."""

    rms_mm: float
    fold_rms_mm: FloatArray
    points: int


def summarize_distances(distance: FloatArray) -> FitMetrics:
    """RMS, 95th and 99th percentile and maximum of distances (mm)."""
    d = np.abs(np.asarray(distance, float))
    return FitMetrics(
        float(np.sqrt(np.mean(d**2))), float(np.percentile(d, 95)), float(np.percentile(d, 99)),
        float(d.max()), int(d.size),
    )


def measure_fit(curve: FramedCurve, spline: RadiusSpline, polar: PolarPoints) -> FitMetrics:
    """True-distance metrics of every kept point against the fitted surface at q = 1."""
    return summarize_distances(closest_surface_points(curve, spline, polar)[0])


def measure_distances(
    curve: FramedCurve,
    spline: RadiusSpline,
    polar: PolarPoints,
    rng: np.random.Generator,
    max_points: int = DISTANCE_SAMPLE_MAX,
    mapper: Mapper = serial_map,
) -> MeasuredDistances:
    """True distances of every kept point, or of a seeded sample above ``max_points``, and the exact max.

    Parameters
    ----------
    curve : the centerline at q = 1
    spline : the fitted rho(l, a)
    polar : the kept wall points with their projection
    rng : draws the sample (large inputs only)
    max_points : the most points measured for RMS, p95 and p99
    mapper : runs the blocks of measured points (each point's search is its own); the same figures for any

    Returns
    -------
    MeasuredDistances; ``metrics.max_mm`` is the largest distance of any kept point.
    """
    return distances_job(curve, spline, polar, rng, max_points).run(mapper)


@dataclass(frozen=True)
class DistancesJob:
    """:func:`measure_distances` with its sample drawn: the search's blocks of points (``closest``), and the
    fitted rho at the points outside the sample in blocks (``bounds``, for the exact max), each block its own,
    then what follows them; for a caller that runs the blocks beside other work in one call of its mapper."""

    curve: FramedCurve
    spline: RadiusSpline
    polar: PolarPoints
    sample: np.ndarray
    closest: ClosestJob
    bounds: ExactMaxBounds

    def finish(self, pieces: Sequence[Found], fitted: Sequence[FloatArray]) -> MeasuredDistances:
        """The distances from the search's results and the bounds' (each in its blocks' order)."""
        distance, l, angle, part = self.closest.join(pieces)
        metrics = self.bounds.exact_max(self.curve, self.spline, self.polar, fitted, summarize_distances(distance))
        return MeasuredDistances(metrics, self.sample, distance, l, angle, part)

    def run(self, mapper: Mapper = serial_map) -> MeasuredDistances:
        """:func:`measure_distances`' result (a single block here, more on ``mapper``)."""
        return self.finish(mapped(mapper, self.closest.task, self.closest.items),
                           mapped(mapper, self.bounds.task, self.bounds.items))


def distances_job(curve: FramedCurve, spline: RadiusSpline, polar: PolarPoints, rng: np.random.Generator,
                  max_points: int = DISTANCE_SAMPLE_MAX) -> DistancesJob:
    """:func:`measure_distances` up to its search: the sample drawn (``rng``), the search's blocks prepared."""
    sample = holdout_sample(len(polar), max_points, rng)
    measured = polar.subset(sample)
    return DistancesJob(curve, spline, polar, sample,
                        closest_job(curve, spline, measured.points, SearchStart(measured.l, measured.angle)),
                        exact_max_bounds(spline, polar, sample))


def with_exact_max(
    curve: FramedCurve, spline: RadiusSpline, polar: PolarPoints, sample: np.ndarray, metrics: FitMetrics,
    mapper: Mapper = serial_map,
) -> FitMetrics:
    """``metrics`` of the points ``sample`` (sorted indices into ``polar``) with the max over every point of ``polar``.

    Only the points whose radial residual (an upper bound of the true distance, see the module notes) reaches
    the sample's largest distance, or whose foot is clamped at an end, are measured; ``total`` counts them all.
    ``mapper`` runs the residuals in blocks of ``PROJECT_BLOCK`` points (each point's own: the same numbers).
    """
    bounds = exact_max_bounds(spline, polar, sample)
    return bounds.exact_max(curve, spline, polar, mapped(mapper, bounds.task, bounds.items), metrics)


@dataclass(frozen=True)
class ExactMaxBounds:
    """:func:`with_exact_max`'s residuals as a task over blocks of the points outside the sample (``rest``, none
    when the sample holds every point), and the exact max from them."""

    rest: np.ndarray
    task: Callable[[slice], FloatArray]
    items: list[slice]

    def exact_max(self, curve: FramedCurve, spline: RadiusSpline, polar: PolarPoints, fitted: Sequence[FloatArray],
                  metrics: FitMetrics) -> FitMetrics:
        """``metrics`` with the max over every point of ``polar``, from the fitted rho of the blocks (in order)."""
        if not self.items:
            return metrics
        rest = self.rest
        bound = np.abs(polar.rho[rest] - np.concatenate(fitted))
        # a foot clamped at an end is not in p's normal plane: the radial residual bounds nothing there
        doubtful = rest[(bound >= metrics.max_mm - BOUND_SLACK_MM) | (polar.end_side[rest] != 0)]
        largest = metrics.max_mm
        if doubtful.size:
            largest = max(largest, float(closest_surface_points(curve, spline, polar.subset(doubtful))[0].max()))
        return replace(metrics, max_mm=largest, total=len(polar))


def exact_max_bounds(spline: RadiusSpline, polar: PolarPoints, sample: np.ndarray) -> ExactMaxBounds:
    """The residuals :func:`with_exact_max` bounds the points outside ``sample`` by, as a task over blocks of
    ``PROJECT_BLOCK`` points (none when the sample holds every point)."""
    if len(sample) == len(polar):
        return ExactMaxBounds(np.zeros(0, np.int64), lambda rows: np.zeros(0), [])
    outside = np.ones(len(polar), bool)
    outside[sample] = False
    rest = np.flatnonzero(outside)  # np.setdiff1d(arange, sample)'s indices, increasing, without its sort
    l, angle = polar.l[rest], polar.angle[rest]
    return ExactMaxBounds(rest, lambda rows: spline.evaluate(l[rows], angle[rows]),
                          bb.chunks(len(rest), PROJECT_BLOCK))


def fold_labels(count: int, folds: int, rng: np.random.Generator) -> np.ndarray:
    """(count,) int fold of each point: a seeded permutation dealt round-robin into ``folds``."""
    labels = np.empty(count, np.int64)
    labels[rng.permutation(count)] = np.arange(count) % folds
    return labels


def holdout_sample(count: int, max_points: int, rng: np.random.Generator) -> np.ndarray:
    """Sorted indices of the points a hold-out uses: all of them (no draw) up to ``max_points``, else a seeded draw."""
    if count <= max_points:
        return np.arange(count)
    return np.sort(rng.choice(count, size=max_points, replace=False))


def holdout_rms(
    curve: FramedCurve,
    polar: PolarPoints,
    settings: FitSettings,
    rng: np.random.Generator,
    holdout: HoldoutSettings = HoldoutSettings(),
    start: tuple[FloatArray, FloatArray] | SearchStart | None = None,
    mapper: Mapper = serial_map,
) -> HoldoutReport:
    """k-fold hold-out: fit on k - 1 folds, true distances of the held-out fold, pooled RMS (mm).

    Above ``holdout.max_points`` points, the folds are dealt from that many drawn by ``rng``.

    Parameters
    ----------
    curve : the centerline at q = 1
    polar : the kept wall points
    settings : the spline space and penalty of every fold's fit
    rng : draws the sample (large inputs only) and the folds
    holdout : folds and the most points used
    start : (l (n,), angle (n,)) of each point's closest point on the fit to all points, where its
        Gauss-Newton starts (fewer steps than from the projection); default the projection.  A
        :class:`SearchStart` (:attr:`MeasuredDistances.start`) also carries the centerline's part there
    mapper : runs the held-out folds' distances (independent of each other); the same figures for any
    """
    return holdout_plan(curve, polar, settings, rng, holdout).run(mapper, start)


@dataclass(frozen=True)
class HoldoutPlan:
    """The hold-out with its sample and folds drawn: each fold's system to assemble (``assemble`` over ``rows``,
    each fold's own), then :meth:`job`, its fits and distances; :meth:`run` runs both on one mapper, a caller
    with other independent work may run each step beside it (:func:`~softdesign.fitting.mapping.map_together`)."""

    curve: FramedCurve
    polar: PolarPoints  # the points the folds are dealt from (the drawn ones)
    settings: FitSettings
    labels: np.ndarray
    sample: np.ndarray  # their indices among the points the plan was drawn from
    assemble: Callable[[np.ndarray], Any]
    rows: list[np.ndarray]

    def job(self, parts: list[Any], start: tuple[FloatArray, FloatArray] | SearchStart | None = None) -> HoldoutJob:
        """The folds' fits and distances, from the assembly's results ``parts`` (in fold order); ``start`` as
        :func:`holdout_rms`'s, for the points the plan was drawn from."""
        solve = fold_solver_from(self.polar, self.curve.length, self.settings, self.rows, parts)
        begin = None if start is None else search_start(self.polar, start).subset(self.sample)
        curve, polar, labels = self.curve, self.polar, self.labels

        def held_out(k: int) -> FloatArray:  # fold k's fit and its distances: on one process, after the assembly
            test = labels == k
            return closest_surface_points(curve, solve(k), polar.subset(test),
                                          None if begin is None else begin.subset(test))[0]

        return HoldoutJob(held_out, list(range(len(self.rows))), len(polar))

    def run(self, mapper: Mapper = serial_map,
            start: tuple[FloatArray, FloatArray] | SearchStart | None = None) -> HoldoutReport:
        """The hold-out's report, every step on ``mapper``."""
        return self.job(mapper(self.assemble, self.rows), start).run(mapper)


@dataclass(frozen=True)
class HoldoutJob:
    """The hold-out's last step: each fold's fit and distances (``task(k)`` for k in ``folds``, each its own), and
    the report from them."""

    task: Callable[[int], FloatArray]
    folds: list[int]
    points: int

    def report(self, distances: Sequence[FloatArray]) -> HoldoutReport:
        """The pooled RMS and each fold's from the held-out distances of every fold (in ``folds``' order), mm."""
        squares = [d**2 for d in distances]
        fold_rms = [np.sqrt(np.mean(square)) for square in squares]
        return HoldoutReport(float(np.sqrt(np.mean(np.concatenate(squares)))), np.array(fold_rms), self.points)

    def run(self, mapper: Mapper = serial_map) -> HoldoutReport:
        """The report, the folds run by ``mapper``."""
        return self.report(mapper(self.task, self.folds))


def holdout_plan(curve: FramedCurve, polar: PolarPoints, settings: FitSettings, rng: np.random.Generator,
                 holdout: HoldoutSettings = HoldoutSettings()) -> HoldoutPlan:
    """:func:`holdout_rms` up to its assembly: the sample and the folds drawn (``rng``, as there)."""
    sample = holdout_sample(len(polar), holdout.max_points, rng)
    return _fold_plan(curve, polar.subset(sample), settings, fold_labels(len(sample), holdout.folds, rng), sample)


def _fold_plan(curve: FramedCurve, polar: PolarPoints, settings: FitSettings, labels: np.ndarray,
               sample: np.ndarray) -> HoldoutPlan:
    assemble, rows = fold_assembly(polar, curve.length, settings, labels)
    return HoldoutPlan(curve, polar, settings, labels, sample, assemble, rows)


def choose_knot_spacing(
    curve: FramedCurve,
    polar: PolarPoints,
    settings: FitSettings,
    rng: np.random.Generator,
    holdout: HoldoutSettings = HoldoutSettings(),
) -> tuple[float, dict[float, float]]:
    """The candidate knot spacing with the lowest hold-out RMS (``knot_spacing_mm: auto``).

    Every candidate is scored on the same folds (of the same sample, above ``holdout.max_points``).

    Returns
    -------
    the chosen spacing (mm), and the hold-out RMS (mm) of every candidate
    """
    drawn = holdout_sample(len(polar), holdout.max_points, rng)
    sample = polar.subset(drawn)
    labels = fold_labels(len(sample), holdout.folds, rng)
    scores = {}
    for spacing in holdout.candidates_mm:
        trial = FitSettings(spacing, settings.angular_intervals, settings.smoothing, settings.breaks)
        scores[float(spacing)] = _fold_plan(curve, sample, trial, labels, drawn).run().rms_mm
    best = min(scores, key=lambda s: (scores[s], -s))
    return best, scores
