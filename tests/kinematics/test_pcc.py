"""PCC sections from cable-encoder lengths (seed 003): known answers, seed cases, round trips, invariants."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import ConfigError, InputDataError
from softdesign.kinematics import pcc
from tests.helpers.seed_transforms import rot_y, rot_z, seed_chain

#: Agreement of two exact computations of the same length, mm (double rounding on ~500 mm).
LENGTH_TOL_MM = 1e-9
#: Same for curvatures, 1/mm.
KAPPA_TOL = 1e-12
#: Same for angles and dimensionless matrix entries.
ANGLE_TOL = 1e-12

D_MM = 15.0
SEED_SINGLE = {
    "initial": (120.1, 120.2, 120.0),
    "extension": (180.0, 179.8, 180.1),
    "bending": (235.0, 185.0, 268.0),
}
SEED_CHAINS = {
    "extended": [(120, 123, 124), (125, 123, 121), (126, 124, 125)],
    "bending": [(121, 123, 125), (236, 187, 269), (236, 186, 268)],
}


# -- independent constructions, written from the seed's text, not from the module --------------


def seed_kappa(l1: float, l2: float, l3: float, d: float) -> float:
    """Seed eq. 5."""
    return 2 * np.sqrt(l1**2 + l2**2 + l3**2 - l1 * l2 - l1 * l3 - l2 * l3) / (d * (l1 + l2 + l3))


def seed_tip(kappa: float, phi: float, theta: float) -> np.ndarray:
    """Seed eq. 6."""
    return np.array([np.cos(phi) * (1 - np.cos(theta)), np.sin(phi) * (1 - np.cos(theta)), np.sin(theta)]) / kappa


def check_rotation(pose: np.ndarray) -> None:
    rotation = pose[..., :3, :3]
    eye = np.broadcast_to(np.eye(3), rotation.shape)
    np.testing.assert_allclose(np.swapaxes(rotation, -1, -2) @ rotation, eye, rtol=0, atol=ANGLE_TOL)
    np.testing.assert_allclose(np.linalg.det(rotation), 1.0, rtol=0, atol=ANGLE_TOL)
    np.testing.assert_array_equal(pose[..., 3, :], np.broadcast_to([0, 0, 0, 1.0], pose[..., 3, :].shape))


# -- known answers ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "lengths, phi_deg",
    [
        ((100, 110, 110), 90),  # cable 1 (90 deg) shortest: bends towards it
        ((110, 100, 110), -150),  # cable 2 (210 deg)
        ((110, 110, 100), -30),  # cable 3 (330 deg)
        ((100, 100, 110), 150),  # cables 1 and 2 equally short: halfway, quadrant II
        ((110, 100, 100), -90),  # halfway between 210 and 330
        ((100, 110, 100), 30),  # halfway between 330 and 90, quadrant I
    ],
)
def test_a_section_bends_towards_its_shortest_cables(lengths, phi_deg):
    arcs = pcc.arcs_from_lengths(lengths, D_MM)
    np.testing.assert_allclose(arcs.phi, np.deg2rad(phi_deg), rtol=0, atol=ANGLE_TOL)
    # eq. 2 at the shortest cable (cos = 1 for one cable; cos 60 deg = 1/2 for two): L - l = theta d cos.
    mean = np.mean(lengths)
    shortest = min(lengths)
    cosine = 1.0 if sorted(lengths)[1] != shortest else 0.5
    np.testing.assert_allclose(arcs.theta, (mean - shortest) / (D_MM * cosine), rtol=0, atol=ANGLE_TOL)
    np.testing.assert_allclose(arcs.kappa, arcs.theta / mean, rtol=0, atol=KAPPA_TOL)
    tip = pcc.tip_position_from_arc(arcs.kappa, arcs.phi, arcs.length)
    np.testing.assert_allclose(np.arctan2(tip[1], tip[0]), np.deg2rad(phi_deg), rtol=0, atol=ANGLE_TOL)


@pytest.mark.parametrize("turn", [0.25, 0.5, 1.0])
def test_quarter_half_and_full_circle(turn):
    radius = 40.0
    length = 2 * np.pi * radius * turn
    pose = pcc.transform_from_arc(1 / radius, 0.0, length)
    theta = 2 * np.pi * turn
    expected_tip = radius * np.array([1 - np.cos(theta), 0.0, np.sin(theta)])
    np.testing.assert_allclose(pose[:3, 3], expected_tip, rtol=0, atol=LENGTH_TOL_MM)
    np.testing.assert_allclose(pose[:3, :3], rot_y(theta)[:3, :3], rtol=0, atol=ANGLE_TOL)


def test_a_single_dh_link_and_a_zero_table():
    link = pcc.transform_from_dh(np.pi / 2, 3.0, 2.0, np.pi / 2)
    # Rz(90) Tz(3) Tx(2) Rx(90): x -> y, y -> z, z -> x; origin at (0, 2, 3)
    expected = np.array([[0, 0, 1, 0], [1, 0, 0, 2], [0, 1, 0, 3], [0, 0, 0, 1.0]])
    np.testing.assert_allclose(link, expected, rtol=0, atol=ANGLE_TOL)
    np.testing.assert_array_equal(pcc.transform_from_dh_table(np.zeros((5, 4))), np.eye(4))


# -- the seed's cases ------------------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(SEED_SINGLE))
def test_seed_single_section_matches_equations_4_to_6_and_the_dh_chain(name):
    l1, l2, l3 = SEED_SINGLE[name]
    arcs = pcc.arcs_from_lengths((l1, l2, l3), D_MM)
    np.testing.assert_allclose(arcs.length, (l1 + l2 + l3) / 3, rtol=0, atol=LENGTH_TOL_MM)  # eq. 3
    np.testing.assert_allclose(arcs.kappa, seed_kappa(l1, l2, l3, D_MM), rtol=0, atol=KAPPA_TOL)  # eq. 5
    np.testing.assert_allclose(arcs.theta, arcs.kappa * arcs.length, rtol=0, atol=ANGLE_TOL)
    # eq. 4 fixes tan(phi); its signs (the quadrant) follow from eq. 2: l2 - l3 = sqrt(3) theta d cos(phi),
    # l2 + l3 - 2 l1 = 3 theta d sin(phi).
    numerator, denominator = np.sqrt(3) * (l2 + l3 - 2 * l1), 3 * (l2 - l3)
    np.testing.assert_allclose(np.sin(arcs.phi) * denominator, np.cos(arcs.phi) * numerator, rtol=0, atol=1e-9)
    assert np.sign(np.cos(arcs.phi)) == np.sign(denominator)
    assert np.sign(np.sin(arcs.phi)) in (np.sign(numerator), 0.0)

    pose = pcc.transform_from_arc(arcs.kappa, arcs.phi, arcs.length)
    chain = seed_chain(float(arcs.kappa), float(arcs.phi), float(arcs.length))
    np.testing.assert_allclose(pose, chain, rtol=0, atol=LENGTH_TOL_MM)
    np.testing.assert_allclose(pose[:3, 3], seed_tip(arcs.kappa, arcs.phi, arcs.theta), rtol=0, atol=LENGTH_TOL_MM)
    np.testing.assert_allclose(chain[:3, 3], seed_tip(arcs.kappa, arcs.phi, arcs.theta), rtol=0, atol=LENGTH_TOL_MM)
    check_rotation(pose)


@pytest.mark.parametrize("name", sorted(SEED_CHAINS))
def test_seed_three_sections_chain_by_product_and_equation_10(name):
    lengths = np.array(SEED_CHAINS[name], float)
    arcs = pcc.arcs_from_lengths(lengths, D_MM)
    for i, (l1, l2, l3) in enumerate(lengths):
        np.testing.assert_allclose(arcs.kappa[i], seed_kappa(l1, l2, l3, D_MM), rtol=0, atol=KAPPA_TOL)
    section2base = pcc.chain_transforms(pcc.transform_from_arc(arcs.kappa, arcs.phi, arcs.length))

    product = np.eye(4)
    position = np.zeros(3)
    for i in range(3):
        kappa, phi, theta = arcs.kappa[i], arcs.phi[i], arcs.theta[i]
        position = position + product[:3, :3] @ seed_tip(kappa, phi, theta)  # eq. 10
        product = product @ seed_chain(kappa, phi, arcs.length[i])
        np.testing.assert_allclose(section2base[i], product, rtol=0, atol=LENGTH_TOL_MM)
        np.testing.assert_allclose(section2base[i, :3, 3], position, rtol=0, atol=LENGTH_TOL_MM)
    check_rotation(section2base)


@pytest.mark.parametrize("lengths", list(SEED_SINGLE.values()) + list(SEED_CHAINS.values()))
def test_seed_lengths_round_trip(lengths):
    arcs = pcc.arcs_from_lengths(lengths, D_MM)
    back = pcc.lengths_from_arcs(arcs.kappa, arcs.phi, arcs.length, D_MM)
    np.testing.assert_allclose(back, np.asarray(lengths, float), rtol=0, atol=LENGTH_TOL_MM)


# -- round trips -----------------------------------------------------------------------------------


def test_arcs_round_trip_through_lengths_in_every_quadrant():
    rng = np.random.default_rng(6)
    phi = np.linspace(-np.pi, np.pi, 97)[1:]  # every quadrant and both axes; -pi is the same as pi
    kappa = rng.uniform(1e-4, 2e-2, phi.shape)
    length = rng.uniform(50.0, 250.0, phi.shape)
    d = rng.uniform(5.0, 20.0, phi.shape)
    lengths = pcc.lengths_from_arcs(kappa, phi, length, d)
    assert np.all(lengths > 0)  # the draw keeps theta d < L, so every cable is a real length
    arcs = pcc.arcs_from_lengths(lengths, d)
    np.testing.assert_allclose(arcs.kappa, kappa, rtol=0, atol=KAPPA_TOL)
    np.testing.assert_allclose(arcs.length, length, rtol=0, atol=LENGTH_TOL_MM)
    np.testing.assert_allclose(np.angle(np.exp(1j * (arcs.phi - phi))), 0.0, rtol=0, atol=1e-9)
    assert np.all(arcs.kappa >= 0) and np.all(np.abs(arcs.phi) <= np.pi)


def test_kappa_is_never_negative():
    rng = np.random.default_rng(7)
    lengths = rng.uniform(1.0, 300.0, (2000, 3))
    arcs = pcc.arcs_from_lengths(lengths, rng.uniform(1.0, 30.0, 2000))
    assert np.all(arcs.kappa >= 0) and np.all(arcs.theta >= 0)


# -- symmetries the geometry dictates --------------------------------------------------------------


def test_bending_by_phi_plus_pi_reflects_the_lengths_about_their_mean():
    lengths = np.array(SEED_SINGLE["bending"])
    arcs = pcc.arcs_from_lengths(lengths, D_MM)
    # eq. 2 with phi + pi flips the sign of the cosine: l_j -> L + theta d cos(...) = 2 L - l_j.
    flipped = pcc.arcs_from_lengths(2 * lengths.mean() - lengths, D_MM)
    np.testing.assert_allclose(flipped.kappa, arcs.kappa, rtol=0, atol=KAPPA_TOL)
    np.testing.assert_allclose(flipped.length, arcs.length, rtol=0, atol=LENGTH_TOL_MM)
    np.testing.assert_allclose(np.cos(flipped.phi - arcs.phi), -1.0, rtol=0, atol=ANGLE_TOL)
    pose = pcc.transform_from_arc(arcs.kappa, arcs.phi, arcs.length)
    pose_flipped = pcc.transform_from_arc(flipped.kappa, flipped.phi, flipped.length)
    # the bent shape turned half a turn about the base tangent z
    np.testing.assert_allclose(pose_flipped, rot_z(np.pi) @ pose @ rot_z(-np.pi), rtol=0, atol=LENGTH_TOL_MM)
    # and a negative curvature means the same bend
    np.testing.assert_allclose(
        pcc.transform_from_arc(-arcs.kappa, arcs.phi, arcs.length), pose_flipped, rtol=0, atol=LENGTH_TOL_MM
    )


def test_turning_the_bend_by_120_degrees_moves_each_reading_to_the_next_cable():
    lengths = np.array(SEED_SINGLE["bending"])
    arcs = pcc.arcs_from_lengths(lengths, D_MM)
    # cable j sits 120 deg after cable j - 1, so after turning the bend by +120 deg it reads what j - 1 read
    turned = pcc.arcs_from_lengths(np.roll(lengths, 1), D_MM)
    np.testing.assert_allclose(np.cos(turned.phi - arcs.phi), np.cos(2 * np.pi / 3), rtol=0, atol=ANGLE_TOL)
    np.testing.assert_allclose(np.sin(turned.phi - arcs.phi), np.sin(2 * np.pi / 3), rtol=0, atol=ANGLE_TOL)
    np.testing.assert_allclose(turned.kappa, arcs.kappa, rtol=0, atol=KAPPA_TOL)


# -- the straight limit ----------------------------------------------------------------------------


def test_straight_section_is_an_exact_translation_and_near_straight_is_the_same():
    exact = pcc.arcs_from_lengths((120.0, 120.0, 120.0), D_MM)
    assert exact.kappa == 0.0 and exact.phi == 0.0
    straight = pcc.transform_from_arc(exact.kappa, exact.phi, exact.length)
    expected = np.eye(4)
    expected[2, 3] = 120.0
    np.testing.assert_array_equal(straight, expected)
    np.testing.assert_array_equal(pcc.dh_table_from_arc(0.0, 0.0, 120.0)[2, 1], 120.0)
    for nudged in [(120.0, 120.0 + 1e-12, 120.0), (120.0 - 1e-12, 120.0, 120.0), (120.0, 120.0, 120.0 + 1e-12)]:
        arcs = pcc.arcs_from_lengths(nudged, D_MM)
        pose = pcc.transform_from_arc(arcs.kappa, arcs.phi, arcs.length)
        assert np.all(np.isfinite(pose))
        np.testing.assert_allclose(pose, straight, rtol=0, atol=LENGTH_TOL_MM)
        np.testing.assert_allclose(
            pcc.transform_from_dh_table(pcc.dh_table_from_arc(arcs.kappa, arcs.phi, arcs.length)),
            straight, rtol=0, atol=LENGTH_TOL_MM,
        )


def test_the_tip_is_smooth_through_zero_curvature():
    length, phi = 120.0, 0.7
    kappa = np.concatenate([-np.logspace(-3, -300, 50), [0.0], np.logspace(-300, -3, 50)])
    tip = pcc.tip_position_from_arc(kappa, phi, length)
    assert np.all(np.isfinite(tip))
    theta = kappa * length
    # series of eq. 6: ((theta/2) L cos phi, (theta/2) L sin phi, L (1 - theta^2/6)) + O(L theta^3)
    series = np.column_stack(
        [theta / 2 * length * np.cos(phi), theta / 2 * length * np.sin(phi), length * (1 - theta**2 / 6)]
    )
    np.testing.assert_array_less(np.abs(tip - series).max(axis=1), length * np.abs(theta) ** 3 + 1e-13)
    # slope at kappa = 0 from a central difference: L^2 / 2 (cos phi, sin phi, 0)
    step = 1e-7
    slope = (pcc.tip_position_from_arc(step, phi, length) - pcc.tip_position_from_arc(-step, phi, length)) / (2 * step)
    # rounding of ~1e-14 mm over 2e-7 1/mm leaves ~1e-7 mm^2; 1e-5 is far below L^2/2 = 7200
    np.testing.assert_allclose(slope, length**2 / 2 * np.array([np.cos(phi), np.sin(phi), 0]), rtol=0, atol=1e-5)


# -- D-H table and invariants ----------------------------------------------------------------------


def test_dh_table_product_equals_closed_form_and_rotations_are_proper():
    rng = np.random.default_rng(8)
    kappa = np.concatenate([[0.0, 1e-14], rng.uniform(-0.05, 0.05, 60)])
    phi = rng.uniform(-np.pi, np.pi, kappa.shape)
    length = rng.uniform(1.0, 400.0, kappa.shape)  # theta up to 20 rad: several turns
    closed = pcc.transform_from_arc(kappa, phi, length)
    from_table = pcc.transform_from_dh_table(pcc.dh_table_from_arc(kappa, phi, length))
    np.testing.assert_allclose(from_table, closed, rtol=0, atol=LENGTH_TOL_MM)
    check_rotation(closed)
    for i in range(0, len(kappa), 10):
        np.testing.assert_allclose(
            pcc.transform_from_dh_table(pcc.dh_table_from_arc(kappa[i], phi[i], length[i])), closed[i],
            rtol=0, atol=LENGTH_TOL_MM,
        )


def test_batches_equal_one_at_a_time():
    lengths = np.array([SEED_CHAINS["extended"], SEED_CHAINS["bending"]], float)  # (2 rows, 3 sections, 3)
    d = np.array([15.0, 14.0, 13.0])
    arcs = pcc.arcs_from_lengths(lengths, d)
    poses = pcc.chain_transforms(pcc.transform_from_arc(arcs.kappa, arcs.phi, arcs.length))
    for row in range(2):
        one = pcc.arcs_from_lengths(lengths[row], d)
        np.testing.assert_array_equal(arcs.kappa[row], one.kappa)
        single = pcc.chain_transforms(pcc.transform_from_arc(one.kappa, one.phi, one.length))
        np.testing.assert_allclose(poses[row], single, rtol=0, atol=LENGTH_TOL_MM)


# -- backbone --------------------------------------------------------------------------------------


def test_backbone_samples_lie_on_each_arc_and_end_at_the_tip():
    lengths = np.array(SEED_CHAINS["bending"], float)
    arcs = pcc.arcs_from_lengths(lengths, D_MM)
    m = 9
    poses = pcc.sample_backbone_poses(arcs.kappa, arcs.phi, arcs.length, m)
    points = pcc.sample_backbone(arcs.kappa, arcs.phi, arcs.length, m)
    arc_length, section = pcc.backbone_arc_lengths(arcs.length, m)
    assert poses.shape == (3 * (m - 1) + 1, 4, 4) and points.shape == (len(poses), 3) and section.shape == (len(poses),)
    np.testing.assert_array_equal(poses[0], np.eye(4))
    section2base = pcc.chain_transforms(pcc.transform_from_arc(arcs.kappa, arcs.phi, arcs.length))
    np.testing.assert_allclose(poses[-1], section2base[-1], rtol=0, atol=LENGTH_TOL_MM)
    np.testing.assert_allclose(
        arc_length[[0, m - 1, -1]], [0, arcs.length[0], arcs.length.sum()], rtol=0, atol=LENGTH_TOL_MM
    )
    check_rotation(poses)
    bases = [np.eye(4), section2base[0], section2base[1]]
    for i in range(3):
        samples = np.flatnonzero(section == i)
        samples = np.concatenate([[samples[0] - 1], samples]) if i else samples  # the junction starts the arc
        # centre of curvature: 1/kappa from the arc's base along its bending direction phi
        centre = bases[i] @ np.array([np.cos(arcs.phi[i]) / arcs.kappa[i], np.sin(arcs.phi[i]) / arcs.kappa[i], 0, 1])
        radii = np.linalg.norm(points[samples] - centre[:3], axis=1)
        np.testing.assert_allclose(radii, 1 / arcs.kappa[i], rtol=0, atol=LENGTH_TOL_MM)
        chord = 2 / arcs.kappa[i] * np.sin(arcs.theta[i] / (m - 1) / 2)
        chords = np.linalg.norm(np.diff(points[samples], axis=0), axis=1)
        np.testing.assert_allclose(chords, chord, rtol=0, atol=LENGTH_TOL_MM)


def test_straight_backbone_is_on_the_z_axis():
    points = pcc.sample_backbone([0.0, 0.0], [0.0, 1.0], [10.0, 30.0], 5)
    expected = np.column_stack([np.zeros(9), np.zeros(9), [0, 2.5, 5, 7.5, 10, 17.5, 25, 32.5, 40]])
    np.testing.assert_allclose(points, expected, rtol=0, atol=LENGTH_TOL_MM)


# -- input checks ----------------------------------------------------------------------------------


def test_bad_inputs_raise_located_errors():
    with pytest.raises(InputDataError, match=r"lengths\[1, 2\] is -3.0"):
        pcc.arcs_from_lengths([[120, 121, 122], [120, 121, -3.0]], D_MM)
    with pytest.raises(InputDataError, match="shape"):
        pcc.arcs_from_lengths([120, 121], D_MM)
    with pytest.raises(ConfigError, match="d .* > 0 mm, got 0"):
        pcc.arcs_from_lengths([120, 121, 122], 0.0)
    with pytest.raises(ConfigError, match="got nan"):
        pcc.lengths_from_arcs(0.01, 0.0, 100.0, np.nan)
    with pytest.raises(ConfigError, match="points per section"):
        pcc.sample_backbone(0.01, 0.0, 100.0, 1)
    with pytest.raises(ConfigError, match=r"chain is \(\.\.\., k, 4, 4\)"):
        pcc.chain_transforms(np.eye(4))
    with pytest.raises(ConfigError, match="D-H table"):
        pcc.transform_from_dh_table(np.zeros((5, 3)))
