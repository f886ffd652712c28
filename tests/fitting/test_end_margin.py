"""fit.end_margin_mm: wall points within the margin of either end are left out, the end held at the inscribed radius."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.fitting.wall_fit import WallFitOptions, fit_wall
from tests.fitting.test_end_prior import R, vessel

#: The ring at an end inside the margin against R: the prior pins its empty cells to R (measured within 1e-6).
HELD_RTOL = 0.01


def test_a_margin_leaves_the_end_points_out_and_holds_both_end_rings_at_the_inscribed_radius():
    curve, vertices, network = vessel(one_sided=True)  # its inlet's rim leans inwards to 0.6 R
    plain = fit_wall(curve, vertices, network, WallFitOptions(), np.random.default_rng(0))
    margin = 6.0
    fit = fit_wall(curve, vertices, network, WallFitOptions(end_margin_mm=margin), np.random.default_rng(0))
    dropped = fit.ends["margin"]
    assert dropped["mm"] == margin and dropped["points"] > 0
    assert fit.surface.point_count == plain.surface.point_count - dropped["points"]
    ring = fit.field.evaluate_grid(1.0, np.array([0.0, 1.0]), np.linspace(0.0, 2 * np.pi, 48, endpoint=False))
    assert ring == pytest.approx(np.full_like(ring, R), rel=HELD_RTOL)
    assert {"inlet", "outlet"} <= set(fit.summary()["end_prior"])


def test_no_margin_is_the_plain_fit():
    curve, vertices, network = vessel(one_sided=False)
    plain = fit_wall(curve, vertices, network, WallFitOptions(), np.random.default_rng(0))
    zero = fit_wall(curve, vertices, network, WallFitOptions(end_margin_mm=0.0), np.random.default_rng(0))
    np.testing.assert_array_equal(plain.surface.whole.coefficients, zero.surface.whole.coefficients)
    assert zero.ends["margin"]["points"] == 0
