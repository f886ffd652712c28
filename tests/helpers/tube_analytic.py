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


def closed_end_pressure(mu: float, inner: float, outer: float, hoop: float, axial: float) -> tuple[float, float]:
    """Inner pressure (kPa) and the axial balance (mN, zero for a closed end) of an incompressible neo-Hookean tube
    at inner hoop stretch ``hoop`` and axial stretch ``axial`` (Rivlin's inflation and extension).

    A material circle of radius R goes to r with ``axial (r^2 - a^2) = R^2 - A^2``; the stretches are
    ``r / R`` (hoop), ``R / (r axial)`` (radial) and ``axial``, and with ``sigma_i - sigma_j = mu (l_i^2 - l_j^2)``:

        P = integral_a^b mu (l_t^2 - l_r^2) dr / r,
        N - pi a^2 P = pi integral_a^b mu (2 l_z^2 - l_t^2 - l_r^2) r dr,

    the second from ``d(r^2 sigma_rr)/dr = r (sigma_rr + sigma_tt)``; a closed end has ``N = pi a^2 P``.
    """
    from scipy.integrate import quad

    a = hoop * inner
    b = math.sqrt(a**2 + (outer**2 - inner**2) / axial)

    def stretches(r: float) -> tuple[float, float]:
        big_r = math.sqrt(inner**2 + axial * (r**2 - a**2))
        return r / big_r, big_r / (r * axial)

    def hoop_minus_radial(r: float) -> float:
        t, rr = stretches(r)
        return mu * (t**2 - rr**2) / r

    def axial_excess(r: float) -> float:
        t, rr = stretches(r)
        return mu * (2 * axial**2 - t**2 - rr**2) * r

    return quad(hoop_minus_radial, a, b, epsabs=1e-13, epsrel=1e-12)[0], \
        math.pi * quad(axial_excess, a, b, epsabs=1e-13, epsrel=1e-12)[0]


def closed_end_axial(mu: float, inner: float, outer: float, hoop: float) -> float:
    """The axial stretch at which a closed-end tube at inner hoop stretch ``hoop`` is in axial balance."""
    from scipy.optimize import brentq

    return float(brentq(lambda z: closed_end_pressure(mu, inner, outer, hoop, z)[1], 0.5, 3.0, xtol=1e-14))


def closed_end_limit(mu: float, inner: float, outer: float) -> tuple[float, float, float]:
    """The closed-end tube's largest pressure (kPa) and the inner hoop and axial stretches there."""
    from scipy.optimize import minimize_scalar

    def minus_pressure(hoop: float) -> float:
        return -closed_end_pressure(mu, inner, outer, hoop, closed_end_axial(mu, inner, outer, hoop))[0]

    best = minimize_scalar(minus_pressure, bounds=(1.5, 5.0), method="bounded", options={"xatol": 1e-9})
    hoop = float(best.x)
    return -float(best.fun), hoop, closed_end_axial(mu, inner, outer, hoop)
