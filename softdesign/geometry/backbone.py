"""A backbone the wall can follow: the centerline smoothed where it turns tighter than the vessel is wide.

A tube of radius r around a centerline of curvature kappa folds through
itself where ``r * kappa >= 1``.  A VMTK centerline does turn that tightly
at wide bifurcations (a trunk of radius 6 mm whose centerline runs a short
straight stub and then turns 60 degrees within 3 mm), but the actuator's
backbone need not follow it there: the wall, not the centerline, is what the
actuator must match.  :func:`regularize_backbone` finds the stretches where
``r * kappa`` of the smoothed centerline (the same smoothing the build uses)
reaches ``REGULARIZE_REACH``, with r the ``MaximumInscribedSphereRadius``, and
smooths the polyline there only:

* each stretch is smoothed by a Gaussian along arc length whose width is a
  multiple of the stretch's largest inscribed radius (the local radius'
  scale), the multiple growing through ``SIGMA_FACTORS`` until the smoothed
  centerline's reach stays below ``TARGET_REACH`` everywhere;
* the smoothed points are blended in by a weight that is 1 on the stretch and
  falls to 0 over ``RAMP_SIGMAS`` widths on each side along a quintic
  smoothstep (C2), so the backbone is unchanged away from the stretch and its
  tangent stays continuous;
* at a path's end the polyline is continued by its mirror image in the end's
  normal plane (the plane through the end point square to the end segment)
  before smoothing, so the smoothed curve is mirror-symmetric there: the end
  keeps its tangent and stays in that plane (the vessel's cap plane, for a
  centerline that ends at a cap), moving only within it, and a straight end
  stays straight.

The radius in ``r * kappa`` is the fold radius (:func:`wall_fold_radius`):
the inscribed radius, or where the wall's own points lie nearer the centre of
curvature than that (the flatter inner side of a real bend), how far the wall
reaches towards it.  The tube map's Jacobian is ``1 - rho(l, a) kappa_n(l, a)``
with kappa_n the curvature's component towards angle a, so the body folds
only where the wall on the inner side reaches the centre of curvature, and a
bend whose inscribed radius alone says ``r * kappa >= 1`` need not fold.

This is not in the papers: seed 000 takes the centerline as the backbone.
The fit then measures the wall around the regularized backbone, and the build
reports how far the backbone moved and the fit error on the stretch.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt
from scipy.ndimage import maximum_filter1d

from softdesign.geometry.curves import CurveOptions, l_from_points, smooth_curve_from_polyline
from softdesign.types import FloatArray, Points

#: r * kappa at which a stretch is regularized (the morph check's limit, :mod:`softdesign.geometry.morph_fold`).
REGULARIZE_REACH = 0.8
#: r * kappa the regularized backbone stays below (room below the trigger for the wall's rho exceeding r).
TARGET_REACH = 0.7
#: r * kappa at which a stretch is regularized when r is the wall's own reach (:func:`wall_fold_radius`), not
#: a lower bound of it: the body folds at 1, and the fitted spline may reach a little past its wall points.
WALL_REGULARIZE_REACH = 0.9
#: Gaussian widths tried, in units of the stretch's largest inscribed radius, smallest first.
SIGMA_FACTORS = (0.25, 0.375, 0.5, 0.75, 1.0, 1.5, 2.0)
#: Length of the blend-in ramp on each side of a stretch, in Gaussian widths.
RAMP_SIGMAS = 3.0
#: A regularized stretch is reported from the first to the last point moved by more than this fraction of its radius.
MOVED_FRACTION = 0.01
#: The Gaussian is cut at this many widths.
KERNEL_SIGMAS = 4.0
#: Wall points within this arc length of a centerline point give its fold radius, mm on each side (about
#: half the fit's default knot interval: the fitted rho follows the wall over a knot interval).
WALL_WINDOW_MM = 1.0
#: Bins along the arc in which the wall's reach is gathered before the window's maximum, mm.
WALL_BIN_MM = 0.1
#: Wall points within this angle of the curvature's direction are its inner side (their rho * cos lies within
#: cos 45 deg of rho): the side where the tube folds first.
INNER_CONE_RAD = 0.25 * np.pi
#: A wall point farther from the centerline than this many inscribed radii is not the path's wall (the fit's
#: default outlier factor).
WALL_OUTLIER_FACTOR = 2.0


@dataclass(frozen=True)
class Stretch:
    """One regularized stretch along the input polyline (arc mm from its first point).

    ``from_mm``, ``to_mm`` bound the points moved by more than ``MOVED_FRACTION`` of ``radius_mm`` (the
    stretch's largest inscribed radius); ``sigma_mm`` is the Gaussian's width.
    """

    from_mm: float
    to_mm: float
    radius_mm: float
    sigma_mm: float
    max_moved_mm: float
    max_moved_at_mm: float


@dataclass(frozen=True)
class BackboneRegularization:
    """The backbone (the input polyline where nothing was regularized) and what was done.

    Attributes
    ----------
    points : (n, 3) mm, the backbone polyline, same point count as the input
    moved_mm : (n,) how far each point moved, mm
    reach_before, reach_after : the largest r * kappa of the smoothed centerline before and after
    stretches : the regularized stretches (empty when nothing was)
    """

    points: Points
    moved_mm: FloatArray
    reach_before: float
    reach_after: float
    stretches: tuple[Stretch, ...] = field(default=())

    @property
    def regularized(self) -> bool:
        """True when some stretch was smoothed."""
        return bool(self.stretches)

    def summary(self) -> dict[str, Any]:
        """JSON-ready figures (mm, dimensionless)."""
        return {
            "regularized": self.regularized,
            "trigger_reach": REGULARIZE_REACH,
            "target_reach": TARGET_REACH,
            "reach_before": self.reach_before,
            "reach_after": self.reach_after,
            "max_moved_mm": float(self.moved_mm.max(initial=0.0)),
            "stretches": [vars(s) for s in self.stretches],
        }


class BackboneError(ValueError):
    """No width in ``SIGMA_FACTORS`` brings the reach below ``TARGET_REACH``.

    ``reach``, ``arc_mm`` and ``radius_mm`` are the input's largest reach, where it is and r there;
    ``smoothed`` the largest reach left by the widest smoothing tried.
    """

    def __init__(self, reach: float, arc_mm: float, radius_mm: float, smoothed: float = float("nan")) -> None:
        super().__init__(f"r * kappa {reach:.3f} at {arc_mm:.1f} mm")
        self.reach, self.arc_mm, self.radius_mm, self.smoothed = reach, arc_mm, radius_mm, smoothed


def wall_fold_radius(points: npt.ArrayLike, radius: npt.ArrayLike, wall: npt.ArrayLike,
                     options: CurveOptions) -> FloatArray:
    """The fold radius at each centerline point: how far the wall reaches towards the centre of curvature.

    At a point of the smoothed centerline with curvature vector kappa u, a wall point p with foot c gives
    ``(p - c) . u`` (its rho * kappa_n / kappa) when it lies within ``INNER_CONE_RAD`` of u; the fold radius
    is the largest of these within ``WALL_WINDOW_MM`` of arc, and never more than the inscribed radius
    (where no wall point lies on the inner side, as at a branch's mouth, it is the inscribed radius).

    Parameters
    ----------
    points : (n, 3) mm, the centerline polyline, inlet first
    radius : (n,) mm, the inscribed radius at the points
    wall : (m, 3) mm, the path's own wall (other branches' walls left out)
    options : the build's resampling and smoothing

    Returns
    -------
    (n,) mm, at most ``radius``
    """
    points, radius, wall = np.asarray(points, float), np.asarray(radius, float), np.asarray(wall, float)
    if len(wall) == 0:
        return radius.copy()
    curve = smooth_curve_from_polyline(points, options)
    at, foot = l_from_points(curve, points), l_from_points(curve, wall)
    order = np.argsort(at, kind="stable")
    offset = wall - curve.points(foot)
    kvec = curve.curvature_vectors(foot)
    kappa = np.linalg.norm(kvec, axis=1)
    toward = np.einsum("ij,ij->i", offset, kvec) / np.where(kappa > 0.0, kappa, 1.0)
    rho = np.linalg.norm(offset, axis=1)
    near = np.interp(foot, at[order], radius[order])
    inner = ((foot > 0.0) & (foot < 1.0) & (kappa > 0.0) & (toward >= np.cos(INNER_CONE_RAD) * rho)
             & (rho <= WALL_OUTLIER_FACTOR * near))
    bins = int(np.ceil(curve.length / WALL_BIN_MM)) + 1
    per_bin = np.full(bins, -np.inf)
    np.maximum.at(per_bin, np.rint(foot[inner] * curve.length / WALL_BIN_MM).astype(np.intp), toward[inner])
    width = 2 * int(round(WALL_WINDOW_MM / WALL_BIN_MM)) + 1
    window = maximum_filter1d(per_bin, width, mode="constant", cval=-np.inf)
    reach = window[np.rint(at * curve.length / WALL_BIN_MM).astype(np.intp)]
    reach[~np.isfinite(reach)] = np.inf  # no inner wall point near: the inscribed radius
    return np.minimum(radius, reach)


def reach_along(points: npt.ArrayLike, radius: npt.ArrayLike, options: CurveOptions) -> tuple[FloatArray, FloatArray]:
    """r * kappa of the smoothed centerline on its dense grid, and the grid's arc length along the polyline, mm.

    Parameters
    ----------
    points : (n, 3) mm, the centerline polyline, inlet first
    radius : (n,) mm, the inscribed radius at the points
    options : the build's resampling and smoothing
    """
    points = np.asarray(points, float)
    curve = smooth_curve_from_polyline(points, options)
    l = curve.dense_l()
    at = l_from_points(curve, points)
    order = np.argsort(at, kind="stable")
    r = np.interp(l, at[order], np.asarray(radius, float)[order])
    return r * curve.curvature(l), l * _arc(points)[-1]


def regularize_backbone(points: npt.ArrayLike, radius: npt.ArrayLike, options: CurveOptions,
                        fold_radius: npt.ArrayLike | None = None) -> BackboneRegularization:
    """The centerline with every stretch of ``r * kappa >= REGULARIZE_REACH`` smoothed at the local radius' scale.

    Parameters
    ----------
    points : (n, 3) mm, the centerline polyline, inlet first
    radius : (n,) mm, ``MaximumInscribedSphereRadius`` at the points (the smoothing widths' scale)
    options : the build's resampling and smoothing (the reach is measured on the curve the build makes)
    fold_radius : (n,) mm, the r of the reach (:func:`wall_fold_radius`), then regularized from
        ``WALL_REGULARIZE_REACH``; default ``radius``, regularized from ``REGULARIZE_REACH``

    Raises
    ------
    BackboneError
        The widest smoothing tried still leaves the reach at or above ``TARGET_REACH``.
    """
    points = np.asarray(points, float)
    radius = np.asarray(radius, float)
    fold = radius if fold_radius is None else np.asarray(fold_radius, float)
    reach, arc = reach_along(points, fold, options)
    before = float(reach.max())
    if before < (REGULARIZE_REACH if fold_radius is None else WALL_REGULARIZE_REACH):
        return BackboneRegularization(points, np.zeros(len(points)), before, before)
    s = _arc(points)
    runs = _runs(arc, reach >= TARGET_REACH)
    scales = [float(np.interp(np.linspace(a, b, 9), s, radius).max()) for a, b in runs]
    at = float(arc[np.argmax(reach)])
    smoothed = before
    for factor in SIGMA_FACTORS:
        sigmas = [factor * r for r in scales]
        moved = points.copy()
        for (a, b), sigma in zip(runs, sigmas, strict=True):
            weight = _ramp_weight(s, a, b, RAMP_SIGMAS * sigma)
            rows = np.flatnonzero(weight > 0.0)
            moved[rows] += weight[rows, None] * (_gaussian(s, points, sigma, rows) - points[rows])
        after, _ = reach_along(moved, fold, options)
        if after.max() < TARGET_REACH:
            return _result(points, moved, before, float(after.max()), runs, scales, sigmas)
        smoothed = float(after.max())
    raise BackboneError(before, at, float(np.interp(at, s, fold)), smoothed)


def _result(points, moved, before, after, runs, scales, sigmas) -> BackboneRegularization:
    distance = np.linalg.norm(moved - points, axis=1)
    s = _arc(points)
    stretches = []
    for (a, b), r, sigma in zip(runs, scales, sigmas, strict=True):
        near = np.flatnonzero((s >= a - RAMP_SIGMAS * sigma) & (s <= b + RAMP_SIGMAS * sigma))
        i = int(near[np.argmax(distance[near])])
        shifted = near[distance[near] > MOVED_FRACTION * r]
        lo, hi = (float(s[shifted[0]]), float(s[shifted[-1]])) if len(shifted) else (a, b)
        stretches.append(Stretch(lo, hi, r, sigma, float(distance[i]), float(s[i])))
    return BackboneRegularization(moved, distance, before, after, tuple(stretches))


def _arc(points: Points) -> FloatArray:
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])


def _runs(arc: FloatArray, flag: npt.NDArray[np.bool_]) -> list[tuple[float, float]]:
    """Contiguous flagged intervals of the dense grid, as (from, to) arc mm."""
    edges = np.diff(np.concatenate([[0], flag.astype(int), [0]]))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    return [(float(arc[i]), float(arc[j])) for i, j in zip(starts, stops, strict=True)]


def _ramp_weight(s: FloatArray, a: float, b: float, ramp: float) -> FloatArray:
    """1 on [a, b], falling to 0 over ``ramp`` mm on each side along the quintic smoothstep (C2)."""
    t = np.clip(1.0 - np.maximum(a - s, s - b) / ramp, 0.0, 1.0)
    return t**3 * (10.0 - 15.0 * t + 6.0 * t**2)


def _gaussian(s: FloatArray, points: Points, sigma: float, rows: npt.NDArray[np.intp]) -> Points:
    """Gaussian-weighted means of the polyline along arc length at the points ``rows``.

    The polyline is continued past each end by its mirror image in the end's normal plane.
    """
    length = s[-1]
    s_ext = np.concatenate([-s[:0:-1], s, 2.0 * length - s[-2::-1]])
    p_ext = np.concatenate([_mirror(points[:0:-1], points[0], points[1] - points[0]), points,
                            _mirror(points[-2::-1], points[-1], points[-1] - points[-2])])
    quadrature = np.gradient(s_ext)
    out = np.empty((len(rows), 3))
    for k, si in enumerate(s[rows]):  # row by row: the kernel is cut at KERNEL_SIGMAS widths
        lo, hi = np.searchsorted(s_ext, [si - KERNEL_SIGMAS * sigma, si + KERNEL_SIGMAS * sigma])
        w = np.exp(-0.5 * ((s_ext[lo:hi] - si) / sigma) ** 2) * quadrature[lo:hi]
        out[k] = w @ p_ext[lo:hi] / w.sum()
    return out


def _mirror(points: Points, origin: FloatArray, normal: FloatArray) -> Points:
    """``points`` reflected in the plane through ``origin`` square to ``normal``."""
    n = normal / np.linalg.norm(normal)
    return points - 2.0 * ((points - origin) @ n)[:, None] * n
