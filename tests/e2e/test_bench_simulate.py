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


def test_the_reachable_q_puts_the_rod_models_largest_pressure_at_a_quarter_of_the_bound(bench, tmp_path) -> None:
    rows = ["q,section,chamber,pressure_kpa", "1.0,1,1,0.0", "1.0,1,2,1089.75", "1.0,1,3,263.5",
            "1.0,2,1,5000.0", "0.5,1,2,556.0"]  # another section's and another q's rows are not read
    (tmp_path / "actuation.csv").write_text("\n".join(rows) + "\n", encoding="utf-8")
    assert bench.REACH_SHARE == 0.25 and bench.MAX_PRESSURE_KPA == 100.0
    assert bench.reachable_q(tmp_path) == 0.0229  # 25 / 1089.75 = 0.02294, three digits
