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
    :func:`offset_metric` gives that metric a block of rows at a time.
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
from softdesign.fitting.radius_rows import SlopeRows, row_blocks
from softdesign.fitting.strain import SectionDerivatives, curve_terms, metric_from_planes
from softdesign.geometry.frames import FramedSpline
from softdesign.meshing.body.sections import body_sections
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


def offset_metric(curve: FramedSpline, field: RadiusField, q: float, l: npt.ArrayLike, angular_count: int,
                  offset_mm: float, frames_mode: str = "rmf") -> FloatArray:
    """``metric_from_sections(offset_sections(...))``, (p, m, 3), a block of rows at a time: the same bits.

    The sections at l and at l +- h are built a block of rows at a time
    (about ``BLOCK_POINTS`` points, as the skin's metric), rho and rho_l from
    one pass over the radius field per grid (:class:`SlopeRows`, the numbers
    of ``evaluate_grid``), the centerline's terms once per grid: every value
    is computed point by point, or row by row for the a-derivatives (a
    transform of each row), so the blocks change no bit.
    """
    l = np.asarray(l, float).reshape(-1)
    a = angle_grid(angular_count)
    h = FD_STEP_MM / curve.length
    grids = (l, l + h, l - h)
    terms = [curve_terms(curve, at, frames_mode) for at in grids]
    rows = [SlopeRows(field, q, at, a, angular=False) for at in grids]
    cos, sin = np.cos(a), np.sin(a)
    planes = np.empty((3, len(l), len(a)))
    for block in row_blocks(len(l), len(a)):
        xy, plus, minus = (_offset_xy(*r.along(block.start, block.stop), speed[block], curvature[block], offset_mm,
                                      cos, sin) for r, (speed, curvature, _) in zip(rows, terms, strict=True))
        xy_l = np.subtract(plus, minus, out=plus)
        xy_l /= 2.0 * h
        xy_a = angular_derivative(xy)
        speed, curvature, twist = terms[0]
        metric_from_planes(speed[block], curvature[block], twist[block], xy[0], xy[1], xy_l[0], xy_l[1], xy_a[0],
                           xy_a[1], out=planes[:, block])
    return np.moveaxis(planes, 0, -1)


def _offset_xy(rho: FloatArray, rho_l: FloatArray, speed: FloatArray, curvature: FloatArray, offset_mm: float,
               cos: FloatArray, sin: FloatArray) -> FloatArray:
    """``section_curves(rho, rho_l / speed, curvature, offset_mm)`` as (x, y) planes (2, b, m): its operations
    on the same numbers in the same order."""
    xy = np.empty((2,) + rho.shape)
    x, y = xy
    np.multiply(rho, cos, out=x)  # points = rho u, u = (cos, sin)
    np.multiply(rho, sin, out=y)
    if offset_mm == 0.0:
        return xy
    rho_a = angular_derivative(rho)
    in_x = x - rho_a * -sin  # in_plane = rho u - rho_a w, w = (-sin, cos)
    in_y = y - rho_a * cos
    span = np.square(in_x)  # |in_plane|, as np.linalg.norm adds the squares
    span += np.square(in_y, out=rho_a)
    np.sqrt(span, out=span)
    stretch = curvature[:, :1] * cos  # 1 - rho kn
    stretch += curvature[:, 1:] * sin
    stretch *= rho
    np.subtract(1.0, stretch, out=stretch)
    stretch *= span
    tan_beta = rho_l / speed[:, None]  # rho rho_s / (stretch span)
    tan_beta *= rho
    tan_beta /= stretch
    factor = np.square(tan_beta, out=tan_beta)  # offset sqrt(1 + tan_beta^2) / span
    factor += 1.0
    np.sqrt(factor, out=factor)
    factor *= offset_mm
    factor /= span
    x += np.multiply(factor, in_x, out=in_x)
    y += np.multiply(factor, in_y, out=in_y)
    return xy


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

