"""The composed-chain design on known answers: k known arcs, a U-turn, monotone in the tolerance (issue 30)."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import ConfigError
from softdesign.geometry.curves import smooth_curve_from_samples
from softdesign.geometry.se3 import rotation_from_rotvec
from softdesign.kinematics import pcc
from softdesign.kinematics.chain_design import ChainOptions, ChainTarget, design_chain
from softdesign.kinematics.pcc_chain import arcs_from_w, chain_points_at, section_poses
from softdesign.pipeline.stages.design import chain_target

#: Issue 30's known-answer bounds.
BREAK_TOL_MM = 0.2
KAPPA_RTOL = 0.005
PHI_TOL_DEG = 0.5
CHAIN_TOL_MM = 0.01
#: The design's tolerance on exact arcs: far below what k - 1 sections can reach, far above round-off.
T_EXACT_MM = 0.05


def known_chain_target(kappa, phi, length, base2world, spacing_mm=0.5) -> ChainTarget:
    """Samples, frames and a dense polyline of an exact chain of arcs (its frames are the chain's own)."""
    kappa, phi, length = (np.asarray(x, float) for x in (kappa, phi, length))
    w = np.stack([kappa * np.cos(phi), kappa * np.sin(phi)], axis=1)
    total = float(length.sum())
    s = np.linspace(0.0, total, int(round(total / spacing_mm)) + 1)
    bases, _ = section_poses(base2world, w, length)
    starts = np.concatenate([[0.0], np.cumsum(length)[:-1]])
    section = np.clip(np.searchsorted(starts, s, side="right") - 1, 0, len(length) - 1)
    local = pcc.transform_from_arc(kappa[section], phi[section], s - starts[section])
    frames = (bases[section] @ local)[:, :3, :3]
    dense = chain_points_at(base2world, w, length, np.linspace(0.0, total, int(round(total / 0.02)) + 1))
    return ChainTarget(chain_points_at(base2world, w, length, s), frames, s, dense)


def tilted_base() -> np.ndarray:
    base = np.eye(4)
    base[:3, :3] = rotation_from_rotvec([0.4, -0.7, 1.1])  # no axis of it along a world axis
    base[:3, 3] = [10.0, -5.0, 3.0]
    return base


def options(tolerance_mm: float, min_link_mm: float = 5.0, max_links: int = 10) -> ChainOptions:
    return ChainOptions(tolerance_mm, tolerance_mm, None, min_link_mm, max_links)


def test_k_known_arcs_give_k_sections_on_their_joints_and_arcs():
    kappa = np.array([0.05, 0.0, 0.08, 0.03])  # a straight piece among them
    phi = np.array([0.3, 0.0, 2.0, -1.2])  # each in its own bending plane
    length = np.array([25.0, 12.0, 20.0, 30.0])
    target = known_chain_target(kappa, phi, length, tilted_base())
    design = design_chain(target, options(T_EXACT_MM))
    assert design.meets and len(design.length) == 4
    total = length.sum()
    np.testing.assert_allclose(design.breaks * total, np.concatenate([[0.0], np.cumsum(length)]), rtol=0,
                               atol=BREAK_TOL_MM)
    found_kappa, found_phi = arcs_from_w(design.w)
    bent = kappa > 0.0
    np.testing.assert_allclose(found_kappa[bent], kappa[bent], rtol=KAPPA_RTOL, atol=0)
    assert found_kappa[~bent].max() * length[~bent].max() < 1e-6  # the straight piece: no bend to speak of
    np.testing.assert_allclose(np.degrees(found_phi[bent]), np.degrees(phi[bent]), rtol=0, atol=PHI_TOL_DEG)
    assert design.chain_max_deviation_mm <= CHAIN_TOL_MM and design.tip_error_mm <= CHAIN_TOL_MM
    assert [k for k, _ in design.tried] == [1, 2, 3, 4] and all(w > T_EXACT_MM for _, w in design.tried[:-1])


def test_a_u_turn_longer_than_pi_is_one_section():
    target = known_chain_target([0.1], [0.7], [40.0], tilted_base())  # theta = 4 rad
    design = design_chain(target, options(T_EXACT_MM))
    assert design.meets and len(design.length) == 1
    found_kappa, found_phi = arcs_from_w(design.w)
    np.testing.assert_allclose([found_kappa[0], found_phi[0], design.length[0]], [0.1, 0.7, 40.0], rtol=1e-4, atol=0)
    assert design.chain_max_deviation_mm <= CHAIN_TOL_MM


def test_a_straight_line_is_one_straight_section():
    target = known_chain_target([0.0], [0.0], [30.0], tilted_base())
    design = design_chain(target, options(T_EXACT_MM))
    assert len(design.length) == 1 and np.hypot(*design.w[0]) * 30.0 < 1e-9
    assert design.chain_max_deviation_mm <= 1e-9 and design.tip_error_deg <= 1e-6


def helix_target() -> ChainTarget:
    """A helix (constant curvature and torsion): no chain of arcs is exact, so the count grows as T falls."""
    t = np.linspace(0.0, 3.0 * np.pi, 241)
    curve = smooth_curve_from_samples(np.stack([20.0 * np.cos(t), 20.0 * np.sin(t), 8.0 * t], axis=1))
    resampled = smooth_curve_from_samples(curve.points(np.linspace(0.0, 1.0, 301)))
    return chain_target(resampled)


@pytest.mark.slow
def test_a_smaller_tolerance_never_gives_fewer_sections():
    target = helix_target()
    counts = []
    for tolerance in (2.0, 1.0, 0.5, 0.25):
        design = design_chain(target, options(tolerance, max_links=20))
        assert design.meets, tolerance
        assert design.chain_max_deviation_mm <= tolerance and design.tip_error_mm <= tolerance
        counts.append(len(design.length))
    assert counts == sorted(counts) and counts[-1] > counts[0]


def test_a_tip_angle_bound_is_met_or_reported():
    target = helix_target()
    loose = design_chain(target, options(2.0, max_links=20))
    bounded = design_chain(target, ChainOptions(2.0, 2.0, 0.5 * loose.tip_error_deg, 5.0, 20))
    assert bounded.meets and bounded.tip_error_deg <= 0.5 * loose.tip_error_deg
    assert len(bounded.length) > len(loose.length)  # the angle bound, not the distance, asked for more sections


def test_none_within_max_links_returns_the_best_found_and_says_so():
    kappa, phi, length = [0.05, 0.08, 0.03], [0.3, 2.0, -1.2], [25.0, 20.0, 30.0]
    design = design_chain(known_chain_target(kappa, phi, length, tilted_base()), options(T_EXACT_MM, max_links=2))
    assert not design.meets and len(design.length) <= 2
    assert design.worst_mm == min(w for _, w in design.tried)


@pytest.mark.parametrize("change, message", [
    ({"tolerance_mm": 0.0}, "tolerance_mm must be a finite number > 0"),
    ({"min_link_mm": 500.0}, "longer than the centerline"),
    ({"max_links": 0}, "max_links must be an integer >= 1"),
    ({"tip_tolerance_deg": -1.0}, "tip_tolerance_deg must be a finite number > 0"),
])
def test_bad_options_are_refused_with_the_fix(change, message):
    target = known_chain_target([0.05], [0.0], [30.0], np.eye(4))
    values = {"tolerance_mm": 1.0, "tip_tolerance_mm": 1.0, "tip_tolerance_deg": None, "min_link_mm": 5.0,
              "max_links": 4, **change}
    with pytest.raises(ConfigError, match=message):
        design_chain(target, ChainOptions(**values))
