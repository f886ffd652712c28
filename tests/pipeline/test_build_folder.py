"""The build folder is a transaction: replaced whole or not at all, one run at a time, never over a user's files.

Every refusal exits 2 with the path and the fix and no traceback, and leaves
the folder there byte for byte as it was (every file hashed before and after).
"""

from __future__ import annotations

import ctypes
import errno
import json
import os
import pathlib
import select
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner, Result

from softdesign.cli import app
from tests.helpers.folders import assert_exactly_as_listed, leftovers, snapshot
from tests.helpers.paths import REPO

runner = CliRunner()
#: how long a child build may take (python start-up, imports, one export of the coarse demo case)
CHILD_TIMEOUT_S = 300


def write_demo(folder: Path, name: str = "demo", **export) -> Path:
    """configs/demo.yaml with absolute inputs and a coarse export (quick), written to ``folder/<name>.yaml``."""
    case = yaml.safe_load((REPO / "configs" / "demo.yaml").read_text())
    for key in ("centerline", "surface"):
        case["final"][key] = str((REPO / "configs" / case["final"][key]).resolve())
    case["export"] = {"q": [0, 1], "angular_count": 48, "spacing_mm": 1.0, **export}
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump(case, sort_keys=False))
    return path


def run(*args: str | Path) -> Result:
    return runner.invoke(app, [str(a) for a in args])


def built(case: Path, out: Path) -> Result:
    """A build on one process (the parallel path is tests/pipeline/test_parallel.py's; a pool of two would add
    about a second of CPU to each of this file's builds)."""
    result = run("build", case, "--out", out, "--jobs", "1")
    assert result.exit_code == 0, result.output
    return result


@pytest.fixture(scope="module")
def demo_built(tmp_path_factory) -> tuple[Path, Path]:
    """``write_demo``'s case and its build, made once for the file: the tests that start from a finished build of
    the coarse demo copy it (:func:`copy_of_demo`) rather than build it again."""
    base = tmp_path_factory.mktemp("demo-built")
    case = write_demo(base)
    built(case, base / "build")
    return case, base / "build"


def copy_of_demo(demo_built: tuple[Path, Path], folder: Path, out: Path) -> Path:
    """``write_demo(folder)`` with ``demo_built``'s build copied to ``out``: as if built there.  The case file names
    its inputs relative to itself, and ``folder`` (a test's ``tmp_path``) lies as deep as the module's folder, so
    the stage keys match and a next build reuses what did not change, as on a build of its own."""
    case, build = demo_built
    assert len(folder.parts) == len(case.parent.parts), (folder, case)
    mine = write_demo(folder)
    assert mine.read_text() == case.read_text()
    shutil.copytree(build, out)
    return mine


def assert_refused(result: Result, *needles: str) -> None:
    """Exit 2, a message with every needle, no traceback."""
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    assert result.exception is None or isinstance(result.exception, SystemExit)
    for needle in needles:
        assert needle in result.output, (needle, result.output)


def contents(folder: Path) -> tuple[dict[str, str], dict]:
    """The files of a build but its manifest and run log (how the run went: seconds, ran or skipped), and the
    manifest."""
    files = snapshot(folder)
    files.pop("manifest.json")
    files.pop("run.log.json")
    return files, json.loads((folder / "manifest.json").read_text())


def child_env() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": str(REPO)}


# --- 1. one atomic step: killed anywhere in the commit, the folder is the old one or the new one ---------------

KILL_AT = """
import json, os, signal, sys
from pathlib import Path
import softdesign.pipeline.store as store
import softdesign.pipeline.swap as swap

call, number, when, fallback = json.loads(sys.argv[1])
if fallback:
    swap._renameat2 = None  # as on a system (or file system) without renameat2(RENAME_EXCHANGE)
counts = {}

def hooked(name, function):
    def wrapped(*args, **kwargs):
        counts[name] = counts.get(name, 0) + 1
        hit = name == call and counts[name] == number
        if hit and when == "during":  # part of the old folder already removed
            for path in sorted(p for p in Path(args[0]).rglob("*") if p.is_file())[:3]:
                path.unlink()
        if hit and when in ("before", "during"):
            os.kill(os.getpid(), signal.SIGKILL)
        result = function(*args, **kwargs)
        if hit and when == "after":
            os.kill(os.getpid(), signal.SIGKILL)
        return result
    return wrapped

os.link = hooked("link", os.link)
os.rename = hooked("rename", os.rename)
swap.exchange = hooked("exchange", swap.exchange)
store.remove_folder = hooked("remove", store.remove_folder)
from softdesign.cli import app
sys.argv = ["softdesign", *sys.argv[2:]]
app()
"""

#: (call, number, when, two-rename fallback) -> what the folder is right after the kill
KILL_POINTS = {
    "linking-kept-files": (("link", 3, "before", False), "old"),
    "before-the-exchange": (("exchange", 1, "before", False), "old"),
    "after-the-exchange": (("exchange", 1, "after", False), "new"),
    "removing-the-old-folder": (("remove", 1, "during", False), "new"),
    "fallback-before-any-rename": (("rename", 1, "before", True), "old"),
    "fallback-between-the-renames": (("rename", 1, "after", True), "missing"),
    "fallback-after-both-renames": (("rename", 2, "after", True), "new"),
}


def exchange_works(folder: Path) -> bool:
    """Whether renameat2(RENAME_EXCHANGE) swaps two folders in ``folder`` on this system."""
    from softdesign.pipeline import swap

    first, second = folder / "probe-a", folder / "probe-b"
    first.mkdir()
    second.mkdir()
    try:
        return swap.exchange(first, second)
    finally:
        first.rmdir()
        second.rmdir()


@pytest.fixture(scope="module")
def old_and_new(tmp_path_factory, demo_built) -> tuple[Path, Path, Path]:
    """A build of the demo case, the case file edited (the export changes), and the build the edit gives from it."""
    base = tmp_path_factory.mktemp("transaction")
    old = base / "old"
    copy_of_demo(demo_built, base, old)
    case = write_demo(base, angular_count=56)
    new = base / "new"
    shutil.copytree(old, new)
    built(case, new)
    return case, old, new


@pytest.mark.slow
@pytest.mark.parametrize("point", list(KILL_POINTS))
def test_a_build_killed_during_its_commit_leaves_the_old_folder_or_the_new_one(point, old_and_new, tmp_path):
    (call, number, when, fallback), state = KILL_POINTS[point]
    if not fallback and not exchange_works(tmp_path):
        pytest.skip("renameat2(RENAME_EXCHANGE) is not available here; the fallback points cover this system")
    case, old, new = old_and_new
    out = tmp_path / "build"
    shutil.copytree(old, out)
    spec = json.dumps([call, number, when, fallback])
    killed = subprocess.run(
        [sys.executable, "-c", KILL_AT, spec, "build", str(case), "--out", str(out), "--jobs", "1"],
        capture_output=True, text=True, env=child_env(), timeout=CHILD_TIMEOUT_S,
    )
    assert killed.returncode == -signal.SIGKILL, killed.stderr
    if state == "old":
        assert snapshot(out) == snapshot(old)
    elif state == "new":
        assert contents(out) == contents(new)
        assert_exactly_as_listed(out)
    else:  # between the two renames: the name is free and the old folder waits under its trash name
        assert not out.exists() and any(".build.trash-" in name for name in leftovers(tmp_path, "build"))
        from softdesign.pipeline.swap import repair

        repair(out)
        assert snapshot(out) == snapshot(old)
    # the next run clears what the killed one left and ends with the new folder
    built(case, out)
    assert contents(out) == contents(new)
    assert_exactly_as_listed(out)
    assert leftovers(tmp_path, "build") == []


def test_the_next_run_restores_a_folder_set_aside_by_an_interrupted_swap(old_and_new, tmp_path):
    case, old, _ = old_and_new
    out = tmp_path / "build"
    shutil.copytree(old, tmp_path / ".build.trash-123-abc")  # the two-rename swap cut between its renames
    result = built(case, out)
    assert "restored the previous build folder" in result.output
    assert "[ingest] skipped" in result.output  # the restored folder's stages are reused: it was complete
    assert_exactly_as_listed(out)
    assert leftovers(tmp_path, "build") == []


@pytest.mark.slow
def test_the_folder_holds_what_its_manifest_lists_and_kept_files_are_linked(tmp_path):
    out = tmp_path / "build"
    built(write_demo(tmp_path, q=[0, 0.25, 1]), out)
    assert (out / "meshes" / "q_0.250.stl").is_file()
    inode = (out / "fit" / "surface.npz").stat().st_ino
    built(write_demo(tmp_path, q=[0, 1]), out)
    # the mesh of a q no longer asked for went with the old folder
    assert sorted(p.name for p in (out / "meshes").iterdir()) == ["q_0.000.stl", "q_1.000.stl"]
    assert_exactly_as_listed(out)
    # the cached fit reached the new folder as a hard link to the same file, not a copy
    assert (out / "fit" / "surface.npz").stat().st_ino == inode
    assert leftovers(tmp_path, "build") == []


# --- 2. a commit that fails part-way: the old folder as it was, exit 2 with the path --------------------------


def refuse_exchange(monkeypatch: pytest.MonkeyPatch) -> None:
    """renameat2 answers EACCES, as it does when the parent folder became read-only."""
    from softdesign.pipeline import swap

    def refusing(*args) -> int:
        ctypes.set_errno(errno.EACCES)
        return -1

    monkeypatch.setattr(swap, "_renameat2", refusing)


def refuse_second_rename(monkeypatch: pytest.MonkeyPatch) -> None:
    """Two-rename swap: the old folder moves aside, then moving the new one in is refused (EACCES)."""
    from softdesign.pipeline import swap

    monkeypatch.setattr(swap, "_renameat2", None)
    calls = []
    rename = os.rename

    def second_refused(source, target) -> None:
        calls.append(target)
        if len(calls) == 2:
            raise PermissionError(errno.EACCES, "Permission denied", str(source), None, str(target))
        rename(source, target)

    monkeypatch.setattr(os, "rename", second_refused)


def fill_the_disk(monkeypatch: pytest.MonkeyPatch) -> None:
    """Writing a mesh fails as on a full disk: write() raises ENOSPC without a file name."""
    write_bytes = pathlib.Path.write_bytes

    def full(self: Path, data: bytes) -> int:
        if self.suffix == ".stl":
            raise OSError(errno.ENOSPC, "No space left on device")
        return write_bytes(self, data)

    monkeypatch.setattr(pathlib.Path, "write_bytes", full)


@pytest.mark.slow
@pytest.mark.parametrize(
    "fault, needles",
    [
        (refuse_exchange, ["Permission denied", "make it writable"]),
        (refuse_second_rename, ["Permission denied", "make it writable"]),
        (fill_the_disk, ["No space left on device", "meshes/q_0.000.stl", "free space"]),
    ],
    ids=["read-only-parent", "read-only-parent-two-renames", "disk-full"],
)
def test_a_commit_that_fails_part_way_leaves_the_old_folder_as_it_was(fault, needles, demo_built, tmp_path,
                                                                     monkeypatch):
    out = tmp_path / "build"
    copy_of_demo(demo_built, tmp_path, out)
    before = snapshot(out)
    case = write_demo(tmp_path, angular_count=56)
    fault(monkeypatch)
    result = run("build", case, "--out", out, "--jobs", "1")
    assert_refused(result, f"build folder {out}", str(tmp_path), *needles)
    assert snapshot(out) == before
    assert leftovers(tmp_path, "build") == []


def test_an_out_that_is_a_file_or_below_a_file_is_refused(tmp_path):
    case = write_demo(tmp_path)
    notes = tmp_path / "notes.txt"
    notes.write_text("mine")
    assert_refused(run("build", case, "--out", notes), f"build folder {notes}: is a file", "--out")
    assert_refused(run("build", case, "--out", notes / "build"), str(notes), "a file is in the way")
    assert notes.read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["demo.yaml", "notes.txt"]


# --- 3. one run at a time ---------------------------------------------------------------------------------------

HOLD_IN_EXPORT = """
import sys, time
import softdesign.pipeline.stages.export as export_stage

def holding(*args, **kwargs):
    print("exporting", flush=True)
    time.sleep(120)

export_stage.mesh_bytes = holding
from softdesign.cli import app
sys.argv = ["softdesign", *sys.argv[1:]]
app()
"""


@pytest.mark.slow
def test_a_second_build_into_a_folder_being_built_is_refused_naming_the_first(demo_built, tmp_path):
    out = tmp_path / "build"
    copy_of_demo(demo_built, tmp_path, out)
    before = snapshot(out)
    case = write_demo(tmp_path, angular_count=56)
    first = subprocess.Popen(
        [sys.executable, "-c", HOLD_IN_EXPORT, "build", str(case), "--out", str(out)],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, env=child_env(),
    )
    try:
        ready, _, _ = select.select([first.stdout], [], [], CHILD_TIMEOUT_S)
        assert ready and first.stdout.readline().strip() == "exporting"
        second = run("build", case, "--out", out)
        assert_refused(second, f"pid {first.pid} on ", "another softdesign run", str(out), "--out")
    finally:
        first.kill()
        first.wait()
    assert snapshot(out) == before
    # the kernel let go of the killed run's lock: the next build goes through
    built(case, out)
    assert_exactly_as_listed(out)
    assert leftovers(tmp_path, "build") == []


# --- 4. what --out may be -----------------------------------------------------------------------------------------


def test_out_must_be_a_softdesign_build_an_empty_folder_or_new(tmp_path):
    case = write_demo(tmp_path)
    papers = tmp_path / "papers"
    papers.mkdir()
    (papers / "thesis.tex").write_text("chapter 1")
    assert_refused(run("build", case, "--out", papers), str(papers), "thesis.tex", "no softdesign manifest.json",
                   "--out")
    assert snapshot(papers) == {"thesis.tex": snapshot(papers)["thesis.tex"]}
    empty = tmp_path / "empty"
    empty.mkdir()
    built(case, empty)
    assert_exactly_as_listed(empty)


def test_a_build_folder_holding_files_of_its_user_is_not_replaced(demo_built, tmp_path):
    out = tmp_path / "build"
    case = copy_of_demo(demo_built, tmp_path, out)
    (out / "notes.txt").write_text("what I saw in the q = 1 mesh")
    before = snapshot(out)
    assert_refused(run("build", case, "--out", out), str(out), "notes.txt", "move them out")
    assert snapshot(out) == before


@pytest.mark.slow
def test_out_may_not_hold_the_input_files(tmp_path):
    data = tmp_path / "data" / "demo"
    shutil.copytree(REPO / "data" / "demo", data)
    case = tmp_path / "case.yaml"
    case.write_text(
        "name: demo\nfinal: {centerline: data/demo/centerline.vtp, surface: data/demo/surface.stl}\n"
        "export: {q: [0, 1], angular_count: 48, spacing_mm: 1.0}\n"
    )
    before = snapshot(tmp_path / "data")
    for out in (data, tmp_path / "data", tmp_path):
        assert_refused(run("build", case, "--out", out), f"build folder {out}", "holds the input file", "--out")
    assert snapshot(tmp_path / "data") == before
    built(case, data / "build")  # beside the inputs is fine: the build replaces only its own folder


# --- 8. names beside the build folder are matched exactly, never as patterns ---------------------------------------


def test_a_build_folder_named_like_a_pattern_touches_only_its_own_leftovers(tmp_path):
    builds = tmp_path / "builds"
    builds.mkdir()
    decoys = [builds / ".other.staging-999999-abc123", builds / ".x.trash-999999-def456", builds / ".a.staging-1"]
    for decoy in decoys:
        decoy.mkdir()
        (decoy / "keep.txt").write_text("not softdesign's")
    built(write_demo(tmp_path), builds / "*")
    assert all((decoy / "keep.txt").read_text() == "not softdesign's" for decoy in decoys)
    assert sorted(p.name for p in builds.iterdir()) == sorted(["*", *(d.name for d in decoys)])  # no lock left
