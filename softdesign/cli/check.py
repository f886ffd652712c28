"""`softdesign check BUILD_DIR --reference REF_DIR`: regression check of a build against a reference.

Parsing and printing live here; the comparison is :mod:`softdesign.regression`.
Register with ``app.command()(check)`` in :mod:`softdesign.cli`.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from softdesign.cli.common import emit_json, note, run_guarded

if TYPE_CHECKING:  # the comparison imports scipy, trimesh and vtk: only when a check runs
    from softdesign.regression import CheckReport, Figure

#: Significant digits of the figures in the table (JSON keeps full precision).
TABLE_DIGITS = 4
HEADER = ("item", "figure", "change", "tolerance", "status", "note")


def check(
    build_dir: Annotated[Path, typer.Argument(help="The build folder to check.", show_default=False)],
    reference: Annotated[
        Path,
        typer.Option("--reference", "-r", help="The reference build folder (e.g. a golden one).", show_default=False),
    ],
    tolerance_mm: Annotated[
        float,
        typer.Option("--tolerance-mm", help="Surface distance, transform translation, lengths, and the most a fit "
                     "or design residual may move, mm."),
    ] = 0.01,
    rtol: Annotated[float, typer.Option(
        "--rtol", help="Relative change of mesh volume and area and of stage figures; a residual (fit, design) "
        "within the smaller of this and its absolute tolerance.")] = 1e-3,
    rotation_tol: Annotated[
        float, typer.Option("--rotation-tol", help="Rotation between link transforms and POE theta2, and the "
                            "most the design's tip angle may move, rad.")
    ] = 1e-4,
    json_out: Annotated[bool, typer.Option("--json", help="Print one JSON object on stdout.")] = False,
    failures_only: Annotated[
        bool,
        typer.Option("--failures-only", help="List only the figures outside tolerance (the verdict counts all)."),
    ] = False,
) -> None:
    """Compare meshes (by geometry), kinematics and every stage's figures with a reference build.

    Exit 0 when every figure is within tolerance, 1 when one is not (or a mesh
    is missing on either side), 2 for a missing folder or bad option.  A
    reference's golden.json (decimation error per mesh) widens that mesh's
    tolerances.  A warning (not an error) says when the two are different
    cases (case names or input files differ).
    """

    def action() -> None:
        from softdesign.regression import CheckOptions, check_build

        options = CheckOptions(distance_mm=tolerance_mm, rtol=rtol, rotation_rad=rotation_tol)
        report = check_build(build_dir, reference, options, progress=note)
        for warning in report.warnings:
            note(f"warning: {warning}")
        if json_out:
            emit_json(report.as_dict(failures_only))
            for line in summary_lines(report):
                note(line)
        else:
            shown = report.failures if failures_only else report.figures
            table = table_lines(shown) + [""] if shown else []
            for line in table + summary_lines(report):
                typer.echo(line)
        if not report.passed:
            raise typer.Exit(code=1)

    run_guarded(action)


def table_lines(figures: tuple[Figure, ...]) -> list[str]:
    """One aligned row per figure: item, figure, change, tolerance, PASS/FAIL, note."""
    rows = [HEADER] + [
        (f.item, f.figure, _change_text(f), _number_text(f.tolerance), "PASS" if f.passed else "FAIL", f.note)
        for f in figures
    ]
    widths = [max(len(row[i]) for row in rows) for i in range(len(HEADER) - 1)]
    padded = ["  ".join(cell.ljust(w) for cell, w in zip(row[:-1], widths, strict=True)) for row in rows]
    return [(cells + "  " + row[-1]).rstrip() for cells, row in zip(padded, rows, strict=True)]


def summary_lines(report: CheckReport) -> list[str]:
    """The verdict, then every failed figure with its value and tolerance, then the notes."""
    lines = [f"note: {text}" for text in report.notes]
    total, build, ref = len(report.figures), report.build_dir, report.reference_dir
    if report.passed:
        return lines + [f"check PASSED: {total} figure(s) of {build} within tolerance of {ref}"]
    failures = report.failures
    lines.append(f"check FAILED: {len(failures)} of {total} figure(s) of {build} moved from {ref}:")
    for f in failures:
        lines.append(f"  {f.item}: {f.figure} {_verdict_text(f)}")
    return lines


def _verdict_text(f: Figure) -> str:
    if f.change is None:
        text = f"build {_value_text(f.build)}, reference {_value_text(f.reference)}"
    else:
        text = f"{_number_text(f.change)} outside tolerance {_number_text(f.tolerance)}"
    return text + (f" ({f.note})" if f.note else "")


def _change_text(f: Figure) -> str:
    if f.change is None:
        return f"{_value_text(f.build)} (ref {_value_text(f.reference)})"
    return _number_text(f.change)


def _value_text(value) -> str:
    return "-" if value is None else _number_text(value) if isinstance(value, float) else str(value)


def _number_text(value) -> str:
    return "-" if value is None else f"{value:.{TABLE_DIGITS}g}"
