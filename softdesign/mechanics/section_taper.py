"""A tapered chamber in a section's swept mesh: the one cross-section's cylinder moved, layer by layer, onto the
chamber's designed distance and diameter.

The swept mesher (:mod:`softdesign.meshing.volume_mesh.sweep_mesh`) cuts every hole from one cross-section, so a
hole is a cylinder in the parameter domain.  A ``supply: single`` chamber tapers with the body
(:mod:`softdesign.pipeline.rod_single`: its distance d(l) and diameter D(l) sampled in ``Chamber.profile``, so
that ``P A d / (E I)`` holds the designed curvature all along).  The mesh keeps its connectivity; only its
nodes move, in each layer's (N, B) plane (mm), by

    x' = x + w(x) [(d(l) - d0) e + (D(l) / D0 - 1) (x - c0)]

where c0 = d0 e is the chamber's reference centre (its middle distance d0 along its direction e), D0 its middle
diameter, and w a weight that is 1 on and inside the chamber's circle and falls linearly, along each ray from
c0, to 0 short of the skin (or of another hole) on that ray.  On the circle the map is the similarity that
takes the reference circle onto the designed one, so the chamber's polygon (area-matched,
:mod:`softdesign.mechanics.layout_section`) keeps the designed circle's area at every layer.  The skin and the
other holes do not move; the material between is compressed on the side the chamber moves to, as the design's
own wall is thinner there.  The weight's reach is measured per ray in the reference disk, so a chamber that
moves towards the axis compresses the wide material on that side, not the thin wall to the skin.

Assumptions: the moved mesh is checked, not assumed: every layer's triangles must keep MIN_AREA_RATIO of their
area (:func:`check_taper`); a taper that would crush or fold one is refused (TaperError), and the whole device
then meshes that chamber as a cylinder of its middle values and says so.  The chamber's axis is straight
between layers (the layers are its profile's piecewise-linear samples).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from softdesign.errors import MeshError
from softdesign.meshing.chambers.layout import Chamber
from softdesign.meshing.volume_mesh.cross_section import Circle
from softdesign.types import FloatArray, IntArray

#: The blend's weight reaches 0 this share of the room short of the skin or another hole on each ray.
BLEND_MARGIN = 0.1
#: Every triangle of a moved layer keeps at least this share of its area (or is refused): a quarter keeps the
#: elements usable (their quality falls as the ratio); the design's wall is at least its wall_min_mm anyway.
MIN_AREA_RATIO = 0.25


class TaperError(MeshError):
    """A chamber's taper is more than the blend can take without folding an element (the caller may mesh it as a
    cylinder of its middle values and say so)."""


def _ray_room(local: FloatArray, centre: FloatArray, others: Sequence[Circle]) -> FloatArray:
    """Distance (P,) reference units from ``centre`` along each point's ray (``local``: the points less the
    centre, (P, 2)) to the unit circle (the skin), capped by the gap to every other circle."""
    length = np.maximum(np.linalg.norm(local, axis=1), 1e-300)
    u = local / length[:, None]
    along = u @ centre
    room = -along + np.sqrt(np.maximum(along * along - centre @ centre + 1.0, 0.0))  # |centre + t u| = 1
    for other in others:
        gap = float(np.hypot(*(np.asarray(other.center, float) - centre))) - other.node_radius(other.nodes)
        room = np.minimum(room, gap)
    return np.asarray(room, float)


def tapered_offsets(points: FloatArray, layer_l: FloatArray, chambers: Sequence[Chamber],
                    circles: Sequence[Circle], others: Sequence[Circle], scale_mm: float) -> FloatArray:
    """The nodes' moves (n, P, 2) mm in each layer's (N, B) plane that taper ``chambers`` as designed.

    Parameters
    ----------
    points : (P, 2) float, the cross-section's points, reference units (fractions of ``scale_mm``)
    layer_l : (n,) float, each layer's normalized l on the body
    chambers : the section's chambers (those without a profile do not move)
    circles : each chamber's circle in the cross-section (reference units), in ``chambers``' order
    others : every other hole's circle (feeds), which the blends keep off
    scale_mm : mm per reference unit inside the rigid core, where the chambers are

    Raises
    ------
    TaperError
        A chamber's circle leaves no room to blend before the skin.
    """
    points, layer_l = np.asarray(points, float), np.asarray(layer_l, float)
    offsets = np.zeros((len(layer_l), len(points), 2))
    for k, (chamber, circle) in enumerate(zip(chambers, circles, strict=True)):
        if not chamber.profile:
            continue
        centre, radius = np.asarray(circle.center, float), circle.node_radius(circle.nodes)
        local = points - centre
        rest = [c for j, c in enumerate(circles) if j != k] + list(others)
        reach = radius + (1.0 - BLEND_MARGIN) * (_ray_room(local, centre, rest) - radius)  # (P,)
        if np.any(reach <= radius):
            raise TaperError(f"section {chamber.section + 1}'s chamber {chamber.index + 1} leaves no room to taper "
                             "between its circle and the skin")
        direction = np.array([math.cos(chamber.angle), math.sin(chamber.angle)])
        shift = (chamber.distance_at(layer_l) - chamber.distance_mm)[:, None] * direction  # (n, 2) mm
        growth = chamber.diameter_at(layer_l) / chamber.diameter_mm - 1.0  # (n,)
        weight = np.clip((reach - np.linalg.norm(local, axis=1)) / (reach - radius), 0.0, 1.0)  # (P,)
        offsets += weight[None, :, None] * (shift[:, None, :] + growth[:, None, None] * scale_mm * local[None])
    return offsets


def check_taper(triangles: IntArray, before: FloatArray, after: FloatArray, chambers: Sequence[Chamber]) -> None:
    """TaperError unless every layer's triangles (T, 3) keep MIN_AREA_RATIO of their area from ``before`` to
    ``after`` (n, P, 2) mm: the moved mesh neither folds nor crushes an element (the layers' prisms are made of
    these triangles)."""
    def areas(xy: FloatArray) -> FloatArray:
        p = xy[:, triangles]  # (n, T, 3, 2)
        u, v = p[:, :, 1] - p[:, :, 0], p[:, :, 2] - p[:, :, 0]
        return np.asarray(0.5 * (u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]), float)

    ratio = areas(after) / areas(before)
    if ratio.min() < MIN_AREA_RATIO:
        layer = int(np.argmin(ratio.min(axis=1)))
        tapered = ", ".join(f"section {c.section + 1}'s chamber {c.index + 1}" for c in chambers if c.profile)
        raise TaperError(f"the taper of {tapered} would crush an element of layer {layer} to {ratio.min():.3g} of "
                         f"its area (at least {MIN_AREA_RATIO:g} kept)")
