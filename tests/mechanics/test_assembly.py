"""The assembled tangent is the derivative of the assembled residual (internal forces and follower pressure)."""

from __future__ import annotations

import numpy as np

from softdesign.continuum.laws import HyperelasticLaw
from softdesign.mechanics.assembly import force_and_tangent, internal_force, volumetric_state
from softdesign.mechanics.pressure import pressure_load
from softdesign.mechanics.tets import boundary_faces, make_tet_mesh
from tests.helpers.fe_meshes import quarter_tube
from tests.helpers.finite_differences import assert_columns_match_central_differences

#: Central differences at 1e-6 mm of forces of order 1 mN: truncation ~1e-12, round-off ~1e-10.
FD_ATOL = 1e-6
LAW = HyperelasticLaw("yeoh", 10.0, 1.0, 0.2, 500.0, "test")


def _mesh_and_displacement() -> tuple:
    points, tets = quarter_tube(2.0, 3.0, 1.0, (2, 3, 2))
    mesh = make_tet_mesh(points, tets)
    u = 0.1 * np.random.default_rng(7).standard_normal(points.shape)
    return mesh, u


def test_internal_tangent_matches_finite_differences() -> None:
    mesh, u = _mesh_and_displacement()
    f, tangent = force_and_tangent(mesh, LAW, volumetric_state(mesh, LAW, u))
    np.testing.assert_allclose(f, internal_force(mesh, LAW, volumetric_state(mesh, LAW, u)), atol=1e-12)
    assert_columns_match_central_differences(tangent.condensed().toarray(),
                                             lambda v: internal_force(mesh, LAW, volumetric_state(mesh, LAW, v)),
                                             u, 1e-6, FD_ATOL, every=5)


def test_pressure_tangent_matches_finite_differences() -> None:
    mesh, u = _mesh_and_displacement()
    faces = boundary_faces(mesh.tets)
    pressure = np.linspace(1.0, 3.0, len(faces))
    x = mesh.points + u
    _, dF = pressure_load(x, faces, pressure, want_tangent=True)
    assert dF is not None
    assert_columns_match_central_differences(
        dF.toarray(), lambda y: pressure_load(y, faces, pressure, want_tangent=False)[0], x, 1e-6, FD_ATOL, every=3)


def test_pressure_on_a_closed_surface_has_no_net_force_and_does_work_p_dv() -> None:
    # the whole boundary of the body, pressurised from outside (normals flipped into the material):
    # a closed surface under uniform pressure has zero resultant, and f . dx = -p dV of the body
    mesh, u = _mesh_and_displacement()
    faces = boundary_faces(mesh.tets)[:, [0, 2, 1]]
    f, _ = pressure_load(mesh.points + u, faces, np.full(len(faces), 2.0), want_tangent=False)
    np.testing.assert_allclose(f.reshape(-1, 3).sum(axis=0), 0.0, atol=1e-12)
    dx = 1e-7 * np.random.default_rng(1).standard_normal(u.shape)
    volume = lambda v: float((mesh.volumes * np.linalg.det(  # noqa: E731
        volumetric_state(mesh, LAW, v).F)).sum())
    np.testing.assert_allclose(f @ dx.ravel(), -2.0 * (volume(u + dx) - volume(u)), rtol=1e-5)
