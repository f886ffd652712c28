"""The case keys' descriptions come from their docstrings when the schema or the reference reads them, not at start."""

from __future__ import annotations

import json
import subprocess
import sys

from pydantic import BaseModel
from pydantic._internal._docs_extraction import extract_docstrings_from_cls  # the rule use_attribute_docstrings ran

from softdesign.cli.schema import case_schema
from softdesign.config import Case
from softdesign.config.field_docs import _models_below, attach_field_docs
from tests.helpers.paths import REPO


def test_importing_the_case_models_reads_no_source():
    child = ("import json; from softdesign.config import Case; "
             "print(json.dumps([f.description for f in Case.model_fields.values()]))")
    done = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True, cwd=REPO, timeout=60)
    assert done.returncode == 0, done.stderr
    assert set(json.loads(done.stdout)) == {None}


def test_the_descriptions_are_pydantics_attribute_docstrings():
    attach_field_docs(Case)
    models = _models_below(Case)
    assert len(models) > 15  # every block, nested ones too (export.mould, material.custom, ...)
    for model in models:
        expected = {}
        for base in reversed([b for b in model.__mro__ if issubclass(b, BaseModel) and b is not BaseModel]):
            found = extract_docstrings_from_cls(base, use_inspect=True)
            expected.update({name: found.get(name) for name in base.__dict__.get("__annotations__", {})})
        for name, field in model.model_fields.items():
            if expected.get(name) is not None:
                assert field.description == expected[name], (model.__name__, name)


def test_the_schema_carries_them():
    properties = case_schema()["properties"]
    assert properties["units"]["description"] == attach_field_docs(Case).model_fields["units"].description
    assert properties["units"]["description"]
