"""Link design (issue 14): the fewest constant-curvature arcs within a tolerance of a centerline.

Known answers first (an exact arc is fitted exactly; the point-to-arc distance
against a dense arc), then the issue's: a centerline made of k known arcs
gives k links and those arcs; the dynamic programme equals a brute-force
search; a smaller tolerance never gives fewer links.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from softdesign.errors import ConfigError
from softdesign.geometry.curves import smooth_curve_from_samples
from softdesign.geometry.frames import framed_curve
from softdesign.geometry.se3 import rotation_from_rotvec
from softdesign.kinematics import pcc
from softdesign.kinematics.arc_design import (
    MAX_SAMPLES,
    DesignOptions,
    best_within,
    curvature_vectors,
    design_links,
    distances_to_arcs,
    fewest_links,
    fit_link,
    link_costs,
)

#: An exact arc's samples give back its arc: rounding of sums of O(L^4) terms.
EXACT_KAPPA_TOL = 1e-10  # 1/mm
EXACT_ANGLE_TOL = 1e-8  # rad
EXACT_MM_TOL = 1e-8

# -- a centerline made of known arcs (seed 003's chain), a straight piece among them ------------------------
#: (kappa 1/mm, phi rad, L mm): different curvatures and bending planes; lengths multiples of SPACING_MM,
#: so every joint is a sample.
ARCS = ((0.05, 0.4, 20.0), (0.0, 0.0, 12.5), (0.07, 2.0, 15.0), (0.03, -1.5, 22.5))
SPACING_MM = 0.5
#: Tolerance of the design: far above the spline's error near a joint, far below a missed joint's error.
ARCS_TOLERANCE_MM = 0.05
#: The quintic spline through the samples cannot follow a curvature jump: its frames near a joint are off by
#: ~0.25 h dk (tests/kinematics/test_pcc_design.py), and a break may land one sample past a joint, so a link
#: may carry one spacing of its neighbour.  Both bend a link's fitted arc by at most these:
ARCS_KAPPA_TOL = 0.003  # 1/mm: one spacing of the neighbour's curvature over a 15 mm link, ~ h dk / L * 2
ARCS_PHI_TOL = 0.02  # rad: the frame error at a joint, 0.25 h dk <= 0.01, doubled
ARCS_LENGTH_TOL_MM = SPACING_MM + 0.01  # one spacing (a break one sample off) plus the fit's end


def arcs_centerline(arcs=ARCS, spacing=SPACING_MM):
    """Samples (n, 3), rmf frames (n, 3, 3) and arc length (n,) of the chained arcs, through the project's curve tools.

    The chain starts at the identity pose and the rmf base normal is x, so every link's phi is comparable with
    the arcs' (both frames are carried without twist).
    """
    pose, points = np.eye(4), []
    for kappa, phi, length in arcs:
        s = np.arange(0.0, length - 1e-9, spacing)
        points.append((pose @ pcc.transform_from_arc(kappa, phi, s))[:, :3, 3])
        pose = pose @ pcc.transform_from_arc(kappa, phi, length)
    curve = smooth_curve_from_samples(np.concatenate(points + [pose[None, :3, 3]]))
    framed = framed_curve(curve, "rmf", base_normal=[1.0, 0.0, 0.0])
    l = curve.l_grid
    return framed.points(l), framed.frames(l), curve.arc_length(l)


def random_centerline(rng: np.random.Generator, n: int, step: float = 2.0):
    """A short smooth random curve: n samples of a random walk of the curvature vector."""
    kappa_vectors = np.cumsum(rng.normal(scale=0.03, size=(n, 2)), axis=0)
    arcs = [(float(np.hypot(*k)), float(np.arctan2(k[1], k[0])), step) for k in kappa_vectors[:-1]]
    return arcs_centerline(arcs, spacing=step / 4)


# -- one arc -------------------------------------------------------------------------------------------
@pytest.mark.parametrize("phi", [0.3, 2.0, -2.5, math.pi])
@pytest.mark.parametrize("kappa", [0.0, 1e-7, 0.02, 0.15])
def test_an_exact_arc_in_any_frame_is_fitted_exactly(kappa, phi):
    length = 30.0
    s = np.linspace(0.0, length, 61)
    base = np.eye(4)
    base[:3, :3] = rotation_from_rotvec([0.3, -1.2, 0.5])
    base[:3, 3] = [5.0, 1.0, -4.0]
    poses = base @ pcc.transform_from_arc(kappa, phi, s)
    link = fit_link(poses[:, :3, 3], poses[:, :3, :3], s, 0, len(s) - 1)
    np.testing.assert_allclose(link.kappa, kappa, rtol=0, atol=EXACT_KAPPA_TOL)
    np.testing.assert_allclose(link.length, length, rtol=0, atol=EXACT_MM_TOL)
    np.testing.assert_allclose(link.max_deviation_mm, 0.0, rtol=0, atol=EXACT_MM_TOL)
    if kappa * length > 1e-6:  # below, the bending plane is not observable to rounding
        np.testing.assert_allclose(math.remainder(link.phi - phi, 2 * math.pi), 0.0, rtol=0, atol=EXACT_ANGLE_TOL)
    if kappa == 0.0:
        assert (link.kappa, link.phi, link.theta) == (0.0, 0.0, 0.0)


def test_the_curvature_vector_of_every_prefix_is_the_arcs():
    kappa, phi = 0.04, -0.8
    local = pcc.tip_position_from_arc(kappa, phi, np.linspace(0.0, 50.0, 101))
    w = curvature_vectors(local)
    np.testing.assert_allclose(w[1:], np.tile(kappa * np.array([np.cos(phi), np.sin(phi)]), (100, 1)),
                               rtol=0, atol=EXACT_KAPPA_TOL)


@pytest.mark.parametrize("kappa, length", [(0.0, 20.0), (0.05, 30.0), (0.05, 100.0), (0.2, 25.0)])
def test_point_to_arc_distance_is_the_distance_to_a_dense_arc(kappa, length):
    # (0.05, 100): theta = 5 rad, more than half a turn; (0.2, 25): theta = 5 rad on a small circle
    rng = np.random.default_rng(7)
    phi = 0.7
    points = rng.uniform(-40.0, 40.0, size=(400, 3)) + [0.0, 0.0, 15.0]
    dense = pcc.tip_position_from_arc(kappa, phi, np.linspace(0.0, length, 200001))
    from scipy.spatial import cKDTree

    nearest, _ = cKDTree(dense).query(points)
    got = distances_to_arcs(points, np.array([[kappa * math.cos(phi), kappa * math.sin(phi)]]), np.array([length]))[0]
    # the dense arc's step is length / 2e5 <= 5e-4 mm: the nearest dense point is at most half a step further
    step = length / 200000
    assert np.all(got <= nearest + 1e-12) and np.all(nearest - got <= 0.5 * step + 1e-12)


def test_vectorised_costs_are_the_single_link_fits():
    points, frames, s = random_centerline(np.random.default_rng(3), 12)
    cost = link_costs(points, frames, s, min_link_mm=1.0)
    for i, j in itertools.combinations(range(len(s)), 2):
        if s[j] - s[i] >= 1.0:
            assert cost[i, j] == pytest.approx(fit_link(points, frames, s, i, j).max_deviation_mm, abs=1e-12)
        else:
            assert cost[i, j] == np.inf
    assert np.all(np.isinf(np.tril(cost)[np.tril_indices(len(s))]))


# -- the known answers ----------------------------------------------------------------------------
def test_a_centerline_of_k_known_arcs_gives_k_links_and_their_arcs():
    points, frames, s = arcs_centerline()
    design = design_links(points, frames, s, DesignOptions(ARCS_TOLERANCE_MM, min_link_mm=5.0, max_links=20))
    assert design.meets_tolerance and len(design.links) == len(ARCS)
    joints = np.cumsum([length for _, _, length in ARCS])[:-1]
    np.testing.assert_allclose(s[design.break_indices[1:-1]], joints, rtol=0, atol=SPACING_MM + 1e-6)
    for link, (kappa, phi, length) in zip(design.links, ARCS, strict=True):
        assert link.max_deviation_mm <= ARCS_TOLERANCE_MM
        np.testing.assert_allclose(link.kappa, kappa, rtol=0, atol=ARCS_KAPPA_TOL)
        np.testing.assert_allclose(link.length, length, rtol=0, atol=ARCS_LENGTH_TOL_MM)
        if kappa > 0.0:
            np.testing.assert_allclose(math.remainder(link.phi - phi, 2 * math.pi), 0.0, rtol=0, atol=ARCS_PHI_TOL)


def test_arcs_fitted_at_the_true_joints_chain_to_the_centerlines_tip():
    from softdesign.kinematics.arc_design import chain_tip_error

    points, frames, s = arcs_centerline()
    joints = np.concatenate([[0.0], np.cumsum([length for _, _, length in ARCS])])
    idx = [int(np.argmin(np.abs(s - j))) for j in joints]
    links = tuple(fit_link(points, frames, s, i, j) for i, j in zip(idx[:-1], idx[1:], strict=True))
    tip_mm, tip_rad = chain_tip_error(links, frames, points)
    # the spline's frame error at each joint (<= 0.25 h dk ~ 0.01 rad) tilts what follows: < 0.05 rad, < 1 mm
    assert tip_rad < 0.05 and tip_mm < 1.0
    exact = pcc.chain_transforms(pcc.transform_from_arc(*np.array(ARCS).T))[-1]
    # the helper's chain is seed 003's
    np.testing.assert_allclose(exact[:3, 3], points[-1] - points[0], rtol=0, atol=1e-6)


def brute_force(cost: np.ndarray, tolerance: float, max_links: int | None = None) -> tuple[int, float] | None:
    """(links, worst cost) of the best segmentation by enumeration: fewest within tolerance, then smallest worst;
    with max_links (and no tolerance), the smallest worst among at most max_links links."""
    n = len(cost)
    best = None
    for r in range(n - 1):
        for inner in itertools.combinations(range(1, n - 1), r):
            breaks = (0, *inner, n - 1)
            worst = max(cost[i, j] for i, j in zip(breaks[:-1], breaks[1:], strict=True))
            if max_links is None and worst > tolerance or max_links is not None and len(breaks) - 1 > max_links:
                continue
            key = (len(breaks) - 1, worst) if max_links is None else (worst, len(breaks) - 1)
            if np.isfinite(worst) and (best is None or key < best):
                best = key
    if best is None:
        return None
    return best if max_links is None else (best[1], best[0])


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_the_dynamic_programme_equals_brute_force(seed):
    points, frames, s = random_centerline(np.random.default_rng(seed), 4)  # 13 samples: 2^11 segmentations
    cost = link_costs(points, frames, s, min_link_mm=1.0)
    # every 4th distinct link cost as the tolerance: ties with a link's cost (cost <= T) and every count
    for tolerance in np.unique(cost[np.isfinite(cost)])[::4]:
        expected = brute_force(cost, float(tolerance))
        found = fewest_links(cost, float(tolerance))
        if expected is None:
            assert found is None
            continue
        worst = max(cost[i, j] for i, j in zip(found[:-1], found[1:], strict=True))
        assert (len(found) - 1, worst) == expected
    for max_links in (1, 2, 3):
        expected = brute_force(cost, np.inf, max_links)
        found = best_within(cost, max_links)
        worst = max(cost[i, j] for i, j in zip(found[:-1], found[1:], strict=True))
        assert (len(found) - 1, worst) == expected


def test_a_smaller_tolerance_never_gives_fewer_links():
    points, frames, s = random_centerline(np.random.default_rng(11), 30)
    counts = []
    for tolerance in (2.0, 1.0, 0.5, 0.2, 0.1, 0.05, 0.02):
        design = design_links(points, frames, s, DesignOptions(tolerance, min_link_mm=1.0, max_links=200))
        assert design.meets_tolerance and design.worst_mm <= tolerance
        counts.append(len(design.links))
    assert counts == sorted(counts) and counts[0] < counts[-1]


def test_without_a_segmentation_in_max_links_the_best_within_it_is_returned():
    points, frames, s = arcs_centerline()
    design = design_links(points, frames, s, DesignOptions(ARCS_TOLERANCE_MM, min_link_mm=5.0, max_links=2))
    assert not design.meets_tolerance and len(design.links) <= 2
    cost = link_costs(points, frames, s, 5.0)
    assert design.worst_mm == pytest.approx(min(max(cost[0, j], cost[j, -1]) for j in range(1, len(s) - 1)), abs=1e-12)
    assert design.worst_mm > ARCS_TOLERANCE_MM


def test_bad_options_and_sizes_are_refused_before_work():
    points, frames, s = arcs_centerline()
    for options, match in [
        (DesignOptions(0.0, 5.0, 4), "tolerance-mm must be a finite number > 0"),
        (DesignOptions(math.nan, 5.0, 4), "tolerance-mm"),
        (DesignOptions(0.1, -1.0, 4), "min-link-mm must be"),
        (DesignOptions(0.1, 500.0, 4), "longer than the centerline"),
        (DesignOptions(0.1, 5.0, 0), "max-links must be an integer >= 1"),
    ]:
        with pytest.raises(ConfigError, match=match):
            design_links(points, frames, s, options)
    n = MAX_SAMPLES + 1
    big = np.column_stack([np.zeros(n), np.zeros(n), np.arange(n, dtype=float)])
    with pytest.raises(ConfigError, match=f"at most {MAX_SAMPLES}"):
        design_links(big, np.broadcast_to(np.eye(3), (n, 3, 3)), big[:, 2], DesignOptions(0.1, 5.0, 4))
