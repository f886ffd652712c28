"""The feeds of distal chambers that cross a section, meshed as cavities (``layout_section_mesh(feeds=True)``):
open on the fixed base, capped where the section's chambers end, their pressures a separate vector."""

from __future__ import annotations

import functools

import numpy as np
import pytest

from softdesign.geometry.blend import blend_shapes
from softdesign.geometry.curves import CurveOptions, smooth_curve_from_polyline
from softdesign.geometry.initial import straight_initial_shape
from softdesign.mechanics.layout_section import layout_section_mesh
from softdesign.mechanics.newton import NewtonSettings
from softdesign.mechanics.section import SectionMesh, simulate_section
from softdesign.meshing.chambers.layout import ChamberLayout, plan_layout
from softdesign.meshing.volume import BodySpec
from tests.fitting.test_fit_strain import _constant_field
from tests.mechanics.test_section_symmetry import LAW, MU, RADIUS_MM, SPEC

#: a 30 mm section (six radii) of a straight two-section body, so that its ends matter little
LENGTH_MM = 60.0
#: the feed's polygon volume against the mesh's cavity: the same prisms, to rounding
VOLUME_RTOL = 1e-9
#: incompressible: E = 3 mu
YOUNG_KPA = 3 * MU


@functools.cache
def _section() -> tuple[SectionMesh, ChamberLayout]:
    s = np.linspace(0.0, LENGTH_MM, 801)
    line = np.column_stack([np.zeros_like(s), np.zeros_like(s), s])
    final = smooth_curve_from_polyline(line, CurveOptions(spacing_mm=0.25, smoothing_mm=0.0))
    curve0 = blend_shapes(straight_initial_shape(final), final, mode="intrinsic").curve_at(0.0)
    l = curve0.curve.dense_l()
    layout = plan_layout(SPEC, (0.0, 0.5, 1.0), l, curve0.curve.arc_length(l))
    section = layout_section_mesh(curve0, _constant_field(RADIUS_MM, RADIUS_MM), BodySpec(), layout, 0,
                                  size_mm=3.0, angular_count=12, layer_mm=8.0, feeds=True)
    return section, layout


def test_the_feeds_crossing_a_section_are_cavities_open_on_its_base_only() -> None:
    section, layout = _section()
    assert section.feed_count == len(layout.feeds_through(0)) == 3
    assert section.feed_faces is not None and section.face_feed is not None
    chamber_end = max(c.l_end for c in layout.section_chambers(0)) * LENGTH_MM
    for k in range(section.feed_count):
        faces = section.feed_faces[section.face_feed == k]
        edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
        unique, counts = np.unique(edges, axis=0, return_counts=True)
        open_edges = unique[counts == 1]
        assert len(open_edges) and np.all(np.abs(section.points[open_edges, 2]) < 1e-9)  # only the base ring
        assert np.all(counts <= 2)
        # the cap where the chambers end; its volume, from the closed surface less the base (z = 0 there)
        corners = section.points[faces]
        volume = np.einsum("ij,ij->i", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])).sum() / 6
        assert section.points[np.unique(faces), 2].max() == pytest.approx(chamber_end, abs=1e-6)
        ring = np.unique(open_edges)
        xy = section.points[ring, :2] - section.points[ring, :2].mean(axis=0)
        order = np.argsort(np.arctan2(xy[:, 1], xy[:, 0]))
        x, y = xy[order, 0], xy[order, 1]
        area = 0.5 * abs(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
        np.testing.assert_allclose(volume, area * chamber_end, rtol=VOLUME_RTOL)


def test_feed_pressures_must_match_the_feeds() -> None:
    section, _ = _section()
    with pytest.raises(ValueError, match="3 feed pressures"):
        simulate_section(section, LAW, np.zeros(3), NewtonSettings(load_steps=1), None, np.zeros(2))


def _beam_curvature(section: SectionMesh, layout: ChamberLayout, pressure_kpa: float) -> float:
    """P A_f d_f / (E I): feed 0's area A_f (mm^2, its polygon's and circle's) at d_f (mm) from the axis, I (mm^4)
    of the material about the axis normal to the feed's direction, integrated over the tets of the layer band at
    mid-length."""
    feed = layout.feeds_through(0)[0]
    assert section.feed_faces is not None and section.face_feed is not None
    ring = np.unique(section.feed_faces[section.face_feed == 0])
    ring = ring[np.abs(section.points[ring, 2]) < 1e-9]
    area = np.pi * (0.5 * feed.diameter_mm) ** 2  # the mesh's polygon has the designed circle's area
    c = section.points[section.tets]
    volume = np.abs(np.einsum("ij,ij->i", np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]), c[:, 3] - c[:, 0])) / 6
    y = c @ np.array([np.cos(feed.angle), np.sin(feed.angle), 0.0])
    second = volume / 20 * ((y**2).sum(axis=1) + y.sum(axis=1) ** 2)  # exact for a linear tet
    levels = np.unique(np.round(section.points[:, 2], 9))
    middle = 0.5 * levels[-1]
    lo, hi = levels[levels <= middle].max(), levels[levels > middle].min()
    band = (c[..., 2].mean(axis=1) > lo) & (c[..., 2].mean(axis=1) < hi)
    return pressure_kpa * area * feed.ring_mm / (YOUNG_KPA * second[band].sum() / (hi - lo))


@pytest.mark.slow
def test_an_unreinforced_pressurised_feed_bends_its_section_away_from_it_by_less_than_a_beam() -> None:
    """Without a thread the feed's side wall, pushed out, shortens its side of an incompressible section and
    cancels most of its cap's pull (issue 41's (1 - 2 nu) result for chambers): only the ends bend.  About 2 min.
    Measured (with inscribed polygons, before the mesh's were area-matched; not re-measured since): 1.88e-6 against
    P A_f d_f / (E I) = 8.82e-6 1/mm at 1 kPa (21 %), phi 0.2 degrees off straight away
    from the feed."""
    section, layout = _section()
    result = simulate_section(section, LAW, np.zeros(3), NewtonSettings(load_steps=1), None, np.array([1.0, 0, 0]))
    away = layout.feeds_through(0)[0].angle + np.pi
    assert abs(np.angle(np.exp(1j * (result.phi - away)))) < np.deg2rad(1.0)
    assert 0 < result.kappa < 0.5 * _beam_curvature(section, layout, 1.0)


@pytest.mark.slow
def test_a_reinforced_pressurised_feed_bends_its_section_more_than_a_bare_one() -> None:
    """With the hoop thread on the feed's wall (wound as the chambers'), the feed no longer swells, so its side
    wall no longer cancels most of its cap's pull: the section bends away from the feed by most of P A_f d_f / (E I)
    (issue 41's rod model's figure, written out here from the mesh's own cross-section).  Measured (inscribed
    polygons, before the area-matched ones; not re-measured): 6.38e-6 against
    8.82e-6 1/mm at 1 kPa (72 %; bare: 21 %), and the solve reaches its load (no false limit).  The remaining 28 %
    is not explained yet (the feed stops at the chambers' end, not at the section's tip; the thread lies 72 degrees
    from the feed's axis at this pitch): the issue's "about" is not met within 10 %."""
    from tests.mechanics.test_reinforced_section import THREAD

    section, layout = _section()
    result = simulate_section(section, LAW, np.zeros(3), NewtonSettings(load_steps=1), THREAD, np.array([1.0, 0, 0]))
    away = layout.feeds_through(0)[0].angle + np.pi
    assert abs(np.angle(np.exp(1j * (result.phi - away)))) < np.deg2rad(1.0)
    beam = _beam_curvature(section, layout, 1.0)
    assert 0.5 * beam < result.kappa < beam  # bare: 0.21 beam (the test above); above beam: more than a stopped swell
