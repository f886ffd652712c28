"""Bodies whose ends are cut at tilted planes carried in the end frames (softdesign/meshing/end_cut.py).

Known answers.  A straight tube's mesh is an na-gon prism; its generators are straight, so re-spacing the
end rings along them keeps every vertex on the prism and the cut solid is exactly the prism between the two
planes.  A plane through the axis at the end tilted theta cuts a centrally symmetric polygon (na even) into
equal wedges on either side: the volume stays ``A L`` and the cap, the polygon's oblique section, has area
``A / cos(theta)``.  A chamber's cap is the outer cap's plane moved ``wall_mm`` inward, so the two planes
are ``wall_mm`` apart.
"""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import MeshError
from softdesign.meshing.checks import check_solid
from softdesign.meshing.end_cut import CutPlane, crease_targets, cut_ends, cut_planes, cut_targets, end_cuts_from_record
from softdesign.meshing.solids import build_solid
from softdesign.meshing.tessellate import Region, TubeSections, sweep_from_sections, tessellate
from softdesign.meshing.volume import BodySpec, integrate_body
from tests.helpers.bodies import Body, circular_arc, straight_line
from tests.meshing.test_meshing_solids import ROUNDOFF_RTOL, polygon_area

#: Cap vertices moved into a plane sit on it to float64 round-off of coordinates of tens of mm.
PLANE_TOL_MM = 1e-9
#: The export's volume check: mesh against integral (plus the cuts' wedges) within 0.5 %.
VOLUME_RTOL = 5e-3


def tilted(theta_deg: float, toward: float, outward_t: float, offset_mm: float = 0.0) -> tuple[float, ...]:
    """A cut: the outward unit normal in the end frame, leaning ``theta_deg`` from +-T towards angle ``toward``
    in (N, B), crossing the axis ``offset_mm`` past the end."""
    t = np.radians(theta_deg)
    return (float(np.sin(t) * np.cos(toward)), float(np.sin(t) * np.sin(toward)), float(outward_t * np.cos(t)),
            offset_mm)


def cap_vertices(solid, region: Region) -> np.ndarray:
    return solid.vertices[np.unique(solid.faces[solid.regions == region])]


def cap_area(solid, region: Region) -> float:
    tri = solid.vertices[solid.faces[solid.regions == region]]
    return float(0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1).sum())


@pytest.mark.parametrize("theta_deg", [3.0, 14.0, 30.0])
def test_a_straight_tube_cut_at_tilted_planes_through_its_ends_is_the_exact_cut_prism(theta_deg):
    r, length, na = 3.0, 40.0, 64
    base, tip = tilted(theta_deg, 0.3, -1.0), tilted(theta_deg, 2.0, 1.0)
    solid = build_solid(Body(straight_line(length), r).sections(81, na), BodySpec(end_cuts=(base, tip)))
    report = check_solid(solid.vertices, solid.faces, solid.expectation(polygon_area(r, na) * length))
    assert (report.watertight, report.winding_consistent, report.euler, report.bodies) == (True, True, 2, 1)
    np.testing.assert_allclose(report.volume, polygon_area(r, na) * length, rtol=0,
                               atol=ROUNDOFF_RTOL * report.volume)
    for region, normal, point in ((Region.BASE_CAP, base, [0, 0, 0]), (Region.TIP_CAP, tip, [0, 0, length])):
        assert np.abs((cap_vertices(solid, region) - point) @ np.array(normal[:3])).max() < PLANE_TOL_MM
        np.testing.assert_allclose(cap_area(solid, region), polygon_area(r, na) / np.cos(np.radians(theta_deg)),
                                   rtol=ROUNDOFF_RTOL)


def test_without_cuts_the_mesh_is_the_square_tessellation_bit_for_bit():
    sections = Body(circular_arc(30.0, 1.0), 2.5).sections(41, 48)
    sweep = sweep_from_sections(sections)
    mesh = tessellate(sweep)
    same, added = cut_ends(mesh, sweep, cut_planes(sweep, (None, None)), "q")
    assert same is mesh and added == 0.0
    plain = build_solid(sections, BodySpec())
    assert np.array_equal(plain.vertices, mesh.vertices) and np.array_equal(plain.faces, mesh.faces)
    assert end_cuts_from_record(None) == (None, None) and end_cuts_from_record({}) == (None, None)


@pytest.mark.parametrize("offsets", [(1.5, -0.8), (-0.6, 2.0)])
def test_a_plane_crossing_the_axis_past_or_short_of_the_end_lengthens_or_shortens_the_prism(offsets):
    # tilted planes crossing the axis offset mm outward from each end: the prism between them is A (L + sum)
    r, length, na, theta = 3.0, 40.0, 64, 10.0
    base, tip = tilted(theta, 1.0, -1.0, offsets[0]), tilted(theta, -0.5, 1.0, offsets[1])
    solid = build_solid(Body(straight_line(length), r).sections(81, na), BodySpec(end_cuts=(base, tip)))
    expected = polygon_area(r, na) * (length + sum(offsets))
    report = check_solid(solid.vertices, solid.faces, solid.expectation(polygon_area(r, na) * length))
    np.testing.assert_allclose(report.volume, expected, rtol=0, atol=ROUNDOFF_RTOL * expected)
    for region, cut, point in ((Region.BASE_CAP, base, [0, 0, -offsets[0]]),
                               (Region.TIP_CAP, tip, [0, 0, length + offsets[1]])):
        assert np.abs((cap_vertices(solid, region) - point) @ np.array(cut[:3])).max() < PLANE_TOL_MM


def test_the_cut_plane_moves_rigidly_with_the_end_frame():
    # the same body in another pose (rotation and translation of every ring): the cut body is the same
    # body in that pose, so the plane is defined in the end frame, not in the world
    sections = Body(circular_arc(30.0, 1.0), 2.5).sections(61, 48)
    rotation = np.linalg.qr(np.array([[0.3, -1.0, 0.2], [0.9, 0.1, -0.4], [0.2, 0.5, 1.0]]))[0]
    rotation *= np.sign(np.linalg.det(rotation))
    shift = np.array([5.0, -2.0, 11.0])
    moved = TubeSections(sections.q, sections.l, sections.centers @ rotation.T + shift,
                         np.einsum("ij,njk->nik", rotation, sections.frames), sections.rho, sections.s,
                         sections.rho_s, sections.curvature)
    spec = BodySpec(end_cuts=(tilted(12.0, 1.0, -1.0), tilted(8.0, -2.0, 1.0)))
    here, there = build_solid(sections, spec), build_solid(moved, spec)
    np.testing.assert_allclose(there.vertices, here.vertices @ rotation.T + shift, rtol=0, atol=1e-9)


def test_a_curved_tapered_body_cut_at_both_ends_passes_the_volume_check():
    na = 64
    body = Body(circular_arc(25.0, 1.2), 2.0, slope=0.01)
    solid = build_solid(body.sections(121, na), BodySpec(end_cuts=(tilted(20.0, 0.5, -1.0), tilted(20.0, 4.0, 1.0))))
    integral = integrate_body(body.field(na), [0, 1]).volume
    report = check_solid(solid.vertices, solid.faces, solid.expectation(integral))
    assert report.watertight and report.euler == 2 and abs(report.volume_rel_error) < VOLUME_RTOL


@pytest.mark.parametrize("port_mm", [0.0, 1.5])
def test_a_hollow_body_keeps_its_wall_at_tilted_ends(port_mm):
    r, length, na, wall = 3.0, 30.0, 64, 1.0
    base, tip = tilted(14.0, 0.0, -1.0), tilted(14.0, 1.5, 1.0)
    solid = build_solid(Body(straight_line(length), r).sections(61, na),
                        BodySpec(wall_mm=wall, port_mm=port_mm, end_cuts=(base, tip)))
    report = check_solid(solid.vertices, solid.faces, solid.expectation(None))
    assert report.watertight and report.bodies == 1 and report.euler == (2 if port_mm else 4)
    chamber_caps = cap_vertices(solid, Region.CHAMBER_CAP)
    # each chamber cap lies in its outer cap's plane moved wall_mm inward (the nearer of the two planes)
    per_vertex = np.maximum(chamber_caps @ np.array(base[:3]), (chamber_caps - [0, 0, length]) @ np.array(tip[:3]))
    np.testing.assert_allclose(per_vertex, -wall, rtol=0, atol=PLANE_TOL_MM)
    assert report.volume > 0
    # the side wall is the prism's: the chamber is the (r - wall) prism, nothing nearer the outside
    chamber = solid.vertices[np.unique(solid.faces[solid.regions == Region.CHAMBER])]
    assert np.hypot(chamber[:, 0], chamber[:, 1]).max() <= r - wall + 1e-9


def test_a_plane_the_body_cannot_reach_is_refused_naming_the_end():
    sections = Body(straight_line(8.0), 3.0).sections(17, 48)
    with pytest.raises(MeshError, match="tip end's cut plane .* too far for a body 8.000 mm long"):
        build_solid(sections, BodySpec(end_cuts=(None, tilted(30.0, 0.0, 1.0))))


def test_the_volume_meshs_layer_before_the_end_lies_on_the_end_ring_where_the_plane_passes_it():
    """crease_targets on a straight tube's generators (rings every 0.25 mm, a plane through the end's centre
    tilted 8 deg): the last ring in the plane as cut_targets puts it; the ring before it exactly on the end
    ring (the crease) where the plane lies at least ``thickness`` past it, ``thickness`` short of the plane
    elsewhere; every generator still increasing; the rings far from the end where they were."""
    r, m, thickness = 3.0, 32, 0.1
    s = np.arange(0.0, 20.0 + 1e-9, 0.25)
    angles = 2.0 * np.pi * np.arange(m) / m
    ring = np.column_stack([r * np.cos(angles), r * np.sin(angles), np.zeros(m)])
    points = ring[None, :, :] + s[:, None, None] * np.array([0.0, 0.0, 1.0])
    normal = np.array(tilted(8.0, 0.7, 1.0)[:3])
    plane = CutPlane(np.array([0.0, 0.0, s[-1]]), normal / np.linalg.norm(normal))
    outward = np.array([0.0, 0.0, 1.0])
    plain = cut_targets(points, s, outward, plane, "tip")
    got = crease_targets(points, s, outward, plane, "tip", thickness)
    np.testing.assert_array_equal(got[-1], plain[-1])
    past = plain[-1] - s[-1]  # how far the plane lies past the end ring along each generator
    assert (past >= thickness).any() and (past < thickness).any()
    np.testing.assert_array_equal(got[-2][past >= thickness], s[-1])
    np.testing.assert_allclose(got[-2][past < thickness], plain[-1][past < thickness] - thickness, rtol=0, atol=1e-12)
    assert np.all(np.diff(got, axis=0) > 0) and np.all(got[-1] - got[-2] >= thickness - 1e-12)
    far = s < s[-1] - 2.0
    np.testing.assert_array_equal(got[far], np.repeat(s[far, None], m, axis=1))
