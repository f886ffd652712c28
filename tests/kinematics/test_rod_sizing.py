"""Chambers sized by the rod model: taper, single-supply and per-chamber round trips, on known answers."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.kinematics.pcc_chain import chain_points_at
from softdesign.kinematics.rod import Cavities, rod_body, section_arcs, station_poses, strains
from softdesign.kinematics.rod_inverse import per_chamber_pressures
from softdesign.kinematics.rod_sizing import (
    Limits,
    Problem,
    design_pressure,
    fits,
    size_single,
    stations_along,
)
from softdesign.kinematics.rod_walls import thread_gap_mm

#: The sizing's Newton converges to 1e-13 of the target's bending; constant within this relative spread.
TAPER_RTOL = 1e-6
#: The composed chain against the designed one, mm (the issue's bound).
CHAIN_ATOL_MM = 1e-6
#: Per-chamber inverse then forward (linear solves only).
ROUND_TRIP_ATOL = 1e-8

E = 120.0  # kPa
ANGLES = 64
LIMITS = Limits(wall_mm=0.5, feed_diameter_mm=0.3, thread_diameter_mm=0.2, max_pressure_kpa=2000.0)


def _problem(lengths, radius, w, backbone="inextensible", per_section=30, end_wall=0.0):
    stations = stations_along(lengths, per_section, end_wall)
    r = radius(stations.s) if callable(radius) else np.full(len(stations.ds), radius)
    return Problem(stations, np.repeat(r[:, None], ANGLES, axis=1), np.asarray(w, float), E, backbone, LIMITS)


def test_a_tapered_chamber_keeps_the_curvature_constant_on_a_tapered_body():
    problem = _problem([30.0], lambda s: 2.6 + 0.03 * s, [[0.0, 0.03]])
    device = size_single(problem, 150.0)
    _, w, _ = strains(device.body, [150.0])
    kappa = np.hypot(w[:, 0], w[:, 1])
    np.testing.assert_allclose(kappa, 0.03, rtol=TAPER_RTOL, atol=0)
    assert device.diameter_mm[-1] > device.diameter_mm[0]  # the stiffer distal body needs the larger chamber
    np.testing.assert_allclose(np.angle(np.exp(1j * (device.angle - np.pi / 2 - np.pi))), 0.0, rtol=0, atol=1e-9)


def _designed():
    lengths = np.array([18.0, 22.0, 20.0, 16.0])
    kappa = np.array([0.04, 0.02, 0.05, 0.03])
    phi = np.array([0.3, 2.2, -1.4, 3.0])
    return lengths, np.stack([kappa * np.cos(phi), kappa * np.sin(phi)], axis=1)


def test_single_supply_round_trip_reaches_the_designed_chain_and_blends_as_pcc():
    lengths, w = _designed()
    problem = _problem(lengths, lambda s: 3.2 - 0.005 * s, w)
    device = design_pressure(problem)
    assert device is not None
    assert np.all(device.walls >= LIMITS.wall_mm * (1 - 1e-12))
    ends = np.concatenate([[0.0], np.cumsum(problem.stations.ds)])
    for fraction in (1.0, 0.5):
        eps0, bend, _ = strains(device.body, [fraction * device.pressure_kpa])
        poses = station_poses(eps0, bend, device.body.ds, np.eye(4))
        designed = chain_points_at(np.eye(4), fraction * w, lengths, ends)
        np.testing.assert_allclose(poses[:, :3, 3], designed, rtol=0, atol=CHAIN_ATOL_MM)
    # P* is the lowest that fits: just below it, a wall or the gap to the axis thread is too thin
    assert fits(device, LIMITS)
    below = size_single(problem, device.pressure_kpa * (1 - 1e-6))
    assert not fits(below, LIMITS)
    assert np.min(below.walls) < LIMITS.wall_mm or np.min(below.thread_gaps) < thread_gap_mm(0.2)


def test_single_supply_refuses_when_no_pressure_fits():
    lengths, w = _designed()
    problem = _problem(lengths, 0.95, w)  # a skin wall of 0.5 mm, the 0.4 mm gap and half the thread fill 1.0 mm
    assert design_pressure(problem) is None


def _three_chamber_body(lengths, backbone):
    stations = stations_along(lengths, 10, 0.0)
    k, n = len(stations.ds), len(lengths)
    d, r, r_f = 1.6, 0.5, 0.15
    angles = np.deg2rad(90.0) + 2 * np.pi * np.arange(3) / 3 + np.arange(n)[:, None] * 2 * np.pi / (3 * n)
    centers = np.zeros((k, 6 * n, 2))
    radii = np.zeros((k, 6 * n))
    starts = np.concatenate([[0.0], np.cumsum(lengths)[:-1]])
    for i in range(n):
        for j in range(3):
            c = 3 * i + j
            centers[:, c] = [d * np.cos(angles[i, j]), d * np.sin(angles[i, j])]
            centers[:, 3 * n + c] = centers[:, c]
            radii[stations.section == i, c] = r
            radii[stations.s < starts[i], 3 * n + c] = r_f  # its feed, through the proximal sections
    channels = np.concatenate([np.arange(3 * n), np.arange(3 * n)])
    outer = np.full((k, ANGLES), 3.0)
    return rod_body(stations.ds, stations.section, outer, Cavities(centers, radii, channels), E, backbone)


@pytest.mark.parametrize("backbone", ["inextensible", "free"])
def test_per_chamber_inverse_then_forward_recovers_every_arc(backbone):
    lengths, w = _designed()
    body = _three_chamber_body(lengths, backbone)
    grow = np.array([0.02, 0.03, 0.01, 0.04]) if backbone == "free" else None  # free: each section lengthens
    pressures = per_chamber_pressures(body, w * lengths[:, None], None if grow is None else grow * lengths)
    eps0, bend, _ = strains(body, pressures)
    kappa, phi, length = section_arcs(body, station_poses(eps0, bend, body.ds, np.eye(4)), eps0)
    expected_length = lengths * (1.0 if grow is None else 1.0 + grow)
    theta = np.hypot(w[:, 0], w[:, 1]) * lengths
    np.testing.assert_allclose(kappa * length, theta, rtol=0, atol=ROUND_TRIP_ATOL)
    np.testing.assert_allclose(np.angle(np.exp(1j * (phi - np.arctan2(w[:, 1], w[:, 0])))), 0.0, rtol=0,
                               atol=ROUND_TRIP_ATOL)
    np.testing.assert_allclose(length, expected_length, rtol=0, atol=ROUND_TRIP_ATOL)
    if backbone == "inextensible":
        assert np.all(pressures >= -1e-9)
        np.testing.assert_allclose(pressures.reshape(-1, 3).min(axis=1), 0.0, rtol=0, atol=1e-9)  # the lowest


def test_a_free_backbone_turns_each_section_through_its_angle_and_lengthens_it():
    lengths, w = _designed()
    problem = _problem(lengths, 3.2, w, backbone="free")
    device = size_single(problem, 400.0)
    eps0, bend, _ = strains(device.body, [400.0])
    kappa, phi, length = section_arcs(device.body, station_poses(eps0, bend, device.body.ds, np.eye(4)), eps0)
    np.testing.assert_allclose(kappa * length, np.hypot(w[:, 0], w[:, 1]) * lengths, rtol=0, atol=ROUND_TRIP_ATOL)
    np.testing.assert_allclose(np.angle(np.exp(1j * (phi - np.arctan2(w[:, 1], w[:, 0])))), 0.0, rtol=0,
                               atol=ROUND_TRIP_ATOL)
    assert np.all(length > lengths)  # the pressure pushes every chamber's ends apart: the rest body is shorter
