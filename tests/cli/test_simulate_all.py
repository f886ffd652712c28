"""`softdesign simulate CASE --all`: bad options and cases refused with exit 2 and the option or key named, before
the build (or, for the mesh's size, before the solve)."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from tests.helpers.paths import DEMO, REPO
from tests.helpers.shared_builds import ACTUATOR_BUILD, workspace_copy

runner = CliRunner()
ACTUATOR = REPO / "configs" / "actuator.yaml"
PER_CHAMBER = REPO / "configs" / "actuator-per-chamber.yaml"


def test_help_names_the_whole_device_options() -> None:
    result = runner.invoke(app, ["simulate", "--help"])
    assert result.exit_code == 0
    for option in ("--all", "--q", "--pressure"):
        assert option in result.output


@pytest.mark.parametrize(("case", "args", "message"), [
    (ACTUATOR, ["--all", "--q", "1.5"], "--q: got 1.5"),
    (ACTUATOR, ["--all", "--pressure", "2000"], "--pressure: got 2000, expected a number in [0, 1000]"),
    (ACTUATOR, ["--all", "--q", "1", "--pressure", "100"], "not both"),
    (ACTUATOR, ["--q", "1"], "--q and --pressure go with --all"),
    (ACTUATOR, ["--all", "--pressures", "1,2,3"], "--all takes neither --pressures"),
    (ACTUATOR, ["--all", "--timeout", "0"], "--timeout: got 0"),
    (PER_CHAMBER, ["--all", "--pressure", "100"], "one supply pressure is for actuation.supply: single"),
    (DEMO, ["--all"], "the case has no actuation chambers"),
])
def test_bad_options_exit_2_before_the_build(case: Path, args: list[str], message: str, tmp_path: Path) -> None:
    result = runner.invoke(app, ["simulate", str(case), "--out", str(tmp_path / "build"), *args])
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert not (tmp_path / "build").exists()


@pytest.mark.slow
def test_a_mesh_over_the_bound_is_refused_before_the_solve(tmp_path: Path, tmp_path_factory) -> None:
    # on a copy of the README's build of configs/actuator.yaml (made once per run, with its case file and inputs):
    # the build through actuation is reused, and the estimate refuses before meshing
    clone = workspace_copy(tmp_path_factory, tmp_path / "clone", ACTUATOR_BUILD, "build/actuator")
    result = runner.invoke(app, ["simulate", str(clone / "configs" / "actuator.yaml"), "--out",
                                 str(clone / "build" / "actuator"), "--all", "--size-mm", "0.2", "--layer-mm", "0.2"])
    assert result.exit_code == 2, result.output
    assert "MAX_DEVICE_NODES" in result.output and "raise --size-mm or --layer-mm" in result.output


def test_a_solve_that_stops_short_prints_its_figures_and_exits_1(monkeypatch: pytest.MonkeyPatch) -> None:
    # the command's side only (the solve's own stop: tests/mechanics/test_device.py): a payload that did not reach
    # its load is printed as any other, then the stop is said and the exit code is 1
    payload = {"reached": {"stopped_because": "the whole device: the solve stopped at 86.9 kPa (load factor 0.1947)"},
               "leaves_out": ["contact with the vessel wall"]}
    monkeypatch.setattr("softdesign.pipeline.device_command.run_device", lambda *args: payload)
    monkeypatch.setattr("softdesign.pipeline.device_figures.device_lines", lambda p: ["NOT REACHED: figures"])
    result = runner.invoke(app, ["simulate", str(ACTUATOR), "--all", "--q", "1"])
    assert result.exit_code == 1, result.output
    assert "NOT REACHED: figures" in result.output
    assert "simulate --all: the whole device: the solve stopped at 86.9 kPa (load factor 0.1947)" in result.output


def test_the_whole_device_waits_longer_by_default_than_a_section(monkeypatch: pytest.MonkeyPatch) -> None:
    # --all's default --timeout is the whole device's (8-9 minutes of CPU for the sample at P*), a user's is kept
    seen: list[float] = []

    def device(case_file, out, o, progress):  # noqa: ANN001, ANN202 - run_device's signature
        seen.append(o.timeout_s)
        return {"reached": None, "leaves_out": []}

    monkeypatch.setattr("softdesign.pipeline.device_command.run_device", device)
    monkeypatch.setattr("softdesign.pipeline.device_figures.device_lines", lambda p: ["figures"])
    for args in ([], ["--timeout", "900"]):
        result = runner.invoke(app, ["simulate", str(ACTUATOR), "--all", "--q", "1", *args])
        assert result.exit_code == 0, result.output
    assert seen == [1800.0, 900.0]
