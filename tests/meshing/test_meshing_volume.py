"""Volume and area integrated from the parametric surface: known answers first."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.meshing.volume import (
    BodySpec,
    angle_grid,
    angular_derivative,
    gauss_legendre_nodes,
    integrate_body,
    l_at_arclength,
    polygon_area_ratio,
    section_curves,
    section_moments,
    sweep_volume,
    tube_lateral_area,
    tube_volume,
)
from tests.helpers.bodies import Body, circular_arc, helix, straight_line

#: Quadrature of smooth (here trigonometric/polynomial) integrands is exact up to round-off, relative.
QUAD_RTOL = 1e-11
NA = 64


def _integrals(body: Body, na: int = NA, order: int = 8):
    return integrate_body(body.field(na), [0.0, 0.5, 1.0], BodySpec(), order)


def test_straight_tube_volume_and_area():
    r, length = 3.0, 40.0
    got = _integrals(Body(straight_line(length), r))
    np.testing.assert_allclose(got.volume, np.pi * r**2 * length, rtol=0, atol=QUAD_RTOL * got.volume)
    area = 2 * np.pi * r * length + 2 * np.pi * r**2
    np.testing.assert_allclose(got.area, area, rtol=0, atol=QUAD_RTOL * area)
    np.testing.assert_allclose(got.length, length, rtol=0, atol=QUAD_RTOL * length)


def test_cone_frustum_volume_and_area_use_rho_s():
    r0, slope, length = 2.0, 0.05, 30.0
    r1 = r0 + slope * length
    got = _integrals(Body(straight_line(length), r0, slope))
    volume = np.pi * length * (r0**2 + r0 * r1 + r1**2) / 3
    area = np.pi * (r0 + r1) * np.hypot(length, r1 - r0) + np.pi * (r0**2 + r1**2)
    np.testing.assert_allclose(got.volume, volume, rtol=0, atol=QUAD_RTOL * volume)
    np.testing.assert_allclose(got.area, area, rtol=0, atol=QUAD_RTOL * area)


def test_torus_section_is_pappus():
    big, r, angle = 20.0, 4.0, 1.3
    got = _integrals(Body(circular_arc(big, angle), r))
    volume, area = np.pi * r**2 * big * angle, 2 * np.pi * r * big * angle + 2 * np.pi * r**2
    np.testing.assert_allclose(got.volume, volume, rtol=0, atol=QUAD_RTOL * volume)
    np.testing.assert_allclose(got.area, area, rtol=0, atol=QUAD_RTOL * area)


def test_eccentric_torus_section_weighs_the_rho_cubed_term():
    """A circle whose centre sits e towards the centre of curvature sweeps pi r^2 (R - e) angle (Pappus)."""
    big, r, e, angle = 20.0, 4.0, 1.5, 1.3
    # rho is not a trigonometric polynomial here: 128 angles resolve it to round-off (spectral convergence)
    got = _integrals(Body(circular_arc(big, angle), r, eccentricity=e), na=128)
    volume = np.pi * r**2 * (big - e) * angle
    np.testing.assert_allclose(got.volume, volume, rtol=0, atol=QUAD_RTOL * volume)


def test_helix_tube_volume_is_pi_r2_length_despite_twisting_frames():
    line = helix(6.0, 9.0, 1.5)
    got = integrate_body(Body(line, 1.5).field(NA), np.linspace(0, 1, 7))
    volume = np.pi * 1.5**2 * line.length
    np.testing.assert_allclose(got.volume, volume, rtol=0, atol=QUAD_RTOL * volume)


def test_tube_form_and_section_form_agree_on_a_random_smooth_section():
    """V from rho^2/2 - rho^3/3 kn equals V from section area and first moment (Green's theorem)."""
    rng = np.random.default_rng(7)
    a = angle_grid(48)
    coeffs = rng.normal(scale=0.2, size=(5, 4, 2))
    modes = enumerate(coeffs.transpose(1, 0, 2), 1)
    rho = 2.0 + sum(c[:, :1] * np.cos(m * a) + c[:, 1:] * np.sin(m * a) for m, c in modes)
    curvature, weights = rng.normal(scale=0.05, size=(5, 2)), rng.uniform(0.5, 1.0, 5)
    xy = section_curves(rho, np.zeros_like(rho), curvature, 0.0)
    tube, sweep = tube_volume(rho, curvature, weights), sweep_volume(xy, curvature, weights)
    np.testing.assert_allclose(sweep, tube, rtol=0, atol=QUAD_RTOL * tube)


def test_section_moments_of_an_offset_circle():
    """Area pi r^2 and first moment pi r^2 (e, 0) of a circle of radius r about (e, 0)."""
    r, e, na = 2.0, 0.5, 96
    a = angle_grid(na)
    xy = np.stack([e + r * np.cos(a), r * np.sin(a)], axis=-1)[None]
    area, moment = section_moments(xy)
    np.testing.assert_allclose(area, [np.pi * r**2], rtol=0, atol=QUAD_RTOL * np.pi * r**2)
    np.testing.assert_allclose(moment, [[np.pi * r**2 * e, 0.0]], rtol=0, atol=QUAD_RTOL * np.pi * r**2)


def test_lateral_area_of_a_torus_section_without_caps():
    big, r, angle = 20.0, 4.0, 1.3
    body = Body(circular_arc(big, angle), r)
    nodes, weights = gauss_legendre_nodes([0.0, 1.0], 8)
    st = body.field(NA)(nodes)
    got = tube_lateral_area(st.rho, st.rho_s, st.curvature, weights * st.speed)
    area = 2 * np.pi * r * big * angle
    np.testing.assert_allclose(got, area, rtol=0, atol=QUAD_RTOL * area)


def test_gauss_legendre_is_exact_to_degree_2n_minus_1():
    nodes, weights = gauss_legendre_nodes([0.0, 0.3, 1.0], 4)
    assert nodes.shape == weights.shape == (8,)
    np.testing.assert_allclose(weights @ nodes**7, 1 / 8, rtol=0, atol=1e-15)


def test_angular_derivative_of_a_trigonometric_polynomial():
    a = angle_grid(16)
    values = 1 + 2 * np.cos(3 * a) - np.sin(7 * a)
    np.testing.assert_allclose(angular_derivative(values), -6 * np.sin(3 * a) - 7 * np.cos(7 * a), rtol=0, atol=1e-12)


def test_polygon_area_ratio_known_values():
    np.testing.assert_allclose(polygon_area_ratio(4), 2 / np.pi, rtol=0, atol=1e-15)  # square: 2 r^2
    np.testing.assert_allclose(polygon_area_ratio(6), 3 * np.sqrt(3) / (2 * np.pi), rtol=0, atol=1e-15)


def test_offset_of_a_cone_is_a_cone_at_normal_distance():
    """The outward normal offset d of a cone of slope m has radius rho + d sqrt(1 + m^2) in every section."""
    slope, d = 0.2, 0.7
    rho = np.array([[2.0] * 8, [3.0] * 8])
    xy = section_curves(rho, np.full_like(rho, slope), np.zeros((2, 2)), d)
    np.testing.assert_allclose(np.linalg.norm(xy, axis=-1), rho + d * np.hypot(1, slope), rtol=0, atol=1e-14)


def test_offset_frustum_volume():
    r0, slope, length, d = 2.0, 0.05, 30.0, 0.4
    got = integrate_body(Body(straight_line(length), r0, slope).field(NA), [0, 1], BodySpec(offset_mm=d))
    g = d * np.hypot(1, slope)
    a, b = r0 + g, r0 + slope * length + g
    volume = np.pi * length * (a**2 + a * b + b**2) / 3
    np.testing.assert_allclose(got.volume, volume, rtol=0, atol=QUAD_RTOL * volume)
    assert got.area is None


def test_hollow_torus_section_volume():
    """Outer torus section minus the chamber: radius r - w, angle shortened by 2 w / R, minus the port."""
    big, r, angle, w, port = 20.0, 4.0, 1.3, 0.8, 1.2
    spec = BodySpec(wall_mm=w, port_mm=port)
    got = integrate_body(Body(circular_arc(big, angle), r).field(NA), [0, 1], spec)
    volume = np.pi * big * (r**2 * angle - (r - w) ** 2 * (angle - 2 * w / big)) - np.pi * (port / 2) ** 2 * w
    np.testing.assert_allclose(got.volume, volume, rtol=0, atol=QUAD_RTOL * volume)


def test_l_at_arclength_inverts_a_nonuniform_speed():
    """speed ds/dl = 1 + 3 l^2 mm gives s(l) = l + l^3; s = 1.125 mm at l = 0.75."""

    def field(l):
        l = np.asarray(l, float)
        return type("S", (), {"speed": 1 + 3 * l**2})()

    np.testing.assert_allclose(l_at_arclength(field, [0.0, 1.0], 0.75 + 0.75**3), 0.75, rtol=0, atol=1e-12)


def test_arc_lengths_use_the_fields_speed_alone_when_it_has_one():
    """A hollow body's chamber ends come from s(l) only: a field with ``speed`` is not asked for radii there."""
    body = Body(circular_arc(30.0, 1.0), 2.0)
    plain = body.field(NA)
    calls = []

    class WithSpeed:
        def __call__(self, l):
            calls.append(np.size(l))
            return plain(l)

        def speed(self, l):
            return plain(l).speed

    spec = BodySpec(wall_mm=0.5, port_mm=0.4)
    breaks = [0.0, 0.5, 1.0]
    assert integrate_body(WithSpeed(), breaks, spec) == integrate_body(plain, breaks, spec)
    assert len(calls) == 2  # the whole body's nodes and the chamber's, nothing for the Newton steps


def test_l_at_arclength_refuses_a_length_beyond_the_curve():
    with pytest.raises(ValueError, match="outside"):
        l_at_arclength(Body(straight_line(10.0), 1.0).field(8), [0.0, 1.0], 11.0)
