"""Ties between two meshes that meet on a common plane face: stiff linear springs (a penalty), both ways.

At a joint, section i's tip face and section i + 1's base face cover the
same plane polygon with different triangles.  Every node of each face (the
6-node faces' corners and midpoints) is tied to the point of the other face
it lies on: the constraint ``g = u_a - sum_b N_b(xi_a) u_b = 0`` (``N_b``
the other face's 6-node shape functions at the node's place), enforced by
the energy ``k |g|^2 / 2``.  Both ways, so neither face can open between
the other's nodes.  A displacement tie between points that coincide in the
reference is a position tie, so it holds at any rotation: the springs are
linear and constant (``S = k C^T C``).

The stiffness ``k = TIE_FACTOR E h`` (mN/mm), ``h`` the faces' mean edge:
about ``TIE_FACTOR`` times the silicone's own over an element, so the gap it
leaves is about 1 / TIE_FACTOR of the elements' strain times h (the solve
reports the largest gap), while the Newton matrix's condition grows by the
same factor only (the hoop thread is already 10^4-10^5 times stiffer than
the silicone).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from softdesign.errors import MeshError
from softdesign.mechanics.quadratic import QuadraticMesh, quadratic_faces
from softdesign.mechanics.tets import boundary_faces
from softdesign.types import FloatArray, IntArray

#: The ties' stiffness over the silicone's across an element (module docstring).
TIE_FACTOR = 1.0e4
#: A node lies on a face when its barycentric coordinates in it are above this (the faces share one polygon).
ON_FACE_TOL = -1e-6
#: A joint's faces lie in one plane within this share of their size.
PLANE_TOL = 1e-6


def joint_faces(tets: IntArray, layer_nodes: IntArray) -> IntArray:
    """The boundary faces (k, 3) of ``tets`` (E, 4) whose three corners are all in ``layer_nodes``."""
    faces = boundary_faces(np.asarray(tets, np.int64))
    return faces[np.isin(faces, layer_nodes).all(axis=1)]


def _six_node_shapes(bary: FloatArray) -> FloatArray:
    """6-node triangle shape functions (n, 6) at barycentric ``bary`` (n, 3): corners, then edges 01, 12, 20."""
    corners = bary * (2.0 * bary - 1.0)
    edges = 4.0 * bary[:, [0, 1, 2]] * bary[:, [1, 2, 0]]
    return np.concatenate([corners, edges], axis=1)


def _plane(points: FloatArray, label: str) -> tuple[FloatArray, FloatArray]:
    """An origin (3,) and in-plane axes (2, 3) of points (n, 3) that lie in one plane (MeshError if not)."""
    origin = points.mean(axis=0)
    _, s, vt = np.linalg.svd(points - origin, full_matrices=False)
    if s[2] > PLANE_TOL * s[0] * np.sqrt(len(points)):
        raise MeshError(f"device mesh: {label}'s faces are not plane (out of plane {s[2]:.3g} against {s[0]:.3g})")
    return origin, vt[:2]


def _tie_rows(points: FloatArray, nodes: IntArray, faces6: IntArray, label: str) -> tuple[IntArray, FloatArray]:
    """For each of ``nodes``, the 6 nodes of the face (``faces6`` (k, 6)) it lies on and their shape values."""
    origin, axes = _plane(points[np.concatenate([nodes, faces6.ravel()])], label)
    xy = (points - origin) @ axes.T
    corners = xy[faces6[:, :3]]  # (k, 3, 2)
    edges = np.stack([corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]], axis=2)  # (k, 2, 2)
    inverse = np.linalg.inv(edges)
    local = np.einsum("kij,nkj->nki", inverse, xy[nodes][:, None, :] - corners[None, :, 0, :])  # (n, k, 2)
    bary = np.concatenate([1.0 - local.sum(axis=2, keepdims=True), local], axis=2)
    best = np.argmax(bary.min(axis=2), axis=1)
    chosen = bary[np.arange(len(nodes)), best]
    if np.any(chosen.min(axis=1) < ON_FACE_TOL):
        worst = int(np.argmin(chosen.min(axis=1)))
        raise MeshError(f"device mesh: {label}: node {int(nodes[worst])} lies on no face of the other section "
                        f"(barycentric {chosen[worst].min():.3g}); the sections' ends do not meet")
    return faces6[best], _six_node_shapes(chosen)


@dataclass(frozen=True)
class Ties:
    """The joints' constraints ``g = C u`` (3T,), mN/mm springs on each, node-major (a tie's x, y, z rows)."""

    constraint: sp.csr_matrix  #: (3T, 3N)
    stiffness: FloatArray  #: (3T,) mN/mm

    def springs(self) -> sp.csr_matrix:
        """The spring matrix ``C^T diag(k) C`` (3N, 3N), mN/mm."""
        return sp.csr_matrix(self.constraint.T @ sp.diags(self.stiffness) @ self.constraint)

    def largest_gap_mm(self, u: FloatArray) -> float:
        """The largest distance (mm) between a tied node and its place on the other face, at displacement ``u``."""
        if self.constraint.shape[0] == 0:
            return 0.0
        g = (self.constraint @ np.asarray(u, float).ravel()).reshape(-1, 3)
        return float(np.linalg.norm(g, axis=1).max())


def tie_joints(mesh: QuadraticMesh, joints: list[tuple[IntArray, IntArray]], modulus_kpa: float) -> Ties:
    """The ties of every joint (its proximal tip faces and distal base faces, corners (k, 3) each)."""
    n = mesh.dof_count
    rows, cols, values, stiffness, count = [], [], [], [], 0
    for j, (tip, base) in enumerate(joints):
        if not len(tip) or not len(base):
            raise MeshError(f"device mesh: joint {j + 1} (sections {j + 1} and {j + 2}) has no end faces")
        faces = [quadratic_faces(mesh, f) for f in (tip, base)]
        corners = mesh.points[tip]
        h = float(np.mean(np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2)))
        for own, other in ((faces[1], faces[0]), (faces[0], faces[1])):
            nodes = np.unique(own)
            targets, shapes = _tie_rows(mesh.points, nodes, other, f"joint {j + 1}")
            for c in range(3):
                r = count + 3 * np.arange(len(nodes)) + c
                rows += [r, np.repeat(r, 6)]
                cols += [3 * nodes + c, (3 * targets + c).ravel()]
                values += [np.ones(len(nodes)), -shapes.ravel()]
            count += 3 * len(nodes)
            stiffness.append(np.full(3 * len(nodes), TIE_FACTOR * modulus_kpa * h))
    if not joints:
        return Ties(sp.csr_matrix((0, n)), np.zeros(0))
    C = sp.csr_matrix((np.concatenate(values), (np.concatenate(rows), np.concatenate(cols))), shape=(count, n))
    return Ties(C, np.concatenate(stiffness))
