"""Quadratic (10-node) tetrahedra with a mean dilatation per element: forces and the exact tangent.

Why quadratic
    A linear tetrahedron's strain is constant: a chamber wall one element
    thick cannot bend, and the section's curvature under a chamber pressure
    jumped between 0.0012 and 0.0023 1/mm as the linear mesh went from 2 mm to
    1 mm (no convergence).  A quadratic tetrahedron's strain is linear, so a
    wall one element thick bends.
Formulation (near-incompressible, no locking)
    The element's nodes are its four corners and six edge midpoints
    (``cells[:, :4]`` corners, then edges 01, 02, 03, 12, 13, 23).  The
    isochoric energy is integrated at four points (degree 2); the volumetric
    energy acts on the element's *mean* dilatation ``theta_e = v_e / V_e``
    (deformed over reference volume), the P2/P0 mean-dilatation form
    (Simo, Taylor and Pister, CMAME 51, 1985; the isochoric energy depends on
    ``F`` only through ``J^(-1/3) F``, so the three-field form condenses to)::

        Psi(x) = sum_e [ sum_q w_eq W_iso(F_q) + V_e U(v_e / V_e) ],   v_e = sum_q w_eq J_q.

    One volume constraint per element against about 4.4 displacement unknowns
    per element: it does not lock (the tube test checks the incompressible
    answer).  It is displacement-only and element-local, so its tangent is the
    exact Hessian and as sparse as the mesh:

        f_e = sum_q w (P_iso : dN/dX) + p_e dv_e/dx,   dv_e/dx_a = sum_q w J_q g_qa,
        K_e = sum_q w dN/dX . A_iso . dN/dX + p_e d2v_e/dx2 + U''/V_e dv_e/dx (x) dv_e/dx,
        d2v_e/dx_a,i dx_b,k = sum_q w J_q (g_qa,i g_qb,k - g_qa,k g_qb,i),

    with ``p_e = U'(theta_e)``, ``g = F^-T dN/dX`` the spatial gradients.
Curved (isoparametric) elements
    An element may have midside nodes off its straight edges' middles (a
    chamber's wall on its true circle: :mod:`softdesign.mechanics.curved_walls`).
    Its reference map ``X(xi) = sum_a N_a(xi) X_a`` is then quadratic, and at
    each point ``dN/dX = dN/dxi (dX/dxi)^-1`` and the weight is
    ``det(dX/dxi) / 24`` (the unit tetrahedron's volume 1/6, a quarter each);
    its volume ``V_e`` is the sum of its weights, so that ``theta_e = 1`` at
    rest.  The four-point rule is then not exact for the volume (``det`` is
    cubic), an error of the order of the edges' bow squared.  Straight
    elements keep the affine form above, bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from softdesign.continuum.laws import HyperelasticLaw, isochoric_stress, isochoric_tangent
from softdesign.errors import MeshError
from softdesign.mechanics.assembly import InvertedElementError
from softdesign.mechanics.element_threads import in_parts
from softdesign.mechanics.tets import TetMesh, node_dofs, summed
from softdesign.types import FloatArray, IntArray

#: The six edges of a tetrahedron (local corners), in the order of the midpoint nodes 4..9.
TET_EDGES = np.array([[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]])
#: Four-point rule, degree 2 (Keast): barycentric coordinates (Q, 4), weights a quarter each.
_A, _B = 0.5854101966249685, 0.1381966011250105
QUAD_POINTS = np.full((4, 4), _B) + np.eye(4) * (_A - _B)
QUAD_WEIGHTS = np.full(4, 0.25)


@dataclass(frozen=True)
class QuadraticMesh:
    """A reference mesh of 10-node tetrahedra from a linear one (corners first, then edge midpoints).

    Attributes
    ----------
    linear : the corner mesh
    points : (N, 3) float, mm: the linear mesh's V points, then one midpoint per edge
    cells : (E, 10) int: corners, then the midpoints of edges 01, 02, 03, 12, 13, 23
    grads : (E, Q, 10, 3) float, 1/mm: ``dN/dX`` at the quadrature points
    weights : (E, Q) float, mm^3: quadrature weights (sum: the element's volume)
    edges : (M, 2) int, sorted corner pairs: node ``V + k`` is the midpoint of ``edges[k]``
    curved_volumes : (E,) float, mm^3, every element's volume (the sum of its weights) when some are curved
        (module docstring), else None (the corners' volumes)
    """

    linear: TetMesh
    points: FloatArray
    cells: IntArray
    grads: FloatArray
    weights: FloatArray
    edges: IntArray
    curved_volumes: FloatArray | None = None

    @property
    def dof_count(self) -> int:
        """Three displacement unknowns per node."""
        return 3 * len(self.points)

    @property
    def volumes(self) -> FloatArray:
        """Reference volumes (E,), mm^3."""
        return self.linear.volumes if self.curved_volumes is None else self.curved_volumes

    @cached_property
    def stiffness_pattern(self) -> tuple[IntArray, IntArray, IntArray]:
        """The element matrices' sparsity as CSR ``indptr``, ``indices``, and the slot (E * 900,) of each entry.

        Found once per mesh, so an assembly is one scatter-add into ``data`` instead of a COO sort.
        """
        dofs = cell_dofs(self.cells)
        n, E = self.dof_count, len(self.cells)
        keys = (np.broadcast_to(dofs[:, :, None], (E, 30, 30)).astype(np.int64) * n
                + np.broadcast_to(dofs[:, None, :], (E, 30, 30))).ravel()
        unique, slot = np.unique(keys, return_inverse=True)
        indptr = np.concatenate([[0], np.cumsum(np.bincount(unique // n, minlength=n))])
        return indptr.astype(np.int64), (unique % n).astype(np.int64), slot.astype(np.int64)


def shape_values(bary: FloatArray) -> FloatArray:
    """The ten shape functions (n, 10) at barycentric coordinates ``bary`` (n, 4)."""
    corners = bary * (2.0 * bary - 1.0)
    edges = 4.0 * bary[:, TET_EDGES[:, 0]] * bary[:, TET_EDGES[:, 1]]
    return np.concatenate([corners, edges], axis=1)


def _shape_gradients(linear_grads: FloatArray) -> FloatArray:
    """``dN/dX`` (E, Q, 10, 3) at the quadrature points from the corners' linear gradients (E, 4, 3)."""
    L = QUAD_POINTS  # (Q, 4)
    corners = (4.0 * L - 1.0)[None, :, :, None] * linear_grads[:, None, :, :]
    i, j = TET_EDGES[:, 0], TET_EDGES[:, 1]
    edges = 4.0 * (L[None, :, i, None] * linear_grads[:, None, j, :]
                   + L[None, :, j, None] * linear_grads[:, None, i, :])
    return np.concatenate([corners, edges], axis=2)


def edge_midpoints(tets: IntArray, vertex_count: int) -> tuple[IntArray, IntArray]:
    """The sorted unique edges (M, 2) of ``tets`` and each element's six midpoint nodes (E, 6), numbered from V."""
    pairs = np.sort(tets[:, TET_EDGES], axis=2)  # (E, 6, 2)
    keys = pairs[..., 0] * vertex_count + pairs[..., 1]
    unique, inverse = np.unique(keys.ravel(), return_inverse=True)
    edges = np.stack([unique // vertex_count, unique % vertex_count], axis=1)
    return edges, vertex_count + inverse.reshape(len(tets), 6)


def quadratic_mesh(linear: TetMesh, curved_edges: IntArray | None = None, curved_midpoints: FloatArray | None = None
                   ) -> QuadraticMesh:
    """The 10-node mesh of ``linear``: straight edges, midpoints at their middles, but the edges ``curved_edges``
    (K, 2) (corner pairs, edges of the mesh) whose midside nodes are at ``curved_midpoints`` (K, 3) mm: their
    elements are curved (module docstring).

    Raises
    ------
    MeshError
        A curved pair is not an edge, or a curved element's map folds (``det(dX/dxi) <= 0`` at a point).
    """
    V = len(linear.points)
    edges, mids = edge_midpoints(linear.tets, V)
    points = np.concatenate([linear.points, 0.5 * (linear.points[edges[:, 0]] + linear.points[edges[:, 1]])])
    cells = np.concatenate([linear.tets, mids], axis=1)
    weights = linear.volumes[:, None] * QUAD_WEIGHTS[None, :]
    mesh = QuadraticMesh(linear, points, cells, _shape_gradients(linear.grads), weights, edges)
    if curved_edges is None or len(curved_edges) == 0:
        return mesh
    return _curved(mesh, np.asarray(curved_edges, np.int64), np.asarray(curved_midpoints, float))


def _reference_derivatives(bary: FloatArray) -> FloatArray:
    """The ten shape functions' derivatives (n, 10, 3) by the last three barycentric coordinates at ``bary``."""
    by_l = np.zeros((len(bary), 10, 4))
    corners = np.arange(4)
    by_l[:, corners, corners] = 4.0 * bary - 1.0
    edge = 4 + np.arange(6)
    by_l[:, edge, TET_EDGES[:, 0]] = 4.0 * bary[:, TET_EDGES[:, 1]]
    by_l[:, edge, TET_EDGES[:, 1]] = 4.0 * bary[:, TET_EDGES[:, 0]]
    return by_l[:, :, 1:] - by_l[:, :, :1]


#: ``dN/dxi`` (Q, 10, 3) at the quadrature points, xi the barycentrics 1..3 (the first is 1 - their sum).
QUAD_DXI = _reference_derivatives(QUAD_POINTS)
#: The same at the element's ten nodes: a curved map that folds shows ``det(dX/dxi) <= 0`` at a node or a
#: quadrature point (a fold between them is not ruled out, but a wall's bow folds an element first at its nodes).
NODE_DXI = _reference_derivatives(np.concatenate([np.eye(4), 0.5 * (np.eye(4)[TET_EDGES[:, 0]]
                                                                      + np.eye(4)[TET_EDGES[:, 1]])]))


def node_jacobians(nodes: FloatArray) -> FloatArray:
    """``det(dX/dxi)`` (E, 10) of elements with reference nodes ``nodes`` (E, 10, 3) mm at their ten nodes (6 V each
    for a straight element)."""
    return np.asarray(np.linalg.det(np.einsum("eai,nak->enik", nodes, NODE_DXI)), np.float64)


def smallest_jacobians(nodes: FloatArray) -> FloatArray:
    """The smallest ``det(dX/dxi)`` (E,) of elements with reference nodes ``nodes`` (E, 10, 3) mm over their ten
    nodes and the four quadrature points: ``<= 0`` where the map folds (the test of :func:`quadratic_mesh`)."""
    at_points = np.linalg.det(np.einsum("eai,qak->eqik", nodes, QUAD_DXI))
    return np.asarray(np.minimum(at_points.min(axis=1), node_jacobians(nodes).min(axis=1)), np.float64)


def isoparametric_geometry(nodes: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``dN/dX`` (E, Q, 10, 3) 1/mm and the weights (E, Q) mm^3 of elements with reference nodes ``nodes``
    (E, 10, 3) mm, at the four-point rule (module docstring, "Curved elements")."""
    jacobian = np.einsum("eai,qak->eqik", nodes, QUAD_DXI)  # dX_i / dxi_k
    grads = np.einsum("qak,eqki->eqai", QUAD_DXI, np.linalg.inv(jacobian))
    return grads, np.linalg.det(jacobian) * (QUAD_WEIGHTS / 6.0)[None, :]


def _curved(mesh: QuadraticMesh, curved_edges: IntArray, curved_midpoints: FloatArray) -> QuadraticMesh:
    """``mesh`` with the midside nodes of ``curved_edges`` (K, 2) at ``curved_midpoints`` (K, 3) mm."""
    if curved_midpoints.shape != (len(curved_edges), 3):
        raise MeshError(f"curved edges: one midside position (3,) per edge; got {curved_midpoints.shape} for "
                        f"{len(curved_edges)} edges")
    try:
        nodes = midpoint_nodes(mesh, curved_edges)
    except ValueError as error:
        raise MeshError(f"curved edges: {error}") from error
    points = mesh.points.copy()
    points[nodes] = curved_midpoints
    moved = np.zeros(len(points), bool)
    moved[nodes] = True
    curved = np.flatnonzero(moved[mesh.cells].any(axis=1))
    grads, weights = mesh.grads.copy(), mesh.weights.copy()
    grads[curved], weights[curved] = isoparametric_geometry(points[mesh.cells[curved]])
    smallest = smallest_jacobians(points[mesh.cells[curved]])
    if not np.all(smallest > 0):
        bad = int(curved[np.argmin(smallest)])
        raise MeshError(f"curved edges: element {bad}'s curved map folds (a midside node too far off its edge's "
                        "middle for the element's size); curve only edges on a smooth wall, or refine the mesh")
    volumes = mesh.linear.volumes.copy()
    volumes[curved] = weights[curved].sum(axis=1)
    return replace(mesh, points=points, grads=grads, weights=weights, curved_volumes=volumes)


def midpoint_nodes(mesh: QuadraticMesh, pairs: IntArray) -> IntArray:
    """The midpoint node (n,) of each corner pair (n, 2); every pair must be an edge of the mesh."""
    V = len(mesh.linear.points)
    keys = mesh.edges[:, 0] * V + mesh.edges[:, 1]
    ordered = np.sort(pairs, axis=1)
    wanted = ordered[:, 0] * V + ordered[:, 1]
    at = np.minimum(np.searchsorted(keys, wanted), len(keys) - 1)
    if not np.array_equal(keys[at], wanted):
        raise ValueError("midpoint_nodes: a corner pair is not an edge of the mesh")
    return V + at


def curved_barycentric(mesh: QuadraticMesh, elements: IntArray, bary: FloatArray, query: FloatArray,
                       iterations: int = 8) -> FloatArray:
    """Barycentric coordinates (n, 4) of reference points ``query`` (n, 3) mm under their ``elements``' (n,)
    quadratic maps, from their straight-element ones ``bary`` (n, 4): Newton's method on ``X(xi) = query``
    (converged to round-off in a few steps where the edges bow little against the element; a straight element's
    are its own).  A mesh without curved elements gets ``bary`` back as it is."""
    if mesh.curved_volumes is None:
        return bary
    nodes = mesh.points[mesh.cells[elements]]  # (n, 10, 3)
    xi = np.array(bary[:, 1:], float)
    for _ in range(iterations):
        full = np.concatenate([1.0 - xi.sum(axis=1, keepdims=True), xi], axis=1)
        miss = query - np.einsum("na,nai->ni", shape_values(full), nodes)
        jacobian = np.einsum("nai,nak->nik", nodes, _reference_derivatives(full))
        xi += np.linalg.solve(jacobian, miss[..., None])[..., 0]
    return np.concatenate([1.0 - xi.sum(axis=1, keepdims=True), xi], axis=1)


def curved_gradients_at(mesh: QuadraticMesh, elements: IntArray, bary: FloatArray) -> FloatArray:
    """``dN/dX`` (n, 10, 3) 1/mm at barycentric points ``bary`` (n, 4) of ``elements`` (n,) under their quadratic
    maps (curved or not: "Curved elements" in the module's docstring)."""
    dxi = _reference_derivatives(bary)  # (n, 10, 3)
    jacobian = np.einsum("nai,nak->nik", mesh.points[mesh.cells[elements]], dxi)
    return np.asarray(np.einsum("nak,nki->nai", dxi, np.linalg.inv(jacobian)), np.float64)


def quadratic_faces(mesh: QuadraticMesh, faces: IntArray) -> IntArray:
    """6-node faces (F, 6) of corner triangles (F, 3): the corners, then the midpoints of c0c1, c1c2, c2c0."""
    mids = [midpoint_nodes(mesh, faces[:, pair]) for pair in ([0, 1], [1, 2], [2, 0])]
    return np.concatenate([faces, np.stack(mids, axis=1)], axis=1)


def quadratic_fixed(mesh: QuadraticMesh, fixed: np.ndarray) -> np.ndarray:
    """Fixed unknowns (N, 3) bool from the corners' (V, 3): a midpoint's component is fixed when both ends' are."""
    return np.concatenate([fixed, fixed[mesh.edges[:, 0]] & fixed[mesh.edges[:, 1]]])


@dataclass(frozen=True)
class QuadraticState:
    """Deformation at the quadrature points and each element's mean dilatation.

    Attributes
    ----------
    F : (E, Q, 3, 3); J : (E, Q)
    theta : (E,) mean dilatation ``v_e / V_e``; pressure : (E,) ``U'(theta)``, kPa
    spatial_grads : (E, Q, 10, 3) ``g = F^-T dN/dX``, 1/mm
    """

    F: FloatArray
    J: FloatArray
    theta: FloatArray
    pressure: FloatArray
    spatial_grads: FloatArray


def quadratic_state(mesh: QuadraticMesh, law: HyperelasticLaw, displacement: FloatArray) -> QuadraticState:
    """The state of ``displacement`` (N, 3) mm (InvertedElementError when a point's det F is not > 0)."""
    u = displacement[mesh.cells]  # (E, 10, 3)
    F = np.eye(3)[None, None] + np.einsum("eai,eqaJ->eqiJ", u, mesh.grads)
    J = np.linalg.det(F)
    if not np.all(J > 0):
        raise InvertedElementError(f"{int(np.sum(J <= 0))} quadrature points inverted (smallest det F {J.min():.3g})")
    theta = (mesh.weights * J).sum(axis=1) / mesh.volumes
    spatial = np.einsum("eqaJ,eqiJ->eqai", mesh.grads, np.linalg.inv(F).transpose(0, 1, 3, 2))
    return QuadraticState(F, J, theta, law.bulk_kpa * (theta - 1.0), spatial)


def cell_dofs(cells: IntArray) -> IntArray:
    """Global unknowns (E, 30) of each element, node-major."""
    return node_dofs(cells)


def _volume_gradient(mesh: QuadraticMesh, state: QuadraticState) -> FloatArray:
    """``dv_e/dx`` (E, 10, 3), mm^2."""
    return _volume_gradient_of(mesh.weights, state.J, state.spatial_grads)


def _volume_gradient_of(weights: FloatArray, J: FloatArray, spatial_grads: FloatArray) -> FloatArray:
    """``dv_e/dx`` (e, 10, 3) mm^2 of elements' weights (e, Q), det F (e, Q) and spatial gradients (e, Q, 10, 3)."""
    return np.einsum("eq,eqai->eai", weights * J, spatial_grads)


def _element_forces(weights: FloatArray, P_iso: FloatArray, grads: FloatArray, pressure: FloatArray,
                    dv: FloatArray) -> FloatArray:
    """Elements' nodal forces (e, 30) mN: ``sum_q w P_iso : dN/dX + p_e dv_e/dx`` (P_iso (e Q, 3, 3) kPa)."""
    E, Q = weights.shape
    forces = np.einsum("eq,eqiJ,eqaJ->eai", weights, P_iso.reshape(E, Q, 3, 3), grads) + pressure[:, None, None] * dv
    return np.asarray(forces.reshape(E, 30), np.float64)


def quadratic_force(mesh: QuadraticMesh, law: HyperelasticLaw, state: QuadraticState) -> FloatArray:
    """Internal nodal forces (3N,) mN."""
    E, Q = mesh.weights.shape
    P_iso, _ = isochoric_stress(law, state.F.reshape(E * Q, 3, 3))
    forces = _element_forces(mesh.weights, P_iso, mesh.grads, state.pressure, _volume_gradient(mesh, state))
    return summed(cell_dofs(mesh.cells), forces, mesh.dof_count)


def quadratic_force_and_tangent(mesh: QuadraticMesh, law: HyperelasticLaw, state: QuadraticState,
                                element_pressure: FloatArray | None = None) -> tuple[FloatArray, sp.csr_matrix]:
    """Internal forces (3N,) mN and their derivative (3N, 3N) mN/mm (see the module's docstring).

    The derivative is exact with ``element_pressure`` None; given (E,) kPa, the geometric part of the
    volume takes that pressure instead of ``U'(theta)`` (the mixed Newton matrix of
    :mod:`softdesign.mechanics.newton`, whose element pressures are updated by their linearization).
    """
    E = len(mesh.cells)
    forces, K = np.empty((E, 30)), np.empty((E, 30, 30))
    pressure = state.pressure if element_pressure is None else element_pressure
    in_parts(E, lambda part: _element_forces_and_tangents(mesh, law, state, pressure, part, forces, K))
    n = mesh.dof_count
    indptr, indices, slot = mesh.stiffness_pattern
    tangent = sp.csr_matrix((summed(slot, K, len(indices)), indices, indptr), shape=(n, n))
    return summed(cell_dofs(mesh.cells), forces, n), tangent


def _element_forces_and_tangents(mesh: QuadraticMesh, law: HyperelasticLaw, state: QuadraticState,
                                 pressure: FloatArray, part: slice, forces: FloatArray, K: FloatArray) -> None:
    """The elements ``part``'s forces into ``forces[part]`` (e, 30) mN and tangents into ``K[part]`` (e, 30, 30)
    mN/mm; ``pressure`` (E,) kPa: the geometric part's element pressures."""
    grads, weights, volumes = mesh.grads[part], mesh.weights[part], mesh.volumes[part]
    F, J, g4 = state.F[part], state.J[part], state.spatial_grads[part]
    E, Q = weights.shape
    P_iso, A_iso = isochoric_tangent(law, F.reshape(E * Q, 3, 3))
    dv = _volume_gradient_of(weights, J, g4)
    forces[part] = _element_forces(weights, P_iso, grads, state.pressure[part], dv)
    # K_(ai)(bk) = sum_q w G_aJ A_iJkL G_bL as batched products: B (EQ, 30, 9) with B_(ai)(i'J) = d_ii' G_aJ
    B = np.einsum("eqaJ,ij->eqaijJ", grads, np.eye(3)).reshape(E * Q, 30, 9)
    A = A_iso.reshape(E * Q, 9, 9) * weights.reshape(E * Q, 1, 1)
    Ke = (B @ A @ B.transpose(0, 2, 1)).reshape(E, Q, 30, 30).sum(axis=1)
    # geometric part of the volume: p_e sum_q w J (g_ai g_bk - g_ak g_bi), and U''/V_e dv (x) dv
    # as one batched product M_(ai)(bk) = sum_q c_q g_ai g_bk; the second term is M with i and k swapped
    g = g4.reshape(E, Q, 30)
    weighted = (weights * J * pressure[part, None])[:, :, None] * g
    M = (g.transpose(0, 2, 1) @ weighted).reshape(E, 10, 3, 10, 3)
    Ke += (M - M.transpose(0, 1, 4, 3, 2)).reshape(E, 30, 30)
    flat = dv.reshape(E, 30)
    Ke += (law.bulk_kpa / volumes)[:, None, None] * flat[:, :, None] * flat[:, None, :]
    K[part] = Ke


def linearized_pressure(mesh: QuadraticMesh, law: HyperelasticLaw, state: QuadraticState, step: FloatArray
                        ) -> FloatArray:
    """Element pressures (E,) kPa after the displacement ``step`` (N, 3) mm from ``state``, to first order.

    ``U'(theta) + U'' (dv_e/dx . step) / V_e`` with ``U'' = kappa``: the pressure unknown of the mixed
    Newton method, updated by its linearization rather than from the new (overshooting) volume.
    """
    change = np.einsum("eai,eai->e", _volume_gradient(mesh, state), step[mesh.cells]) / mesh.volumes
    return np.asarray(state.pressure + law.bulk_kpa * change, np.float64)


def quadratic_deformation(mesh: QuadraticMesh, law: HyperelasticLaw, displacement: FloatArray
                          ) -> tuple[FloatArray, FloatArray]:
    """F (E, Q, 3, 3) at the quadrature points and the mean-dilatation pressure (E,) kPa (for stresses)."""
    state = quadratic_state(mesh, law, displacement)
    return state.F, state.pressure
