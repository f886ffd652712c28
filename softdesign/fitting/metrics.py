"""How well a fitted tube matches the wall points, measured as true distances.

The fitted surface at q = 1 is ``S(l, a) = c(l) + rho(l, a) (cos a N(l) + sin a B(l))``.
The distance of a point p to it is ``min |p - S(l, a)|``, found by damped
Gauss-Newton on (l, a) from the point's own projection (l, a): the radial
residual ``rho_p - rho(l_p, a_p)`` over-states the distance wherever the wall
is inclined to the radial direction, so it is never reported as the error.

Hold-out: the kept points are dealt into k folds by a seeded permutation; each
fold is measured against the fit on the other k - 1 folds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdesign.errors import ConfigError
from softdesign.fitting.bspline_surface import FitSettings, RadiusSpline, fit_radius_surface
from softdesign.fitting.projection import PolarPoints
from softdesign.types import FloatArray, FramedCurve, Points

#: Gauss-Newton stops when every (l, a) step moves the surface point less than this, mm.
CLOSEST_TOL_MM = 1e-9
#: Hard stop on Gauss-Newton steps (it converges in 3-5 from the projection).
CLOSEST_MAX_STEPS = 30
#: Step in normalized l for the central difference of the frames (their derivative is not in the protocol).
FRAME_DIFF_STEP = 1e-6
#: Knot spacings (mm) tried by ``knot_spacing_mm: auto``.
AUTO_SPACINGS_MM = (1.0, 1.5, 2.0, 3.0, 4.0)


@dataclass(frozen=True)
class FitMetrics:
    """True point-to-surface distances, mm."""

    rms_mm: float
    p95_mm: float
    p99_mm: float
    max_mm: float
    count: int

    def as_dict(self) -> dict[str, float | int]:
        """JSON-ready dict with snake_case keys."""
        return {"rms_mm": self.rms_mm, "p95_mm": self.p95_mm, "p99_mm": self.p99_mm,
                "max_mm": self.max_mm, "count": self.count}


@dataclass(frozen=True)
class HoldoutSettings:
    """k-fold hold-out: the number of folds and the knot spacings ``auto`` tries (mm)."""

    folds: int = 5
    candidates_mm: tuple[float, ...] = AUTO_SPACINGS_MM

    def __post_init__(self) -> None:
        if int(self.folds) != self.folds or self.folds < 2:
            raise ConfigError(f"fit.holdout_folds must be an integer >= 2, got {self.folds}")
        if not self.candidates_mm or min(self.candidates_mm) <= 0:
            raise ConfigError(f"knot spacing candidates must be > 0 mm, got {self.candidates_mm}")


@dataclass(frozen=True)
class HoldoutReport:
    """Hold-out distances: pooled RMS and RMS per fold, mm."""

    rms_mm: float
    fold_rms_mm: FloatArray


def surface_points(curve: FramedCurve, spline: RadiusSpline, l: FloatArray, angle: FloatArray) -> Points:
    """``S(l, a)`` at paired parameters, (n, 3) mm."""
    frames = curve.frames(l)
    rho = spline.evaluate(l, angle)
    direction = np.cos(angle)[:, None] * frames[:, :, 0] + np.sin(angle)[:, None] * frames[:, :, 1]
    return curve.points(l) + rho[:, None] * direction


def closest_surface_points(
    curve: FramedCurve, spline: RadiusSpline, polar: PolarPoints
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Closest point on the fitted surface to each point, from its projection.

    Returns
    -------
    distance (n,) mm, l (n,) and angle (n,) rad of the closest surface point.
    """
    p, l, a = polar.points, polar.l.copy(), polar.angle.copy()
    surface, du, dv = _surface_and_tangents(curve, spline, l, a)
    dist = np.linalg.norm(p - surface, axis=1)
    active = np.ones(len(l), bool)
    for _ in range(CLOSEST_MAX_STEPS):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        step = _gauss_newton_step(p[idx] - surface[idx], du[idx], dv[idx])
        update = _damped_update(curve, spline, p[idx], (l[idx], a[idx]), step, dist[idx])
        moved = np.linalg.norm(update[2] - surface[idx], axis=1)
        l[idx], a[idx], surface[idx], du[idx], dv[idx], dist[idx] = update
        active[idx[moved <= CLOSEST_TOL_MM]] = False
    return dist, l, a


def _surface_and_tangents(curve: FramedCurve, spline: RadiusSpline, l: FloatArray, a: FloatArray):
    """S, dS/dl and dS/da at (l, a); the frames' l derivative by a central difference."""
    lo = np.clip(l - FRAME_DIFF_STEP, 0.0, 1.0)
    hi = np.clip(l + FRAME_DIFF_STEP, 0.0, 1.0)
    frames = curve.frames(l)
    dframes = (curve.frames(hi) - curve.frames(lo)) / (hi - lo)[:, None, None]
    cos, sin = np.cos(a)[:, None], np.sin(a)[:, None]
    direction = cos * frames[:, :, 0] + sin * frames[:, :, 1]
    rho = spline.evaluate(l, a)[:, None]
    surface = curve.points(l) + rho * direction
    d_dir_l = cos * dframes[:, :, 0] + sin * dframes[:, :, 1]
    d_dir_a = -sin * frames[:, :, 0] + cos * frames[:, :, 1]
    du = curve.derivative(l, 1) + spline.evaluate(l, a, dl=1)[:, None] * direction + rho * d_dir_l
    dv = spline.evaluate(l, a, da=1)[:, None] * direction + rho * d_dir_a
    return surface, du, dv


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


def _damped_update(curve, spline, p, start, step, dist):
    """Take the Gauss-Newton step, halving it (up to 8 times) for the points where it does not help.

    A point whose step never reduces the distance stays where it was (it has converged).
    """
    l0, a0 = start
    l_out, a_out = l0.copy(), a0.copy()
    pending = np.arange(len(l0))
    scale = 1.0
    for _ in range(8):
        l = np.clip(l0[pending] + scale * step[pending, 0], 0.0, 1.0)
        a = a0[pending] + scale * step[pending, 1]
        d = np.linalg.norm(p[pending] - surface_points(curve, spline, l, a), axis=1)
        better = d <= dist[pending]
        l_out[pending[better]], a_out[pending[better]] = l[better], a[better]
        pending = pending[~better]
        if pending.size == 0:
            break
        scale *= 0.5
    surface, du, dv = _surface_and_tangents(curve, spline, l_out, a_out)
    return l_out, a_out, surface, du, dv, np.linalg.norm(p - surface, axis=1)


def summarize_distances(distance: FloatArray) -> FitMetrics:
    """RMS, 95th and 99th percentile and maximum of distances (mm)."""
    d = np.abs(np.asarray(distance, float))
    return FitMetrics(
        float(np.sqrt(np.mean(d**2))), float(np.percentile(d, 95)), float(np.percentile(d, 99)),
        float(d.max()), int(d.size),
    )


def measure_fit(curve: FramedCurve, spline: RadiusSpline, polar: PolarPoints) -> FitMetrics:
    """True-distance metrics of the kept points against the fitted surface at q = 1."""
    return summarize_distances(closest_surface_points(curve, spline, polar)[0])


def fold_labels(count: int, folds: int, rng: np.random.Generator) -> np.ndarray:
    """(count,) int fold of each point: a seeded permutation dealt round-robin into ``folds``."""
    labels = np.empty(count, np.int64)
    labels[rng.permutation(count)] = np.arange(count) % folds
    return labels


def holdout_rms(
    curve: FramedCurve, polar: PolarPoints, settings: FitSettings, rng: np.random.Generator, folds: int = 5
) -> HoldoutReport:
    """k-fold hold-out: fit on k - 1 folds, true distances of the held-out fold, pooled RMS (mm).

    Raises
    ------
    ConfigError
        ``folds`` is not an integer >= 2.
    """
    HoldoutSettings(folds=folds)  # validates folds
    return _holdout(curve, polar, settings, fold_labels(len(polar), folds, rng))


def _holdout(curve: FramedCurve, polar: PolarPoints, settings: FitSettings, labels: np.ndarray) -> HoldoutReport:
    squares, fold_rms = [], []
    for k in range(int(labels.max()) + 1):
        test = labels == k
        fit = fit_radius_surface(polar.subset(~test), curve.length, settings)
        d = closest_surface_points(curve, fit.whole, polar.subset(test))[0]
        squares.append(d**2)
        fold_rms.append(np.sqrt(np.mean(d**2)))
    return HoldoutReport(float(np.sqrt(np.mean(np.concatenate(squares)))), np.array(fold_rms))


def choose_knot_spacing(
    curve: FramedCurve,
    polar: PolarPoints,
    settings: FitSettings,
    rng: np.random.Generator,
    holdout: HoldoutSettings = HoldoutSettings(),
) -> tuple[float, dict[float, float]]:
    """The candidate knot spacing with the lowest hold-out RMS (``knot_spacing_mm: auto``).

    Every candidate is scored on the same folds.

    Returns
    -------
    the chosen spacing (mm), and the hold-out RMS (mm) of every candidate
    """
    labels = fold_labels(len(polar), holdout.folds, rng)
    scores = {}
    for spacing in holdout.candidates_mm:
        trial = FitSettings(spacing, settings.angular_intervals, settings.smoothing, settings.breaks)
        scores[float(spacing)] = _holdout(curve, polar, trial, labels).rms_mm
    best = min(scores, key=lambda s: (scores[s], -s))
    return best, scores
