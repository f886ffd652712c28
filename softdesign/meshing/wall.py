"""The wall of a hollow body: the metric of offset surfaces (the chamber) and the wall's true thickness.

Offset surfaces
    The chamber (and an offset outer skin) is the section curve of
    :func:`softdesign.meshing.volume.section_curves` at every l: the exporter's
    own definition.  Its metric uses
    :func:`softdesign.fitting.strain.metric_from_sections` with the a-derivative
    taken spectrally on the angle grid (as the offset itself takes rho_a) and
    the l-derivative by a central difference of step ``FD_STEP_MM`` of arc
    length (truncation ~ (h/2)^2 x the third derivative: below 1e-9 relative
    on vessel-sized bodies; the offset has no closed-form l-derivative).
Thickness
    The true distance from every chamber vertex (exact points of the chamber
    surface, on its (l, a) grid) to the outer surface's triangles, with vtk's
    cell locator (:mod:`softdesign.meshing.compare`).  The outer mesh is a
    polygon inscribed in the true surface, so the distance errs low by at most
    the chord sagitta ``rho (1 - cos(pi / na))`` around and the ring spacing's
    sagitta along; :func:`tessellation_error_mm` bounds it.
Port
    The thinnest material around the inlet channel: for outer-surface points
    within the base cap's thickness, their distance from the port's axis minus
    the port's radius.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.fitting.radius_field import RadiusField
from softdesign.fitting.strain import SectionDerivatives, curve_terms
from softdesign.geometry.frames import FramedSpline
from softdesign.meshing.body import body_sections
from softdesign.meshing.compare import squared_distances
from softdesign.meshing.tessellate import Sweep, ring_points, sweep_from_sections, tessellate
from softdesign.meshing.volume import BodySpec, angle_grid, angular_derivative, section_curves
from softdesign.types import FloatArray

#: Arc-length step of the central difference along l of an offset section, mm.
FD_STEP_MM = 1e-3


def offset_sections(curve: FramedSpline, field: RadiusField, q: float, l: npt.ArrayLike, angular_count: int,
                    offset_mm: float, frames_mode: str = "rmf") -> SectionDerivatives:
    """The surface offset by ``offset_mm`` along its normal (< 0: inward, the chamber) with its derivatives.

    ``l`` must keep ``FD_STEP_MM`` of arc length from both ends (the chamber is
    ``wall_mm`` short of them).
    """
    l = np.asarray(l, float)
    a = angle_grid(angular_count)
    h = FD_STEP_MM / curve.length

    def xy_at(at: FloatArray) -> FloatArray:
        speed, curvature, _ = curve_terms(curve, at, frames_mode)
        rho = field.evaluate_grid(q, at, a)
        rho_s = field.evaluate_grid(q, at, a, dl=1) / speed[:, None]
        return section_curves(rho, rho_s, curvature, offset_mm)

    speed, curvature, twist = curve_terms(curve, l, frames_mode)
    xy = xy_at(l)
    xy_l = (xy_at(l + h) - xy_at(l - h)) / (2.0 * h)
    xy_a = np.moveaxis(angular_derivative(np.moveaxis(xy, -1, 0)), 0, -1)
    return SectionDerivatives(speed, curvature, twist, xy, xy_l, xy_a)


@dataclass(frozen=True)
class ThinSpot:
    """The thinnest wall found and where: ``thickness_mm`` at normalized ``l``, angle ``a`` (rad)."""

    thickness_mm: float
    l: float
    a: float


def wall_distances(
    inner_points: npt.ArrayLike, outer_vertices: npt.ArrayLike, outer_faces: npt.ArrayLike
) -> FloatArray:
    """True distance (mm) from each inner point (..., 3) to the outer triangle mesh, same leading shape."""
    points = np.asarray(inner_points, float)
    flat = points.reshape(-1, 3)
    squared = squared_distances(flat, np.asarray(outer_vertices, float), np.asarray(outer_faces, np.int64))
    return np.sqrt(squared).reshape(points.shape[:-1])


def thinnest(distances: npt.ArrayLike, l: npt.ArrayLike, angles: npt.ArrayLike, mask=None) -> ThinSpot:
    """The smallest of ``distances`` (p, m) on the grid l (p,) x angles (m,), optionally where ``mask`` (p,)."""
    d = np.asarray(distances, float)
    if mask is not None:
        d = np.where(np.asarray(mask, bool)[:, None], d, np.inf)
    i, k = np.unravel_index(int(np.argmin(d)), d.shape)
    return ThinSpot(float(d[i, k]), float(np.asarray(l)[i]), float(np.asarray(angles)[k]))


def port_wall_mm(outer_points: npt.ArrayLike, base: npt.ArrayLike, axis: npt.ArrayLike, port_mm: float,
                 depth_mm: float) -> ThinSpot:
    """Thinnest material between the port channel and the outer surface within ``depth_mm`` of the base.

    Parameters
    ----------
    outer_points : (n, m, 3) float, mm, rings of the outer surface (ring 0 the base)
    base : (3,) float, mm, the base centre (the port's axis passes through it)
    axis : (3,) float, the base tangent (the port's direction)
    port_mm : float, the channel's diameter
    depth_mm : float, how far along the axis the channel runs in material (the base cap's thickness)

    Returns the smallest ``|p - axis| - port_mm / 2`` with its ring's index as ``l`` and angle index as ``a``.
    """
    p = np.asarray(outer_points, float) - np.asarray(base, float)
    t = np.asarray(axis, float) / np.linalg.norm(axis)
    along = p @ t
    radial = np.linalg.norm(p - along[..., None] * t, axis=-1) - 0.5 * port_mm
    inside = (along >= -1e-9) & (along <= depth_mm + 1e-9)
    radial = np.where(inside, radial, np.inf)
    i, k = np.unravel_index(int(np.argmin(radial)), radial.shape)
    return ThinSpot(float(radial[i, k]), float(i), float(k))


def tessellation_error_mm(radius_mm: float, angular_count: int) -> float:
    """How far a chord of the na-gon inscribed in a circle of ``radius_mm`` falls inside it, mm."""
    return float(radius_mm * (1.0 - np.cos(np.pi / angular_count)))


@dataclass(frozen=True)
class WallMap:
    """The wall's thickness at every chamber vertex of a hollow body at one q.

    Attributes
    ----------
    l : (p,) float, the chamber's rings in normalized l
    a : (m,) float, rad, the angle grid
    thickness_mm : (p, m) float, true distance to the outer surface's mesh
    outer : the outer sweep (its first ring is the base, where the port enters)
    """

    l: FloatArray
    a: FloatArray
    thickness_mm: FloatArray
    outer: Sweep


def wall_map(curve: FramedSpline, field: RadiusField, q: float, spec: BodySpec, spacing_mm: float,
             angular_count: int) -> WallMap:
    """Chamber and outer surface as the exporter builds them at q, and the distance between them.

    Raises
    ------
    MeshError
        As the export would: a fold, or a wall the local radius cannot take.
    """
    from softdesign.meshing.solids import _chamber  # the exporter's own chamber, trimmed wall_mm short of the ends

    sections = body_sections(curve, field, q, spacing_mm, angular_count)
    outer = sweep_from_sections(sections, spec.offset_mm, spec.min_radius_mm)
    body = tessellate(outer)
    chamber = _chamber(sections, outer, spec)
    distances = wall_distances(ring_points(chamber), body.vertices, body.faces)
    return WallMap(chamber.l, angle_grid(angular_count), distances, outer)

