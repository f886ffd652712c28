"""What each path of a centerline network is, and which one is the main vessel.

A VMTK network has one path per outlet, all from the inlet, sharing the
trunk; which one a user means is seldom path 0 (the file's order is the
outlets', often a small branch first).  For every path this gives its
length, its inscribed radius at the inlet and at the end, where it leaves
the others (the arc length from the inlet at which it parts from the path it
shares most with) and which opening it ends at; and it proposes one path as
the main vessel.

The main-vessel rule
    The path of largest lumen volume, ``integral r(s)^2 ds`` along it (pi
    times it is the volume of the tube of inscribed spheres): the path that
    stays widest longest.  Every path shares the trunk, so the comparison is
    of what each adds after it leaves the others: a side branch that leaves
    early and narrow (a supra-aortic or coronary branch, a renal artery, an
    ophthalmic artery) adds little; the trunk's own continuation (the
    descending or aorto-iliac aorta, the ICA to its terminal) adds most.  Width
    counts squared, so a long thin branch does not outweigh a short wide one
    (a subclavian-vertebral path of 5 mm radius over 150 mm adds 3,750 mm^3,
    a descending aorta of 12 mm over 200 mm 28,800 mm^3).  Without radii the
    longest path is proposed.  Ties go to the lower index.

Leaving
    Path k leaves path j at the first point of k (from the inlet) farther
    from j than ``LEAVE_RADII`` of k's radius there (or ``LEAVE_STEPS`` point
    spacings without radii): the point where k's centre has left j's lumen
    half-way, which is where the two tubes part.

    With more than ``MAX_PAIRWISE_PATHS`` paths (a big tree: the pairs grow
    as the square), each path is measured against the main vessel only, and
    ``leaves`` says so by naming it.

Radius at an end
    The largest inscribed radius within ``END_REACH_RADII`` of the path's
    median radius of the end: at a capped end the last point lies on the cap
    (a radius measured as the distance to the surface is 0 there), while the
    sphere that touches the cap, about a radius inside, has the vessel's
    radius.

Openings
    The far ends of the paths, one opening for ends within the leave
    tolerance of each other, numbered from 1 in path order (0 is the inlet).

Pure: numpy (and scipy's KD-tree for long paths only, so that ``softdesign validate`` on a
usual centerline does not import scipy); lengths in the paths' own unit.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from softdesign.geometry.median import median
from softdesign.types import FloatArray, Points

#: Path k has left path j where its centre lies farther from j than this many of its radii.
LEAVE_RADII = 0.5
#: Without radii, farther than this many of k's median point spacings.
LEAVE_STEPS = 4.0
#: The radius at an end is the largest within this many of the path's median radius of it.
END_REACH_RADII = 1.0
#: Most paths measured against each other; above it, each against the main vessel only (about 1.3 ms a pair
#: of 500-point paths: 24 paths take 0.7 s, 64 took 5 s).
MAX_PAIRWISE_PATHS = 24


@dataclass(frozen=True)
class PathFacts:
    """One path as :func:`survey_paths` describes it (the paths' unit; radii None without radii).

    Attributes
    ----------
    index : the ``final.path`` value of the path
    length : arc length
    radius_inlet, radius_end : inscribed radius at its two ends (the largest within reach: module notes)
    leaves : (other path's index, arc length from the inlet where it parts from it), or None for a single path
    opening : the opening it ends at, from 1 (0 is the inlet)
    end : (3,) float -- its last point
    lumen : integral of r^2 along it (unit^3), or None without radii
    """

    index: int
    length: float
    radius_inlet: float | None
    radius_end: float | None
    leaves: tuple[int, float] | None
    opening: int
    end: FloatArray
    lumen: float | None


def arc_lengths(points: Points) -> FloatArray:
    """Arc length (n,) from the first point of a polyline (n, 3)."""
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])


def lumen_integral(points: Points, radius: FloatArray) -> float:
    """``integral r^2 ds`` along a polyline (n, 3) with radii (n,), by the trapezoid rule (unit^3)."""
    s = arc_lengths(points)
    r2 = np.asarray(radius, float) ** 2
    return float(np.sum(0.5 * (r2[1:] + r2[:-1]) * np.diff(s)))


def end_radius(points: Points, radius: FloatArray) -> float:
    """The radius at the first end of a path (see the module notes): the largest within reach of it."""
    radius = np.asarray(radius, float)
    near = arc_lengths(points) <= END_REACH_RADII * median(radius)
    return float(radius[near].max())


def _tolerance(points: Points, radius: FloatArray | None) -> FloatArray:
    """(n,) the distance from another path beyond which a point of this path has left it."""
    if radius is not None:
        return LEAVE_RADII * np.asarray(radius, float)
    step = median(np.linalg.norm(np.diff(points, axis=0), axis=1))
    return np.full(len(points), LEAVE_STEPS * step)


#: Up to this many point-vertex pairs the nearest vertex is found by direct distances (numpy), above by a KD-tree.
DIRECT_PAIRS = 4_000_000
#: Points per block of the direct search (a block's distances: DIRECT_BLOCK x vertices floats).
DIRECT_BLOCK = 2048
NearestVertex = Callable[[Points], np.ndarray]


def nearest_vertex_of(polyline: Points, queries: int) -> NearestVertex:
    """A function giving, for points (n, 3), the index (n,) of the nearest vertex of ``polyline`` (m, 3): direct
    distances when ``queries`` x m is at most :data:`DIRECT_PAIRS`, else scipy's KD-tree (the same answer)."""
    polyline = np.asarray(polyline, float)
    if queries * len(polyline) > DIRECT_PAIRS:
        from scipy.spatial import cKDTree

        tree = cKDTree(polyline)
        return lambda points: np.asarray(tree.query(points)[1], np.int64)

    def direct(points: Points) -> np.ndarray:
        points = np.asarray(points, float)
        out = np.empty(len(points), np.int64)
        for start in range(0, len(points), DIRECT_BLOCK):
            block = points[start:start + DIRECT_BLOCK]
            d2 = np.einsum("ijk,ijk->ij", block[:, None, :] - polyline[None], block[:, None, :] - polyline[None])
            out[start:start + DIRECT_BLOCK] = np.argmin(d2, axis=1)
        return out

    return direct


def distances_to_polyline(points: Points, polyline: Points, nearest_of: NearestVertex | None = None) -> FloatArray:
    """Distance (n,) from each point (n, 3) to the polyline (m, 3): to the segments beside its nearest vertex."""
    nearest_of = nearest_vertex_of(polyline, len(points)) if nearest_of is None else nearest_of
    nearest = nearest_of(points)
    best = np.linalg.norm(points - polyline[nearest], axis=1)
    for first in (nearest - 1, nearest):  # the segments ending and starting at the nearest vertex
        ok = (first >= 0) & (first + 1 < len(polyline))
        a, b = polyline[np.clip(first, 0, len(polyline) - 2)], polyline[np.clip(first + 1, 1, len(polyline) - 1)]
        ab = b - a
        t = np.clip(np.einsum("ij,ij->i", points - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300), 0, 1)
        d = np.linalg.norm(points - (a + t[:, None] * ab), axis=1)
        best = np.where(ok, np.minimum(best, d), best)
    return best


def leave_length(points: Points, radius: FloatArray | None, other: Points,
                 nearest_of: NearestVertex | None = None) -> float:
    """Arc length along ``points`` (from its first point) where it leaves ``other`` (see the module notes).

    0 when its first point is already off ``other``; its whole length when it never leaves.
    """
    off = distances_to_polyline(points, other, nearest_of) > _tolerance(points, radius)
    s = arc_lengths(points)
    return float(s[int(np.argmax(off))]) if off.any() else float(s[-1])


def survey_paths(paths: Sequence[tuple[int, Points, FloatArray | None]]) -> list[PathFacts]:
    """The facts of every path (see :class:`PathFacts` and the module notes).

    Parameters
    ----------
    paths : (index, points (n, 3) inlet first, radius (n,) or None) per path
    """
    own = [_own_facts(index, points, radius) for index, points, radius in paths]
    main = next(k for k, f in enumerate(own) if f.index == main_path(own))
    partners = range(len(paths)) if len(paths) <= MAX_PAIRWISE_PATHS else [main]
    longest = max(len(points) for _, points, _ in paths)
    trees = {j: nearest_vertex_of(paths[j][1], longest) for j in partners}
    ends: list[FloatArray] = []
    out = []
    for k, (_, points, radius) in enumerate(paths):
        parts = [(paths[j][0], leave_length(points, radius, paths[j][1], trees[j])) for j in partners if j != k]
        leaves = max(parts, key=lambda part: part[1]) if parts else None  # the path it shares most with
        tol = float(_tolerance(points, radius)[-1])
        near = [n for n, e in enumerate(ends) if np.linalg.norm(e - points[-1]) <= tol]
        if not near:
            ends.append(points[-1])
        opening = (near[0] if near else len(ends) - 1) + 1
        out.append(replace(own[k], leaves=leaves, opening=opening))
    return out


def _own_facts(index: int, points: Points, radius: FloatArray | None) -> PathFacts:
    """What a path says by itself (its leaving and its opening still to be found)."""
    return PathFacts(
        index=index, length=float(arc_lengths(points)[-1]),
        radius_inlet=None if radius is None else end_radius(points, radius),
        radius_end=None if radius is None else end_radius(points[::-1], radius[::-1]),
        leaves=None, opening=0, end=np.array(points[-1], float),
        lumen=None if radius is None else lumen_integral(points, radius),
    )


def main_path(facts: Sequence[PathFacts]) -> int:
    """The ``index`` of the main vessel: the largest lumen integral, or without radii the longest (module notes)."""
    if not facts:
        raise ValueError("no paths to choose from")
    if all(f.lumen is not None for f in facts):
        scores = [float(f.lumen) for f in facts if f.lumen is not None]
    else:
        scores = [f.length for f in facts]
    return facts[int(np.argmax(scores))].index


#: The rule, as the case file's comment and the messages state it.
MAIN_PATH_RULE = "the path of largest lumen volume (integral of r^2 along it): the one that stays widest longest"
