"""The body's cross-section in its parameter domain: the unit disk, triangulated to conform to circular holes.

Reference plane
    Coordinates (x, y) along the section's (N, B), in fractions of the section's
    radius: the outer boundary is the unit circle, sampled at the export's
    angles ``a_k = 2 pi k / na`` (so the swept mesh's skin has the surface
    mesh's vertices).  A hole is a circle (centre, radius in the same units)
    that the triangulation conforms to: its circle is a chain of edges, every
    triangle lies wholly inside or outside it.  The hole's inside is meshed
    too: a chamber exists only over part of the length, and where it does not
    the section is solid (:mod:`softdesign.meshing.volume_mesh.sweep_mesh` drops the
    hole's triangles layer by layer).
Points
    Each circle (the outer one and every hole's) is a front: its own nodes,
    then rings of points stepping away from it (inwards and, for a hole,
    outwards) by ``sqrt(3)/2`` of the local size, each ring turned half a
    step from the last (near-equilateral triangles), the size growing by
    ``GROWTH`` per ring up to ``size``.  Candidates are kept in order of
    their ring's distance from a circle; one closer than ``KEEP_FRACTION`` of
    the smaller local size to a kept point is dropped.  A circle's nodes are
    equal steps from angle 0, or graded (``Circle.angles``) where it passes a
    narrow gap (:mod:`softdesign.meshing.volume_mesh.section_gaps`); a graded circle's
    fronts start at its largest edge and keep off it by that edge.
Three-fold symmetry
    When the holes map onto themselves under a rotation by 120 degrees and
    ``na`` is a multiple of three (issue 31's chambers and feeds), the points
    are made orbit by orbit with the centre among them, and prisms are split
    by a rule that turns with the rotation
    (:mod:`softdesign.meshing.volume_mesh.three_fold`): the mesh maps onto itself, so
    three equal chambers at equal pressure do not bend it.  Should the
    Delaunay triangulation of those points break a tie unevenly, the points
    above are used instead.
Triangulation
    Delaunay (qhull through scipy: deterministic for the same points).  The
    rings either side of a circle make its edges Delaunay; every circle edge
    is checked present and a missing one is a MeshError (a bug to report),
    never a silent non-conforming mesh.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from softdesign.errors import MeshError
from softdesign.meshing.volume_mesh.three_fold import SymmetricPoints, hole_turns, keep_orbits, orbit_heads, with_copies
from softdesign.types import FloatArray, IntArray

#: Local size grows by this factor per ring away from a circle.  1.4 rather than 1.25: the aorta with chambers
#: (24 circles of 12 and 16 nodes in one section) 2464 -> 2076 triangles, 361k -> 297k tetrahedra, its least
#: dihedral angle 1.40 -> 1.42 degrees at q = 0 and 1.24 -> 1.38 at q = 1 (the layers' needles, not the
#: section's), its largest radius-edge ratio 16.7 -> 15.4; the least section angle 20.4 -> 20.3 degrees.
GROWTH = 1.4
#: A candidate closer than this fraction of the smaller local size to a kept point is dropped.
KEEP_FRACTION = 0.7
#: Fewest nodes on a hole's circle.
MIN_HOLE_NODES = 12
#: Ring points stay this many of a circle's edge lengths off it: outside every edge's diametral disk
#: (half an edge plus the sagitta), so each circle edge is a Gabriel, hence Delaunay, edge.
CIRCLE_CLEARANCE = 0.6


@dataclass(frozen=True)
class Circle:
    """A hole of the cross-section: ``center`` (x, y) and ``radius`` in fractions of the section's radius."""

    center: tuple[float, float]
    radius: float
    #: nodes on the circle; 0: from the local size (at least MIN_HOLE_NODES)
    nodes: int = 0
    #: put the nodes on the radius whose polygon has the circle's area (a cavity of the right volume with
    #: few nodes: r sqrt(h / sin h), h = 2 pi / nodes) rather than on the circle itself
    equal_area: bool = False
    #: the nodes' angles (rad, increasing from 0), graded where the circle passes a narrow gap
    #: (:func:`softdesign.meshing.volume_mesh.section_gaps.resolve_circles`); empty: ``nodes`` equal steps from angle 0
    angles: tuple[float, ...] = ()

    def node_angles(self, count: int) -> FloatArray:
        """The nodes' angles: ``angles`` if given, else ``count`` equal steps from 0."""
        if self.angles:
            return np.asarray(self.angles, float)
        return 2.0 * np.pi * np.arange(count) / count

    def node_radius(self, count: int) -> float:
        """The radius the circle's nodes lie on (``count`` of them unless ``angles`` are given): with
        ``equal_area``, the one whose polygon has the circle's area, r sqrt(2 pi / sum sin(step))."""
        if not self.equal_area:
            return self.radius
        if not self.angles:
            h = 2.0 * np.pi / count
            return float(self.radius * np.sqrt(h / np.sin(h)))
        steps = np.diff(np.append(self.node_angles(count), 2.0 * np.pi + self.node_angles(count)[0]))
        return float(self.radius * np.sqrt(2.0 * np.pi / np.sum(np.sin(steps))))

    def largest_edge(self, count: int) -> float:
        """The longest edge of the circle's polygon."""
        if not self.angles:
            return float(2.0 * self.node_radius(count) * np.sin(np.pi / count))
        steps = np.diff(np.append(self.node_angles(count), 2.0 * np.pi + self.node_angles(count)[0]))
        return float(2.0 * self.node_radius(count) * np.sin(0.5 * np.max(steps)))


@dataclass(frozen=True)
class CrossSection:
    """The triangulated unit disk.

    Attributes
    ----------
    points : (P, 2) float, reference (x, y); points[:na] are the outer circle at angles 2 pi k / na
    triangles : (T, 3) int64, counter-clockwise
    inside : (T, H) bool, triangle t lies inside hole h
    circle_nodes : tuple of H (m_h,) int64, each hole's circle nodes in counter-clockwise order
    outer_count : int, na
    corner_order : (T, 3) int64 or None, the order of each triangle's corners that prisms over it are split
        by (None: the points' own order); set when the section is three-fold symmetric
        (:mod:`softdesign.meshing.volume_mesh.three_fold`), so that the split commutes with the rotation
    """

    points: FloatArray
    triangles: IntArray
    inside: np.ndarray
    circle_nodes: tuple[IntArray, ...]
    outer_count: int
    corner_order: IntArray | None = None

    def triangle_areas(self) -> FloatArray:
        """Signed area of each triangle, (T,) in squared section radii (> 0: counter-clockwise)."""
        p = self.points[self.triangles]
        u, v = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
        return 0.5 * (u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0])

    def min_angle_deg(self) -> float:
        """Smallest interior angle of any triangle, degrees (a quality figure)."""
        p = self.points[self.triangles]
        angles = []
        for k in range(3):
            u, v = p[:, (k + 1) % 3] - p[:, k], p[:, (k + 2) % 3] - p[:, k]
            cos = np.einsum("ij,ij->i", u, v) / (np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1))
            angles.append(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))
        return float(np.min(angles))


def _ring(center: FloatArray, radius: float, count: int, phase: float) -> FloatArray:
    angles = phase + 2.0 * np.pi * np.arange(count) / count
    return center + radius * np.column_stack([np.cos(angles), np.sin(angles)])


def _front(center: FloatArray, radius: float, h0: float, size: float, outward: bool,
           reach: float, multiple: int = 1) -> list[tuple[int, FloatArray, float]]:
    """Rings stepping away from a circle: (ring index from 1, points, local size); each ring's count a
    ``multiple`` of its nearest."""
    rings, r, h, phase = [], radius, h0, 0.0
    for index in range(1, 10_000):
        step = h * math.sqrt(3.0) / 2.0
        r = r + step if outward else r - step
        phase += 0.5 * h / max(r, 1e-12)
        h = min(h * GROWTH, size)
        if (not outward and r < 0.5 * h) or (outward and r - radius > reach):
            if not outward:
                rings.append((index, center[None, :].copy(), h))
            break
        count = max(3, multiple * round(2.0 * np.pi * r / h / multiple))
        rings.append((index, _ring(center, r, count, phase), h))
    return rings


def _hole_count(c: Circle, size: float, h_outer: float) -> int:
    """Nodes on a hole's circle: its graded angles', its own, or from the local size (at least MIN_HOLE_NODES)."""
    return len(c.angles) or c.nodes or max(MIN_HOLE_NODES, round(2.0 * np.pi * c.radius / max(size, h_outer)))


def _check_holes(circles: Sequence[Circle]) -> None:
    for k, c in enumerate(circles):
        reach = math.hypot(*c.center) + c.radius
        if not (c.radius > 0 and reach < 1.0):
            raise MeshError(f"cross-section hole {k}: centre {c.center} radius {c.radius:g} (section radii) must lie "
                            "inside the unit disk; this is a bug in the chamber layout, please report it")


def _candidates(outer_count: int, circles: Sequence[Circle], size: float):
    """Fixed circle nodes, and candidate rings ordered by ring index then front."""
    h_outer = 2.0 * np.sin(np.pi / outer_count)
    fixed = [_ring(np.zeros(2), 1.0, outer_count, 0.0)]
    sizes = [np.full(outer_count, h_outer)]
    fronts = [_front(np.zeros(2), 1.0, h_outer, max(size, h_outer), False, 2.0)]
    for c in circles:
        centre = np.asarray(c.center, float)
        count = _hole_count(c, size, h_outer)
        radius = c.node_radius(count)
        if c.angles:  # graded: a node's local size is its smaller edge; the fronts start at the largest
            nodes = centre + radius * np.column_stack([np.cos(c.node_angles(count)), np.sin(c.node_angles(count))])
            edges = np.linalg.norm(np.roll(nodes, -1, axis=0) - nodes, axis=1)
            fixed.append(nodes)
            sizes.append(np.minimum(edges, np.roll(edges, 1)))
        else:
            fixed.append(_ring(centre, radius, count, 0.0))
            sizes.append(np.full(count, 2.0 * radius * np.sin(np.pi / count)))
        h0 = c.largest_edge(count)
        fronts.append(_front(centre, radius, h0, max(size, h_outer), False, 2.0))
        fronts.append(_front(centre, radius, h0, max(size, h_outer), True, 2.0))
    rings = sorted(((index, f, pts, h) for f, front in enumerate(fronts) for index, pts, h in front),
                   key=lambda item: (item[0], item[1]))
    return fixed, sizes, rings


def _keep(fixed: list[FloatArray], sizes: list[FloatArray], rings,
          circles: Sequence[Circle]) -> tuple[FloatArray, FloatArray]:
    from scipy.spatial import cKDTree

    points, local = np.concatenate(fixed), np.concatenate(sizes)
    bounds = [(np.zeros(2), 1.0, sizes[0][0])] + [(np.asarray(c.center, float), c.node_radius(len(e)),
                                                     c.largest_edge(len(e)))
                                                    for c, e in zip(circles, sizes[1:], strict=True)]
    for _, _, pts, h in rings:
        r_ok = np.linalg.norm(pts, axis=1) <= 1.0
        for centre, radius, edge in bounds:  # off every circle's diametral disks: its edges stay Delaunay
            r_ok &= np.abs(np.linalg.norm(pts - centre, axis=1) - radius) >= CIRCLE_CLEARANCE * edge
        pts = pts[r_ok]
        if not len(pts):
            continue
        distance, nearest = cKDTree(points).query(pts)
        ok = distance >= KEEP_FRACTION * np.minimum(h, local[nearest])
        pts = pts[ok]
        # within one ring the points are h apart; keep them all, they are spaced by construction
        points = np.concatenate([points, pts])
        local = np.concatenate([local, np.full(len(pts), h)])
    return points, local


def _symmetric_points(outer_count: int, circles: Sequence[Circle], size: float,
                      counts: list[int]) -> SymmetricPoints | None:
    """The points of :func:`_candidates` and :func:`_keep` made orbit by orbit under the 120-degree rotation
    (:mod:`softdesign.meshing.volume_mesh.three_fold`), or None when the section is not three-fold symmetric."""
    centres = np.array([c.center for c in circles], float).reshape(-1, 2)
    turns = hole_turns(centres, np.array([c.radius for c in circles]), counts)
    if not circles or outer_count % 3 or turns is None or any(c.equal_area != circles[turns[i]].equal_area
                                               for i, c in enumerate(circles)):
        return None
    h_outer = 2.0 * np.sin(np.pi / outer_count)
    third = outer_count // 3
    fixed = [_ring(np.zeros(2), 1.0, outer_count, 0.0)]
    orbit, copy = [np.arange(outer_count) % third], [np.arange(outer_count) // third]
    heads = orbit_heads(turns)
    first_of = {}
    for k, (head, once, twice) in enumerate(heads):  # graded or not, an orbit's holes take its first's nodes
        nodes = with_copies(_circle_nodes(circles[head], counts[head]))
        for power, hole in enumerate((head, once, twice)):
            first_of[hole] = (nodes[power], third + sum(counts[h[0]] for h in heads[:k]), power)
    sizes = [np.full(outer_count, h_outer)]
    for hole in range(len(circles)):
        nodes, start, power = first_of[hole]
        fixed.append(nodes)
        edges = np.linalg.norm(np.roll(nodes, -1, axis=0) - nodes, axis=1)
        sizes.append(np.minimum(edges, np.roll(edges, 1)))  # a node's local size: its smaller edge
        orbit.append(start + np.arange(len(nodes)))
        copy.append(np.full(len(nodes), power))
    big = max(size, h_outer)
    fixed.append(np.zeros((1, 2)))  # the centre: no triangle holds a whole orbit (three copies around it)
    orbit.append(np.array([third + sum(counts)]))
    copy.append(np.zeros(1, np.int64))
    fronts = [_front(np.zeros(2), 1.0, h_outer, big, False, 2.0, multiple=3)[:-1]]  # its last: the centre
    for head, _, _ in heads:
        c = circles[head]
        centre, radius, h0 = np.asarray(c.center, float), c.node_radius(counts[head]), c.largest_edge(counts[head])
        fronts += [_front(centre, radius, h0, big, outward, 2.0) for outward in (False, True)]
    rings = sorted(((index, f, pts, h) for f, front in enumerate(fronts) for index, pts, h in front),
                   key=lambda item: (item[0], item[1]))
    points, local = np.concatenate(fixed), np.concatenate(sizes + [np.full(1, big)])
    orbits, copies = np.concatenate(orbit), np.concatenate(copy)
    for _, f, pts, h in rings:
        if f == 0:
            pts = pts[:len(pts) // 3]  # the axis's rings: their first third, the rest is its copies
        pts = keep_orbits(_clear_of_circles(pts, circles, [outer_count] + counts), points, local, h, KEEP_FRACTION)
        if not len(pts):
            continue
        turned, which = with_copies(pts).reshape(-1, 2), np.repeat(np.arange(3), len(pts))
        new = orbits.max() + 1 + np.tile(np.arange(len(pts)), 3)
        points, local = np.concatenate([points, turned]), np.concatenate([local, np.full(len(turned), h)])
        orbits, copies = np.concatenate([orbits, new]), np.concatenate([copies, which])
    return SymmetricPoints(points, orbits.astype(np.int64), copies.astype(np.int64))


def _circle_nodes(c: Circle, count: int) -> FloatArray:
    """A hole's ``count`` circle nodes (count, 2), counter-clockwise from its first angle."""
    return np.asarray(c.center, float) + c.node_radius(count) * np.column_stack(
        [np.cos(c.node_angles(count)), np.sin(c.node_angles(count))])


def turned_gradings(outer_count: int, circles: Sequence[Circle], size: float) -> list[Circle]:
    """``circles`` with each graded circle of a three-fold symmetric section given its orbit's first circle's
    grading, turned (the section's nodes are those turned nodes); any other section's circles as they are."""
    counts = [_hole_count(c, size, 2.0 * np.sin(np.pi / outer_count)) for c in circles]
    turns = hole_turns(np.array([c.center for c in circles], float), np.array([c.radius for c in circles]), counts)
    if not circles or outer_count % 3 or turns is None:
        return list(circles)
    out = list(circles)
    for head, once, twice in orbit_heads(turns):
        if circles[head].angles:
            for power, hole in ((1, once), (2, twice)):
                turned = np.sort(np.mod(np.asarray(circles[head].angles) + 2.0 * np.pi * power / 3, 2.0 * np.pi))
                out[hole] = replace(circles[hole], angles=tuple(turned.tolist()))
    return out


def _clear_of_circles(pts: FloatArray, circles: Sequence[Circle], counts: list[int]) -> FloatArray:
    """The points inside the unit disk and off every circle's edges' diametral disks (as :func:`_keep`)."""
    ok = np.linalg.norm(pts, axis=1) <= 1.0
    ok &= np.abs(np.linalg.norm(pts, axis=1) - 1.0) >= CIRCLE_CLEARANCE * 2.0 * np.sin(np.pi / counts[0])
    for c, n in zip(circles, counts[1:], strict=True):
        ok &= (np.abs(np.linalg.norm(pts - np.asarray(c.center), axis=1) - c.node_radius(n))
               >= CIRCLE_CLEARANCE * c.largest_edge(n))
    return pts[ok]


def cross_section(outer_count: int, circles: Sequence[Circle], size: float) -> CrossSection:
    """The unit disk triangulated with ``outer_count`` nodes on its circle and conforming to ``circles``.

    Parameters
    ----------
    outer_count : int, nodes on the unit circle at angles 2 pi k / outer_count (the export's angular count)
    circles : the holes, in fractions of the section's radius (nested holes allowed: a port in a chamber)
    size : float, largest edge length inside, in fractions of the section's radius

    Raises
    ------
    MeshError
        A hole outside the disk, or a circle whose edges the triangulation does not keep (a bug).
    """
    if outer_count < 3 or not size > 0:
        raise ValueError(f"cross_section: outer_count >= 3 and size > 0, got {outer_count}, {size}")
    _check_holes(circles)
    counts = [outer_count] + [_hole_count(c, size, 2.0 * np.sin(np.pi / outer_count)) for c in circles]
    symmetric = _symmetric_points(outer_count, circles, size, counts[1:])
    if symmetric is not None:
        triangles = _triangulate(symmetric.points)
        if symmetric.is_symmetric(triangles):  # else co-circular ties fell unevenly: the general points
            return _section(symmetric.points, triangles, circles, counts, symmetric.corner_order(triangles))
    fixed, sizes, rings = _candidates(outer_count, circles, size)
    points, _ = _keep(fixed, sizes, rings, circles)
    return _section(points, _triangulate(points), circles, counts, None)


def _triangulate(points: FloatArray) -> IntArray:
    """The Delaunay triangles (T, 3) of ``points``, counter-clockwise, none of zero area."""
    from scipy.spatial import Delaunay

    triangles = np.asarray(Delaunay(points).simplices, np.int64)
    u, v = (points[triangles[:, k]] - points[triangles[:, 0]] for k in (1, 2))
    area2 = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
    triangles = np.where((area2 < 0)[:, None], triangles[:, [0, 2, 1]], triangles)
    return triangles[np.abs(area2) > 1e-14]


def _section(points: FloatArray, triangles: IntArray, circles: Sequence[Circle], counts: list[int],
             corner_order: IntArray | None) -> CrossSection:
    """The cross-section of ``points`` (``counts[0]`` outer circle nodes, then ``counts[1 + h]`` of each hole
    h, then the rest) and their ``triangles``, its circles' edges checked present."""
    outer_count = counts[0]
    starts = np.cumsum([0] + counts)
    circle_nodes = tuple(np.arange(starts[k], starts[k + 1], dtype=np.int64) for k in range(1, len(counts)))
    _check_edges(triangles, [np.arange(outer_count)] + list(circle_nodes))
    centroids = points[triangles].mean(axis=1)
    inside = np.stack([np.linalg.norm(centroids - np.asarray(c.center), axis=1) < c.radius for c in circles],
                      axis=1) if circles else np.zeros((len(triangles), 0), bool)
    return CrossSection(points, triangles, inside, circle_nodes, outer_count, corner_order)


def _check_edges(triangles: IntArray, chains: list[np.ndarray]) -> None:
    edges = np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]]), axis=1)
    have = set(map(tuple, edges.tolist()))
    for k, chain in enumerate(chains):
        wanted = np.sort(np.column_stack([chain, np.roll(chain, -1)]), axis=1)
        missing = [e for e in map(tuple, wanted.tolist()) if e not in have]
        if missing:
            what = "the outer circle" if k == 0 else f"hole {k - 1}'s circle"
            raise MeshError(f"cross-section: {len(missing)} edges of {what} are not in the triangulation (first "
                            f"{missing[0]}); the section would not conform; this is a bug, please report the case")
