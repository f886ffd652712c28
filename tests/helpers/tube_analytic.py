"""Known answers of a thick-walled tube inflated by an inner pressure, in plane strain (no axial stretch).

Incompressible neo-Hookean, shear modulus mu, reference radii A < B, deformed a < b.
With no axial stretch, incompressibility keeps the annulus' area: a material
circle of radius R goes to r with ``r^2 = R^2 + c``, ``c = a^2 - A^2``, so
``b^2 = B^2 + c``.  The principal stretches are ``lambda = r / R`` (hoop),
``1 / lambda`` (radial) and 1 (axial), and the Cauchy stress difference is

    sigma_tt - sigma_rr = mu (lambda^2 - lambda^-2).

Radial equilibrium ``d sigma_rr / dr + (sigma_rr - sigma_tt) / r = 0`` with
``sigma_rr(a) = -p`` and ``sigma_rr(b) = 0`` gives

    p = integral_a^b mu (lambda^2 - lambda^-2) dr / r.

With ``u = r^2``, ``lambda^2 = u / (u - c)`` and ``dr / r = du / (2 u)``:

    p = mu/2 integral [1/(u - c) - 1/u + c/u^2] du
      = mu/2 [ln((u - c)/u) - c/u]_{a^2}^{b^2}
      = mu/2 [ln(a^2 B^2 / (A^2 b^2)) + c (1/a^2 - 1/b^2)].

For small ``c`` (``c ~ 2 A u_a``) this is ``p = mu c (1/A^2 - 1/B^2)``, which is
Lamé's incompressible plane-strain answer ``u(r) = p A^2 B^2 / (2 mu (B^2 - A^2)) / r``.
The slightly compressible law of the finite elements (bulk modulus kappa,
Poisson's ratio ``nu = (3 kappa - 2 mu) / (2 (3 kappa + mu))``) has Lamé's
plane-strain answer

    u(r) = (1 + nu) / E * p A^2 / (B^2 - A^2) * ((1 - 2 nu) r + B^2 / r),   E = 2 mu (1 + nu).
"""

from __future__ import annotations

import math


def inflation_pressure(mu: float, inner: float, outer: float, deformed_inner: float) -> float:
    """Inner pressure, kPa, that holds an incompressible neo-Hookean tube at ``deformed_inner`` (plane strain)."""
    c = deformed_inner**2 - inner**2
    b2 = outer**2 + c
    return 0.5 * mu * (math.log(deformed_inner**2 * outer**2 / (inner**2 * b2)) + c * (1 / deformed_inner**2 - 1 / b2))


def lame_displacement(mu: float, bulk: float, inner: float, outer: float, pressure: float, r: float) -> float:
    """Lamé's radial displacement, mm, at radius ``r`` of a linear plane-strain tube under inner ``pressure``."""
    nu = (3 * bulk - 2 * mu) / (2 * (3 * bulk + mu))
    young = 2 * mu * (1 + nu)
    return (1 + nu) / young * pressure * inner**2 / (outer**2 - inner**2) * ((1 - 2 * nu) * r + outer**2 / r)
