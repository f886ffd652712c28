"""The fit measured against all of the path's own wall, and where the fit saw no wall (issue 29, item 1).

The kept-point figures (:mod:`softdesign.fitting.metrics`) are measured on the
points the fit used.  Near branches the selection drops much of a path's wall,
and the fit bridges the gap or holds it at the inscribed radius: figures on
the kept points then read well while the body is off the wall.  This module
measures the same true distances on the path's *own wall*: every surface
vertex whose foot lies within the path (not past an end) and which is not
nearer another path (the selection's ``other_branch`` and ``cap`` points left
out, its outliers kept), and reports the coverage:

* the fraction of the own wall the fit used;
* each *unseen stretch*: a run of knot intervals whose fitted points leave an
  empty angular sector wider than ``SEEN_GAP_RAD`` (the end prior's test), with
  where it is, its length, and how the body is made there (held at the
  inscribed radius by the end prior at an end, bridged by the fit inside).

Two flags, each with a warning: a stretch held at the inscribed radius longer
than one local diameter, and an all-wall p95 above ``ALL_WALL_P95_FRACTION``
of the path's median radius.  A stretch bridged inside the path (a branch's
mouth: no wall there to match) is listed, not flagged.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from softdesign.fitting.bspline_surface import RadiusSpline
from softdesign.fitting.closest import SearchStart, closest_with_part
from softdesign.fitting.end_prior import SEEN_GAP_RAD, largest_gap
from softdesign.fitting.mapping import Mapper, serial_map
from softdesign.fitting.metrics import (
    DISTANCE_SAMPLE_MAX,
    FitMetrics,
    measure_distances,
    summarize_distances,
    with_exact_max,
)
from softdesign.fitting.projection import PolarPoints
from softdesign.fitting.selection import REASONS, WallSelection
from softdesign.types import FloatArray, FramedCurve

#: The all-wall p95 above this fraction of the path's median radius is flagged (a body off the wall by a tenth
#: of the radius on one point in twenty is visibly not the vessel).
ALL_WALL_P95_FRACTION = 0.1
#: Seed of the sample the all-wall figures are measured on above DISTANCE_SAMPLE_MAX points (its own generator,
#: so the kept-point figures and the hold-out draw exactly as before).
ALL_WALL_SEED = 29
#: Flags, by name, as the fit summary carries them.
FLAG_LONG_STRETCH = "unseen_stretch_longer_than_diameter"
FLAG_P95 = "all_wall_p95_above_fraction"


@dataclass(frozen=True)
class WallCoverage:
    """All-wall figures, coverage and flags (JSON-ready through :meth:`as_dict`)."""

    metrics: FitMetrics
    own_points: int
    fitted_points: int
    radius_mm: float
    stretches: tuple[dict[str, Any], ...]
    flags: tuple[str, ...]
    warnings: tuple[str, ...]
    #: the all-wall figures outside ``spans_mm`` (None without local caps)
    outside: FitMetrics | None = None
    spans_mm: tuple[tuple[float, float], ...] = ()

    def as_dict(self) -> dict[str, Any]:
        """``all_wall`` distances (mm), ``coverage`` figures, ``flags`` and ``warnings``."""
        return {
            "all_wall": self.metrics.as_dict(),
            "coverage": {
                "own_wall_points": self.own_points,
                "fitted_points": self.fitted_points,
                "fraction": self.fitted_points / self.own_points if self.own_points else float("nan"),
                "radius_mm": self.radius_mm,
                "p95_fraction_limit": ALL_WALL_P95_FRACTION,
                "unseen_stretches": list(self.stretches),
            },
            "flags": list(self.flags),
            "warnings": list(self.warnings),
        } | ({} if self.outside is None else {"all_wall_outside_local_caps": {
            **self.outside.as_dict(), "spans_mm": [list(span) for span in self.spans_mm]}})


def own_wall(polar: PolarPoints, selection: WallSelection) -> np.ndarray:
    """(n,) bool: the path's own wall: foot within the path, neither another branch's wall nor a cap."""
    other, cap = 1 + REASONS.index("other_branch"), 1 + REASONS.index("cap")
    return (polar.end_side == 0) & (selection.reason != other) & (selection.reason != cap)


def measure_coverage(
    curve: FramedCurve,
    surface: RadiusSpline,
    polar: PolarPoints,
    selection: WallSelection,
    fitted: np.ndarray,
    interval_mm: float,
    reference: tuple[FloatArray, FloatArray] | None,
    held_ends: dict[str, Any],
    mapper: Mapper = serial_map,
    spans_mm: tuple[tuple[float, float], ...] = (),
    known: tuple[np.ndarray, FloatArray] | None = None,
    known_max: float | None = None,
) -> WallCoverage:
    """True distances of the own wall to the fitted surface, the coverage, the unseen stretches and the flags.

    Parameters
    ----------
    curve : the centerline at q = 1
    surface : the fitted rho(l, a)
    polar : every surface point projected on ``curve``
    selection : the selection's reasons
    fitted : (k,) indices into ``polar`` of the points the fit used
    interval_mm : the fit's knot interval along l, mm (the unseen test's cells)
    reference : normalized l (m,) and inscribed radius (m,) mm, or None (then the fitted points' rho)
    held_ends : the end prior's per-end figures (which ends are held at the inscribed radius)
    mapper : runs the distance blocks
    spans_mm : stretches (from, to), mm from the inlet, where local caps hold the body thinner on purpose: the
        all-wall figures are given outside them too, and the p95 flag judges those
    known : sorted indices into ``polar`` (m,) of fitted points already measured against ``surface`` (all of
        them, or a seeded uniform sample: the kept-point figures'), and their distances (m,) mm, which are used,
        not searched again (:func:`_own_wall_distances`); None: the own wall is measured afresh
    known_max : the largest distance of every fitted point (the kept-point figures' exact max, mm), used as the own
        wall's when the own wall is the fitted points and ``known`` their whole sample (then the same searches);
        None: found here
    """
    own = own_wall(polar, selection)
    nan = float("nan")
    measured, outside = FitMetrics(nan, nan, nan, nan, 0), None
    if own.any():
        if known is None:
            found = measure_distances(curve, surface, polar.subset(own), np.random.default_rng(ALL_WALL_SEED),
                                      mapper=mapper)
            measured, sample, distance = found.metrics, np.flatnonzero(own)[found.sample], found.distance
        else:
            measured, sample, distance = _own_wall_distances(curve, surface, polar, own, fitted, known, mapper,
                                                             known_max)
        if spans_mm:  # local caps hold the body off the wall on purpose there: judged outside them
            s = polar.l[sample] * curve.length
            away = ~np.any([(s >= lo) & (s <= hi) for lo, hi in spans_mm], axis=0)
            outside = summarize_distances(distance[away]) if away.any() else FitMetrics(nan, nan, nan, nan, 0)
    judged = measured if outside is None else outside
    kept = polar.subset(fitted)
    radius = float(np.median(reference[1] if reference is not None else kept.rho)) if len(kept) else float("nan")
    stretches = unseen_stretches(kept, curve.length, interval_mm, reference, held_ends)
    flags, warnings = [], []
    long = [s for s in stretches if s["length_mm"] > s["diameter_mm"] and s["held"]]
    if long:
        flags.append(FLAG_LONG_STRETCH)
        warnings += [
            f"no wall seen all round over {s['length_mm']:.1f} mm at {s['from_mm']:.1f}-{s['to_mm']:.1f} mm from the "
            f"inlet, longer than the local diameter {s['diameter_mm']:.1f} mm: the body there is {s['how']}, not "
            "matched to the wall (the report's fit section shows where)" for s in long]
    if judged.count and judged.p95_mm > ALL_WALL_P95_FRACTION * radius:
        flags.append(FLAG_P95)
        where = "" if outside is None else ", outside the fit.local_max_radius stretches,"
        warnings.append(
            f"against all of the path's own wall{where} ({int(own.sum())} vertices, {len(fitted) / own.sum():.0%} "
            f"of them fitted) the body's p95 distance is {judged.p95_mm:.3f} mm, above {ALL_WALL_P95_FRACTION:g} of "
            f"the radius {radius:.3f} mm (max {judged.max_mm:.3f} mm): the kept-point figures do not describe it")
    return WallCoverage(measured, int(own.sum()), int(len(fitted)), radius, tuple(stretches), tuple(flags),
                        tuple(warnings), outside, tuple(spans_mm))


def _own_wall_distances(
    curve: FramedCurve, surface: RadiusSpline, polar: PolarPoints, own: np.ndarray, fitted: np.ndarray,
    known: tuple[np.ndarray, FloatArray], mapper: Mapper, known_max: float | None = None,
) -> tuple[FitMetrics, np.ndarray, FloatArray]:
    """The all-wall figures from the fitted points' known distances and the searches of the other own points.

    Up to ``DISTANCE_SAMPLE_MAX`` own points, every one is measured (a known distance is the same search's
    result: the same number); above it, a stratified sample: the known points (a uniform sample of the fitted
    ones at rate r) and a seeded uniform draw at the same rate r of the own points the fit did not use, so every
    own point has the same chance r; the max is over every own point, as :func:`measure_distances` makes it.

    Returns
    -------
    metrics, the measured own points (sorted indices into ``polar``) and their distances, mm.
    """
    own_index = np.flatnonzero(own)
    order = np.argsort(known[0], kind="stable")  # the fit's points run along the path, not in input order
    known_index, known_distance = known[0][order], known[1][order]
    if len(own_index) <= DISTANCE_SAMPLE_MAX:
        sample = own_index
    else:
        unfitted = own.copy()
        unfitted[fitted] = False
        rate = len(known_index) / max(len(fitted), 1)
        candidates = np.flatnonzero(unfitted)
        drawn = np.random.default_rng(ALL_WALL_SEED).choice(candidates, size=round(rate * len(candidates)),
                                                            replace=False)
        chosen = np.zeros(len(own), bool)
        chosen[drawn] = True
        chosen[known_index[own[known_index]]] = True
        sample = np.flatnonzero(chosen)
    at = np.minimum(np.searchsorted(known_index, sample), max(len(known_index) - 1, 0))
    hit = known_index[at] == sample if len(known_index) else np.zeros(len(sample), bool)
    distance = np.empty(len(sample))
    distance[hit] = known_distance[at[hit]]
    if not hit.all():
        rest = polar.subset(sample[~hit])
        distance[~hit] = closest_with_part(curve, surface, rest.points, SearchStart(rest.l, rest.angle), mapper)[0]
    summary = summarize_distances(distance)
    if (known_max is not None and len(sample) < len(own_index) and np.array_equal(sample, known_index)
            and np.array_equal(own_index, np.sort(fitted))):
        # the own wall is the fitted points and the sample theirs: with_exact_max would bound and search the same
        # points left out of the same sample as the kept-point figures did, so their max is this one
        return replace(summary, max_mm=known_max, total=len(own_index)), sample, distance
    metrics = with_exact_max(curve, surface, polar.subset(own_index), np.searchsorted(own_index, sample), summary,
                             mapper)
    return metrics, sample, distance


def unseen_stretches(
    kept: PolarPoints, length_mm: float, interval_mm: float, reference: tuple[FloatArray, FloatArray] | None,
    held_ends: dict[str, Any],
) -> list[dict[str, Any]]:
    """Runs of knot intervals whose fitted points leave an empty sector wider than ``SEEN_GAP_RAD``, mm along the path.

    Each: ``from_mm``, ``to_mm``, ``length_mm``, ``diameter_mm`` (twice the radius at its middle: the
    inscribed one, else the median rho of the fitted points) and ``how`` the body is made there.
    """
    intervals = max(1, int(round(length_mm / interval_mm)))
    row = np.minimum((kept.l * intervals).astype(int), intervals - 1)
    order = np.argsort(row, kind="stable")
    bounds = np.searchsorted(row[order], np.arange(intervals + 1))
    unseen = np.array([largest_gap(kept.angle[order[bounds[k]:bounds[k + 1]]]) > SEEN_GAP_RAD
                       for k in range(intervals)])
    edges = np.diff(np.concatenate([[0], unseen.astype(int), [0]]))
    out = []
    for first, stop in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1), strict=True):
        lo, hi = first * length_mm / intervals, stop * length_mm / intervals
        middle = 0.5 * (lo + hi) / length_mm
        r = float(np.interp(middle, *reference)) if reference is not None else (
            float(np.median(kept.rho)) if len(kept) else float("nan"))
        end = "inlet" if first == 0 else ("outlet" if stop == intervals else None)
        held = end is not None and end in held_ends
        how = (f"held at the inscribed radius where no wall was seen near the {end}" if held
               else "bridged by the fit's smoothing (a branch's mouth, or wall dropped there)")
        out.append({"from_mm": lo, "to_mm": hi, "length_mm": hi - lo, "diameter_mm": 2.0 * r, "held": held,
                    "how": how, "end": end})
    return out
