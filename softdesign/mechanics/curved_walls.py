"""Round chamber walls: the quadratic elements' midside nodes on a chamber's side wall placed on its circle.

Why
    A section's chamber is a polygon of wall nodes round a circle.  With
    straight edges, a hoop thread on it is a chain of chords with a kink at
    every corner, and refinement (:mod:`softdesign.mechanics.refine`) keeps the
    polygon facet for facet.  On the reinforced study section (a 2 mm chamber
    at 2.5 mm in a 10 mm section, tests/helpers/refinement_study.py) one red
    refinement moved the curvature by -3.10 % with an inscribed octagon and
    -3.15 % with an octagon of the circle's area; with this module's walls,
    -1.47 %, and the refined curvature is the same for 8, 16 and 32 wall nodes
    within 0.06 % (tests/mechanics/test_refinement_thread.py records the
    figures).
What
    :func:`round_chamber_walls` lists every edge of a chamber's side walls
    (the wall faces that span two levels; a cap lies in one) with its midside
    node on the chamber's surface: the circle through that level's wall nodes
    (fitted in their plane), or for an edge between two levels the circle
    midway between theirs, the node moved perpendicularly to the chamber's
    axis.  The elements that hold those nodes are isoparametric
    (:mod:`softdesign.mechanics.quadratic`, "Curved elements"), so the wall,
    the pressure on it and the thread on it follow the circle to the
    quadratic's order; the corners stay where the mesher put them.
Assumptions
    Each level's side-wall nodes of a chamber lie on a circle (checked:
    MeshError otherwise), a level being the nodes of one ``node_l``; a
    chamber's wall between two levels is the ruled surface between their
    circles.  Feeds' walls are left straight.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from softdesign.errors import MeshError
from softdesign.mechanics.quadratic import TET_EDGES, shape_values
from softdesign.mechanics.section import LEVEL_TOL_MM, SectionMesh
from softdesign.types import FloatArray, IntArray

#: A level's wall nodes are on one circle when their distances from the fitted centre differ by less than this
#: share of its radius.
CIRCLE_RTOL = 1e-6


def round_chamber_walls(section: SectionMesh) -> SectionMesh:
    """``section`` with its chambers' side-wall edges curved onto the chambers' circles (the module's docstring).

    Raises
    ------
    MeshError
        The section is curved already, or a chamber's wall nodes at a level are not on a circle.
    """
    if section.curved_edges is not None:
        raise MeshError("round chamber walls: the section's walls are curved already")
    faces = np.asarray(section.wall_faces, np.int64)
    levels = np.round(section.node_l / LEVEL_TOL_MM).astype(np.int64)
    side = levels[faces].min(axis=1) != levels[faces].max(axis=1)
    edges, positions = [], []
    for chamber in range(section.chamber_count):
        walls = faces[side & (section.face_chamber == chamber)]
        pairs = np.unique(np.sort(walls[:, [[0, 1], [1, 2], [2, 0]]].reshape(-1, 2), axis=1), axis=0)
        circles = _level_circles(section.points, np.unique(walls), levels, chamber)
        edges.append(pairs)
        positions.append(_on_surface(section.points, pairs, levels, circles))
    return replace(section, curved_edges=np.concatenate(edges), curved_midpoints=np.concatenate(positions))


def _level_circles(points: FloatArray, nodes: IntArray, levels: IntArray, chamber: int
                   ) -> dict[int, tuple[FloatArray, float]]:
    """Each level's circle (centre (3,) mm, radius mm) through the wall ``nodes`` of ``chamber`` at that level."""
    circles = {}
    for level in np.unique(levels[nodes]):
        ring = points[nodes[levels[nodes] == level]]
        centre, radius = _fitted_circle(ring)
        spread = np.abs(np.linalg.norm(ring - centre, axis=1) - radius).max()
        if len(ring) < 3 or spread > CIRCLE_RTOL * radius:
            raise MeshError(f"round chamber walls: chamber {chamber}'s {len(ring)} wall nodes at level "
                            f"{level * LEVEL_TOL_MM:.6g} mm are not on a circle (off by {spread:.3g} mm); the "
                            "curved walls need each level's wall nodes on the chamber's circle")
        circles[int(level)] = (centre, radius)
    return circles


def _fitted_circle(ring: FloatArray) -> tuple[FloatArray, float]:
    """The circle (centre (3,) mm, radius mm) through planar points ``ring`` (n, 3) (least squares, in their
    plane: exact for points on a circle however spaced)."""
    middle = ring.mean(axis=0)
    _, _, axes = np.linalg.svd(ring - middle)
    local = (ring - middle) @ axes[:2].T  # (n, 2) in the points' plane
    system = np.column_stack([2.0 * local, np.ones(len(local))])
    (cx, cy, c), *_ = np.linalg.lstsq(system, (local**2).sum(axis=1), rcond=None)
    return middle + cx * axes[0] + cy * axes[1], float(np.sqrt(c + cx**2 + cy**2))


def _on_surface(points: FloatArray, pairs: IntArray, levels: IntArray,
                circles: dict[int, tuple[FloatArray, float]]) -> FloatArray:
    """The midside positions (K, 3) mm of the edges ``pairs`` (K, 2) on the chamber's surface."""
    out = np.empty((len(pairs), 3))
    for k, (i, j) in enumerate(pairs):
        (ci, ri), (cj, rj) = circles[int(levels[i])], circles[int(levels[j])]
        centre, radius = 0.5 * (ci + cj), 0.5 * (ri + rj)
        offset = 0.5 * (points[i] + points[j]) - centre
        if levels[i] != levels[j]:  # off the axis between the two levels' centres
            axis = (cj - ci) / np.linalg.norm(cj - ci)
            along = (offset @ axis) * axis
            centre, offset = centre + along, offset - along
        out[k] = centre + radius * offset / np.linalg.norm(offset)
    return out


def curved_children(parent_nodes: FloatArray, children: IntArray) -> FloatArray:
    """The midside positions (E, 8, 6, 3) mm of the red children's edges (in :data:`TET_EDGES`' order) under
    their parents' quadratic maps, so that a refined curved mesh is nested in its parent.

    Parameters
    ----------
    parent_nodes : (E, 10, 3) float, mm -- each parent's ten reference nodes (corners, then midside nodes)
    children : (E, 8, 4) int -- each child's corners as the parent's local nodes 0..9
    """
    local = np.concatenate([np.eye(4), 0.5 * (np.eye(4)[TET_EDGES[:, 0]] + np.eye(4)[TET_EDGES[:, 1]])])  # (10, 4)
    corners = local[children]  # (E, 8, 4, 4): the children's corners' barycentric coordinates in their parent
    middles = 0.5 * (corners[:, :, TET_EDGES[:, 0]] + corners[:, :, TET_EDGES[:, 1]])  # (E, 8, 6, 4)
    E = len(children)
    shapes = shape_values(middles.reshape(-1, 4)).reshape(E, 8, 6, 10)
    return np.einsum("ecka,eai->ecki", shapes, parent_nodes)
