"""Least-squares tensor-product spline rho(l, a), split into links by knot insertion.

``rho(l, a) = sum_ij C[i, j] B_i(l) P_j(a)`` with ``B_i`` cubic on an open knot
vector in normalized l (each link break a simple knot, so the surface is C2
across joints) and ``P_j`` periodic cubic with M equal angular intervals.

The coefficients minimize the mean squared radial residual plus a roughness
penalty, the thin-plate energy of rho over the tube's developed wall
(``s = L l`` and ``u = r a``, both mm, ``r`` the median rho of the data),
averaged over the wall's area and scaled by ``r^4``::

    E(C) = mean_k (rho_k - rho(l_k, a_k))^2
         + smoothing * r^4 / (2 pi L r) * iint (rho_ss^2 + 2 rho_su^2 + rho_uu^2) ds du

so ``smoothing`` is dimensionless, does not depend on the point count, and
scaling a whole case by a factor scales the fit by the same factor.  Linear
functions of s have no energy; the penalty bridges walls with no data (the
opening of a side branch), where the plain least-squares problem is singular.

Once solved on the whole path, each interior break is inserted DEGREE more
times: the knot vector then splits into one open vector per link that
reproduces the same surface, so adjacent links agree along the joint circle
in value and derivatives up to rounding.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from softdesign.errors import ConfigError, FitError, InputFitError
from softdesign.fitting import bspline_basis as bb
from softdesign.fitting.end_prior import EndPrior
from softdesign.fitting.mapping import Mapper, serial_map
from softdesign.fitting.projection import PolarPoints
from softdesign.fitting.surface_system import design_and_gram, design_matrix, roughness_matrix
from softdesign.types import FloatArray, IntArray

#: Defaults, from the VMTK aorta (see the note in tests/fitting/test_fit_aorta.py): knots every 1.5 mm
#: and 24 around (about 1.5 mesh edges each way), and the smallest smoothing that keeps the
#: fit across the other iliac's opening inside the range of the observed radii.
DEFAULT_KNOT_SPACING_MM = 1.5
DEFAULT_ANGULAR_INTERVALS = 24
DEFAULT_SMOOTHING = 1.0e-5
#: Angles per angular interval at which joint jumps are measured.
JUMP_SAMPLES_PER_INTERVAL = 8
#: A bin is surrounded by wall points when no empty angular sector is wider than this, rad.
SURROUND_GAP_RAD = np.pi
#: At least this fraction of the path's knot intervals must be surrounded.
MIN_SURROUNDED_FRACTION = 0.6


@dataclass(frozen=True)
class FitSettings:
    """The spline space and its penalty.

    Attributes
    ----------
    knot_spacing_mm : target knot interval along the centerline, mm (each link
        gets the nearest whole number of equal intervals, at least one)
    angular_intervals : M, knot intervals around the centerline (>= 4)
    smoothing : dimensionless weight of the roughness penalty (>= 0)
    breaks : link breaks in normalized l, from 0 to 1, strictly increasing
    prior : pseudo-observations where an end's wall is unseen (:mod:`softdesign.fitting.end_prior`),
        added to the least squares with their weights; None (or empty) for the plain fit
    """

    knot_spacing_mm: float = DEFAULT_KNOT_SPACING_MM
    angular_intervals: int = DEFAULT_ANGULAR_INTERVALS
    smoothing: float = DEFAULT_SMOOTHING
    breaks: tuple[float, ...] = (0.0, 1.0)
    prior: EndPrior | None = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        if not self.knot_spacing_mm > 0:
            raise ConfigError(f"fit.knot_spacing_mm must be > 0 mm, got {self.knot_spacing_mm}")
        if int(self.angular_intervals) != self.angular_intervals or self.angular_intervals < 4:
            raise ConfigError(f"fit.angular_intervals must be an integer >= 4, got {self.angular_intervals}")
        if not self.smoothing >= 0:
            raise ConfigError(f"fit.smoothing must be >= 0, got {self.smoothing}")
        b = np.asarray(self.breaks, float)
        if len(b) < 2 or b[0] != 0.0 or b[-1] != 1.0 or np.any(np.diff(b) <= 0):
            raise ConfigError(f"link breaks must rise strictly from 0 to 1 (normalized l), got {list(self.breaks)}")


@dataclass(frozen=True)
class RadiusSpline:
    """``rho(l, a)`` on ``[knots[3], knots[-4]]`` x periodic a, mm.

    Attributes
    ----------
    knots : (n + 4,) float, open knot vector in normalized l (of the whole path)
    coefficients : (n, M) float, mm
    """

    knots: FloatArray
    coefficients: FloatArray

    @property
    def angular_intervals(self) -> int:
        """M, the number of periodic basis functions around the centerline."""
        return self.coefficients.shape[1]

    @property
    def domain(self) -> tuple[float, float]:
        """The l range this spline covers."""
        return float(self.knots[bb.DEGREE]), float(self.knots[-bb.DEGREE - 1])

    def evaluate(self, l: npt.ArrayLike, a: npt.ArrayLike, dl: int = 0, da: int = 0) -> FloatArray:
        """``d^(dl+da) rho / dl^dl da^da`` at paired (l, a); l, a broadcast together; mm (per unit l, rad)."""
        l, a = np.broadcast_arrays(np.asarray(l, float), np.asarray(a, float))
        flat_l, flat_a = l.reshape(-1), a.reshape(-1)
        # each point's value is its own: cache-sized pieces, the same numbers
        pieces = [self._evaluate_flat(flat_l[r], flat_a[r], dl, da) for r in bb.chunks(len(flat_l), bb.BASIS_CHUNK)]
        return (pieces[0] if len(pieces) == 1 else np.concatenate(pieces)).reshape(l.shape)

    def _evaluate_flat(self, l: FloatArray, a: FloatArray, dl: int, da: int) -> FloatArray:
        il, vl = bb.open_local(self.knots, l, dl)
        ia, va = bb.periodic_local(self.angular_intervals, a, da)
        local = self.coefficients[il[:, :, None], ia[:, None, :]]
        return np.einsum("nr,ns,nrs->n", vl, va, local)

    def evaluate_with_slopes(self, l: npt.ArrayLike, a: npt.ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """rho, d rho / dl and d rho / da at paired (l, a) (n,), in one pass over the coefficients."""
        l, a = (np.asarray(v, float).reshape(-1) for v in np.broadcast_arrays(l, a))
        il, vl, dvl = bb.open_local_and_slope(self.knots, l)
        ia, va, dva = bb.periodic_local_and_slope(self.angular_intervals, a)
        local = self.coefficients[il[:, :, None], ia[:, None, :]]
        around = np.einsum("nrs,ns->nr", local, va)
        return (np.einsum("nr,nr->n", vl, around), np.einsum("nr,nr->n", dvl, around),
                np.einsum("nr,nrs,ns->n", vl, local, dva))

    def evaluate_grid(self, l: npt.ArrayLike, a: npt.ArrayLike, dl: int = 0, da: int = 0) -> FloatArray:
        """Values on the grid l (p,) x a (m,), returns (p, m), mm."""
        along = bb.open_local(self.knots, l, dl)
        return grid_from_local(self.coefficients, along, bb.periodic_local(self.angular_intervals, a, da))

    def to_arrays(self) -> dict[str, FloatArray]:
        """Plain arrays for ``np.savez``: ``knots`` and ``coefficients``."""
        return {"knots": self.knots.copy(), "coefficients": self.coefficients.copy()}

    @classmethod
    def from_arrays(cls, knots: npt.ArrayLike, coefficients: npt.ArrayLike) -> RadiusSpline:
        """The inverse of :meth:`to_arrays`."""
        return cls(np.array(knots, float), np.array(coefficients, float))


def grid_from_local(
    coefficients: FloatArray, along: tuple[IntArray, FloatArray], around: tuple[IntArray, FloatArray]
) -> FloatArray:
    """``sum_rs B_r(l_p) P_s(a_m) C[i_pr, j_ms]`` on the grid l (p,) x a (m,), (..., p, m).

    Parameters
    ----------
    coefficients : (..., n, M) float, C; leading axes stack surfaces on the same knots
    along : indices (p, DEGREE + 1) and values of the open basis at l, from :func:`bspline_basis.open_local`
    around : the same (m, DEGREE + 1) for the periodic basis at a, from :func:`bspline_basis.periodic_local`

    The products are added in ascending basis index, first around then along,
    starting from zero: the order of the sparse ``B (P C^T)^T`` this replaces,
    so the values are the same to the last bit.  Dense gathers of the DEGREE + 1
    local terms skip building sparse matrices, which cost most of a call.
    """
    rows_l, values_l = along
    order = np.argsort(around[0], axis=1, kind="stable")
    rows_a, values_a = np.take_along_axis(around[0], order, axis=1), np.take_along_axis(around[1], order, axis=1)
    lead = coefficients.shape[:-2]
    inner = np.zeros(lead + (coefficients.shape[-2], rows_a.shape[0]))  # (..., n, m): sum over the periodic basis
    for s in range(rows_a.shape[1]):
        inner += coefficients[..., rows_a[:, s]] * values_a[:, s]
    out = np.zeros(lead + (rows_l.shape[0], rows_a.shape[0]))
    for r in range(rows_l.shape[1]):
        out += values_l[:, r, None] * inner[..., rows_l[:, r], :]
    return out


@dataclass(frozen=True)
class SurfaceFit:
    """A fitted rho(l, a): the whole path, its links, and what the solve saw.

    Attributes
    ----------
    whole : the spline over [0, 1]
    links : one spline per link, domains ``[breaks[j], breaks[j + 1]]``
    joint_value_jump_mm : (J - 1,) max |rho_left - rho_right| along each joint circle
    joint_slope_jump : (J - 1,) max |d rho / ds| jump (mm per mm of arc) along each joint circle
    penalty_radius_mm : r, the length scale of the penalty (median rho of the data)
    radial_rms_mm : RMS of the radial residual (not the true distance: see metrics)
    point_count : number of points fitted
    """

    whole: RadiusSpline
    links: tuple[RadiusSpline, ...]
    joint_value_jump_mm: FloatArray
    joint_slope_jump: FloatArray
    penalty_radius_mm: float
    radial_rms_mm: float
    point_count: int


def intervals_per_link(length_mm: float, settings: FitSettings) -> list[int]:
    """Knot intervals in each link: the nearest whole number to link length / spacing, at least 1."""
    widths = np.diff(np.asarray(settings.breaks, float)) * length_mm
    return [max(1, int(round(w / settings.knot_spacing_mm))) for w in widths]


def fit_radius_surface(polar: PolarPoints, length_mm: float, settings: FitSettings) -> SurfaceFit:
    """Fit rho(l, a) to wall points by penalized least squares and split it into links.

    Parameters
    ----------
    polar : the kept wall points (l, angle, rho) on the path
    length_mm : arc length of the path, mm (sets the knot count and the penalty's s scale)
    settings : knot spacing, angular intervals, smoothing, link breaks

    Raises
    ------
    FitError
        Too few points; the points do not surround the path; smoothing is 0
        and some coefficients have no data; the solve is not finite.
    """
    check_surrounds(polar, length_mm, settings)
    knots = path_knots(length_mm, settings)
    design, gram = design_and_gram(knots, settings.angular_intervals, polar.l, polar.angle)
    if settings.smoothing == 0:
        _check_supported(design, knots, settings.angular_intervals, length_mm)
    scale = float(np.median(polar.rho))
    coef = _solve(gram, design.T @ polar.rho, len(polar), knots, scale, length_mm, settings)
    whole = RadiusSpline(knots, coef.reshape(-1, settings.angular_intervals))
    links = split_at_breaks(whole, settings.breaks)
    value_jump, slope_jump = joint_jumps(links, length_mm)
    residual = polar.rho - design @ coef
    return SurfaceFit(whole, links, value_jump, slope_jump, scale, float(np.sqrt(np.mean(residual**2))), len(polar))


def fold_solver(
    polar: PolarPoints, length_mm: float, settings: FitSettings, labels: np.ndarray,
    mapper: Mapper = serial_map,
) -> Callable[[int], RadiusSpline]:
    """``solve(k)``: the whole-path spline fitted to the points outside fold k (``labels != k``).

    The same penalized least squares as :func:`fit_radius_surface` (penalty scale from each
    training set's median rho), assembled once here: fold k's normal equations are those of every
    point minus the rows of fold k, equal to a fresh assembly up to rounding.  Each fold's rows
    ``A_k^T A_k`` and ``A_k^T rho_k`` are assembled by ``mapper`` (perhaps on other processes; a
    row of the design matrix is its point's own, so ``A_k`` is the whole design's rows of fold k
    to the bit), then summed here in fold order.  Each fold's solve is its own (the hold-out runs
    it with the fold's distances, perhaps on another process): the same spline whenever and
    wherever it is solved.
    """
    assembled, rows = fold_assembly(polar, length_mm, settings, labels)
    return fold_solver_from(polar, length_mm, settings, rows, mapper(assembled, rows))


def fold_assembly(polar: PolarPoints, length_mm: float, settings: FitSettings, labels: np.ndarray
                  ) -> tuple[Callable[[np.ndarray], tuple[sp.csc_matrix, FloatArray]], list[np.ndarray]]:
    """:func:`fold_solver`'s assembly as a task and its items: ``A_k^T A_k`` and ``A_k^T rho_k`` of each fold's
    rows (the items, in fold order), for any mapper (each fold's own)."""
    knots = path_knots(length_mm, settings)

    def assembled(r: np.ndarray) -> tuple[sp.csc_matrix, FloatArray]:
        design = design_matrix(knots, settings.angular_intervals, polar.l[r], polar.angle[r])
        return design.T @ design, design.T @ polar.rho[r]

    return assembled, [np.flatnonzero(labels == k) for k in range(int(labels.max()) + 1)]


def fold_solver_from(polar: PolarPoints, length_mm: float, settings: FitSettings, rows: list[np.ndarray],
                     parts: list[Any]) -> Callable[[int], RadiusSpline]:
    """:func:`fold_solver` from its assembly's results ``parts`` for the folds' ``rows`` (:func:`fold_assembly`)."""
    knots = path_knots(length_mm, settings)
    gram, moment = sum(p[0] for p in parts), sum(p[1] for p in parts)

    def solve(k: int) -> RadiusSpline:
        fold_gram, fold_moment = parts[k]
        train = np.ones(len(polar), bool)
        train[rows[k]] = False
        scale = float(np.median(polar.rho[train]))
        coef = _solve(gram - fold_gram, moment - fold_moment, int(train.sum()), knots, scale, length_mm, settings)
        return RadiusSpline(knots, coef.reshape(-1, settings.angular_intervals))

    return solve


def path_knots(length_mm: float, settings: FitSettings) -> FloatArray:
    """The open knot vector in l of the whole path: whole intervals per link, every break a knot."""
    return bb.open_knots(settings.breaks, intervals_per_link(length_mm, settings))


def _solve(gram, moment, count: int, knots: FloatArray, scale: float, length_mm: float, settings: FitSettings):
    """Coefficients minimizing ``|A c - rho|^2 / n + smoothing * c^T P c`` from ``A^T A`` and ``A^T rho``.

    With ``settings.prior``, its weighted pseudo-observations add ``sum_p w_p (rho_p - rho(l_p, a_p))^2 / n``.

    Raises
    ------
    FitError
        The system is singular (no penalty and coefficients without data).
    """
    normal = gram / count
    if settings.smoothing > 0:
        normal = normal + settings.smoothing * roughness_matrix(knots, settings.angular_intervals, scale / length_mm)
    rhs = moment / count
    prior = settings.prior
    if prior is not None and not prior.empty:
        pseudo = design_matrix(knots, settings.angular_intervals, prior.l, prior.angle)
        normal = normal + (pseudo.T @ sp.diags(prior.weight) @ pseudo) / count
        rhs = rhs + pseudo.T @ (prior.weight * prior.rho) / count
    coef = spla.spsolve(sp.csc_matrix(normal), rhs)
    if not np.all(np.isfinite(coef)):
        raise FitError(
            f"surface fit: the least-squares system is singular (fit.smoothing = {settings.smoothing}); "
            f"expected wall points all around the path; set fit.smoothing > 0 (default {DEFAULT_SMOOTHING:g})"
        )
    return coef


def split_at_breaks(whole: RadiusSpline, breaks: tuple[float, ...]) -> tuple[RadiusSpline, ...]:
    """One spline per link, by raising every interior break to multiplicity DEGREE + 1."""
    knots, coef = whole.knots, whole.coefficients
    for b in breaks[1:-1]:
        for _ in range(bb.DEGREE + 1 - int(np.count_nonzero(knots == b))):
            knots, coef = bb.insert_knot(knots, coef, b)
    links = []
    for b0, b1 in zip(breaks[:-1], breaks[1:], strict=True):
        first = int(np.flatnonzero(knots == b0)[0])
        last = int(np.flatnonzero(knots == b1)[0])
        links.append(RadiusSpline(knots[first : last + bb.DEGREE + 1].copy(), coef[first:last].copy()))
    return tuple(links)


def joint_jumps(links: tuple[RadiusSpline, ...], length_mm: float) -> tuple[FloatArray, FloatArray]:
    """Max |jump| of rho (mm) and of d rho / ds (mm/mm) along every joint circle."""
    if len(links) < 2:
        return np.zeros(0), np.zeros(0)
    count = JUMP_SAMPLES_PER_INTERVAL * links[0].angular_intervals
    angle = np.linspace(0.0, 2.0 * np.pi, count, endpoint=False)
    values, slopes = [], []
    for left, right in zip(links[:-1], links[1:], strict=True):
        joint = np.full(count, left.domain[1])
        values.append(np.max(np.abs(left.evaluate(joint, angle) - right.evaluate(joint, angle))))
        d = left.evaluate(joint, angle, dl=1) - right.evaluate(joint, angle, dl=1)
        slopes.append(np.max(np.abs(d)) / length_mm)
    return np.array(values), np.array(slopes)


def check_surrounds(polar: PolarPoints, length_mm: float, settings: FitSettings) -> None:
    """Raise FitError unless wall points surround most of the path.

    The path is cut into knot intervals; an interval is surrounded when its
    points leave no empty sector wider than ``SURROUND_GAP_RAD``.  A surface
    beside the path, or one that covers little of it, fails here instead of
    giving a fit that the penalty alone has invented.
    """
    intervals = max(1, int(round(length_mm / settings.knot_spacing_mm)))
    minimum = 4 * settings.angular_intervals
    if len(polar) < minimum:
        raise FitError(
            f"surface fit: {len(polar)} wall points kept, expected at least {minimum} "
            f"(4 per angular interval); check final.surface and final.path, or lower fit.angular_intervals"
        )
    bins = np.minimum((polar.l * intervals).astype(int), intervals - 1)
    # each bin's angles as one slice of the points sorted by bin (a mask per bin read every point once per bin)
    order = np.argsort(bins, kind="stable")
    edges = np.searchsorted(bins[order], np.arange(intervals + 1))
    gaps = np.array([_largest_gap(polar.angle[order[edges[k] : edges[k + 1]]]) for k in range(intervals)])
    surrounded = gaps <= SURROUND_GAP_RAD
    if surrounded.mean() < MIN_SURROUNDED_FRACTION:
        first = int(np.flatnonzero(~surrounded)[0])
        raise InputFitError(
            f"surface fit: the wall points surround only {surrounded.mean():.0%} of the path "
            f"(expected >= {MIN_SURROUNDED_FRACTION:.0%}); first gap at l = {first / intervals:.3f} "
            f"({first * length_mm / intervals:.1f} mm), widest empty sector {np.degrees(gaps[first]):.0f} deg; "
            "the surface does not enclose this centerline: check final.surface, final.path and units"
        )


def _largest_gap(angle: FloatArray) -> float:
    if len(angle) < 3:
        return 2.0 * np.pi
    a = np.sort(np.mod(angle, 2.0 * np.pi))
    return float(np.max(np.diff(np.append(a, a[0] + 2.0 * np.pi))))


def _check_supported(design: sp.csr_matrix, knots: FloatArray, intervals: int, length_mm: float) -> None:
    """Without a penalty, every coefficient needs data under its support."""
    weight = np.asarray(design.power(2).sum(axis=0)).ravel().reshape(-1, intervals)
    empty = np.flatnonzero((weight <= 0.0).any(axis=1))
    if empty.size:
        lo, hi = knots[empty[0]], knots[empty[-1] + bb.DEGREE + 1]
        raise FitError(
            f"surface fit: fit.smoothing is 0 and the wall has no points near l = {lo:.3f}..{hi:.3f} "
            f"({lo * length_mm:.1f}..{hi * length_mm:.1f} mm), so the least-squares system is singular; "
            f"set fit.smoothing > 0 (default {DEFAULT_SMOOTHING:g}) to bridge the gap"
        )
