"""`softdesign report BUILD_DIR`: the HTML page of plots of a build (and the hook for `build --report`).

Parsing and printing live here; the report is :mod:`softdesign.report.writer`.
Register with ``app.command()(report)`` in :mod:`softdesign.cli`; ``build
--report`` calls :func:`report_after_build` with the build folder.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer

from softdesign.cli.common import distances_from_text, note, run_guarded
from softdesign.cli.progress import part_progress


def pcc_d_from_text(text: str | None) -> tuple[float, ...] | None:
    """Parse ``--pcc-d``: one distance in mm for every link ("15") or one per link ("15,14,13"), each > 0."""
    if text is None:
        return None
    return tuple(distances_from_text(text, "--pcc-d", "chambers' distance from the backbone", item="link"))


def report_after_build(build_dir: Path, pcc_d: str | None = None, jobs: int | None = None) -> None:
    """Write the report of ``build_dir`` and print where it is (stdout) and what was left out (stderr).

    ``jobs``: worker processes for the figures (None: the cores available); checked before any work.
    """
    from softdesign.pipeline.parallel import checked_jobs
    from softdesign.report.writer import ReportOptions, write_report

    workers = checked_jobs(jobs, note=note)
    options = ReportOptions(pcc_d=pcc_d_from_text(pcc_d))
    start = time.perf_counter()
    with part_progress("report") as tick:  # a bar on a terminal only; logs get the one summary line below
        result = write_report(build_dir, options, tick, workers)
    seconds = time.perf_counter() - start
    for line in result.notes:
        note(f"report: {line}")
    slowest = sorted(result.seconds.items(), key=lambda item: -item[1])[:5]
    note("report: slowest parts: " + ", ".join(f"{name} {s:.1f} s" for name, s in slowest))
    for line in result.warnings:
        note(f"report: {line}")
    size = sum(result.files.values())
    typer.echo(
        f"report: {result.page} ({len(result.files)} files, {size / 1e6:.2f} MB, "
        f"checks {result.checks_passed}/{result.checks_total} passed, {seconds:.1f} s)"
    )


def report(
    build_dir: Annotated[Path, typer.Argument(help="The build folder (made by softdesign build).", show_default=False)],
    pcc_d: Annotated[
        str | None,
        typer.Option(
            "--pcc-d",
            help='Add the PCC chamber lengths over q: chamber distance from the backbone in mm, one value ("15") '
            'or one per link ("15,14,13").',
            show_default=False,
        ),
    ] = None,
    jobs: Annotated[
        int | None,
        typer.Option("--jobs", "-j", help="Worker processes drawing the figures side by side [default: the cores "
                     "available]; 1 draws everything in this process. The files are the same bytes whatever N.",
                     show_default=False),
    ] = None,
) -> None:
    """Write BUILD_DIR/report/index.html: the morph, surfaces, fit quality, kinematics, figures and checks, a GIF.

    Exit 0 when the page is written, 2 for a folder that is not a build or a
    bad option, 1 when drawing fails.  The page and its images replace an
    older report in one step; nothing else in the folder changes.
    """
    run_guarded(lambda: report_after_build(build_dir, pcc_d, jobs))
