"""A tapered chamber in a section's swept mesh: the one cross-section's cylinder moved, layer by layer, onto the
chamber's designed distance and diameter.

The swept mesher (:mod:`softdesign.meshing.volume_mesh.sweep_mesh`) cuts every hole from one cross-section, so a
hole is a cylinder in the parameter domain.  A ``supply: single`` chamber tapers with the body
(:mod:`softdesign.pipeline.rod_single`: its distance d(l) and diameter D(l) sampled in ``Chamber.profile``, so
that ``P A d / (E I)`` holds the designed curvature all along).  The mesh keeps its connectivity; only its
nodes move, in each layer's (N, B) plane (mm), by

    x' = x + w(x) [(d(l) - d0) e + (D(l) / D0 - 1) (x - c0)]

where c0 = d0 e is the chamber's reference centre (its middle distance d0 along its direction e), D0 its middle
diameter, and w a weight that is 1 on and inside the chamber's circle and falls linearly to 0 at ``reach`` from
its centre.  On the circle the map is the similarity that takes the reference circle onto the designed one, so
the chamber's polygon (area-matched, :mod:`softdesign.mechanics.layout_section`) keeps the designed circle's area
at every layer.  ``reach`` stays inside the rigid core and off every other hole, so the skin, the other holes
and the thread's fibres elsewhere do not move.

Assumptions: the taper is gentle (its change over a section, |d - d0| + |D/D0 - 1| r, is small against the
blend's width ``reach - r``; :func:`tapered_offsets` refuses one that would fold an element, and the whole device
then meshes that chamber as a cylinder of its middle values and says so), and the chamber's axis stays straight
between layers (the layers are its profile's piecewise-linear samples).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from softdesign.errors import MeshError
from softdesign.meshing.chambers.layout import Chamber
from softdesign.meshing.volume_mesh.cross_section import Circle
from softdesign.types import FloatArray

#: The blend keeps this share of the room between a chamber's circle and the nearest other circle or the core's
#: rim clear (its weight reaches 0 before them).
BLEND_MARGIN = 0.1
#: The largest move of the blend over its width: beyond it an element could fold (the map's Jacobian is
#: 1 - move / width at worst); a taper of a few per cent moves a tenth of this.
MAX_BLEND_STRAIN = 0.5


class TaperError(MeshError):
    """A chamber's taper is more than the blend can take without folding an element (the caller may mesh it as a
    cylinder of its middle values and say so)."""


def _reach(circle: Circle, others: Sequence[Circle], core: float) -> float:
    """Where the weight of ``circle``'s blend reaches 0, reference units: short of the core's rim and of every
    other circle by BLEND_MARGIN of the room left."""
    centre = np.asarray(circle.center, float)
    room = core - float(np.hypot(*centre))
    for other in others:
        gap = float(np.hypot(*(np.asarray(other.center, float) - centre))) - other.node_radius(other.nodes)
        room = min(room, gap)
    radius = circle.node_radius(circle.nodes)
    return radius + (1.0 - BLEND_MARGIN) * (room - radius)


def tapered_offsets(points: FloatArray, layer_l: FloatArray, chambers: Sequence[Chamber],
                    circles: Sequence[Circle], others: Sequence[Circle], core: float, scale_mm: float) -> FloatArray:
    """The nodes' moves (n, P, 2) mm in each layer's (N, B) plane that taper ``chambers`` as designed.

    Parameters
    ----------
    points : (P, 2) float, the cross-section's points, reference units (fractions of ``scale_mm``)
    layer_l : (n,) float, each layer's normalized l on the body
    chambers : the section's chambers (those without a profile do not move)
    circles : each chamber's circle in the cross-section (reference units), in ``chambers``' order
    others : every other hole's circle (feeds), which the blends keep off
    core : the rigid core's radius, reference units (inside it a point is ``scale_mm`` times its coordinates)
    scale_mm : mm per reference unit

    Raises
    ------
    TaperError
        A chamber's circle leaves no room to blend, or its taper would move nodes by more than
        MAX_BLEND_STRAIN of the blend's width (a fold).
    """
    points, layer_l = np.asarray(points, float), np.asarray(layer_l, float)
    offsets = np.zeros((len(layer_l), len(points), 2))
    for k, (chamber, circle) in enumerate(zip(chambers, circles, strict=True)):
        if not chamber.profile:
            continue
        rest = [c for j, c in enumerate(circles) if j != k] + list(others)
        reach, radius = _reach(circle, rest, core), circle.node_radius(circle.nodes)
        direction = np.array([math.cos(chamber.angle), math.sin(chamber.angle)])
        shift = (chamber.distance_at(layer_l) - chamber.distance_mm)[:, None] * direction  # (n, 2) mm
        growth = chamber.diameter_at(layer_l) / chamber.diameter_mm - 1.0  # (n,)
        move = float(np.max(np.linalg.norm(shift, axis=1) + np.abs(growth) * radius * scale_mm))
        width = (reach - radius) * scale_mm
        if not width > 0 or move > MAX_BLEND_STRAIN * width:
            raise TaperError(f"section {chamber.section + 1}'s chamber {chamber.index + 1} tapers by {move:.3g} mm, "
                             f"more than {MAX_BLEND_STRAIN:g} of the {max(width, 0.0):.3g} mm between its circle and "
                             "the next hole or the rigid core's rim: moving the cylinder's nodes would fold the mesh")
        local = points - np.asarray(circle.center, float)
        weight = np.clip((reach - np.linalg.norm(local, axis=1)) / (reach - radius), 0.0, 1.0)  # (P,)
        offsets += weight[None, :, None] * (shift[:, None, :] + growth[:, None, None] * scale_mm * local[None])
    return offsets
