"""The case file's error messages: each problem with its file, line, dotted key, what was expected and what
was found; an unknown key with the nearest valid one.
"""

from __future__ import annotations

import difflib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml
from pydantic import BaseModel, ValidationError

from softdesign.limits import MEMORY_BUDGET_TEXT
from softdesign.meshing.volume_tolerance import MIN_ANGULAR_COUNT, VOLUME_RTOL

_TEMPLATES = {
    "greater_than": "must be > {gt}",
    "greater_than_equal": "must be >= {ge}",
    "less_than": "must be < {lt}",
    "less_than_equal": "must be <= {le}",
    "missing": "is required",
    "finite_number": "must be a finite number (not NaN, inf, or too large for a float)",
    "int_type": "must be a whole number written as one (e.g. 4; not true/false, 4.0, 1e6 or a string)",
    "too_long": "has more than {max_length} entries (the limit)",
}
#: Keys whose upper bound is a limit of softdesign.limits (what it protects, for the message).
_LIMITED = {
    "resample.count", "links.count", "links.breaks", "fit.angular_intervals", "fit.holdout_folds",
    "export.q", "export.frames", "export.angular_count",
}
#: Longest shown input value in a message, characters (a value of megabytes would make a message of megabytes).
_SHOWN_CHARS = 200


def format_errors(path: Path, root: yaml.Node | None, err: ValidationError, model: type[BaseModel]) -> str:
    """The message of ``err``, raised validating the case file ``path`` (parsed to ``root``) as ``model``."""
    lines = [f"{path}: the case file is invalid ({err.error_count()} problem(s)):"]
    for item in err.errors():
        loc = tuple(item["loc"])
        line = _line_of(root, loc)
        where = f"{path}:{line}" if line else str(path)
        lines.append(f"  {where}: {_describe(loc, item, model)}")
    lines.append("Fix the listed keys; `softdesign validate CASE.yaml` re-checks without building.")
    return "\n".join(lines)


#: Why a range holds, added to its message (dotted field -> reason).
_RANGE_REASONS = {
    "export.angular_count": (
        f"fewer vertices around cannot pass the mesh volume check (a {MIN_ANGULAR_COUNT - 1}-gon already misses "
        f"more than {100 * VOLUME_RTOL:g}% of a round section's area)"
    ),
}


def _describe(loc: tuple[Any, ...], item: Mapping[str, Any], model: type[BaseModel]) -> str:
    field = ".".join(str(p) for p in loc) or "(top level)"
    kind = item["type"]
    if kind == "extra_forbidden":
        return _unknown_key(loc, model)
    ctx = item.get("ctx") or {}
    if kind in _TEMPLATES:
        text = _TEMPLATES[kind].format(**ctx)
    else:
        text = item["msg"].removeprefix("Value error, ")
        if text.startswith("Input should be"):
            text = "should be" + text[len("Input should be") :]
    # a model-level rule names its keys and quotes the values in its own message
    if kind == "value_error":
        return f"{field}: {text}"
    got = "" if kind == "missing" else f", got {_shown(item.get('input'))}"
    reason = f": {_RANGE_REASONS[field]}" if field in _RANGE_REASONS and kind in _TEMPLATES else ""
    if field in _LIMITED and kind in ("less_than_equal", "too_long"):
        reason = f": a limit of softdesign/limits/__init__.py that keeps a build within {MEMORY_BUDGET_TEXT} of memory"
    return f"{field} {text}{got}{reason}"


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= _SHOWN_CHARS else f"{text[:_SHOWN_CHARS]}... ({len(text)} characters)"


def _unknown_key(loc: tuple[Any, ...], model: type[BaseModel]) -> str:
    for part in loc[:-1]:
        if isinstance(part, int):
            continue
        ann = model.model_fields[str(part)].annotation
        model = next((a for a in _model_args(ann)), model)
    valid = sorted(model.model_fields)
    key = str(loc[-1])
    near = difflib.get_close_matches(key, valid, n=1, cutoff=0.5)
    parent = ".".join(str(p) for p in loc[:-1]) or "the top level"
    hint = f"did you mean '{near[0]}'? " if near else ""
    return f"unknown key '{key}' in {parent}; {hint}valid keys: {', '.join(valid)}"


def _model_args(ann: Any) -> list[type[BaseModel]]:
    if isinstance(ann, type) and issubclass(ann, BaseModel):
        return [ann]
    found: list[type[BaseModel]] = []
    for arg in getattr(ann, "__args__", ()):
        found.extend(_model_args(arg))
    return found


def _line_of(root: yaml.Node | None, loc: tuple[Any, ...]) -> int | None:
    """1-based line of the YAML node at ``loc`` (or of its deepest existing parent)."""
    node, line = root, None
    for part in loc:
        if isinstance(node, yaml.MappingNode):
            match = next(((k, v) for k, v in node.value if k.value == str(part)), None)
            if match is None:
                break
            line = match[0].start_mark.line + 1
            node = match[1]
        elif isinstance(node, yaml.SequenceNode) and isinstance(part, int) and part < len(node.value):
            node = node.value[part]
            line = node.start_mark.line + 1
        else:
            break
    return line
