"""Smooth centerlines parameterized by normalized arc length l in [0, 1].

A polyline (mm, proximal first) becomes a :class:`SmoothCurve` in four steps:

1. a parametric spline on the chord-length parameter, interpolating
   (``smoothing_mm = 0``) or smoothing with ``s = n * smoothing_mm**2`` (the
   RMS distance of the input points from the spline is at most ``smoothing_mm``);
2. reparameterization by its true arc length (Gauss-Legendre quadrature, then
   Newton on s(u) = target);
3. optional end handling: the last ``end_straight_mm`` of each end is replaced
   by a straight extension along the tangent where the trim starts, so that the
   length is kept and the curl of a VMTK centerline into its caps is removed;
4. resampling at equal arc length (``spacing_mm`` or ``count`` points) and a
   quintic interpolating spline in l on that uniform grid.

Step 4 gives every curve resampled with the same count the same knot vector,
so blends of shapes are exact on the spline coefficients, and curvature and
torsion come from analytic derivatives, not finite differences.

Joints: link breaks where the curvature jumps (seed 003's sections meet) are
kept sharp when asked, at any smoothing: each piece between them is smoothed
(pinned at its joints) and resampled on its own, so no smoothing crosses a
joint (:mod:`softdesign.geometry.curve_joints` says when a break is one).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import numpy.typing as npt
from scipy.interpolate import BSpline, PPoly, make_interp_spline

from softdesign.errors import ConfigError, GeometryError
from softdesign.geometry.curve_joints import checked_grid, joint_cuts, pieces_spline
from softdesign.geometry.polyline_spline import (
    ARC_REL_TOL,
    MIN_POLYLINE_POINTS,
    NEWTON_STEPS,
    arc_length_table,
    chord_spline,
    distinct_points,
    points_at_arc_length,
    speed_integral,
)
from softdesign.types import FloatArray, Points

#: Degree of the spline in l (5: torsion, a third derivative, is still C2).
DEGREE = 5
#: Dense evaluation grid (frames, reports): at least this many per sample interval ...
DENSE_PER_INTERVAL = 8
#: ... and no coarser than this arc step, mm.
DENSE_STEP_MM = 0.05
#: Weight of a joint's vertex in the smoothing of the pieces it ends: a pin.  The spline may leave a point of
#: weight w by at most sqrt(s) / w (s the smoothing's sum of squares, n * smoothing_mm**2): 6e-4 mm for 36 points
#: at 0.1 mm; on seed 003's arcs it leaves it by 1e-9 mm.
JOINT_WEIGHT = 1e3
#: Curvature below which torsion is not reported, 1/mm: a bend of radius 1 m or more.  Torsion, the
#: turning rate of the osculating plane, is (c' x c'') . c''' / |c' x c''|^2: it divides by kappa^2,
#: so near an inflection it is the noise of c''' magnified.  At the vessel scale such a bend is
#: straight: over 40 mm (a few diameters of the widest vessel) it leaves its chord by at most
#: L^2 kappa / 8 = 0.2 mm, the order of a VMTK centerline's placement noise and of
#: resample.smoothing_mm, so its plane is set by that noise, not by the anatomy.  On the VMTK aorta
#: |tau| reaches 4.7 /mm where kappa ~ 1e-4 /mm; FRENET_KAPPA_TOL (1e-6 /mm), where the frames
#: themselves give up, is far too low for a rate divided by kappa^2.
TORSION_KAPPA_FLOOR = 1e-3
#: The reported largest torsion is taken where the curve bends at least this fraction as tightly as its tightest
#: bend: on a real centerline a stretch a hundred times straighter than the vessel's bends still turns its
#: osculating plane by noise (the VMTK aorta read 3.7 /mm, a 14.7 /mm elsewhere, at kappa ~ 2e-3 /mm).
TORSION_REL_FLOOR = 0.2


@dataclass(frozen=True)
class CurveOptions:
    """How a polyline is smoothed, trimmed and resampled (mm).

    Attributes
    ----------
    spacing_mm : target arc-length spacing of the samples (the actual one is <= it)
    count : number of samples; overrides ``spacing_mm`` when given (>= 6)
    smoothing_mm : allowed RMS deviation of the smoothing spline from the input; 0 interpolates
    end_straight_mm : length at each end replaced by a straight extension along the end tangent
    """

    spacing_mm: float = 0.5
    count: int | None = None
    smoothing_mm: float = 0.1
    end_straight_mm: float = 0.0


@dataclass(frozen=True)
class CurveReport:
    """Per-path figures for the manifest: mm, 1/mm; ``*_l`` is where the maximum is."""

    length_mm: float
    sample_count: int
    spacing_mm: float
    max_curvature_per_mm: float
    max_curvature_l: float
    max_abs_torsion_per_mm: float | None  # where kappa >= TORSION_KAPPA_FLOOR; None when it never is
    max_abs_torsion_l: float | None
    torsion_defined_fraction: float  # of the dense grid: where kappa >= torsion_floor_per_mm
    torsion_floor_per_mm: float  # max(TORSION_KAPPA_FLOOR, TORSION_REL_FLOOR * max curvature)


@dataclass(frozen=True)
class SmoothCurve:
    """A quintic spline c(l), l in [0, 1], interpolating samples at equal arc length.

    Attributes
    ----------
    spline : scipy BSpline in l, values (3,) mm
    length : arc length of the spline, mm
    l_grid : (m,) uniform sample parameters, l_grid[0] = 0, l_grid[-1] = 1
    joints : indices into ``l_grid`` of the sharp joints: knots of full multiplicity, nothing smoothed across
    """

    spline: BSpline
    length: float
    l_grid: FloatArray
    joints: tuple[int, ...] = ()

    @cached_property
    def pieces(self) -> PPoly:
        """The same spline as polynomial pieces (evaluated 2-4x faster than de Boor on many points)."""
        return piecewise_polynomial(self.spline)

    @cached_property
    def arc_length_table(self) -> FloatArray:
        """Arc length from l = 0 to each ``l_grid`` sample, mm."""
        return arc_length_table(self.spline, self.l_grid)

    def points(self, l: npt.ArrayLike) -> Points:
        """Positions c(l), (n, 3) mm, for l (n,) in [0, 1]."""
        return self.pieces(checked_l(l))

    def derivative(self, l: npt.ArrayLike, order: int = 1) -> Points:
        """d^k c / dl^k (n, 3), mm, with respect to normalized l."""
        return self.pieces(checked_l(l), nu=order)

    def speed(self, l: npt.ArrayLike) -> FloatArray:
        """|dc/dl| (n,), mm: the local arc length per unit l (= length if l is exact arc length)."""
        return np.linalg.norm(self.derivative(l), axis=1)

    def tangents(self, l: npt.ArrayLike) -> Points:
        """Unit tangents T = c' / |c'|, (n, 3)."""
        d1 = self.derivative(l)
        return d1 / np.linalg.norm(d1, axis=1, keepdims=True)

    def curvature(self, l: npt.ArrayLike) -> FloatArray:
        """kappa = |c' x c''| / |c'|^3, (n,) 1/mm."""
        d1, d2 = self.derivative(l, 1), self.derivative(l, 2)
        return np.linalg.norm(np.cross(d1, d2), axis=1) / np.linalg.norm(d1, axis=1) ** 3

    def curvature_vectors(self, l: npt.ArrayLike) -> Points:
        """dT/ds = kappa * N_frenet, (n, 3) 1/mm (defined on straight runs too, where it is 0)."""
        d1, d2 = self.derivative(l, 1), self.derivative(l, 2)
        speed2 = np.einsum("ij,ij->i", d1, d1)
        normal_part = d2 - (np.einsum("ij,ij->i", d2, d1) / speed2)[:, None] * d1
        return normal_part / speed2[:, None]

    def torsion(self, l: npt.ArrayLike) -> FloatArray:
        """tau = (c' x c'') . c''' / |c' x c''|^2, (n,) 1/mm; NaN where kappa < TORSION_KAPPA_FLOOR.

        Torsion is the turning rate of the Frenet binormal; where the curve is
        straight there is no binormal and no torsion, and where it is nearly
        straight (below the floor) the figure is noise over kappa^2: NaN says so.
        """
        d1, d2, d3 = (self.derivative(l, k) for k in (1, 2, 3))
        cross = np.cross(d1, d2)
        norm2 = np.einsum("ij,ij->i", cross, cross)
        kappa = np.sqrt(norm2) / np.linalg.norm(d1, axis=1) ** 3
        with np.errstate(divide="ignore", invalid="ignore"):
            tau = np.einsum("ij,ij->i", cross, d3) / norm2
        return np.where(kappa >= TORSION_KAPPA_FLOOR, tau, np.nan)

    def arc_length(self, l: npt.ArrayLike) -> FloatArray:
        """Arc length from l = 0 to each l (n,), mm (Gauss-Legendre on the sample intervals)."""
        l = checked_l(l)
        table = self.arc_length_table
        k = np.clip(np.searchsorted(self.l_grid, l, side="right") - 1, 0, len(self.l_grid) - 2)
        return table[k] + speed_integral(self.pieces, self.l_grid[k], l)

    @cached_property
    def uniform(self) -> bool:
        """True when ``l_grid`` is ``linspace(0, 1, m)`` (every curve but one on a grid of pieces)."""
        return bool(np.array_equal(self.l_grid, np.linspace(0.0, 1.0, len(self.l_grid))))

    def dense_l(self) -> FloatArray:
        """Evaluation grid containing ``l_grid``: DENSE_PER_INTERVAL per interval, steps <= DENSE_STEP_MM.

        Uniform on a uniform ``l_grid``; on a grid of pieces (:func:`smooth_curve_from_samples` given ``l_grid``)
        each interval is divided alike, so every joint is a dense sample and no Taylor chord crosses it.
        """
        intervals = len(self.l_grid) - 1
        if not self.uniform:
            widest = float(np.max(np.diff(self.l_grid)))
            factor = max(DENSE_PER_INTERVAL, int(np.ceil(self.length * widest / DENSE_STEP_MM)))
            steps = np.linspace(0.0, 1.0, factor + 1)[:-1]
            inner = self.l_grid[:-1, None] + np.diff(self.l_grid)[:, None] * steps
            return np.concatenate([inner.ravel(), self.l_grid[-1:]])
        factor = max(DENSE_PER_INTERVAL, int(np.ceil(self.length / intervals / DENSE_STEP_MM)))
        # a dense point may sit one ulp off its sample (a knot): a Taylor chord from it then uses the
        # neighbouring polynomial piece, which costs ~1e-13 mm (measured on the aorta), i.e. nothing
        return np.linspace(0.0, 1.0, intervals * factor + 1)

    def report(self) -> CurveReport:
        """Length, sample count and spacing, max curvature, and max |torsion| where the curve bends (dense grid).

        Torsion is reported where the curvature is at least ``torsion_floor_per_mm``: the larger of the absolute
        floor and :data:`TORSION_REL_FLOOR` of the curve's largest curvature.
        """
        l = self.dense_l()
        kappa = self.curvature(l)
        floor = max(TORSION_KAPPA_FLOOR, TORSION_REL_FLOOR * float(kappa.max()))
        tau = np.where(kappa >= floor, np.abs(self.torsion(l)), np.nan)
        ik = int(np.argmax(kappa))
        defined = np.isfinite(tau)
        it = int(np.nanargmax(tau)) if defined.any() else None
        return CurveReport(
            length_mm=float(self.length),
            sample_count=len(self.l_grid),
            spacing_mm=float(self.length / (len(self.l_grid) - 1)),
            max_curvature_per_mm=float(kappa[ik]),
            max_curvature_l=float(l[ik]),
            max_abs_torsion_per_mm=None if it is None else float(tau[it]),
            max_abs_torsion_l=None if it is None else float(l[it]),
            torsion_defined_fraction=float(defined.mean()),
            torsion_floor_per_mm=floor,
        )


def piecewise_polynomial(spline: BSpline) -> PPoly:
    """A vector-valued BSpline as a PPoly with the same values and derivatives (to rounding).

    A point's piece is found by bisection and its polynomial summed directly, instead of de
    Boor's recursion per point and per derivative order.
    """
    coefficients = np.asarray(spline.c, float)
    per_axis = [PPoly.from_spline(BSpline(spline.t, column, spline.k).tck) for column in coefficients.T]
    return PPoly(np.stack([p.c for p in per_axis], axis=-1), per_axis[0].x)


def checked_l(l: npt.ArrayLike) -> FloatArray:
    """l as a float array (n,) in [0, 1] (rounding just outside is clipped).

    Raises
    ------
    ConfigError
        A value outside [0, 1] or not finite.
    """
    l = np.atleast_1d(np.asarray(l, float))
    if l.ndim != 1 or not np.all(np.isfinite(l)) or l.min() < -ARC_REL_TOL or l.max() > 1.0 + ARC_REL_TOL:
        raise ConfigError(
            f"l (normalized arc length) must be finite values in [0, 1], got shape {l.shape}, "
            f"range [{np.nanmin(l) if l.size else np.nan:.6g}, {np.nanmax(l) if l.size else np.nan:.6g}]"
        )
    return np.clip(l, 0.0, 1.0)


def smooth_curve_from_samples(
    samples: npt.ArrayLike, joints: tuple[int, ...] = (), l_grid: FloatArray | None = None
) -> SmoothCurve:
    """Quintic interpolating spline through samples taken at equal arc length.

    Parameters
    ----------
    samples : (m, 3) float, mm, m >= 6, at l = linspace(0, 1, m)
    joints : increasing indices of samples where the curve may turn its curvature sharply: the spline is
        a separate interpolant on each piece between them (>= 6 samples each), joined at the shared sample
    l_grid : (m,) the samples' l instead of linspace(0, 1, m), with ``joints``: uniform on each piece between
        joints (:func:`~softdesign.geometry.curve_joints.grid_with_joints`), so joints at any l (a PCC chain's)

    Every call with the same m and joints gives the same knot vector, so spline
    coefficients of such curves blend exactly.
    """
    samples = np.asarray(samples, float)
    if samples.ndim != 2 or samples.shape[1] != 3 or len(samples) < DEGREE + 1:
        raise GeometryError(
            f"curve samples: expected an (m, 3) array with m >= {DEGREE + 1}, got shape {samples.shape}; "
            "resample with more points (resample.count or a smaller resample.spacing_mm)"
        )
    l_grid = np.linspace(0.0, 1.0, len(samples)) if l_grid is None else checked_grid(l_grid, len(samples))
    if joints:
        spline = pieces_spline(l_grid, samples, joints, DEGREE)
    else:
        spline = make_interp_spline(l_grid, samples, k=DEGREE)
    length = float(arc_length_table(spline, l_grid)[-1])
    return SmoothCurve(spline, length, l_grid, tuple(int(j) for j in joints))


def smooth_curve_from_polyline(
    points: npt.ArrayLike, options: CurveOptions = CurveOptions(), joints: npt.ArrayLike = ()
) -> SmoothCurve:
    """Smooth, end-trim and resample a polyline by arc length (see the module docstring).

    Parameters
    ----------
    points : (n, 3) float, mm, proximal first; consecutive duplicates are skipped
    options : spacing or count, smoothing and end handling, mm
    joints : (k,) normalized l of link breaks to keep sharp where the polyline has a vertex on a grid
        sample (see the module docstring); the others are smoothed over

    Raises
    ------
    GeometryError
        Fewer than 4 distinct points, non-finite points, or the spline fit failed.
    ConfigError
        Bad options (negative sizes, count < 6, ends longer than half the path).
    """
    _check_options(options)
    points = distinct_points(points)
    spline, u = chord_spline(points, options.smoothing_mm, DEGREE)
    table = arc_length_table(spline, u)
    total = float(table[-1])
    end = options.end_straight_mm
    if 2.0 * end >= total:
        raise ConfigError(
            f"resample.end_straight_mm = {end:g} mm must be less than half the path length "
            f"({total:.4g} mm); lower it"
        )
    joints = np.asarray(joints, float).ravel()
    pieced = _pieced_samples(points, options, joints) if joints.size else None
    if pieced is not None:
        return smooth_curve_from_samples(*pieced)
    count = _sample_count(options, total)
    s_target = np.linspace(0.0, total, count)
    samples = points_at_arc_length(spline, u, table, s_target, end)
    return smooth_curve_from_samples(samples)


def _sample_count(options: CurveOptions, total: float) -> int:
    """Samples of the resampling grid over a path of ``total`` mm (``count``, or spacing at most ``spacing_mm``)."""
    count = options.count if options.count is not None else int(np.ceil(total / options.spacing_mm - 1e-9)) + 1
    return max(count, DEGREE + 1)


def _pieced_samples(points: Points, options: CurveOptions, joints: FloatArray) -> tuple[Points, tuple[int, ...]] | None:
    """Samples (count, 3) smoothed piece by piece between the joints, and the joints' samples; None without a joint.

    Whether a break is a joint is read on the spline interpolating every vertex, whatever the smoothing: a
    smoothing spline through the whole path rounds the corner and moves the vertex's arc length by about the
    smoothing, far more than :data:`~softdesign.geometry.curve_joints.JOINT_TOL_SPACINGS` allows.  The grid is
    that spline's length's; each piece then keeps its own length (:func:`_samples_by_piece`).
    """
    spline, u = chord_spline(points, 0.0, DEGREE)
    table = arc_length_table(spline, u)
    count = _sample_count(options, float(table[-1]))
    cuts = joint_cuts(table, count, joints)
    samples = _samples_by_piece(points, options, cuts, count) if cuts else None
    return None if samples is None else (samples, tuple(grid for _, grid in cuts))


def _samples_by_piece(points: Points, options: CurveOptions, cuts: list[tuple[int, int]], count: int) -> Points | None:
    """Samples (count, 3) with each piece between joints smoothed and resampled on its own; None if one is too short.

    A piece from vertex a to vertex b fills grid samples g_a..g_b at equal arc length of its own spline; the
    straight ends apply to the first piece's start and the last one's end.  A smoothing piece is pinned at its
    joints (:data:`JOINT_WEIGHT`): both pieces pass through the joint's vertex, and the joint's sample is their
    midpoint (the same point to ~1e-9 mm).
    """
    vertices = [0, *(v for v, _ in cuts), len(points) - 1]
    grids = [0, *(g for _, g in cuts), count - 1]
    end_mm = options.end_straight_mm
    pieces = []
    for i in range(len(vertices) - 1):
        va, vb, ga, gb = vertices[i], vertices[i + 1], grids[i], grids[i + 1]
        if vb - va + 1 < MIN_POLYLINE_POINTS or gb - ga < DEGREE:
            return None
        weights = np.ones(vb - va + 1)
        weights[[0, -1]] = (JOINT_WEIGHT if i > 0 else 1.0), (JOINT_WEIGHT if i < len(vertices) - 2 else 1.0)
        spline, u = chord_spline(points[va : vb + 1], options.smoothing_mm, DEGREE, weights)
        table = arc_length_table(spline, u)
        start, stop = (end_mm if i == 0 else 0.0), (end_mm if i == len(vertices) - 2 else 0.0)
        if start + stop >= table[-1]:
            return None
        pieces.append(points_at_arc_length(spline, u, table, np.linspace(0.0, table[-1], gb - ga + 1), start, stop))
    for left, right in zip(pieces[:-1], pieces[1:], strict=True):
        right[0] = 0.5 * (left[-1] + right[0])
    return np.concatenate([pieces[0]] + [piece[1:] for piece in pieces[1:]])


def l_from_points(curve: SmoothCurve, points: npt.ArrayLike) -> FloatArray:
    """Foot point parameters (n,) in [0, 1]: where (p - c(l)) . c'(l) = 0, or the nearer end.

    Seeded from the nearest dense sample (KD-tree), then safeguarded Newton
    steps (at most one dense interval each) on the spline.
    """
    from scipy.spatial import cKDTree

    points = np.asarray(points, float).reshape(-1, 3)
    l_dense = curve.dense_l()
    step = l_dense[1] - l_dense[0]
    l = l_dense[cKDTree(curve.points(l_dense)).query(points)[1]]
    for _ in range(NEWTON_STEPS):
        d = points - curve.points(l)
        d1, d2 = curve.derivative(l, 1), curve.derivative(l, 2)
        slope = np.einsum("ij,ij->i", d, d1)
        curvature_term = np.einsum("ij,ij->i", d1, d1) - np.einsum("ij,ij->i", d, d2)
        move = np.where(curvature_term > 0.0, slope / np.where(curvature_term > 0.0, curvature_term, 1.0), 0.0)
        l = np.clip(l + np.clip(move, -step, step), 0.0, 1.0)
    return l


def measure_deviation(curve: SmoothCurve, points: npt.ArrayLike) -> FloatArray:
    """Distance from each point (n, 3) to the curve at its foot point, (n,) mm."""
    points = np.asarray(points, float).reshape(-1, 3)
    return np.linalg.norm(points - curve.points(l_from_points(curve, points)), axis=1)


def _check_options(options: CurveOptions) -> None:
    if not options.spacing_mm > 0.0:
        raise ConfigError(f"resample.spacing_mm must be > 0 mm, got {options.spacing_mm}")
    if options.count is not None and options.count < DEGREE + 1:
        raise ConfigError(f"resample.count must be >= {DEGREE + 1} (a quintic spline), got {options.count}")
    for key in ("smoothing_mm", "end_straight_mm"):
        if not getattr(options, key) >= 0.0:
            raise ConfigError(f"resample.{key} must be >= 0 mm, got {getattr(options, key)}")
