"""How finely a cross-section's circles must be noded so that the triangulation keeps them all.

The swept mesher (:mod:`softdesign.meshing.volume_mesh.cross_section`) lays every hole
of the body in one reference section: with issue 31's layout, every
section's three chambers and every feed, 3n ring members ``120 / n``
degrees apart, the chambers of neighbouring sections only
``2 d sin(60 deg / n) - D`` apart (0.032 mm on the demo's defaults at five
sections).  A circle's edge is kept by the Delaunay triangulation when it is
a Gabriel edge, its diametral disk empty of other nodes.  The disk of an
edge of a circle of node radius R with m nodes (h = 2 pi / m) reaches
``R (1 - cos(h/2) + sin(h/2))`` off the circle (inwards, the larger side);
so each circle gets the fewest nodes, at least those asked, for which
that reach is at most ``GAP_REACH`` of its smallest gap to another circle's
nodes (two disjoint circles: centre distance less both radii; nested:
outer radius less inner radius less the centre offset).  The circles keep
uniform nodes, so their polygons keep the circle's area
(:attr:`~softdesign.meshing.volume_mesh.cross_section.Circle.equal_area`).  Refining
the gaps' circles, not the whole section, keeps the mesh small: only the
circles next to a narrow gap get more nodes.

A gap that needs more than ``MAX_CIRCLE_NODES`` nodes on a circle, or a
pair that touches or overlaps, cannot be resolved:
:func:`unresolved` names it so that the caller can refuse it before work.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from softdesign.meshing.volume_mesh.cross_section import Circle
from softdesign.types import FloatArray

#: An edge's diametral disk may reach at most this fraction of the circle's smallest gap off the circle.
GAP_REACH = 0.45
#: Most nodes on one hole's circle (the bound on how narrow a gap the mesher resolves).
MAX_CIRCLE_NODES = 256


def edge_reach(radius: float, nodes: int) -> float:
    """How far the diametral disk of an edge of ``nodes`` equal edges on a circle of ``radius`` reaches off it."""
    h = 2.0 * np.pi / nodes
    return float(radius * (1.0 - np.cos(0.5 * h) + np.sin(0.5 * h)))


def _radii(circles: Sequence[Circle]) -> FloatArray:
    return np.array([c.node_radius(c.nodes) if c.nodes else c.radius for c in circles], float)


def pair_gaps(circles: Sequence[Circle]) -> FloatArray:
    """(H, H) clearance between the circles' node circles (< 0: they cross), inf on the diagonal.

    Nested circles (one inside the other) give the outer radius less the inner radius less the centres'
    distance; disjoint ones the centres' distance less both radii.
    """
    centres = np.array([c.center for c in circles], float).reshape(-1, 2)
    r = _radii(circles)
    dist = np.linalg.norm(centres[:, None] - centres[None], axis=-1)
    big, small = np.maximum(r[:, None], r[None]), np.minimum(r[:, None], r[None])
    nested = dist + small <= big
    gaps = np.where(nested, big - small - dist, dist - r[:, None] - r[None])
    np.fill_diagonal(gaps, np.inf)
    return gaps


@dataclass(frozen=True)
class Unresolved:
    """The narrowest pair of circles the mesher cannot resolve: their indices, their gap (reference units;
    <= 0: they touch or cross) and the nodes the first would need (0 when they touch or cross)."""

    first: int
    second: int
    gap: float
    nodes: int


def unresolved(circles: Sequence[Circle], resolved: Sequence[Circle] | None = None) -> Unresolved | None:
    """The narrowest pair that touches, crosses, or needs more than ``MAX_CIRCLE_NODES`` on a circle, or None
    (``resolved``: :func:`resolve_circles` of ``circles`` if already made)."""
    if len(circles) < 2:
        return None
    gaps = pair_gaps(circles)
    i, j = np.unravel_index(int(np.argmin(gaps)), gaps.shape)
    if gaps[i, j] <= 0:
        return Unresolved(int(min(i, j)), int(max(i, j)), float(gaps[i, j]), 0)
    counts = [len(c.angles) or c.nodes for c in (resolved or resolve_circles(circles))]
    over = [k for k, m in enumerate(counts) if m > MAX_CIRCLE_NODES]
    if not over:
        return None
    k = min(over, key=lambda m: (float(np.min(gaps[m])), m))
    other = int(np.argmin(gaps[k]))
    return Unresolved(min(k, other), max(k, other), float(gaps[k, other]), counts[k])


def smallest_gap(radius: float, nodes: int) -> float:
    """The narrowest gap between two circles of ``radius`` (``nodes`` equal steps each, equal area) that
    :func:`resolve_circles` resolves within ``MAX_CIRCLE_NODES``, by bisection (reference units)."""
    low, high = 0.0, 2.0 * radius
    for _ in range(30):
        gap = 0.5 * (low + high)
        pair = [Circle((0.0, 0.0), radius, nodes, True), Circle((2.0 * radius + gap, 0.0), radius, nodes, True)]
        low, high = (low, gap) if unresolved(pair) is None else (gap, high)
    return high


#: Angle samples per circle for its clearance to the others.
CLEARANCE_SAMPLES = 1024
#: Neighbouring edges of a graded circle differ by at most this much per edge length along it.
EDGE_SLOPE = 0.3


def clearance(circle: Circle, others: Sequence[Circle], angles: FloatArray) -> FloatArray:
    """Distance from ``circle``'s node circle at ``angles`` (K,) to the nearest other node circle, (K,)."""
    radius = circle.node_radius(circle.nodes)
    points = np.asarray(circle.center, float) + radius * np.column_stack([np.cos(angles), np.sin(angles)])
    centres = np.array([c.center for c in others], float).reshape(-1, 2)
    dist = np.linalg.norm(points[:, None] - centres[None], axis=-1)
    return np.min(np.abs(dist - _radii(others)[None]), axis=1)


def _graded(edge: FloatArray, x: FloatArray, period: float) -> FloatArray:
    """min over j of edge[j] + EDGE_SLOPE |x - x_j| on a periodic line (x increasing within one period)."""
    xs = np.concatenate([x - period, x, x + period])
    es = np.tile(edge, 3)
    forward = np.minimum.accumulate(es - EDGE_SLOPE * xs) + EDGE_SLOPE * xs
    backward = (np.minimum.accumulate((es + EDGE_SLOPE * xs)[::-1]) - EDGE_SLOPE * xs[::-1])[::-1]
    return np.minimum(forward, backward)[x.size:2 * x.size]


def graded_angles(circle: Circle, gap_edge: FloatArray, angles: FloatArray) -> tuple[float, ...]:
    """Node angles whose edges follow ``gap_edge`` (K,) (the longest edge each sample allows), no edge longer
    than the circle's own, the step graded by ``EDGE_SLOPE``; () when the equal steps already do."""
    radius, base = circle.radius, 2.0 * np.pi / circle.nodes
    if np.all(gap_edge >= radius * base):
        return ()
    edge = np.minimum(_graded(gap_edge, radius * angles, 2.0 * np.pi * radius), radius * base)
    if np.all(edge >= radius * base * (1.0 - 1e-12)):
        return ()
    step = angles[1] - angles[0]
    density = np.concatenate([[0.0], np.cumsum(radius * step / edge)])  # nodes per arc, integrated from 0
    count = max(circle.nodes, int(np.ceil(density[-1])))
    where = np.interp(np.arange(count) * density[-1] / count, density, np.append(angles, 2.0 * np.pi))
    return tuple(float(a) for a in where)


def resolve_circles(circles: Sequence[Circle]) -> list[Circle]:
    """``circles`` with the nodes graded finer where a circle passes near another (module notes).

    A circle keeps its equal steps unless a gap needs more; circles with ``nodes == 0`` are left to the
    section's size.  :func:`unresolved` finds the pairs no grading up to ``MAX_CIRCLE_NODES`` resolves.
    """
    if len(circles) < 2:
        return list(circles)
    angles = 2.0 * np.pi * np.arange(CLEARANCE_SAMPLES) / CLEARANCE_SAMPLES
    out = []
    for k, c in enumerate(circles):
        if c.nodes and not c.angles:
            others = [o for i, o in enumerate(circles) if i != k]
            # the reach R (1 - cos(h/2) + sin(h/2)) <= GAP_REACH x clearance, with h/2 at most the equal step's
            allowed = 2.0 * GAP_REACH * clearance(c, others, angles) / (1.0 + np.pi / (2.0 * c.nodes))
            graded = graded_angles(c, np.maximum(allowed, 1e-12), angles)
            if graded:
                c = replace(c, angles=graded)
        out.append(c)
    return out
