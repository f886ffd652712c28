"""Issue 45, nothing outlives its command: a dead worker is one line, output that cannot be written is one line and
exit 1, a killed child leaves no scratch folder, and ``--jobs`` never starts more workers than cores.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import subprocess
import sys
import tempfile

import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.errors import MeshError, SoftdesignError
from softdesign.pipeline.child import SCRATCH_MARKER, SCRATCH_PREFIX, remove_stale_scratch, run_in_child
from softdesign.pipeline.parallel import MAX_JOBS, available_cores, checked_jobs, jobs_for_build, map_items, working_on

runner = CliRunner()
#: A command that fails at once must end this fast, s (python start-up and imports on a loaded machine).
QUICK_S = 60


@pytest.mark.parametrize("args", [["schema"], ["materials", "--json"], ["materials"]])
def test_output_that_cannot_be_written_is_one_line_and_exit_1(args):
    if not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full on this system")
    code = "import sys; from softdesign.cli import main; sys.argv[0] = 'softdesign'; main()"
    with open("/dev/full", "w") as full:
        result = subprocess.run([sys.executable, "-c", code, *args], stdout=full, stderr=subprocess.PIPE, text=True,
                                timeout=QUICK_S, stdin=subprocess.DEVNULL)
    assert result.returncode == 1, result.stderr
    assert "Traceback" not in result.stderr and "Exception ignored" not in result.stderr, result.stderr
    assert result.stderr.splitlines() == [result.stderr.strip()], result.stderr  # one line
    assert "cannot write the standard output (No space left on device)" in result.stderr


def _die_on_two(item: int) -> int:
    if item == 2:
        os.kill(os.getpid(), signal.SIGKILL)  # as the out-of-memory killer would
    return item


def test_a_worker_killed_during_a_stage_is_one_line_and_no_worker_is_left():
    with jobs_for_build(2), working_on("export"), pytest.raises(SoftdesignError) as caught:
        map_items(_die_on_two, [1, 2, 3, 4])
    assert "a worker died (signal 9) during export; the previous build is kept" in str(caught.value)
    assert type(caught.value).exit_code == 1
    assert multiprocessing.active_children() == []


def test_a_child_that_crashes_leaves_no_scratch_folder(tmp_path, monkeypatch):
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    with pytest.raises(MeshError, match="crashed"):
        run_in_child(os.abort, (), 60.0, "the test's child", "nothing to fix")
    assert list(tmp_path.iterdir()) == []


def test_a_scratch_folder_of_a_parent_killed_before_is_removed_only_when_it_is_ours(tmp_path):
    dead = tmp_path / f"{SCRATCH_PREFIX}999999999-abc"
    dead.mkdir()
    (dead / SCRATCH_MARKER).write_bytes(b"")
    no_marker = tmp_path / f"{SCRATCH_PREFIX}999999999-def"
    no_marker.mkdir()
    alive = tmp_path / f"{SCRATCH_PREFIX}{os.getpid()}-ghi"
    alive.mkdir()
    (alive / SCRATCH_MARKER).write_bytes(b"")
    remove_stale_scratch(str(tmp_path))
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([no_marker.name, alive.name])


def test_jobs_are_capped_at_the_cores_with_a_note():
    told: list[str] = []
    assert checked_jobs(MAX_JOBS, note=told.append) == min(available_cores(), MAX_JOBS)
    if available_cores() < MAX_JOBS:
        assert len(told) == 1 and f"--jobs {MAX_JOBS}: capped at the {available_cores()} core(s)" in told[0]
    result = runner.invoke(app, ["report", "no-such-build", "--jobs", str(MAX_JOBS)])
    assert result.exit_code == 2 and "capped at" in result.output
