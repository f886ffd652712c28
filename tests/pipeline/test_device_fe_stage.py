"""The device_fe stage's verdict (issue 42): "FE: within X mm at P*" from its figures as a margin, a limit the
figures cross as a reason naming the key to change; it runs only for a single-supply device with simulate on."""

from __future__ import annotations

from pathlib import Path

import pytest

from softdesign.config import load_case
from softdesign.pipeline.stages.device_fe import describe_device, device_judgement, fe_line, wanted
from tests.helpers.cases import case_from
from tests.helpers.paths import REPO


def _solve(q: float, stress: float, thread: float) -> dict:
    return {"q": q, "pressure_kpa": 852.5 * q, "design_pressure_kpa": 852.5, "reached": None,
            "versus_design": {"max_mm": 0.42, "tip_mm": 0.5, "tip_angle_rad": 0.01},
            "versus_rod_model": {"max_mm": 0.3, "tip_mm": 0.4, "tip_angle_rad": 0.01},
            "max_stress_kpa": {"value": stress, "section": 2, "tensile_strength_kpa": 1379.0},
            "max_stretch": {"value": 1.31, "section": 3}, "thread": {"value": 0.2 * thread, "limit_n": 0.2,
                                                       "fraction_of_limit": thread}}


def test_the_verdict_line_gives_the_largest_q_s_figures() -> None:
    summary = {"solves": [_solve(0.5, 400.0, 0.005), _solve(1.0, 900.0, 0.01)]}
    line = fe_line(summary)
    assert line is not None and line.startswith("FE: within 0.42 mm of the designed chain at P* (852.5 kPa;")
    assert "the rod model 0.3 mm from it" in line and "largest stress 900 kPa of 1379 kPa" in line
    assert "thread at 1.0 % of its limit" in line
    judgement = device_judgement(summary)
    assert judgement is not None and judgement.margins == (line,) and not judgement.reasons


def test_a_crossed_limit_is_a_reason_naming_the_key() -> None:
    judgement = device_judgement({"solves": [_solve(1.0, 1500.0, 1.5)]})
    assert judgement is not None and not judgement.margins
    stress, thread = judgement.reasons
    assert "stress 1500 kPa in section 2 > the tensile strength 1379 kPa" in stress and "material.name" in stress
    assert "actuation.reinforcement.pitch_mm" in thread


def test_no_solves_no_judgement() -> None:
    assert device_judgement(None) is None and device_judgement({"solves": []}) is None


@pytest.mark.parametrize(("changes", "expected"), [
    ({"simulate": {"enabled": True}}, True),
    ({}, False),
    ({"simulate": {"enabled": True}, "actuation": {"supply": "per_chamber"}}, False),
])
def test_it_runs_for_a_single_supply_device_with_simulate_on(changes: dict, expected: bool, tmp_path: Path) -> None:
    assert wanted(load_case(case_from(tmp_path, REPO / "configs" / "actuator.yaml", changes))) is expected


def test_a_device_that_stops_short_is_not_feasible_and_says_where() -> None:
    stopped = {**_solve(0.5, 200.0, 0.004), "max_stretch": {"value": 2.15, "section": 5},
               "reached": {"load_factor": 0.2, "q": 0.1, "pressure_kpa": 85.25, "pressures_kpa": [85.25],
                           "stopped_because": "the whole device: the solve stopped at 85.25 kPa"}}
    summary = {"solves": [stopped]}
    assert fe_line(summary) is None  # no "within X mm at P*" for a load the device does not reach
    judgement = device_judgement(summary)
    assert judgement is not None and not judgement.margins
    (reason,) = judgement.reasons
    assert reason.startswith("FE: pressure does not reach the shape: the whole device in finite elements finds no "
                             "equilibrium past 85.2 kPa (10.0 % of P* 852.5 kPa), bent to q = 0.1")
    assert "largest stretch 2.15 in section 5" in reason and "material.min_wall_mm" in reason
    assert "actuation.reinforcement.ends" not in reason  # a payload without the thread's ends offers none
    assert describe_device(summary)[0].startswith("q=0.5 (426.2 kPa): stopped at 85.2 kPa (q = 0.1), there against")


@pytest.mark.parametrize(("ends", "offered"), [("bare", True), ("patch", False)])
def test_a_stop_with_bare_ends_offers_patching_them(ends: str, offered: bool) -> None:
    stopped = {**_solve(0.5, 200.0, 0.004), "max_stretch": {"value": 2.15, "section": 5},
               "reached": {"load_factor": 0.2, "q": 0.1, "pressure_kpa": 85.25, "pressures_kpa": [85.25],
                           "stopped_because": "the whole device: the solve stopped at 85.25 kPa"}}
    stopped["thread"] = {**stopped["thread"], "ends": ends}
    judgement = device_judgement({"solves": [stopped]})
    assert judgement is not None
    (reason,) = judgement.reasons
    assert ("patch them (actuation.reinforcement.ends: patch)" in reason) is offered
    assert "material.min_wall_mm" in reason


def test_a_device_that_reaches_its_load_off_the_shape_is_not_feasible() -> None:
    solve = _solve(1.0, 900.0, 0.01)
    solve["sections"] = [{"section": 1, "kappa": 0.0101, "designed": {"kappa": 0.01}},
                         {"section": 2, "kappa": 0.0713, "designed": {"kappa": 0.0386}}]
    within = device_judgement({"solves": [solve], "shape_tolerance_mm": 0.5})  # the solve is 0.42 mm off
    assert within is not None and not within.reasons and within.margins
    off = device_judgement({"solves": [solve], "shape_tolerance_mm": 0.4})
    assert off is not None and not off.margins
    (reason,) = off.reasons
    assert reason.startswith("FE at q = 1: pressure does not reach the shape: the whole device in finite elements "
                             "lies 0.42 mm from the designed chain (the furthest arc section 2's, kappa 0.0713 1/mm "
                             "against 0.0386 designed) > simulate.shape_tolerance_mm 0.4")
