"""The device_fe stage's verdict (issue 42): "FE: within X mm at P*" from its figures as a margin, a limit the
figures cross as a reason naming the key to change; it runs only for a single-supply device with simulate on."""

from __future__ import annotations

from pathlib import Path

import pytest

from softdesign.config import load_case
from softdesign.pipeline.stages.device_fe import device_judgement, fe_line, wanted
from tests.helpers.cases import case_from
from tests.helpers.paths import REPO


def _solve(q: float, stress: float, thread: float) -> dict:
    return {"q": q, "pressure_kpa": 852.5 * q, "versus_design": {"max_mm": 0.42}, "versus_rod_model": {"max_mm": 0.3},
            "max_stress_kpa": {"value": stress, "section": 2, "tensile_strength_kpa": 1379.0},
            "max_stretch": {"value": 1.31}, "thread": {"value": 0.2 * thread, "limit_n": 0.2,
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
