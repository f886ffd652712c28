"""A case file's text with new link breaks, the rest of the user's text kept (comments, order, style).

``softdesign design`` writes the case it was given with ``links: {breaks: [...]}``
in place of the old ``links`` value.  The edit is made on the text at the
positions PyYAML's composer reports, so comments and layout elsewhere stay as
the user wrote them; relative input paths are re-expressed from the new file's
folder when it is written elsewhere.  The edit is checked by parsing it back:
if the parsed result is not exactly the case with the new links (YAML the
span edit cannot handle, e.g. anchors), the file is written whole by
``yaml.safe_dump`` instead (comments lost, values the same).  Every parse is
:func:`~softdesign.io.case_yaml.parse_case_yaml`'s, the one reader of case
files, so what ``build`` and ``validate`` accept (a tab before a comment, CRLF
line ends, a byte-order mark) is edited the same way; a byte-order mark is
dropped first, as the reader's positions do not count it.
"""

from __future__ import annotations

import copy
import json
import os
from pathlib import Path
from typing import Any

import yaml

from softdesign.errors import ConfigError
from softdesign.io.case_yaml import parse_case_yaml

#: Case keys that hold input file paths, relative to the case file's folder (``intermediate`` is a list of these).
PATH_KEYS = (("final", "centerline"), ("final", "surface"), ("initial", "centerline"), ("initial", "surface"))


def breaks_text(breaks: list[float]) -> str:
    """``{breaks: [0.0, 0.25, ..., 1.0]}`` as YAML flow text (six decimals of normalized l)."""
    return "{breaks: [" + ", ".join(repr(round(float(b), 6)) for b in breaks) + "]}"


def rounded_breaks(breaks: list[float]) -> list[float]:
    """The breaks as :func:`breaks_text` writes them."""
    return [round(float(b), 6) for b in breaks]


def case_text_with_breaks(text: str, breaks: list[float], source_dir: Path, target_dir: Path,
                          where: Path = Path("case.yaml")) -> tuple[str, bool]:
    """The case file ``text`` with ``links: {breaks: ...}``, paths rebased from ``source_dir`` to ``target_dir``.

    Returns
    -------
    (text, kept) : the new text, and whether the user's text was kept (False: written whole by safe_dump)
    """
    return case_text_with_keys(text, {"links": ({"breaks": rounded_breaks(breaks)}, breaks_text(breaks))},
                               source_dir, target_dir, where)


def case_text_with_keys(text: str, updates: dict[str, tuple[Any, str]], source_dir: Path,
                        target_dir: Path, where: Path = Path("case.yaml")) -> tuple[str, bool]:
    """The case file ``text`` with top-level keys set (``{key: (value, its YAML flow text)}``), paths rebased.

    ``where`` names the case file in the messages of a text the reader refuses (ConfigError with its line).

    Returns
    -------
    (text, kept) : the new text, and whether the user's text was kept (False: written whole by safe_dump)
    """
    text = text.removeprefix("\ufeff")
    raw, root = parse_case_yaml(where, text)
    expected = _expected(raw, updates, source_dir, target_dir)
    if isinstance(root, yaml.MappingNode) and not root.flow_style:
        edited = _edited(text, raw, root, updates, source_dir, target_dir)
        try:
            if parse_case_yaml(where, edited)[0] == expected:
                return edited, True
        except ConfigError:
            pass
    return yaml.safe_dump(expected, sort_keys=False, default_flow_style=None), False


def _rebased(value: Any, source_dir: Path, target_dir: Path) -> Any:
    if not isinstance(value, str) or os.path.isabs(value) or source_dir.resolve() == target_dir.resolve():
        return value
    if not (source_dir / value).exists():  # not a file (e.g. a keyword): leave it as written
        return value
    return Path(os.path.relpath(source_dir.resolve() / value, target_dir.resolve())).as_posix()


def _path_slots(raw: dict[str, Any]) -> list[tuple[Any, ...]]:
    """Key paths of every input-path value present in the parsed case."""
    slots: list[tuple[Any, ...]] = [keys for keys in PATH_KEYS
                                    if isinstance(raw.get(keys[0]), dict) and keys[1] in raw[keys[0]]]
    for i, item in enumerate(raw.get("intermediate") or []):
        if isinstance(item, dict) and "centerline" in item:
            slots.append(("intermediate", i, "centerline"))
    return slots


def _expected(raw: dict[str, Any], updates: dict[str, tuple[Any, str]], source_dir: Path,
              target_dir: Path) -> dict[str, Any]:
    out = copy.deepcopy(raw)
    for slot in _path_slots(out):
        holder = out
        for key in slot[:-1]:
            holder = holder[key]
        holder[slot[-1]] = _rebased(holder[slot[-1]], source_dir, target_dir)
    for key, (value, _) in updates.items():
        out[key] = copy.deepcopy(value)
    return out


def _child(node: yaml.Node, key: Any) -> tuple[yaml.Node, yaml.Node] | None:
    if isinstance(node, yaml.MappingNode):
        for k, v in node.value:
            if k.value == key:
                return k, v
    if isinstance(node, yaml.SequenceNode) and isinstance(key, int) and key < len(node.value):
        return node.value[key], node.value[key]
    return None


def _content_end(node: yaml.Node) -> int:
    """Index just after a node's last character of content (a block collection ends at its last child)."""
    if isinstance(node, (yaml.MappingNode, yaml.SequenceNode)) and not node.flow_style and node.value:
        last = node.value[-1]
        return _content_end(last[1] if isinstance(last, tuple) else last)
    return node.end_mark.index


def _edited(text: str, raw: dict[str, Any], root: yaml.MappingNode, updates: dict[str, tuple[Any, str]],
            source_dir: Path, target_dir: Path) -> str:
    edits: list[tuple[int, int, str]] = []
    for slot in _path_slots(raw):
        node: yaml.Node | None = root
        for key in slot:
            found = _child(node, key) if node is not None else None
            node = None if found is None else found[1]
        value = raw
        for key in slot:
            value = value[key]
        new = _rebased(value, source_dir, target_dir)
        if isinstance(node, yaml.ScalarNode) and new != value:
            edits.append((node.start_mark.index, node.end_mark.index, json.dumps(new)))
    appended = ""
    for name, (_, flow) in updates.items():
        found = _child(root, name)
        if found is None:
            appended += f"{name}: {flow}\n"
            continue
        key, value_node = found
        if isinstance(value_node, (yaml.MappingNode, yaml.SequenceNode)) and not value_node.flow_style:
            end = text.find("\n", _content_end(value_node))
            end = len(text) if end < 0 else end
            edits.append((key.end_mark.index, end, f": {flow}"))
        else:
            edits.append((value_node.start_mark.index, value_node.end_mark.index, flow))
    if appended:
        tail = "" if text.endswith("\n") or not text else "\n"
        edits.append((len(text), len(text), tail + appended))
    for start, end, new_text in sorted(edits, reverse=True):
        text = text[:start] + new_text + text[end:]
    return text
