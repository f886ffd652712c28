"""fit.local_max_radius: the cap over a stretch only, its bound on rho, and the stretches a fold needs capped."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.errors import FoldError
from softdesign.fitting import bspline_basis as bb
from softdesign.fitting.bspline_surface import RadiusSpline, split_at_breaks
from softdesign.fitting.local_cap import (
    LocalCap,
    cap_over,
    capped_locally,
    fold_advice,
    fold_stretches,
)
from softdesign.fitting.radius_field import FOLD_FIX_REACH, RadiusField, check_self_folding, fold_margin
from tests.helpers.analytic import Arc

#: Spline evaluations of O(10 mm) values.
VALUE_TOL_MM = 1e-12
#: The stretch reaches one fold-grid row (0.1 mm) past the last row over the reach, rounded outwards to 0.1 mm.
STRETCH_TOL_MM = 0.2 + 1e-9


def test_the_cap_is_the_radius_on_the_stretch_and_rises_linearly_over_the_taper():
    cap = (LocalCap(10.0, 20.0, 2.0, 4.0),)
    lo = np.array([12.0, 5.0, 21.0, 22.0, 23.0, 30.0, 0.0])
    hi = np.array([13.0, 9.0, 22.0, 22.0, 40.0, 31.0, 50.0])
    # top 6: the cap rises (6 - 2) / 4 = 1 mm per mm from the stretch's ends
    np.testing.assert_allclose(cap_over(cap, lo, hi, 6.0), [2.0, 3.0, 3.0, 4.0, 5.0, 6.0, 2.0], rtol=0,
                               atol=VALUE_TOL_MM)
    # no taper: a step
    np.testing.assert_allclose(cap_over((LocalCap(10.0, 20.0, 2.0, 0.0),), lo, hi, 6.0),
                               [2.0, 6.0, 6.0, 6.0, 6.0, 6.0, 2.0], rtol=0, atol=VALUE_TOL_MM)


def _wavy_spline(length_mm: float, seed: int = 3) -> RadiusSpline:
    rng = np.random.default_rng(seed)
    knots = bb.open_knots([0.0, 1.0], [int(length_mm / 1.5)])
    return RadiusSpline(knots, 5.0 + rng.uniform(-1.0, 1.0, (len(knots) - 4, 12)))


def test_a_locally_capped_spline_stays_under_the_cap_and_is_the_fit_beyond_its_support():
    length = 60.0
    spline = _wavy_spline(length)
    cap = LocalCap(20.0, 30.0, 3.0, 5.0)
    held = capped_locally(spline, (cap,), length)
    s = np.linspace(0.0, length, 3001)
    a = np.linspace(0.0, 2 * np.pi, 97)
    before, after = spline.evaluate_grid(s / length, a), held.evaluate_grid(s / length, a)
    limit = cap_over((cap,), s, s, float(spline.coefficients.max()))
    assert np.all(after <= limit[:, None] + VALUE_TOL_MM)  # the bound, the taper included
    assert np.all(after <= before + VALUE_TOL_MM)  # never raised
    assert np.all(after[(s >= cap.from_mm) & (s <= cap.to_mm)] <= cap.radius_mm + VALUE_TOL_MM)
    # beyond the taper and one B-spline support (4 knot intervals) the body is the fit, unchanged
    support = 4 * length / (len(spline.knots) - 7)
    far = (s < cap.from_mm - cap.taper_mm - support) | (s > cap.to_mm + cap.taper_mm + support)
    np.testing.assert_array_equal(after[far], before[far])
    # split into links after capping, the joints stay exact
    links = split_at_breaks(held, (0.0, 0.45, 1.0))
    joint = np.array([0.45])
    np.testing.assert_allclose(links[0].evaluate_grid(joint, a), links[1].evaluate_grid(joint, a), rtol=0,
                               atol=1e-9)


def _bump_field(curve: Arc, height: float = 8.0) -> RadiusField:
    """rho = 10 + height exp(-((l - 0.5) / 0.1)^2), round, on knots every 1 mm of the arc."""
    knots = bb.open_knots([0.0, 1.0], [int(curve.length)])
    greville = np.array([knots[i + 1: i + 4].mean() for i in range(len(knots) - 4)])
    radius = 10.0 + height * np.exp(-(((greville - 0.5) / 0.1) ** 2))
    spline = RadiusSpline(knots, np.repeat(radius[:, None], 16, axis=1))
    return RadiusField.from_links((0.0, 1.0), (spline,))


def test_the_stretch_of_a_bump_that_folds_is_where_rho_kappa_exceeds_the_fix_and_its_cap_brings_it_there():
    curve = Arc(20.0, 2.0)  # kappa 1/20 everywhere, 40 mm long
    field = _bump_field(curve)
    [stretch] = fold_stretches(curve, field)
    # rho * kappa > 0.7 where rho > 14 mm on the inner side: found on the field itself, every 0.01 mm
    s = np.linspace(0.0, curve.length, 4001)
    over = s[field.evaluate_grid(1.0, s / curve.length, np.array([0.0]))[:, 0] / 20.0 > FOLD_FIX_REACH]
    assert stretch.cap.from_mm <= over[0] <= stretch.cap.from_mm + STRETCH_TOL_MM
    assert stretch.cap.to_mm - STRETCH_TOL_MM <= over[-1] <= stretch.cap.to_mm
    assert stretch.cap.radius_mm == pytest.approx(FOLD_FIX_REACH * 20.0, abs=0.01)  # 0.7 x the bend's radius
    assert stretch.bend_radius_mm == pytest.approx(20.0, abs=1e-6)
    # the turn between the stretch's ends: 2 rad over 40 mm of arc
    assert stretch.turn_deg == pytest.approx(np.degrees((stretch.cap.to_mm - stretch.cap.from_mm) / 20.0), abs=1e-6)
    assert stretch.radius_before_mm < stretch.cap.radius_mm and stretch.radius_after_mm < stretch.cap.radius_mm
    # held by the offered cap, the body's rho * kappa_n is at most the fix's reach, and the fit far from it
    spline = field.final[0]
    held = capped_locally(spline, (stretch.cap,), curve.length)
    capped_field = RadiusField.from_links((0.0, 1.0), (held,))
    assert fold_margin(curve, capped_field).max_rho_kappa <= FOLD_FIX_REACH + VALUE_TOL_MM
    assert fold_margin(curve, field).max_rho_kappa > FOLD_FIX_REACH


def test_a_field_that_does_not_exceed_the_reach_has_no_stretch():
    curve = Arc(20.0, 2.0)
    assert fold_stretches(curve, _bump_field(curve, height=2.0)) == ()


def test_the_refusal_offers_the_local_cap_first_and_keeps_the_whole_path_cap():
    curve = Arc(20.0, 2.0)
    field = _bump_field(curve, height=12.0)  # rho * kappa 1.1 at the bump's top: folds
    with pytest.raises(FoldError) as err:
        check_self_folding(curve, field)
    stretches = fold_stretches(curve, field)
    message = fold_advice(str(err.value), stretches)
    [stretch] = stretches
    local = message.index("fit: {local_max_radius: [" + stretch.cap.key_text() + "]}")
    whole = message.index("set fit.max_radius_mm: 14.00")
    assert local < whole
    assert f"{stretch.cap.from_mm:g}-{stretch.cap.to_mm:g} mm from the inlet" in message
    assert "the path turns" in message and "tightest radius of curvature 20.00 mm" in message
    assert fold_advice("no stretches", ()) == "no stretches"


def test_the_case_key_is_bounded_and_ordered():
    from pydantic import ValidationError

    from softdesign.config import Fit
    from softdesign.config.fit_caps import MAX_LOCAL_CAPS

    entry = {"from_mm": 1.9, "to_mm": 9.2, "radius_mm": 2.24, "taper_mm": 4}
    assert Fit(local_max_radius=[entry]).local_max_radius[0].taper_mm == 4.0
    for bad, words in (({**entry, "to_mm": 1.0}, "to_mm must be more than from_mm"),
                       ({**entry, "radius_mm": 0.0}, "radius_mm"), ({**entry, "taper_mm": 1e6}, "taper_mm"),
                       ({**entry, "width": 1}, "width")):
        with pytest.raises(ValidationError, match=words):
            Fit(local_max_radius=[bad])
    with pytest.raises(ValidationError, match=f"at most {MAX_LOCAL_CAPS} items"):
        Fit(local_max_radius=[entry] * (MAX_LOCAL_CAPS + 1))
