"""Wall thickness of hollow bodies: a straight tube's wall is wall_mm, an off-centre chamber's thin side, the port."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.fitting import radius_rows
from softdesign.fitting.radius_field import RadiusField
from softdesign.fitting.strain import metric_from_sections, principal_stretches, skin_metric
from softdesign.geometry.blend import blend_shapes
from softdesign.geometry.curves import CurveOptions, smooth_curve_from_polyline
from softdesign.geometry.initial import straight_initial_shape
from softdesign.meshing.body.sections import body_sections
from softdesign.meshing.body.wall import (
    offset_metric,
    offset_sections,
    port_wall_mm,
    tessellation_error_mm,
    thinnest,
    wall_distances,
)
from softdesign.meshing.solids import _chamber
from softdesign.meshing.tessellate import Sweep, ring_points, sweep_from_sections, tessellate
from softdesign.meshing.volume import BodySpec, angle_grid
from tests.fitting.test_fit_strain import _constant_field

RADIUS_MM, WALL_MM, LENGTH_MM, NA = 3.0, 1.0, 30.0, 64


@pytest.fixture(scope="module")
def straight():
    z = np.linspace(0.0, LENGTH_MM, 301)
    line = np.column_stack([0 * z, 0 * z, z])
    final = smooth_curve_from_polyline(line, CurveOptions(spacing_mm=0.25, smoothing_mm=0))
    shape = blend_shapes(straight_initial_shape(final), final)
    return shape, _constant_field(RADIUS_MM, RADIUS_MM)


def test_a_hollow_straight_tube_has_wall_mm_everywhere(straight):
    shape, field = straight
    sections = body_sections(shape.curve_at(1.0), field, 1.0, 0.5, NA)
    outer = sweep_from_sections(sections)
    chamber = _chamber(sections, outer, BodySpec(wall_mm=WALL_MM))
    body = tessellate(outer)
    d = wall_distances(ring_points(chamber), body.vertices, body.faces)
    # the outer mesh is inscribed in the true surface: distances err low by at most a chord's sagitta
    bound = tessellation_error_mm(RADIUS_MM, NA)
    assert np.all(d <= WALL_MM + 1e-9)
    assert np.all(d >= WALL_MM - bound)
    # the ends: the chamber stops wall_mm short of each flat cap
    np.testing.assert_allclose(d[[0, -1]], WALL_MM, atol=bound)


def test_an_off_centre_chamber_reports_its_thin_side_at_the_right_angle():
    n = 41
    l = np.linspace(0.0, 1.0, n)
    s = l * LENGTH_MM
    centers = np.column_stack([0 * s, 0 * s, s])
    frames = np.repeat(np.eye(3)[None], n, axis=0)
    a = angle_grid(NA)
    outer_xy = RADIUS_MM * np.stack([np.cos(a), np.sin(a)], -1)
    shift, phi, inner = 0.8, np.radians(123.75), 1.5  # phi is one of the grid's angles (k = 22)
    inner_xy = shift * np.array([np.cos(phi), np.sin(phi)]) + inner * np.stack([np.cos(a), np.sin(a)], -1)
    outer = Sweep(1.0, l, s, centers, frames, np.repeat(outer_xy[None], n, axis=0))
    cavity = Sweep(1.0, l[5:-5], s[5:-5], centers[5:-5], frames[5:-5], np.repeat(inner_xy[None], n - 10, axis=0))
    body = tessellate(outer)
    spot = thinnest(wall_distances(ring_points(cavity), body.vertices, body.faces), cavity.l, a)
    expected = RADIUS_MM - inner - shift
    # on the polygonal outer mesh a neighbouring vertex can see a chord a sagitta closer: one angular step
    assert spot.a == pytest.approx(phi, abs=2 * np.pi / NA + 1e-12)
    assert expected - tessellation_error_mm(RADIUS_MM, NA) <= spot.thickness_mm <= expected + 1e-9


def test_the_port_wall_of_a_centred_port_is_radius_minus_half_the_port(straight):
    shape, field = straight
    sections = body_sections(shape.curve_at(1.0), field, 1.0, 0.5, NA)
    outer = sweep_from_sections(sections)
    port = port_wall_mm(ring_points(outer), outer.centers[0], outer.frames[0][:, 2], 1.5, WALL_MM)
    assert port.thickness_mm == pytest.approx(RADIUS_MM - 0.75, abs=1e-9)


def test_the_chamber_of_a_bent_tube_stretches_as_its_own_radius_times_kappa():
    """The chamber is the inward offset (radius r - w): its axial stretch is 1 - (r - w) kappa cos(theta)."""
    from tests.fitting.test_fit_strain import BEND_RADIUS_MM, _arc

    final = smooth_curve_from_polyline(_arc(60.0, BEND_RADIUS_MM), CurveOptions(spacing_mm=0.25, smoothing_mm=0.0))
    shape = blend_shapes(straight_initial_shape(final), final, mode="intrinsic")
    field = _constant_field(RADIUS_MM, RADIUS_MM)
    l = np.linspace(0.1, 0.9, 17)
    rest = metric_from_sections(offset_sections(shape.curve_at(0.0), field, 0.0, l, NA, -WALL_MM))
    bent = metric_from_sections(offset_sections(shape.curve_at(1.0), field, 1.0, l, NA, -WALL_MM))
    lam1, lam2 = principal_stretches(rest, bent)
    rk = (RADIUS_MM - WALL_MM) / BEND_RADIUS_MM
    # the grid holds the exact extremes' angles only to within half a step
    grid = rk * (1 - np.cos(np.pi / NA))
    assert abs(lam1.max() - (1 + rk)) <= grid + 1e-6
    assert abs(lam2.min() - (1 - rk)) <= grid + 1e-6
    # and the outer skin's exact form agrees with the offset route at offset 0 up to its finite difference
    skin = principal_stretches(skin_metric(shape.curve_at(0.0), field, 0.0, l, angle_grid(NA)),
                               skin_metric(shape.curve_at(1.0), field, 1.0, l, angle_grid(NA)))
    assert abs(skin[0].max() - (1 + RADIUS_MM / BEND_RADIUS_MM)) <= grid * 1.5 + 1e-6


@pytest.mark.parametrize("frames", ["rmf", "frenet"])
def test_the_offset_metric_in_blocks_of_rows_has_the_bits_of_the_sections_route(monkeypatch, frames):
    """offset_metric is metric_from_sections(offset_sections(...)) bit for bit, in any block of rows, any offset."""
    from tests.fitting.test_fit_radius_field import _random_links
    from tests.fitting.test_fit_strain import BEND_RADIUS_MM, _arc

    final = smooth_curve_from_polyline(_arc(60.0, BEND_RADIUS_MM), CurveOptions(spacing_mm=0.25, smoothing_mm=0.0))
    shape = blend_shapes(straight_initial_shape(final), final, mode="intrinsic", frames=frames)
    field = RadiusField.from_links((0.0, 0.4, 1.0), _random_links())  # rho varies along and around: every term counts
    l = np.unique(np.append(np.linspace(0.02, 0.98, 29), 0.4))
    for q in (0.6, 1.0):  # bent: Frenet frames need curvature
        curve = shape.curve_at(q)
        for offset in (-0.8, 0.0, 0.5):
            whole = metric_from_sections(offset_sections(curve, field, q, l, 24, offset, frames))
            for points in (radius_rows.BLOCK_POINTS, 24 * 5, 1):
                monkeypatch.setattr(radius_rows, "BLOCK_POINTS", points)
                assert offset_metric(curve, field, q, l, 24, offset, frames).tobytes() == whole.tobytes()
