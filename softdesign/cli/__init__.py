"""The `softdesign` command line: parse, load, call the pipeline, map errors to exit codes.

Exit codes: 0 success, 1 processing failure, 2 bad usage or bad input.
With ``--json`` a command prints one JSON object on stdout and nothing else;
notes, progress and warnings go to stderr.

One module per command family: :mod:`~softdesign.cli.build` (validate, build
and one command per stage), :mod:`~softdesign.cli.pose`,
:mod:`~softdesign.cli.check`, :mod:`~softdesign.cli.report`, :mod:`~softdesign.cli.centerline`,
:mod:`~softdesign.cli.sample`, :mod:`~softdesign.cli.design` and :mod:`~softdesign.cli.pcc` (the ``pcc``
group); what they share is :mod:`~softdesign.cli.common`.
"""

from __future__ import annotations

import gc
from typing import Annotated

import typer

from softdesign.cli.build import blend, build, export, fit, ingest, kinematics, links, mould, validate
from softdesign.cli.centerline import centerline
from softdesign.cli.check import check
from softdesign.cli.common import list_whole_first_paragraphs, unwritable_output
from softdesign.cli.design import design
from softdesign.cli.init import init
from softdesign.cli.materials import materials
from softdesign.cli.pcc import PCC_SHORT_HELP, pcc_app
from softdesign.cli.pose import pose
from softdesign.cli.pressure import pressure
from softdesign.cli.report import report
from softdesign.cli.sample import sample
from softdesign.cli.schema import schema
from softdesign.cli.simulate import simulate
from softdesign.pipeline.parallel import one_blas_thread

#: Help is click's plain text, not typer's rich panels: rich markup ate every ``[default: ...]`` in the option
#: help (``--out`` read "Build folder .") and importing rich for it doubled the time of ``softdesign --help``
#: (issue 19).  The command list shows each command's whole first paragraph, as the panels did.
app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="Patient-specific soft actuators from VMTK vessel exports.",
    rich_markup_mode=None,
)


def _print_version(value: bool) -> None:
    if value:
        from softdesign import __version__

        typer.echo(f"softdesign {__version__}")
        raise typer.Exit()


@app.callback()
def _options(
    version: Annotated[
        bool, typer.Option("--version", help="Print softdesign's version and exit.", callback=_print_version,
                           is_eager=True)
    ] = False,
) -> None:
    """Patient-specific soft actuators from VMTK vessel exports."""


app.add_typer(pcc_app, name="pcc", short_help=PCC_SHORT_HELP)
for command in (
    validate, build, ingest, blend, links, kinematics, fit, export, mould, pose, check, report, sample, centerline,
    design, init, schema, materials, simulate, pressure,
):
    app.command()(command)
for group in (app, pcc_app):
    list_whole_first_paragraphs(group)


def main() -> None:
    """Console-script entry point.

    When the command is done (its files written and closed, whatever the exit code), everything alive is frozen
    out of the garbage collector's reach: the interpreter's exit then skips a last full collection over the
    hundreds of thousands of objects a build or a report leaves (0.3 to 0.5 s of the demo's build and report).
    Module teardown, atexit handlers and the flushing of stdout and stderr still run.  OpenBLAS is asked for one
    thread per process (:func:`softdesign.pipeline.parallel.one_blas_thread`) unless the environment sets it.
    Only here: the command line run in-process (tests' CliRunner, ``app``) is left alone.
    """
    one_blas_thread()  # before any command loads numpy
    try:
        with unwritable_output():  # > /dev/full: one line and exit 1
            app()
    finally:
        gc.freeze()


__all__ = [
    "app", "main", "validate", "build", "ingest", "blend", "links", "kinematics", "fit", "export", "mould",
    "pose", "check", "report", "sample", "centerline", "design", "init", "schema", "materials", "simulate",
]
