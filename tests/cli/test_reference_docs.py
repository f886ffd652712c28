"""The reference pages in docs/ are generated from the code: every key described, and the pages up to date."""

from __future__ import annotations

import importlib.util
import json

from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.cli.reference import case_keys, missing_descriptions
from softdesign.config import Case
from tests.helpers.paths import REPO


def _docs_module():
    spec = importlib.util.spec_from_file_location("docs_pages", REPO / "pipelines" / "docs.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_key_of_the_case_file_has_a_description():
    assert missing_descriptions(Case) == []
    assert len(list(case_keys(Case))) > 80  # the walk reaches the nested blocks (export.mould, material.custom, ...)


def test_the_reference_pages_are_what_the_code_gives():
    for path, text in _docs_module().pages().items():
        assert path.read_text(encoding="utf-8") == text, f"{path} is out of date: run python pipelines/docs.py"


def test_every_key_and_every_command_is_on_its_page():
    case_page = (REPO / "docs" / "case-file.md").read_text(encoding="utf-8")
    assert all(f"`{key}`" in case_page for key, _, _ in case_keys(Case))
    commands_page = (REPO / "docs" / "commands.md").read_text(encoding="utf-8")
    for name in ("build", "design", "init", "schema", "materials", "pcc forward", "pcc reconstruct", "check"):
        assert f"## `softdesign {name}`" in commands_page, name
    for option in ("--tolerance-mm", "--rtol", "--rotation-tol", "--max-rate", "--points-per-section", "--samples"):
        assert f"`{option}`" in commands_page, option


def test_the_schema_carries_the_descriptions_for_editors():
    schema = json.loads(CliRunner().invoke(app, ["schema"]).output)
    assert schema["$defs"]["Resample"]["properties"]["spacing_mm"]["description"].startswith("Arc length")
