"""Names the case file gives to files: ``name`` is a name and never a path; every export q names its own mesh."""

from __future__ import annotations

import pytest
import yaml
from typer.testing import CliRunner

from softdesign.cli import app
from tests.helpers.cases import straight_tube, write_case

runner = CliRunner()


@pytest.fixture
def tube_case(tmp_path, monkeypatch):
    """Write a valid straight-tube case with ``write(**keys)``; the current folder is ``tmp_path``."""
    monkeypatch.chdir(tmp_path)
    centerline, surface = straight_tube(tmp_path)
    final = {"centerline": centerline.name, "surface": surface.name}

    def write(**keys):
        path = tmp_path / "case.yaml"  # write_case's name= names the file; here `name:` is a key of the case
        path.write_text(yaml.safe_dump({"final": final, **keys}, sort_keys=False))
        return path

    return write


def assert_refused(args: list[str], *needles: str) -> None:
    result = runner.invoke(app, args)
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output and (result.exception is None or isinstance(result.exception, SystemExit))
    for needle in needles:
        assert needle in result.output, (needle, result.output)


@pytest.mark.parametrize(
    "name",
    ["../escaped", "/tmp/abs", "a/b", ".hidden", "", "two words", "x" * 101, "..", "naïve"],
    ids=["parent", "absolute", "slash", "dot-first", "empty", "space", "too-long", "dot-dot", "non-ascii"],
)
def test_a_name_that_is_not_a_plain_name_is_refused_by_validate_and_build(name, tube_case, tmp_path):
    case = tube_case(name=name)
    before = sorted(p.name for p in tmp_path.iterdir())
    for command in ("validate", "build"):
        assert_refused([command, str(case)], "name: must be a name, not a path", repr(name), "write e.g. name: ")
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # nothing built anywhere, inside or outside build/


@pytest.mark.parametrize("name", ["demo", "patient-07_left.v2", "A" * 100, "7"])
def test_plain_names_are_accepted(name, tube_case):
    result = runner.invoke(app, ["validate", str(tube_case(name=name))])
    assert result.exit_code == 0, result.output


def test_a_case_file_whose_stem_is_not_a_name_is_told_to_give_one(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    centerline, _ = straight_tube(tmp_path)
    case = write_case(tmp_path, name="patient 7", final={"centerline": centerline.name})
    assert_refused(["validate", str(case)], "'patient 7'", "write e.g. name: patient-7", "the default is the case file")


@pytest.mark.parametrize(
    "q, needles",
    [
        ([0, 0.5, 0.5004, 1], ["export.q", "0.5 and 0.5004 both name their mesh q_0.500.stl", "0.001 apart"]),
        ([0, 1, 0.9996], ["export.q", "1.0 and 0.9996 both name their mesh q_1.000.stl"]),
        ([0, 0.5, 0.5, 1], ["export.q", "0.5 is listed twice", "give each q once"]),
    ],
    ids=["print-alike", "print-alike-unsorted", "duplicate"],
)
def test_export_q_values_that_would_share_a_mesh_file_are_refused(q, needles, tube_case, tmp_path):
    case = tube_case(export={"q": q})
    assert_refused(["validate", str(case)], *needles)
    assert_refused(["build", str(case), "--out", str(tmp_path / "out")], *needles)
    assert not (tmp_path / "out").exists()


def test_export_q_values_a_thousandth_apart_are_accepted(tube_case):
    result = runner.invoke(app, ["validate", str(tube_case(export={"q": [0, 0.5, 0.501, 1]}))])
    assert result.exit_code == 0, result.output
