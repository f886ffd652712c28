"""Extremes of the skin's principal stretches over a body, converged on a grid, and over the whole morph.

Grid
    l: ``ceil(L / spacing)`` equal steps in normalized l with every link joint
    added; a: ``angles`` equal steps from 0.  Starting from
    ``START_SPACING_MM`` and ``START_ANGLES_PER_INTERVAL`` per angular knot
    interval, the grid is halved both ways until the largest and smallest
    stretch change by less than ``STRETCH_TOL`` (at most ``MAX_REFINEMENTS``
    times); the grid, its point count and the last change are reported.
Morph
    The extremes over q in [0, 1] (the linear blend shortens the middle, so
    they need not sit at an exported q): ``Q_SAMPLES`` equally spaced q, then
    a bounded scalar search between the neighbours of the best sample, to
    ``Q_XTOL`` in q, on the converged grid.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt
from scipy.optimize import minimize_scalar

from softdesign.fitting.strain import principal_stretches
from softdesign.types import FloatArray

#: Change of the extreme stretches between two grids at which they count as converged (dimensionless).
STRETCH_TOL = 1e-4
#: First grid: l step (mm of the final length) and angles per angular knot interval.
START_SPACING_MM = 0.5
START_ANGLES_PER_INTERVAL = 4
#: Largest number of halvings of the grid.
MAX_REFINEMENTS = 4
#: Most grid points evaluated at once (bounds memory: ~10 arrays of this many float64).
MAX_GRID_POINTS = 2_000_000
#: q samples of the morph search and the bounded search's tolerance in q.
Q_SAMPLES = 21
Q_XTOL = 1e-3

#: (l (p,), a (m,)) -> metric (p, m, 3) of the surface at one q.
MetricAt = Callable[[FloatArray, FloatArray], FloatArray]


@dataclass(frozen=True)
class Grid:
    """An (l, a) grid: ``spacing_mm`` along, ``angles`` around; ``l`` (p,) and ``a`` (m,)."""

    spacing_mm: float
    angles: int
    l: FloatArray
    a: FloatArray

    @property
    def points(self) -> int:
        """Number of grid points."""
        return len(self.l) * len(self.a)


def make_grid(length_mm: float, breaks: npt.ArrayLike, spacing_mm: float, angles: int,
              span: tuple[float, float] = (0.0, 1.0)) -> Grid:
    """Equal steps of about ``spacing_mm`` in l over ``span``, every joint inside it added, ``angles`` around."""
    lo, hi = span
    count = max(2, math.ceil((hi - lo) * length_mm / spacing_mm)) + 1
    b = np.asarray(breaks, float)
    l = np.unique(np.concatenate([np.linspace(lo, hi, count), b[(b > lo) & (b < hi)]]))
    return Grid(spacing_mm, angles, l, 2.0 * np.pi * np.arange(angles) / angles)


@dataclass(frozen=True)
class Extreme:
    """One extreme stretch and where: link index, normalized l, angle (rad), and which principal stretch."""

    value: float
    link: int
    l: float
    a: float

    def as_dict(self) -> dict[str, float | int]:
        """JSON-ready, the angle in degrees."""
        return {"link": self.link, "l": self.l, "angle_deg": float(np.degrees(self.a))}


@dataclass(frozen=True)
class StretchExtremes:
    """Largest lambda1 and smallest lambda2 over the surface, overall and per link, with the grid used.

    ``per_link`` holds (max, min) per link; ``change`` the last refinement's change of the extremes.
    """

    maximum: Extreme
    minimum: Extreme
    per_link: tuple[tuple[float, float], ...]
    grid: Grid
    change: float = 0.0
    converged: bool = True
    history: tuple[tuple[int, float, float], ...] = field(default=())


def extremes_on(grid: Grid, rest: MetricAt, deformed: MetricAt, breaks: npt.ArrayLike) -> StretchExtremes:
    """The extremes of the principal stretches on ``grid``, per link (a joint belongs to the link after it)."""
    lam1, lam2 = principal_stretches(rest(grid.l, grid.a), deformed(grid.l, grid.a))
    b = np.asarray(breaks, float)
    owner = np.clip(np.searchsorted(b, grid.l, side="right") - 1, 0, len(b) - 2)
    i, k = np.unravel_index(int(np.argmax(lam1)), lam1.shape)
    j, m = np.unravel_index(int(np.argmin(lam2)), lam2.shape)
    if np.all(owner[1:] >= owner[:-1]):  # l ascending (as make_grid makes it): each link's rows are one slice
        ends = np.searchsorted(owner, np.arange(len(b)))
        rows = [slice(int(lo), int(hi)) if hi > lo else None for lo, hi in zip(ends[:-1], ends[1:], strict=True)]
    else:
        rows = [owner == n if np.any(owner == n) else None for n in range(len(b) - 1)]
    per_link = tuple((float(lam1[r].max()), float(lam2[r].min())) if r is not None else (1.0, 1.0) for r in rows)
    return StretchExtremes(
        Extreme(float(lam1[i, k]), int(owner[i]), float(grid.l[i]), float(grid.a[k])),
        Extreme(float(lam2[j, m]), int(owner[j]), float(grid.l[j]), float(grid.a[m])),
        per_link, grid,
    )


def converged_extremes(rest: MetricAt, deformed: MetricAt, length_mm: float, breaks: npt.ArrayLike,
                       angular_intervals: int, span: tuple[float, float] = (0.0, 1.0),
                       start: tuple[float, int] | None = None, first: StretchExtremes | None = None
                       ) -> StretchExtremes:
    """:func:`extremes_on` on grids halved until the extremes move by less than ``STRETCH_TOL``.

    ``start`` (spacing_mm, angles) replaces the first grid (e.g. one already found converged at another q).
    ``first``: :func:`extremes_on` of the same metrics already computed, used when on the first grid
    (e.g. the morph search's sample at this q); on another grid it is ignored.
    """
    spacing, angles = start or (START_SPACING_MM, START_ANGLES_PER_INTERVAL * angular_intervals)
    grid = make_grid(length_mm, breaks, spacing, angles, span)
    if first is not None and _same_grid(first.grid, grid):
        current = first
    else:
        current = extremes_on(grid, rest, deformed, breaks)
    history = [(current.grid.points, current.maximum.value, current.minimum.value)]
    change = math.inf
    for _ in range(MAX_REFINEMENTS):
        finer = make_grid(length_mm, breaks, current.grid.spacing_mm / 2, current.grid.angles * 2, span)
        if finer.points > MAX_GRID_POINTS:
            break
        nxt = extremes_on(finer, rest, deformed, breaks)
        change = max(abs(nxt.maximum.value - current.maximum.value), abs(nxt.minimum.value - current.minimum.value))
        current = nxt
        history.append((finer.points, nxt.maximum.value, nxt.minimum.value))
        if change < STRETCH_TOL:
            break
    return StretchExtremes(current.maximum, current.minimum, current.per_link, current.grid, float(change),
                           bool(change < STRETCH_TOL), tuple(history))


def _same_grid(a: Grid, b: Grid) -> bool:
    return a.spacing_mm == b.spacing_mm and a.angles == b.angles and np.array_equal(a.l, b.l) and np.array_equal(
        a.a, b.a)


@dataclass(frozen=True)
class MorphExtreme:
    """The extreme of one stretch over q in [0, 1]: its value, the q, and where on the body."""

    value: float
    q: float
    where: Extreme


def morph_samples() -> list[float]:
    """The q values :func:`search_morph` samples first (a caller may compute them ahead, e.g. in parallel)."""
    return [float(q) for q in np.linspace(0.0, 1.0, Q_SAMPLES)]


def search_morph(extremes_at: Callable[[float], StretchExtremes]) -> tuple[MorphExtreme, MorphExtreme]:
    """Largest lambda1 and smallest lambda2 over q in [0, 1]: samples, then a bounded search near the best.

    Accuracy: the bounded search stops within ``Q_XTOL`` of a local optimum in
    q, bracketed by the neighbours of the best of ``Q_SAMPLES`` samples; a
    second, narrower optimum between samples can be missed.
    """
    qs = np.array(morph_samples())
    found = [extremes_at(float(q)) for q in qs]
    out = []
    for sign, pick in ((-1.0, lambda e: e.maximum), (1.0, lambda e: e.minimum)):
        values = np.array([sign * pick(e).value for e in found])
        best = int(np.argmin(values))
        q_best, e_best = float(qs[best]), pick(found[best])
        lo, hi = qs[max(best - 1, 0)], qs[min(best + 1, len(qs) - 1)]
        result = minimize_scalar(lambda q, s=sign, p=pick: s * p(extremes_at(float(q))).value, bounds=(lo, hi),
                                 method="bounded", options={"xatol": Q_XTOL})
        if result.fun < values[best]:
            q_best, e_best = float(result.x), pick(extremes_at(float(result.x)))
        out.append(MorphExtreme(e_best.value, q_best, e_best))
    return out[0], out[1]
