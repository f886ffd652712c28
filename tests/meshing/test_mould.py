"""Casting moulds (issue 16): known answers on a straight tube, an undercut refused, a curved chamber's lost core."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.meshing.mould.frame import parting_frame
from softdesign.meshing.mould.make import make_mould
from softdesign.meshing.mould.parts import MouldRefused, MouldSpec, build_mould
from softdesign.meshing.solids import manifold_from_mesh
from softdesign.meshing.tessellate import TubeSections, sweep_from_sections, tessellate
from softdesign.meshing.volume import BodySpec, angle_grid
from tests.helpers.bodies import Body, circular_arc, straight_line

RADIUS, LENGTH, NA = 4.0, 40.0, 64
SPEC = MouldSpec()
#: Volumes of booleans of the same meshes agree to rounding, relative (manifold3d works in double precision).
BOOLEAN_RTOL = 1e-9


def one_link(l):
    return np.zeros(np.size(l), int)


def tube(q: float = 0.0) -> TubeSections:
    return Body(straight_line(LENGTH), RADIUS).sections(81, NA, q=q)


def test_straight_tube_halves_are_the_box_halves_minus_half_cylinders_plus_keys_and_channels():
    """Known answer: each half is half the box less half the body and half the channels' outside part,
    A plus the four bumps' protruding halves, B less the four sockets (clearance wider and deeper)."""
    sections = tube()
    mesh = tessellate(sweep_from_sections(sections))
    body, _ = manifold_from_mesh(mesh.vertices, mesh.faces, "tube")
    parts = build_mould(body, body, None, parting_frame(sections.centers, sections.frames[0]), SPEC)
    r, c = SPEC.key_mm / 2, SPEC.clearance_mm
    # the keys are 48-gons: area (n / 2) r^2 sin(2 pi / n)
    gon = 0.5 * SPEC.segments * np.sin(2 * np.pi / SPEC.segments)
    bump_out, socket_in = 4 * gon * r**2 * r, 4 * gon * (r + c) ** 2 * (r + c)
    # parts are in the mould frame (z the plane's normal): the body there is parts.body
    half_box, half_body = parts.box.volume() / 2, parts.body.volume() / 2
    half_channels = ((parts.channels ^ parts.box) - parts.body).volume() / 2
    np.testing.assert_allclose(parts.half_a.volume(), half_box - half_body - half_channels + bump_out,
                               rtol=BOOLEAN_RTOL)
    np.testing.assert_allclose(parts.half_b.volume(), half_box - half_body - half_channels - socket_in,
                               rtol=BOOLEAN_RTOL)
    # the body mesh is the analytic cylinder's inscribed 64-gon prism: pi R^2 L sin(h)/h
    h = 2 * np.pi / NA
    np.testing.assert_allclose(body.volume(), np.pi * RADIUS**2 * LENGTH * np.sin(h) / h, rtol=BOOLEAN_RTOL)


def test_straight_tube_mould_passes_every_check():
    mould = make_mould(tube(), BodySpec(), SPEC, one_link)
    f = mould.figures
    assert [p.name for p in mould.parts] == ["half_a", "half_b"]
    assert all(p["ok"] and p["bodies"] == 1 and p["genus"] == 0 for p in f["parts"].values())
    assert f["disjoint"]["ok"] and f["disjoint"]["shared_mm3"]["half_a/half_b"] == 0.0
    assert f["cavity"]["rel_difference"] <= f["cavity"]["tolerance"]
    for pull in f["pull"].values():
        assert pull["against_pull"] == 0 and pull["blocked_rays"] == 0 and pull["faces_checked"] > 0
    # the plane holds the axis (z) and N0 (x): the pulls are +-B0 = +-y
    np.testing.assert_allclose(f["pull"]["half_a"]["pull"], [0.0, 1.0, 0.0], atol=1e-12)
    assert f["frame"]["straight"] and f["core"] is None


def test_keys_keep_the_clearance_asked_for():
    """Bump and socket are concentric 48-gons: their walls are c cos(pi / 48) apart, their ends c."""
    sections = tube()
    mesh = tessellate(sweep_from_sections(sections))
    body, _ = manifold_from_mesh(mesh.vertices, mesh.faces, "tube")
    for c in (0.1, 0.5):
        spec = MouldSpec(clearance_mm=c)
        parts = build_mould(body, body, None, parting_frame(sections.centers, sections.frames[0]), spec)
        assert (parts.bumps - parts.half_a).volume() == 0.0  # the bumps are half A's
        gap = parts.bumps.min_gap(parts.half_b, 10.0)
        np.testing.assert_allclose(gap, c * np.cos(np.pi / spec.segments), rtol=1e-9)


def bulged_tube(amplitude: float) -> TubeSections:
    """A straight tube whose middle third grows a lobe at a = 45 deg: its flank toward the parting line
    (a = 0) faces down, against half A's pull (+B)."""
    s = np.linspace(0.0, LENGTH, 81)
    a = angle_grid(NA)
    along = np.exp(-(((s - LENGTH / 2) / (LENGTH / 8)) ** 2))
    lobe = np.exp(-(((a - np.pi / 4) / 0.25) ** 2))
    rho = RADIUS * (1.0 + amplitude * along[:, None] * lobe[None, :])
    line = straight_line(LENGTH)
    return TubeSections(0.0, s / LENGTH, line.points(s), line.frames(s), rho)


def test_an_undercut_body_is_refused_naming_link_l_and_angle():
    with pytest.raises(MouldRefused) as err:
        make_mould(bulged_tube(0.8), BodySpec(), SPEC, one_link)
    text = str(err.value)
    assert "half A cannot be pulled off" in text and "link 0, l=0." in text and " deg" in text
    angle = float(text.split("angle ")[1].split(" deg")[0])
    assert 0.0 < angle < 45.0  # the lobe's flank toward the parting line


def test_a_gentle_bulge_is_no_undercut():
    """The same lobe small enough that every section stays a graph over the parting line."""
    assert make_mould(bulged_tube(0.05), BodySpec(), SPEC, one_link).figures["pull"]["half_a"]["ok"]


def test_hollow_straight_body_gets_a_removable_core_seated_in_both_halves():
    spec = BodySpec(wall_mm=1.0, port_mm=1.5)
    mould = make_mould(tube(), spec, SPEC, one_link)
    f = mould.figures
    assert [p.name for p in mould.parts] == ["half_a", "half_b", "core"]
    assert f["core"]["process"] == "removable"
    assert f["disjoint"]["ok"] and f["cavity"]["ok"]
    np.testing.assert_allclose(f["core"]["chamber_widest_mm"], 2 * (RADIUS - 1.0), rtol=1e-12)
    core = next(p for p in mould.parts if p.name == "core")
    frame = parting_frame(tube().centers, tube().frames[0])
    height = frame.to_frame(core.vertices)[:, 2]
    # the core print lies across the parting plane: half of it in each half's groove
    np.testing.assert_allclose([height.max(), -height.min()], RADIUS - 1.0, rtol=1e-9)
    print_end = frame.to_frame(core.vertices)[:, 0].min()
    box_end = frame.to_frame(mould.parts[0].vertices)[:, 0].min()
    np.testing.assert_allclose(box_end - print_end, SPEC.print_mm, rtol=1e-9)


def test_curved_chamber_is_written_for_a_lost_core():
    body = Body(circular_arc(60.0, LENGTH / 60.0), RADIUS)
    mould = make_mould(body.sections(81, NA, q=0.0), BodySpec(wall_mm=1.0, port_mm=1.5), SPEC, one_link)
    f = mould.figures
    assert f["core"]["process"] == "lost-core" and "dissolvable or wax" in f["core"]["note"]
    assert not f["frame"]["straight"] and f["frame"]["out_of_plane_mm"] < 1e-9
    assert f["pull"]["half_a"]["ok"] and f["pull"]["half_b"]["ok"] and f["cavity"]["ok"]


def test_a_sealed_chamber_and_a_key_without_room_are_refused():
    with pytest.raises(MouldRefused, match="export.port_mm"):
        make_mould(tube(), BodySpec(wall_mm=1.0), SPEC, one_link)
    with pytest.raises(MouldRefused, match="margin_mm >= 8.4"):
        make_mould(tube(), BodySpec(), MouldSpec(margin_mm=6.0, key_mm=6.0), one_link)
