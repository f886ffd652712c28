"""Stress of a prescribed motion: neo-Hookean and Yeoh under uniaxial stretch, on one element."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.continuum.kinematic_stress import (
    cauchy_stress,
    deformation_gradients,
    element_strain,
    principal_stresses,
    principal_stretches_3d,
)
from softdesign.continuum.laws import HyperelasticLaw

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
    from softdesign.continuum.kinematic_stress import symmetric_eigenvalues

    # near a repeated root the trigonometric form keeps about half the digits
    np.testing.assert_allclose(symmetric_eigenvalues(A), np.linalg.eigvalsh(A)[:, ::-1], rtol=0, atol=1e-7)


@pytest.mark.parametrize("free", [None, "random"])
def test_the_largest_stress_without_the_tensor_is_the_tensor_s(free):
    """element_strain's largest principal stress (from the stretches) against cauchy_stress's eigenvalues."""
    rng = np.random.default_rng(3)
    F = np.eye(3) + 0.3 * rng.normal(size=(200, 3, 3))
    F = F[np.linalg.det(F) > 0.2]
    directions = None if free is None else rng.normal(size=(len(F), 3))
    moved = np.einsum("nij,kj->nki", F, TET)  # each tetrahedron its own four nodes
    rest = np.tile(TET, (len(F), 1))
    tets = np.arange(4 * len(F)).reshape(-1, 4)
    fast = element_strain(rest, moved.reshape(-1, 3), tets, YEOH, directions).stress_max
    full = np.linalg.eigvalsh(cauchy_stress(YEOH, F, directions))[:, -1]
    np.testing.assert_allclose(fast, full, rtol=1e-9, atol=1e-9 * np.abs(full).max())


def test_chunks_and_batches_change_no_bit():
    """strains on more tetrahedra than a chunk, and on a stack of moved states, gives each tetrahedron's figures
    exactly as alone (element by element arithmetic), the stack's as each state's."""
    from softdesign.continuum.kinematic_stress import STRAIN_CHUNK, _strains, rest_state, strains

    rng = np.random.default_rng(5)
    F = np.eye(3) + 0.2 * rng.normal(size=(STRAIN_CHUNK + 1000, 3, 3))
    F = F[np.linalg.det(F) > 0.2]
    assert len(F) > STRAIN_CHUNK
    moved = np.einsum("nij,kj->nki", F, TET).reshape(-1, 3)
    state = rest_state(np.tile(TET, (len(F), 1)), np.arange(4 * len(F)).reshape(-1, 4), rng.normal(size=(len(F), 3)))
    whole, chunked = _strains(state, moved, YEOH), strains(state, moved, YEOH)
    for a, b in ((whole.stretches, chunked.stretches), (whole.green_max, chunked.green_max),
                 (whole.stress_max, chunked.stress_max)):
        np.testing.assert_array_equal(a, b)
    stack = strains(state, np.stack([moved, 1.1 * moved]), YEOH)
    assert stack.stress_max is not None and stack.stretches.shape == (2, len(F), 3)
    np.testing.assert_array_equal(stack.stretches[0], chunked.stretches)
    np.testing.assert_array_equal(stack.stress_max[1], strains(state, 1.1 * moved, YEOH).stress_max)
