"""Link transforms and POE: seed 003's PCC arcs as known answers, then POE round trips, singular cases, links."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import ConfigError, GeometryError
from softdesign.geometry.blend import blend_shapes
from softdesign.geometry.curves import CurveOptions, smooth_curve_from_polyline
from softdesign.geometry.frames import framed_curve
from softdesign.geometry.initial import arc_initial_shape, straight_initial_shape
from softdesign.geometry.se3 import inverse_pose, pose_from_twist, rotation_from_rotvec, rotvec_from_rotation
from softdesign.kinematics.links import LinkChain, link_breaks, link_transforms
from softdesign.kinematics.poe import PoeSplit, poe_from_pose, pose_from_poe
from tests.helpers.seed_transforms import seed_chain, trans_z

#: The issue's bound on reproducing S_T_E from its POE split (we reach rounding).
POE_TOL = 1e-9
#: Rounding-level agreement of exact compositions.
ROUND_TOL = 1e-12


# --- seed 003's transform, written out independently of the package -------------------------------------
#: (kappa 1/mm, phi rad, length mm) of each arc; joints of moderate curvature jump (0.035 and 0.047 /mm).
ARCS = ((0.05, 0.4, 20.0), (0.07, 0.9, 15.0), (0.04, 0.2, 20.0))
#: Sample step of the dense polyline and of the resampling, mm.
STEP_MM = 0.005


def curvature_jumps() -> list[float]:
    """|change of the curvature vector| at each joint, 1/mm (in the common RMF: constant per arc)."""
    vectors = [k * np.array([np.cos(p), np.sin(p)]) for k, p, _ in ARCS]
    return [float(np.linalg.norm(b - a)) for a, b in zip(vectors[:-1], vectors[1:], strict=True)]


@pytest.fixture(scope="module")
def arcs_case():
    """Dense polyline of the arcs from a random base pose; joint poses; the smooth curve from it."""
    rng = np.random.default_rng(2024)
    base = np.eye(4)
    base[:3, :3] = rotation_from_rotvec(rng.normal(size=3))
    base[:3, 3] = rng.normal(scale=50, size=3)
    pose, points, joints = base, [], [base]
    for kappa, phi, length in ARCS:
        s = np.linspace(0, length, int(round(length / STEP_MM)) + 1)[:-1]
        points += [(pose @ seed_chain(kappa, phi, si))[:3, 3] if si > 0 else pose[:3, 3] for si in s]
        pose = pose @ seed_chain(kappa, phi, length)
        joints.append(pose)
    points.append(pose[:3, 3])
    curve = smooth_curve_from_polyline(np.array(points), CurveOptions(spacing_mm=STEP_MM, smoothing_mm=0.0))
    total = sum(a[2] for a in ARCS)
    breaks = np.concatenate([[0.0], np.cumsum([a[2] for a in ARCS])]) / total
    return curve, base, np.array(joints), breaks


def test_rmf_link_transforms_equal_seed_003_arcs(arcs_case):
    curve, base, joints, breaks = arcs_case
    framed = framed_curve(curve, "rmf", base_normal=base[:3, 0])
    # joint positions (world) to 1e-6 of the link length
    for j, (_, _, length) in enumerate(ARCS):
        np.testing.assert_allclose(
            curve.points(breaks[j : j + 2]), joints[j : j + 2, :3, 3], rtol=0, atol=1e-6 * length
        )
    jumps = [0.0, *curvature_jumps(), 0.0]
    transforms = link_transforms(framed, breaks)
    for j, (kappa, phi, length) in enumerate(ARCS):
        expected = seed_chain(kappa, phi, length)
        # A quintic spline cannot follow a curvature jump dk: its tangent at a joint is off by about
        # c * h * dk, c ~ 0.13 measured (by scaling, a constant of the spline); we allow 0.25 * h * dk
        # at each end of the link, here 0.7e-4 to 1.0e-4 rad.
        angle_tol = 0.25 * STEP_MM * (jumps[j] + jumps[j + 1])
        assert angle_tol <= 1.05e-4
        error = rotvec_from_rotation(expected[:3, :3].T @ transforms[j][:3, :3])
        assert np.linalg.norm(error) <= max(angle_tol, ROUND_TOL)
        # the translation length is frame-free: 1e-6 of the link length; its direction in {S} carries
        # {S}'s orientation error, hence the angle tolerance times the chord
        chord = np.linalg.norm(expected[:3, 3])
        np.testing.assert_allclose(np.linalg.norm(transforms[j][:3, 3]), chord, rtol=0, atol=1e-6 * length)
        np.testing.assert_allclose(transforms[j][:3, 3], expected[:3, 3], rtol=0,
                                   atol=1e-6 * length + max(angle_tol, ROUND_TOL) * chord)
        # the POE split of the arc: theta2 = kappa L about the binormal axis (-sin phi, cos phi, 0)
        split = poe_from_pose(transforms[j])
        np.testing.assert_allclose(split.theta2, kappa * length, rtol=0, atol=2 * angle_tol)
        np.testing.assert_allclose(
            split.omega, [-np.sin(phi), np.cos(phi), 0], rtol=0, atol=2 * angle_tol / (kappa * length)
        )
        np.testing.assert_allclose(pose_from_poe(split), transforms[j], rtol=0, atol=POE_TOL)


def test_frenet_link_transforms_show_phi_zero_on_every_arc(arcs_case):
    curve, _, _, breaks = arcs_case
    framed = framed_curve(curve, "frenet")
    total = curve.length
    # Frenet's normal is undefined at a joint (it jumps between bending planes); 0.1 mm (20 samples)
    # inside each arc the spline's disturbance from the joint has decayed to the level of the rest
    inset = 0.1
    for j, (kappa, _, length) in enumerate(ARCS):
        l_s, l_e = breaks[j] + inset / total, breaks[j + 1] - inset / total
        transform = link_transforms(framed, [l_s, l_e])[0]
        p = transform[:3, 3]
        np.testing.assert_allclose(np.arctan2(p[1], p[0]), 0.0, rtol=0, atol=1e-7)
        expected = seed_chain(kappa, 0.0, length - 2 * inset)
        np.testing.assert_allclose(p, expected[:3, 3], rtol=0, atol=1e-6 * length)
        # the Frenet normal comes from c'', one order less accurate than the tangent: 4e-8 measured
        np.testing.assert_allclose(transform[:3, :3], expected[:3, :3], rtol=0, atol=1e-7)


# --- POE split ----------------------------------------------------------------------------------------
def test_poe_split_round_trips_on_random_poses():
    rng = np.random.default_rng(17)
    for _ in range(100):
        twist = np.concatenate([rng.normal(scale=20, size=3), rng.normal(size=3)])
        twist[3:] *= rng.uniform(0, np.pi - 1e-3) / np.linalg.norm(twist[3:])
        pose = pose_from_twist(twist)
        np.testing.assert_allclose(pose_from_poe(poe_from_pose(pose)), pose, rtol=0, atol=POE_TOL)


@pytest.mark.parametrize("angle", [0.0, 1e-13, 1e-10, 1e-6, 0.5 * np.pi, np.pi - 1e-6, np.pi - 1e-9, np.pi])
def test_poe_split_near_singular_rotations(angle):
    rng = np.random.default_rng(int(angle * 1e6) % 1000)
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    pose = np.eye(4)
    pose[:3, :3] = rotation_from_rotvec(axis * angle)
    pose[:3, 3] = rng.normal(scale=10, size=3)
    split = poe_from_pose(pose)
    np.testing.assert_allclose(pose_from_poe(split), pose, rtol=0, atol=POE_TOL)
    np.testing.assert_allclose(split.theta1, np.linalg.norm(pose[:3, 3]), rtol=0, atol=ROUND_TOL)
    if angle < 1e-12:
        assert split.omega is None and split.theta2 == 0.0  # DESIGN.md: at theta2 = 0 the axis is null
        return
    np.testing.assert_allclose(split.theta2, angle, rtol=0, atol=1e-15 if angle < 1 else 1e-12)
    if angle == np.pi:  # axis and its opposite give the same rotation
        assert abs(abs(split.omega @ axis) - 1) < 1e-12
    else:
        np.testing.assert_allclose(split.omega, axis, rtol=0, atol=1e-6 if angle < 1e-9 else 1e-9)


def test_pure_translation_and_identity_splits():
    split = poe_from_pose(np.eye(4))
    assert split == PoeSplit(0.0, None, 0.0, None)
    np.testing.assert_array_equal(pose_from_poe(split), np.eye(4))
    moved = np.eye(4)
    moved[:3, 3] = [0, 3, 4]
    split = poe_from_pose(moved)
    assert split.theta1 == 5.0 and split.omega is None
    np.testing.assert_allclose(split.xi1, [0, 0.6, 0.8], rtol=0, atol=ROUND_TOL)


def test_poe_refuses_a_matrix_that_is_not_a_rotation():
    bad = np.eye(4)
    bad[0, 0] = -1.0
    with pytest.raises(GeometryError, match=r"orthonormal matrix with det \+1.*det = -1"):
        poe_from_pose(bad)


# --- links ---------------------------------------------------------------------------------------------
def test_link_break_rules():
    np.testing.assert_allclose(link_breaks(100.0, count=4), [0, 0.25, 0.5, 0.75, 1], rtol=0, atol=0)
    np.testing.assert_array_equal(link_breaks(100.0, breaks=[0, 0.3, 1]), [0, 0.3, 1])
    # 30 mm links on 100 mm: a 10 mm remainder (< half a link) joins the last link
    np.testing.assert_allclose(link_breaks(100.0, length_mm=30.0), [0, 0.3, 0.6, 1], rtol=0, atol=ROUND_TOL)
    # 40 mm links on 100 mm: a 20 mm remainder (half a link) is its own link
    np.testing.assert_allclose(link_breaks(100.0, length_mm=40.0), [0, 0.4, 0.8, 1], rtol=0, atol=ROUND_TOL)
    np.testing.assert_allclose(link_breaks(100.0, length_mm=150.0), [0, 1], rtol=0, atol=0)


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({}, "exactly one of count, breaks, length_mm"),
        ({"count": 2, "length_mm": 3.0}, "exactly one"),
        ({"count": 0}, "links.count must be an integer >= 1, got 0"),
        ({"breaks": [0.1, 1]}, "start at 0 and end at 1"),
        ({"breaks": [0, 0.5, 0.4, 1]}, "strictly increasing"),
        ({"length_mm": -2.0}, "links.length_mm must be > 0 mm, got -2"),
        ({"count": 5000}, "shortest link spans"),
    ],
)
def test_link_break_errors(kwargs, words):
    with pytest.raises(ConfigError, match=words):
        link_breaks(100.0, **kwargs)


@pytest.fixture(scope="module")
def chain():
    final = arc_initial_shape(
        smooth_curve_from_polyline(np.column_stack([np.zeros(50), np.zeros(50), np.linspace(0, 60, 50)]),
                                   CurveOptions(count=121, smoothing_mm=0.0)),
        bend_radius_mm=25.0, bend_plane_rad=0.7,
    )
    shape = blend_shapes(straight_initial_shape(final), final, mode="linear", frames="rmf")
    return LinkChain(shape, link_breaks(final.length, count=3))


def test_forward_kinematics_with_one_q_telescopes_to_the_end_frames(chain):
    for q in (0.0, 0.4, 1.0):
        curve = chain.shape.curve_at(q)
        ends = curve.poses([0.0, 1.0])
        np.testing.assert_allclose(chain.tip2base(q), inverse_pose(ends[0]) @ ends[1], rtol=0, atol=1e-12)
        np.testing.assert_allclose(chain.tip2world(q), ends[1], rtol=0, atol=1e-12)


def test_forward_kinematics_with_one_q_per_link(chain):
    q = np.array([0.2, 0.8, 1.0])
    links = chain.transforms(q)
    for j in range(3):
        own = link_transforms(chain.shape.curve_at(q[j]), chain.breaks[j : j + 2])[0]
        np.testing.assert_allclose(links[j], own, rtol=0, atol=0)
    np.testing.assert_allclose(chain.tip2base(q), links[0] @ links[1] @ links[2], rtol=0, atol=ROUND_TOL)
    # the base is registered: F(q, 0) is the same for every q, so tip2world only prepends it
    np.testing.assert_allclose(chain.base2world(q), chain.base2world(0.0), rtol=0, atol=ROUND_TOL)
    # changing the last link's q leaves the first two links alone
    np.testing.assert_array_equal(chain.transforms([0.2, 0.8, 0.0])[:2], links[:2])
    with pytest.raises(ConfigError, match="one value or 3 values"):
        chain.transforms([0.2, 0.8])


def test_one_q_for_every_link_gives_each_links_own_numbers_bit_for_bit(chain):
    # one q: the links' transforms and stats in one call each, the same numbers as link by link
    for q in (0.0, 0.4, 1.0):
        curve = chain.shape.curve_at(q)
        own = [link_transforms(curve, chain.breaks[j : j + 2])[0] for j in range(3)]
        np.testing.assert_array_equal(chain.transforms(q), np.array(own))
        stats = [chain.shape.stats_at(q, (float(chain.breaks[j]), float(chain.breaks[j + 1]))) for j in range(3)]
        assert [r.stats for r in chain.reports(q)] == stats


def test_link_reports_carry_poe_and_lengths(chain):
    reports = chain.reports(1.0)
    assert [r.index for r in reports] == [0, 1, 2]
    np.testing.assert_allclose(sum(r.length_mm for r in reports), chain.shape.keys[-1].length, rtol=0, atol=1e-9)
    for report in reports:
        # each link of a circular arc of radius 25: theta2 = length / radius, chord 2 R sin(theta2 / 2);
        # the quintic through samples every 0.5 mm carries ~1e-8 mm of interpolation error
        np.testing.assert_allclose(report.poe.theta2, report.length_mm / 25.0, rtol=0, atol=1e-8)
        np.testing.assert_allclose(report.poe.theta1, 50.0 * np.sin(report.poe.theta2 / 2), rtol=0, atol=1e-7)
        np.testing.assert_allclose(report.stats.curvature_max_per_mm, 1 / 25.0, rtol=1e-6, atol=0)


def test_straight_initial_shape_at_q0_works_in_rmf_and_fails_clearly_in_frenet(chain):
    straight = chain.shape.curve_at(0.0)
    transforms = LinkChain(chain.shape, chain.breaks).transforms(0.0)
    third = straight.length / 3
    for transform in transforms:
        expected = np.eye(4)
        expected[2, 3] = third
        np.testing.assert_allclose(transform, expected, rtol=0, atol=1e-9)
    frenet = blend_shapes(chain.shape.keys[0], chain.shape.keys[-1], frames="frenet")
    LinkChain(frenet, chain.breaks).transforms(1.0)  # the arc has curvature everywhere
    with pytest.raises(GeometryError) as caught:
        LinkChain(frenet, chain.breaks).transforms(0.0)
    message = str(caught.value)
    assert "frenet, q = 0" in message and "l in [0.0000, 1.0000]" in message and "use frames: rmf" in message


# --- exact joints: a break at a curvature jump is a knot the smoothing does not cross (issue 35 item 4) -------
#: The issue's bound at every joint, for the link transforms (D-H / POE) and the frames in the world.
JOINT_ANGLE_TOL = 1e-4  # rad
JOINT_MM_TOL = 1e-4
#: Arcs of different planes, one straight, at the project's default sample spacing (100 x the test above's).
JOINT_ARCS = ((0.05, 0.4, 20.0), (0.0, 0.0, 12.5), (0.07, 2.0, 15.0), (0.03, -1.5, 22.5))
JOINT_SPACING_MM = 0.5


def _section(kappa: float, phi: float, length: float) -> np.ndarray:
    """Seed 003's section transform; a straight one (kappa = 0, where its chord formula divides by zero) is Tz(L)."""
    return seed_chain(kappa, phi, length) if kappa > 0.0 else trans_z(length)


def _joint_case(joints: bool):
    """Framed curve of the arcs' vertices (every joint a vertex), resampled with or without joints; the poses."""
    rng = np.random.default_rng(35)
    base = np.eye(4)
    base[:3, :3] = rotation_from_rotvec(rng.normal(size=3))
    base[:3, 3] = rng.normal(scale=50, size=3)
    pose, points, poses = base, [], [base]
    for kappa, phi, length in JOINT_ARCS:
        for si in np.arange(0.0, length - 1e-9, JOINT_SPACING_MM):
            points.append((pose @ _section(kappa, phi, si))[:3, 3] if si > 0 else pose[:3, 3])
        pose = pose @ _section(kappa, phi, length)
        poses.append(pose)
    points.append(pose[:3, 3])
    breaks = np.concatenate([[0.0], np.cumsum([a[2] for a in JOINT_ARCS])]) / sum(a[2] for a in JOINT_ARCS)
    options = CurveOptions(spacing_mm=JOINT_SPACING_MM, smoothing_mm=0.0, end_straight_mm=0.0)
    curve = smooth_curve_from_polyline(np.array(points), options, breaks if joints else ())
    return framed_curve(curve, "rmf", base_normal=base[:3, 0]), breaks, np.array(poses)


def _errors(framed, breaks, poses):
    """Largest angle (rad) and distance (mm) of each link's S_T_E and each joint's world frame from the chain."""
    transforms, world = link_transforms(framed, breaks), framed.poses(breaks)
    angles, distances = [], []
    for j in range(len(JOINT_ARCS)):
        expected = inverse_pose(poses[j]) @ poses[j + 1]
        angles.append(np.linalg.norm(rotvec_from_rotation(expected[:3, :3].T @ transforms[j][:3, :3])))
        distances.append(np.linalg.norm(transforms[j][:3, 3] - expected[:3, 3]))
    for j in range(len(poses)):
        angles.append(np.linalg.norm(rotvec_from_rotation(poses[j][:3, :3].T @ world[j][:3, :3])))
        distances.append(np.linalg.norm(world[j][:3, 3] - poses[j][:3, 3]))
    return max(angles), max(distances)


def test_breaks_at_the_joints_keep_every_joint_exact():
    framed, breaks, poses = _joint_case(joints=True)
    assert framed.curve.joints == (40, 65, 95)  # 20, 32.5 and 47.5 mm of 70 at 0.5 mm
    angle, distance = _errors(framed, breaks, poses)
    assert angle <= JOINT_ANGLE_TOL and distance <= JOINT_MM_TOL, (angle, distance)
    # and the POE split of each link is its arc: theta2 = kappa L (the straight link: no rotation)
    for transform, (kappa, _, length) in zip(link_transforms(framed, breaks), JOINT_ARCS, strict=True):
        assert abs(poe_from_pose(transform).theta2 - kappa * length) <= JOINT_ANGLE_TOL


def test_without_joints_the_smoothing_rounds_the_corners():
    # the starting point (1.9e-3 rad on its centerline): the quintic through every sample crosses the jumps
    angle, _ = _joint_case_errors(joints=False)
    assert angle > 10 * JOINT_ANGLE_TOL


def _joint_case_errors(joints: bool):
    framed, breaks, poses = _joint_case(joints)
    return _errors(framed, breaks, poses)
