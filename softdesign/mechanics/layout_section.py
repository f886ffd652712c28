"""One section of a chambered body as a finite-element mesh: issue 32's swept mesh over the section alone.

The section i of a body with issue 31's chambers is meshed on its own with
the parametric mesher (:func:`softdesign.meshing.volume_mesh.sweep_mesh.swept_disk`): the
unit disk with the section's three chamber circles, swept through layers
from the section's start ``l0`` to its end ``l1``, and placed on the body at
q = 0 (the cast, unloaded state) the way the volume mesh is
(:mod:`softdesign.meshing.volume_mesh.sweep_body`: a rigid core keeps the chambers
round and at their distance, the annulus outside it is stretched to the
skin).  It differs from the body's own volume mesh in what a solve of one
section needs and can afford:

- only this section's chambers are holes; the feed lines of more distal
  chambers that run through it are left out (solid) unless asked for
  (``feeds``: cavities open at the base, capped below the tip), and the short feed from the
  section's base into its own chamber is left out (the chamber is closed);
- the layers are ``size_mm`` apart and the outer circle has ``angular_count``
  nodes (not the export's), so that a solve fits in its time;
- the section's ends are planes normal to the centerline (the body's slanted
  end cuts, at the base of section 0 and the tip of the last, are not applied);
- every polygon has its circle's area, as the surface meshes' chambers have
  (:func:`softdesign.meshing.chambers.carve.area_radius`): the chambers' and
  feeds' (their nodes on r sqrt(h / sin h), h = 2 pi / n) and the skin's
  (its corners that factor outside the surface; a regular polygon of the
  circle's area has its second moment too, to 1e-4 at 12 corners).  With the
  few nodes a solve affords (8 round a chamber, 12 round the skin), inscribed
  polygons would hold 10 % less chamber area and 8.8 % less bending stiffness
  than the design, and the FE curvature P A d / (E I) would miss it by as much.

The result is expressed in the section's base frame at q = 0: origin the
centerline's point at ``l0``, axes (N, B, T) of the body's frame there, so a
chamber's angle is its layout angle.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from softdesign.geometry.frames import FramedSpline
from softdesign.mechanics.curved_walls import round_chamber_walls
from softdesign.mechanics.section import SectionMesh
from softdesign.mechanics.section_taper import check_taper, tapered_offsets
from softdesign.meshing.chambers.carve import area_radius
from softdesign.meshing.chambers.layout import ChamberLayout
from softdesign.meshing.volume import BodySpec, angle_grid
from softdesign.meshing.volume_mesh.cross_section import Circle
from softdesign.meshing.volume_mesh.sweep_body import SweepReference, section_sweeps, section_xy
from softdesign.meshing.volume_mesh.sweep_mesh import Hole, swept_disk
from softdesign.types import FloatArray

#: The rigid core reaches this fraction of the way from the chambers' outer edge to the thinnest skin (as issue 32).
CORE_GAP_FRACTION = 0.5
#: Fewest nodes on a chamber's circle: the solve's elements are quadratic, and each chamber node adds about seven
#: more (edge midpoints) along every layer; 8 keeps a section solvable.  The polygons have their circles' area
#: (``Circle.equal_area``: nodes on r sqrt(h / sin h), h = 2 pi / n, 5.4 % outside the circle at 8): an inscribed
#: octagon held 10 % less, so the chamber's force P A and with it the FE curvature came out 10 % low.
MIN_CHAMBER_NODES = 8


def section_layers(curve0: FramedSpline, l0: float, l1: float, size_mm: float) -> FloatArray:
    """Layers (n,) in [l0, l1], about ``size_mm`` apart along the q = 0 centerline."""
    s = curve0.curve.arc_length(np.array([l0, l1]))
    count = max(2, int(np.ceil((s[1] - s[0]) / size_mm)))
    return np.linspace(l0, l1, count + 1)


def _holes(layout: ChamberLayout, section: int, scale_mm: float, size_mm: float, equal_area: bool = True
           ) -> list[Hole]:
    """The section's chambers as holes, their l-ranges in the section's own l (0 at its start, 1 at its end);
    ``equal_area``: their polygons have their circles' area (else their nodes are on the circles)."""
    l0, l1 = layout.breaks[section], layout.breaks[section + 1]
    holes = []
    for c in layout.section_chambers(section):
        radius = 0.5 * c.diameter_mm / scale_mm
        nodes = max(MIN_CHAMBER_NODES, int(np.ceil(np.pi * c.diameter_mm / size_mm)))
        centre = (c.distance_mm * np.cos(c.angle) / scale_mm, c.distance_mm * np.sin(c.angle) / scale_mm)
        own = ((c.l_start - l0) / (l1 - l0), (c.l_end - l0) / (l1 - l0))
        holes.append(Hole(f"s{section}_c{c.index}", Circle(centre, radius, nodes, equal_area=equal_area), own))
    return holes


def _feed_holes(layout: ChamberLayout, section: int, scale_mm: float, size_mm: float) -> list[Hole]:
    """The feeds that cross the section, as holes open at its base and closed where its chambers end (the end
    wall below its tip: the wall the feed's pressure pulls on, for the distal part the section leaves out)."""
    l0, l1 = layout.breaks[section], layout.breaks[section + 1]
    cap = max((c.l_end - l0) / (l1 - l0) for c in layout.section_chambers(section))
    holes = []
    for f in layout.feeds_through(section):
        nodes = max(MIN_CHAMBER_NODES, int(np.ceil(np.pi * f.diameter_mm / size_mm)))
        centre = (f.ring_mm * np.cos(f.angle) / scale_mm, f.ring_mm * np.sin(f.angle) / scale_mm)
        holes.append(Hole(f"s{f.section}_f{f.chamber}",
                          Circle(centre, 0.5 * f.diameter_mm / scale_mm, nodes, equal_area=True), (0.0, cap)))
    return holes


def layout_section_mesh(curve0: FramedSpline, field: object, spec: BodySpec, layout: ChamberLayout, section: int,
                        size_mm: float, angular_count: int, layer_mm: float, feeds: bool = False,
                        taper: bool = True, curved_walls: bool = True) -> SectionMesh:
    """Section ``section``'s mesh at q = 0 in its base frame, with its base fixed and chamber walls named.

    Parameters
    ----------
    curve0 : the centerline at q = 0
    field : the fit's radius field (``evaluate_grid(q, l, angles)``)
    spec : the body's offset (its wall must be 0: chambers and a single hollow chamber exclude each other)
    layout : the chambers
    section : index, 0 at the base
    size_mm : edge length inside the cross-section, mm
    angular_count : nodes on the outer circle
    layer_mm : spacing of the layers along the centerline, mm
    feeds : mesh the feeds of distal chambers that cross the section as cavities (``feed_faces``: their walls
        and a cap where the section's chambers end, which carries the pull of the feed's pressure on the
        distal part), not solid
    taper : mesh a tapered chamber as designed (:mod:`softdesign.mechanics.section_taper`); False: as a cylinder
        of its middle distance and diameter
    curved_walls : the chambers' nodes on their circles and their side walls' midside nodes too, the bow spread
        into the rubber (:mod:`softdesign.mechanics.curved_walls`; the default: under one refinement the
        reinforced section's curvature moves -0.44 % at the simulate command's mesh, -3.83 % straight); False:
        polygons of their circles' area, straight (the model of rounds 1-4 until the mixed fibres' retry,
        :mod:`softdesign.mechanics.newton`, let the aorta's curved device reach its P*)

    Raises
    ------
    MeshError
        As the swept mesher: a chamber that does not fit, a fold; TaperError: a taper the mesh cannot follow.
    """
    l0, l1 = layout.breaks[section], layout.breaks[section + 1]
    layers = section_layers(curve0, l0, l1, layer_mm)
    rho = field.evaluate_grid(0.0, layers, angle_grid(angular_count))  # type: ignore[attr-defined]
    scale = float(np.median(rho))
    chambers = layout.section_chambers(section)
    holes = _holes(layout, section, scale, size_mm, equal_area=not curved_walls)
    feed_holes = _feed_holes(layout, section, scale, size_mm) if feeds else []
    # the area-matched polygons' corners reach past the circles: the rigid core holds them (round and in place)
    reach = scale * max(math.hypot(*h.circle.center) + h.circle.node_radius(h.circle.nodes) for h in holes + feed_holes)
    core_mm = reach + CORE_GAP_FRACTION * (float(np.min(rho)) - reach)
    # the mesher sweeps l from 0 to 1: the section's own l, put back on the body's before placing
    own = swept_disk(angular_count, holes + feed_holes, size_mm / scale, (layers - l0) / (l1 - l0))
    mesh = replace(own, l=l0 + own.l * (l1 - l0))
    ref = SweepReference(core=core_mm / scale, scale_mm=scale)
    outer, inner = section_sweeps(mesh, ref, curve0, field, 0.0, spec, angular_count)  # type: ignore[arg-type]
    # the skin's polygon with the outline's area (and, to 1e-4 at 12 nodes, its second moment): inscribed, its
    # angular_count corners on the surface would leave 8.8 % of the bending stiffness out at the default 12
    outer = replace(outer, xy=outer.xy * area_radius(1.0, angular_count))
    xy = section_xy(mesh.section.points, outer, inner, ref)
    # a tapered chamber (supply: single) moved layer by layer onto its designed distance and diameter
    circles = [h.circle for h in mesh.holes]
    if taper:
        moved = xy + tapered_offsets(mesh.section.points, mesh.l, chambers, circles[:len(holes)],
                                     circles[len(holes):], scale)
        check_taper(mesh.section.triangles, xy, moved, chambers)
        xy = moved
    frames = outer.frames[:, None, :, :]
    grid = outer.centers[:, None, :] + xy[..., :1] * frames[..., 0] + xy[..., 1:] * frames[..., 1]
    world = grid[mesh.node_layer, mesh.node_point]
    origin, frame = curve0.points([l0])[0], curve0.frames([l0])[0]
    local = (world - origin) @ frame
    walls = [mesh.cavity_surface(h.name) for h in holes]
    centerline = (curve0.points(mesh.l) - origin) @ frame
    s = curve0.curve.arc_length(mesh.l)
    # a feed's wall and cap, out of the feed; its inlet lid is on the fixed base (no work, no volume: z = 0)
    feed_walls = [np.concatenate([mesh.group_faces(f"{h.name}_{part}") for part in ("wall", "cap")])[:, ::-1]
                  for h in feed_holes]
    feed_parts = (np.concatenate(feed_walls),
                  np.concatenate([np.full(len(w), k, np.int64) for k, w in enumerate(feed_walls)]),
                  np.array([0.5 * f.diameter_mm for f in layout.feeds_through(section)])) if feed_walls else (
                      None, None, None)
    made = SectionMesh(local, mesh.tets, mesh.node_layer == 0, np.concatenate(walls),
                       np.concatenate([np.full(len(w), k, np.int64) for k, w in enumerate(walls)]),
                       centerline, (s - s[0])[mesh.node_layer], np.array([c.angle for c in chambers]),
                       np.array([0.5 * c.diameter_mm for c in chambers]), *feed_parts)
    return round_chamber_walls(made) if curved_walls else made
