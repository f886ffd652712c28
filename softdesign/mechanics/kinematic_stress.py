"""Strain and stress of a prescribed motion, element by element: the morph's 3D strain and what it costs.

The morph prescribes every material point's place at every q (no equilibrium
is solved), so each linear tetrahedron carries a constant deformation gradient
``F = dx dX^-1`` (edges at q over edges at q = 0, the cast state).  From it:

principal stretches
    lambda_i, square roots of the eigenvalues of ``C = F^T F`` (sorted
    descending); the largest principal Green strain is ``(lambda_1^2 - 1) / 2``.
Cauchy stress
    The laws of :mod:`softdesign.mechanics.laws` (neo-Hookean, Yeoh) taken
    incompressible: ``sigma = 2 W'(I1_bar) B_bar - p I`` with ``B_bar =
    J^(-2/3) F F^T``.  The morph does not say p (it is what equilibrium would
    fix), so it is taken from a traction-free direction: ``n . sigma n = 0``
    with n the current direction of a given reference direction (through
    the wall: the wall's faces carry no load but the chamber's pressure,
    which is small against the stresses of a large stretch), or, when none is
    given, the direction of the least principal stretch.  In uniaxial
    tension ``F = diag(l, l^-1/2, l^-1/2)`` either gives ``sigma_11 = 2 W'
    (l^2 - 1/l)``: ``mu (l^2 - 1/l)`` for neo-Hookean (W' = mu / 2) and
    ``2 (l^2 - 1/l) (C1 + 2 C2 (I1 - 3) + 3 C3 (I1 - 3)^2)`` for Yeoh.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.mechanics.laws import HyperelasticLaw
from softdesign.types import FloatArray, IntArray


def deformation_gradients(rest: npt.ArrayLike, moved: npt.ArrayLike, tets: npt.ArrayLike) -> FloatArray:
    """F of every tetrahedron, (T, 3, 3), from node positions at rest and moved (V, 3) mm.

    Raises
    ------
    ValueError
        A tetrahedron of zero volume at rest (no gradient is defined).
    """
    rest, moved, tets = np.asarray(rest, float), np.asarray(moved, float), np.asarray(tets, np.int64)
    edges0 = (rest[tets[:, 1:]] - rest[tets[:, :1]]).transpose(0, 2, 1)  # columns: edges
    edges = (moved[tets[:, 1:]] - moved[tets[:, :1]]).transpose(0, 2, 1)
    det = np.linalg.det(edges0)
    if np.any(np.abs(det) <= 1e-300):
        raise ValueError("deformation_gradients: a tetrahedron of zero volume at rest")
    return np.asarray(edges @ np.linalg.inv(edges0), np.float64)


def principal_stretches_3d(F: npt.ArrayLike) -> FloatArray:
    """(T, 3) principal stretches, descending, of deformation gradients (T, 3, 3)."""
    F = np.asarray(F, float)
    C = np.einsum("nki,nkj->nij", F, F)
    return np.sqrt(np.maximum(np.linalg.eigvalsh(C)[:, ::-1], 0.0))


def cauchy_stress(law: HyperelasticLaw, F: npt.ArrayLike, free: npt.ArrayLike | None = None) -> FloatArray:
    """Cauchy stress (T, 3, 3) kPa of the incompressible law, p from the traction-free direction (module notes).

    Parameters
    ----------
    law : the material's law (its bulk modulus is not used: incompressible)
    F : (T, 3, 3) deformation gradients
    free : (T, 3) reference directions that stay traction-free (normals of a plane of zero normal stress), or
        None: the direction of least principal stretch
    """
    F = np.asarray(F, float)
    J = np.linalg.det(F)
    B_bar = J[:, None, None] ** (-2.0 / 3.0) * np.einsum("nik,njk->nij", F, F)
    w1, _ = law.energy_derivatives(np.trace(B_bar, axis1=1, axis2=2))
    deviator = 2.0 * w1[:, None, None] * B_bar
    if free is None:
        normal_stress = np.linalg.eigvalsh(deviator)[:, 0]  # B_bar's eigenvectors are the stretch directions
    else:
        n = np.einsum("nji,nj->ni", np.linalg.inv(F), np.asarray(free, float))  # a material plane's normal: F^-T N
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        normal_stress = np.einsum("ni,nij,nj->n", n, deviator, n)
    return np.asarray(deviator - normal_stress[:, None, None] * np.eye(3), np.float64)


def principal_stresses(sigma: npt.ArrayLike) -> FloatArray:
    """(T, 3) principal values, descending, of symmetric stresses (T, 3, 3)."""
    return np.asarray(np.linalg.eigvalsh(np.asarray(sigma, float))[:, ::-1], np.float64)


@dataclass(frozen=True)
class ElementStrain:
    """Per tetrahedron at one q.

    Attributes
    ----------
    stretches : (T, 3) principal stretches, descending
    green_max : (T,) largest principal Green strain
    stress_max : (T,) largest principal Cauchy stress, kPa (None without a law)
    """

    stretches: FloatArray
    green_max: FloatArray
    stress_max: FloatArray | None


def element_strain(rest: FloatArray, moved: FloatArray, tets: IntArray, law: HyperelasticLaw | None,
                   free: FloatArray | None = None) -> ElementStrain:
    """Stretches, Green strain and (with a law) the largest principal stress of every tetrahedron."""
    F = deformation_gradients(rest, moved, tets)
    stretches = principal_stretches_3d(F)
    green = 0.5 * (stretches[:, 0] ** 2 - 1.0)
    stress = None if law is None else principal_stresses(cauchy_stress(law, F, free))[:, 0]
    return ElementStrain(stretches, green, stress)
