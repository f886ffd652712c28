"""Path facts and the main-vessel rule (issue 43 item 1): known lumens, where a branch leaves, big trees."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.geometry.path_survey import MAX_PAIRWISE_PATHS, PathFacts, lumen_integral, main_path, survey_paths
from tests.helpers.robust_vessels import segment
from tests.helpers.trees import LEAVE_TOL_MM


def test_the_rule_on_known_lumens():
    """Lumen integral of a constant tube is r^2 L; the wider-longer path wins; without radii the longest."""
    line = segment(np.zeros(3), np.array([0.0, 0.0, 40.0]), 0.5)
    np.testing.assert_allclose(lumen_integral(line, np.full(len(line), 3.0)), 9.0 * 40.0, rtol=1e-12, atol=0)
    trunk = segment(np.zeros(3), np.array([0.0, 0.0, 100.0]), 0.5)
    branch = np.concatenate([trunk[:21], segment(trunk[20], trunk[20] + [150.0, 0.0, 0.0], 0.5)])
    paths = [(0, branch, np.r_[np.full(21, 10.0), np.full(len(branch) - 21, 2.0)]),  # thin and long
             (1, trunk, np.full(len(trunk), 10.0))]  # wide
    facts = survey_paths(paths)
    assert main_path(facts) == 1  # 100 x 100 = 10,000 against 100 x 10 + 4 x 150 = 1,600
    assert facts[0].leaves is not None and facts[0].leaves[0] == 1
    np.testing.assert_allclose(facts[0].leaves[1], 10.0, rtol=0, atol=LEAVE_TOL_MM)
    assert [f.opening for f in facts] == [1, 2]
    bare = survey_paths([(k, p, None) for k, p, _ in paths])
    assert main_path(bare) == 0 and all(f.lumen is None for f in bare)  # 170 mm against 100 mm
    single = survey_paths([(0, trunk, None)])
    assert single[0].leaves is None and main_path(single) == 0


@pytest.mark.parametrize("count", [MAX_PAIRWISE_PATHS + 6])
def test_a_big_tree_is_measured_against_the_main_vessel(count):
    """More than MAX_PAIRWISE_PATHS paths: each is measured against the main vessel only, still correctly."""
    trunk = segment(np.zeros(3), np.array([0.0, 0.0, 200.0]), 0.5)
    paths = [(0, trunk, np.full(len(trunk), 8.0))]
    for k in range(1, count):
        at = int(2 * 2.5 * k) % 380 + 10
        limb = segment(trunk[at], trunk[at] + 20.0 * np.array([np.cos(k), np.sin(k), 0.0]), 0.5)[1:]
        paths.append((k, np.concatenate([trunk[:at + 1], limb]), np.r_[np.full(at + 1, 8.0), np.full(len(limb), 1.0)]))
    facts = survey_paths(paths)
    assert main_path(facts) == 0
    for (k, _, _), f in zip(paths[1:], facts[1:], strict=True):
        assert isinstance(f, PathFacts) and f.leaves is not None and f.leaves[0] == 0
        at = (int(2 * 2.5 * k) % 380 + 10) * 0.5
        np.testing.assert_allclose(f.leaves[1], at, rtol=0, atol=LEAVE_TOL_MM)


def test_the_nearest_vertex_is_the_same_found_directly_or_by_the_kd_tree():
    from softdesign.geometry.path_survey import DIRECT_PAIRS, nearest_vertex_of

    rng = np.random.default_rng(7)
    polyline, points = rng.normal(size=(300, 3)), rng.normal(size=(5000, 3))
    direct = nearest_vertex_of(polyline, 10)(points)  # few queries: direct distances
    tree = nearest_vertex_of(polyline, DIRECT_PAIRS)(points)  # DIRECT_PAIRS x 300 pairs: the KD-tree
    np.testing.assert_array_equal(direct, tree)
