"""A build that changes nothing keeps its report; one that changes outputs says it removed it (issue 34)."""

from __future__ import annotations

import pytest
import yaml
from typer.testing import CliRunner

from softdesign.cli import app
from tests.helpers.attacks import demo_case
from tests.helpers.folders import snapshot

runner = CliRunner()


@pytest.mark.slow
def test_an_unchanged_rebuild_keeps_the_report_and_a_changed_one_says_it_is_gone(tmp_path):
    case, out = demo_case(tmp_path), tmp_path / "build"
    first = runner.invoke(app, ["build", str(case), "--out", str(out), "--report", "--jobs", "1"])
    assert first.exit_code == 0, first.output
    report = {k: v for k, v in snapshot(out).items() if k.startswith("report/")}
    assert "report/index.html" in report
    again = runner.invoke(app, ["build", str(case), "--out", str(out), "--jobs", "1"])  # nothing changed
    assert again.exit_code == 0, again.output
    assert {k: v for k, v in snapshot(out).items() if k.startswith("report/")} == report
    assert "report/ removed" not in again.output
    data = yaml.safe_load(case.read_text())
    data["export"]["q"] = [0, 0.5, 1]  # another output: the page would describe a build no longer there
    case.write_text(yaml.safe_dump(data))
    changed = runner.invoke(app, ["build", str(case), "--out", str(out), "--jobs", "1"])
    assert changed.exit_code == 0, changed.output
    assert not (out / "report").exists()
    assert "report/ removed" in changed.output and f"softdesign report {out}" in changed.output
