"""A polyline's parametric spline on its chord length, and the spline's arc length (steps 1 and 2 of
:mod:`softdesign.geometry.curves`).

The arc length is integrated by Gauss-Legendre quadrature between parameters and inverted, s(u) = target, by
Newton's method from a linear interpolation of a table of it.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from scipy.interpolate import BSpline, PPoly, make_interp_spline, splprep

from softdesign.errors import GeometryError
from softdesign.types import POINT_TOL_MM, FloatArray, Points

#: Gauss-Legendre nodes per interval for arc-length integrals.
GAUSS_NODES = 8
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(GAUSS_NODES)
#: Newton iterations allowed to invert s(u) = target; converges in 3-4 on smooth splines.
NEWTON_STEPS = 8
#: Relative tolerance on arc length when inverting s(u), and on l at the domain ends.
ARC_REL_TOL = 1e-13
#: A FITPACK warning is accepted when the residual sum of squares is within this factor of its target s.
SMOOTHING_SLACK = 1.5
#: Fewest distinct input points: a cubic (torsion needs a third derivative) needs 4.
MIN_POLYLINE_POINTS = 4


def distinct_points(points: npt.ArrayLike) -> Points:
    """``points`` (n, 3) mm, checked finite, without repeats (steps within POINT_TOL_MM)."""
    points = np.asarray(points, float)
    if points.ndim != 2 or points.shape[1] != 3 or not np.all(np.isfinite(points)):
        raise GeometryError(f"centerline: expected finite (n, 3) points in mm, got shape {points.shape}")
    step = np.linalg.norm(np.diff(points, axis=0), axis=1)
    kept = points[np.concatenate([[True], step > POINT_TOL_MM])]
    if len(kept) < MIN_POLYLINE_POINTS:
        raise GeometryError(
            f"centerline: expected at least {MIN_POLYLINE_POINTS} distinct points, got {len(kept)}; "
            "the path is too short to carry curvature and torsion - pick another path or re-export it"
        )
    return kept


def chord_spline(points: Points, smoothing_mm: float, degree: int, weights: FloatArray | None = None
                 ) -> tuple[BSpline, FloatArray]:
    """Spline of ``degree`` (3 for fewer points) on the chord-length parameter u (mm), and the parameters of the
    input points.

    ``weights`` (n,) scale the points' residuals in the smoothing's sum of squares (default 1; unused when
    interpolating): a large weight pins the spline to that point.
    """
    u = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    k = degree if len(points) > degree else 3
    if smoothing_mm == 0.0:
        return make_interp_spline(u, points, k=k), u
    s = len(points) * smoothing_mm**2
    # splprep returns [t, c, k] with the k it was given
    ((t, c, _), _), fp, ier, msg = splprep(points.T, w=weights, u=u, k=k, s=s, full_output=True, quiet=True)
    # FITPACK: ier <= 0 success, 1..3 warnings (then check the residual it reached), >= 10 bad input.
    if ier >= 10 or (ier > 0 and fp > SMOOTHING_SLACK * s):
        raise GeometryError(
            f"centerline: the smoothing spline failed (FITPACK ier = {ier}: {msg}); "
            "raise resample.smoothing_mm or check the centerline for loops"
        )
    return BSpline(np.asarray(t), np.asarray(c).T, k), u


def speed_integral(spline: BSpline | PPoly, a: FloatArray, b: FloatArray) -> FloatArray:
    """Integral of |spline'| from a to b (element-wise), Gauss-Legendre."""
    x, w = _GAUSS_X, _GAUSS_W
    half = 0.5 * (np.asarray(b) - np.asarray(a))
    nodes = 0.5 * (np.asarray(a) + np.asarray(b))[..., None] + half[..., None] * x
    speed = np.linalg.norm(spline(nodes.ravel(), nu=1), axis=1).reshape(nodes.shape)
    return half * (speed @ w)


def arc_length_table(spline: BSpline, u: FloatArray) -> FloatArray:
    """Cumulative arc length at the parameters u (m,), mm."""
    return np.concatenate([[0.0], np.cumsum(speed_integral(spline, u[:-1], u[1:]))])


def u_at_arc_length(spline: BSpline, u: FloatArray, table: FloatArray, s: FloatArray) -> FloatArray:
    """Parameters where the arc length equals s (Newton from linear interpolation of the table)."""
    k = np.clip(np.searchsorted(table, s, side="right") - 1, 0, len(u) - 2)
    frac = (s - table[k]) / (table[k + 1] - table[k])
    ut = u[k] + frac * (u[k + 1] - u[k])
    for _ in range(NEWTON_STEPS):
        err = table[k] + speed_integral(spline, u[k], ut) - s
        if np.max(np.abs(err)) <= ARC_REL_TOL * table[-1]:
            break
        ut = np.clip(ut - err / np.linalg.norm(spline(ut, nu=1), axis=1), u[0], u[-1])
    return ut


def points_at_arc_length(
    spline: BSpline, u: FloatArray, table: FloatArray, s: FloatArray, end_mm: float, stop_mm: float | None = None
) -> Points:
    """Points at arc lengths s; within end_mm of the start (stop_mm of the end, default end_mm), a straight
    extension of the tangent there."""
    total = table[-1]
    stop_mm = end_mm if stop_mm is None else stop_mm
    inner = np.clip(s, end_mm, total - stop_mm)
    ut = u_at_arc_length(spline, u, table, inner)
    out = spline(ut)
    if end_mm > 0.0 or stop_mm > 0.0:
        tangent = spline(ut, nu=1)
        tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
        out = out + (s - inner)[:, None] * tangent
    return out
