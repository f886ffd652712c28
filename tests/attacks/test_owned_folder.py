"""Issue 36, data loss: a rebuild, a report or a pose never deletes or overwrites what softdesign did not write.

Each test plants what a user (or a hostile neighbour in a shared /tmp) would,
runs the command, and checks the planted file is still there, byte for byte,
and the command said why it refused.
"""

from __future__ import annotations

import os
import shutil

import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.errors import ConfigError
from softdesign.pipeline.layout import lock_name
from softdesign.pipeline.lock import BuildLock
from softdesign.report.writer import PAGE, REPORT_DIR, commit_folder, write_report
from tests.helpers.attacks import assert_refused, demo_case
from tests.helpers.folders import snapshot

runner = CliRunner()


@pytest.mark.parametrize(
    ("planted", "named"),
    [
        ("meshes/notes.txt", "meshes/notes.txt"),
        ("fit/mine/a.txt", "fit/mine/"),
        (f"{REPORT_DIR}/notes.txt", f"{REPORT_DIR}/notes.txt"),
    ],
    ids=["file-in-meshes", "folder-under-stage", "file-beside-report"],
)
def test_a_user_file_inside_the_build_folder_refuses_the_rebuild_and_stays(out, tmp_path, planted, named):
    case = demo_case(tmp_path)
    commit_folder(out / REPORT_DIR, {PAGE: b"the report's page"})  # a report of softdesign's, with its marker
    user_file = out / planted
    user_file.parent.mkdir(parents=True, exist_ok=True)
    user_file.write_text("the user's own notes\n")
    before = snapshot(out)
    result = runner.invoke(app, ["build", str(case), "--out", str(out)])
    assert_refused(result, named, "softdesign did not write", "move them out")
    assert snapshot(out) == before  # refused before any work: not a byte of the folder changed


def test_the_lock_does_not_follow_a_symlink_planted_beside_the_build_folder(out, tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("someone else's file\n")
    (out.parent / lock_name(out.name)).unlink(missing_ok=True)
    (out.parent / lock_name(out.name)).symlink_to(victim)
    result = runner.invoke(app, ["build", str(demo_case(tmp_path)), "--out", str(out)])
    assert_refused(result, "symbolic link", str(victim))
    assert victim.read_text() == "someone else's file\n"


def test_a_run_that_ends_releases_the_lock_and_a_killed_one_is_named_by_the_next(tmp_path):
    build = tmp_path / "build"
    with BuildLock(build) as lock:
        assert lock.notes == []
    assert not (tmp_path / lock_name("build")).exists()  # ended: no lock file outlives its run (issue 34)
    (tmp_path / lock_name("build")).write_text("999999999 on elsewhere\n")  # what a killed run leaves
    with BuildLock(build) as lock:
        assert len(lock.notes) == 1 and "999999999 on elsewhere" in lock.notes[0], lock.notes
        assert "ended without finishing" in lock.notes[0]
    assert not (tmp_path / lock_name("build")).exists()


def test_a_run_that_locked_a_file_removed_under_it_starts_over_on_the_paths_file(tmp_path, monkeypatch):
    # the race removing the lock file opens: B opens the file, A (holding it) removes it and ends, B locks the
    # removed file; B must not go on holding a file no other run can see
    import fcntl

    build = tmp_path / "build"
    real_flock = fcntl.flock
    removed = []

    def flock_after_removal(fd, how):
        if not removed:  # the first lock taken: its file is removed first, as an ending run does
            removed.append(True)
            (tmp_path / lock_name("build")).unlink()
        return real_flock(fd, how)

    monkeypatch.setattr(fcntl, "flock", flock_after_removal)
    with BuildLock(build):
        path = tmp_path / lock_name("build")
        assert path.exists() and path.read_text().startswith(f"{__import__('os').getpid()} on ")
    assert removed == [True] and not (tmp_path / lock_name("build")).exists()


def test_report_removes_only_its_own_temporary_folders(tmp_path):
    target = tmp_path / REPORT_DIR
    not_a_pid = tmp_path / ".report-notes"
    like_ours = tmp_path / ".report-999999999-0123456789ab"  # a dead pid, but no marker: not a report's
    for folder in (not_a_pid, like_ours):
        folder.mkdir()
        (folder / "keep.txt").write_text("mine\n")
    commit_folder(target, {PAGE: b"page"})
    commit_folder(target, {PAGE: b"page 2"})
    assert (not_a_pid / "keep.txt").read_text() == "mine\n"
    assert (like_ours / "keep.txt").read_text() == "mine\n"
    assert (target / PAGE).read_bytes() == b"page 2"


def test_report_refuses_a_symlinked_report_folder_and_leaves_nothing_behind(tmp_path):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "index.html").write_text("not the report's\n")
    build = tmp_path / "build"
    build.mkdir()
    (build / REPORT_DIR).symlink_to(elsewhere)
    with pytest.raises(ConfigError, match="symbolic link"):
        commit_folder(build / REPORT_DIR, {PAGE: b"page"})
    assert (elsewhere / "index.html").read_text() == "not the report's\n"
    assert sorted(p.name for p in build.iterdir()) == [REPORT_DIR]  # no .report-* left to block the next build
    assert (build / REPORT_DIR).is_symlink()


def test_report_takes_the_build_lock_before_reading_anything(out):
    parts: list[str] = []
    with BuildLock(out), pytest.raises(ConfigError, match="another softdesign run"):
        write_report(out, progress=lambda name, seconds: parts.append(name))
    assert parts == []  # refused before loading: a page never mixes a build being replaced with its successor


def test_pose_output_never_overwrites_the_cases_surface(tmp_path):
    surface = tmp_path / "surface.stl"
    case = demo_case(tmp_path)
    text = case.read_text()
    source = next(line.split(": ", 1)[1] for line in text.splitlines() if line.strip().startswith("surface:"))
    shutil.copyfile(source.strip(), surface)
    case.write_text(text.replace(source, str(surface)))
    before = surface.read_bytes()
    result = runner.invoke(app, ["pose", str(case), "--q", "0.5", "--output", str(surface),
                                 "--out", str(tmp_path / "build")])
    assert_refused(result, "an input of this case", "write to another file")
    assert surface.read_bytes() == before
    assert not os.path.exists(tmp_path / "build")  # refused before the build


def test_a_report_of_an_older_version_without_marker_is_still_ours(out, prior_build, tmp_path):
    report = out / REPORT_DIR
    report.mkdir()
    (report / PAGE).write_text("<html>an older report</html>")
    (report / "morph.png").write_bytes(b"png")
    # the case as deep as the prior build's (the stage keys name the inputs relative to the case file): every stage
    # is reused, with or without xdist (whose workers' folders lie one level deeper)
    folder = tmp_path
    while len(folder.parts) < len(prior_build.parent.parts):
        folder = folder / "case"
    folder.mkdir(parents=True, exist_ok=True)
    result = runner.invoke(app, ["build", str(demo_case(folder)), "--out", str(out), "--jobs", "1"])
    assert result.exit_code == 0, result.output  # rebuilt, outputs unchanged: the report is kept (issue 34)
    assert (report / PAGE).read_text() == "<html>an older report</html>"
    commit_folder(report, {PAGE: b"new page"})  # and a new report replaces it
    assert (report / PAGE).read_bytes() == b"new page"


def test_pcc_reconstruct_never_writes_over_its_readings(tmp_path):
    readings = tmp_path / "tips.csv"
    readings.write_text("t,a,b,c\n0,100,100,100\n1,100,101,99\n")
    before = readings.read_bytes()
    result = runner.invoke(app, ["pcc", "reconstruct", str(readings), "--d", "5", "--shapes-dir", str(tmp_path)])
    assert_refused(result, "--shapes-dir", "an input of this case")
    assert readings.read_bytes() == before
