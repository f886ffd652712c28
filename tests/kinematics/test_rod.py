"""The rod model of the body on known answers: beam formulas of holed round sections, symmetry, the thread."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.kinematics import pcc
from softdesign.kinematics.rod import Cavities, hoop_tension_per_turn_n, rod_body, section_arcs, station_poses, strains

#: Closed-form quantities against the model's linear solves: rounding only.
EXACT_REL = 1e-12
#: Absolute tolerance on positions after composing a few hundred station transforms, mm.
CHAIN_ATOL_MM = 1e-9

R, E, P = 3.0, 120.0, 150.0  # mm, kPa, kPa
STATIONS, ANGLES = 40, 96


def _body(cavity_centers, cavity_radii, channels, backbone, radius=R, sections=None):
    k = STATIONS
    centers = np.broadcast_to(np.asarray(cavity_centers, float), (k, len(channels), 2))
    radii = np.broadcast_to(np.asarray(cavity_radii, float), (k, len(channels)))
    outer = np.broadcast_to(np.asarray(radius, float).reshape(-1, 1), (k, ANGLES))
    section = np.zeros(k, np.int64) if sections is None else sections
    return rod_body(np.full(k, 0.5), section, outer, Cavities(centers, radii, np.asarray(channels)), E, backbone)


def _polar(d, angle):
    return [d * np.cos(angle), d * np.sin(angle)]


@pytest.mark.parametrize("angle", [0.0, 1.0, -2.5])
def test_one_chamber_inextensible_bends_away_by_p_a_d_over_e_i(angle):
    d, r = 1.6, 0.7
    body = _body([_polar(d, angle)], [r], [0], "inextensible")
    eps0, w, tension = strains(body, [P])
    a = np.pi * r**2
    i_holed = np.pi * R**4 / 4 - (np.pi * r**4 / 4 + a * d**2)  # about the axis normal to the chamber's direction
    np.testing.assert_allclose(np.hypot(w[:, 0], w[:, 1]), P * a * d / (E * i_holed), rtol=EXACT_REL, atol=0)
    away = np.angle(np.exp(1j * (np.arctan2(w[:, 1], w[:, 0]) - angle - np.pi)))
    np.testing.assert_allclose(away, 0.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(eps0, 0.0, rtol=0, atol=1e-15)
    # the thread carries P A and what the bent, off-centre net section pulls on it: the material's net force
    # -E S.w, with S = -A d e (the hole's first moment) and w = -kappa e
    kappa = P * a * d / (E * i_holed)
    np.testing.assert_allclose(tension, (P * a + E * a * d * kappa) * 1e-3, rtol=EXACT_REL, atol=0)


def test_one_chamber_free_is_the_beam_about_the_holed_centroid():
    d, r = 1.6, 0.7
    body = _body([[d, 0.0]], [r], [0], "free")
    eps0, w, _ = strains(body, [P])
    a = np.pi * r**2
    a_net = np.pi * R**2 - a
    c = -a * d / a_net  # the net section's centroid, on the chamber's line, away from it
    i_centroid = np.pi * R**4 / 4 - (np.pi * r**4 / 4 + a * d**2) - a_net * c**2
    kappa = P * a * (d - c) / (E * i_centroid)  # P A at its arm from the centroid
    np.testing.assert_allclose(w[:, 0], -kappa, rtol=EXACT_REL, atol=0)
    np.testing.assert_allclose(w[:, 1], 0.0, rtol=0, atol=1e-15)
    eps_centroid = P * a / (E * a_net)
    np.testing.assert_allclose(eps0, eps_centroid - kappa * c, rtol=EXACT_REL, atol=0)  # strain at the axis


@pytest.mark.parametrize("backbone", ["free", "inextensible"])
def test_three_equal_chambers_stretch_without_bending(backbone):
    d, r = 1.6, 0.6
    centers = [_polar(d, np.pi / 2 + 2 * np.pi * j / 3) for j in range(3)]
    body = _body(centers, [r] * 3, [0, 0, 0], backbone)
    eps0, w, _ = strains(body, [P])
    np.testing.assert_allclose(w, 0.0, rtol=0, atol=1e-15)
    a = np.pi * r**2
    expected = 3 * P * a / (E * (np.pi * R**2 - 3 * a)) if backbone == "free" else 0.0
    np.testing.assert_allclose(eps0, expected, rtol=EXACT_REL, atol=1e-15)


def test_no_taper_on_a_tapered_body_bends_as_one_over_i():
    d, r = 1.4, 0.6
    radius = np.linspace(2.6, 3.4, STATIONS)
    body = _body([[0.0, d]], [r], [0], "inextensible", radius=radius)
    _, w, _ = strains(body, [P])
    a = np.pi * r**2
    i_holed = np.pi * radius**4 / 4 - (np.pi * r**4 / 4 + a * d**2)
    np.testing.assert_allclose(-w[:, 1] * i_holed, P * a * d / E, rtol=EXACT_REL, atol=0)
    assert np.ptp(w[:, 1]) > 0.5 * abs(w[:, 1]).min()  # the curvature does change along the body


def test_a_feed_bends_the_section_it_runs_through():
    # section 0 holds its own unpressurised chamber (channel 0) and the feed (channel 1) of section 1's chamber,
    # on one line through the axis so that the holed section's principal axes are that line and its normal
    d, r, d_f, r_f = 1.5, 0.6, 1.5, 0.2
    feed_angle = 2.0
    sections = np.repeat([0, 1], STATIONS // 2)
    centers, radii = np.zeros((STATIONS, 3, 2)), np.zeros((STATIONS, 3))
    first = sections == 0
    centers[:, 0], radii[first, 0] = _polar(d, feed_angle + np.pi), r
    centers[:, 1], radii[first, 1] = _polar(d_f, feed_angle), r_f
    centers[:, 2], radii[~first, 2] = _polar(d_f, feed_angle), r
    outer = np.full((STATIONS, ANGLES), R)
    body = rod_body(np.full(STATIONS, 0.5), sections, outer, Cavities(centers, radii, np.array([0, 1, 1])), E,
                    "inextensible")
    _, w, _ = strains(body, [0.0, P])
    a, a_f = np.pi * r**2, np.pi * r_f**2
    i_holed = np.pi * R**4 / 4 - (np.pi * r**4 / 4 + a * d**2) - (np.pi * r_f**4 / 4 + a_f * d_f**2)
    expected = -P * a_f * d_f / (E * i_holed) * np.asarray(_polar(1.0, feed_angle))  # away from the feed
    np.testing.assert_allclose(w[first], np.broadcast_to(expected, w[first].shape), rtol=EXACT_REL, atol=1e-15)
    assert np.all(np.hypot(w[~first, 0], w[~first, 1]) > np.hypot(*expected))  # its own chamber bends section 1


def test_uniform_stations_compose_into_the_arc():
    d, r = 1.6, 0.7
    body = _body([_polar(d, 0.4)], [r], [0], "free")
    eps0, w, _ = strains(body, [P])
    poses = station_poses(eps0, w, body.ds, np.eye(4))
    kappa, phi, length = section_arcs(body, poses, eps0)
    np.testing.assert_allclose(length, STATIONS * 0.5 * (1 + eps0[0]), rtol=EXACT_REL, atol=0)
    np.testing.assert_allclose(kappa * length, np.hypot(*w[0]) * STATIONS * 0.5, rtol=1e-10, atol=0)
    tip = pcc.tip_position_from_arc(kappa[0], phi[0], length[0])
    np.testing.assert_allclose(poses[-1][:3, 3], tip, rtol=0, atol=CHAIN_ATOL_MM)
    np.testing.assert_allclose(phi[0], 0.4 - np.pi, rtol=0, atol=1e-12)


def test_thread_tension_per_turn_is_p_r_pitch():
    np.testing.assert_allclose(hoop_tension_per_turn_n(200.0, 0.5, 1.0), 200e-3 * 0.5 * 1.0, rtol=EXACT_REL, atol=0)
    np.testing.assert_allclose(hoop_tension_per_turn_n([100.0, 50.0], [0.4, 0.8], 0.5), [0.02, 0.02],
                               rtol=EXACT_REL, atol=0)
