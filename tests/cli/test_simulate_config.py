"""The case file's simulate block: off by default, its bounds and cross-checks refused by `softdesign validate`
(exit 2, the key named), and `simulate --write` refused without --target before any work."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.config import load_case
from tests.cli.test_cli_validate import demo_case

runner = CliRunner()


def test_simulate_is_off_unless_enabled(tmp_path: Path) -> None:
    assert load_case(demo_case(tmp_path, actuation={})).simulate is None
    block = load_case(demo_case(tmp_path, name="block", actuation={}, simulate={"q": [1, 0.5]})).simulate
    assert block is not None and block.enabled is False
    assert block.q == [0.5, 1.0] and block.sections is None  # sorted; every section by default


@pytest.mark.parametrize(("simulate", "message"), [
    ({"q": [1.5]}, "q values must lie in [0, 1]"),
    ({"q": [0.5, 0.5004]}, "at least 0.001 apart"),
    ({"q": [i / 20 for i in range(12)]}, "more than 11 entries"),
    ({"q": []}, "at least 1"),
    ({"sections": [0]}, "numbered from 1"),
    ({"sections": [1, 1]}, "each once"),
    ({"size_mm": 0.1}, "size_mm"),
    ({"layer_mm": 1000}, "layer_mm"),
    ({"angular_count": 4}, "angular_count"),
    ({"angular_count": 1e9}, "angular_count"),
    ({"max_pressure_kpa": 5000}, "max_pressure_kpa"),
    ({"max_solves": 41}, "max_solves"),
    ({"timeout_s": 0}, "timeout_s"),
    ({"timeout_s": 1e6}, "timeout_s"),
    ({"size_mm": ".nan"}, "size_mm"),
    ({"enable": True}, "enable"),
])
def test_bad_simulate_keys_are_refused_naming_the_key(tmp_path: Path, simulate: dict, message: str) -> None:
    result = runner.invoke(app, ["validate", str(demo_case(tmp_path, actuation={}, simulate=simulate))])
    assert result.exit_code == 2, result.output
    assert "simulate" in result.stderr and message in result.stderr
    assert "Traceback" not in result.output


def test_enabled_without_chambers_is_refused(tmp_path: Path) -> None:
    result = runner.invoke(app, ["validate", str(demo_case(tmp_path, simulate={"enabled": True}))])
    assert result.exit_code == 2 and "add an actuation: block" in result.stderr
    # a block kept but switched off asks nothing of the case
    assert runner.invoke(app, ["validate", str(demo_case(tmp_path, name="off", simulate={}))]).exit_code == 0


def test_write_needs_a_target_before_any_work(tmp_path: Path) -> None:
    case = demo_case(tmp_path, actuation={})
    result = runner.invoke(app, ["simulate", str(case), "--out", str(tmp_path / "build"), "--pressures", "10,0,0",
                                 "--write"])
    assert result.exit_code == 2 and "give --target" in result.output
    assert not (tmp_path / "build").exists()
