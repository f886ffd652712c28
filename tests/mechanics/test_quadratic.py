"""Quadratic tetrahedra: the tangent is the derivative of the forces, the pressure load's too, and a closed
surface under pressure has no resultant and does the work p dV."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.continuum.laws import HyperelasticLaw
from softdesign.mechanics.quadratic import (
    QuadraticMesh,
    linearized_pressure,
    midpoint_nodes,
    quadratic_faces,
    quadratic_force,
    quadratic_force_and_tangent,
    quadratic_mesh,
    quadratic_state,
    shape_values,
)
from softdesign.mechanics.quadratic_pressure import quadratic_pressure_load
from softdesign.mechanics.tets import boundary_faces, make_tet_mesh
from tests.helpers.fe_meshes import quarter_tube
from tests.helpers.finite_differences import assert_columns_match_central_differences

#: Central differences at 1e-6 mm of forces up to ~600 mN: truncation ~1e-12, round-off ~1e-8.
FD_ATOL = 1e-6
LAW = HyperelasticLaw("yeoh", 10.0, 1.0, 0.2, 500.0, "test")
H = 1e-6


def _mesh_and_displacement() -> tuple[QuadraticMesh, np.ndarray]:
    points, tets = quarter_tube(2.0, 3.0, 1.0, (2, 3, 2))
    mesh = quadratic_mesh(make_tet_mesh(points, tets))
    return mesh, 0.01 * np.random.default_rng(7).standard_normal(mesh.points.shape)


def _force(mesh: QuadraticMesh, u: np.ndarray) -> np.ndarray:
    return quadratic_force(mesh, LAW, quadratic_state(mesh, LAW, u))


def test_quadratic_tangent_matches_finite_differences() -> None:
    mesh, u = _mesh_and_displacement()
    f, K = quadratic_force_and_tangent(mesh, LAW, quadratic_state(mesh, LAW, u))
    np.testing.assert_allclose(f, _force(mesh, u), atol=1e-12)
    dense = K.toarray()
    np.testing.assert_allclose(dense, dense.T, atol=1e-9)  # the Hessian of a potential
    assert_columns_match_central_differences(dense, lambda v: _force(mesh, v), u, H, FD_ATOL, every=7)


def _faces(mesh: QuadraticMesh) -> np.ndarray:
    return quadratic_faces(mesh, boundary_faces(mesh.linear.tets))


def test_quadratic_pressure_tangent_matches_finite_differences() -> None:
    mesh, u = _mesh_and_displacement()
    faces = _faces(mesh)
    pressure, x = np.linspace(1.0, 3.0, len(faces)), mesh.points + u
    _, dF = quadratic_pressure_load(x, faces, pressure, want_tangent=True)
    assert dF is not None
    dense = dF.toarray()
    assert_columns_match_central_differences(
        dense, lambda y: quadratic_pressure_load(y, faces, pressure, want_tangent=False)[0], x, H, FD_ATOL, every=3)


def test_quadratic_pressure_on_a_closed_surface_has_no_resultant_and_does_work_p_dv() -> None:
    mesh, u = _mesh_and_displacement()
    faces = _faces(mesh)[:, [0, 2, 1, 5, 4, 3]]  # pressurised from outside: normals into the material
    f, _ = quadratic_pressure_load(mesh.points + u, faces, np.full(len(faces), 2.0), want_tangent=False)
    np.testing.assert_allclose(f.reshape(-1, 3).sum(axis=0), 0.0, atol=1e-12)
    dx = 1e-7 * np.random.default_rng(1).standard_normal(u.shape)
    volume = lambda v: float((mesh.weights * quadratic_state(mesh, LAW, v).J).sum())  # noqa: E731
    np.testing.assert_allclose(f @ dx.ravel(), -2.0 * (volume(u + dx) - volume(u)), rtol=1e-3)


def test_shape_functions_interpolate_quadratics_exactly() -> None:
    mesh, _ = _mesh_and_displacement()
    field = lambda p: np.stack([p[:, 0] ** 2, p[:, 0] * p[:, 1] - p[:, 2], p[:, 2] ** 2 + 1], axis=1)  # noqa: E731
    bary = np.random.default_rng(3).dirichlet(np.ones(4), size=len(mesh.cells))
    where = np.einsum("ea,eai->ei", bary, mesh.linear.points[mesh.linear.tets])
    got = np.einsum("ea,eai->ei", shape_values(bary), field(mesh.points)[mesh.cells])
    np.testing.assert_allclose(got, field(where), atol=1e-12)
    with pytest.raises(ValueError, match="not an edge"):
        midpoint_nodes(mesh, np.array([[0, len(mesh.linear.points) - 1]]))


def test_linearized_pressure_is_first_order_in_the_step() -> None:
    """The mixed method's pressure after a step misses U'(theta) of the stepped state by O(step^2)."""
    mesh, u = _mesh_and_displacement()
    state = quadratic_state(mesh, LAW, u)
    direction = np.random.default_rng(11).standard_normal(mesh.points.shape)
    misses = []
    for scale in (1e-3, 5e-4):
        exact = quadratic_state(mesh, LAW, u + scale * direction).pressure
        misses.append(np.abs(linearized_pressure(mesh, LAW, state, scale * direction) - exact).max())
        change = np.abs(exact - state.pressure).max()
        assert misses[-1] < 0.05 * change  # far better than keeping the old pressure
    assert 3.5 < misses[0] / misses[1] < 4.5  # second order: half the step, a quarter of the miss


def test_the_mixed_tangent_takes_the_given_element_pressures() -> None:
    """With its own pressures U'(theta) given, the matrix is the exact one; others change only the geometric part."""
    mesh, u = _mesh_and_displacement()
    state = quadratic_state(mesh, LAW, u)
    _, exact = quadratic_force_and_tangent(mesh, LAW, state)
    _, same = quadratic_force_and_tangent(mesh, LAW, state, state.pressure.copy())
    _, other = quadratic_force_and_tangent(mesh, LAW, state, state.pressure + 100.0)
    assert abs(exact - same).max() == 0.0
    difference = other - exact
    assert abs(difference).max() > 0.0
    assert abs(difference - difference.T).max() <= 1e-9 * abs(difference).max()  # p sum w J (g g - g g): symmetric


def test_the_tangent_is_the_same_bit_for_bit_in_one_thread_or_several(monkeypatch: pytest.MonkeyPatch) -> None:
    # the element loop split over threads (softdesign.mechanics.element_threads) changes the time, not the answer
    import softdesign.mechanics.element_threads as threads

    points, tets = quarter_tube(2.0, 3.0, 1.0, (4, 5, 4))
    mesh = quadratic_mesh(make_tet_mesh(points, tets))
    u = 0.01 * np.random.default_rng(11).standard_normal(mesh.points.shape)
    state = quadratic_state(mesh, LAW, u)
    monkeypatch.setattr(threads, "_cores", lambda: 1)
    f1, K1 = quadratic_force_and_tangent(mesh, LAW, state)
    monkeypatch.setattr(threads, "_cores", lambda: 3)
    monkeypatch.setattr(threads, "MIN_PART_ELEMENTS", 7)  # three uneven parts of this small mesh
    assert len(mesh.cells) // threads.MIN_PART_ELEMENTS >= 3
    f3, K3 = quadratic_force_and_tangent(mesh, LAW, state)
    assert np.array_equal(f1, f3)
    assert np.array_equal(K1.indptr, K3.indptr) and np.array_equal(K1.indices, K3.indices)
    assert np.array_equal(K1.data, K3.data)
