"""Issue 31's layout as the swept mesher's holes, and the check that its one cross-section can hold them.

The swept mesh (:mod:`softdesign.meshing.volume_mesh.sweep_mesh`) has one cross-section
for the whole body, so every section's chambers and every feed are holes of
it at once, each existing over its own l-range.  On issue 31's layout they
all lie on one ring, 3n of them ``120 / n`` degrees apart, and neighbouring
sections' chambers come ``2 d sin(60 deg / n) - D`` apart there, closer than
the layout's own walls (which only count what exists at one l): 0.032 mm on
the demo's defaults at five sections, 0 or less when ``D - f`` exceeds twice
the layout's thinnest wall.  :mod:`softdesign.meshing.volume_mesh.section_gaps` grades
the circles' nodes at such gaps; :func:`check_resolvable` refuses, before
any meshing, a layout whose gaps no grading resolves, with the keys and
the values that would fit.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from softdesign.errors import ConfigError
from softdesign.meshing.chambers.layout import ChamberLayout
from softdesign.meshing.volume_mesh.cross_section import Circle
from softdesign.meshing.volume_mesh.sweep_mesh import Hole

#: Nodes on a chamber's and a feed's circle (at least).  Their polygons have the circle's area
#: (Circle.equal_area: nodes on r sqrt(h / sin h), h = 2 pi / n), so the cavity's volume is the layout's at any
#: count; an inscribed polygon would lose 1 - sin(h) / h of it, 2.5 % at 16 nodes and under 1 % from 26.  The
#: floors keep the circle round enough for the gap grading's reach (:func:`~softdesign.meshing.volume_mesh.section_gaps.
#: smallest_gap` is stated at MIN_CHAMBER_NODES); more nodes where the skin's are closer.
MIN_CHAMBER_NODES, MIN_FEED_NODES = 16, 12


def circle_nodes(diameter_mm: float, size_mm: float, least: int) -> int:
    """Nodes on a circle of ``diameter_mm``: its circumference over ``size_mm`` (the requested element size),
    at least ``least`` (MIN_CHAMBER_NODES or MIN_FEED_NODES), before any grading at narrow gaps."""
    return max(least, int(np.ceil(np.pi * diameter_mm / size_mm)))


def chamber_name(section: int, chamber: int) -> str:
    """``s1_c1``: the cavity of chamber ``chamber`` of section ``section`` (both 0-based in the layout), counted
    from 1 at the base as actuation.csv, ``simulate --section`` and every other output count them."""
    return f"s{section + 1}_c{chamber + 1}"


def layout_holes(layout: ChamberLayout, scale_mm: float, size_mm: float) -> list[Hole]:
    """The layout's chambers and feeds as holes of the reference section (``scale_mm`` mm per unit), each
    circle with :func:`circle_nodes` at ``size_mm`` (the volume mesh's element size, mm), before any
    grading; named by :func:`chamber_name`."""

    def circle(distance: float, angle: float, diameter: float, least: int) -> Circle:
        return Circle((distance * np.cos(angle) / scale_mm, distance * np.sin(angle) / scale_mm),
                      0.5 * diameter / scale_mm, circle_nodes(diameter, size_mm, least), equal_area=True)

    holes = []
    for c in layout.chambers:
        holes.append(Hole(chamber_name(c.section, c.index), circle(c.distance_mm, c.angle, c.diameter_mm,
                                                             MIN_CHAMBER_NODES), (c.l_start, c.l_end)))
    for f in layout.feeds:
        name = chamber_name(f.section, f.chamber)
        holes.append(Hole(f"{name}_feed", circle(f.ring_mm, f.angle, f.diameter_mm, MIN_FEED_NODES),
                          (f.l_start, f.l_end), cavity=name))
    return holes


def check_resolvable(layout: ChamberLayout, holes: list[Hole], scale_mm: float) -> list[Hole]:
    """``holes`` with their circles graded at narrow gaps (:func:`~softdesign.meshing.volume_mesh.section_gaps.
    resolve_circles`); ConfigError (exit 2) for a layout whose chambers and feeds the one cross-section
    cannot resolve.

    The section holds every section's chambers and feeds at once
    (:mod:`softdesign.meshing.volume_mesh.section_gaps`): neighbouring sections' chambers are
    ``2 d sin(60 deg / n) - D`` apart there, less than the layout's own walls.  Checked before any meshing.
    """
    from softdesign.meshing.volume_mesh.section_gaps import resolve_circles, smallest_gap, unresolved

    circles = [h.circle for h in holes]
    crossing = unresolved(circles, circles)  # touching or crossing only: no grading yet
    resolved = resolve_circles(circles) if crossing is None else circles
    bad = crossing or unresolved(circles, resolved)
    if bad is None:
        return [replace(h, circle=c) for h, c in zip(holes, resolved, strict=True)]
    raise ConfigError(_refusal(layout, holes[bad.first].name, holes[bad.second].name, bad.gap * scale_mm,
                               bad.nodes, smallest_gap(0.5 * layout.spec.diameter_mm / scale_mm, MIN_CHAMBER_NODES)
                               * scale_mm))


def _refusal(layout: ChamberLayout, first: str, second: str, gap_mm: float, nodes: int, floor_mm: float) -> str:
    """What cannot be resolved, where, and the values that would (``floor_mm``: the narrowest gap resolved)."""
    from softdesign.meshing.volume_mesh.section_gaps import MAX_CIRCLE_NODES

    spec, n = layout.spec, layout.sections
    what = (("touch" if gap_mm == 0 else "cross") if gap_mm <= 0 else
            f"are {gap_mm:.4f} mm apart, which needs {nodes} nodes on a circle (at most {MAX_CIRCLE_NODES})")
    head = f"export.volume_mesh (mesher sweep): {first} and {second} {what} in the swept mesher's cross-section"
    if {first, second} == {first.removesuffix("_feed"), first.removesuffix("_feed") + "_feed"}:  # a chamber, its feed
        return (f"{head} (a feed runs inside its chamber, {0.5 * (spec.diameter_mm - spec.feed_diameter_mm):.4f} mm "
                f"from its wall; it resolves {floor_mm:.4f} mm); use actuation.feed_diameter_mm <= "
                f"{spec.diameter_mm - 2.0 * floor_mm:.3f}, or export.volume_mesh.mesher: ftetwild")
    chord = 2.0 * spec.distance_mm * np.sin(np.pi / (3.0 * n))
    most = max((k for k in range(1, n + 1) if 2.0 * spec.distance_mm * np.sin(np.pi / (3.0 * k))
                - spec.diameter_mm >= floor_mm), default=1)
    return (f"{head}, which holds every section's chambers and feeds at once (neighbouring sections' chambers "
            f"2 d sin(60 deg / {n}) - D = {chord - spec.diameter_mm:.4f} mm apart; it resolves {floor_mm:.4f} mm); "
            f"use actuation.diameter_mm <= {chord - floor_mm:.3f}, or links.count <= {most}, or "
            "export.volume_mesh.mesher: ftetwild")
