"""The report of a build is the same bytes wherever the build folder is (issue 35 item 1), and `softdesign report`
says where it wrote the page.

The page once named the folder and showed each stage's time, so two identical
builds in different folders gave pages a few bytes apart; those now go only
into ``report/report.log``.
"""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.pipeline.layout import REPORT_DIR
from softdesign.report.writer import LOG
from tests.helpers.shared_builds import demo_build, demo_build_copy

runner = CliRunner()


@pytest.mark.slow
def test_identical_builds_in_other_folders_give_the_same_report_bytes(tmp_path, tmp_path_factory):
    # the README's demo build with the report `build --report` drew (made once per run, only read here), and a copy
    # of it without the report in a folder of another name and depth, where `softdesign report` draws it again
    first = demo_build(tmp_path_factory)
    second = demo_build_copy(tmp_path_factory, tmp_path / "elsewhere" / "folder-beta")
    result = runner.invoke(app, ["report", str(second), "--jobs", "1"])  # the pool: test_report_jobs
    assert result.exit_code == 0, result.output
    # the command says where the page is and how its checks went; no --pcc-d, no PCC panel
    assert str(second / REPORT_DIR / "index.html") in result.stdout and "checks" in result.stdout
    one, two = ({p.name: p.read_bytes() for p in sorted((folder / REPORT_DIR).iterdir())} for folder in (first, second))
    assert sorted(one) == sorted(two) and "index.html" in one and "pcc_chambers.png" not in two
    assert [name for name in one if one[name] != two[name] and name != LOG] == []
    page = two["index.html"].decode("utf-8")
    assert "folder-beta" not in page and "elsewhere" not in page
    assert "time (s)" not in page and "/timing_s/" not in page
    # the log has what the page leaves out: the folder and the times
    log = two[LOG].decode("utf-8")
    assert f"build folder: {second.resolve().as_posix()}\n" in log
    assert "stage fit: " in log and "report part load the build: " in log
