"""The radius field rho(q, l, a) of the actuator, per link, and the self-folding check.

``rho(q, l, a) = (1 - q) rho0(l, a) + q rhof(l, a)``: rhof is the fitted wall
(q = 1), rho0 the insertion shape's radius (q = 0).  Both are splines on the
*same* knots, so rho(q) is one spline whose coefficients blend linearly, and
the C2 joints of the fit stay C2 at every q.  rho0 is, by default, the mean
of rhof around each l (an axially symmetric body, exact in the spline space
because every periodic basis function has the same integral), or a constant,
or another fitted surface on the same knots.

A tube ``c(l) + rho (cos a N + sin a B)`` folds through itself where
``rho * kappa_n >= 1``, kappa_n = the curvature vector's component along the
direction (cos a N + sin a B) (its inner side); :func:`check_self_folding`
measures the largest value on a dense grid.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from softdesign.errors import FitError, FoldError
from softdesign.fitting import bspline_basis as bb
from softdesign.fitting.bspline_surface import RadiusSpline, grid_from_local
from softdesign.fitting.radius_rows import SlopeRows, row_blocks
from softdesign.geometry.frames import FramedSpline
from softdesign.types import FloatArray, FramedCurve, IntArray

#: Grid spacing along the centerline for the folding check, mm.
FOLD_SPACING_MM = 0.1
#: rho * kappa_n the body radius offered as the fix of a fold brings the body to (the regularized backbone's
#: target, :data:`softdesign.geometry.backbone.TARGET_REACH`: room below 1 for the meshes' own curvature).
FOLD_FIX_REACH = 0.7
#: Angles per angular knot interval for the folding check.
FOLD_ANGLES_PER_INTERVAL = 8
#: Memory for the grids of rho0 and rhof a field keeps (:meth:`RadiusField.end_grids`), bytes: room
#: for the volume integral's rho and rho_l of a few bodies (2.6 MB on a 1M-triangle benchmark case,
#: 1248 Gauss nodes x 64 angles), without letting a long run of one-off grids pile up.
GRID_CACHE_BYTES = 32 * 2**20
#: Memory for the bases along l a field keeps (:meth:`RadiusField.along_bases`), bytes: the finest
#: stretch grid of the 1M-triangle benchmark case needs 0.2 MB (1900 rows).
BASIS_CACHE_BYTES = 8 * 2**20


def axisymmetric(spline: RadiusSpline) -> RadiusSpline:
    """The mean of rho over a at each l, as a spline on the same knots (exact)."""
    mean = spline.coefficients.mean(axis=1, keepdims=True)
    return RadiusSpline(spline.knots.copy(), np.repeat(mean, spline.angular_intervals, axis=1))


def capped(spline: RadiusSpline, radius_mm: float) -> RadiusSpline:
    """rho held at most ``radius_mm``: the coefficients clamped, so the spline stays C2, below both rho and the cap.

    B-splines are non-negative and sum to one, so clamping the coefficients bounds the values by the cap,
    and by the unclamped spline; within a knot interval of where rho crosses the cap it is a little lower.
    """
    return RadiusSpline(spline.knots.copy(), np.minimum(spline.coefficients, float(radius_mm)))


def constant_like(spline: RadiusSpline, radius_mm: float) -> RadiusSpline:
    """rho = radius_mm everywhere on the knots of ``spline`` (B-splines sum to one)."""
    if not radius_mm > 0:
        raise FitError(f"initial radius: initial.radius_mm must be > 0 mm, got {radius_mm}")
    return RadiusSpline(spline.knots.copy(), np.full_like(spline.coefficients, float(radius_mm)))


@dataclass(frozen=True)
class FoldReport:
    """Largest rho * kappa_n over the tube, where it occurs, and the smallest rho.

    Attributes
    ----------
    max_rho_kappa : dimensionless; the tube folds where it reaches 1
    l : normalized l of the maximum
    arc_mm : the same place in mm of arc length
    angle : rad, angle of the maximum (from N towards B)
    min_rho_mm : smallest radius on the grid, mm
    """

    max_rho_kappa: float
    l: float
    arc_mm: float
    angle: float
    min_rho_mm: float


@dataclass(frozen=True)
class RadiusField:
    """Per-link rho0 and rhof on shared knots, with ``breaks`` (J + 1,) in normalized l."""

    breaks: FloatArray
    final: tuple[RadiusSpline, ...]
    initial: tuple[RadiusSpline, ...]

    def __post_init__(self) -> None:
        if not (len(self.final) == len(self.initial) == len(self.breaks) - 1):
            raise FitError(
                f"radius field: expected {len(self.breaks) - 1} links for breaks {list(self.breaks)}, "
                f"got {len(self.final)} final and {len(self.initial)} initial splines"
            )
        for j, (f, i) in enumerate(zip(self.final, self.initial, strict=True)):
            if f.knots.shape != i.knots.shape or not np.array_equal(f.knots, i.knots) or (
                f.coefficients.shape != i.coefficients.shape
            ):
                raise FitError(
                    f"radius field: link {j}: the initial surface's knots differ from the final's; "
                    "fit the initial surface with the same fit settings and link breaks"
                )

    @classmethod
    def from_links(cls, breaks: npt.ArrayLike, final: tuple[RadiusSpline, ...], radius_mm: float | None = None):
        """rho0 = the constant ``radius_mm``, or (None) the axially symmetric mean of each final link."""
        initial = tuple(axisymmetric(s) if radius_mm is None else constant_like(s, radius_mm) for s in final)
        return cls(np.array(breaks, float), tuple(final), initial)

    def link_spline(self, link: int, q: float) -> RadiusSpline:
        """rho(q) of one link as a spline: coefficients ``(1 - q) C0 + q Cf``."""
        f, i = self.final[link], self.initial[link]
        return RadiusSpline(f.knots.copy(), (1.0 - q) * i.coefficients + q * f.coefficients)

    def link_of(self, l: npt.ArrayLike) -> np.ndarray:
        """Index of the link containing each l (a joint belongs to the link after it; l = 1 to the last)."""
        return np.clip(np.searchsorted(self.breaks, np.asarray(l, float), side="right") - 1, 0, len(self.final) - 1)

    def evaluate_grid(self, q: float, l: npt.ArrayLike, a: npt.ArrayLike, dl: int = 0, da: int = 0) -> FloatArray:
        """rho(q) (or its derivatives) on the grid l (p,) x a (m,), (p, m) mm; each l in its own link.

        The same numbers as ``link_spline(j, q).evaluate_grid`` on each link.
        """
        blended = [
            ((1.0 - q) * i.coefficients + q * f.coefficients)[None]
            for f, i in zip(self.final, self.initial, strict=True)
        ]
        return self._link_grids(blended, l, a, dl, da)[0]  # blended as link_spline blends them

    def along_bases(self, l: npt.ArrayLike, slopes: bool = True
                    ) -> tuple[tuple[int, IntArray, IntArray, FloatArray, FloatArray], ...]:
        """Per link present in l (n,): its rows of l (ascending), and the open basis along l at them.

        Each item is ``(link, rows, indices (r, DEGREE + 1), values, slopes)`` (``slopes`` the values
        again with ``slopes=False``), read-only.  The field keeps the last ones it was asked for (keyed
        on the values of l; least recently used out past ``BASIS_CACHE_BYTES``): the grids of every q
        are the same, and so are their bases.
        """
        l = np.ascontiguousarray(l, float).reshape(-1)
        key = (l.tobytes(), bool(slopes))
        cache = self._cache("_basis_cache")
        bases = cache.pop(key, None)  # put back last: the dict runs from least to most recently used
        if bases is None:
            owner = self.link_of(l)
            found = []
            for j in np.unique(owner):
                rows = np.flatnonzero(owner == j)
                if slopes:
                    index, values, slopes_l = bb.open_local_and_slope(self.final[j].knots, l[rows])
                else:
                    index, values = bb.open_local(self.final[j].knots, l[rows])
                    slopes_l = values
                for array in (rows, index, values, slopes_l):
                    array.setflags(write=False)
                found.append((int(j), rows, index, values, slopes_l))
            bases = tuple(found)
        cache[key] = bases
        _trim(cache, BASIS_CACHE_BYTES, lambda b: sum(a.nbytes for item in b for a in item[1:]), keep=1)
        return bases

    def end_grids(self, l: npt.ArrayLike, a: npt.ArrayLike, dl: int = 0, da: int = 0) -> tuple[FloatArray, FloatArray]:
        """rho0 and rhof (or their derivatives) on the grid l (p,) x a (m,), each (p, m) mm, read-only.

        The field keeps the grids it was last asked for (keyed on the values of
        l and a and the orders; the least recently used go first past
        ``GRID_CACHE_BYTES``), so a caller that evaluates every q at the same
        nodes, like the volume integral, builds them once.
        """
        l = np.ascontiguousarray(l, float).reshape(-1)
        a = np.ascontiguousarray(a, float).reshape(-1)
        key = (l.tobytes(), a.tobytes(), int(dl), int(da))
        cache = self._cache("_grid_cache")
        grids = cache.pop(key, None)  # put back last: the dict runs from least to most recently used
        if grids is None:
            ends = [np.stack([i.coefficients, f.coefficients]) for f, i in zip(self.final, self.initial, strict=True)]
            grids = self._link_grids(ends, l, a, dl, da)
            grids.setflags(write=False)
        cache[key] = grids
        _trim(cache, GRID_CACHE_BYTES, lambda g: g.nbytes, keep=0)
        return grids[0], grids[1]

    def blend_grid(self, q: float, l: npt.ArrayLike, a: npt.ArrayLike, dl: int = 0, da: int = 0) -> FloatArray:
        """rho(q) on the grid as ``(1 - q) rho0 + q rhof`` of :meth:`end_grids`, (p, m) mm.

        Equals :meth:`evaluate_grid` up to rounding (it blends values, not
        coefficients); always the same bits for the same arguments, cached or not.
        """
        initial, final = self.end_grids(l, a, dl, da)
        return (1.0 - q) * initial + q * final

    def _link_grids(self, stacks: list[FloatArray], l: npt.ArrayLike, a: npt.ArrayLike, dl: int, da: int) -> FloatArray:
        """Grids (k, p, m) of stacked coefficients, ``stacks[j]`` (k, n, M) on link j; each l in its own link."""
        l = np.asarray(l, float).reshape(-1)
        out = np.empty((stacks[0].shape[0], len(l), np.size(a)))
        owner = self.link_of(l)
        around: dict[int, tuple[IntArray, FloatArray]] = {}  # the angular basis, once for all links
        for j in np.unique(owner):
            rows = owner == j
            knots, m = self.final[j].knots, self.final[j].angular_intervals
            if m not in around:
                around[m] = bb.periodic_local(m, a, da)
            out[:, rows] = grid_from_local(stacks[j], bb.open_local(knots, l[rows], dl), around[m])
        return out

    def _cache(self, name: str) -> dict[Any, Any]:
        """The field's cache ``name`` (a dict, least recently used first), made on first use; not part of its value."""
        cache = self.__dict__.get(name)
        if cache is None:
            cache = {}
            object.__setattr__(self, name, cache)  # frozen: the cache is not part of the value
        return cache

    def __getstate__(self) -> dict[str, object]:
        # pickles carry the field, not the grids cached from it
        return {k: v for k, v in self.__dict__.items() if k not in ("_grid_cache", "_basis_cache", "_fold_cache")}

    def keep_fold(self, curve: FramedCurve, q: float, report: FoldReport) -> None:
        """Keep :func:`fold_margin`'s ``report`` of this field around ``curve`` (the very object) at q, for
        :func:`known_fold_margin` (the fit's morph check reports the q values a later stage asks for again)."""
        self._cache("_fold_cache")[float(q)] = (curve, report)

    def evaluate_pairs(self, q: float, l: npt.ArrayLike, a: npt.ArrayLike) -> FloatArray:
        """rho(q) at paired points (l_i, a_i), (n,) mm; each l in its own link."""
        l, a = (np.asarray(v, float).reshape(-1) for v in (l, a))
        out = np.empty(len(l))
        owner = self.link_of(l)
        for j in np.unique(owner):
            rows = owner == j
            out[rows] = self.link_spline(int(j), q).evaluate(l[rows], a[rows])
        return out

    def to_arrays(self) -> dict[str, FloatArray]:
        """Plain arrays for ``np.savez``: ``breaks`` and ``link{j}_knots|final|initial``."""
        out = {"breaks": np.array(self.breaks, float)}
        for j, (f, i) in enumerate(zip(self.final, self.initial, strict=True)):
            out[f"link{j}_knots"] = f.knots.copy()
            out[f"link{j}_final"] = f.coefficients.copy()
            out[f"link{j}_initial"] = i.coefficients.copy()
        return out

    @classmethod
    def from_arrays(cls, arrays) -> RadiusField:
        """The inverse of :meth:`to_arrays` (accepts the mapping ``np.load`` returns)."""
        breaks = np.array(arrays["breaks"], float)
        count = len(breaks) - 1
        final = tuple(RadiusSpline.from_arrays(arrays[f"link{j}_knots"], arrays[f"link{j}_final"])
                      for j in range(count))
        initial = tuple(RadiusSpline.from_arrays(arrays[f"link{j}_knots"], arrays[f"link{j}_initial"])
                        for j in range(count))
        return cls(breaks, final, initial)


def fold_margin(curve: FramedCurve, field: RadiusField, q: float = 1.0) -> FoldReport:
    """Largest ``rho(q) * kappa_n`` on a dense grid over the tube around ``curve``.

    Parameters
    ----------
    curve : the centerline at this q (c(q, .) with its frames); l normalized
    field : the radius field
    q : blend parameter in [0, 1]
    """
    l, a, k_n, k_b = fold_grid(curve, field)
    cos, sin = np.cos(a)[None, :], np.sin(a)[None, :]
    rows = SlopeRows(field, q, l, a, slopes=False)
    best, at, smallest = -np.inf, (0, 0), []
    for block in row_blocks(len(l), len(a)):  # the largest first in row-major order, as np.argmax over the whole grid
        rho = rows.values(block.start, block.stop)
        product = rho * (k_n[block, None] * cos + k_b[block, None] * sin)
        i, j = np.unravel_index(int(np.argmax(product)), product.shape)
        if block.start == 0 or (not np.isnan(best) and (np.isnan(product[i, j]) or product[i, j] > best)):
            best, at = float(product[i, j]), (block.start + int(i), int(j))
        smallest.append(rho.min())
    row, column = at
    return FoldReport(best, float(l[row]), float(l[row] * curve.length), float(a[column]), float(np.min(smallest)))


def known_fold_margin(curve: FramedCurve, field: RadiusField, q: float) -> FoldReport:
    """:func:`fold_margin`, or the report :meth:`RadiusField.keep_fold` kept for the same curve object at q.

    The same inputs give the same report: kept or computed, the same numbers.
    """
    kept = field.__dict__.get("_fold_cache", {}).get(float(q))
    if kept is not None and kept[0] is curve:
        return kept[1]
    return fold_margin(curve, field, q)


def check_self_folding(curve: FramedCurve, field: RadiusField, q: float = 1.0, limit: float = 1.0) -> FoldReport:
    """:func:`fold_margin`, raising FitError when rho * kappa_n reaches ``limit`` or rho <= 0.

    Raises
    ------
    FoldError
        The tube folds: naming q, the place (l, mm, angle), the turn, and the body radius that fits there
        (``fit.max_radius_mm``, from :func:`fold_fix_radius`).
    FitError
        rho <= 0 somewhere.
    """
    report = fold_margin(curve, field, q)
    if report.min_rho_mm <= 0.0:
        raise FitError(
            f"radius field at q = {q:g}: rho reaches {report.min_rho_mm:.3g} mm, expected > 0 everywhere; "
            "raise fit.smoothing, or check the wall points near the path's ends"
        )
    if report.max_rho_kappa >= limit:
        kappa = float(curve_curvature(curve, np.array([report.l]))[0])
        rho = float(field.evaluate_pairs(q, [report.l], [report.angle])[0])
        fix = fold_fix_radius(curve, field, q)
        raise FoldError(
            f"radius field at q = {q:g}: the tube folds through itself: rho * kappa = {report.max_rho_kappa:.3f} "
            f"(expected < {limit:g}) at l = {report.l:.4f} ({report.arc_mm:.1f} mm from the inlet), "
            f"angle {np.degrees(report.angle):.0f} deg: the path turns there with a radius of curvature of "
            f"{1.0 / kappa:.3f} mm, tighter than the body is wide (rho {rho:.3f} mm); a body of radius at most "
            f"{fix:.2f} mm makes rho * kappa <= {FOLD_FIX_REACH:g} wherever it now exceeds it: set "
            f"fit.max_radius_mm: {fix:.2f} (the body is held at most that wide along the whole path; "
            "export.offset_mm cannot, it is taken along the folded body's normals)"
        )
    return report


def curve_curvature(curve: FramedCurve, l: FloatArray) -> FloatArray:
    """kappa = |c' x c''| / |c'|^3 at normalized l (n,), 1/mm, for any framed curve."""
    d1, d2 = curve.derivative(l, 1), curve.derivative(l, 2)
    return np.linalg.norm(np.cross(d1, d2), axis=1) / np.linalg.norm(d1, axis=1) ** 3


def fold_fix_radius(curve: FramedCurve, field: RadiusField, q: float = 1.0, reach: float = FOLD_FIX_REACH) -> float:
    """The largest body radius (a cap on rho, mm) with which rho * kappa_n <= ``reach`` wherever it now exceeds it.

    The least ``reach / kappa_n`` over the grid points of :func:`fold_margin` where ``rho * kappa_n > reach``
    (inf where none): held at most that, the body's rho * kappa_n stays at most ``reach`` there, and no larger
    elsewhere, as :func:`capped` never raises rho.  Rounded down to 0.01 mm.
    """
    l, a, k_n_row, k_b_row = fold_grid(curve, field)
    k_n = k_n_row[:, None] * np.cos(a)[None, :] + k_b_row[:, None] * np.sin(a)[None, :]
    rho = field.evaluate_grid(q, l, a)
    over = rho * k_n > reach
    if not over.any():
        return float("inf")
    return float(np.floor(100.0 * np.min(reach / k_n[over]) + 1e-9) / 100.0)  # 1e-9: 13.9999999 is 14.00


def fold_grid(curve: FramedCurve, field: RadiusField) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """The fold checks' grid (l every FOLD_SPACING_MM, FOLD_ANGLES_PER_INTERVAL angles per interval) and the
    curvature vector's components along each l's N and B, 1/mm (l and the components read-only: a
    :class:`~softdesign.geometry.frames.FramedSpline` keeps them for the next check of the same curve)."""
    count = max(int(np.ceil(curve.length / FOLD_SPACING_MM)), 16) + 1
    a = np.linspace(0.0, 2.0 * np.pi, FOLD_ANGLES_PER_INTERVAL * field.final[0].angular_intervals, endpoint=False)

    def along() -> tuple[FloatArray, FloatArray, FloatArray]:
        l = np.linspace(0.0, 1.0, count)
        d1, d2, frames = curve.derivative(l, 1), curve.derivative(l, 2), curve.frames(l)
        speed2 = np.einsum("ni,ni->n", d1, d1)
        tangent = d1 / np.sqrt(speed2)[:, None]
        kvec = (d2 - np.einsum("ni,ni->n", d2, tangent)[:, None] * tangent) / speed2[:, None]
        out = l, np.einsum("ni,ni->n", kvec, frames[:, :, 0]), np.einsum("ni,ni->n", kvec, frames[:, :, 1])
        for array in out:
            array.setflags(write=False)
        return out

    # the curve's part is the same for every field: kept on a FramedSpline (the blend's look at the body and
    # the fit each check the same curves of the morph), the same numbers
    l, k_n, k_b = curve.kept(("fold_grid", count), along) if isinstance(curve, FramedSpline) else along()
    return l, a, k_n, k_b


def _trim(cache: dict[Any, Any], limit: int, size: Callable[[Any], int], keep: int) -> None:
    """Drop ``cache``'s least recently used entries while they take more than ``limit`` bytes and more than
    ``keep`` are left."""
    while len(cache) > keep and sum(size(value) for value in cache.values()) > limit:
        cache.pop(next(iter(cache)))
