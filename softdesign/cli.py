"""The `softdesign` command line: parse, load, call the pipeline, map errors to exit codes.

Exit codes: 0 success, 1 processing failure, 2 bad usage or bad input.
With ``--json`` a command prints one JSON object on stdout and nothing else;
notes, progress and warnings go to stderr.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from softdesign.cli_support import note, run_guarded
from softdesign.errors import SoftdesignError
from softdesign.pcc_cli import pcc_app

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="Patient-specific soft actuators from VMTK vessel exports.",
)
app.add_typer(pcc_app, name="pcc")

CaseArg = Annotated[Path, typer.Argument(help="The case file (YAML).", show_default=False)]
OutOpt = Annotated[Optional[Path], typer.Option("--out", "-o", help="Build folder [default: build/<name>].")]
ForceOpt = Annotated[bool, typer.Option("--force", help="Redo every stage, ignoring the cache.")]


def _build_dir(case, out: Optional[Path]) -> Path:
    return out if out is not None else Path("build") / case.name


def _run(case_file: Path, out: Optional[Path], target: str | None, force: bool) -> None:
    from softdesign.config import load_case
    from softdesign.pipeline.run import RunOptions, run_stages
    from softdesign.pipeline.stages import STAGES, input_files, stages_through

    case = load_case(case_file)
    build_dir = _build_dir(case, out)
    stages = STAGES if target is None else stages_through(target)
    try:
        _, runs = run_stages(case, build_dir, stages, input_files(case), RunOptions(force=force, progress=note))
    except SoftdesignError as err:
        raise type(err)(f"{case_file}: {err}") from err
    for run in runs:
        typer.echo(f"[{run.name}] {run.status} ({run.seconds:.2f} s)")
        for line in run.lines:
            typer.echo(f"  {line}")
    typer.echo(f"build folder: {build_dir}")


@app.command()
def validate(case_file: CaseArg) -> None:
    """Check a case file (schema, ranges, input files present) without building."""

    def action() -> None:
        from softdesign.config import load_case
        from softdesign.pipeline.stages import input_files

        case = load_case(case_file)
        files = input_files(case)
        typer.echo(f"{case_file}: valid (case '{case.name}', {len(files)} input file(s) found)")

    run_guarded(action)


@app.command()
def build(case_file: CaseArg, out: OutOpt = None, force: ForceOpt = False) -> None:
    """Run every stage (unchanged stages are skipped) and write the manifest."""
    run_guarded(lambda: _run(case_file, out, None, force))


@app.command()
def ingest(case_file: CaseArg, out: OutOpt = None, force: ForceOpt = False) -> None:
    """Read and check the inputs; keep them, in mm, under BUILD/ingest."""
    run_guarded(lambda: _run(case_file, out, "ingest", force))


@app.command()
def sample(out_dir: Annotated[Path, typer.Argument(help="Folder to write the sample vessel into.")]) -> None:
    """Write the project's sample vessel (centerline .vtp and surface .stl), VMTK-style."""

    def action() -> None:
        from softdesign.io.sample_files import write_sample

        for path in write_sample(out_dir):
            typer.echo(f"wrote {path}")

    run_guarded(action)


def main() -> None:
    """Console-script entry point."""
    app()
