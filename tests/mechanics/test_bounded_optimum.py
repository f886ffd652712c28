"""The bounded least-squares optimum test (:mod:`softdesign.mechanics.bounded_optimum`) on linear problems whose
bounded optimum is known in closed form: ``e(p) = e0 + J p`` on ``0 <= p <= p_max``."""

from __future__ import annotations

import numpy as np

from softdesign.mechanics.bounded_optimum import stationarity, why_left

#: The tests' share and tolerance of :meth:`Stationarity.is_optimum` (the inverse's STATIONARY_SHARE).
SHARE, TOLERANCE_MM = 1e-3, 1e-4
#: lsq_linear's (BVLS) least error is exact to rounding on these 3 x 3 problems, mm.
ROUND_MM = 1e-12

#: Three chambers: each bends the tip its own way (first two rows) and lengthens it (third), mm/kPa.
J = np.array([[0.02, -0.01, -0.01],
              [0.0, 0.017, -0.017],
              [0.004, 0.004, 0.004]])


def test_inside_the_bounds_the_least_squares_answer_is_an_optimum_and_a_point_beside_it_is_not() -> None:
    truth = np.array([30.0, 10.0, 5.0])
    e0 = -J @ truth  # e(truth) = 0: reachable inside [0, 100]
    at = stationarity(J, e0 + J @ truth, truth, 100.0)
    assert at.is_optimum(SHARE, TOLERANCE_MM) and at.held_high == at.held_low == ()
    beside = truth + np.array([5.0, 0.0, 0.0])
    off = stationarity(J, e0 + J @ beside, beside, 100.0)
    assert not off.is_optimum(SHARE, TOLERANCE_MM)
    assert off.predicted_mm < ROUND_MM  # the model reaches the target from there in one step


def test_a_target_beyond_the_bound_has_its_optimum_on_it_with_the_chamber_named() -> None:
    # chamber 1 bends along +x: a bend of 3 mm needs 150 kPa, and the target's length is the one 100 kPa in it
    # gives; chambers 2 and 3 bend along -x.  Within 100 kPa the best is (100, 0, 0), 1 mm of bend short: raising
    # chamber 1 is barred by the bound, raising 2 or 3 bends the wrong way and lengthens
    e0 = -np.array([3.0, 0.0, 0.4])
    best = np.array([100.0, 0.0, 0.0])
    at = stationarity(J, e0 + J @ best, best, 100.0)
    assert abs(at.error_mm - 1.0) < ROUND_MM
    assert at.is_optimum(SHARE, TOLERANCE_MM)
    assert at.held_high == (0,) and at.held_low == (1, 2)
    below = np.array([90.0, 0.0, 0.0])
    assert not stationarity(J, e0 + J @ below, below, 100.0).is_optimum(SHARE, TOLERANCE_MM)


def test_a_target_shorter_than_the_rest_shape_is_best_met_at_rest() -> None:
    e0 = np.array([0.0, 0.0, 1.0])  # straight, and 1 mm shorter than the section: every pressure lengthens it
    rest = np.zeros(3)
    at = stationarity(J, e0, rest, 100.0)
    assert at.is_optimum(SHARE, TOLERANCE_MM)
    assert at.held_low == (0, 1, 2) and at.held_high == ()
    assert abs(at.predicted_mm - 1.0) < ROUND_MM
    text = why_left(at, 100.0, e0, (0.0, 0.0, 21.0), (0.0, 0.0, 20.0), J[2])
    assert "chambers 1, 2 and 3 at 0 kPa" in text and "pressure bound" not in text
    assert "1 mm of length (21.0000 mm, the target's 20.0000 mm)" in text
    assert "every chamber's pressure lengthens the section" in text


def test_the_reason_names_the_upper_bound_and_leaves_out_the_length_sentence_when_it_does_not_hold() -> None:
    e0 = -np.array([3.0, 0.0, 0.4])
    best = np.array([100.0, 0.0, 0.0])
    at = stationarity(J, e0 + J @ best, best, 100.0)
    text = why_left(at, 100.0, e0 + J @ best, (0.01, 0.0, 20.0), (0.03, 0.0, 20.0), J[2])
    assert text.startswith("chamber 1 at the pressure bound 100 kPa (--max-pressure")
    assert "lengthens" not in text  # the section is not longer than the target


def test_a_chamber_just_below_the_bound_whose_best_step_reaches_it_is_named_as_held() -> None:
    # the trust-region search stops inside the box (the demo's section: 99.90 of 100 kPa): the model's best step
    # takes the chamber onto the bound, so the bound is what holds it
    e0 = -np.array([3.0, 0.0, 0.4])
    near = np.array([99.9, 0.0, 0.0])
    at = stationarity(J, e0 + J @ near, near, 100.0)
    assert at.held_high == (0,)
    # the 0.1 kPa left bends 0.002 mm more (and lengthens 0.0004 mm, which the error also lacks: 8e-8 mm of |e|)
    assert abs((at.error_mm - at.predicted_mm) - 0.1 * 0.02) < 1e-6
