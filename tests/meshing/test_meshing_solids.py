"""Closed solids with manifold3d: exact polyhedral answers, topology, the volume check, refusals.

Known answers.  An na-gon inscribed in a circle of radius r has area
``na r^2 sin(2 pi / na) / 2`` and perimeter ``2 na r sin(pi / na)``.  The
quads of a straight tube and of a torus section are planar, so their meshes
are exact polyhedra: a prism, and n - 1 wedges, each of which (slicing at
fixed height) holds ``sin(h) / h`` of the solid of revolution over angle h,
i.e. ``sin(h) R A_polygon`` (Pappus with the polygon's centroid at R).
"""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import MeshError
from softdesign.meshing.checks import check_solid, inspect_mesh
from softdesign.meshing.solids import build_solid, manifold_from_mesh
from softdesign.meshing.tessellate import Region, TubeSections
from softdesign.meshing.volume import BodySpec, integrate_body, polygon_area_ratio
from tests.helpers.bodies import Body, circular_arc, helix, straight_line

#: Booleans and sums of ~1e4 faces keep exact polyhedral figures to this relative round-off.
ROUNDOFF_RTOL = 1e-9


def polygon_area(r: float, na: int) -> float:
    return 0.5 * na * r**2 * np.sin(2 * np.pi / na)


def polygon_perimeter(r: float, na: int) -> float:
    return 2 * na * r * np.sin(np.pi / na)


def assert_figures(report, volume: float, area: float) -> None:
    np.testing.assert_allclose(report.volume, volume, rtol=0, atol=ROUNDOFF_RTOL * volume)
    np.testing.assert_allclose(report.area, area, rtol=0, atol=ROUNDOFF_RTOL * area)


def _check(solid, volume_expected=None):
    return check_solid(solid.vertices, solid.faces, solid.expectation(volume_expected))


def test_straight_tube_is_an_exact_prism_and_passes_the_volume_check():
    r, length, na = 3.0, 40.0, 64
    body = Body(straight_line(length), r)
    solid = build_solid(body.sections(41, na))
    report = _check(solid, integrate_body(body.field(na), [0, 1]).volume)
    assert_figures(report, polygon_area(r, na) * length, polygon_perimeter(r, na) * length + 2 * polygon_area(r, na))
    assert (solid.kind, report.euler, report.shells, report.bodies) == ("solid", 2, 1, 1)
    # against the smooth tube the error is exactly the polygon's: sin(2 pi/na)/(2 pi/na) - 1 = -0.16%
    np.testing.assert_allclose(report.volume_rel_error, polygon_area(r, na) / (np.pi * r**2) - 1, rtol=0, atol=1e-12)


def test_offset_straight_tube_is_the_prism_of_the_offset_radius():
    r, d, length, na = 3.0, 0.75, 20.0, 48
    report = _check(build_solid(Body(straight_line(length), r).sections(11, na), BodySpec(offset_mm=d)))
    rd = r + d
    assert_figures(report, polygon_area(rd, na) * length, polygon_perimeter(rd, na) * length + 2 * polygon_area(rd, na))


def _torus_wedges(big: float, r: float, h: float, wedges: int, na: int) -> tuple[float, float]:
    """Volume and lateral area of ``wedges`` polyhedral wedges of angle h around a ring of radius r."""
    a = 2 * np.pi * np.arange(na + 1) / na
    rho, z = big - r * np.cos(a), r * np.sin(a)  # N points to the torus axis
    chord = 2 * np.sin(h / 2) * rho
    height = np.hypot(np.diff(rho) * np.cos(h / 2), np.diff(z))
    lateral = wedges * np.sum(0.5 * (chord[:-1] + chord[1:]) * height)
    return wedges * np.sin(h) * big * polygon_area(r, na), lateral


def test_torus_section_is_exact_wedges_and_passes_the_volume_check():
    big, r, angle, n, na = 20.0, 4.0, 1.3, 53, 64
    body = Body(circular_arc(big, angle), r)
    report = _check(build_solid(body.sections(n, na)), integrate_body(body.field(na), [0, 1]).volume)
    volume, lateral = _torus_wedges(big, r, angle / (n - 1), n - 1, na)
    assert_figures(report, volume, lateral + 2 * polygon_area(r, na))
    # against Pappus the error is the chord's times the polygon's: (sin(h)/h) sin(2pi/na)/(2pi/na) - 1
    h = angle / (n - 1)
    np.testing.assert_allclose(report.volume_rel_error, np.sin(h) / h * polygon_area_ratio(na) - 1, rtol=0, atol=1e-9)
    assert (report.euler, report.bodies) == (2, 1)


def test_hollow_tube_is_prism_minus_chamber_with_euler_four():
    """Sealed chamber: outer and inner shell are two spheres (Euler 4), one body with one void."""
    r, w, length, na = 3.0, 0.5, 40.0, 64
    body = Body(straight_line(length), r)
    solid = build_solid(body.sections(41, na), BodySpec(wall_mm=w))
    report = _check(solid, integrate_body(body.field(na), [0, 1], BodySpec(wall_mm=w)).volume)
    inner = length - 2 * w
    volume = polygon_area(r, na) * length - polygon_area(r - w, na) * inner
    area = polygon_perimeter(r, na) * length + 2 * polygon_area(r, na)
    area += polygon_perimeter(r - w, na) * inner + 2 * polygon_area(r - w, na)
    assert_figures(report, volume, area)
    assert (solid.kind, report.euler, report.shells, report.bodies, report.voids) == ("hollow", 4, 2, 1, 1)
    # JOINT_STEP only in pose bodies
    assert set(np.unique(solid.regions)) == set(Region) - {Region.PORT, Region.JOINT_STEP}


def _axis_crossings(solid, x: float, y: float, z_range: tuple[float, float]) -> int:
    """Faces the line through (x, y) parallel to z crosses with z in ``z_range`` (the mesh is along z)."""
    v = solid.vertices[solid.faces]
    p = np.array([x, y])
    e1, e2, d = v[:, 1, :2] - v[:, 0, :2], v[:, 2, :2] - v[:, 0, :2], p - v[:, 0, :2]
    det = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    safe = np.where(det == 0, 1.0, det)  # faces seen edge-on (the wall) cannot be crossed by the line
    b1 = (d[:, 0] * e2[:, 1] - d[:, 1] * e2[:, 0]) / safe
    b2 = (e1[:, 0] * d[:, 1] - e1[:, 1] * d[:, 0]) / safe
    inside = (det != 0) & (b1 >= 0) & (b2 >= 0) & (b1 + b2 <= 1)
    z = v[:, 0, 2] + b1 * (v[:, 1, 2] - v[:, 0, 2]) + b2 * (v[:, 2, 2] - v[:, 0, 2])
    return int(np.sum(inside & (z > z_range[0]) & (z < z_range[1])))


def test_port_opens_the_chamber_through_the_base_cap():
    """The channel removes an m-gon prism of length w from the base cap: Euler 2 (one genus-0 shell)."""
    r, w, port, length, na, m = 3.0, 0.5, 1.2, 40.0, 64, 24
    spec = BodySpec(wall_mm=w, port_mm=port, port_segments=m)
    body = Body(straight_line(length), r)
    sealed = build_solid(body.sections(41, na), BodySpec(wall_mm=w))
    solid = build_solid(body.sections(41, na), spec)
    report = _check(solid, integrate_body(body.field(na), [0, 1], spec).volume)
    hollow = inspect_mesh(sealed.vertices, sealed.faces)
    rp = port / 2
    volume = hollow.volume - polygon_area(rp, m) * w
    area = hollow.area - 2 * polygon_area(rp, m) + polygon_perimeter(rp, m) * w
    assert_figures(report, volume, area)
    assert (solid.kind, report.euler, report.shells, report.voids) == ("ported", 2, 1, 0)
    assert Region.PORT in solid.regions
    # a line along the port axis from outside into the chamber crosses no face; before the port it crossed the cap
    assert _axis_crossings(solid, 0.1 * rp, 0.05 * rp, (-1.0, w + 0.5)) == 0
    assert _axis_crossings(sealed, 0.1 * rp, 0.05 * rp, (-1.0, w + 0.5)) == 2


def test_hollow_torus_section_with_wall_on_a_ring_is_exact():
    """w equal to the ring spacing: the chamber is n - 3 wedges of the ring of radius r - w."""
    big, r, angle, n, na = 20.0, 4.0, 1.3, 53, 64
    h = angle / (n - 1)
    w = big * h
    body = Body(circular_arc(big, angle), r)
    solid = build_solid(body.sections(n, na), BodySpec(wall_mm=w))
    report = _check(solid, integrate_body(body.field(na), [0, 1], BodySpec(wall_mm=w)).volume)
    outer, outer_lateral = _torus_wedges(big, r, h, n - 1, na)
    chamber, chamber_lateral = _torus_wedges(big, r - w, h, n - 3, na)
    area = outer_lateral + chamber_lateral + 2 * polygon_area(r, na) + 2 * polygon_area(r - w, na)
    assert_figures(report, outer - chamber, area)
    assert report.euler == 4


@pytest.mark.parametrize(
    "spec",
    [
        BodySpec(),
        BodySpec(offset_mm=0.3),
        BodySpec(offset_mm=-0.3),
        BodySpec(wall_mm=0.4),
        BodySpec(wall_mm=0.4, port_mm=0.5),
    ],
)
def test_twisted_eccentric_body_matches_its_integral_at_second_order(spec):
    """Helix with an off-centre section: mesh volume -> integral, error / 4 when both resolutions double."""
    body = Body(helix(6.0, 9.0, 1.5), 1.5, eccentricity=0.5)
    errors = []
    for n, na in ((120, 64), (240, 128)):
        solid = build_solid(body.sections(n, na, exact=False), spec)
        report = _check(solid, integrate_body(body.field(na), np.linspace(0, 1, 7), spec).volume)
        errors.append(report.volume_rel_error)
    # piecewise-linear surfaces converge as h^2: the ratio is 4 up to higher-order terms
    np.testing.assert_allclose(errors[0] / errors[1], 4.0, rtol=0, atol=0.1)


def test_same_input_gives_the_same_mesh():
    sections = Body(helix(6.0, 9.0, 1.0), 1.5, eccentricity=0.3).sections(50, 32)
    spec = BodySpec(wall_mm=0.4, port_mm=0.4)
    a, b = build_solid(sections, spec), build_solid(sections, spec)
    assert a.vertices.tobytes() == b.vertices.tobytes() and a.faces.tobytes() == b.faces.tobytes()


def test_too_thick_wall_is_refused_naming_q_and_l():
    """rho dips to 1 mm at l = 0.75: a 0.9 mm wall leaves 0.1 mm < 0.2 mm there."""
    line = straight_line(20.0)
    s = np.linspace(0, 20.0, 41)
    rho = np.outer(3.0 - 2.0 * np.exp(-(((s / 20.0 - 0.75) / 0.15) ** 2)), np.ones(16))
    sections = TubeSections(0.4, s / 20.0, line.points(s), line.frames(s), rho)
    with pytest.raises(MeshError, match=r"wall_mm: at q=0\.400, l=0\.7500.*radius of 0\.100 mm, expected >= 0\.2 mm"):
        build_solid(sections, BodySpec(wall_mm=0.9))


def test_folding_surface_is_refused_before_meshing():
    with pytest.raises(MeshError, match=r"surface folds at q=0\.500, l=0\.0000.*rho \* kappa = 1\.250"):
        build_solid(Body(circular_arc(8.0, 1.0), 10.0).sections(11, 16), BodySpec(wall_mm=1.0))


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        (BodySpec(wall_mm=0.5, port_mm=5.0), r"port_mm: at q=0\.500, l=0\.0250 a port of diameter 5 mm does not fit"),
        (BodySpec(port_mm=1.0), r"port_mm=1 needs a chamber"),
        (BodySpec(wall_mm=-1.0), r"wall_mm and port_mm >= 0"),
    ],
)
def test_bad_export_settings_are_refused(spec, message):
    with pytest.raises(MeshError, match=message):
        build_solid(Body(straight_line(20.0), 3.0).sections(11, 32), spec)


def test_chamber_too_short_is_refused():
    message = r"wall_mm: at q=0\.500, l=0\.5000 a wall of 0\.95 mm .* chamber 0\.100 mm long"
    with pytest.raises(MeshError, match=message):
        build_solid(Body(straight_line(2.0), 3.0).sections(5, 32), BodySpec(wall_mm=0.95))


def test_manifold3d_status_is_checked():
    """An open mesh makes manifold3d return an empty Manifold with status NotManifold: that must raise."""
    solid = build_solid(Body(straight_line(5.0), 1.0).sections(3, 8))
    with pytest.raises(MeshError, match="status NotManifold"):
        manifold_from_mesh(solid.vertices, solid.faces[:-1], "q=0.000: body")


def _open(solid):
    return solid.vertices, solid.faces[:-1]


def _flipped(solid):
    faces = solid.faces.copy()
    faces[0] = faces[0, ::-1]
    return solid.vertices, faces


def _not_finite(solid):
    vertices = solid.vertices.copy()
    vertices[0, 0] = np.nan
    return vertices, solid.faces


@pytest.mark.parametrize("fault", [_open, _flipped, _not_finite])
def test_a_plain_solid_that_manifold3d_refuses_is_refused_by_check_solid_too(fault):
    """A plain solid skips manifold3d (no boolean needs it): check_solid, run on every exported solid, refuses it."""
    vertices, faces = fault(build_solid(Body(straight_line(5.0), 1.0).sections(3, 8)))
    with pytest.raises(MeshError, match="manifold3d refused"):
        manifold_from_mesh(vertices, faces, "q=0.000: body")
    with pytest.raises(MeshError, match="not a valid solid"):
        check_solid(vertices, faces)
