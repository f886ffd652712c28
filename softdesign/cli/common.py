"""What every command shares: options, parsers, error mapping, JSON output, notes on stderr.

Options are declared once here (``CaseArg``, ``OutOpt``, ``ForceOpt``,
``JsonOpt``, ``QOpt``) so that a flag means the same thing in every command:
``--out/-o`` is always the build folder.  The two list parsers (``--q`` and
the distance lists ``--d``/``--pcc-d``) are the only ones; they raise
:class:`~softdesign.errors.ConfigError` naming the option and the fix.
"""

from __future__ import annotations

import errno
import inspect
import json
import math
import os
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated, Any, TypeVar

import typer

from softdesign.errors import ConfigError, SoftdesignError

T = TypeVar("T")

CaseArg = Annotated[Path, typer.Argument(help="The case file (YAML).", show_default=False)]
OutOpt = Annotated[Path | None, typer.Option("--out", "-o", help="Build folder [default: build/<name>].")]
ForceOpt = Annotated[bool, typer.Option("--force", help="Redo every stage, ignoring the cache.")]
#: ``--force`` of a command that writes a file with ``--output`` and builds nothing.
ReplaceOpt = Annotated[bool, typer.Option("--force", help="Replace the --output file if it exists.")]
JsonOpt = Annotated[bool, typer.Option("--json", help="Print one JSON object on stdout.")]
QOpt = Annotated[
    str,
    typer.Option("--q", help="One q for every link ('0.5') or one per link ('0.2,0.8,1'), each in [0, 1].",
                 show_default=False),
]

#: The one angle convention of every text output (JSON keeps radians, DESIGN.md).
TEXT_ANGLES = "angles in degrees in this text (the JSON of --json gives radians)"
#: What Ctrl-C prints (exit 130, the shell's code for SIGINT).
INTERRUPTED = "interrupted; the previous build is kept (nothing half-written is left)"

Q_FIX = "give one q for every link (e.g. 0.5) or one per link separated by commas (e.g. 0.2,0.8,1), each in [0, 1]"


def list_whole_first_paragraphs(group: typer.Typer) -> None:
    """Let ``--help`` list each command of ``group`` with the whole first paragraph of its docstring.

    Click's plain help cuts a command's line at about 60 characters ("...") unless it has a short help;
    the first paragraph is written to be that line.
    """
    for info in group.registered_commands:
        if info.short_help is None and info.callback is not None and info.callback.__doc__:
            info.short_help = " ".join(inspect.cleandoc(info.callback.__doc__).split("\n\n")[0].split())


def note(message: str) -> None:
    """Write a human note to stderr (stdout is kept for --json output)."""
    typer.echo(message, err=True)


def emit_json(payload: dict[str, Any]) -> None:
    """Print one JSON object on stdout, keys in a fixed order."""
    typer.echo(json.dumps(payload, indent=2, allow_nan=False))


def run_guarded(action: Callable[[], T]) -> T:
    """Run ``action``; turn a SoftdesignError into a message and its exit code.

    A user error (bad case file, bad input) exits 2 and a processing failure
    exits 1, each with a one-paragraph message and no traceback; Ctrl-C exits
    130 saying that the previous build is kept.  Anything
    else is a bug and propagates with its traceback.
    """
    try:
        return action()
    except SoftdesignError as err:
        typer.echo(f"error: {err}", err=True)
        raise typer.Exit(code=err.exit_code) from None
    except KeyboardInterrupt:
        # every command writes through a staging folder or a temporary name, removed on the way out: a build
        # folder (or an output file) is the previous one, whole
        typer.echo(INTERRUPTED, err=True)
        raise typer.Exit(code=130) from None


#: Why an output cannot be written that is no bug: a full disk or quota, a device that refuses (/dev/full), a file
#: too large for its file system, an I/O error.
_UNWRITABLE = {errno.ENOSPC, errno.EDQUOT, errno.EIO, errno.EFBIG}


@contextmanager
def unwritable_output() -> Iterator[None]:
    """Output that cannot be written (``> /dev/full``, a full disk): one line on stderr and exit 1, no traceback.

    Standard output is flushed inside the block, so that what a command printed fails here rather than in the
    interpreter's exit; it is then pointed at the null device, so that the exit does not try again.
    """
    try:
        try:
            yield
        finally:
            sys.stdout.flush()
    except OSError as err:
        if err.errno not in _UNWRITABLE:
            raise
        where = os.fsdecode(err.filename) if err.filename is not None else "the standard output"
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError, AttributeError):
            pass
        sys.stderr.write(f"error: cannot write {where} ({err.strerror or err}); free space on that disk or write "
                         "the output elsewhere\n")
        raise SystemExit(1) from None


def finite_number(text: str, what: str, fix: str) -> float:
    """``text`` as a finite float, or a ConfigError naming ``what`` and giving ``fix``."""
    try:
        value = float(text)
    except ValueError:
        raise ConfigError(f"{what}: '{text.strip()}' is not a number; {fix}") from None
    if not math.isfinite(value):
        raise ConfigError(f"{what}: got {text.strip()}, expected a finite number; {fix}")
    return value


def q_values_from_text(text: str) -> list[float]:
    """Parse ``--q`` into a list of q values, each finite and in [0, 1].

    Raises
    ------
    ConfigError
        An empty entry, a non-number, or a value outside [0, 1].
    """
    values = []
    for i, part in enumerate(text.split(","), start=1):
        try:
            value = float(part)
        except ValueError:
            raise ConfigError(f"--q: value {i} '{part.strip()}' of {text!r} is not a number; {Q_FIX}") from None
        if not (math.isfinite(value) and 0.0 <= value <= 1.0):
            raise ConfigError(f"--q: value {i} of {text!r} is {part.strip()}, expected a number in [0, 1]; {Q_FIX}")
        values.append(value)
    return values


def distances_from_text(
    text: str, option: str, what: str, count: int | None = None, item: str = "section", where: str = ""
) -> list[float]:
    """Parse a distance list (``--d``, ``--pcc-d``): one value in mm for every item or one per item, each > 0.

    Parameters
    ----------
    text : the option's value, e.g. ``"15"`` or ``"15,14,13"``
    option : the option's name for messages, e.g. ``"--d"``
    what : what the distance is, for the fix (e.g. "cable distance from the backbone")
    count : how many items there are, or None when not known yet (values are then only checked)
    item, where : what an item is ("section", "link") and what they belong to, for the count message

    Returns
    -------
    list of float, mm: ``count`` values (one given value repeated), or the values as given when ``count`` is None.
    """
    example = ",".join(["15"] * count) if count else "15,14,13"
    per = f"one per {item} ({count} values, e.g. \"{example}\")" if count else f'one per {item} (e.g. "{example}")'
    fix = f'give the {what} in mm: one value ("15") or {per}'
    values = []
    for i, part in enumerate(text.split(","), start=1):
        value = finite_number(part, f"{option} value {i}", fix)
        if value <= 0:
            raise ConfigError(f"{option} value {i}: {value:g} mm, expected > 0; {fix}")
        values.append(value)
    if count is not None and len(values) not in (1, count):
        suffix = f" in {where}" if where else ""
        raise ConfigError(f"{option}: {len(values)} values for {count} {item}(s){suffix}; {fix}")
    if count is not None and len(values) == 1:
        return values * count
    return values


def point_from_text(text: str, option: str) -> tuple[float, float, float]:
    """Parse a point ``x,y,z`` (``--inlet``, ``--outlet``): three finite numbers.

    Raises
    ------
    ConfigError
        Not three entries, or an entry that is not a finite number.
    """
    parts = text.split(",")
    fix = f"give the point as three numbers separated by commas, in the surface's units (e.g. {option} 12.5,-3,40)"
    if len(parts) != 3:
        raise ConfigError(f"{option} {text!r}: {len(parts)} value(s), expected 3 (x,y,z); {fix}")
    values = []
    for part in parts:
        try:
            value = float(part)
        except ValueError:
            raise ConfigError(f"{option} {text!r}: '{part.strip()}' is not a number; {fix}") from None
        if not math.isfinite(value):
            raise ConfigError(f"{option} {text!r}: '{part.strip()}' is not finite; {fix}")
        values.append(value)
    return values[0], values[1], values[2]


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


def refuse_overwriting_inputs(option: str, target: Path, inputs: list[Path]) -> None:
    """ConfigError when ``target`` (a file a command writes) is one of ``inputs`` (the case file, its input files).

    The same file by any name counts (a link, ``./``, another spelling): compared by real path and by identity.
    """
    real = Path(os.path.realpath(target))
    for item in inputs:
        same = real == Path(os.path.realpath(item))
        if not same and target.exists() and item.exists():
            same = os.path.samefile(target, item)
        if same:
            raise ConfigError(f"{option} {target}: is {item}, an input of this case, which writing would overwrite; "
                              "write to another file")


def check_output_file(option: str, target: Path, force: bool, inputs: list[Path] | tuple[Path, ...] = ()) -> None:
    """Refuse, before any work, an output file ``target`` that writing would damage (ConfigError with the fix).

    Refused: a target that exists and is not a regular file (a device, a FIFO, a folder, a link); one of the
    ``inputs``; a target inside a softdesign build folder (only ``build`` writes there, and a file it did not
    write makes every rebuild refuse the folder), even with ``--force``; an existing file without ``force``.
    """
    from softdesign.io.atomic import check_replaceable
    from softdesign.pipeline.out_folder import build_folder_holding

    if os.path.isdir(target) and not os.path.islink(target):
        raise ConfigError(f"{option} {target}: is a folder, expected the name of the file to write")
    check_replaceable(target)
    if not target.parent.is_dir():
        raise ConfigError(f"{option} {target}: the folder {target.parent} does not exist; create it first")
    refuse_overwriting_inputs(option, target, list(inputs))
    build_dir = build_folder_holding(target.parent)
    if build_dir is not None:
        raise ConfigError(f"{option} {target}: is inside the build folder {build_dir}, which only `softdesign build` "
                          "writes (a file it did not write there makes every rebuild refuse the folder); "
                          "write it outside the build folder")
    if os.path.lexists(target) and not force:
        raise ConfigError(f"{option} {target}: already exists; give --force to replace it, or another name")


def case_inputs(case_file: Path) -> list[Path]:
    """The case file and every file its build reads (for :func:`refuse_overwriting_inputs`); the case is checked."""
    from softdesign.config import load_case
    from softdesign.pipeline.inputs import input_fields

    return [case_file, *(path for _, path in input_fields(load_case(case_file)))]
