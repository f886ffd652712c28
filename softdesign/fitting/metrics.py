"""How well a fitted tube matches the wall points, measured as true distances.

The fitted surface at q = 1 is ``S(l, a) = c(l) + rho(l, a) (cos a N(l) + sin a B(l))``.
The distance of a point p to it is ``min |p - S(l, a)|``, found by damped
Gauss-Newton on (l, a) from the point's own projection (l, a), with the
surface's tangents exact (the frames' l derivative from c', c'' and their
measured twist, see :func:`frame_twist_table`): the radial
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

from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np
import numpy.typing as npt

from softdesign.errors import ConfigError
from softdesign.fitting import bspline_basis as bb
from softdesign.fitting.bspline_surface import FitSettings, RadiusSpline, fold_solver
from softdesign.fitting.mapping import Mapper, serial_map
from softdesign.fitting.projection import PolarPoints
from softdesign.types import FloatArray, FramedCurve, Points

#: Gauss-Newton stops when a point's (l, a) step moves its surface point less than this, mm.  The
#: distance is stationary at the closest point and what is left after such a step is a small fraction
#: of it, so the distances are far closer than this: within 2e-12 mm of those at a 1e-10 mm stop on the
#: VMTK aorta and the benchmark tube (1e-13 mm of the closed forms in tests/fitting/test_fit_metrics.py).
CLOSEST_TOL_MM = 1e-5
#: Hard stop on Gauss-Newton steps (from the projection, 2-3 for most points, ~10 for the slowest).
CLOSEST_MAX_STEPS = 30
#: Points searched together (their arrays, a few MB, stay in cache): 200k points in one go took ~20 % longer.
CLOSEST_CHUNK = 1 << 15
#: Step in normalized l of the central differences that measure the frames' twist (not in the protocol).
FRAME_DIFF_STEP = 1e-6
#: Spacing of the samples of the frames' twist, interpolated linearly in between, mm.
TWIST_SPACING_MM = 0.1
#: Knot spacings (mm) tried by ``knot_spacing_mm: auto``.
AUTO_SPACINGS_MM = (1.0, 1.5, 2.0, 3.0, 4.0)
#: RMS, p95 and p99 use at most this many points, drawn by the seeded rng from larger inputs: the
#: RMS of a uniform sample of n is then within ~1/sqrt(2n) = 0.16 % (one standard deviation, for
#: near-normal residuals) of that of every point, and the percentiles within a few 1e-3 of their
#: rank; the maximum is exact over every point (see the module docstring).
DISTANCE_SAMPLE_MAX = 200_000
#: A point's radial residual bounds its true distance up to the projection's own error (its foot
#: is found to 1e-10 mm along the tangent); bounds this close below the sample's largest distance
#: are measured too.
BOUND_SLACK_MM = 1e-6
#: The hold-out uses at most this many points, drawn by the seeded rng from larger inputs (the
#: VMTK aorta keeps ~4,000; 200,000 are still ~50 per coefficient on a 240 mm path at 1.5 mm x 24).
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


@dataclass(frozen=True)
class CurvePart:
    """The centerline's share of ``S(l, a)`` and of ``dS/dl`` at n values of l: all that rho and a leave alone.

    Attributes
    ----------
    points, d1 : (n, 3) c(l) and c'(l), mm
    normal, binormal : (n, 3) N(l), B(l)
    normal_change, binormal_change : (n, 3) dN/dl, dB/dl
    """

    points: Points
    d1: Points
    normal: Points
    binormal: Points
    normal_change: Points
    binormal_change: Points

    def arrays(self) -> tuple[Points, ...]:
        """The fields in order (the arrays themselves, not copies)."""
        return (self.points, self.d1, self.normal, self.binormal, self.normal_change, self.binormal_change)

    def subset(self, index: np.ndarray | slice) -> CurvePart:
        """The rows ``index`` (a boolean mask, indices, or a slice: then views)."""
        return CurvePart(*(v[index] for v in self.arrays()))


@dataclass(frozen=True)
class SearchStart:
    """Where a closest-point search starts: (l (n,), angle (n,)) per point, and the curve's part there if known.

    The hold-out's folds start from the closest points on the fit to every point:
    the centerline there is the same, so its part is carried over, not found again.
    """

    l: FloatArray
    angle: FloatArray
    curve_part: CurvePart | None = None

    def subset(self, index: np.ndarray | slice) -> SearchStart:
        """The points ``index`` (a boolean mask, indices, or a slice: then views)."""
        part = None if self.curve_part is None else self.curve_part.subset(index)
        return SearchStart(np.asarray(self.l)[index], np.asarray(self.angle)[index], part)


def surface_points(curve: FramedCurve, spline: RadiusSpline, l: FloatArray, angle: FloatArray) -> Points:
    """``S(l, a)`` at paired parameters, (n, 3) mm."""
    frames = curve.frames(l)
    rho = spline.evaluate(l, angle)
    direction = np.cos(angle)[:, None] * frames[:, :, 0] + np.sin(angle)[:, None] * frames[:, :, 1]
    return curve.points(l) + rho[:, None] * direction


class RadiusSurface(Protocol):
    """rho(l, a) of a fitted surface: a :class:`RadiusSpline`, or a radius field at one q (the report's)."""

    def evaluate(self, l: npt.ArrayLike, a: npt.ArrayLike, dl: int = 0, da: int = 0) -> FloatArray:
        """rho (or its derivatives) at the points (l, a), mm."""
        ...


def closest_surface_points(
    curve: FramedCurve, spline: RadiusSurface, polar: PolarPoints,
    start: tuple[FloatArray, FloatArray] | SearchStart | None = None,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Closest point on the fitted surface to each point, from its projection (or from ``start``).

    Parameters
    ----------
    curve : the centerline at q = 1
    spline : rho(l, a), anything with ``evaluate(l, a, dl, da)``
    polar : the points, with their projection (l, angle) on ``curve``
    start : (l (n,), angle (n,)) to start from instead, e.g. the closest points on a nearby surface
        (a :class:`SearchStart`, which may also carry the centerline's part there)

    Returns
    -------
    distance (n,) mm, l (n,) and angle (n,) rad of the closest surface point.
    """
    distance, l, a, _ = _closest(curve, spline, polar.points, _search_start(polar, start))
    return distance, l, a


def _search_start(polar: PolarPoints, start: tuple[FloatArray, FloatArray] | SearchStart | None) -> SearchStart:
    if start is None:
        return SearchStart(polar.l, polar.angle)
    return start if isinstance(start, SearchStart) else SearchStart(*start)


def _closest(
    curve: FramedCurve, spline: RadiusSurface, p: Points, start: SearchStart, mapper: Mapper = serial_map,
) -> tuple[FloatArray, FloatArray, FloatArray, CurvePart]:
    """:func:`closest_surface_points` on the points p (n, 3) mm, also returning the curve's part at the result.

    Every point's search is its own: they run ``CLOSEST_CHUNK`` points at a time, whose arrays stay in
    the processor's caches (the same numbers as all at once, in less time), the blocks by ``mapper``
    (perhaps on other processes: the same numbers; a single block always runs here).
    """
    twist = frame_twist_table(curve)
    rows = bb.chunks(len(p), CLOSEST_CHUNK)

    def piece(r: slice) -> tuple[FloatArray, FloatArray, FloatArray, CurvePart]:
        return _closest_piece(curve, spline, twist, p[r], start.subset(r))

    pieces = mapper(piece, rows) if len(rows) > 1 else [piece(rows[0])]
    if len(pieces) == 1:
        return pieces[0]
    dist, l, a = (np.concatenate([piece[k] for piece in pieces]) for k in range(3))
    part = CurvePart(*(np.concatenate(arrays) for arrays in zip(*(piece[3].arrays() for piece in pieces), strict=True)))
    return dist, l, a, part


def _closest_piece(
    curve: FramedCurve, spline: RadiusSurface, twist, p: Points, start: SearchStart
) -> tuple[FloatArray, FloatArray, FloatArray, CurvePart]:
    """Damped Gauss-Newton from ``start`` to the closest surface point of each point p (n, 3) mm."""
    l, a = np.array(start.l, float), np.array(start.angle, float)
    part = _curve_part(curve, twist, l) if start.curve_part is None else start.curve_part
    part = CurvePart(*(np.array(v, float) for v in part.arrays()))  # updated in place below
    surface, du, dv = _surface_and_tangents(part, spline, l, a)
    dist = np.linalg.norm(p - surface, axis=1)
    active = np.ones(len(l), bool)
    for _ in range(CLOSEST_MAX_STEPS):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        current = (l[idx], a[idx], surface[idx], du[idx], dv[idx], dist[idx], *(v[idx] for v in part.arrays()))
        step = _gauss_newton_step(p[idx] - surface[idx], du[idx], dv[idx])
        update = _damped_update(curve, spline, twist, p[idx], current, step)
        moved = np.linalg.norm(update[2] - surface[idx], axis=1)
        for target, value in zip((l, a, surface, du, dv, dist, *part.arrays()), update, strict=True):
            target[idx] = value
        active[idx[moved <= CLOSEST_TOL_MM]] = False
    return dist, l, a, part


def frame_twist_table(curve: FramedCurve) -> tuple[FloatArray, FloatArray]:
    """Normalized l (k,) and the frames' twist ``w = dN/dl . B`` (k,) rad per unit l, for interpolation.

    A frame field with T = c'/|c'| turns as ``N' = -(N . T') T + w B`` and
    ``B' = -(B . T') T - w N``: the bending part is exact from c' and c'',
    the twist w is the frame mode's (0 for rotation-minimizing frames, the
    torsion times |c'| for Frenet).  It is measured once per curve by central
    differences on a grid ``TWIST_SPACING_MM`` apart, not assumed.
    """
    count = max(int(np.ceil(curve.length / TWIST_SPACING_MM)), 16) + 1
    l = np.linspace(0.0, 1.0, count)
    lo, hi = np.clip(l - FRAME_DIFF_STEP, 0.0, 1.0), np.clip(l + FRAME_DIFF_STEP, 0.0, 1.0)
    normal_change = (curve.frames(hi)[:, :, 0] - curve.frames(lo)[:, :, 0]) / (hi - lo)[:, None]
    return l, np.einsum("ni,ni->n", normal_change, curve.frames(l)[:, :, 1])


def _curve_part(curve: FramedCurve, twist, l: FloatArray) -> CurvePart:
    """c, c', the frames and their l derivative (from c', c'' and the twist table) at l."""
    frames = curve.frames(l)
    normal, binormal, tangent = frames[:, :, 0], frames[:, :, 1], frames[:, :, 2]
    d1, d2 = curve.derivative(l, 1), curve.derivative(l, 2)
    speed = np.linalg.norm(d1, axis=1)
    tangent_change = (d2 - np.einsum("ni,ni->n", d2, tangent)[:, None] * tangent) / speed[:, None]
    w = np.interp(l, *twist)[:, None]
    normal_change = -np.einsum("ni,ni->n", normal, tangent_change)[:, None] * tangent + w * binormal
    binormal_change = -np.einsum("ni,ni->n", binormal, tangent_change)[:, None] * tangent - w * normal
    return CurvePart(curve.points(l), d1, normal, binormal, normal_change, binormal_change)


def _surface_and_tangents(part: CurvePart, spline: RadiusSurface, l: FloatArray, a: FloatArray):
    """S, dS/dl and dS/da at (l, a), the centerline's share of them in ``part``."""
    cos, sin = np.cos(a)[:, None], np.sin(a)[:, None]
    direction = cos * part.normal + sin * part.binormal
    rho, rho_l, rho_a = (v[:, None] for v in _radius_and_slopes(spline, l, a))
    surface = part.points + rho * direction
    d_dir_l = cos * part.normal_change + sin * part.binormal_change
    d_dir_a = -sin * part.normal + cos * part.binormal
    return surface, part.d1 + rho_l * direction + rho * d_dir_l, rho_a * direction + rho * d_dir_a


def _radius_and_slopes(spline, l: FloatArray, a: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """rho, d rho / dl, d rho / da: in one pass for a RadiusSpline, else by ``evaluate`` (e.g. a radius field)."""
    if isinstance(spline, RadiusSpline):
        return spline.evaluate_with_slopes(l, a)
    return spline.evaluate(l, a), spline.evaluate(l, a, dl=1), spline.evaluate(l, a, da=1)


def _gauss_newton_step(residual: Points, du: Points, dv: Points) -> FloatArray:
    """(n, 2) solution of ``J^T J step = J^T r`` with J = [dS/dl, dS/da]."""
    a11 = np.einsum("ni,ni->n", du, du)
    a12 = np.einsum("ni,ni->n", du, dv)
    a22 = np.einsum("ni,ni->n", dv, dv)
    b1 = np.einsum("ni,ni->n", du, residual)
    b2 = np.einsum("ni,ni->n", dv, residual)
    det = a11 * a22 - a12**2
    with np.errstate(divide="ignore", invalid="ignore"):
        step = np.column_stack([(a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det])
    return np.where(np.isfinite(step), step, 0.0)


def _damped_update(curve, spline, twist, p, current, step):
    """Take the Gauss-Newton step, halving it (up to 8 times) for the points where it does not help.

    ``current`` is (l, a, S, dS/dl, dS/da, distance, then the fields of the curve's part);
    returns the same at the new (l, a).
    A point whose step never reduces the distance stays where it was (it has converged).
    """
    l0, a0, dist0 = current[0], current[1], current[5]
    out = tuple(v.copy() for v in current)
    pending = np.arange(len(l0))
    scale = 1.0
    for _ in range(8):
        l = np.clip(l0[pending] + scale * step[pending, 0], 0.0, 1.0)
        a = a0[pending] + scale * step[pending, 1]
        part = _curve_part(curve, twist, l)
        surface, du, dv = _surface_and_tangents(part, spline, l, a)
        d = np.linalg.norm(p[pending] - surface, axis=1)
        better = d <= dist0[pending]
        for target, value in zip(out, (l, a, surface, du, dv, d, *part.arrays()), strict=True):
            target[pending[better]] = value[better]
        pending = pending[~better]
        if pending.size == 0:
            break
        scale *= 0.5
    return out


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
    sample = holdout_sample(len(polar), max_points, rng)
    measured = polar.subset(sample)
    distance, l, angle, part = _closest(curve, spline, measured.points, SearchStart(measured.l, measured.angle),
                                        mapper)
    metrics = summarize_distances(distance)
    if len(sample) < len(polar):
        rest = np.setdiff1d(np.arange(len(polar)), sample, assume_unique=True)
        bound = np.abs(polar.rho[rest] - spline.evaluate(polar.l[rest], polar.angle[rest]))
        # a foot clamped at an end is not in p's normal plane: the radial residual bounds nothing there
        doubtful = rest[(bound >= metrics.max_mm - BOUND_SLACK_MM) | (polar.end_side[rest] != 0)]
        largest = metrics.max_mm
        if doubtful.size:
            largest = max(largest, float(closest_surface_points(curve, spline, polar.subset(doubtful))[0].max()))
        metrics = replace(metrics, max_mm=largest, total=len(polar))
    return MeasuredDistances(metrics, sample, distance, l, angle, part)


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
    sample = holdout_sample(len(polar), holdout.max_points, rng)
    labels = fold_labels(len(sample), holdout.folds, rng)
    begin = None if start is None else _search_start(polar, start).subset(sample)
    return _holdout(curve, polar.subset(sample), settings, labels, begin, mapper)


def _holdout(
    curve: FramedCurve, polar: PolarPoints, settings: FitSettings, labels: np.ndarray,
    start: SearchStart | None = None, mapper: Mapper = serial_map,
) -> HoldoutReport:
    solve = fold_solver(polar, curve.length, settings, labels)

    def held_out(k: int) -> FloatArray:  # fold k's fit and its distances: on one process, after the assembly
        test = labels == k
        begin = None if start is None else start.subset(test)
        return closest_surface_points(curve, solve(k), polar.subset(test), begin)[0]

    squares, fold_rms = [], []
    for d in mapper(held_out, range(int(labels.max()) + 1)):
        squares.append(d**2)
        fold_rms.append(np.sqrt(np.mean(d**2)))
    return HoldoutReport(float(np.sqrt(np.mean(np.concatenate(squares)))), np.array(fold_rms), len(polar))


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
    sample = polar.subset(holdout_sample(len(polar), holdout.max_points, rng))
    labels = fold_labels(len(sample), holdout.folds, rng)
    scores = {}
    for spacing in holdout.candidates_mm:
        trial = FitSettings(spacing, settings.angular_intervals, settings.smoothing, settings.breaks)
        scores[float(spacing)] = _holdout(curve, sample, trial, labels).rms_mm
    best = min(scores, key=lambda s: (scores[s], -s))
    return best, scores
