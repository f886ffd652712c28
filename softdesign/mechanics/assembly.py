"""Internal force and tangent stiffness of linear tetrahedra with nodally averaged dilatation (locking-free).

Formulation
    Linear tetrahedra lock when a near-incompressible law is evaluated per
    element: one element has one volume constraint but only about 1/5 of a
    node's three unknowns.  Here the volumetric energy is evaluated on a
    dilatation averaged over each node's patch (the *average nodal pressure*
    tetrahedron of Bonet and Burton, Commun. Numer. Meth. Engng 14, 1998;
    Bonet, Marriott and Hassan, IJNME 50, 2001)::

        Psi(x) = sum_e V_e W_iso(F_e) + sum_a V_a U(J_a),   J_a = v_a / V_a,

    where ``V_a = sum_{e ni a} V_e / 4`` is the node's lumped reference volume
    and ``v_a`` the same sum of deformed volumes: one volume constraint per
    node, which a mesh of tetrahedra can meet without locking.  It is a
    displacement-only potential, so the tangent below is its exact Hessian
    (symmetric).  It is the three-field (u, p, theta) form with nodal p and
    theta and a lumped projection, condensed.
Derivatives
    ``dv_e/dx_b = v_e g_b`` with the spatial gradient ``g_b = F^-T dN_b/dX``;
    ``d2 v_e / dx_b,i dx_c,k = v_e (g_b,i g_c,k - g_b,k g_c,i)``.  With the
    nodal pressure ``p_a = U'(J_a)`` and ``p_e`` the mean of its four nodes':

        f_int = sum_e [V_e P_iso : dN/dX + p_e dv_e/dx]
        K = sum_e V_e dN/dX . A_iso . dN/dX + sum_e p_e d2v_e/dx2 + G^T diag(U''(J_a) / V_a) G,

    ``G`` (V x 3V) the gradient of the nodal deformed volumes, so the last term
    couples each node's patch (its stencil reaches the neighbours' neighbours).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from softdesign.continuum.laws import HyperelasticLaw, isochoric_stress, isochoric_tangent
from softdesign.mechanics.tets import TetMesh, deformation_gradients, node_dofs, summed
from softdesign.types import FloatArray, IntArray


class InvertedElementError(ArithmeticError):
    """A trial displacement turns an element inside out (det F <= 0): the step must be cut."""


@dataclass(frozen=True)
class VolumetricState:
    """Element and nodal dilatations of one displacement.

    Attributes
    ----------
    F : (E, 3, 3) deformation gradients
    J : (E,) element volume ratios
    nodal_J : (V,) patch volume ratios ``v_a / V_a``
    nodal_pressure : (V,) ``U'(J_a)``, kPa (tension > 0)
    element_pressure : (E,) mean of the element's four nodal pressures, kPa
    spatial_grads : (E, 4, 3) ``g = F^-T dN/dX``, 1/mm
    """

    F: FloatArray
    J: FloatArray
    nodal_J: FloatArray
    nodal_pressure: FloatArray
    element_pressure: FloatArray
    spatial_grads: FloatArray


def element_dofs(tets: IntArray) -> IntArray:
    """Global unknowns (E, 12) of each element, node-major: ``3 node + component``."""
    return node_dofs(tets)


def volumetric_state(mesh: TetMesh, law: HyperelasticLaw, displacement: FloatArray) -> VolumetricState:
    """Dilatations and pressures of ``displacement`` (V, 3) mm.

    Raises
    ------
    InvertedElementError
        An element's det F is not > 0.
    """
    F = deformation_gradients(mesh, displacement)
    J = np.linalg.det(F)
    if not np.all(J > 0):
        raise InvertedElementError(f"{int(np.sum(J <= 0))} elements inverted (smallest det F {J.min():.3g})")
    deformed = summed(mesh.tets, np.repeat(mesh.volumes * J / 4.0, 4), len(mesh.points))
    nodal_J = deformed / mesh.node_volumes
    nodal_pressure = law.bulk_kpa * (nodal_J - 1.0)
    element_pressure = nodal_pressure[mesh.tets].mean(axis=1)
    spatial = np.einsum("eaJ,eiJ->eai", mesh.grads, np.linalg.inv(F).transpose(0, 2, 1))
    return VolumetricState(F, J, nodal_J, nodal_pressure, element_pressure, spatial)


def internal_force(mesh: TetMesh, law: HyperelasticLaw, state: VolumetricState) -> FloatArray:
    """Internal nodal forces (3V,) mN of a state."""
    P_iso, _ = isochoric_stress(law, state.F)
    return _assemble_force(mesh, state, P_iso)


def _assemble_force(mesh: TetMesh, state: VolumetricState, P_iso: FloatArray) -> FloatArray:
    iso = np.einsum("e,eiJ,eaJ->eai", mesh.volumes, P_iso, mesh.grads)
    vol = (state.element_pressure * mesh.volumes * state.J)[:, None, None] * state.spatial_grads
    return summed(element_dofs(mesh.tets), iso + vol, mesh.dof_count)


def volume_gradient(mesh: TetMesh, state: VolumetricState) -> sp.csr_matrix:
    """``G`` (V, 3V): the gradient of each node's deformed patch volume ``v_a``, mm^2."""
    dv = (mesh.volumes * state.J / 4.0)[:, None, None] * state.spatial_grads  # (E, 4, 3): dv_e/dx / 4
    rows = np.repeat(mesh.tets, 12, axis=1)  # each of the element's 4 nodes gets all 12 entries
    cols = np.tile(element_dofs(mesh.tets), (1, 4))
    values = np.tile(dv.reshape(len(mesh.tets), 12), (1, 4))
    return sp.csr_matrix((values.ravel(), (rows.ravel(), cols.ravel())), shape=(len(mesh.points), mesh.dof_count))


def element_stiffness(mesh: TetMesh, law: HyperelasticLaw, state: VolumetricState) -> tuple[FloatArray, FloatArray]:
    """Element forces (E, 12) mN and element tangents (E, 12, 12) mN/mm of the isochoric and geometric parts."""
    P_iso, A_iso = isochoric_tangent(law, state.F)
    iso_f = np.einsum("e,eiJ,eaJ->eai", mesh.volumes, P_iso, mesh.grads)
    weight = state.element_pressure * mesh.volumes * state.J
    vol_f = weight[:, None, None] * state.spatial_grads
    g = state.spatial_grads
    K_iso = np.einsum("e,eaJ,eiJkL,ebL->eaibk", mesh.volumes, mesh.grads, A_iso, mesh.grads, optimize=True)
    K_geo = weight[:, None, None, None, None] * (np.einsum("eai,ebk->eaibk", g, g) - np.einsum("eak,ebi->eaibk", g, g))
    E = len(mesh.tets)
    return (iso_f + vol_f).reshape(E, 12), (K_iso + K_geo).reshape(E, 12, 12)


@dataclass(frozen=True)
class Tangent:
    """The Newton matrix of the internal forces, kept in two parts so it stays as sparse as one element's patch.

    The exact tangent is ``K + G^T diag(U''(J_a) / V_a) G``; its last term couples
    each node with its neighbours' neighbours and makes a sparse LU fill in five
    times more.  :func:`softdesign.mechanics.newton` solves instead the
    equivalent augmented system with one volume unknown per node (see there).

    Attributes
    ----------
    K : (3V, 3V) the isochoric and geometric part, mN/mm
    G : (V, 3V) the gradient of the nodal deformed volumes, mm^2
    compliance : (V,) ``V_a / U''(J_a)``, mm^3/kPa
    """

    K: sp.csr_matrix
    G: sp.csr_matrix
    compliance: FloatArray

    def condensed(self) -> sp.csr_matrix:
        """The exact tangent ``K + G^T diag(1 / compliance) G`` (3V, 3V)."""
        return (self.K + self.G.T @ sp.diags(1.0 / self.compliance) @ self.G).tocsr()


def force_and_tangent(mesh: TetMesh, law: HyperelasticLaw, state: VolumetricState) -> tuple[FloatArray, Tangent]:
    """Internal forces (3V,) mN and the tangent (the exact Hessian of Psi, in two parts) of a state."""
    forces, blocks = element_stiffness(mesh, law, state)
    dofs = element_dofs(mesh.tets)
    n = mesh.dof_count
    f = summed(dofs, forces, n)
    rows = np.broadcast_to(dofs[:, :, None], blocks.shape).ravel()
    cols = np.broadcast_to(dofs[:, None, :], blocks.shape).ravel()
    K = sp.csr_matrix((blocks.ravel(), (rows, cols)), shape=(n, n))
    return f, Tangent(K, volume_gradient(mesh, state), mesh.node_volumes / law.bulk_kpa)
