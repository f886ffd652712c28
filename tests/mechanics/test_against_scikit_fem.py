"""Cross-check with scikit-fem: at rest, a section's Newton matrix is the linear operator scikit-fem assembles.

The sections' solver assembles its own vectorised tangent of quadratic tetrahedra with a mean dilatation per
element (:mod:`softdesign.mechanics.quadratic`: scikit-fem's generic forms took 12 s a Newton iteration on 2,550
quadratic tetrahedra, the issue measured).  At zero displacement that tangent must be the small-strain operator

    a(u, v) = 2 mu dev eps(u) : dev eps(v) over the body + kappa / V_e (int_e div u)(int_e div v) per element,

with ``mu = 2 C1``: the isochoric part of a neo-Hookean or Yeoh law, linearised, and the mean dilatation's
volumetric part.  scikit-fem assembles both independently (the vector quadratic element and the P0 one); the
unknowns are matched by node and component.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from skfem import Basis, BilinearForm, ElementTetP0, ElementTetP2, ElementVector, MeshTet
from skfem.helpers import ddot, div, eye, sym_grad, trace

from softdesign.continuum.laws import HyperelasticLaw
from softdesign.mechanics.quadratic import QuadraticMesh, quadratic_force_and_tangent, quadratic_mesh, quadratic_state
from softdesign.mechanics.tets import make_tet_mesh
from tests.helpers.fe_meshes import quarter_tube

#: Both assemble exact integrals (degree 2 integrands, degree 2 rules): they agree to round-off.
MATRIX_RTOL = 1e-10
LAW = HyperelasticLaw("yeoh", 10.0, 1.0, 0.2, 500.0, "test")  # mu = 2 C1 = 20 kPa, kappa = 500 kPa


def _our_dofs(mesh: QuadraticMesh, basis: Basis, edges: np.ndarray) -> np.ndarray:
    """Our unknown (3 node + component) for each of scikit-fem's, by vertex and by edge."""
    ours = np.empty(basis.N, np.int64)
    vertex_count = len(mesh.linear.points)
    ours[basis.nodal_dofs] = 3 * np.arange(vertex_count)[None, :] + np.arange(3)[:, None]
    index = {tuple(pair): k for k, pair in enumerate(mesh.edges.tolist())}
    node = vertex_count + np.array([index[tuple(sorted(pair))] for pair in edges.T.tolist()])
    ours[basis.edge_dofs] = 3 * node[None, :] + np.arange(3)[:, None]
    return ours


def _scikit_fem_operator(points: np.ndarray, tets: np.ndarray, mu: float, kappa: float
                         ) -> tuple[sp.csr_matrix, Basis, np.ndarray]:
    m = MeshTet(points.T, tets.T)
    basis = Basis(m, ElementVector(ElementTetP2()), intorder=2)
    constant = basis.with_element(ElementTetP0())

    @BilinearForm
    def deviatoric(u, v, _):  # type: ignore[no-untyped-def]
        eu, ev = sym_grad(u), sym_grad(v)
        return 2.0 * mu * ddot(eu - eye(trace(eu) / 3.0, 3), ev - eye(trace(ev) / 3.0, 3))

    @BilinearForm
    def dilatation(u, q, _):  # type: ignore[no-untyped-def]
        return div(u) * q

    @BilinearForm
    def mass(p, q, _):  # type: ignore[no-untyped-def]
        return p * q

    divergence = sp.csr_matrix(dilatation.assemble(basis, constant))
    volumes = np.asarray(mass.assemble(constant).diagonal())
    operator = deviatoric.assemble(basis) + kappa * divergence.T @ sp.diags(1.0 / volumes) @ divergence
    return sp.csr_matrix(operator), basis, np.asarray(m.edges)


def test_the_tangent_at_rest_is_scikit_fems_small_strain_operator() -> None:
    points, tets = quarter_tube(2.0, 3.0, 1.0, (2, 3, 2))
    mesh = quadratic_mesh(make_tet_mesh(points, tets))
    _, ours = quadratic_force_and_tangent(mesh, LAW, quadratic_state(mesh, LAW, np.zeros_like(mesh.points)))
    theirs, basis, edges = _scikit_fem_operator(points, tets, 2.0 * LAW.c1, LAW.bulk_kpa)
    order = _our_dofs(mesh, basis, edges)
    matched = sp.csr_matrix(ours)[order][:, order]
    assert abs(matched - theirs).max() <= MATRIX_RTOL * abs(theirs).max()


def test_the_cross_check_sees_a_wrong_modulus() -> None:
    """The comparison is not blind: a shear modulus 1 % off is seen."""
    points, tets = quarter_tube(2.0, 3.0, 1.0, (2, 3, 2))
    mesh = quadratic_mesh(make_tet_mesh(points, tets))
    _, ours = quadratic_force_and_tangent(mesh, LAW, quadratic_state(mesh, LAW, np.zeros_like(mesh.points)))
    theirs, basis, edges = _scikit_fem_operator(points, tets, 1.01 * 2.0 * LAW.c1, LAW.bulk_kpa)
    order = _our_dofs(mesh, basis, edges)
    assert abs(sp.csr_matrix(ours)[order][:, order] - theirs).max() > 1e-4 * abs(theirs).max()
