"""What every command shares: error mapping, JSON output and notes on stderr."""

from __future__ import annotations

import json
import sys
from typing import Any, Callable, TypeVar

import typer

from softdesign.errors import SoftdesignError

T = TypeVar("T")


def note(message: str) -> None:
    """Write a human note to stderr (stdout is kept for --json output)."""
    typer.echo(message, err=True)


def emit_json(payload: dict[str, Any]) -> None:
    """Print one JSON object on stdout, keys in a fixed order."""
    typer.echo(json.dumps(payload, indent=2, allow_nan=False))


def run_guarded(action: Callable[[], T]) -> T:
    """Run ``action``; turn a SoftdesignError into a message and its exit code.

    A user error (bad case file, bad input) exits 2 and a processing failure
    exits 1, each with a one-paragraph message and no traceback.  Anything
    else is a bug and propagates with its traceback.
    """
    try:
        return action()
    except SoftdesignError as err:
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(code=err.exit_code) from None


def fail_usage(message: str) -> None:
    """Report bad usage (exit 2) from inside a command."""
    typer.echo(f"error: {message}", err=True)
    sys.stderr.flush()
    raise typer.Exit(code=2)
