"""Tessellation of S(q): grid, seams, winding, caps in the end planes, offsets and refusals."""

from __future__ import annotations

import re

import numpy as np
import pytest

from softdesign.errors import MeshError
from softdesign.meshing.checks import inspect_mesh
from softdesign.meshing.tessellate import (
    Region,
    TubeSections,
    curvature_from_frames,
    l_grid_from_spacing,
    ring_points,
    sweep_from_sections,
    tessellate,
    trim_sweep,
)
from softdesign.meshing.volume import angle_grid
from tests.helpers.bodies import Body, circular_arc, helix, straight_line

#: Coordinates built from exact frames agree to round-off at these sizes (mm).
ROUNDOFF_MM = 1e-12


def _l_in_message(message: str) -> float:
    return float(re.search(r"l=([0-9.]+)", message).group(1))


def test_vertex_and_face_counts_without_seam_duplicates():
    n, na = 21, 32
    mesh = tessellate(sweep_from_sections(Body(circular_arc(20.0, 1.0), 3.0).sections(n, na)))
    assert mesh.vertices.shape == (n * na + 2, 3)
    assert mesh.faces.shape == (2 * (n - 1) * na + 2 * na, 3)
    assert np.unique(np.round(mesh.vertices, 9), axis=0).shape[0] == n * na + 2
    assert np.bincount(mesh.regions).tolist() == [2 * (n - 1) * na, na, na]


def test_faces_are_counter_clockwise_seen_from_outside():
    """On a straight tube along z the wall normals point away from the axis, the caps along -z and +z."""
    mesh = tessellate(sweep_from_sections(Body(straight_line(10.0), 2.0).sections(6, 16)))
    v = mesh.vertices[mesh.faces]
    normal = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    radial = v.mean(axis=1) * [1, 1, 0]
    wall = mesh.regions == Region.WALL
    assert np.all(np.einsum("ij,ij->i", normal[wall], radial[wall]) > 0)
    assert np.all(normal[mesh.regions == Region.BASE_CAP, 2] < 0)
    assert np.all(normal[mesh.regions == Region.TIP_CAP, 2] > 0)


@pytest.mark.parametrize("offset", [0.0, 0.4, -0.5])
def test_cap_vertices_lie_in_the_end_frame_planes(offset):
    """Eccentric sections on a helix (rho varies with angle): rings and cap centres stay in the end planes."""
    body = Body(helix(6.0, 9.0, 1.5), 1.5, eccentricity=0.4)
    sections = body.sections(40, 48)
    mesh = tessellate(sweep_from_sections(sections, offset))
    n, na = 40, 48
    for ring, hub, end in ((slice(0, na), n * na, 0), (slice((n - 1) * na, n * na), n * na + 1, -1)):
        points = np.vstack([mesh.vertices[ring], mesh.vertices[hub]])
        height = (points - sections.centers[end]) @ sections.frames[end][:, 2]
        np.testing.assert_allclose(height, 0.0, rtol=0, atol=ROUNDOFF_MM)


def test_l_grid_keeps_joints_exactly_and_spacing_below_target():
    l_samples = np.linspace(0.0, 1.0, 201)
    s_samples = 50.0 * (l_samples + 0.2 * l_samples**2)  # speed varies: rings are placed by arc length
    joints = np.array([0.0, 0.3, 0.7, 1.0])
    grid = l_grid_from_spacing(l_samples, s_samples, joints, 2.0)
    assert np.all(np.diff(grid) > 0)
    assert np.all(np.isin(joints, grid))
    s = np.interp(grid, l_samples, s_samples)
    assert np.max(np.diff(s)) <= 2.0 + 1e-9
    s_joints = np.interp(joints, l_samples, s_samples)
    assert grid.size == 1 + int(np.sum(np.ceil(np.diff(s_joints) / 2.0)))


def test_a_body_over_several_links_is_one_closed_surface():
    """Rings on an l grid with joints, each joint once: watertight, no crack at the joints."""
    body = Body(circular_arc(25.0, 1.5), 2.5)
    joints = [0.0, 0.25, 0.6, 1.0]
    grid = l_grid_from_spacing(np.linspace(0, 1, 50), np.linspace(0, body.line.length, 50), joints, 1.0)
    s = grid * body.line.length
    sections = TubeSections(0.2, grid, body.line.points(s), body.line.frames(s), body.rho(s, 40))
    report = inspect_mesh(*(lambda m: (m.vertices, m.faces))(tessellate(sweep_from_sections(sections))))
    assert (report.watertight, report.winding_consistent, report.shells, report.euler) == (True, True, 1, 2)


def test_finite_differences_recover_the_curvature():
    """Second-order differences of T on a circle: leading error h^2 kappa^3 / 6 inside, h^2 kappa^3 / 3 at the ends."""
    kappa, h = 0.1, 0.5
    line = circular_arc(1 / kappa, 1.0)
    s = np.arange(0.0, line.length + 1e-12, h)
    got = curvature_from_frames(line.frames(s), s)
    np.testing.assert_allclose(got[1:-1], line.curvature(s)[1:-1], rtol=0, atol=h**2 * kappa**3 / 6)
    np.testing.assert_allclose(got, line.curvature(s), rtol=0, atol=h**2 * kappa**3 / 3)


def test_offset_straight_tube_rings_have_the_offset_radius():
    sweep = sweep_from_sections(Body(straight_line(10.0), 2.0).sections(5, 24), -0.5)
    np.testing.assert_allclose(np.linalg.norm(sweep.xy, axis=-1), 1.5, rtol=0, atol=ROUNDOFF_MM)


def test_trim_places_end_rings_at_the_arc_lengths_and_drops_slivers():
    body = Body(circular_arc(20.0, 1.0), 2.0)
    sweep = sweep_from_sections(body.sections(21, 16))
    spacing = body.line.length / 20
    ends = [0.1 * spacing, body.line.length - 2.5 * spacing]
    trimmed = trim_sweep(sweep, *ends)
    np.testing.assert_allclose(trimmed.s[[0, -1]], ends, rtol=0, atol=1e-12)
    assert np.diff(trimmed.s).min() > 0.25 * spacing
    # the linear interpolation of the frames is re-orthonormalized
    f = trimmed.frames[[0, -1]]
    np.testing.assert_allclose(np.einsum("nji,njk->nik", f, f), np.broadcast_to(np.eye(3), f.shape), rtol=0, atol=1e-12)
    # an end ring sits on the chord between its neighbours but for renormalizing the interpolated N and B:
    # |(1 - t) N0 + t N1| = sqrt(1 - 2 t (1 - t) (1 - cos(h kappa))), which moves a point at radius r inward by
    t, turn = 0.1, spacing / 20.0
    shift = 2.0 * (1 - np.sqrt(1 - 2 * t * (1 - t) * (1 - np.cos(turn))))
    expected = (1 - t) * ring_points(sweep)[0] + t * ring_points(sweep)[1]
    np.testing.assert_allclose(ring_points(trimmed)[0], expected, rtol=0, atol=shift + 1e-12)


def test_folding_surface_is_refused_naming_q_and_l():
    """rho bulges to 1.2 R around l = 0.5 on an arc of radius R: rho * kappa > 1 there."""
    big, n = 10.0, 41
    line = circular_arc(big, 1.0)
    s = np.linspace(0, line.length, n)
    l = s / line.length
    rho = np.outer(3.0 + 9.0 * np.exp(-(((l - 0.5) / 0.05) ** 2)), np.ones(16))
    sections = TubeSections(0.75, l, line.points(s), line.frames(s), rho, s=s, curvature=line.curvature(s))
    with pytest.raises(MeshError, match=r"folds at q=0\.750, l=0\.5000.*rho \* kappa = 1\.200") as err:
        sweep_from_sections(sections)
    assert "a=0 deg" in str(err.value)


def test_outward_offset_that_folds_is_refused():
    with pytest.raises(MeshError, match=r"offset_mm=3 mm: offset surface folds at q=0\.500, l=0\.0000"):
        sweep_from_sections(Body(circular_arc(10.0, 1.0), 8.0).sections(11, 16), 3.0)


def test_inward_offset_beyond_the_local_radius_is_refused():
    """rho dips to 1 mm at l = 0.25; shrinking by 1 mm there leaves nothing."""
    line = straight_line(20.0)
    s = np.linspace(0, 20.0, 41)
    rho = np.outer(3.0 - 2.0 * np.exp(-(((s / 20.0 - 0.25) / 0.15) ** 2)), np.ones(16))
    sections = TubeSections(0.0, s / 20.0, line.points(s), line.frames(s), rho)
    with pytest.raises(MeshError, match=r"offset_mm: at q=0\.000, l=0\.2500") as err:
        sweep_from_sections(sections, -1.0)
    assert "local radius is 1.000 mm" in str(err.value)


def test_rings_that_cross_are_refused_even_when_the_curvature_given_is_wrong():
    """Frames turning 90 degrees between two rings 1 mm apart fold a 3 mm tube; curvature claimed 0."""
    frames = np.stack([np.eye(3), np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])])
    centers = np.array([[0.0, 0, 0], [0, 0, 1.0]])
    rho = np.full((2, 16), 3.0)
    sections = TubeSections(1.0, np.array([0.0, 1.0]), centers, frames, rho, curvature=np.zeros((2, 2)))
    with pytest.raises(MeshError, match=r"rings cross between q=1\.000, l=0\.0000 and l=1\.0000"):
        sweep_from_sections(sections)


def test_inputs_are_not_mutated():
    sections = Body(circular_arc(20.0, 1.0), 2.0, eccentricity=0.3).sections(11, 16)
    for array in (sections.l, sections.centers, sections.frames, sections.rho, sections.s, sections.curvature):
        array.setflags(write=False)
    sweep = sweep_from_sections(sections, -0.2)
    tessellate(trim_sweep(sweep, 1.0, 10.0))


def test_angle_grid_starts_at_n():
    """Angle 0 is along N: the first vertex of each ring is c + rho N."""
    sections = Body(straight_line(5.0), 2.0).sections(3, 8)
    first = ring_points(sweep_from_sections(sections))[:, 0]
    np.testing.assert_allclose(first, sections.centers + [2.0, 0, 0], rtol=0, atol=0)
    np.testing.assert_allclose(angle_grid(4), [0, np.pi / 2, np.pi, 3 * np.pi / 2], rtol=0, atol=0)


@pytest.mark.parametrize("offset", [0.0, 0.5])
def test_largest_rho_kappa_of_a_torus_section(offset):
    """The ring at a = 0 (along N, towards the axis) reaches (r + d) / R."""
    sweep = sweep_from_sections(Body(circular_arc(20.0, 1.0), 4.0).sections(11, 16), offset)
    np.testing.assert_allclose(sweep.max_rho_kappa, (4.0 + offset) / 20.0, rtol=0, atol=ROUNDOFF_MM)


def test_frames_that_are_not_orthonormal_are_a_caller_bug():
    sections = Body(straight_line(5.0), 1.0).sections(3, 8)
    bent = TubeSections(sections.q, sections.l, sections.centers, 1.01 * sections.frames, sections.rho)
    with pytest.raises(ValueError, match="orthonormal"):
        sweep_from_sections(bent)
