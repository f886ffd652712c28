"""The closest point on a fitted tube to each wall point: damped Gauss-Newton on (l, a).

The fitted surface at q = 1 is ``S(l, a) = c(l) + rho(l, a) (cos a N(l) + sin a B(l))``.  The distance of a point
p to it is ``min |p - S(l, a)|``, found from the point's own projection (l, a), with the surface's tangents exact
(the frames' l derivative from c', c'' and their measured twist, see :func:`frame_twist_table`).  What the
distances say about the fit (RMS, percentiles, the hold-out) is :mod:`softdesign.fitting.metrics`'.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import numpy.typing as npt

from softdesign.fitting import bspline_basis as bb
from softdesign.fitting.bspline_surface import RadiusSpline
from softdesign.fitting.mapping import Mapper, mapped, serial_map
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
    distance, l, a, _ = closest_with_part(curve, spline, polar.points, search_start(polar, start))
    return distance, l, a


def search_start(polar: PolarPoints, start: tuple[FloatArray, FloatArray] | SearchStart | None) -> SearchStart:
    """Where each point's search starts: ``start`` as given, or the point's own projection (l, a)."""
    if start is None:
        return SearchStart(polar.l, polar.angle)
    return start if isinstance(start, SearchStart) else SearchStart(*start)


def closest_with_part(
    curve: FramedCurve, spline: RadiusSurface, p: Points, start: SearchStart, mapper: Mapper = serial_map,
) -> tuple[FloatArray, FloatArray, FloatArray, CurvePart]:
    """:func:`closest_surface_points` on the points p (n, 3) mm, also returning the curve's part at the result.

    Every point's search is its own: they run ``CLOSEST_CHUNK`` points at a time, whose arrays stay in
    the processor's caches (the same numbers as all at once, in less time), the blocks by ``mapper``
    (perhaps on other processes: the same numbers; a single block always runs here).
    """
    job = closest_job(curve, spline, p, start)
    return job.join(mapped(mapper, job.task, job.items))


Found = tuple[FloatArray, FloatArray, FloatArray, CurvePart]


@dataclass(frozen=True)
class ClosestJob:
    """:func:`closest_with_part` as a task over its blocks of points (``items``, slices in order, each its own) and
    the join of their results, for a caller that runs the blocks beside other work."""

    task: Callable[[slice], Found]
    items: list[slice]

    def join(self, pieces: Sequence[Found]) -> Found:
        """distance, l, angle and the curve's part of every point, from the blocks' results in order."""
        if len(pieces) == 1:
            return pieces[0]
        dist, l, a = (np.concatenate([piece[k] for piece in pieces]) for k in range(3))
        arrays = zip(*(piece[3].arrays() for piece in pieces), strict=True)
        return dist, l, a, CurvePart(*(np.concatenate(parts) for parts in arrays))


def closest_job(curve: FramedCurve, spline: RadiusSurface, p: Points, start: SearchStart) -> ClosestJob:
    """The blocks of :func:`closest_with_part`'s search, its parameters but the mapper."""
    twist = frame_twist_table(curve)

    def piece(r: slice) -> Found:
        return _closest_piece(curve, spline, twist, p[r], start.subset(r))

    return ClosestJob(piece, bb.chunks(len(p), CLOSEST_CHUNK))


def _closest_piece(
    curve: FramedCurve, spline: RadiusSurface, twist, p: Points, start: SearchStart
) -> tuple[FloatArray, FloatArray, FloatArray, CurvePart]:
    """Damped Gauss-Newton from ``start`` to the closest surface point of each point p (n, 3) mm."""
    l, a = np.array(start.l, float), np.array(start.angle, float)
    part = _curve_part(curve, twist, l) if start.curve_part is None else start.curve_part
    part = CurvePart(*(np.array(v, float) for v in part.arrays()))  # updated in place below
    surface, du, dv = _surface_and_tangents(part, spline, l, a)
    dist = np.linalg.norm(p - surface, axis=1)
    state = (l, a, surface, du, dv, dist, *part.arrays())
    active = np.ones(len(l), bool)
    for _ in range(CLOSEST_MAX_STEPS):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        every = idx.size == len(l)  # every point still moves: the state itself is updated, no gather and scatter
        current = state if every else tuple(v[idx] for v in state)
        points = p if every else p[idx]
        step = _gauss_newton_step(points - current[2], current[3], current[4])
        moved = _damped_update(curve, spline, twist, points, current, step)
        if not every:
            for target, value in zip(state, current, strict=True):
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
    """c, c', the frames and their l derivative (from c', c'' and the twist table) at l.

    A curve with ``frames_and_derivative`` (:class:`~softdesign.geometry.frames.FramedSpline`) evaluates c' once
    for its frames' tangents and for c' itself: the same numbers as ``frames`` and ``derivative``.
    """
    both = getattr(curve, "frames_and_derivative", None)
    frames, d1 = both(l) if both is not None else (curve.frames(l), curve.derivative(l, 1))
    normal, binormal, tangent = frames[:, :, 0], frames[:, :, 1], frames[:, :, 2]
    d2 = curve.derivative(l, 2)
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


def _damped_update(curve, spline, twist, p, current, step) -> FloatArray:
    """Take the Gauss-Newton step, halving it (up to 8 times) for the points where it does not help.

    ``current`` is (l, a, S, dS/dl, dS/da, distance, then the fields of the curve's part), each (n, ...):
    updated in place to the same at the new (l, a) of each point whose distance a step does not increase
    (a point whose step never reduces the distance stays where it was: it has converged).

    Returns
    -------
    (n,) mm, how far each point's surface point moved (0 where it stayed).
    """
    l0, a0, surface0, dist0 = current[0], current[1], current[2], current[5]
    moved = np.zeros(len(l0))
    pending = np.arange(len(l0))
    scale = 1.0
    for _ in range(8):  # a row is written once, when it leaves ``pending``: the rows still read are the start's
        l = np.clip(l0[pending] + scale * step[pending, 0], 0.0, 1.0)
        a = a0[pending] + scale * step[pending, 1]
        part = _curve_part(curve, twist, l)
        surface, du, dv = _surface_and_tangents(part, spline, l, a)
        d = np.linalg.norm(p[pending] - surface, axis=1)
        better = d <= dist0[pending]
        rows = pending[better]
        moved[rows] = np.linalg.norm(surface[better] - surface0[rows], axis=1)
        for target, value in zip(current, (l, a, surface, du, dv, d, *part.arrays()), strict=True):
            target[rows] = value[better]
        pending = pending[~better]
        if pending.size == 0:
            break
        scale *= 0.5
    return moved
