"""A tapered chamber in a section's swept mesh (:mod:`softdesign.mechanics.section_taper`): its cavity is the
designed one layer by layer (centre at d(l), the circle's area at D(l)), the elements stay positive, and a taper
too steep for the blend is refused."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from softdesign.geometry.blend import blend_shapes
from softdesign.geometry.curves import CurveOptions, smooth_curve_from_polyline
from softdesign.geometry.frames import FramedSpline
from softdesign.geometry.initial import straight_initial_shape
from softdesign.mechanics.curved_walls import on_walls
from softdesign.mechanics.layout_section import layout_section_mesh
from softdesign.mechanics.section import SectionMesh, check_section
from softdesign.mechanics.section_taper import TaperError
from softdesign.meshing.chambers.layout import ActuationSpec, ChamberLayout, plan_layout
from softdesign.meshing.volume import BodySpec
from tests.fitting.test_fit_strain import _constant_field

RADIUS_MM, LENGTH_MM = 5.0, 30.0
SPEC = ActuationSpec(distance_mm=2.5, diameter_mm=2.0, feed_diameter_mm=0.5, end_wall_mm=1.5, first_angle_deg=90.0,
                     chambers_per_section=1)
#: The chamber's distance and diameter at its two ends (mm): it tapers by 0.2 mm both ways about the middle's.
DISTANCE_ENDS, DIAMETER_ENDS = (2.7, 2.3), (2.2, 1.8)
#: A taper the mesh cannot follow: at its base end the chamber (r = 1.1 mm) comes within 0.05 mm of the skin.
STEEP = (3.85, 1.15)
#: Volumes and centres: the polygons scale and move as similarities between layers (planar trapezoid sides), so
#: the cavity is the designed frustum to rounding.
EXACT_TOL = 1e-9
#: A midside node between two layers lies on the ruled surface between their circles (mechanics.curved_walls),
#: which leaves the tapered chamber's frustum by second order in the taper: 1.2e-4 mm measured here, mm.
RULED_TOL_MM = 1e-3


def _layout(distances: tuple[float, float], diameters: tuple[float, float]) -> tuple[ChamberLayout, FramedSpline]:
    s = np.linspace(0.0, LENGTH_MM, 801)
    line = np.column_stack([np.zeros_like(s), np.zeros_like(s), s])
    final = smooth_curve_from_polyline(line, CurveOptions(spacing_mm=0.25, smoothing_mm=0.0))
    curve0 = blend_shapes(straight_initial_shape(final), final, mode="intrinsic").curve_at(0.0)
    l = curve0.curve.dense_l()
    layout = replace(plan_layout(SPEC, (0.0, 1.0), l, curve0.curve.arc_length(l)), feeds=())
    c = layout.chambers[0]
    profile = ((c.l_start, distances[0], diameters[0]), (c.l_end, distances[1], diameters[1]))
    return replace(layout, chambers=(replace(c, profile=profile),)), curve0


def _mesh(distances: tuple[float, float], diameters: tuple[float, float], curved_walls: bool = True
          ) -> tuple[SectionMesh, ChamberLayout]:
    layout, curve0 = _layout(distances, diameters)
    section = layout_section_mesh(curve0, _constant_field(RADIUS_MM, RADIUS_MM), BodySpec(), layout, 0,
                                  size_mm=3.0, angular_count=12, layer_mm=4.0, curved_walls=curved_walls)
    return section, layout


def test_a_tapered_chamber_is_meshed_as_designed() -> None:
    # straight polygons of the circles' area (curved_walls=False): the cavity is the designed frustum to rounding
    section, layout = _mesh(DISTANCE_ENDS, DIAMETER_ENDS, curved_walls=False)
    check_section(section)  # every element positive
    chamber = layout.chambers[0]
    z0, z1 = chamber.l_start * LENGTH_MM, chamber.l_end * LENGTH_MM
    corners = section.points[section.wall_faces]
    volume = np.einsum("ij,ij->i", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])).sum() / 6
    r0, r1 = 0.5 * DIAMETER_ENDS[0], 0.5 * DIAMETER_ENDS[1]
    np.testing.assert_allclose(volume, np.pi * (z1 - z0) / 3 * (r0 * r0 + r0 * r1 + r1 * r1), rtol=EXACT_TOL)
    # layer by layer, the wall's nodes are centred at d(l) along the chamber's direction (+y)
    wall = np.unique(section.wall_faces)
    for z in np.unique(np.round(section.points[wall, 2], 9)):
        ring = wall[np.isclose(section.points[wall, 2], z) & (z > z0 + 1e-9) & (z < z1 - 1e-9)]
        if len(ring):
            expected = np.interp(z, [z0, z1], DISTANCE_ENDS)
            np.testing.assert_allclose(section.points[ring, :2].mean(axis=0), [0.0, expected], rtol=0,
                                       atol=EXACT_TOL)


def test_a_tapered_chambers_curved_wall_is_on_its_designed_circles() -> None:
    # curved walls: every layer's wall nodes, corners and side walls' midside nodes, on the circle of d(l), r(l)
    section, layout = _mesh(DISTANCE_ENDS, DIAMETER_ENDS, curved_walls=True)
    assert section.curved_edges is not None and section.curved_midpoints is not None
    chamber = layout.chambers[0]
    z0, z1 = chamber.l_start * LENGTH_MM, chamber.l_end * LENGTH_MM
    wall = np.unique(section.wall_faces)
    inner = wall[(section.points[wall, 2] > z0 + 1e-9) & (section.points[wall, 2] < z1 - 1e-9)]
    walls = section.curved_midpoints[on_walls(section)]  # the others: the rubber's, moved by the spread
    assert len(walls) > 0
    for points, tol in ((section.points[inner], EXACT_TOL), (walls, RULED_TOL_MM)):
        z = points[:, 2]
        centre = np.interp(z, [z0, z1], DISTANCE_ENDS)
        radius = 0.5 * np.interp(z, [z0, z1], DIAMETER_ENDS)
        np.testing.assert_allclose(np.hypot(points[:, 0], points[:, 1] - centre), radius, rtol=0, atol=tol)


def test_an_untapered_chamber_does_not_move() -> None:
    middle = (2.5, 2.5), (2.0, 2.0)
    tapered_flat, _ = _mesh(*middle)
    layout, curve0 = _layout(*middle)
    plain = layout_section_mesh(curve0, _constant_field(RADIUS_MM, RADIUS_MM), BodySpec(),
                                replace(layout, chambers=(replace(layout.chambers[0], profile=()),)), 0,
                                size_mm=3.0, angular_count=12, layer_mm=4.0)
    np.testing.assert_array_equal(tapered_flat.points, plain.points)
    np.testing.assert_array_equal(tapered_flat.curved_midpoints, plain.curved_midpoints)


def test_a_taper_the_blend_cannot_take_is_refused() -> None:
    with pytest.raises(TaperError, match="would crush an element"):
        _mesh(STEEP, DIAMETER_ENDS)


def test_the_device_meshes_a_taper_it_cannot_follow_as_a_cylinder_and_says_so() -> None:
    from softdesign.mechanics.device_layout import device_parts

    layout, curve0 = _layout(STEEP, DIAMETER_ENDS)
    field = _constant_field(RADIUS_MM, RADIUS_MM)
    (part,) = device_parts(curve0, field, BodySpec(), layout, 3.0, 12, 4.0)
    assert len(part.notes) == 1 and "meshed as a cylinder of its middle distance and diameter" in part.notes[0]
    cylinder = layout_section_mesh(curve0, field, BodySpec(), layout, 0, size_mm=3.0, angular_count=12,
                                   layer_mm=4.0, taper=False)
    np.testing.assert_allclose(part.mesh.points, cylinder.points, rtol=0, atol=EXACT_TOL)  # the base frame is I
