"""The `softdesign` command line: parse, load, call the pipeline, map errors to exit codes.

Exit codes: 0 success, 1 processing failure, 2 bad usage or bad input.
With ``--json`` a command prints one JSON object on stdout and nothing else;
notes, progress and warnings go to stderr.
"""

from __future__ import annotations

import typer

from softdesign.cli_support import run_guarded
from softdesign.pcc_cli import pcc_app

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="Patient-specific soft actuators from VMTK vessel exports.",
)
app.add_typer(pcc_app, name="pcc")


def main() -> None:
    """Console-script entry point."""
    app()


__all__ = ["app", "main", "run_guarded"]
