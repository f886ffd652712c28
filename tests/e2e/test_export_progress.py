"""The export's per-mesh bar in real builds (issue 17): on a terminal it counts every mesh, also from forked workers;
a pipe and ``--json`` get none; the build's files are the same bytes with the bar and without it."""

from __future__ import annotations

import json
import os
import pty
import re
import select
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from softdesign.pipeline.bounds import VERTICES_PER_WORKER
from tests.helpers.attacks import demo_case
from tests.helpers.paths import REPO

Q_VALUES = [0, 0.25, 0.5, 0.75, 1]
CODE = "import sys; from softdesign.cli import main; sys.argv[0] = 'softdesign'; main()"
TIMEOUT_S = 600
#: The one file that differs between two runs of the same build: how the run went (statuses, seconds).
RUN_LOG = "run.log.json"


def _on_a_terminal(*args: str) -> tuple[int, str, str]:
    """Exit code, stdout and what a terminal on stderr received, of ``softdesign ARGS``."""
    master, slave = pty.openpty()
    child = subprocess.Popen([sys.executable, "-c", CODE, *args], stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                             stderr=slave, cwd=REPO)
    os.close(slave)
    received = bytearray()
    deadline = time.monotonic() + TIMEOUT_S
    while time.monotonic() < deadline:
        if select.select([master], [], [], 1.0)[0]:
            try:
                data = os.read(master, 65536)
            except OSError:  # the child closed the terminal
                break
            if not data:
                break
            received += data
    os.close(master)
    stdout = child.communicate(timeout=TIMEOUT_S)[0]
    return child.returncode, stdout.decode(), received.decode(errors="replace")


def _files(folder: Path) -> dict[str, bytes]:
    files = {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}
    assert b'"seconds"' in files.pop(RUN_LOG)
    return files


@pytest.mark.slow
def test_the_bar_counts_every_mesh_on_a_terminal_and_changes_no_byte(tmp_path):
    case = demo_case(tmp_path)
    spec = yaml.safe_load(case.read_text())
    spec["export"] = {"q": Q_VALUES, "angular_count": 64, "spacing_mm": 0.3}  # enough vertices for two workers
    case.write_text(yaml.safe_dump(spec, sort_keys=False))

    code, _, screen = _on_a_terminal("build", str(case), "--out", str(tmp_path / "tty"), "--jobs", "2")
    assert code == 0, screen
    for done, q in enumerate(Q_VALUES, start=1):
        assert re.search(rf"\[\d+/\d+\] export: mesh q = {q:g} done .*{done}/{len(Q_VALUES)}", screen), screen
    assert re.search(r"\d+/\d+ export: done in", screen), screen

    piped = subprocess.run([sys.executable, "-c", CODE, "build", str(case), "--out", str(tmp_path / "pipe"),
                            "--jobs", "2"], capture_output=True, text=True, cwd=REPO, timeout=TIMEOUT_S,
                           stdin=subprocess.DEVNULL)
    assert piped.returncode == 0, piped.stderr
    assert "\x1b" not in piped.stderr and "mesh q" not in piped.stderr and "export: done in" in piped.stderr

    with_bar, without = _files(tmp_path / "tty"), _files(tmp_path / "pipe")
    assert sorted(with_bar) == sorted(without)
    assert [name for name in with_bar if with_bar[name] != without[name]] == []
    manifest = json.loads(without["manifest.json"])
    vertices = [o["vertices"] for o in manifest["outputs"] if re.fullmatch(r"meshes/q_[0-9.]+\.stl", o["path"])]
    assert len(vertices) == len(Q_VALUES) and sum(vertices) >= 2 * VERTICES_PER_WORKER  # export ran on two workers

    code, stdout, screen = _on_a_terminal("pose", str(case), "--q", "1", "--output", str(tmp_path / "pose.stl"),
                                          "--out", str(tmp_path / "pipe"), "--force", "--json")
    assert code == 0, screen
    json.loads(stdout)
    assert "mesh q" not in screen and "\x1b[" not in screen  # --json: no bar, however long the build
