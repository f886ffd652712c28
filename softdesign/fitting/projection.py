"""Surface points in the centerline's frames: p -> (l, a, rho).

The foot point of ``p`` is the point ``c(l)`` of the smooth centerline where
``(p - c(l)) . T(l) = 0`` and ``|p - c(l)|`` is least.  It is seeded by the
nearest of a dense set of curve samples (a KD-tree query) and refined on the
curve itself by a safeguarded Newton iteration inside the bracket of the
neighbouring samples, for all points at once.  Then, with the frame columns
(N, B, T) at l::

    a   = atan2((p - c) . B, (p - c) . N)      in (-pi, pi]
    rho = |p - c|                              mm

A foot point that falls outside [0, 1] is clamped to the end, and the point
is flagged as lying before the start (-1) or beyond the end (+1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.spatial import cKDTree

from softdesign.errors import InputDataError
from softdesign.fitting import bspline_basis as bb
from softdesign.fitting.mapping import Mapper, serial_map
from softdesign.types import FloatArray, FramedCurve, Points

#: Spacing of the curve samples that seed the Newton iteration, mm.
SEED_SPACING_MM = 0.5
#: Newton stops when every step is below this, mm of arc length.
NEWTON_TOL_MM = 1e-10
#: Safeguarded Newton converges in 4-6 steps from a bracket one sample wide; this is a hard stop.
NEWTON_MAX_STEPS = 60
#: Feet refined together (500k in one go took ~25 % longer: their arrays no longer stay in cache).
FOOT_CHUNK = 1 << 15
#: Points projected by one task of the mapper: a 1,000,000-vertex surface in 8 blocks, which two
#: processes share evenly; fewer than twice this many in two halves.
PROJECT_BLOCK = 1 << 17
#: Up to this many points are projected here in one go (a task's fork costs more than it saves); more, on the
#: mapper: the blend's look at the body (100k vertices of the 1M case, 0.26 s of CPU) in two halves.
SPLIT_POINTS = 1 << 16


@dataclass(frozen=True)
class PolarPoints:
    """Points with their coordinates in the centerline's frames.

    Attributes
    ----------
    points : (n, 3) float, mm, the input points
    l : (n,) float, normalized arc length of the foot point, in [0, 1]
    angle : (n,) float, rad, in (-pi, pi], measured from N towards B
    rho : (n,) float, mm, distance from the foot point
    end_side : (n,) int8, -1 foot clamped at l = 0, +1 clamped at l = 1, 0 inside
    """

    points: Points
    l: FloatArray
    angle: FloatArray
    rho: FloatArray
    end_side: npt.NDArray[np.int8]

    def __len__(self) -> int:
        return len(self.l)

    def subset(self, mask: npt.ArrayLike) -> PolarPoints:
        """The points selected by a boolean mask or an index array (copies: indexing by an array makes new ones)."""
        mask = np.asarray(mask)
        if mask.ndim != 1:
            raise ValueError(f"PolarPoints.subset: expected a 1-D boolean mask or index array, got shape {mask.shape}")
        return PolarPoints(self.points[mask], self.l[mask], self.angle[mask], self.rho[mask], self.end_side[mask])


def project_points(curve: FramedCurve, points: npt.ArrayLike, mapper: Mapper = serial_map,
                   known: tuple[slice, PolarPoints] | None = None) -> PolarPoints:
    """Foot point, angle and distance of every point on a framed centerline.

    Parameters
    ----------
    curve : the smooth centerline (normalized l, frames with columns N, B, T)
    points : (n, 3) float, mm
    mapper : runs the blocks of at most ``PROJECT_BLOCK`` points above ``SPLIT_POINTS`` (each point's projection
        is its own), perhaps on other processes; the same numbers for any, and for any block size
    known : the rows of ``points`` (a slice) already projected on this very curve, and their projection (e.g. the
        blend's look at the body, every fifth vertex): only the others are projected here, and each point's
        projection being its own, the result is the same

    Returns
    -------
    PolarPoints with the foot point refined on the curve to ``NEWTON_TOL_MM``.

    Raises
    ------
    InputDataError
        ``points`` is not an (n, 3) array of finite numbers.
    """
    points = np.asarray(points, float)
    if points.ndim != 2 or points.shape[1] != 3 or not np.all(np.isfinite(points)):
        raise InputDataError(
            f"surface points: expected an (n, 3) array of finite mm coordinates, got shape {points.shape}; "
            "check the surface file"
        )
    if known is not None:
        return _with_known(curve, points, mapper, *known)
    if len(points) <= SPLIT_POINTS:
        return PolarPoints(points.copy(), *_polar(curve, points))
    parts = mapper(lambda rows: _polar(curve, points[rows]), even_blocks(len(points)))
    l, angle, rho, side = (np.concatenate([part[k] for part in parts]) for k in range(4))
    return PolarPoints(points.copy(), l, angle, rho, side)


def even_blocks(count: int) -> list[slice]:
    """``count`` rows in an even number of blocks of at most ``PROJECT_BLOCK`` rows, of equal size but the last:
    two processes share them evenly (500k rows: 4 of 125k, where blocks of ``PROJECT_BLOCK`` left one worker 262k
    and the other 238k)."""
    pairs = -(-count // (2 * PROJECT_BLOCK))
    return bb.chunks(count, -(-count // (2 * pairs)))


def _with_known(curve: FramedCurve, points: Points, mapper: Mapper, rows: slice, polar: PolarPoints) -> PolarPoints:
    """:func:`project_points` of ``points`` (n, 3) mm whose ``rows`` are projected already (``polar``)."""
    todo = np.ones(len(points), bool)
    todo[rows] = False
    rest = np.flatnonzero(todo)
    found = project_points(curve, points[rest], mapper) if len(rest) else None
    out = []
    for name in ("l", "angle", "rho", "end_side"):
        kept = getattr(polar, name)
        merged = np.empty(len(points), kept.dtype)
        merged[rows] = kept
        if found is not None:
            merged[rest] = getattr(found, name)
        out.append(merged)
    return PolarPoints(points.copy(), *out)


def _polar(curve: FramedCurve, points: Points) -> tuple[FloatArray, FloatArray, FloatArray, npt.NDArray[np.int8]]:
    """l, angle, rho and end side of the points (n, 3) mm, checked (:func:`project_points`)."""
    l = foot_parameters(curve, points)
    order = np.argsort(l, kind="stable")  # the curve evaluated in order along it, then put back
    origin, frames = np.empty_like(points), np.empty((len(l), 3, 3))
    origin[order], frames[order] = curve.points(l[order]), curve.frames(l[order])
    offset = points - origin
    local = np.einsum("nij,ni->nj", frames, offset)
    tangent_part = curve.derivative(np.array([0.0, 1.0]))
    side = np.zeros(len(points), np.int8)
    side[(l <= 0.0) & (offset @ tangent_part[0] < 0.0)] = -1
    side[(l >= 1.0) & (offset @ tangent_part[1] > 0.0)] = 1
    return l, np.arctan2(local[:, 1], local[:, 0]), np.linalg.norm(offset, axis=1), side


def foot_parameters(curve: FramedCurve, points: Points) -> FloatArray:
    """Normalized l of the nearest foot point of each point, clamped to [0, 1].

    Minimizes ``g(l) = |p - c(l)|^2 / 2``: ``g' = -(p - c) . c'`` and
    ``g'' = |c'|^2 - (p - c) . c''``, by Newton steps kept inside the bracket
    of the samples next to the nearest sample (bisection when a step leaves it).
    """
    count = max(int(np.ceil(curve.length / SEED_SPACING_MM)), 8) + 1
    grid = np.linspace(0.0, 1.0, count)
    # c, c' and c'' at the samples: every search starts at one and brackets itself by its neighbours
    samples = (curve.points(grid), curve.derivative(grid, 1), curve.derivative(grid, 2))
    nearest = np.asarray(cKDTree(samples[0]).query(points)[1])
    # solved in order along the curve (each evaluation then reads its polynomial pieces in turn)
    order = np.argsort(nearest, kind="stable")
    l = np.empty(len(points))
    # each foot is its own search: FOOT_CHUNK points at a time keep the arrays in cache
    for lo in range(0, len(points), FOOT_CHUNK):
        part = order[lo : lo + FOOT_CHUNK]
        l[part] = _refined_feet(curve, points[part], grid, nearest[part], samples)
    return l


def _refined_feet(
    curve: FramedCurve, points: Points, grid: FloatArray, nearest: np.ndarray, samples: tuple[Points, Points, Points]
) -> FloatArray:
    """Safeguarded Newton from the nearest samples ``grid[nearest]`` to each point's foot, clamped to [0, 1].

    ``samples`` holds c, c' and c'' at ``grid`` (each (count, 3)): the bracket's slopes and the first
    step read them there instead of evaluating the curve at those same l again.
    """
    count = len(grid)
    c, d1, d2 = samples
    below, above = np.maximum(nearest - 1, 0), np.minimum(nearest + 1, count - 1)
    lo, hi = grid[below], grid[above]
    slope_lo = -np.einsum("ni,ni->n", points - c[below], d1[below])
    slope_hi = -np.einsum("ni,ni->n", points - c[above], d1[above])
    x = grid[nearest].copy()
    at_lo, at_hi = slope_lo >= 0.0, slope_hi <= 0.0
    active = ~(at_lo | at_hi)
    tol = NEWTON_TOL_MM / curve.length
    for step in range(NEWTON_MAX_STEPS):
        if not active.any():
            break
        idx = np.flatnonzero(active)
        if step == 0:  # every x is still its sample
            at = nearest[idx]
            x_new, lo_new, hi_new = _newton_step(points[idx], x[idx], lo[idx], hi[idx], (c[at], d1[at], d2[at]))
        else:
            x_new, lo_new, hi_new = _safeguarded_step(curve, points[idx], x[idx], lo[idx], hi[idx])
        done = np.abs(x_new - x[idx]) <= tol
        x[idx], lo[idx], hi[idx] = x_new, lo_new, hi_new
        active[idx[done]] = False
    # A slope that already points away from the bracket means the minimum is at its edge
    # (only the curve's ends, for a dense enough sampling).
    x[at_lo] = lo[at_lo]
    x[at_hi & ~at_lo] = hi[at_hi & ~at_lo]
    return np.clip(x, 0.0, 1.0)


def _safeguarded_step(
    curve: FramedCurve, points: Points, x: FloatArray, lo: FloatArray, hi: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """One Newton step on g'(l) = 0 with bisection fallback; returns x, and the shrunk bracket."""
    return _newton_step(points, x, lo, hi, (curve.points(x), curve.derivative(x, 1), curve.derivative(x, 2)))


def _newton_step(
    points: Points, x: FloatArray, lo: FloatArray, hi: FloatArray, at_x: tuple[Points, Points, Points]
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """:func:`_safeguarded_step` given c, c' and c'' at x (``at_x``)."""
    offset = points - at_x[0]
    d1, d2 = at_x[1], at_x[2]
    slope = -np.einsum("ni,ni->n", offset, d1)
    curvature = np.einsum("ni,ni->n", d1, d1) - np.einsum("ni,ni->n", offset, d2)
    lo = np.where(slope < 0.0, x, lo)
    hi = np.where(slope > 0.0, x, hi)
    with np.errstate(divide="ignore", invalid="ignore"):
        newton = x - slope / curvature
    # The closed bracket: a root reached exactly becomes a bracket end (lo or hi) on the next step.
    ok = (curvature > 0.0) & (newton >= lo) & (newton <= hi)
    x_new = np.where(ok, newton, 0.5 * (lo + hi))
    x_new = np.where(slope == 0.0, x, x_new)
    return x_new, lo, hi
