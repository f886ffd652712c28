"""The hand-derived stress and tangent of the laws against finite differences, and uniaxial known answers."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.continuum.laws import HyperelasticLaw, cauchy_stress, isochoric_stress, isochoric_tangent

#: Central differences of a smooth function at step 1e-6: error ~ 1e-10 relative, far below this.
FD_RTOL = 1e-6
LAWS = [HyperelasticLaw("neo-hookean", 10.0, 0.0, 0.0, 1e4, "test"),
        HyperelasticLaw("yeoh", 10.0, 1.5, 0.3, 1e4, "test")]


def _energy(law: HyperelasticLaw, F: np.ndarray) -> np.ndarray:
    J = np.linalg.det(F)
    x = J ** (-2 / 3) * np.einsum("nij,nij->n", F, F) - 3
    return law.c1 * x + law.c2 * x**2 + law.c3 * x**3


@pytest.mark.parametrize("law", LAWS)
def test_stress_is_the_energy_derivative(law: HyperelasticLaw) -> None:
    rng = np.random.default_rng(3)
    F = np.eye(3)[None] + 0.3 * rng.standard_normal((5, 3, 3))
    P, _ = isochoric_stress(law, F)
    h = 1e-6
    numeric = np.zeros_like(P)
    for i in range(3):
        for j in range(3):
            step = np.zeros((3, 3))
            step[i, j] = h
            numeric[:, i, j] = (_energy(law, F + step) - _energy(law, F - step)) / (2 * h)
    np.testing.assert_allclose(P, numeric, rtol=FD_RTOL, atol=FD_RTOL * np.abs(P).max())


@pytest.mark.parametrize("law", LAWS)
def test_tangent_is_the_stress_derivative(law: HyperelasticLaw) -> None:
    rng = np.random.default_rng(4)
    F = np.eye(3)[None] + 0.3 * rng.standard_normal((5, 3, 3))
    P, A = isochoric_tangent(law, F)
    np.testing.assert_allclose(P, isochoric_stress(law, F)[0], rtol=1e-12)
    h = 1e-6
    for k in range(3):
        for m in range(3):
            step = np.zeros((3, 3))
            step[k, m] = h
            numeric = (isochoric_stress(law, F + step)[0] - isochoric_stress(law, F - step)[0]) / (2 * h)
            np.testing.assert_allclose(A[:, :, :, k, m], numeric, rtol=FD_RTOL, atol=FD_RTOL * np.abs(A).max())


@pytest.mark.parametrize("law", LAWS)
def test_uniaxial_stress_known_answer(law: HyperelasticLaw) -> None:
    # incompressible uniaxial stretch: sigma = 2 (lambda^2 - 1/lambda) W'(I1), I1 = lambda^2 + 2/lambda
    stretch = np.array([0.7, 1.0, 1.8, 3.0])
    F = np.zeros((len(stretch), 3, 3))
    F[:, 0, 0], F[:, 1, 1], F[:, 2, 2] = stretch, stretch**-0.5, stretch**-0.5
    # the lateral faces are free: the volumetric pressure cancels the deviatoric lateral stress
    sigma_iso = cauchy_stress(law, F, np.zeros(len(stretch)))
    lateral = sigma_iso[:, 1, 1]
    sigma = cauchy_stress(law, F, -lateral)
    x = stretch**2 + 2 / stretch - 3
    expected = 2 * (stretch**2 - 1 / stretch) * (law.c1 + 2 * law.c2 * x + 3 * law.c3 * x**2)
    np.testing.assert_allclose(sigma[:, 0, 0], expected, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(sigma[:, 1, 1], 0.0, atol=1e-12)


def test_bad_law_is_refused() -> None:
    with pytest.raises(ValueError, match="c1 > 0"):
        HyperelasticLaw("neo-hookean", -1.0, 0.0, 0.0, 1e3, "test")
    with pytest.raises(ValueError, match="must be one of"):
        HyperelasticLaw("mooney", 1.0, 0.0, 0.0, 1e3, "test")
