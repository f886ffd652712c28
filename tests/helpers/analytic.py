"""Analytic framed curves for the fitting tests (exact positions, derivatives and frames).

Each class follows ``softdesign.types.FramedCurve``: normalized arc length
l in [0, 1], frames with columns (N, B, T), rotation-minimizing (except ``FrenetHelix``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def _l(values) -> np.ndarray:
    return np.asarray(values, float).reshape(-1)


@dataclass(frozen=True)
class Line:
    """Straight segment from the origin along +z; N = x, B = y."""

    length: float

    def points(self, l):
        l = _l(l)
        return np.column_stack([np.zeros_like(l), np.zeros_like(l), self.length * l])

    def derivative(self, l, order=1):
        l = _l(l)
        out = np.zeros((len(l), 3))
        if order == 1:
            out[:, 2] = self.length
        return out

    def frames(self, l):
        return np.broadcast_to(np.eye(3), (len(_l(l)), 3, 3)).copy()


@dataclass(frozen=True)
class Arc:
    """Circular arc of radius ``radius`` in the xy plane, sweeping ``sweep`` rad from (R, 0, 0).

    N points to the arc's centre and B = +z: for a planar curve this frame is
    rotation-minimizing.  A tube around it is a torus section.
    """

    radius: float
    sweep: float

    @property
    def length(self) -> float:
        return self.radius * self.sweep

    def points(self, l):
        phi = self.sweep * _l(l)
        return self.radius * np.column_stack([np.cos(phi), np.sin(phi), np.zeros_like(phi)])

    def derivative(self, l, order=1):
        phi = self.sweep * _l(l)
        base = np.column_stack([np.cos(phi + order * np.pi / 2), np.sin(phi + order * np.pi / 2), np.zeros_like(phi)])
        return self.radius * self.sweep**order * base

    def frames(self, l):
        phi = self.sweep * _l(l)
        c, s, z = np.cos(phi), np.sin(phi), np.zeros_like(phi)
        normal = np.column_stack([-c, -s, z])
        binormal = np.column_stack([z, z, np.ones_like(phi)])
        tangent = np.column_stack([-s, c, z])
        return np.stack([normal, binormal, tangent], axis=2)


@dataclass(frozen=True)
class Helix:
    """``(r cos t, r sin t, h t)`` for t in [0, turns 2 pi], with its exact rotation-minimizing frame.

    The RMF is the Frenet frame turned about T by ``theta(s) = -tau s``
    (tau = h / (r^2 + h^2)), which makes ``d/ds`` of the first column parallel to T.
    """

    r: float
    h: float
    turns: float

    @property
    def t_total(self) -> float:
        return 2.0 * np.pi * self.turns

    @property
    def speed(self) -> float:
        return float(np.hypot(self.r, self.h))

    @property
    def length(self) -> float:
        return self.speed * self.t_total

    @property
    def curvature(self) -> float:
        return self.r / self.speed**2

    @property
    def torsion(self) -> float:
        return self.h / self.speed**2

    def points(self, l):
        t = self.t_total * _l(l)
        return np.column_stack([self.r * np.cos(t), self.r * np.sin(t), self.h * t])

    def derivative(self, l, order=1):
        t = self.t_total * _l(l)
        k = self.t_total**order
        ang = t + order * np.pi / 2
        z = np.full_like(t, self.h if order == 1 else 0.0)
        return k * np.column_stack([self.r * np.cos(ang), self.r * np.sin(ang), z])

    def frenet_frames(self, l):
        """The Frenet frames (N towards the axis), (n, 3, 3)."""
        t = self.t_total * _l(l)
        w = self.speed
        tangent = np.column_stack([-self.r * np.sin(t), self.r * np.cos(t), np.full_like(t, self.h)]) / w
        normal = np.column_stack([-np.cos(t), -np.sin(t), np.zeros_like(t)])
        binormal = np.column_stack([self.h * np.sin(t), -self.h * np.cos(t), np.full_like(t, self.r)]) / w
        return np.stack([normal, binormal, tangent], axis=2)

    def frames(self, l):
        """Rotation-minimizing frames: the Frenet frame turned back by the accumulated torsion."""
        frenet = self.frenet_frames(l)
        normal, binormal = frenet[:, :, 0], frenet[:, :, 1]
        theta = -self.torsion * self.length * _l(l)
        u = np.cos(theta)[:, None] * normal + np.sin(theta)[:, None] * binormal
        v = np.cos(theta)[:, None] * binormal - np.sin(theta)[:, None] * normal
        return np.stack([u, v, frenet[:, :, 2]], axis=2)


def tube_points(curve, l, angle, rho) -> np.ndarray:
    """``c(l) + rho (cos a N + sin a B)``, (n, 3) mm."""
    frames = curve.frames(l)
    direction = np.cos(angle)[:, None] * frames[:, :, 0] + np.sin(angle)[:, None] * frames[:, :, 1]
    return curve.points(l) + np.asarray(rho, float)[:, None] * direction


def grid_parameters(n_l: int, n_a: int, rng: np.random.Generator, l_range=(0.0, 1.0)):
    """Jittered (l, a) covering [l_range] x [0, 2 pi) about uniformly, like mesh vertices."""
    lo, hi = l_range
    l = (np.arange(n_l)[:, None] + rng.random((n_l, n_a))) / n_l * (hi - lo) + lo
    a = (np.arange(n_a)[None, :] + rng.random((n_l, n_a))) / n_a * 2 * np.pi - np.pi
    return l.ravel(), a.ravel()


@dataclass(frozen=True)
class FrenetHelix(Helix):
    """The same helix with its Frenet frame (N towards the axis), which twists about T at the torsion."""

    def frames(self, l):
        return self.frenet_frames(l)
