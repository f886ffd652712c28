"""`softdesign simulate`: help, and bad options refused with exit 2 and the option named before any work."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from tests.helpers.paths import DEMO

runner = CliRunner()


def test_help_names_the_options() -> None:
    result = runner.invoke(app, ["simulate", "--help"])
    assert result.exit_code == 0
    for option in ("--section", "--pressures", "--target", "--json", "--timeout"):
        assert option in result.output


@pytest.mark.parametrize(("args", "message"), [
    (["--pressures", "10,20"], "expected 3"),
    (["--pressures", "10,x,0"], "is not a number"),
    (["--pressures", "10,2000,0"], "expected a number in [0, 1000]"),
    (["--pressures", "-1,0,0"], "expected a number in [0, 1000]"),
    (["--pressures", "10,0,0", "--target", "1"], "not both or neither"),
    ([], "not both or neither"),
    (["--target", "1.5"], "--target: got 1.5"),
    (["--pressures", "10,0,0", "--size-mm", "0"], "--size-mm: got 0"),
    (["--pressures", "10,0,0", "--timeout", "1e9"], "--timeout"),
])
def test_bad_options_exit_2_before_any_work(args: list[str], message: str, tmp_path) -> None:
    result = runner.invoke(app, ["simulate", str(DEMO), "--out", str(tmp_path / "build"), *args])
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert not (tmp_path / "build").exists()  # refused before the build started
