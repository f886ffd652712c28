"""Round chamber walls: the quadratic elements' midside nodes on a chamber's side wall placed on its circle.

Why
    A section's chamber is a polygon of wall nodes round a circle.  With
    straight edges, a hoop thread on it is a chain of chords with a kink at
    every corner, and refinement (:mod:`softdesign.mechanics.refine`) keeps the
    polygon facet for facet.  On the reinforced study section (a 2 mm chamber
    at 2.5 mm in a 10 mm section, tests/helpers/refinement_study.py) one red
    refinement moved the curvature by -3.10 % with an inscribed octagon and
    -3.15 % with an octagon of the circle's area; with this module's walls,
    -1.48 %, and the refined curvature is the same for 8, 16 and 32 wall nodes
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
Spread
    A wall's midside node moves off its chord by up to a tenth of the chord
    (an octagon's sagitta), into the element beside it.  When that element is
    thin across the wall (the swept mesher's prisms split into tetrahedra of
    0.5 mm by 6-8 mm), the wall's whole bow folds its map: on the sample
    single-supply device one element of section 3 had ``det(dX/dxi)`` below
    zero at a node (-0.29 of its straight value), and the smallest over
    every curved element of the five sections, at its nodes and between,
    was 0.45, 0.43, -0.29, 0.41, 0.45.  So the walls' midside offsets are
    carried into the rubber (:func:`_spread_inwards`): a discrete harmonic
    extension with every corner held, as moving-mesh methods move a
    boundary's displacement into a mesh, each element's Laplacian weighted
    by the inverse of its volume so that small elements move nearly rigidly
    (Jacobian-based stiffening: Stein, Tezduyar and Benney, J. Appl. Mech.
    70, 2003).  Measured on the same device: 0.64, 0.55, 0.14, 0.58, 0.63
    (unweighted: 0.62, 0.51, -0.02, 0.51, 0.55); on the sample aorta's three
    sections 0.040, 0.29, 0.18 before, 0.046, 0.44, 0.40 after (its smallest
    is an element with three corners on one chamber's ring, whose two curved
    edges meet nearly tangent at the middle corner: no interior offset
    changes that).
Folds
    Where an element's map would still fold (``det(dX/dxi) <= 0`` at a node
    or a quadrature point), the walls' edges at its corners stay straight
    (chords, as the straight model has them), the spread holds its midside
    nodes where they are, and the spread is found again, for up to
    :data:`UNFOLD_ROUNDS` rounds: a section the curved walls cannot follow
    everywhere is meshed with them where they can, not refused.  At the
    default mesh none of the sample single-supply device's or the VMTK
    aorta's elements fold; the per-chamber sample's section 2 at a coarse
    mesh (4 mm across, 10 mm layers, 8 nodes round) had slivers 7.7 mm long
    and 0.3 mm across that the spread folded (-0.27 of the straight ``det``
    at a corner), one per layer as the last was held: five rounds.
    :func:`~softdesign.mechanics.quadratic.quadratic_mesh` still refuses a
    map that folds, the last guard.
Assumptions
    Each level's side-wall nodes of a chamber lie on a circle (checked:
    MeshError otherwise), a level being the nodes of one ``node_l``; a
    chamber's wall between two levels is the ruled surface between their
    circles.  Feeds' walls are left straight.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import spsolve

from softdesign.errors import MeshError
from softdesign.mechanics.quadratic import (
    TET_EDGES,
    QuadraticMesh,
    midpoint_nodes,
    quadratic_mesh,
    shape_values,
    smallest_jacobians,
)
from softdesign.mechanics.section import LEVEL_TOL_MM, SectionMesh
from softdesign.mechanics.tets import boundary_faces, make_tet_mesh
from softdesign.types import FloatArray, IntArray

#: A level's wall nodes are on one circle when their distances from the fitted centre differ by less than this
#: share of its radius.
CIRCLE_RTOL = 1e-6
#: The walls' bow is spread over the elements within this many node rings of a curved wall edge.
SPREAD_RINGS = 2
#: Rounds of unfolding ("Folds"): the walls' edges at a folded element kept straight, its spread midside nodes held.
UNFOLD_ROUNDS = 32


def round_chamber_walls(section: SectionMesh, spread: bool = True) -> SectionMesh:
    """``section`` with its chambers' side-wall edges curved onto the chambers' circles (the module's docstring);
    ``spread``: their bow carried into the rubber beside them ("Spread"; False: the walls' edges alone).

    Raises
    ------
    MeshError
        The section is curved already, or a chamber's wall nodes at a level are not on a circle.
    """
    if section.curved_edges is not None:
        raise MeshError("round chamber walls: the section's walls are curved already")
    faces, side, levels = _side_walls(section)
    edges, positions = [], []
    for chamber in range(section.chamber_count):
        walls = faces[side & (section.face_chamber == chamber)]
        pairs = _face_edges(walls)
        circles = _level_circles(section.points, np.unique(walls), levels, chamber)
        edges.append(pairs)
        positions.append(_on_surface(section.points, pairs, levels, circles))
    return _unfolded(section, np.concatenate(edges), np.concatenate(positions), spread)


def _unfolded(section: SectionMesh, walls: IntArray, midpoints: FloatArray, spread: bool) -> SectionMesh:
    """``section`` with the wall edges ``walls`` (K, 2) curved to ``midpoints`` (K, 3) mm (and, if ``spread``, their
    bow spread), except where an element's map would fold: the walls' edges at its corners stay straight, and the
    spread leaves its midside nodes where they are, in up to :data:`UNFOLD_ROUNDS` rounds (module docstring,
    "Folds")."""
    straight = quadratic_mesh(make_tet_mesh(section.points, section.tets))
    keep = np.ones(len(walls), bool)
    pinned = np.zeros(len(straight.points), bool)  # midside nodes the spread must leave where they are
    for _ in range(UNFOLD_ROUNDS):
        edges, positions = walls[keep], midpoints[keep]
        if spread:
            inner, moved = _spread_inwards(section, straight, edges, positions, pinned)
            edges, positions = np.concatenate([edges, inner]), np.concatenate([positions, moved])
        folded = _folded(straight, edges, positions)
        touching = keep & np.isin(walls, section.tets[folded]).any(axis=1)
        by_spread = straight.cells[folded][:, 4:].ravel()
        if not touching.any() and pinned[by_spread].all():
            break
        keep &= ~touching  # a wall's bow folds them: their walls' edges straight
        pinned[by_spread] = True  # the spread folds them: their midside nodes held
    return replace(section, curved_edges=edges, curved_midpoints=positions)


def _folded(straight: QuadraticMesh, edges: IntArray, midpoints: FloatArray) -> IntArray:
    """The elements (n,) of the ``straight`` quadratic mesh whose map folds (``det(dX/dxi) <= 0`` at a node or a
    quadrature point: :func:`~softdesign.mechanics.quadratic.smallest_jacobians`) with the midside nodes of
    ``edges`` (K, 2) at ``midpoints`` (K, 3) mm."""
    points = straight.points.copy()
    points[midpoint_nodes(straight, edges)] = midpoints
    return np.flatnonzero(smallest_jacobians(points[straight.cells]) <= 0.0)


def _spread_inwards(section: SectionMesh, straight: QuadraticMesh, walls: IntArray, midpoints: FloatArray,
                    pinned: np.ndarray | None = None) -> tuple[IntArray, FloatArray]:
    """The interior edges (K, 2) near the curved walls and their midside positions (K, 3) mm: the walls' midside
    offsets carried into the rubber by a discrete harmonic extension (the quadratic elements' Laplacian on the
    straight mesh, each element's weighted by the patch's largest volume over its own, every corner and every
    other boundary midside node held), over the elements within :data:`SPREAD_RINGS` node rings of a curved wall
    edge, so that no element next to a wall takes the wall's whole bow (module docstring, "Spread"); ``straight``:
    the section's quadratic mesh with every edge straight; ``pinned`` (its nodes,) bool: midside nodes held too."""
    linear = straight.linear
    V = len(linear.points)
    wall_nodes = midpoint_nodes(straight, walls)
    offsets = np.zeros((len(straight.points), 3))
    offsets[wall_nodes] = midpoints - straight.points[wall_nodes]
    patch = _near(linear.tets, np.unique(walls), SPREAD_RINGS)
    held = np.ones(len(straight.points), bool)
    held[np.unique(straight.cells[patch][:, 4:])] = False
    held[np.unique(straight.cells[~patch][:, 4:])] = True  # the patch's rim: shared with elements outside it
    held[midpoint_nodes(straight, _boundary_edges(linear.tets))] = True
    if pinned is not None:
        held |= pinned
    free = np.flatnonzero(~held)
    if len(free) == 0:
        return np.zeros((0, 2), np.int64), np.zeros((0, 3))
    cells = straight.cells[patch]
    stiffer = linear.volumes[patch].max() / linear.volumes[patch]  # small elements move nearly rigidly
    local = np.einsum("eqai,eqbi,eq,e->eab", straight.grads[patch], straight.grads[patch], straight.weights[patch],
                      stiffer)
    rows = np.broadcast_to(cells[:, :, None], local.shape).ravel()
    cols = np.broadcast_to(cells[:, None, :], local.shape).ravel()
    n = len(straight.points)
    laplacian = sparse.csr_matrix((local.ravel(), (rows, cols)), shape=(n, n))
    inner = laplacian[free][:, free].tocsc()
    given = -(laplacian[free] @ offsets)
    offsets[free] = spsolve(inner, given).reshape(-1, 3)
    return straight.edges[free - V], straight.points[free] + offsets[free]


def _near(tets: IntArray, nodes: IntArray, rings: int) -> np.ndarray:
    """The elements (E,) bool within ``rings`` node rings of ``nodes``: ring 1 holds a node, each next ring shares
    a node with the last."""
    reached = np.zeros(int(tets.max()) + 1, bool)
    reached[nodes] = True
    inside = reached[tets].any(axis=1)
    for _ in range(rings - 1):
        reached[tets[inside]] = True
        inside = reached[tets].any(axis=1)
    return np.asarray(inside, bool)


def _boundary_edges(tets: IntArray) -> IntArray:
    """The corner pairs (K, 2) of the edges of the mesh's boundary faces."""
    return _face_edges(boundary_faces(tets))


def on_walls(section: SectionMesh) -> np.ndarray:
    """Which of ``section``'s curved edges (K,) bool lie on a chamber's side wall (their midside nodes on its
    circle); the others are the rubber's, moved by the spread (module docstring)."""
    if section.curved_edges is None:
        return np.zeros(0, bool)
    faces, side, _ = _side_walls(section)
    walls = _face_edges(faces[side])
    n = int(section.points.shape[0])
    curved = np.sort(np.asarray(section.curved_edges, np.int64), axis=1)
    return np.isin(curved[:, 0] * n + curved[:, 1], walls[:, 0] * n + walls[:, 1])


def _side_walls(section: SectionMesh) -> tuple[IntArray, np.ndarray, IntArray]:
    """The wall faces (F, 3), which of them are side walls (F,) bool (spanning two levels; a cap lies in one) and
    every node's level (V,) (its ``node_l`` in LEVEL_TOL_MM)."""
    faces = np.asarray(section.wall_faces, np.int64)
    levels = np.round(section.node_l / LEVEL_TOL_MM).astype(np.int64)
    return faces, levels[faces].min(axis=1) != levels[faces].max(axis=1), levels


def _face_edges(faces: IntArray) -> IntArray:
    """The sorted unique corner pairs (K, 2) of triangles ``faces`` (F, 3)."""
    return np.unique(np.sort(faces[:, [[0, 1], [1, 2], [2, 0]]].reshape(-1, 2), axis=1), axis=0)


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
