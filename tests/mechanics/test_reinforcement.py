"""The hoop thread's fibre membrane: its tangent is its forces' derivative, its forces its energy's gradient, and
its energy and direction are the thread's on a stretched tube wall (:mod:`softdesign.mechanics.reinforcement`)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from softdesign.mechanics.quadratic import QuadraticMesh, quadratic_faces, quadratic_mesh
from softdesign.mechanics.reinforcement import FibreMembrane, HoopThread, hoop_membrane
from softdesign.mechanics.tets import boundary_faces, make_tet_mesh
from tests.helpers.fe_meshes import quarter_tube
from tests.helpers.finite_differences import assert_columns_match_central_differences

INNER, OUTER, HEIGHT = 2.0, 3.0, 1.0
#: The silicone's Young's modulus, kPa (3 mu of an Ecoflex-like mu = 40 kPa): the thread buckles at e = 4.4e-3.
MATRIX_KPA = 120.0
#: A polyester-like thread: 0.2 mm, 2 GPa, one turn every 0.5 mm.
THREAD = HoopThread(pitch_mm=0.5, diameter_mm=0.2, modulus_kpa=2.0e6)
#: Central differences at 1e-6 mm of forces up to ~1e4 mN: truncation ~1e-12 relative, round-off ~1e-6 mN.
FD_ATOL = 1e-4
H = 1e-6
#: Energies and stretches computed two ways in floating point.
EXACT_RTOL = 1e-12


def _wall(thread: HoopThread = THREAD) -> tuple[QuadraticMesh, FibreMembrane]:
    points, tets = quarter_tube(INNER, OUTER, HEIGHT, (2, 4, 2))
    mesh = quadratic_mesh(make_tet_mesh(points, tets))
    faces = boundary_faces(mesh.linear.tets)
    radius = np.hypot(points[faces][..., 0], points[faces][..., 1])
    inner = quadratic_faces(mesh, faces[np.all(np.isclose(radius, INNER), axis=1)])
    axes = np.tile([0.0, 0.0, 1.0], (len(inner), 1))
    return mesh, hoop_membrane(mesh.points, inner, axes, np.full(len(inner), INNER), thread, MATRIX_KPA)


def test_the_tangent_matches_finite_differences_of_the_forces() -> None:
    mesh, fibres = _wall()
    # a random motion about a 2 % radial inflation: threads stretched, some shortened past their buckling
    x = mesh.points * np.array([1.02, 1.02, 1.0]) + 0.02 * np.random.default_rng(3).standard_normal(mesh.points.shape)
    e = fibres.strains(x)
    assert (e > 0).any() and (e < -fibres.buckling_strain[:, None]).any()
    _, K = fibres.force_and_tangent(x, want_tangent=True)
    assert K is not None
    dense = K.toarray()
    np.testing.assert_allclose(dense, dense.T, atol=1e-9)  # the Hessian of an energy
    assert_columns_match_central_differences(
        dense, lambda y: fibres.force_and_tangent(y, want_tangent=False)[0], x, H, FD_ATOL, every=5)


def test_the_forces_are_the_energys_gradient() -> None:
    mesh, fibres = _wall()
    x = mesh.points * np.array([1.1, 1.1, 1.02])
    f, _ = fibres.force_and_tangent(x, want_tangent=False)
    direction = np.random.default_rng(5).standard_normal(x.shape)
    h = 1e-6
    slope = (fibres.energy(x + h * direction) - fibres.energy(x - h * direction)) / (2 * h)
    np.testing.assert_allclose(f @ direction.ravel(), slope, rtol=1e-6)  # central difference of an energy ~1e2


@pytest.mark.parametrize("stretch", [1.2, 0.999, 0.9])
def test_a_uniformly_scaled_wall_stores_the_threads_energy(stretch: float) -> None:
    """Scaling the wall radially by lambda strains a hoop thread by e = (lambda^2 - 1) / 2: W = k e^2 / 2 per area,
    and past the buckling strain e_b the force stays at k e_b (W linear in e)."""
    hoop = HoopThread(pitch_mm=1e-6, diameter_mm=0.2, modulus_kpa=2.0e6)  # a pitch that makes it pure hoop
    mesh, fibres = _wall(hoop)
    x = mesh.points * np.array([stretch, stretch, 1.0])
    area, k = float(fibres.weights.sum()), hoop.stiffness_mn_per_mm
    e, e_b = (stretch**2 - 1) / 2, hoop.buckling_strain(MATRIX_KPA)
    expected = k * e**2 / 2 if e >= -e_b else k * e_b**2 / 2 - k * e_b * (e + e_b)
    np.testing.assert_allclose(fibres.energy(x), expected * area, rtol=1e-9)  # the pitch's cos(beta) ~ 1e-7 squared
    np.testing.assert_allclose(fibres.thread_tension_mn(x), hoop.axial_stiffness_mn * max(e, -e_b), rtol=1e-9)


def test_the_winding_follows_the_helix_angle_from_the_axis() -> None:
    """Stretching the wall axially by s alone: a helix at beta from the axis has I4 = cos^2(beta) s^2 + sin^2(beta)."""
    mesh, fibres = _wall()
    beta = math.atan(2 * math.pi * INNER / THREAD.pitch_mm)
    assert math.isclose(THREAD.winding_angle_rad(INNER), beta, rel_tol=EXACT_RTOL)
    s = 1.3
    _, i4 = fibres.fibre_invariants(mesh.points * np.array([1.0, 1.0, s]))
    np.testing.assert_allclose(i4, math.cos(beta) ** 2 * s**2 + math.sin(beta) ** 2, rtol=1e-9)
    _, rest = fibres.fibre_invariants(mesh.points)
    np.testing.assert_allclose(rest, 1.0, rtol=1e-12)  # unit fibres at rest


def test_a_thread_needs_positive_data() -> None:
    with pytest.raises(ValueError, match="pitch_mm, diameter_mm and modulus_kpa > 0"):
        HoopThread(pitch_mm=0.0, diameter_mm=0.2, modulus_kpa=1e6)
