"""Stress of a prescribed motion: neo-Hookean and Yeoh under uniaxial stretch, on one element."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.mechanics.kinematic_stress import (
    cauchy_stress,
    deformation_gradients,
    element_strain,
    principal_stresses,
    principal_stretches_3d,
)
from softdesign.mechanics.laws import HyperelasticLaw

#: Closed-form expressions evaluated in float64: agreement to round-off.
EXACT_RTOL = 1e-10
NEO = HyperelasticLaw("neo-hookean", 20.0, 0.0, 0.0, 1.0e5, "test")
YEOH = HyperelasticLaw("yeoh", 20.0, -0.5, 0.05, 1.0e5, "test")
TET = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])


def _uniaxial(stretch: float) -> np.ndarray:
    return np.diag([stretch, stretch**-0.5, stretch**-0.5])


@pytest.mark.parametrize(("stretch", "free"), [(0.8, [[0.0, 1.0, 0.0]]), (1.0, None), (1.5, None), (3.0, None),
                                               (3.0, [[0.0, 0.0, 1.0]])])
def test_neo_hookean_uniaxial_on_one_element(stretch, free):
    """In tension the least stretch is lateral, so the default free direction gives uniaxial stress; in
    compression the lateral direction must be named (the least stretch is then the axial one)."""
    moved = TET @ _uniaxial(stretch).T
    result = element_strain(TET, moved, np.array([[0, 1, 2, 3]]), NEO, None if free is None else np.array(free))
    np.testing.assert_allclose(result.stretches[0], sorted([stretch, stretch**-0.5, stretch**-0.5], reverse=True),
                               rtol=EXACT_RTOL)
    sigma = cauchy_stress(NEO, deformation_gradients(TET, moved, np.array([[0, 1, 2, 3]])),
                          None if free is None else np.array(free))[0]
    np.testing.assert_allclose(sigma[0, 0], NEO.mu_kpa * (stretch**2 - 1.0 / stretch), rtol=EXACT_RTOL, atol=1e-12)
    np.testing.assert_allclose(sigma[1:, 1:], 0.0, atol=1e-10)
    np.testing.assert_allclose(result.green_max[0], 0.5 * (max(stretch, stretch**-0.5) ** 2 - 1.0), rtol=EXACT_RTOL)


@pytest.mark.parametrize("stretch", [1.2, 2.0, 4.0])
def test_yeoh_uniaxial_on_one_element_with_a_free_direction(stretch):
    F = _uniaxial(stretch)[None]
    i1 = stretch**2 + 2.0 / stretch
    x = i1 - 3.0
    expected = 2.0 * (stretch**2 - 1.0 / stretch) * (YEOH.c1 + 2.0 * YEOH.c2 * x + 3.0 * YEOH.c3 * x * x)
    sigma = cauchy_stress(YEOH, F, free=np.array([[0.0, 1.0, 0.0]]))[0]
    np.testing.assert_allclose(sigma[0, 0], expected, rtol=EXACT_RTOL)
    np.testing.assert_allclose(principal_stresses(sigma[None])[0, 0], expected, rtol=EXACT_RTOL)


def test_a_rotation_is_free_of_strain_and_stress():
    angle = 0.7
    R = np.array([[np.cos(angle), -np.sin(angle), 0.0], [np.sin(angle), np.cos(angle), 0.0], [0.0, 0.0, 1.0]])
    F = deformation_gradients(TET, TET @ R.T, np.array([[0, 1, 2, 3]]))
    np.testing.assert_allclose(principal_stretches_3d(F), 1.0, rtol=EXACT_RTOL)
    np.testing.assert_allclose(cauchy_stress(NEO, F), 0.0, atol=1e-10)


def test_closed_form_eigenvalues_match_lapack():
    rng = np.random.default_rng(7)
    M = rng.normal(size=(500, 3, 3))
    A = M + M.transpose(0, 2, 1)
    A[:10] = np.eye(3)  # a triple root
    A[10:20] = np.diag([2.0, 1.0, 1.0])  # a double root
    from softdesign.mechanics.kinematic_stress import symmetric_eigenvalues

    # near a repeated root the trigonometric form keeps about half the digits
    np.testing.assert_allclose(symmetric_eigenvalues(A), np.linalg.eigvalsh(A)[:, ::-1], rtol=0, atol=1e-7)
