"""The load-stepping rules from rest (softdesign.mechanics.load_steps): the first step's size in shear moduli, as
few halvings as keep the smallest step the one asked, and the path's tolerance."""

from __future__ import annotations

from softdesign.mechanics.load_steps import (
    FIRST_STEP_MU,
    PATH_RTOL,
    first_step_settings,
    first_steps,
    stepped_from_rest,
)
from softdesign.mechanics.newton import NewtonSettings


def test_the_first_load_step_is_at_most_a_tenth_of_the_shear_modulus() -> None:
    mu = 39.4
    for asked, largest in ((8, 446.6), (8, 223.3), (8, 44.7), (8, 2.0), (256, 446.6), (1, 0.0)):
        steps = first_steps(asked, largest, mu)
        if steps == asked:  # the asked steps already start low enough
            assert largest / asked <= FIRST_STEP_MU * mu
        else:  # the fewest steps, a power of two, that start low enough
            assert steps > asked and steps & (steps - 1) == 0
            assert largest / steps <= FIRST_STEP_MU * mu < largest / (steps // 2)
    assert first_steps(8, 446.6, mu) == 128  # the sample device at P*: 3.5 kPa, 0.09 mu
    for asked, cutbacks, largest in ((8, 10, 446.6), (4, 6, 197.0), (5, 6, 197.0), (8, 2, 446.6), (8, 10, 2.0)):
        chosen = first_step_settings(NewtonSettings(load_steps=asked, max_cutbacks=cutbacks), largest, mu)
        smallest, asked_smallest = 1 / (chosen.load_steps * 2**chosen.max_cutbacks), 1 / (asked * 2**cutbacks)
        assert chosen.load_steps == first_steps(asked, largest, mu)
        # the smallest step the one asked or at most half of it (none finer is possible when no halving is left)
        assert asked_smallest / 2 <= smallest <= asked_smallest or chosen.max_cutbacks == 0


def test_a_solve_from_rest_steps_its_path_to_the_path_tolerance_unless_told() -> None:
    mu = 39.4
    chosen = stepped_from_rest(NewtonSettings(load_steps=2, max_cutbacks=6), 20.0, mu)
    # the per-chamber demo's section 1 at 20 kPa in one chamber: eight steps of 2.5 kPa, the smallest still 1/128
    assert (chosen.load_steps, chosen.max_cutbacks, chosen.path_rtol) == (8, 4, PATH_RTOL)
    assert chosen.rtol == NewtonSettings().rtol  # the last step converges as asked
    kept = stepped_from_rest(NewtonSettings(path_rtol=1e-6), 20.0, mu)
    assert kept.path_rtol == 1e-6
