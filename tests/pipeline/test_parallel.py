"""Per-q work on worker processes (issue 19): the same outputs, in the same order, whatever --jobs is."""

from __future__ import annotations

import json
import multiprocessing
import os
import re
import resource
import time
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.errors import MeshError
from softdesign.pipeline.bounds import VERTICES_PER_WORKER
from softdesign.pipeline.parallel import (
    MAX_JOBS,
    available_cores,
    checked_jobs,
    jobs_for_build,
    map_per_q,
    settle_workers,
)
from tests.helpers.paths import REPO

runner = CliRunner()
#: The one file that differs between two runs of the same build whatever the jobs: how the run went.
RUN_LOG = "run.log.json"


def _pid_and_square(q: float) -> tuple[int, float]:
    return os.getpid(), q * q


def _refuse_half(q: float) -> float:
    if q == 0.5:
        raise MeshError(f"q={q:.3f}: the solid folds at l=0.25")
    return q


def test_results_come_back_in_order_from_other_processes():
    q_values = [i / 6 for i in range(7)]
    with jobs_for_build(2):
        done = map_per_q(_pid_and_square, q_values)
    assert [square for _, square in done] == [q * q for q in q_values]
    assert {pid for pid, _ in done} - {os.getpid()}, "no q ran in a worker process"


#: CPU seconds each worker spends in :func:`_busy`: far above the kernel's accounting tick (1-10 ms).
BUSY_CPU_S = 0.05


def _busy(q: float) -> float:
    start = time.process_time()
    while time.process_time() - start < BUSY_CPU_S:
        pass
    return q


def _children_cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def test_settled_workers_have_ended_and_their_cpu_time_is_counted():
    # a build goes on while its workers end; a measurement settles them first (RUSAGE_CHILDREN counts reaped ones)
    before = _children_cpu_s()
    with jobs_for_build(2):
        assert map_per_q(_busy, [0.0, 1.0]) == [0.0, 1.0]
    settle_workers()
    assert multiprocessing.active_children() == []
    assert _children_cpu_s() - before >= 2 * BUSY_CPU_S * 0.9  # both workers' loops, less the accounting's tick


def test_one_job_or_a_bound_of_one_runs_in_this_process():
    with jobs_for_build(1):
        assert {pid for pid, _ in map_per_q(_pid_and_square, [0.0, 0.5, 1.0])} == {os.getpid()}
    with jobs_for_build(4):
        assert {pid for pid, _ in map_per_q(_pid_and_square, [0.0, 0.5, 1.0], most=1)} == {os.getpid()}
    assert {pid for pid, _ in map_per_q(_pid_and_square, [0.0, 1.0])} == {os.getpid()}  # outside a build: 1 job


def test_an_error_in_a_worker_arrives_with_its_type_and_message():
    with jobs_for_build(2), pytest.raises(MeshError, match=r"q=0\.500: the solid folds at l=0\.25"):
        map_per_q(_refuse_half, [0.0, 0.5, 1.0])


def test_the_default_is_the_cores_this_process_may_use():
    assert checked_jobs(None) == min(len(os.sched_getaffinity(0)), MAX_JOBS) == min(available_cores(), MAX_JOBS)
    assert checked_jobs(1) == 1 and checked_jobs(MAX_JOBS) == min(available_cores(), MAX_JOBS)  # capped (issue 45)


@pytest.mark.parametrize("command", ["build", "export"])
@pytest.mark.parametrize("jobs", ["0", "-1", str(MAX_JOBS + 1)])
def test_jobs_outside_the_bound_is_refused_before_any_work(tmp_path, jobs, command):
    out = tmp_path / "out"
    result = runner.invoke(app, [command, str(REPO / "configs" / "demo.yaml"), "--out", str(out), "--jobs", jobs])
    assert result.exit_code == 2, result.output
    assert f"--jobs must be 1 to {MAX_JOBS} worker processes, got {jobs}" in result.output
    assert "Traceback" not in result.output and not out.exists()


def test_jobs_that_is_not_a_whole_number_is_refused(tmp_path):
    out = tmp_path / "out"
    result = runner.invoke(app, ["build", str(REPO / "configs" / "demo.yaml"), "--out", str(out), "--jobs", "two"])
    assert result.exit_code == 2 and "--jobs" in result.output and not out.exists()


def _files(folder: Path) -> dict[str, bytes]:
    files = {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}
    assert b'"seconds"' in files.pop(RUN_LOG)
    return files


@pytest.mark.slow
def test_a_build_is_the_same_bytes_with_one_and_two_jobs(tmp_path):
    case = yaml.safe_load((REPO / "configs" / "demo.yaml").read_text())
    for key in ("centerline", "surface"):
        case["final"][key] = str((REPO / "configs" / case["final"][key]).resolve())
    case["export"] = {"q": [0, 0.25, 0.5, 0.75, 1], "angular_count": 64, "spacing_mm": 0.3,
                      "formats": ["stl", "ply", "vtp"], "split_regions": True}
    path = tmp_path / "demo.yaml"
    path.write_text(yaml.safe_dump(case, sort_keys=False))
    built = {}
    for jobs in ("1", "2"):
        out = tmp_path / f"jobs{jobs}"
        result = runner.invoke(app, ["build", str(path), "--out", str(out), "--jobs", jobs])
        assert result.exit_code == 0, result.output
        built[jobs] = _files(out)
    one, two = built["1"], built["2"]
    assert sorted(one) == sorted(two)
    meshes = [name for name in one if name.startswith("meshes/")]
    assert len(meshes) == 5 * (3 + 3)  # per q: 3 formats, and one STL per region (wall, two caps)
    assert one["manifest.json"] == two["manifest.json"]
    manifests = [json.loads(files.pop("manifest.json")) for files in (one, two)]
    vertices = [o["vertices"] for o in manifests[0]["outputs"] if re.fullmatch(r"meshes/q_[0-9.]+\.stl", o["path"])]
    assert len(vertices) == 5
    assert sum(vertices) >= 2 * VERTICES_PER_WORKER  # so that export, too, ran on two workers
    assert [name for name in one if one[name] != two[name]] == []
