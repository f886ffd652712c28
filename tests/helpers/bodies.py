"""Analytic bodies for the meshing tests (straight tube, cone, torus section, helix).

Each builder returns the body on a tessellation grid (``TubeSections``) and a
``field(l)`` evaluating it anywhere for the integrals, with exact frames,
curvature and d rho / ds, so the meshing code is tested against geometry
nobody else's code produced.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdesign.meshing.tessellate import TubeSections
from softdesign.meshing.volume import Stations, angle_grid

#: Round-off level for frame identities, dimensionless.
FRAME_TOL = 1e-12


@dataclass(frozen=True)
class Centerline:
    """Exact centerline geometry at arc length s (mm): points, frames (N, B, T), curvature (k1, k2)."""

    length: float
    points: object
    frames: object
    curvature: object


def straight_line(length: float) -> Centerline:
    """Along +z from the origin; N = x, B = y."""

    def points(s):
        return np.column_stack([np.zeros_like(s), np.zeros_like(s), s])

    def frames(s):
        return np.broadcast_to(np.eye(3), (np.size(s), 3, 3)).copy()

    return Centerline(length, points, frames, lambda s: np.zeros((np.size(s), 2)))


def circular_arc(radius: float, angle: float) -> Centerline:
    """Arc of the circle of ``radius`` about the z axis in the xy plane; N points to the centre, B = z."""

    def points(s):
        t = s / radius
        return radius * np.column_stack([np.cos(t), np.sin(t), np.zeros_like(t)])

    def frames(s):
        t = s / radius
        n = -np.column_stack([np.cos(t), np.sin(t), np.zeros_like(t)])
        tangent = np.column_stack([-np.sin(t), np.cos(t), np.zeros_like(t)])
        b = np.broadcast_to([0.0, 0.0, 1.0], n.shape)
        return np.stack([n, b, tangent], axis=-1)

    def curvature(s):
        return np.column_stack([np.full(np.size(s), 1.0 / radius), np.zeros(np.size(s))])

    return Centerline(radius * angle, points, frames, curvature)


def helix(radius: float, pitch: float, turns: float) -> Centerline:
    """Helix (r cos t, r sin t, p t / 2 pi) with its rotation-minimizing frame.

    Frenet: kappa = r / c^2, tau = b / c^2 with b = p / 2 pi, c = sqrt(r^2 + b^2).
    Rotating (N_f, B_f) by phi = -tau s gives N' = -k1 T, B' = -k2 T with
    k1 = kappa cos(phi), k2 = -kappa sin(phi).
    """
    b = pitch / (2.0 * np.pi)
    c = np.hypot(radius, b)
    kappa, tau = radius / c**2, b / c**2

    def points(s):
        t = s / c
        return np.column_stack([radius * np.cos(t), radius * np.sin(t), b * t])

    def frames(s):
        t, phi = s / c, -tau * s
        tangent = np.column_stack([-radius * np.sin(t), radius * np.cos(t), np.full_like(t, b)]) / c
        n_f = -np.column_stack([np.cos(t), np.sin(t), np.zeros_like(t)])
        b_f = np.column_stack([b * np.sin(t), -b * np.cos(t), np.full_like(t, radius)]) / c
        n = np.cos(phi)[:, None] * n_f + np.sin(phi)[:, None] * b_f
        binormal = -np.sin(phi)[:, None] * n_f + np.cos(phi)[:, None] * b_f
        return np.stack([n, binormal, tangent], axis=-1)

    def curvature(s):
        phi = -tau * s
        return np.column_stack([kappa * np.cos(phi), -kappa * np.sin(phi)])

    return Centerline(2.0 * np.pi * turns * c, points, frames, curvature)


def circle_rho(radius: float, eccentricity: float, na: int) -> np.ndarray:
    """rho(a_k), (na,): a circle of ``radius`` whose centre sits ``eccentricity`` mm along N."""
    a = angle_grid(na)
    return eccentricity * np.cos(a) + np.sqrt(radius**2 - (eccentricity * np.sin(a)) ** 2)


@dataclass(frozen=True)
class Body:
    """A centerline with rho(s, a) = r0 + slope s (+ a fixed eccentric circle)."""

    line: Centerline
    r0: float
    slope: float = 0.0
    eccentricity: float = 0.0

    def rho(self, s: np.ndarray, na: int) -> np.ndarray:
        return np.stack([circle_rho(self.r0 + self.slope * si, self.eccentricity, na) for si in np.atleast_1d(s)])

    def rho_s(self, s: np.ndarray, na: int) -> np.ndarray:
        if self.eccentricity and self.slope:
            raise NotImplementedError("d rho / ds of a tapered eccentric circle is not needed here")
        return np.full((np.size(s), na), self.slope)

    def sections(self, n: int, na: int, q: float = 0.5, exact: bool = True) -> TubeSections:
        """On n rings uniformly spaced in arc length; ``exact=False`` leaves s, rho_s, curvature to the mesher."""
        s = np.linspace(0.0, self.line.length, n)
        extra = dict(s=s, rho_s=self.rho_s(s, na), curvature=self.line.curvature(s)) if exact else {}
        return TubeSections(q, s / self.line.length, self.line.points(s), self.line.frames(s), self.rho(s, na), **extra)

    def field(self, na: int):
        """``l -> Stations`` for the integrals (l = s / length)."""

        def evaluate(l):
            s = np.asarray(l, float) * self.line.length
            speed = np.full(s.size, self.line.length)
            return Stations(self.rho(s, na), self.rho_s(s, na), self.line.curvature(s), speed)

        return evaluate
