"""Vessels of the sample cohort: the sample vessel's kind of network in other shapes and sizes.

Each :class:`VesselVariant` gives a main path (a closed-form 3-D curve named
by ``path``), a radius tapering linearly from inlet to outlet, an elliptical
section like the sample vessel's, and one side branch leaving the trunk
towards ``branch_side``.  :func:`make_variant_vessel` returns the same
:class:`~softdesign.samples.sample_vessel.SampleVessel` the sample generator
builds, so :func:`softdesign.samples.surfaces.sample_surface` makes its
capped wall.  Pure geometry, mm.

Paths (``s`` runs over ``[0, length_mm]`` before arc-length resampling)
    meander  the sample vessel's own 3-D meander
    arch     an aortic-arch-like half turn of radius ``length / pi`` rising
             out of its plane (curvature ~ pi / length)
    helix    a coil of radius 6 mm and pitch 24 mm (curvature 0.12 /mm)
    s_bend   a planar S, 8 mm either side of its axis over the length
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from softdesign.samples.sample_vessel import SampleVessel, main_curve
from softdesign.types import FloatArray, Points

#: Dense samples of a path before arc-length resampling.
_DENSE_SAMPLES = 20001
#: The branch bends away from the trunk over this arc length (smoothstep), mm.
_BRANCH_RAMP_MM = 12.0
#: Helix radius and pitch, mm.
_HELIX_RADIUS_MM, _HELIX_PITCH_MM = 6.0, 24.0
#: Half-width of the S bend, mm.
_S_BEND_AMPLITUDE_MM = 8.0


@dataclass(frozen=True)
class VesselVariant:
    """One vessel of the sample cohort (mm, degrees where named).

    Attributes
    ----------
    name : the case name (folder under data/cohort)
    path : ``meander``, ``arch``, ``helix`` or ``s_bend``
    length_mm : parameter range of the path (about its arc length)
    radius_mm : (inlet, outlet) mean wall radius, linear in between
    ellipticity : relative semi-axis difference of the main vessel's section
    branch_at_mm : arc length of the trunk where the side branch leaves
    branch_length_mm, branch_radius_mm : the branch's length and (constant) radius
    branch_angle_deg : final angle between the branch and the trunk's tangent
    branch_side : direction the branch turns towards (made normal to the trunk)
    """

    name: str
    path: str
    length_mm: float
    radius_mm: tuple[float, float]
    ellipticity: float
    branch_at_mm: float
    branch_length_mm: float
    branch_radius_mm: float
    branch_angle_deg: float
    branch_side: tuple[float, float, float]
    spacing_mm: float = 0.5


#: The sample cohort: four shapes, radii from 1.6 to 5 mm (see configs/cohort/).
COHORT_VARIANTS: tuple[VesselVariant, ...] = (
    VesselVariant("arch", "arch", 75.0, (5.0, 4.2), 0.06, 30.0, 20.0, 2.0, 70.0, (0.0, 1.0, 0.0)),
    VesselVariant("coil", "helix", 70.0, (1.8, 1.5), 0.04, 20.0, 15.0, 1.0, 50.0, (1.0, 0.0, 0.0)),
    VesselVariant("meander", "meander", 60.0, (3.0, 2.6), 0.08, 25.0, 18.0, 1.8, 45.0, (1.0, 0.0, 0.0)),
    VesselVariant("s_bend", "s_bend", 55.0, (2.4, 2.0), 0.0, 15.0, 15.0, 1.4, 60.0, (0.0, 1.0, 0.0)),
)


def _arch(s: FloatArray, length: float) -> Points:
    radius = length / np.pi
    theta = s / radius
    return np.column_stack([radius * (1.0 - np.cos(theta)), 3.0 * np.sin(0.5 * theta) ** 2, radius * np.sin(theta)])


def _helix(s: FloatArray, length: float) -> Points:
    c = _HELIX_PITCH_MM / (2.0 * np.pi)
    t = s / np.hypot(_HELIX_RADIUS_MM, c)
    return np.column_stack([_HELIX_RADIUS_MM * (np.cos(t) - 1.0), _HELIX_RADIUS_MM * np.sin(t), c * t])


def _s_bend(s: FloatArray, length: float) -> Points:
    return np.column_stack([_S_BEND_AMPLITUDE_MM * np.sin(2.0 * np.pi * s / length), np.zeros_like(s), s])


_PATHS: dict[str, Callable[[FloatArray, float], Points]] = {
    "arch": _arch,
    "helix": _helix,
    "meander": lambda s, length: main_curve(s),
    "s_bend": _s_bend,
}


def variant_named(name: str) -> VesselVariant:
    """The cohort variant called ``name``.

    Raises
    ------
    ValueError
        No variant has that name (the message lists them).
    """
    for variant in COHORT_VARIANTS:
        if variant.name == name:
            return variant
    names = ", ".join(v.name for v in COHORT_VARIANTS)
    raise ValueError(f"no sample cohort vessel named {name!r}; expected one of {names}")


def make_variant_vessel(variant: VesselVariant) -> SampleVessel:
    """Centerlines (main and branch, inlet first, sharing the trunk) and radii of a variant.

    Raises
    ------
    ValueError
        An unknown path kind, or a branch that does not fit (starts past the
        trunk's end, or is not thinner than the trunk).
    """
    if variant.path not in _PATHS:
        raise ValueError(f"{variant.name}: path must be one of {', '.join(sorted(_PATHS))}, got {variant.path!r}")
    dense = _PATHS[variant.path](np.linspace(0.0, variant.length_mm, _DENSE_SAMPLES), variant.length_mm)
    main = _resampled(dense, variant.spacing_mm)
    u = np.linspace(0.0, 1.0, len(main))
    main_radius = variant.radius_mm[0] + (variant.radius_mm[1] - variant.radius_mm[0]) * u
    branch, branch_radius = _branch(main, main_radius, variant)
    major_angle = 0.5 * np.pi * u
    return SampleVessel(main, branch, main_radius, branch_radius, variant.ellipticity, major_angle)


def _resampled(points: Points, spacing_mm: float) -> Points:
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    count = int(round(arc[-1] / spacing_mm)) + 1
    target = np.linspace(0.0, arc[-1], count)
    return np.column_stack([np.interp(target, arc, points[:, k]) for k in range(3)])


def _branch(main: Points, main_radius: FloatArray, variant: VesselVariant) -> tuple[Points, FloatArray]:
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(main, axis=0), axis=1))])
    at = int(np.searchsorted(arc, variant.branch_at_mm))
    if not 0 < at < len(main) - 1:
        raise ValueError(
            f"{variant.name}: branch_at_mm {variant.branch_at_mm} must lie inside the trunk (0, {arc[-1]:.1f})"
        )
    if variant.branch_radius_mm >= (1.0 - variant.ellipticity) * main_radius[at]:
        raise ValueError(
            f"{variant.name}: the branch (radius {variant.branch_radius_mm} mm) must be thinner than the trunk"
        )
    tangent = main[at + 1] - main[at - 1]
    tangent /= np.linalg.norm(tangent)
    side = np.asarray(variant.branch_side, float)
    side = side - side.dot(tangent) * tangent
    side /= np.linalg.norm(side)
    n = int(round(variant.branch_length_mm / variant.spacing_mm))
    step = np.arange(1, n + 1) * variant.spacing_mm
    ramp = np.clip(step / _BRANCH_RAMP_MM, 0.0, 1.0)
    angle = np.deg2rad(variant.branch_angle_deg) * ramp**2 * (3.0 - 2.0 * ramp)
    directions = np.cos(angle)[:, None] * tangent + np.sin(angle)[:, None] * side
    limb = main[at] + np.cumsum(directions * variant.spacing_mm, axis=0)
    branch = np.concatenate([main[: at + 1], limb])
    radius = np.concatenate([main_radius[: at + 1], np.full(n, variant.branch_radius_mm)])
    return branch, radius
