"""Linear tetrahedra: reference shape gradients, volumes and the deformation gradient of each element.

A tetrahedron's displacement is linear, so its deformation gradient ``F`` is
constant over it and one point integrates every element quantity exactly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.errors import MeshError
from softdesign.types import FloatArray, IntArray

#: Smallest reference volume of an element relative to the mean (a sliver below it is refused), 1.
MIN_RELATIVE_VOLUME = 1e-9


@dataclass(frozen=True)
class TetMesh:
    """A reference (unloaded) linear tetrahedral mesh and its shape gradients.

    Attributes
    ----------
    points : (V, 3) float, mm
    tets : (E, 4) int, positively oriented (``det[x1-x0, x2-x0, x3-x0] > 0``)
    grads : (E, 4, 3) float, 1/mm: ``dN_a/dX`` of each element's four shape functions
    volumes : (E,) float, mm^3
    node_volumes : (V,) float, mm^3: a quarter of each touching element's volume (the lumped patch volume)
    """

    points: FloatArray
    tets: IntArray
    grads: FloatArray
    volumes: FloatArray
    node_volumes: FloatArray

    @property
    def dof_count(self) -> int:
        """Three displacement unknowns per node."""
        return 3 * len(self.points)


def node_dofs(nodes: IntArray) -> IntArray:
    """Global unknowns (K, 3 n) of each row of ``nodes`` (K, n) (an element's, a face's, a fibre's), node-major:
    ``3 node + component``."""
    return (3 * nodes[:, :, None] + np.arange(3)[None, None, :]).reshape(len(nodes), 3 * nodes.shape[1])


def summed(index: IntArray, values: FloatArray, length: int) -> FloatArray:
    """``out[i] = sum of values[index == i]`` (length,): the scatter-add of an assembly."""
    return np.asarray(np.bincount(index.ravel(), values.ravel(), minlength=length), dtype=np.float64)


def edge_matrices(points: FloatArray, tets: IntArray) -> FloatArray:
    """Columns ``x1 - x0, x2 - x0, x3 - x0`` (E, 3, 3) of each tetrahedron."""
    corners = points[tets]
    return (corners[:, 1:, :] - corners[:, :1, :]).transpose(0, 2, 1)


def make_tet_mesh(points: npt.ArrayLike, tets: npt.ArrayLike) -> TetMesh:
    """The reference mesh of ``points`` (V, 3) mm and ``tets`` (E, 4), with every node used.

    Raises
    ------
    MeshError
        Bad shapes, an index out of range, an unused node, or an element that
        is inverted or degenerate (its volume is stated).
    """
    points, tets = np.asarray(points, float), np.asarray(tets, np.int64)
    if points.ndim != 2 or points.shape[1] != 3 or tets.ndim != 2 or tets.shape[1] != 4 or len(tets) == 0:
        raise MeshError(f"mechanics: expected points (V, 3) and tets (E, 4); got {points.shape} and {tets.shape}")
    if tets.min() < 0 or tets.max() >= len(points) or not np.all(np.isfinite(points)):
        raise MeshError(f"mechanics: tet indices must lie in [0, {len(points)}) and points be finite")
    used = np.zeros(len(points), bool)
    used[tets.ravel()] = True
    if not used.all():
        raise MeshError(f"mechanics: {int((~used).sum())} nodes belong to no element; drop them first")
    edges = edge_matrices(points, tets)
    volumes = np.linalg.det(edges) / 6.0
    worst = int(np.argmin(volumes))
    if volumes[worst] <= MIN_RELATIVE_VOLUME * abs(volumes.mean()):
        raise MeshError(f"mechanics: element {worst} is inverted or degenerate (volume {volumes[worst]:.3g} mm^3, "
                        f"mean {volumes.mean():.3g}); orient every tetrahedron positively")
    inverse = np.linalg.inv(edges)  # rows: gradients of N1, N2, N3
    grads = np.concatenate([-inverse.sum(axis=1, keepdims=True), inverse], axis=1)
    node_volumes = summed(tets, np.repeat(volumes / 4.0, 4), len(points))
    return TetMesh(points, tets, grads, volumes, node_volumes)


def deformation_gradients(mesh: TetMesh, displacement: FloatArray) -> FloatArray:
    """``F = I + du/dX`` (E, 3, 3) of each element for nodal ``displacement`` (V, 3) mm."""
    u = displacement[mesh.tets]
    return np.eye(3)[None] + np.einsum("eai,eaJ->eiJ", u, mesh.grads)


#: The four faces of a tetrahedron (local corners), each wound with its normal out of the element.
_TET_FACES = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def boundary_faces(tets: IntArray) -> IntArray:
    """Triangles (F, 3) on the boundary of positively oriented ``tets`` (E, 4), normals out of the material.

    A face is on the boundary when exactly one element has it; the result is sorted (same input, same output).
    """
    faces = tets[:, _TET_FACES].reshape(-1, 3)
    keys = np.sort(faces, axis=1)
    _, first, counts = np.unique(keys, axis=0, return_index=True, return_counts=True)
    return faces[np.sort(first[counts == 1])]
