"""`make bench`'s targets (issue 46): every one listed with its figure and verdict, validate judged on CPU, and
``--fail-on-miss`` failing only beyond the margin.  Figures are fed in by hand: no timing is asserted."""

from __future__ import annotations

import pytest

from tests.e2e.test_bench import bench  # noqa: F401  (the fixture: pipelines/bench.py as a module)


@pytest.fixture
def judged(bench):  # noqa: F811
    """The run's list of judged targets, empty for the test and restored after it."""
    saved = list(bench.JUDGED)
    bench.JUDGED.clear()
    yield bench.JUDGED
    bench.JUDGED[:] = saved


def test_validate_is_judged_on_its_cpu_time(bench, judged):  # noqa: F811
    lines = bench.startup_lines({"help_s": 0.2, "help_cpu_s": 0.1, "validate_s": 0.5, "validate_cpu_s": 0.7})
    validate_line = next(line for line in lines if "validate" in line)
    assert "MISSED" in validate_line and "s cpu" in validate_line  # 0.5 s wall would be met: the CPU is judged
    assert [(j.name, j.figure, j.ok) for j in judged] == [("softdesign --help, wall", 0.2, True),
                                                          ("softdesign validate, cpu", 0.7, False)]


def test_the_margin_separates_a_near_miss_from_a_far_one(bench):  # noqa: F811
    target = bench.TARGET_FLOOR_RATIO
    near = bench.Judged("ratio", target * (1 + bench.MISS_MARGIN / 2), target, "x", False)
    far = bench.Judged("ratio", target * (1 + 2 * bench.MISS_MARGIN), target, "x", False)
    met = bench.Judged("ratio", target, target, "x", True)
    assert not near.far_off() and far.far_off() and not met.far_off()
    assert bench.Judged("linear", None, None, "", False).far_off()  # a yes/no target has no margin
    assert not bench.Judged("linear", None, None, "", None).far_off()  # not measured is no miss


def test_the_summary_lists_every_target_with_its_figure_and_verdict(bench, judged):  # noqa: F811
    bench.judge("build / I/O floor, scaled case", 2.5, 3.0, "x")
    bench.judge("peak memory, scaled case", 2500.0, 2048.0, "MiB")
    bench.judge("linear in frames", None, None, "", None)
    lines = bench.summary_lines(judged)
    assert lines[0].startswith("every target (3)")
    assert "2.50 x" in lines[1] and "<= 3 x" in lines[1] and lines[1].rstrip().endswith("met")
    assert "2500.00 MiB" in lines[2] and lines[2].rstrip().endswith("MISSED")
    assert lines[3].rstrip().endswith("not measured")
    assert "1 missed, 1 of them by more than 20%" in lines[-1]  # 2500 MiB is 22 % over 2048


def test_a_sub_benchmark_s_verdicts_are_counted(bench, judged, monkeypatch):  # noqa: F811
    class Done:
        returncode = 1
        stdout = "volume mesh, sample: 3.2 s cpu  target 10 s: met\naorta: 12.5 s cpu  target 10 s: MISSED\nnote\n"
        stderr = ""

    monkeypatch.setattr(bench.subprocess, "run", lambda *a, **k: Done())
    assert len(bench.script_lines("bench_volume.py")) == 3
    assert [j.ok for j in judged] == [True, False] and judged[1].far_off()
