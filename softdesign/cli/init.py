"""`softdesign init SURFACE [CENTERLINE] [--output case.yaml]`: a commented case file for one's own vessel files."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Annotated, Any, Literal

import typer

from softdesign.cli.common import check_output_file, note, run_guarded
from softdesign.errors import ConfigError, SoftdesignError

InitSurfaceArg = Annotated[
    Path, typer.Argument(help="The vessel surface (.stl .ply .obj .vtp .vtk), open at its ends or capped.",
                         show_default=False)
]
InitCenterlineArg = Annotated[
    Path | None,
    typer.Argument(help="Its centerlines (.vtp .vtk .csv .npy) [default: extracted from the surface].",
                   show_default=False),
]
InitOutputOpt = Annotated[Path, typer.Option("--output", help="The case file to write.")]
InitUnitsOpt = Annotated[
    Literal["mm", "cm", "m"] | None,
    typer.Option("--units", help="Units of the files [default: guessed from the vessel's size, with the evidence].",
                 show_default=False),
]
InitForceOpt = Annotated[bool, typer.Option("--force", help="Replace an existing case file.")]
#: A case name: what the case file's ``name`` accepts.
_NAME = re.compile(r"[^A-Za-z0-9_-]+")


def init(
    surface: InitSurfaceArg,
    centerline: InitCenterlineArg = None,
    output: InitOutputOpt = Path("case.yaml"),
    units: InitUnitsOpt = None,
    force: InitForceOpt = False,
) -> None:
    """Inspect a vessel's files and write a commented case file that builds (paths, sizes, units, inlet)."""

    def action() -> None:
        from softdesign.cli.schema import schema_text
        from softdesign.geometry.path_survey import MAIN_PATH_RULE
        from softdesign.io.atomic import atomic_target, write_bytes_atomically
        from softdesign.pipeline.case_template import SCHEMA_FILE, init_case_text
        from softdesign.pipeline.inspect_inputs import inspect_inputs, inspection_path_lines

        _check_output(output, [p for p in (surface, centerline) if p is not None], force)
        inspection = inspect_inputs(surface, centerline, units)
        name = _NAME.sub("-", output.stem).strip("-") or "case"
        text = init_case_text(inspection, output, name)
        schema_path = output.parent / SCHEMA_FILE
        try:
            if not schema_path.exists() or _is_our_schema(schema_path):
                write_bytes_atomically(schema_path, schema_text().encode())
            with atomic_target(output) as temporary:
                temporary.write_bytes(text.encode("utf-8", "surrogateescape"))
                _read_back(temporary, output, inspection)  # before it replaces anything
        except OSError as err:
            raise ConfigError(f"--output {output}: cannot write it ({err.strerror or err}); choose a writable path"
                              ) from err
        for line in inspection.notes:
            note(line)
        if inspection.guess is not None:
            note(f"units: {inspection.units}, guessed from the sizes ({inspection.guess.evidence[0]}, ...); "
                 "give --units to say otherwise")
        for line in inspection_path_lines(inspection):
            note(f"  {line}")
        if len(inspection.paths) > 1:
            note(f"path: {inspection.main}, the main vessel, {MAIN_PATH_RULE}; the case file's comments name the "
                 "alternatives")
        typer.echo(f"wrote {output}; build it with: softdesign build {output}")

    run_guarded(action)


def _check_output(output: Path, inputs: list[Path], force: bool) -> None:
    if output.suffix.lower() not in (".yaml", ".yml"):
        raise ConfigError(f"--output {output}: expected a .yaml case file, got '{output.suffix or '(no suffix)'}'")
    check_output_file("--output", output, force, inputs)
    for path in (*inputs, output):
        try:
            str(path.resolve()).encode("utf-8")
        except UnicodeEncodeError:
            raise ConfigError(f"{path!r}: its name is not UTF-8 text, and a case file is UTF-8; rename the file "
                              "(or its folder) with UTF-8 characters") from None


#: The largest file read to tell whether it is a schema softdesign wrote (the schema is about 40 kB).
MAX_SCHEMA_BYTES = 4 << 20


def _read_back(written: Path, output: Path, inspection: Any) -> None:
    """Read the case file just written (at ``written``, beside ``output``) as a build would; exit 1 if it differs.

    The paths must read back as the files inspected, and the case must pass the schema: a case that ``init``
    writes and ``build`` refuses is init's bug, reported before the file takes the name ``output``.
    """
    from softdesign.config import load_case
    from softdesign.io.case_yaml import parse_case_yaml, read_case_text
    from softdesign.pipeline.case_template import expected_paths, paths_read_back

    expected = expected_paths(inspection, output)
    try:
        got = paths_read_back(parse_case_yaml(written, read_case_text(written))[0])
        load_case(written)
    except ConfigError as err:
        got = {"error": str(err)}
    if got != expected:
        raise SoftdesignError(f"--output {output}: the case file init wrote does not read back as written "
                              f"(expected final paths {expected}, read {got}); nothing was written. This is a bug "
                              "in softdesign init: please report it with the files' names")


def _is_our_schema(path: Path) -> bool:
    """True when ``path`` holds a schema ``softdesign schema`` wrote (so it may be brought up to date)."""
    try:
        if not path.is_file() or path.stat().st_size > MAX_SCHEMA_BYTES:  # a FIFO would hang the read
            return False
        return json.loads(path.read_text()).get("title") == "softdesign case file"
    except (OSError, ValueError, AttributeError):
        return False
