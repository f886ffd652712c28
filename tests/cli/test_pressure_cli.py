"""`softdesign pressure`: bad input refused before any stage runs (exit 2, the key), and the rod model's shape."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.pipeline.rod_pressure import answer_if_unchanged
from tests.cli.test_cli_validate import demo_case
from tests.helpers.cases import case_from
from tests.helpers.paths import REPO
from tests.helpers.shared_builds import ACTUATOR_BUILD, PER_CHAMBER_BUILD, workspace_copy

runner = CliRunner()
#: q P* against the pressure printed (both from one float), and the same model at --q and --pressure, kPa and mm.
SAME_TOL = 1e-9


def test_help_names_both_ways_of_asking():
    result = runner.invoke(app, ["pressure", "--help"])
    assert result.exit_code == 0 and "--q" in result.output and "--pressure" in result.output


@pytest.mark.parametrize(("args", "sections", "message"), [
    (["--q", "0.5", "--pressure", "100"], {"actuation": {}}, "give --q or --pressure, not both"),
    (["--q", "1.5"], {"actuation": {}}, "--q must be in [0, 1], got 1.5"),
    (["--pressure", "-1"], {"actuation": {}}, "--pressure must be in [0, 100000] kPa, got -1"),
    ([], {}, "the case has no actuation: block"),
    ([], {"actuation": {"reinforcement": {"kind": "none"}}}, "kappa = (1 - 2 nu) P A d / (E I) = 0"),
    (["--pressure", "100"], {"actuation": {}}, "--pressure is one supply pressure (actuation.supply: single)"),
    ([], {"actuation": {}, "material": None}, "the rod model takes E = 3 mu from the material's law"),
])
def test_bad_input_exits_2_naming_what_to_change(tmp_path: Path, args: list[str], sections: dict,
                                                 message: str) -> None:
    case = demo_case(tmp_path, **sections)
    result = runner.invoke(app, ["pressure", str(case), "--out", str(tmp_path / "build"), *args])
    assert result.exit_code == 2, result.output
    assert message in result.stderr and "Traceback" not in result.output
    assert not (tmp_path / "build").exists()  # refused before any stage ran


def test_without_a_build_it_names_the_command_that_makes_one(tmp_path: Path) -> None:
    case = case_from(tmp_path, REPO / "configs" / "actuator.yaml", {})
    result = runner.invoke(app, ["pressure", str(case), "--out", str(tmp_path / "b"), "--q", "0.5"])
    assert result.exit_code == 2, result.output
    assert f"run `softdesign build {case} --out {tmp_path / 'b'}` first" in result.stderr
    assert "Traceback" not in result.output and not (tmp_path / "b").exists()


@pytest.mark.slow
def test_the_single_supply_demo_from_its_build(tmp_path: Path, tmp_path_factory) -> None:
    # the README's build of configs/actuator.yaml (made once per run), copied with its case file and inputs
    clone = workspace_copy(tmp_path_factory, tmp_path / "clone", ACTUATOR_BUILD, "build/actuator")
    case, out = clone / "configs" / "actuator.yaml", clone / "build" / "actuator"
    summary = json.loads((out / "actuation" / "summary.json").read_text())
    half = runner.invoke(app, ["pressure", str(case), "--out", str(out), "--q", "0.5", "--json"])
    assert half.exit_code == 0, half.output
    doc = json.loads(half.stdout)
    assert doc["supply"] == "single" and doc["q"] == 0.5
    assert doc["design_pressure_kpa"] == summary["design_pressure_kpa"]
    assert abs(doc["pressure_kpa"] - 0.5 * doc["design_pressure_kpa"]) <= SAME_TOL
    # the same rod model as the build's: its deviation from the designed chain at q = 0.5, to the last bits
    assert abs(doc["deviation_mm"] - summary["model_deviation_by_q_mm"]["0.5"]) <= SAME_TOL
    same = runner.invoke(app, ["pressure", str(case), "--out", str(out), "--pressure",
                               repr(doc["pressure_kpa"]), "--json"])
    again = json.loads(same.stdout)
    assert abs(again["q"] - 0.5) <= SAME_TOL
    for a, b in zip(again["sections"], doc["sections"], strict=True):
        assert abs(a["kappa"] - b["kappa"]) <= SAME_TOL and abs(a["length"] - b["length"]) <= SAME_TOL
    # unchanged case file and inputs: answered from the build alone, without the case's models (a new process)
    assert _answers_without_the_case_models(case, out)
    quick = answer_if_unchanged(case, out, 0.5, None)
    assert quick is not None and {**quick, "seconds": 0} == {**doc, "seconds": 0}
    # a comment is an edit the quick path cannot see through: the case is loaded and checked, the same answer
    case.write_text(case.read_text() + "# a comment\n")
    assert answer_if_unchanged(case, out, 0.5, None) is None
    commented = runner.invoke(app, ["pressure", str(case), "--out", str(out), "--q", "0.5", "--json"])
    assert commented.exit_code == 0 and {**json.loads(commented.stdout), "seconds": 0} == {**doc, "seconds": 0}
    # a build of other settings is not this case's: it says so and which command remakes it
    edited = case_from(tmp_path, case, {"export": {"q": [0.0, 1.0]}})
    stale = runner.invoke(app, ["pressure", str(edited), "--out", str(out), "--q", "0.5"])
    assert stale.exit_code == 2 and "made from other settings than this case file's" in stale.stderr


@pytest.mark.slow
def test_the_per_chamber_demo_gives_the_builds_pressures_at_a_grid_q(tmp_path: Path, tmp_path_factory) -> None:
    # configs/actuator-per-chamber.yaml's build as tests/e2e/test_one_story.py reads it (made once per run), copied
    clone = workspace_copy(tmp_path_factory, tmp_path / "clone", PER_CHAMBER_BUILD, "build/per-chamber")
    case, out = clone / "configs" / "actuator-per-chamber.yaml", clone / "build" / "per-chamber"
    result = runner.invoke(app, ["pressure", str(case), "--out", str(out), "--q", "0.5", "--json"])
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    rows = json.loads((out / "actuation" / "summary.json").read_text())["rows"]
    built = [[r["pressure_kpa"] for r in rows if r["q"] == 0.5 and r["section"] == i + 1]
             for i in range(len(doc["pressures_kpa"]))]
    for mine, theirs in zip(doc["pressures_kpa"], built, strict=True):
        assert all(abs(a - b) <= SAME_TOL * max(1.0, abs(b)) for a, b in zip(mine, theirs, strict=True))


def _answers_without_the_case_models(case: Path, out: Path) -> bool:
    """``softdesign pressure`` in a fresh interpreter answers (exit 0) and never imports softdesign.config."""
    code = ("import sys\nfrom softdesign.cli import main\n"
            f"sys.argv = ['softdesign', 'pressure', {str(case)!r}, '--out', {str(out)!r}, '--q', '0.5']\n"
            "try:\n    main()\nexcept SystemExit as e:\n    assert not e.code, e.code\n"
            "print('config imported:', 'softdesign.config' in sys.modules)\n")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120)
    return "config imported: False" in result.stdout

