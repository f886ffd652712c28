"""`softdesign sample DIR` never overwrites a file unless told to with --force."""

from __future__ import annotations

from typer.testing import CliRunner

from softdesign.cli import app
from tests.helpers.folders import snapshot

runner = CliRunner()


def test_sample_refuses_to_overwrite_files_unless_forced(tmp_path):
    (tmp_path / "surface.stl").write_bytes(b"my own segmentation")
    before = snapshot(tmp_path)
    result = runner.invoke(app, ["sample", str(tmp_path)])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    assert str(tmp_path / "surface.stl") in result.output and "--force" in result.output
    assert snapshot(tmp_path) == before  # not even the centerline, which was not there, is written
    forced = runner.invoke(app, ["sample", str(tmp_path), "--force"])
    assert forced.exit_code == 0, forced.output
    assert (tmp_path / "surface.stl").read_bytes() != b"my own segmentation"
    assert (tmp_path / "centerline.vtp").is_file()


def test_sample_into_a_file_is_refused(tmp_path):
    target = tmp_path / "notes.txt"
    target.write_text("mine")
    result = runner.invoke(app, ["sample", str(target)])
    assert result.exit_code == 2 and "is a file" in result.output and str(target) in result.output
    assert target.read_text() == "mine"
