"""A scaled synthetic vessel for benchmarks: one long tortuous tube, no branches.

The centerline winds in 3-D for ``axial_length_mm`` along z (about 215 mm of
arc for the default 200 mm, curvature up to about 0.09 /mm, so a 4.5 mm
radius stays well clear of folding: rho * kappa < 0.45).  The radius
tapers linearly from ``radius_mm[0]`` to ``radius_mm[1]``; the section is
slightly elliptical like the sample vessel's, its major axis turning
slowly.  The size of the benchmark (triangle count of the wall) is chosen
when the wall is tessellated (:mod:`softdesign.samples.surfaces`),
so the same vessel can be meshed at any resolution.  Pure geometry, mm.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdesign.types import FloatArray, Points

#: Dense parameter samples used to measure arc length before resampling.
_DENSE_SAMPLES = 40001


@dataclass(frozen=True)
class SyntheticShape:
    """Parameters of the synthetic vessel (mm, rad).

    Attributes
    ----------
    axial_length_mm : extent of the centerline along z
    spacing_mm : arc length between centerline points
    radius_mm : (inlet, outlet) mean wall radius, linear taper between
    ellipticity : relative semi-axis difference of the section
    meander_mm : (x, y) amplitudes of the two sine meanders
    period_mm : (x, y) periods of the meanders along z
    """

    axial_length_mm: float = 200.0
    spacing_mm: float = 0.5
    radius_mm: tuple[float, float] = (4.5, 3.0)
    ellipticity: float = 0.06
    meander_mm: tuple[float, float] = (8.0, 5.0)
    period_mm: tuple[float, float] = (70.0, 55.0)


@dataclass(frozen=True)
class SyntheticVessel:
    """Centerline and wall description of the synthetic vessel.

    Attributes
    ----------
    points : (n, 3) float, mm -- inlet first, about ``spacing_mm`` apart
    radius : (n,) float, mm -- mean wall radius
    ellipticity : relative semi-axis difference of the section
    major_angle : (n,) float, rad -- angle of the major axis from the
        rotation-minimizing normal along ``points``
    """

    points: Points
    radius: FloatArray
    ellipticity: float
    major_angle: FloatArray

    @property
    def length(self) -> float:
        """Polyline arc length, mm."""
        return float(np.linalg.norm(np.diff(self.points, axis=0), axis=1).sum())

    def inscribed_radius(self) -> FloatArray:
        """VMTK's MaximumInscribedSphereRadius: the minor semi-axis, (n,) mm."""
        return self.radius * (1.0 - self.ellipticity)


def synthetic_curve(z: FloatArray, shape: SyntheticShape = SyntheticShape()) -> Points:
    """Centerline points (n, 3) mm at axial positions ``z`` (n,) mm."""
    z = np.asarray(z, float)
    (ax, ay), (px, py) = shape.meander_mm, shape.period_mm
    return np.column_stack([ax * np.sin(2 * np.pi * z / px), ay * (1.0 - np.cos(2 * np.pi * z / py)), z])


def make_synthetic_vessel(shape: SyntheticShape = SyntheticShape()) -> SyntheticVessel:
    """The synthetic vessel's centerline, resampled at equal arc length, and its radii."""
    if shape.axial_length_mm <= 0 or shape.spacing_mm <= 0:
        raise ValueError(
            f"axial_length_mm and spacing_mm must be > 0, got {shape.axial_length_mm} and {shape.spacing_mm}"
        )
    dense = synthetic_curve(np.linspace(0.0, shape.axial_length_mm, _DENSE_SAMPLES), shape)
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(dense, axis=0), axis=1))])
    count = int(round(arc[-1] / shape.spacing_mm)) + 1
    at = np.linspace(0.0, arc[-1], count)
    points = np.column_stack([np.interp(at, arc, dense[:, k]) for k in range(3)])
    u = np.linspace(0.0, 1.0, count)
    radius = shape.radius_mm[0] + (shape.radius_mm[1] - shape.radius_mm[0]) * u
    return SyntheticVessel(points, radius, shape.ellipticity, 0.8 * np.pi * u)
