"""`softdesign report` on a damaged or unwritable build folder: exit 2 naming the folder, nothing else changed."""

from __future__ import annotations

import errno
import os
from pathlib import Path

import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.pipeline.lock import BuildLock
from tests.helpers.attacks import assert_refused
from tests.helpers.folders import snapshot

runner = CliRunner()


@pytest.mark.parametrize("kept", ["blend/curves.npz", "ingest/surface.npz"])
def test_a_truncated_npz_is_a_user_error_naming_the_folder(out, kept):
    file = out / kept
    file.write_bytes(file.read_bytes()[: file.stat().st_size // 2])
    before = snapshot(out)
    result = runner.invoke(app, ["report", str(out)])
    assert_refused(result, str(out), "kept files are unreadable", "BadZipFile", "--force")
    assert snapshot(out) == before


def test_a_folder_the_report_cannot_write_is_a_user_error_with_the_path(out, monkeypatch):
    """A read-only file system (EROFS) as the report's temporary folder is made: exit 2, the folder, the fix."""
    real_mkdir = Path.mkdir

    def read_only(self: Path, *args, **kwargs) -> None:
        if self.name.startswith(".report-"):
            raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(self))
        real_mkdir(self, *args, **kwargs)

    monkeypatch.setattr(Path, "mkdir", read_only)
    before = snapshot(out)
    result = runner.invoke(app, ["report", str(out)])
    assert_refused(result, f"build folder {out}", "Read-only file system", "read-only")
    assert snapshot(out) == before


def test_the_report_is_refused_while_a_build_holds_the_folder(out):
    before = snapshot(out)
    with BuildLock(Path(os.path.realpath(out))):
        result = runner.invoke(app, ["report", str(out)])
    assert_refused(result, f"pid {os.getpid()}", "another softdesign run")
    assert snapshot(out) == before
