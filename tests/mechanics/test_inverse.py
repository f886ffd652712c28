"""The inverse's linear start and its continued trials (:mod:`softdesign.mechanics.inverse`) on the straight
three-chamber section of tests/mechanics/test_section.py: in the linear range the start is the answer, and a
converged search finds the pressures of a forward solve and gives the target's arc again when they are solved
afresh from rest."""

from __future__ import annotations

import functools

import numpy as np
import pytest

from softdesign.mechanics.inverse import InverseResult, InverseSettings, arc_vector, find_pressures, weighted_error
from softdesign.mechanics.section import SectionMesh, SectionResult, simulate_section
from tests.helpers.fe_meshes import three_chamber_section
from tests.mechanics.test_section import LAW, NEWTON, SHAPE, SIZE_MM

#: The search's tolerance on the weighted arc error, mm.
TOLERANCE_MM = 1e-4
#: A fresh solve from rest and the search's continued one stop at Newton's relative residual of 1e-8 on different
#: paths to the same equilibrium: their arcs differ by about that share of the section's bend (here below 1e-6 mm).
PATH_MM = 1e-6
#: At 1 % of the pressures below the section is near linear, and the linear start lands within this share of the
#: pressures' size (measured 1.1 %: the common pressure, which mostly lengthens the section, is the least determined
#: direction, see the module docstring of softdesign/mechanics/inverse.py).
LINEAR_SHARE = 0.02
#: A converged search (TOLERANCE_MM) finds a forward solve's pressures within this share of each (measured 0.02 %,
#: 0.07 %, 0.37 % for 12, 6, 2 kPa: the smallest is the least determined).
PRESSURE_RTOL = 0.01


@functools.cache
def _section() -> SectionMesh:
    return three_chamber_section(size=SIZE_MM, **SHAPE)


@functools.cache
def _forward(pressures: tuple[float, float, float]) -> SectionResult:
    return simulate_section(_section(), LAW, np.array(pressures), NEWTON)


def _target(result: SectionResult) -> tuple[float, float, float]:
    return result.kappa, result.phi, result.length


def _search(target: tuple[float, float, float], told: list[np.ndarray]) -> InverseResult:
    settings = InverseSettings(max_pressure_kpa=30.0, start_kpa=None, max_step_kpa=10.0, tolerance_mm=TOLERANCE_MM)
    return find_pressures(_section(), LAW, target, settings, NEWTON,
                          on_trial=lambda k, p, error, seconds: told.append(p))


@pytest.mark.slow
def test_in_the_linear_range_the_linear_start_is_the_answer() -> None:
    truth = np.array([0.12, 0.06, 0.02])
    told: list[np.ndarray] = []
    found = _search(_target(_forward(tuple(truth))), told)
    # the first trial is the linear start
    np.testing.assert_allclose(told[0], truth, rtol=0, atol=LINEAR_SHARE * float(np.linalg.norm(truth)))
    assert found.converged
    assert len(told) <= 2


@pytest.mark.slow
def test_a_converged_search_finds_the_pressures_and_gives_its_target_again_when_solved_from_rest() -> None:
    truth = (12.0, 6.0, 2.0)
    target = _target(_forward(truth))
    told: list[np.ndarray] = []
    found = _search(target, told)
    assert found.converged
    assert float(np.linalg.norm(found.error_mm)) <= TOLERANCE_MM
    np.testing.assert_allclose(found.pressures_kpa, truth, rtol=PRESSURE_RTOL, atol=0.0)
    fresh = simulate_section(_section(), LAW, found.pressures_kpa, NEWTON)
    error = weighted_error(arc_vector(*_target(fresh)), arc_vector(*target))
    assert float(np.linalg.norm(error)) <= TOLERANCE_MM + PATH_MM
    np.testing.assert_allclose(fresh.kappa, found.section.kappa, rtol=1e-6)
