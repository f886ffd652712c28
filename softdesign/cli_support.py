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


class StageProgress:
    """Progress of a build on stderr: a bar on a terminal, plain lines otherwise (logs, make -j).

    Reads the ``[done/total] message`` lines the pipeline runner emits.
    """

    WIDTH = 24

    def __init__(self, stream=None) -> None:
        self.stream = stream if stream is not None else sys.stderr
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())

    def __call__(self, line: str) -> None:
        if not self.tty:
            self.stream.write(line + "\n")
            return
        counts, _, message = line.partition("] ")
        done, _, total = counts.lstrip("[").partition("/")
        if not (done.isdigit() and total.isdigit()):
            self.stream.write(line + "\n")
            return
        filled = self.WIDTH * int(done) // max(int(total), 1)
        bar = "#" * filled + "-" * (self.WIDTH - filled)
        end = "\n" if int(done) == int(total) and not message.endswith("running") else ""
        self.stream.write(f"\r[{bar}] {done}/{total} {message:<60.60}{end}")
        self.stream.flush()


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
