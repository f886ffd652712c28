"""The reference pages in ``docs/``, generated from the code so they cannot drift from it.

``docs/case-file.md`` walks the pydantic models of the case file
(:mod:`softdesign.config`): every key with its type, default, bounds and
description (the attribute docstring under the field); ``docs/commands.md``
walks the command line's click commands: every command and option with its
help.  ``python pipelines/docs.py`` writes both; a test fails when a written
page differs from the generated one, or a key has no description.
"""

from __future__ import annotations

import json
import re
import types
import typing
from collections.abc import Iterator
from typing import Any

from pydantic import BaseModel
from pydantic.fields import FieldInfo

from softdesign.config.field_docs import attach_field_docs

#: Bounds pydantic keeps in a field's metadata, and how the page writes them.
BOUNDS = (("gt", ">"), ("ge", ">="), ("lt", "<"), ("le", "<="), ("min_length", "length >="),
          ("max_length", "length <="))


def case_keys(model: type[BaseModel], prefix: str = "") -> Iterator[tuple[str, FieldInfo, type[BaseModel] | None]]:
    """Every key of ``model`` as (dotted name, field, nested model or None), depth first in declaration order."""
    for name, field in model.model_fields.items():
        nested = _nested_model(field.annotation)
        yield prefix + name, field, nested
        if nested is not None:
            yield from case_keys(nested, f"{prefix}{name}.")


def missing_descriptions(model: type[BaseModel]) -> list[str]:
    """The dotted keys whose field has no description (the test of the reference fails on any)."""
    return [key for key, field, _ in case_keys(attach_field_docs(model)) if not (field.description or "").strip()]


def case_reference_markdown(model: type[BaseModel]) -> str:
    """The case-file reference page (see the module notes)."""
    lines = ["# The case file, key by key", "",
             "Generated from the pydantic models that validate it (`python pipelines/docs.py`); do not edit.",
             "Every key is optional unless marked required; sizes in mm, angles in degrees only where the key says "
             "so. Editors can complete and check case files with the JSON Schema of `softdesign schema`.", ""]
    for key, field, nested in case_keys(attach_field_docs(model)):
        depth = key.count(".")
        heading = "##" if depth == 0 else "###"
        lines.append(f"{heading} `{key}`")
        lines.append("")
        lines.append((field.description or "").strip())
        lines.append("")
        facts = [f"type: {_type_text(field.annotation)}"]
        if field.is_required():
            facts.append("required")
        elif nested is None:
            facts.append(f"default: `{_default_text(field)}`")
        bounds = _bounds_text(field)
        if bounds:
            facts.append(f"bounds: {bounds}")
        lines.append("- " + "; ".join(facts))
        lines.append("")
    return "\n".join(lines).rstrip() + "\n"


def command_reference_markdown(group: Any, prefix: str = "softdesign") -> str:
    """The command reference page: every command of the click ``group``, its help and each option's."""
    lines = ["# Commands", "", "Generated from the command line itself (`python pipelines/docs.py`); do not edit.",
             "Exit codes: 0 success, 1 processing failure, 2 bad usage or bad input.", ""]
    for name, command in _commands(group, prefix):
        lines += [f"## `{name}`", "", (command.help or "").strip(), ""]
        for param in command.params:
            if param.name == "help":
                continue
            opts = ", ".join(f"`{o}`" for o in param.opts) if param.param_type_name == "option" else (
                f"`{param.name.upper()}`")
            help_text = " ".join((getattr(param, "help", None) or "").split())
            lines.append(f"- {opts}: {help_text}".rstrip(": "))
        lines.append("")
    return "\n".join(lines).rstrip() + "\n"


def _commands(group: Any, prefix: str) -> Iterator[tuple[str, Any]]:
    for name in sorted(group.commands):
        command = group.commands[name]
        if hasattr(command, "commands"):  # a group of commands (``pcc``)
            yield from _commands(command, f"{prefix} {name}")
        else:
            yield f"{prefix} {name}", command


def _nested_model(annotation: Any) -> type[BaseModel] | None:
    candidates = [annotation, *typing.get_args(annotation)]
    for item in candidates:
        if isinstance(item, type) and issubclass(item, BaseModel):
            return item
    return None


def _type_text(annotation: Any) -> str:
    text = repr(annotation) if not isinstance(annotation, type) else annotation.__name__
    if isinstance(annotation, types.UnionType) or typing.get_origin(annotation) is not None:
        text = str(annotation)
    text = re.sub(r"typing\.|pathlib\.|softdesign\.[a-z_.]+\.|<class '([^']+)'>", r"\1", text)
    text = re.sub(r"Annotated\[([^,\[\]]+)(\[[^\]]*\])?, [^\]]*\]", r"\1", text)
    text = re.sub(r"Optional\[(.*)\]$", r"\1 | None", text)
    text = re.sub(r"^Union\[(.*), (Path|float)\]", r"\1 | \2", text)
    return f"`{text.replace('NoneType', 'None')}`"


def _default_text(field: FieldInfo) -> str:
    default = field.get_default(call_default_factory=True)
    if isinstance(default, BaseModel):
        return "(the defaults below)"
    try:
        return json.dumps(default)
    except TypeError:
        return str(default)


def _bounds_text(field: FieldInfo) -> str:
    found = []
    for item in field.metadata:
        for attr, sign in BOUNDS:
            value = getattr(item, attr, None)
            if value is not None:
                found.append(f"{sign} {value:g}" if isinstance(value, float) else f"{sign} {value}")
    return ", ".join(found)
