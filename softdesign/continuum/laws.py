"""Near-incompressible isotropic hyperelastic laws: neo-Hookean and Yeoh, split into isochoric and volumetric parts.

The strain energy per reference volume is

    W(F) = W_iso(I1_bar) + U(J),    I1_bar = J^(-2/3) tr(F^T F),    J = det F,

with ``W_iso = C1 (I1_bar - 3) + C2 (I1_bar - 3)^2 + C3 (I1_bar - 3)^3`` (Yeoh;
neo-Hookean is ``C2 = C3 = 0`` and ``mu = 2 C1``) and ``U(J) = kappa/2 (J - 1)^2``.
Only the isochoric part is evaluated here, per element; the volumetric part is
evaluated on nodally averaged dilatations (:mod:`softdesign.mechanics.assembly`),
which is what keeps linear tetrahedra from locking.

Derivatives (hand-derived; the tests check them against finite differences):

    dI1_bar/dF = J^(-2/3) (2 F - 2/3 I1 F^-T)
    d2I1_bar/dF_iJ dF_kL = J^(-2/3) [2 d_ik d_JL - 4/3 (F_iJ H_kL + H_iJ F_kL)
                                     + 4/9 I1 H_iJ H_kL + 2/3 I1 H_iL H_kJ],   H = F^-T
    P_iso = W' dI1_bar/dF,   A_iso = W'' dI1_bar/dF (x) dI1_bar/dF + W' d2I1_bar/dF dF.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdesign.types import FloatArray

#: Laws this module evaluates.
LAW_KINDS = ("neo-hookean", "yeoh")


@dataclass(frozen=True)
class HyperelasticLaw:
    """A Yeoh law (neo-Hookean when ``c2 = c3 = 0``) with a bulk modulus, kPa.

    Attributes
    ----------
    kind : ``neo-hookean`` or ``yeoh``
    c1, c2, c3 : Yeoh coefficients, kPa (initial shear modulus ``mu = 2 c1``)
    bulk_kpa : bulk modulus kappa of ``U(J) = kappa/2 (J - 1)^2``, kPa (near-incompressible: >> mu)
    source : where the numbers come from
    """

    kind: str
    c1: float
    c2: float
    c3: float
    bulk_kpa: float
    source: str

    @property
    def mu_kpa(self) -> float:
        """Initial shear modulus, kPa."""
        return 2.0 * self.c1

    def __post_init__(self) -> None:
        if self.kind not in LAW_KINDS:
            raise ValueError(f"law kind must be one of {', '.join(LAW_KINDS)}, got {self.kind!r}")
        if not (self.c1 > 0 and self.bulk_kpa > 0 and np.isfinite([self.c1, self.c2, self.c3, self.bulk_kpa]).all()):
            raise ValueError(f"law needs c1 > 0 and bulk_kpa > 0, finite; got c1 {self.c1}, bulk {self.bulk_kpa}")
        if self.kind == "neo-hookean" and (self.c2 != 0 or self.c3 != 0):
            raise ValueError("a neo-Hookean law has c2 = c3 = 0")

    def energy_derivatives(self, i1_bar: FloatArray) -> tuple[FloatArray, FloatArray]:
        """``W'(I1_bar)`` and ``W''(I1_bar)``, kPa, each shaped like ``i1_bar``."""
        x = np.asarray(i1_bar, float) - 3.0
        first = self.c1 + 2.0 * self.c2 * x + 3.0 * self.c3 * x * x
        second = 2.0 * self.c2 + 6.0 * self.c3 * x
        return np.asarray(first, np.float64), np.asarray(second, np.float64)


def isochoric_stress(law: HyperelasticLaw, F: FloatArray) -> tuple[FloatArray, FloatArray]:
    """First Piola-Kirchhoff stress of the isochoric part (n, 3, 3) kPa and ``F^-T`` (n, 3, 3), for F (n, 3, 3)."""
    H = np.linalg.inv(F).transpose(0, 2, 1)
    J = np.linalg.det(F)
    i1 = np.einsum("nij,nij->n", F, F)
    scale = J ** (-2.0 / 3.0)
    d_i1bar = scale[:, None, None] * (2.0 * F - (2.0 / 3.0) * i1[:, None, None] * H)
    w1, _ = law.energy_derivatives(scale * i1)
    return np.asarray(w1[:, None, None] * d_i1bar, np.float64), np.asarray(H, np.float64)


def isochoric_tangent(law: HyperelasticLaw, F: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Stress P (n, 3, 3) kPa and tangent dP/dF (n, 3, 3, 3, 3) kPa of the isochoric part, for F (n, 3, 3)."""
    H = np.linalg.inv(F).transpose(0, 2, 1)
    J = np.linalg.det(F)
    i1 = np.einsum("nij,nij->n", F, F)
    scale = J ** (-2.0 / 3.0)
    d_i1bar = scale[:, None, None] * (2.0 * F - (2.0 / 3.0) * i1[:, None, None] * H)
    w1, w11 = law.energy_derivatives(scale * i1)
    eye = np.eye(3)
    second = (2.0 * np.einsum("ik,JL->iJkL", eye, eye)[None]
              - (4.0 / 3.0) * (np.einsum("niJ,nkL->niJkL", F, H) + np.einsum("niJ,nkL->niJkL", H, F))
              + (4.0 / 9.0) * i1[:, None, None, None, None] * np.einsum("niJ,nkL->niJkL", H, H)
              + (2.0 / 3.0) * i1[:, None, None, None, None] * np.einsum("niL,nkJ->niJkL", H, H))
    tangent = (w11[:, None, None, None, None] * np.einsum("niJ,nkL->niJkL", d_i1bar, d_i1bar)
               + (w1 * scale)[:, None, None, None, None] * second)
    return w1[:, None, None] * d_i1bar, tangent


def cauchy_stress(law: HyperelasticLaw, F: FloatArray, pressure: FloatArray) -> FloatArray:
    """Cauchy stress (n, 3, 3) kPa from F (n, 3, 3) and the volumetric pressure ``U'(J)`` (n,) kPa (tension > 0)."""
    P_iso, _ = isochoric_stress(law, F)
    J = np.linalg.det(F)
    sigma = np.einsum("niJ,nkJ->nik", P_iso, F) / J[:, None, None]
    return sigma + pressure[:, None, None] * np.eye(3)[None]
