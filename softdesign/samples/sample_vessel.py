"""The project's own sample vessel: a tortuous artery with a side branch.

A main path about 90 mm long winds in 3-D (curvature up to ~0.08 /mm); its
radius tapers from 4.0 to 3.2 mm with a gentle bulge, and its cross-section
is slightly elliptical (semi-axes r(1 + e) and r(1 - e), the major axis
turning slowly along the vessel).  A side branch of radius 2.5 -> 2.0 mm
leaves the trunk at 40 mm and bends away by 50 degrees.  Like
``vmtkcenterlines`` output, the two centerlines start at the inlet and share
the trunk's points exactly.  Everything here is pure geometry in mm.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdesign.types import FloatArray, Points


@dataclass(frozen=True)
class SampleShape:
    """Parameters of the sample vessel (mm, rad)."""

    main_length_mm: float = 90.0
    branch_at_mm: float = 40.0
    branch_length_mm: float = 30.0
    branch_angle_rad: float = np.deg2rad(50.0)
    spacing_mm: float = 0.5
    ellipticity: float = 0.08


@dataclass(frozen=True)
class SampleVessel:
    """Centerlines and the wall's cross-section description.

    Attributes
    ----------
    main, branch : (n, 3), (m, 3) float, mm -- inlet first; the branch
        repeats the main path's trunk points exactly
    main_radius, branch_radius : (n,), (m,) float, mm -- mean wall radius
    ellipticity : relative semi-axis difference of the main vessel
    major_angle : (n,) float, rad -- angle of the major axis from the
        parallel-transported normal along ``main``
    """

    main: Points
    branch: Points
    main_radius: FloatArray
    branch_radius: FloatArray
    ellipticity: float
    major_angle: FloatArray

    def inscribed_radius(self, which: str) -> FloatArray:
        """VMTK's MaximumInscribedSphereRadius: the minor semi-axis where elliptical."""
        if which == "main":
            return self.main_radius * (1.0 - self.ellipticity)
        trunk = self.trunk_count()
        radius = self.branch_radius.copy()
        radius[:trunk] = self.main_radius[:trunk] * (1.0 - self.ellipticity)
        return radius

    def trunk_count(self) -> int:
        """How many leading points the branch shares with the main path."""
        n = min(len(self.main), len(self.branch))
        same = np.all(self.main[:n] == self.branch[:n], axis=1)
        return int(np.argmin(same)) if not same.all() else n


def main_curve(s: FloatArray) -> Points:
    """The main path at arc-length-like parameter ``s`` (mm): a 3-D meander."""
    s = np.asarray(s, float)
    return np.column_stack(
        [6.0 * np.sin(2 * np.pi * s / 60.0), 4.0 * (1.0 - np.cos(2 * np.pi * s / 45.0)), s]
    )


def make_sample_vessel(shape: SampleShape = SampleShape()) -> SampleVessel:
    """Build the sample vessel's centerlines and radii."""
    dense = np.linspace(0.0, shape.main_length_mm, 20001)
    points = main_curve(dense)
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    count = int(round(arc[-1] / shape.spacing_mm)) + 1
    main = np.column_stack([np.interp(np.linspace(0, arc[-1], count), arc, points[:, k]) for k in range(3)])
    u = np.linspace(0.0, 1.0, count)
    main_radius = 4.0 - 0.8 * u + 0.25 * np.exp(-(((u - 0.7) / 0.08) ** 2))
    major_angle = 0.6 * np.pi * u
    branch, branch_radius = _branch(main, main_radius, shape)
    return SampleVessel(main, branch, main_radius, branch_radius, shape.ellipticity, major_angle)


def _branch(main: Points, main_radius: FloatArray, shape: SampleShape) -> tuple[Points, FloatArray]:
    step = np.linalg.norm(np.diff(main, axis=0), axis=1)
    arc = np.concatenate([[0.0], np.cumsum(step)])
    at = int(np.searchsorted(arc, shape.branch_at_mm))
    tangent = (main[at + 1] - main[at - 1]) / np.linalg.norm(main[at + 1] - main[at - 1])
    side = np.cross(tangent, [1.0, 0.0, 0.0])
    side /= np.linalg.norm(side)
    n = int(round(shape.branch_length_mm / shape.spacing_mm))
    u = np.arange(1, n + 1) * shape.spacing_mm
    ramp = np.clip(u / 12.0, 0.0, 1.0)
    angle = shape.branch_angle_rad * ramp**2 * (3 - 2 * ramp)  # smoothstep: the branch bends away gently
    directions = np.cos(angle)[:, None] * tangent + np.sin(angle)[:, None] * side
    limb = main[at] + np.cumsum(directions * shape.spacing_mm, axis=0)
    branch = np.concatenate([main[: at + 1], limb])
    radius = np.concatenate([main_radius[: at + 1], np.linspace(2.5, 2.0, n)])
    return branch, radius
