"""`softdesign report --jobs N`: the figures drawn on worker processes give the same files, byte for byte."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.pipeline.layout import REPORT_DIR
from softdesign.pipeline.parallel import MAX_JOBS
from softdesign.report.writer import LOG
from tests.helpers.shared_builds import demo_build_copy

runner = CliRunner()


@pytest.mark.parametrize("jobs", ["0", "-1", str(MAX_JOBS + 1)])
def test_jobs_outside_the_bound_is_refused_before_any_work(tmp_path, jobs):
    folder = tmp_path / "not-built"  # the bound is checked before the folder is even read
    result = runner.invoke(app, ["report", str(folder), "--jobs", jobs])
    assert result.exit_code == 2, result.output
    assert f"--jobs must be 1 to {MAX_JOBS} worker processes, got {jobs}" in result.output
    assert "Traceback" not in result.output and not folder.exists()


@pytest.mark.slow
def test_a_report_is_the_same_bytes_with_one_and_two_jobs(tmp_path, tmp_path_factory):
    build_dir = demo_build_copy(tmp_path_factory, tmp_path / "build")  # the README's demo build, without its report
    drawn = {}
    for jobs in ("1", "2"):
        result = runner.invoke(app, ["report", str(build_dir), "--jobs", jobs])
        assert result.exit_code == 0, result.output
        report = build_dir / REPORT_DIR
        drawn[jobs] = {p.name: p.read_bytes() for p in sorted(report.iterdir())}
    one, two = drawn["1"], drawn["2"]
    assert sorted(one) == sorted(two)
    assert {"index.html", "morph.gif", "stretch.png", "surfaces.png", "morph.png"} <= set(one)
    # report.log holds the times of the parts, which differ run to run (and say nothing of the files)
    assert [name for name in one if one[name] != two[name] and name != LOG] == []


def test_the_garbage_collector_is_given_back_as_it_was_even_when_drawing_fails():
    """The report freezes what is loaded and raises the collector's threshold while it draws (process-wide
    settings): both are restored afterwards, also when a figure raises."""
    import gc

    from softdesign.report.drawing_run import GC_THRESHOLD, collector_for_figures

    before = gc.get_threshold()
    assert before[0] != GC_THRESHOLD
    with pytest.raises(ZeroDivisionError), collector_for_figures():
        assert gc.get_threshold()[0] == GC_THRESHOLD and gc.get_freeze_count() > 0
        _ = 1 / 0
    assert gc.get_threshold() == before and gc.get_freeze_count() == 0
