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


def payload(converged: bool = True) -> dict:
    return {"tensile_strength_kpa": 1380.0, "max_stress_kpa": 250.0, "pressures_kpa": [12.0, 30.5, 0.0],
            "mesh": {"nodes": 2642}, "target": {"error_mm": [0.3, 0.4, 0.0], "converged": converged}}


def test_the_targets_are_issue_42s(bench) -> None:
    assert bench.FORWARD_TARGET_S == 30.0 and bench.INVERSE_TARGET_S == 60.0
    assert bench.INVERSE_TIMEOUT_S > bench.INVERSE_TARGET_S


def test_a_run_within_the_target_is_met_with_its_figures(bench) -> None:
    text, ok = bench.line("demo", "--target 1", 60.0, 59.0, payload(), "")
    assert ok and text.endswith("target <= 60 s: met")
    assert "2642 nodes" in text and "arc error 0.500 mm" in text and "stress 250/1380 kPa" in text


def test_a_slow_or_failed_run_is_missed(bench) -> None:
    text, ok = bench.line("demo", "--target 1", 60.0, 61.0, payload(converged=False), "")
    assert not ok and text.endswith("MISSED") and "(not converged)" in text
    text, ok = bench.line("aorta", "--pressures 20,0,0", 30.0, 12.0, None, "error: did not finish within 120 s")
    assert not ok and "failed: error: did not finish" in text and text.endswith("MISSED")
    text, ok = bench.line("demo", "--pressures 20,0,0", 30.0, 31.0, payload(), "")  # the forward's own target
    assert not ok and text.endswith("target <= 30 s: MISSED")
