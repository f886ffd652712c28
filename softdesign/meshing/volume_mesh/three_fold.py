"""The points of a three-fold symmetric cross-section: made one orbit of the 120-degree rotation at a time.

When it applies
    The outer circle's node count is a multiple of three, no hole is centred
    on the axis, no hole's nodes are graded, and the rotation R by 120 degrees
    about the section's centre takes every hole onto a hole of the same radius
    and nodes (within ``CENTRE_TOL``): issue 31's layout, each section's three
    chambers and the feeds on one ring ``120 / n`` degrees apart.  Otherwise
    :func:`symmetric_points` returns None and the section is meshed as before.
How
    The points are those of :mod:`softdesign.meshing.volume_mesh.cross_section` (circle
    nodes, then fronts of rings kept greedily in order of their distance from a
    circle), but every point comes with its two turned copies: the holes of an
    orbit take the first one's nodes turned; the outer circle's fronts (centred
    on the axis) have a multiple of three points per ring and give their first
    third; only the first hole of each orbit grows fronts, and a candidate is
    kept when it and its copies keep off every kept point and each other.  The
    set maps onto itself under R, point for point, so its Delaunay triangulation
    does too, unless co-circular ties are broken unevenly: the caller checks.
Prism split
    Each point has an orbit and a copy (0, 1, 2: R^copy of the orbit's first;
    the centre, always a point, is an orbit of one).  A side of a prism
    (:mod:`softdesign.meshing.volume_mesh.sweep_mesh`) has its diagonal start at the
    corner of the lower orbit, or between two copies of one orbit at the copy
    that R takes to the other: a rule that turns with R and depends on the
    side alone (neighbours conform).  It splits every prism unless a triangle
    holds a whole orbit, which the centre point rules out: that triangle would
    have the centre inside it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from softdesign.types import FloatArray, IntArray

#: Two holes' centres (or radii) are the same under the rotation within this, in section radii.
CENTRE_TOL = 1e-9
#: The rotation by 120 degrees about the section's centre.
TURN = np.array([[np.cos(2 * np.pi / 3), -np.sin(2 * np.pi / 3)], [np.sin(2 * np.pi / 3), np.cos(2 * np.pi / 3)]])


@dataclass(frozen=True)
class SymmetricPoints:
    """A point set that the 120-degree rotation maps onto itself.

    Attributes
    ----------
    points : (P, 2) float, the outer circle's nodes, then each hole's circle nodes in hole order, then the rest
    orbit : (P,) int64, each point's orbit under the rotation
    copy : (P,) int64, 0, 1, 2: the point is the rotation to that power of its orbit's first point
    """

    points: FloatArray
    orbit: IntArray
    copy: IntArray

    def turned_index(self) -> IntArray:
        """(P,) the index of each point's image under the rotation (itself for the centre)."""
        size = np.bincount(self.orbit)
        where = {(o, c): i for i, (o, c) in enumerate(zip(self.orbit.tolist(), self.copy.tolist(), strict=True))}
        return np.array([where[(o, (c + 1) % size[o])] for o, c in zip(self.orbit.tolist(), self.copy.tolist(),
                                                                     strict=True)], np.int64)

    def corner_order(self, triangles: IntArray) -> IntArray:
        """(T, 3) each corner's place in its triangle's prism split (0 starts both its side diagonals, 1 one,
        2 none): a side's diagonal starts at the corner of the lower orbit or, between two copies of one
        orbit, at the copy the rotation takes to the other.  The rule turns with the rotation, and it orders
        every triangle that does not hold a whole orbit (:meth:`is_symmetric`)."""
        o, c = self.orbit[triangles], self.copy[triangles]
        wins = np.zeros(triangles.shape, np.int64)
        for i in range(3):
            for j in range(3):
                if i != j:
                    starts = (o[:, i] < o[:, j]) | ((o[:, i] == o[:, j]) & ((c[:, i] + 1) % 3 == c[:, j]))
                    wins[:, i] += starts
        return 2 - wins

    def is_symmetric(self, triangles: IntArray) -> bool:
        """Whether ``triangles`` (T, 3) map onto themselves under the rotation, none holding a whole orbit
        (then :meth:`corner_order` orders each of them and the split commutes with the rotation)."""
        turned = self.turned_index()[triangles]
        same = {tuple(t) for t in np.sort(turned, axis=1).tolist()} == {tuple(t) for t in
                                                                        np.sort(triangles, axis=1).tolist()}
        o = self.orbit[triangles]
        return same and not np.any((o[:, 0] == o[:, 1]) & (o[:, 1] == o[:, 2]))


def hole_turns(centres: FloatArray, radii: FloatArray, nodes: Sequence[int]) -> IntArray | None:
    """(H,) the hole each hole turns onto under the rotation, or None when the holes do not map onto themselves.

    ``centres`` (H, 2) and ``radii`` (H,) in section radii, ``nodes`` each circle's node count.
    """
    centres = np.asarray(centres, float).reshape(-1, 2)
    if np.any(np.linalg.norm(centres, axis=1) < CENTRE_TOL):
        return None
    turned = centres @ TURN.T
    turns = np.full(len(centres), -1, np.int64)
    for i, target in enumerate(turned):
        match = np.flatnonzero((np.linalg.norm(centres - target, axis=1) < CENTRE_TOL)
                               & (np.abs(radii - radii[i]) < CENTRE_TOL) & (np.asarray(nodes) == nodes[i]))
        if len(match) != 1:
            return None
        turns[i] = match[0]
    return turns


def orbit_heads(turns: IntArray) -> list[tuple[int, int, int]]:
    """Each orbit's holes (first, turned once, turned twice), first being the lowest index."""
    return [(i, int(turns[i]), int(turns[turns[i]])) for i in range(len(turns))
            if i < turns[i] and i < turns[turns[i]]]


def with_copies(points: FloatArray) -> FloatArray:
    """(3, n, 2): ``points`` (n, 2) turned 0, 1 and 2 times."""
    once = points @ TURN.T
    return np.stack([points, once, once @ TURN.T])


def keep_orbits(candidates: FloatArray, kept: FloatArray, local: FloatArray, h: float,
                keep_fraction: float) -> FloatArray:
    """The candidates (n, 2) that, with their copies, keep off the ``kept`` points (local sizes ``local``) and
    off each other by ``keep_fraction`` of the smaller local size (``h`` for the candidates): (m, 2), in order."""
    from scipy.spatial import cKDTree

    if not len(candidates):
        return candidates
    distance, nearest = cKDTree(kept).query(candidates)
    candidates = candidates[distance >= keep_fraction * np.minimum(h, local[nearest])]
    least = keep_fraction * h
    accepted: list[FloatArray] = []
    for p in candidates:
        if np.sqrt(3.0) * np.linalg.norm(p) < least:  # p and its own copies, sqrt(3) |p| apart
            continue
        if accepted and np.min(np.linalg.norm(with_copies(np.array(accepted)) - p, axis=2)) < least:
            continue
        accepted.append(p)
    return np.array(accepted).reshape(-1, 2)
