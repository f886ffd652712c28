"""Issue 45, writes that destroy: an output never replaces what is not a regular file, what the user did not ask to
replace, or a file inside a build folder; its temporary name cannot be predicted or redirected by a link.
"""

from __future__ import annotations

import os
import shutil
import stat

import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.config import load_case
from softdesign.errors import ConfigError
from softdesign.io.atomic import write_bytes_atomically
from softdesign.pipeline.layout import MANIFEST, lock_name
from softdesign.pipeline.store import Staging
from softdesign.pipeline.swap import repair
from tests.helpers.attacks import assert_refused, demo_case
from tests.helpers.paths import REPO

DEMO_DATA = REPO / "data" / "demo"

runner = CliRunner()


def test_schema_output_refuses_a_fifo_and_leaves_it_a_fifo(tmp_path):
    fifo = tmp_path / "f"
    os.mkfifo(fifo)
    result = runner.invoke(app, ["schema", "--output", str(fifo), "--force"])
    assert_refused(result, str(fifo), "a FIFO", "not a regular file")
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)


def test_the_atomic_writer_refuses_a_device_a_folder_and_a_link(tmp_path):
    # never the real /dev/null: a writer that is wrong would replace it for the whole machine
    folder = tmp_path / "folder"
    folder.mkdir()
    link = tmp_path / "link.json"
    victim = tmp_path / "victim.txt"
    victim.write_text("the user's\n")
    link.symlink_to(victim)
    targets = [(folder, "a folder"), (link, "a symbolic link")]
    device = tmp_path / "null"
    if os.geteuid() == 0:  # only root can make a device node: a null device of its own, in tmp_path
        os.mknod(device, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
        targets.append((device, "a character device"))
    for target, kind in targets:
        with pytest.raises(ConfigError, match=kind):
            write_bytes_atomically(target, b"x")
    assert not device.exists() or stat.S_ISCHR(os.lstat(device).st_mode)
    assert victim.read_text() == "the user's\n" and link.is_symlink()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["folder", "link.json", "victim.txt"]
                                                                + (["null"] if device.exists() else []))


def test_a_link_planted_at_the_old_temporary_name_is_not_followed(tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("someone else's file\n")
    target = tmp_path / "schema.json"
    (tmp_path / f".{target.name}.{os.getpid()}.tmp").symlink_to(victim)  # the name the writer used to take
    result = runner.invoke(app, ["schema", "--output", str(target)])
    assert result.exit_code == 0, result.output
    assert victim.read_text() == "someone else's file\n"
    assert stat.S_ISREG(os.lstat(target).st_mode)
    assert [p.name for p in tmp_path.iterdir() if p.name.endswith(".tmp") and not p.is_symlink()] == []


def test_the_output_has_the_permissions_of_a_plain_write(tmp_path):
    target = write_bytes_atomically(tmp_path / "a.txt", b"x")
    mask = os.umask(0o022)
    os.umask(mask)
    assert stat.S_IMODE(os.stat(target).st_mode) == 0o666 & ~mask


@pytest.mark.parametrize("command", [["schema"], ["design", "CASE", "--tolerance-mm", "1", "--out", "B"],
                                     ["pose", "CASE", "--q", "0", "--out", "B"]], ids=["schema", "design", "pose"])
def test_an_existing_output_is_replaced_only_with_force(tmp_path, command):
    replace = {"CASE": str(demo_case(tmp_path)), "B": str(tmp_path / "b")}
    notes = tmp_path / ("notes.stl" if command[0] == "pose" else "notes.txt")
    notes.write_text("the user's notes\n")
    result = runner.invoke(app, [*(replace.get(a, a) for a in command), "--output", str(notes)])
    assert_refused(result, str(notes), "already exists", "--force")
    assert notes.read_text() == "the user's notes\n"
    assert not (tmp_path / "b").exists()  # refused before any work


def test_schema_with_force_replaces_a_regular_file(tmp_path):
    target = tmp_path / "s.json"
    target.write_text("old\n")
    result = runner.invoke(app, ["schema", "--output", str(target), "--force"])
    assert result.exit_code == 0, result.output
    assert target.read_text().startswith("{")


@pytest.mark.parametrize("relative", [MANIFEST, "meshes/q_0.000.stl", "notes.json"])
def test_no_command_but_build_writes_inside_a_build_folder_even_with_force(out, tmp_path, relative):
    target = out / relative
    before = target.read_bytes() if target.exists() else None
    if relative.endswith(".stl"):
        result = runner.invoke(app, ["pose", str(demo_case(tmp_path)), "--q", "0", "--output", str(target),
                                     "--force", "--out", str(tmp_path / "other")])
    else:
        result = runner.invoke(app, ["schema", "--output", str(target), "--force"])
    assert_refused(result, "inside the build folder", "write it outside the build folder")
    assert (target.read_bytes() if target.exists() else None) == before


def test_the_lock_refuses_a_hard_link_to_another_file(tmp_path):
    victim = tmp_path / "victim.txt"
    victim.write_text("someone else's file\n")
    os.link(victim, tmp_path / lock_name("b3"))
    result = runner.invoke(app, ["build", str(demo_case(tmp_path)), "--out", str(tmp_path / "b3")])
    assert_refused(result, "2 names", "hard link")
    assert victim.read_text() == "someone else's file\n"
    assert not (tmp_path / "b3").exists()


@pytest.mark.parametrize("name", [".b.staging-1-cafe", ".b.trash-22-beef"])
def test_a_users_folder_with_a_reserved_name_beside_the_build_folder_is_kept(tmp_path, name):
    mine = tmp_path / name
    mine.mkdir()
    (mine / "keep.txt").write_text("mine\n")
    repair(tmp_path / "b")
    assert (mine / "keep.txt").read_text() == "mine\n"


def test_a_killed_runs_staging_folder_is_still_removed(tmp_path):
    with Staging(tmp_path / "b") as staging:
        leftover = staging.folder.with_name(staging.folder.name.replace(str(os.getpid()), "999999999"))
        shutil.copytree(staging.folder, leftover)  # what a run killed before its swap leaves: marker included
    repair(tmp_path / "b")
    assert not leftover.exists()


@pytest.mark.parametrize("folder", ["Patient #12", "a: b", "- lead", "{braces}", "new\nline", "naïve 'q' \"dq\""])
def test_init_quotes_the_paths_it_writes_and_they_read_back(tmp_path, folder):
    data = tmp_path / folder
    data.mkdir()
    for name in ("surface.stl", "centerline.vtp"):
        shutil.copyfile(DEMO_DATA / name, data / name)
    output = tmp_path / "case.yaml"
    result = runner.invoke(app, ["init", str(data / "surface.stl"), str(data / "centerline.vtp"),
                                 "--output", str(output), "--units", "mm"])
    assert result.exit_code == 0, result.output
    case = load_case(output)
    assert case.final.surface == (data / "surface.stl").resolve()
    assert case.final.centerline == (data / "centerline.vtp").resolve()
