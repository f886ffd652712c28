"""Issue 45, case files as users type them: a tab before a comment, a byte-order mark, CRLF line ends, non-ASCII
paths.  One reader serves every command: what ``validate`` accepts, ``design`` edits and ``pose`` builds; what it
refuses names the line.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.config import load_case
from softdesign.io.case_edit import case_text_with_breaks
from tests.helpers.attacks import assert_refused, demo_case
from tests.helpers.paths import REPO

runner = CliRunner()
DEMO_DATA = REPO / "data" / "demo"

VARIANTS = {
    "tab-before-comment": lambda t: t.replace("\nunits: mm\n", "\nunits: mm\t# the files' unit\n"),
    "bom": lambda t: "\ufeff" + t,
    "crlf": lambda t: t.replace("\n", "\r\n"),
    "all-three": lambda t: "\ufeff" + t.replace("\nunits: mm\n", "\nunits: mm\t# unit\n").replace("\n", "\r\n"),
}


def typed_case(tmp_path: Path, variant: str) -> Path:
    """The coarse demo case, its inputs in a folder with a non-ASCII name, written as ``variant`` types it."""
    data = tmp_path / "données patient"
    data.mkdir()
    for name in ("surface.stl", "centerline.vtp"):
        shutil.copyfile(DEMO_DATA / name, data / name)
    case = demo_case(tmp_path, final={"surface": str(data / "surface.stl"), "centerline": str(data / "centerline.vtp")})
    text = case.read_text(encoding="utf-8")
    assert "\nunits: mm\n" in text
    case.write_bytes(VARIANTS[variant](text).encode("utf-8"))
    return case


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_validate_reads_a_case_as_typed(tmp_path, variant):
    case = typed_case(tmp_path, variant)
    result = runner.invoke(app, ["validate", str(case)])
    assert result.exit_code == 0, result.output
    assert load_case(case).final.surface.parent.name == "données patient"


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_the_case_editor_reads_what_validate_reads(tmp_path, variant):
    case = typed_case(tmp_path, variant)
    text, kept = case_text_with_breaks(case.read_text(encoding="utf-8"), [0.0, 0.5, 1.0], tmp_path, tmp_path)
    assert kept  # the user's text (and comment) kept, only the links replaced
    edited = tmp_path / "edited.yaml"
    edited.write_text(text, encoding="utf-8")
    assert load_case(edited).links.breaks == [0.0, 0.5, 1.0]
    assert load_case(edited).final == load_case(case).final


def test_design_writes_its_case_from_a_case_with_a_tab_before_a_comment(tmp_path):
    case = typed_case(tmp_path, "all-three")
    output = tmp_path / "designed.yaml"
    result = runner.invoke(app, ["design", str(case), "--tolerance-mm", "2", "--out", str(tmp_path / "b"),
                                 "--output", str(output)])
    assert result.exit_code == 0, result.output
    assert "Traceback" not in result.output
    assert load_case(output).blend == "pcc"
    assert "# unit" in output.read_text(encoding="utf-8")  # the user's comment kept


def test_a_refused_case_names_its_line(tmp_path):
    case = typed_case(tmp_path, "crlf")
    case.write_bytes(case.read_bytes().replace(b"\r\nunits: mm\r\n", b"\r\nunits: [mm\r\n"))
    result = runner.invoke(app, ["validate", str(case)])
    assert_refused(result, "not valid YAML", f"{case}:")
