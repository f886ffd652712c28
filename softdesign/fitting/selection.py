"""Which surface points are the selected path's wall, with the count of every reason to drop one.

Each point is dropped for the first reason that applies, in this order:

``other_branch``
    its nearest point on the centerline network lies on another polyline,
    off the trunk that polyline shares with the path.  Distances are to the
    nearest point of each polyline's segments, so a foot point beyond a
    polyline's end is clamped to that end (without the clamp the far dome of
    the other iliac looks close to the path's extension and is kept).
``cap``
    its foot point on the path is at, or beyond, an end of the path (within
    ``end_margin_mm``).  VMTK caps are rounded domes that meet the wall at a
    shallow angle, so no crease-angle rule finds them; every dome point lies
    past the end of the centerline it caps.  A flat cap that the (smoothed)
    centerline reaches or runs through has its points' feet inside the path
    instead, each (p - c) square to T like a wall point's: what gives its
    hub and rings away is that they lie inside the wall beside them.  So,
    within ``cap_zone_radii`` reference radii of an end, a point is a cap
    point too when its rho is below ``cap_inner_fraction`` times the median
    rho of the points in the same angular sector over the next such length.
``outlier``
    rho is above ``outlier_factor`` times the reference radius, or below the
    reference divided by it: the ``MaximumInscribedSphereRadius``
    interpolated at the foot point, or, without it, the median rho of the
    kept points within ``median_window_mm`` of arc length.  (A wall point
    never lies near the centerline: one there leaves residuals of about the
    radius and drags the fit with it.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from softdesign.errors import ConfigError, InputDataError
from softdesign.fitting.projection import PolarPoints, project_points
from softdesign.types import FloatArray, FramedCurve, Points

REASONS = ("other_branch", "cap", "outlier")
#: Angular sectors in which the wall beside an end zone is measured (22.5 degrees each: an elliptical
#: section's radius changes little across one).
CAP_SECTORS = 16
#: Segments first tried per point in the point-to-polyline distance (a wall point's nearest
#: segment is among its ~2 sqrt(radius / segment length) nearest midpoints: 16 covers 10 mm at 0.2 mm).
_FIRST_K = 16
#: Point-segment pairs per chunk of that distance (bounds its memory to ~100 MB).
_CHUNK_ENTRIES = 1 << 20


@dataclass(frozen=True)
class SelectionSettings:
    """Thresholds of the point selection.

    Attributes
    ----------
    outlier_factor : rho above this many times the reference radius, or below it divided by this,
        is an outlier (> 1)
    median_window_mm : arc-length window of the local median rho, mm (used without radii)
    end_margin_mm : foot points this close to an end count as cap points, mm (>= 0)
    shared_tol_mm : another polyline's points this close to the path are shared trunk, mm
    cap_zone_radii : length of each end zone, in reference radii at that end (> 0)
    cap_inner_fraction : in an end zone, rho below this fraction of the wall beside it is a cap (0..1)
    """

    # cap_inner_fraction: on the VMTK aorta (both surfaces) every wall point within a radius of an end
    # keeps rho above 0.83 of the wall beside it; a flat cap's hub and rings inside 3/4 of it go.
    outlier_factor: float = 2.0
    median_window_mm: float = 5.0
    end_margin_mm: float = 0.0
    shared_tol_mm: float = 0.05
    cap_zone_radii: float = 1.0
    cap_inner_fraction: float = 0.75

    def __post_init__(self) -> None:
        if not self.outlier_factor > 1.0:
            raise ConfigError(f"fit.outlier_factor must be > 1, got {self.outlier_factor}")
        if not (self.cap_zone_radii > 0 and 0 < self.cap_inner_fraction < 1):
            raise ConfigError(
                "selection: cap_zone_radii must be > 0 and cap_inner_fraction in (0, 1), got "
                f"{self.cap_zone_radii}, {self.cap_inner_fraction}"
            )
        if not (self.median_window_mm > 0 and self.end_margin_mm >= 0 and self.shared_tol_mm >= 0):
            raise ConfigError(
                "selection: median_window_mm must be > 0 and end_margin_mm, shared_tol_mm >= 0, got "
                f"{self.median_window_mm}, {self.end_margin_mm}, {self.shared_tol_mm}"
            )


@dataclass(frozen=True)
class NetworkContext:
    """The centerline network around the selected path.

    Attributes
    ----------
    path : (m, 3) float, mm, the selected path's polyline as in the file
    others : every other polyline of the network, each (k, 3) mm
    inscribed_l : (m,) normalized l of the inscribed-sphere radii, or None
    inscribed_radius : (m,) mm, ``MaximumInscribedSphereRadius``, or None
    """

    path: Points
    others: tuple[Points, ...] = ()
    inscribed_l: FloatArray | None = None
    inscribed_radius: FloatArray | None = None


@dataclass(frozen=True)
class WallSelection:
    """Per-point reason code (0 kept, else 1 + index in ``REASONS``) and counts by name."""

    reason: np.ndarray
    counts: dict[str, int]

    @property
    def keep(self) -> np.ndarray:
        """(n,) bool, the wall points to fit."""
        return self.reason == 0


def inscribed_profile(curve: FramedCurve, path: Points, radius: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Normalized l (sorted) and radius of a polyline's inscribed-sphere radii, by projection on ``curve``."""
    path, radius = np.asarray(path, float), np.asarray(radius, float).reshape(-1)
    if len(radius) != len(path) or not np.all(np.isfinite(radius)) or np.any(radius <= 0):
        raise InputDataError(
            f"centerline: MaximumInscribedSphereRadius must be positive and one per point ({len(path)}), "
            f"got {len(radius)} values with minimum {np.min(radius) if radius.size else 'none'}; re-run vmtkcenterlines"
        )
    l = project_points(curve, path).l
    order = np.argsort(l, kind="stable")
    return l[order], radius[order]


def select_wall_points(
    polar: PolarPoints, length_mm: float, network: NetworkContext, settings: SelectionSettings = SelectionSettings()
) -> WallSelection:
    """Classify every projected surface point as kept wall or dropped, with the reason.

    Parameters
    ----------
    polar : every surface point projected on the path's smooth centerline
    length_mm : arc length of that centerline, mm
    network : the path's polyline, the network's other polylines, inscribed radii
    settings : thresholds

    Returns
    -------
    WallSelection with counts ``input``, ``kept`` and one per reason.
    """
    reason = np.zeros(len(polar), np.int8)
    reason[other_branch_mask(polar.points, network, settings.shared_tol_mm)] = 1
    s = polar.l * length_mm
    at_end = (polar.end_side != 0) | (s <= settings.end_margin_mm) | (length_mm - s <= settings.end_margin_mm)
    reason[(reason == 0) & at_end] = 2
    profile = _reference_profile(polar, reason == 0, length_mm, network, settings)
    reason[(reason == 0) & inside_end_walls(polar, reason == 0, length_mm, profile, settings)] = 2
    reference = np.interp(polar.l, *profile)
    far = (polar.rho > settings.outlier_factor * reference) | (polar.rho < reference / settings.outlier_factor)
    reason[(reason == 0) & far] = 3
    counts = {"input": len(polar), "kept": int(np.count_nonzero(reason == 0))}
    counts.update({name: int(np.count_nonzero(reason == k + 1)) for k, name in enumerate(REASONS)})
    return WallSelection(reason, counts)


def other_branch_mask(points: Points, network: NetworkContext, shared_tol_mm: float) -> np.ndarray:
    """(n,) bool: the point is nearer another polyline's own (unshared) part than the path."""
    nearer = np.zeros(len(points), bool)
    if not network.others:
        return nearer
    # every other polyline's own segments at once: nearer one of them than the path is nearer the nearest of them,
    # the same distances (each segment's own formula) and one search instead of one per polyline (issue 43: a
    # tree's hundreds of paths took minutes); a segment shared by several others (their common trunk) counts once
    others = [np.asarray(other, float) for other in network.others]
    near_path = polyline_distances(np.concatenate(others), network.path) <= shared_tol_mm  # all in one search
    starts, ends = [], []
    for other, on_path in zip(others, np.split(near_path, np.cumsum([len(o) for o in others])[:-1]), strict=True):
        own = ~(on_path[:-1] & on_path[1:])
        starts.append(other[:-1][own])
        ends.append(other[1:][own])
    pairs = np.unique(np.concatenate([np.concatenate(starts), np.concatenate(ends)], axis=1), axis=0)
    if not len(pairs):
        return nearer
    path = np.asarray(network.path, float)
    # bounds first: the nearest midpoint's distance m bounds a set's distance d by m - (longest half segment) <= d
    # <= m; most points (another branch's wall far from the path, the path's wall far from the others) are settled
    # by them, and only the rest are measured exactly
    low_path, high_path = _midpoint_bounds(points, path[:-1], path[1:])
    low_other, high_other = _midpoint_bounds(points, pairs[:, :3], pairs[:, 3:])
    nearer = high_other < low_path
    open_ = np.flatnonzero(~nearer & (low_other < high_path))
    if open_.size:
        to_path = polyline_distances(points[open_], path)
        nearer[open_] = segment_distances(points[open_], pairs[:, :3], pairs[:, 3:]) < to_path
    return nearer


def _midpoint_bounds(points: Points, start: Points, end: Points) -> tuple[FloatArray, FloatArray]:
    """Lower and upper bounds (n,) mm of each point's distance to the segments: from the nearest midpoint."""
    half = 0.5 * float(np.sqrt(np.max(np.einsum("ij,ij->i", end - start, end - start))))
    nearest = np.asarray(cKDTree(0.5 * (start + end)).query(points, k=1, workers=-1)[0], float).reshape(-1)
    return nearest - half, nearest


def polyline_distances(points: Points, polyline: Points, segments: np.ndarray | None = None) -> FloatArray:
    """Distance from each point to the nearest point of a polyline's segments (ends clamped), mm.

    Exact, without measuring every point against every segment: each point is
    measured against the segments whose midpoints are its k nearest; every
    other segment is at least (k-th midpoint distance - largest half segment)
    away, so when the best distance found is within that bound it is the
    minimum.  The points it does not settle are retried with a larger k.

    Parameters
    ----------
    points : (n, 3) mm
    polyline : (m, 3) mm, m >= 1
    segments : (m - 1,) bool, the segments to use (default all)
    """
    points = np.asarray(points, float)
    polyline = np.asarray(polyline, float)
    if len(polyline) == 1:
        return np.linalg.norm(points - polyline[0], axis=1)
    start, end = polyline[:-1], polyline[1:]
    if segments is not None:
        start, end = start[segments], end[segments]
    return segment_distances(points, start, end)


def segment_distances(points: Points, start: Points, end: Points) -> FloatArray:
    """Distance from each point (n, 3) to the nearest of the segments ``start``-``end`` (m, 3), m >= 1, mm.

    The search of :func:`polyline_distances`, on any set of segments.
    """
    points = np.asarray(points, float)
    start, end = np.asarray(start, float), np.asarray(end, float)
    edge = end - start
    edge2 = np.maximum(np.einsum("ij,ij->i", edge, edge), np.finfo(float).tiny)
    tree = cKDTree(0.5 * (start + end))
    half_max = 0.5 * float(np.sqrt(edge2.max()))
    out = np.empty(len(points))
    pending, k = np.arange(len(points)), min(_FIRST_K, len(start))
    while pending.size:
        best, kth = _nearest_segment_distances(points[pending], start, edge, edge2, tree, k)
        settled = (k == len(start)) | (best <= kth - half_max)
        out[pending[settled]] = best[settled]
        pending, k = pending[~settled], min(4 * k, len(start))
    return out


def _nearest_segment_distances(
    points: Points, start: Points, edge: Points, edge2: FloatArray, tree: cKDTree, k: int
) -> tuple[FloatArray, FloatArray]:
    """Least distance to the k segments with the nearest midpoints, and the k-th midpoint distance (mm)."""
    best, kth = np.empty(len(points)), np.empty(len(points))
    chunk = max(1, _CHUNK_ENTRIES // k)
    for lo in range(0, len(points), chunk):
        p = points[lo : lo + chunk]
        mid_distance, index = tree.query(p, k=k, workers=-1)
        mid_distance, index = np.asarray(mid_distance).reshape(len(p), k), np.asarray(index).reshape(len(p), k)
        near_start, near_edge = start[index], edge[index]
        t = np.clip(np.einsum("nkj,nkj->nk", p[:, None, :] - near_start, near_edge) / edge2[index], 0.0, 1.0)
        nearest = near_start + t[:, :, None] * near_edge
        best[lo : lo + chunk] = np.sqrt(np.min(np.sum((p[:, None, :] - nearest) ** 2, axis=2), axis=1))
        kth[lo : lo + chunk] = mid_distance[:, -1]
    return best, kth


def inside_end_walls(
    polar: PolarPoints,
    candidate: np.ndarray,
    length_mm: float,
    profile: tuple[FloatArray, FloatArray],
    settings: SelectionSettings,
) -> np.ndarray:
    """(n,) bool: near an end, the point lies well inside the wall beside it (a flat cap's hub or rings).

    Parameters
    ----------
    polar : the projected points
    candidate : (n,) bool, the points still kept (they alone measure the wall)
    length_mm : arc length of the path, mm
    profile : normalized l (k,) and reference radius (k,) mm, the end zones' length scale
    settings : ``cap_zone_radii`` and ``cap_inner_fraction``
    """
    s = polar.l * length_mm
    sector = np.minimum((np.mod(polar.angle, 2.0 * np.pi) * (CAP_SECTORS / (2.0 * np.pi))).astype(int), CAP_SECTORS - 1)
    inside = np.zeros(len(polar), bool)
    for end_l, to_end in ((0.0, s), (1.0, length_mm - s)):
        zone = settings.cap_zone_radii * float(np.interp(end_l, *profile))
        beside = candidate & (to_end > zone) & (to_end <= 2.0 * zone)
        wall = np.full(CAP_SECTORS, np.nan)  # a sector with no wall beside the zone drops nothing
        near = np.flatnonzero(beside)  # the few points beside the zone, each sector's in their order
        near_sector, near_rho = sector[near], polar.rho[near]
        for k in np.unique(near_sector):
            wall[k] = np.median(near_rho[near_sector == k])
        inside |= candidate & (to_end <= zone) & (polar.rho < settings.cap_inner_fraction * wall[sector])
    return inside


def _reference_profile(
    polar: PolarPoints, candidate: np.ndarray, length_mm: float, network: NetworkContext, settings: SelectionSettings
) -> tuple[FloatArray, FloatArray]:
    """Normalized l (k,) and radius (k,) mm that rho is compared with, for ``np.interp``.

    The inscribed-sphere radii when the network has them, else the median rho
    of the candidates in bins ``median_window_mm`` long (inf without candidates).
    """
    if network.inscribed_l is not None and network.inscribed_radius is not None:
        return np.asarray(network.inscribed_l, float), np.asarray(network.inscribed_radius, float)
    if not candidate.any():
        return np.array([0.0, 1.0]), np.full(2, np.inf)
    bins = max(1, int(round(length_mm / settings.median_window_mm)))
    index = np.minimum((polar.l * bins).astype(int), bins - 1)
    centres, medians = [], []
    for k in range(bins):
        rows = candidate & (index == k)
        if rows.any():
            centres.append((k + 0.5) / bins)
            medians.append(np.median(polar.rho[rows]))
    return np.array(centres), np.array(medians)
