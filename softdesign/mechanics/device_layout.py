"""A chambered body's sections as the whole device's parts: each meshed alone, placed on the body as cast.

Section i is meshed by :func:`~softdesign.mechanics.layout_section.layout_section_mesh`
(its own cross-section: its chambers, and the feeds of more distal chambers
that cross it as cavities, capped where its chambers end) and carried from its
base frame into the frame of the body's q = 0 centerline (the case's frame, mm).
Its centerline is sampled every ``sample_mm`` or finer for the measures.

A tapered chamber (``supply: single``) is meshed as designed, its distance
and diameter following its profile layer by layer
(:mod:`softdesign.mechanics.section_taper`), or, when its taper is more than
the mesh can follow without folding, as a cylinder of its middle values (the
part's ``notes`` say so).  What this leaves out (stated with every answer):
the short feed from the base face into section 1's chamber, and the channels
that join consecutive chambers in series, are not meshed (their walls' loads
are in the end walls, which they cross); the body's slanted end cuts are not
applied.
"""

from __future__ import annotations

import numpy as np

from softdesign.geometry.frames import FramedSpline
from softdesign.mechanics.device import DevicePart, placed_section
from softdesign.mechanics.layout_section import layout_section_mesh
from softdesign.mechanics.section_taper import TaperError
from softdesign.meshing.chambers.layout import ChamberLayout
from softdesign.meshing.volume import BodySpec

#: The centerline is measured at points at most this far apart along each section, mm.
SAMPLE_MM = 1.0
#: Fewest measured points per section (an arc's fit needs several).
MIN_SAMPLES = 9


def device_parts(curve0: FramedSpline, field: object, spec: BodySpec, layout: ChamberLayout, size_mm: float,
                 angular_count: int, layer_mm: float, curved_walls: bool = True) -> list[DevicePart]:
    """Every section of ``layout`` meshed (feeds that cross it as cavities) and placed on ``curve0``;
    ``curved_walls``: the chambers' side walls curved onto their circles (:mod:`softdesign.mechanics.curved_walls`;
    False: straight polygons of their circles' area).

    Raises
    ------
    MeshError
        As the swept mesher: a chamber that does not fit, a fold.
    """
    parts = []
    for i in range(layout.sections):
        l0, l1 = layout.breaks[i], layout.breaks[i + 1]
        notes: tuple[str, ...] = ()
        try:
            local = layout_section_mesh(curve0, field, spec, layout, i, size_mm, angular_count, layer_mm,
                                        feeds=bool(layout.feeds_through(i)), curved_walls=curved_walls)
        except TaperError as err:  # meshed as a cylinder of its middle values, and the answer says so
            local = layout_section_mesh(curve0, field, spec, layout, i, size_mm, angular_count, layer_mm,
                                        feeds=bool(layout.feeds_through(i)), taper=False, curved_walls=curved_walls)
            notes = (f"a taper the mesh cannot follow ({err}): that chamber is meshed as a cylinder of its middle "
                     "distance and diameter",)
        origin, frames = curve0.points([l0])[0], curve0.frames([l0, l1])
        s = curve0.curve.arc_length(np.array([l0, l1]))
        count = max(MIN_SAMPLES, int(np.ceil((s[1] - s[0]) / SAMPLE_MM)) + 1)
        samples = curve0.points(np.linspace(l0, l1, count))
        fed = [layout.chambers.index(next(c for c in layout.chambers if (c.section, c.index) == (f.section, f.chamber)))
               for f in layout.feeds_through(i)]
        parts.append(DevicePart(placed_section(local, origin, frames[0]), frames[0], frames[1], samples,
                                np.array(fed, np.int64), notes))
    return parts
