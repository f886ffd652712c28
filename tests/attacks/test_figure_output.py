"""Issue 45, writes that destroy: ``simulate --figure`` is an output like every ``--output``: an existing file is
replaced only with ``--force``, and the refusal comes before any work.
"""

from __future__ import annotations

from typer.testing import CliRunner

from softdesign.cli import app
from tests.helpers.attacks import assert_refused, demo_case

runner = CliRunner()


def test_an_existing_figure_is_kept_without_force_and_nothing_is_built(tmp_path):
    figure = tmp_path / "notes.png"
    figure.write_bytes(b"the user's figure\n")
    result = runner.invoke(app, ["simulate", str(demo_case(tmp_path)), "--out", str(tmp_path / "b"),
                                 "--pressures", "10,0,0", "--figure", str(figure)])
    assert_refused(result, str(figure), "already exists", "--force")
    assert figure.read_bytes() == b"the user's figure\n"
    assert not (tmp_path / "b").exists()  # refused before the build started


def test_a_figure_is_never_written_over_a_folder_even_with_force(tmp_path):
    folder = tmp_path / "shown.png"
    folder.mkdir()
    result = runner.invoke(app, ["simulate", str(demo_case(tmp_path)), "--out", str(tmp_path / "b"),
                                 "--pressures", "10,0,0", "--figure", str(folder), "--force"])
    assert_refused(result, str(folder), "is a folder")
    assert folder.is_dir() and not (tmp_path / "b").exists()
