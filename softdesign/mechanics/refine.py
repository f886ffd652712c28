"""Uniform (red) refinement of a section's tetrahedral mesh, its named sets carried along.

Each tetrahedron is split into eight through its six edge midpoints
(Bey, "Tetrahedral grid refinement", Computing 55, 1995): four corner
tetrahedra, each the parent shrunk by one half about one of its corners, and
four in the inner octahedron, cut along its shortest diagonal (the best shaped
of the three choices; ties go to the first in the order m01-m23, m02-m13,
m03-m12, so the same mesh gives the same split).  Each boundary triangle is
split into four through the same midpoints, so the refined mesh is conforming
and its boundary is the parent's, facet for facet: a study over refinements
measures the discretisation error alone, on one faceted geometry.

What a :class:`~softdesign.mechanics.section.SectionMesh` carries:

- points: the parent's, then one midpoint per edge (numbered as
  :func:`softdesign.mechanics.quadratic.edge_midpoints` numbers them);
- base: a midpoint is fixed when both ends of its edge are (the base is a
  plane face, and an edge between two of its nodes lies in it);
- wall faces: four children each, with the parent's chamber and winding;
- node levels: a midpoint's is the mean of its edge's ends' (exact where the
  level is linear along the edge, as on a straight section);
- the centerline and the chamber angles: kept as they are, so every level
  measures its arc on the same reference points;
- curved edges (:mod:`softdesign.mechanics.curved_walls`): a curved parent is
  split through its quadratic map: the children's corners at its midside
  nodes, and every child's midside nodes where the parent's map puts its
  edges' middles.  A quadratic map on a sub-tetrahedron is quadratic, so the
  children's maps are the parent's: the refined geometry is the parent's
  (curved walls stay the same curve), and the refinement is nested.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from softdesign.errors import MeshError
from softdesign.mechanics.curved_walls import curved_children
from softdesign.mechanics.quadratic import TET_EDGES, edge_midpoints, quadratic_mesh
from softdesign.mechanics.section import SectionMesh
from softdesign.mechanics.tets import make_tet_mesh
from softdesign.types import FloatArray, IntArray

#: The most refinements one call makes: each multiplies the elements by 8.
MAX_LEVELS = 3

#: Corner children in the ten local nodes (corners 0..3, midpoints of edges 01, 02, 03, 12, 13, 23 as 4..9).
_CORNER_CHILDREN = np.array([[0, 4, 5, 6], [4, 1, 7, 8], [5, 7, 2, 9], [6, 8, 9, 3]])
#: The inner octahedron's three diagonals and, for each, the four other midpoints in order around it.
_DIAGONALS = np.array([[4, 9], [5, 8], [6, 7]])
_RINGS = np.array([[5, 6, 8, 7], [4, 6, 9, 7], [4, 5, 9, 8]])
#: A triangle's four children in its six local nodes (corners 0..2, midpoints of 01, 12, 20 as 3..5).
_FACE_CHILDREN = np.array([[0, 3, 5], [3, 1, 4], [5, 4, 2], [3, 4, 5]])


def refine_tets(points: FloatArray, tets: IntArray) -> tuple[FloatArray, IntArray, IntArray]:
    """One red refinement of positively oriented ``tets`` (E, 4) on ``points`` (V, 3) mm.

    Returns
    -------
    points : (V + M, 3) float, mm: the parent's points, then the midpoints of its M edges
    tets : (8 E, 4) int, positively oriented; element ``8 e + c`` is child ``c`` of parent ``e``
    edges : (M, 2) int, sorted corner pairs: node ``V + k`` is the midpoint of ``edges[k]``
    """
    fine, out, edges, _ = _split(points, tets)
    return fine, out, edges


def _split(points: FloatArray, tets: IntArray) -> tuple[FloatArray, IntArray, IntArray, IntArray]:
    """:func:`refine_tets`'s points, children and edges, and the children's corners (E, 8, 4) as their parents'
    local nodes 0..9 (corners, then the midpoints of edges 01, 02, 03, 12, 13, 23)."""
    V = len(points)
    edges, mids = edge_midpoints(tets, V)
    fine = np.concatenate([points, 0.5 * (points[edges[:, 0]] + points[edges[:, 1]])])
    local = np.concatenate([tets, mids], axis=1)  # (E, 10)
    lengths = np.stack([np.linalg.norm(fine[local[:, a]] - fine[local[:, b]], axis=1) for a, b in _DIAGONALS], axis=1)
    choice = np.argmin(lengths, axis=1)
    diagonal, ring = _DIAGONALS[choice], _RINGS[choice]  # (E, 2), (E, 4)
    inner = np.stack([np.concatenate([diagonal, ring[:, [k, (k + 1) % 4]]], axis=1) for k in range(4)], axis=1)
    children = np.concatenate([np.broadcast_to(_CORNER_CHILDREN, (len(tets), 4, 4)), inner], axis=1)  # (E, 8, 4)
    out = np.take_along_axis(local, children.reshape(len(tets), -1), axis=1).reshape(-1, 4)
    return fine, _positive(fine, out), edges, children


def _positive(points: FloatArray, tets: IntArray) -> IntArray:
    """``tets`` with each negatively oriented one's last two corners swapped (the inner four's winding varies)."""
    c = points[tets]
    det = np.einsum("ei,ei->e", c[:, 1] - c[:, 0], np.cross(c[:, 2] - c[:, 0], c[:, 3] - c[:, 0]))
    out = tets.copy()
    out[det < 0, 2], out[det < 0, 3] = tets[det < 0, 3], tets[det < 0, 2]
    return out


def refine_faces(faces: IntArray, edges: IntArray, vertex_count: int) -> IntArray:
    """Triangles (F, 3) split into four each (4 F, 3), same winding; child ``4 f + c`` of parent ``f``.

    ``edges`` (M, 2) are the refined mesh's sorted parent edges (midpoint of ``edges[k]`` is ``vertex_count + k``).

    Raises
    ------
    MeshError
        A triangle's side is not an edge of the mesh.
    """
    keys = edges[:, 0] * vertex_count + edges[:, 1]
    sides = np.sort(faces[:, [[0, 1], [1, 2], [2, 0]]], axis=2)  # (F, 3, 2)
    wanted = sides[..., 0] * vertex_count + sides[..., 1]
    at = np.clip(np.searchsorted(keys, wanted), 0, len(keys) - 1)
    if np.any(keys[at] != wanted):
        bad = int(np.argwhere(keys[at] != wanted)[0, 0])
        raise MeshError(f"refine: face {bad} {faces[bad].tolist()} has a side that is no edge of the tetrahedra; "
                        "wall faces must be faces of the mesh")
    local = np.concatenate([faces, vertex_count + at], axis=1)  # (F, 6)
    return np.take_along_axis(local, np.tile(_FACE_CHILDREN.ravel(), (len(faces), 1)), axis=1).reshape(-1, 3)


def refine_section(section: SectionMesh, levels: int = 1) -> SectionMesh:
    """``section`` refined ``levels`` times (1 .. MAX_LEVELS), its named sets carried (see the module's docstring).

    Raises
    ------
    ValueError
        ``levels`` outside 1 .. MAX_LEVELS.
    MeshError
        A wall face is not a face of the tetrahedra.
    """
    if not 1 <= levels <= MAX_LEVELS:
        raise ValueError(f"refine: levels must be 1 .. {MAX_LEVELS} (each multiplies the elements by 8); "
                         f"got {levels}")
    for _ in range(levels):
        section = _refine_once(section)
    return section


def _refine_once(section: SectionMesh) -> SectionMesh:
    """One red refinement of ``section`` and its named sets."""
    V = len(section.points)
    points, tets, edges, children = _split(np.asarray(section.points, float), np.asarray(section.tets, np.int64))
    curved_edges, curved_midpoints = None, None
    if section.curved_edges is not None:
        points, tets, curved_edges, curved_midpoints = _curved_split(section, points, tets, children)
    base = np.concatenate([section.base, section.base[edges[:, 0]] & section.base[edges[:, 1]]])
    node_l = np.concatenate([section.node_l, 0.5 * (section.node_l[edges[:, 0]] + section.node_l[edges[:, 1]])])
    faces = refine_faces(np.asarray(section.wall_faces, np.int64), edges, V)
    return replace(section, points=points, tets=tets, base=base, wall_faces=faces,
                   face_chamber=np.repeat(np.asarray(section.face_chamber, np.int64), 4), node_l=node_l,
                   curved_edges=curved_edges, curved_midpoints=curved_midpoints)


def _curved_split(section: SectionMesh, points: FloatArray, tets: IntArray, children: IntArray
                  ) -> tuple[FloatArray, IntArray, IntArray, FloatArray]:
    """A curved ``section``'s red split (straight ``points`` and children ``tets`` from :func:`_split`) put on its
    parents' maps: the points, the children (oriented on them), and the children's curved edges (K, 2) and their
    midside nodes (K, 3) mm (the module's docstring)."""
    parent = quadratic_mesh(make_tet_mesh(np.asarray(section.points, float), np.asarray(section.tets, np.int64)),
                            section.curved_edges, section.curved_midpoints)
    V = len(section.points)
    moved = np.any(parent.points[V:] != points[V:], axis=1)  # the parent's midside nodes off their middles
    curved = np.flatnonzero(np.concatenate([np.zeros(V, bool), moved])[parent.cells].any(axis=1))
    points = parent.points  # numbered as the split's: a corner, then the midside node of each parent edge
    middles = curved_children(parent.points[parent.cells[curved]], children[curved])  # (C, 8, 6, 3)
    corners = tets.reshape(-1, 8, 4)[curved]  # (C, 8, 4)
    pairs = np.sort(corners[:, :, TET_EDGES].reshape(-1, 2), axis=1)
    kept, first = np.unique(pairs, axis=0, return_index=True)
    return points, _positive(points, tets), kept, middles.reshape(-1, 3)[first]
