"""pipelines/bench_simulate.py's verdicts on payloads fed in by hand: within its target (30 s forward, 60 s inverse)
met, beyond it or failed MISSED.

No timing is measured here (the benchmark itself is `make bench`)."""

from __future__ import annotations

import importlib.util
import sys

import pytest

from tests.helpers.paths import REPO


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("softdesign_bench_simulate", REPO / "pipelines" / "bench_simulate.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def payload(converged: bool = True, best_within_bounds: bool = False) -> dict:
    return {"tensile_strength_kpa": 1380.0, "max_stress_kpa": 250.0, "pressures_kpa": [12.0, 30.5, 0.0],
            "mesh": {"nodes": 2642}, "target": {"error_mm": [0.3, 0.4, 0.0], "converged": converged,
                                                "best_within_bounds": best_within_bounds}}


def test_the_targets_are_issue_42s(bench) -> None:
    assert bench.FORWARD_TARGET_S == 30.0 and bench.INVERSE_TARGET_S == 60.0
    assert bench.INVERSE_TIMEOUT_S > bench.INVERSE_TARGET_S


def test_a_run_within_the_target_is_met_with_its_figures(bench) -> None:
    text, ok = bench.line("demo", "--target 1", 60.0, 59.0, payload(), "")
    assert ok and text.endswith("target <= 60 s: met")
    assert "2642 nodes" in text and "arc error 0.500 mm" in text and "stress 250/1380 kPa" in text


def test_a_slow_or_failed_run_is_missed(bench) -> None:
    text, ok = bench.line("demo", "--target 1", 60.0, 61.0, payload(), "")
    assert not ok and text.endswith("MISSED")
    text, ok = bench.line("aorta", "--pressures 20,0,0", 30.0, 12.0, None, "error: did not finish within 120 s")
    assert not ok and "failed: error: did not finish" in text and text.endswith("MISSED")
    text, ok = bench.line("demo", "--pressures 20,0,0", 30.0, 31.0, payload(), "")  # the forward's own target
    assert not ok and text.endswith("target <= 30 s: MISSED")


def test_a_target_recognised_out_of_reach_in_time_is_an_answer_unless_the_line_is_the_reachable_one(bench) -> None:
    out_of_reach = payload(converged=False, best_within_bounds=True)
    text, ok = bench.line("demo", "--target 1", 60.0, 59.0, out_of_reach, "")
    assert ok and "(out of reach: its best within the bounds)" in text and text.endswith("met")
    text, ok = bench.line("demo", "--target 0.0229", 60.0, 59.0, out_of_reach, "", reachable=True)
    assert not ok and text.endswith("MISSED")


def test_a_search_that_stopped_short_is_missed_however_fast(bench) -> None:
    text, ok = bench.line("demo", "--target 1", 60.0, 10.0, payload(converged=False), "")
    assert not ok and "(not converged)" in text and text.endswith("MISSED")


def test_a_round_trip_says_how_close_the_pressures_come_back_and_hands_on_every_digit_of_the_arc(bench) -> None:
    found = payload() | {"pressures_kpa": [19.98, 0.004, 0.0]}
    text, ok = bench.line("demo", "--target-arc", 60.0, 40.0, found, "", reachable=True, expected_kpa="20,0,0")
    assert ok and "pressures back within 0.02 kPa of 20,0,0" in text
    arc = {"arc": {"kappa_per_mm": 0.0012345678901234, "phi_rad": 0.5, "length_mm": 26.123456789012345}}
    kappa, phi, length = (float(v) for v in bench.arc_text(arc).split(","))
    assert kappa == 0.0012345678901234 and length == 26.123456789012345
    assert abs(phi - 28.64788975654116) < 1e-12  # 0.5 rad in degrees
