"""`softdesign schema [--output FILE]`: the case file's JSON Schema, for editors that complete and check YAML."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Any

import typer

from softdesign.cli.common import ReplaceOpt, check_output_file, run_guarded
from softdesign.errors import ConfigError

SchemaOutputOpt = Annotated[
    Path | None, typer.Option("--output", help="Write the schema to this file [default: print it].",
                              show_default=False)
]
#: The JSON Schema dialect pydantic writes.
DIALECT = "https://json-schema.org/draft/2020-12/schema"


def case_schema() -> dict[str, Any]:
    """The case file's JSON Schema, made from the same pydantic models that validate it (so it cannot drift)."""
    from softdesign.config import Case
    from softdesign.config.field_docs import attach_field_docs

    schema = attach_field_docs(Case).model_json_schema()
    schema["title"] = "softdesign case file"
    return {"$schema": DIALECT, **schema}


def schema_text() -> str:
    """:func:`case_schema` as the bytes ``schema`` writes: sorted keys, two-space indent, a final newline."""
    return json.dumps(case_schema(), indent=2, sort_keys=True) + "\n"


def schema(output: SchemaOutputOpt = None, force: ReplaceOpt = False) -> None:
    """Print (or write) the case file's JSON Schema, for editors that complete and check case files."""

    def action() -> None:
        from softdesign.io.atomic import write_bytes_atomically

        text = schema_text()
        if output is None:
            typer.echo(text, nl=False)
            return
        check_output_file("--output", output, force)
        try:
            write_bytes_atomically(output, text.encode())
        except OSError as err:
            raise ConfigError(f"--output {output}: cannot write it ({err.strerror or err}); choose a writable path"
                              ) from err
        typer.echo(f"wrote {output}", err=True)

    run_guarded(action)
