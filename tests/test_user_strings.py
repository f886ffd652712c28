"""Issue 44, item 5: what the user reads names things in an engineer's words, never the project's own bookkeeping.

Every string literal of the package that is not a docstring or a comment (messages, warnings, verdicts, help,
the texts written into the build's files) is searched for the internal identifiers a user cannot follow: a
project issue's number, the papers' file names ("seeds/000", "seed 003"), the fit's internal names ("end prior",
"fit.summary coverage"), "as quoted in".  The material presets' sources say "unverified" where a number was not
read at its source.  Whole builds' terminal, manifest and report are searched too (tests/e2e/test_one_story.py).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

from softdesign.materials.data import material_presets

PACKAGE = Path(__file__).resolve().parents[1] / "softdesign"

#: Identifiers of the project's own bookkeeping, as a user would meet them in a message.
INTERNAL = re.compile(r"\bend prior\b|fit\.summary\b|\bissue \d+|\bseeds?/0\d\d|\bseed 00\d\b|as quoted in", re.I)


def _docstrings(tree: ast.AST) -> set[int]:
    """The ids of the docstring constants of ``tree`` (module, classes, functions)."""
    found = set()
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and body:
            first = body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                found.add(id(first.value))
    return found


def user_strings(path: Path) -> list[tuple[int, str]]:
    """``(line, text)`` of every string literal of ``path`` but its docstrings (f-strings: their literal parts)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docs = _docstrings(tree)
    return [(node.lineno, node.value) for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docs]


def test_the_scan_finds_an_internal_identifier_in_a_message_and_leaves_docstrings_alone(tmp_path):
    sample = tmp_path / "sample.py"
    sample.write_text('"""Module notes may say issue 44."""\n\ndef f(end):\n    """The end prior."""\n'
                      '    return f"held (the {end}\'s end prior)"\n', encoding="utf-8")
    assert [text for _, text in user_strings(sample) if INTERNAL.search(text)] == ["'s end prior)"]


def test_no_user_facing_string_names_the_projects_bookkeeping():
    found = [f"{path.relative_to(PACKAGE.parent)}:{line}: {text[:80]!r}"
             for path in sorted(PACKAGE.rglob("*.py")) for line, text in user_strings(path) if INTERNAL.search(text)]
    assert found == []


def test_every_material_source_names_its_document_and_says_unverified_when_it_was_not_read_there():
    for name, preset in material_presets().items():
        assert not INTERNAL.search(preset.source) and not INTERNAL.search(preset.law_source), name
        if not preset.checked:
            assert "unverified" in preset.source, name
        assert preset.mixing, name
