"""An end whose fitted radius goes to zero or below is held at the inscribed radius and fitted again (issue 29)."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.fitting import wall_fit
from softdesign.fitting.bspline_surface import FitSettings, fit_radius_surface
from softdesign.fitting.end_hold import MAX_HOLD_FRACTION, negative_end
from softdesign.fitting.end_prior import EndPrior, end_prior
from softdesign.fitting.projection import project_points
from softdesign.fitting.selection import select_wall_points
from tests.fitting.test_end_prior import LENGTH, R, vessel


def _without_prior_first(monkeypatch) -> list[int]:
    """The end prior gives nothing on its first call (as where it does not catch a one-sided end), then as it is."""
    calls: list[int] = []

    def prior(kept, *args, **kwargs) -> EndPrior:
        calls.append(len(kept))
        found = end_prior(kept, *args, **kwargs)
        return EndPrior(*(np.zeros(0) for _ in range(4)), {}) if len(calls) == 1 else found

    monkeypatch.setattr(wall_fit, "end_prior", prior)
    return calls


def test_negative_end_finds_the_end_and_the_stretch_to_hold():
    curve, vertices, network = vessel()
    polar = project_points(curve, vertices)
    kept = polar.subset(np.flatnonzero(select_wall_points(polar, curve.length, network).keep))
    plain = fit_radius_surface(kept, curve.length, FitSettings())
    hold = negative_end(plain.whole, curve.length, 1.5)
    assert hold is not None and hold.end == "inlet" and hold.from_l == 0.0 and hold.rho_min_mm <= 0.0
    # one knot interval past the last thin ring, within the path's first quarter, past the first wall ring (z = 3)
    assert hold.at_l * LENGTH < hold.to_l * LENGTH - 1.5 + 1e-9 and hold.to_l <= MAX_HOLD_FRACTION
    assert hold.to_l * LENGTH > 3.0
    assert not hold.keeps(kept.l[kept.l <= hold.to_l]).any() and hold.keeps(kept.l[kept.l > hold.to_l]).all()
    prior = end_prior(kept, curve.length, 1.5, 24, (network.inscribed_l, network.inscribed_radius))
    with_prior = fit_radius_surface(kept, curve.length, FitSettings(prior=prior))
    assert negative_end(with_prior.whole, curve.length, 1.5) is None


def test_a_fit_whose_end_goes_negative_holds_that_end_and_builds_a_positive_radius(monkeypatch):
    calls = _without_prior_first(monkeypatch)
    curve, vertices, network = vessel()
    fit = wall_fit.fit_wall(curve, vertices, network, wall_fit.WallFitOptions(), np.random.default_rng(0))
    assert len(calls) == 2 and calls[1] < calls[0]  # fitted again without the held stretch's points
    held = fit.ends["inlet_held"]
    assert held["rho_min_mm"] <= 0.0 and held["from_mm"] == 0.0 and 0.0 < held["held_mm"] <= MAX_HOLD_FRACTION * LENGTH
    assert fit.folding.min_rho_mm > 0.5 * R
    # the held stretch is at the inscribed radius all round, and shows in the coverage as held by the end prior
    ring = fit.field.evaluate_grid(1.0, np.array([0.0]), np.linspace(0.0, 2 * np.pi, 24, endpoint=False))[0]
    assert ring == pytest.approx(np.full_like(ring, R), rel=0.01)
    s = fit.summary()
    [stretch] = [x for x in s["coverage"]["unseen_stretches"] if x["held"]]
    assert stretch["end"] == "inlet" and stretch["length_mm"] >= held["held_mm"] - 1.5
