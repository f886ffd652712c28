"""Each case key's description (the docstring under its field), attached only where it is read.

The case file's models document every key by an attribute docstring::

    spacing_mm: FiniteFloat = 0.5
    \"\"\"Distance between resampled points, mm.\"\"\"

Pydantic's ``use_attribute_docstrings`` finds them while each model class is
created: it tokenizes and parses that class's source, about 0.1 s of every
command's start-up (``validate`` included) for text only the JSON Schema
(``softdesign schema``, ``init``) and the reference page (``docs/case-file.md``)
read.  :func:`attach_field_docs` gives the same text on demand: it reads each
model module's source once, takes the string statement that follows an
annotated field in the class body (pydantic's rule: a field that sets its own
``description`` keeps it; an inherited field gets the docstring of the class
that declares it), and rebuilds the models' schemas, nested models first.
"""

from __future__ import annotations

import ast
import inspect
import sys
import typing
from collections.abc import Iterator
from functools import cache
from typing import Any

from pydantic import BaseModel

#: Models whose fields already carry their docstrings (attaching twice would change nothing).
_DONE: set[type[BaseModel]] = set()


def attach_field_docs(model: type[BaseModel]) -> type[BaseModel]:
    """``model`` and every model nested in it, each field described by its docstring; returns ``model``.

    The JSON Schema (``model.model_json_schema()``) and ``model_fields[...].description`` are then those
    ``use_attribute_docstrings`` would give.  Validation does not read descriptions and is unchanged.
    """
    pending = [m for m in _models_below(model) if m not in _DONE]
    for cls in pending:
        docs = _declared_docs(cls)
        for name, field in cls.model_fields.items():
            if field.description is None and name in docs:
                field.description = docs[name]
    for cls in pending:  # leaves first: a model's schema embeds its nested models' schemas as they are
        cls.model_rebuild(force=True)
        _DONE.add(cls)
    return model


def _models_below(model: type[BaseModel]) -> list[type[BaseModel]]:
    """Every model class reachable from ``model``'s fields (unions, lists, Annotated), leaves before parents."""
    order: list[type[BaseModel]] = []
    seen: set[type[BaseModel]] = set()

    def visit(cls: type[BaseModel]) -> None:
        seen.add(cls)
        for field in cls.model_fields.values():
            for nested in _model_types(field.annotation):
                if nested not in seen:
                    visit(nested)
        order.append(cls)

    visit(model)
    return order


def _model_types(annotation: Any) -> Iterator[type[BaseModel]]:
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        yield annotation
    for argument in typing.get_args(annotation):
        yield from _model_types(argument)


def _declared_docs(cls: type[BaseModel]) -> dict[str, str]:
    """Field name -> docstring, each from the nearest class of the MRO that declares the field."""
    docs: dict[str, str] = {}
    for base in reversed(cls.__mro__):
        if not (isinstance(base, type) and issubclass(base, BaseModel)) or base is BaseModel:
            continue
        own = _class_docs(base.__module__, base.__qualname__)
        for name in base.__dict__.get("__annotations__", {}):
            if name in own:
                docs[name] = own[name]
            else:
                docs.pop(name, None)  # re-declared without a docstring: pydantic gives it none
    return docs


@cache
def _class_docs(module: str, qualname: str) -> dict[str, str]:
    """The attribute docstrings of class ``qualname`` in ``module``'s source ({} when it cannot be read)."""
    try:
        tree = _module_tree(module)
    except (OSError, TypeError, SyntaxError):
        return {}
    body: list[ast.stmt] = tree.body
    node: ast.ClassDef | None = None
    for part in qualname.split("."):
        node = next((s for s in body if isinstance(s, ast.ClassDef) and s.name == part), None)
        if node is None:
            return {}
        body = node.body
    docs: dict[str, str] = {}
    previous: ast.stmt | None = None
    for statement in body:
        if (isinstance(statement, ast.Expr) and isinstance(statement.value, ast.Constant)
                and isinstance(statement.value.value, str) and isinstance(previous, ast.AnnAssign)
                and isinstance(previous.target, ast.Name)):
            docs[previous.target.id] = inspect.cleandoc(statement.value.value)
        previous = statement
    return docs


@cache
def _module_tree(module: str) -> ast.Module:
    return ast.parse(inspect.getsource(sys.modules[module]))
