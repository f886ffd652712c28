"""Issue 36, left running: a build killed (SIGKILL) while its forked workers run leaves none of them behind.

A worker that outlived its build slept on its pipe for ever, held about 135 MB
and the build folder's lock, so every later build was refused.  Each test
starts a real ``build --jobs 2``, kills it with SIGKILL as soon as its workers
exist during one stage, then checks that every worker is gone within seconds
and that the next build of the same folder proceeds and says the last one was
killed.
"""

from __future__ import annotations

import os
import queue
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from tests.helpers.attacks import BUILD_TIMEOUT_S, demo_case, run_limited

#: How long killed workers may take to be gone, s (the kernel signals them at once; reaping is quick).
GONE_WITHIN_S = 15.0
#: How long to wait for the stage's workers to appear, s (a loaded CI machine builds the demo slowly).
STAGE_WAIT_S = 240.0


def _children(pid: int) -> set[int]:
    found: set[int] = set()
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            found |= {int(c) for c in (task / "children").read_text().split()}
        except OSError:
            continue
    return found


def _running(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state not in ("Z", "X")


def _lines(stream, into: queue.Queue) -> None:
    for line in stream:
        into.put(line)


def _kill_when_workers_run(stage: str, tmp_path: Path) -> tuple[set[int], Path, Path]:
    """Start a --jobs 2 build, SIGKILL it once ``stage`` has started workers; their pids, the case, the folder."""
    # 33 q: the coarse export's meshes are worth two workers (softdesign.pipeline.bounds.VERTICES_PER_WORKER: with
    # five q export had one, and the export case killed the build during feasibility's pool instead), and they live
    # long enough to see
    case = demo_case(tmp_path, export={"q": [k / 32 for k in range(33)]})
    out = tmp_path / "build"
    code = "import sys; from softdesign.cli import main; sys.argv[0] = 'softdesign'; main()"
    build = subprocess.Popen([sys.executable, "-c", code, "build", str(case), "--out", str(out), "--jobs", "2"],
                             stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    lines: queue.Queue = queue.Queue()
    threading.Thread(target=_lines, args=(build.stderr, lines), daemon=True).start()
    workers: set[int] = set()
    try:
        deadline, started = time.monotonic() + STAGE_WAIT_S, False
        while time.monotonic() < deadline and len(workers) < 2 and build.poll() is None:
            while not lines.empty():
                line = lines.get()
                started = started or f"{stage}: running" in line
            if started:
                workers |= _children(build.pid)
            time.sleep(0.005)
        assert workers, f"no workers seen during {stage} (build exit {build.poll()})"
        os.kill(build.pid, signal.SIGKILL)
        build.wait(30)
    finally:
        if build.poll() is None:
            build.kill()
            build.wait(30)
    return workers, case, out


@pytest.mark.slow
@pytest.mark.parametrize("stage", ["feasibility", "export"])
def test_workers_die_with_a_killed_build_and_the_next_build_proceeds(stage, tmp_path):
    workers, case, out = _kill_when_workers_run(stage, tmp_path)
    try:
        deadline = time.monotonic() + GONE_WITHIN_S
        while time.monotonic() < deadline and any(_running(pid) for pid in workers):
            time.sleep(0.05)
        assert [pid for pid in workers if _running(pid)] == [], "workers outlived their killed build"
    finally:
        for pid in workers:  # on the old code: end the orphans this test made, by their id
            if _running(pid):
                os.kill(pid, signal.SIGKILL)
    result = run_limited("build", str(case), "--out", str(out), "--jobs", "2", timeout=BUILD_TIMEOUT_S)
    assert result.returncode == 0, result.stderr
    assert "ended without finishing" in result.stderr, result.stderr
