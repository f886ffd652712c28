"""The `softdesign` command line: parse, load, call the pipeline, map errors to exit codes.

Exit codes: 0 success, 1 processing failure, 2 bad usage or bad input.
With ``--json`` a command prints one JSON object on stdout and nothing else;
notes, progress and warnings go to stderr.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from softdesign.cli_support import StageProgress, emit_json, run_guarded
from softdesign.check_cli import check
from softdesign.pcc_cli import pcc_app
from softdesign.pose_cli import pose
from softdesign.report_cli import report, report_after_build

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="Patient-specific soft actuators from VMTK vessel exports.",
)
app.add_typer(pcc_app, name="pcc")
app.command()(check)
app.command()(pose)
app.command()(report)

CaseArg = Annotated[Path, typer.Argument(help="The case file (YAML).", show_default=False)]
OutOpt = Annotated[Optional[Path], typer.Option("--out", "-o", help="Build folder (default: build/<name>).")]
ForceOpt = Annotated[bool, typer.Option("--force", help="Redo every stage, ignoring the cache.")]
ReportOpt = Annotated[bool, typer.Option("--report", help="Then write BUILD/report/index.html (softdesign report).")]


def _run(case_file: Path, out: Optional[Path], target: str | None, force: bool):
    """Load the case and run the stages through ``target``; returns (case, build_dir, results, runs)."""
    from softdesign.pipeline.api import build_through

    outcome = build_through(case_file, out, target, force, progress=StageProgress())
    return outcome.case, outcome.build_dir, outcome.results, outcome.runs


def _report(build_dir: Path, runs) -> None:
    for run in runs:
        typer.echo(f"[{run.name}] {run.status} ({run.seconds:.2f} s)")
        for line in run.lines:
            typer.echo(f"  {line}")
    typer.echo(f"build folder: {build_dir}")


def _stage_command(case_file: Path, out: Optional[Path], target: str | None, force: bool) -> None:
    def action() -> None:
        _, build_dir, _, runs = _run(case_file, out, target, force)
        _report(build_dir, runs)

    run_guarded(action)


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
def build(case_file: CaseArg, out: OutOpt = None, force: ForceOpt = False, with_report: ReportOpt = False) -> None:
    """Run every stage (unchanged stages are skipped) and write the manifest; --report adds the HTML report."""

    def action() -> None:
        _, build_dir, _, runs = _run(case_file, out, None, force)
        _report(build_dir, runs)
        if with_report:
            report_after_build(build_dir)

    run_guarded(action)


@app.command()
def ingest(case_file: CaseArg, out: OutOpt = None, force: ForceOpt = False) -> None:
    """Read and check the inputs; keep them, in mm, under BUILD/ingest."""
    _stage_command(case_file, out, "ingest", force)


@app.command()
def blend(case_file: CaseArg, out: OutOpt = None, force: ForceOpt = False) -> None:
    """Smooth and resample the centerlines, blend c(q, l), frames; figures per export q."""
    _stage_command(case_file, out, "blend", force)


@app.command()
def fit(case_file: CaseArg, out: OutOpt = None, force: ForceOpt = False) -> None:
    """Fit rho(l, a) per link to the wall; print the metrics table (true distances, hold-out)."""
    _stage_command(case_file, out, "fit", force)


@app.command()
def export(case_file: CaseArg, out: OutOpt = None, force: ForceOpt = False) -> None:
    """Checked watertight solids of S(q) at every export q (STL and the other formats asked for)."""
    _stage_command(case_file, out, "export", force)


@app.command()
def kinematics(
    case_file: CaseArg,
    out: OutOpt = None,
    force: ForceOpt = False,
    q: Annotated[Optional[str], typer.Option(help="One q for every link ('0.5') or one per link ('0.2,0.8,1').")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object on stdout.")] = False,
) -> None:
    """Links, S_T_E and POE per link; with --q, the chain at that q (one per link allowed)."""

    def action() -> None:
        from softdesign.pipeline.kinematics_stage import pose_document

        q_values = None if q is None else _q_values(q)
        case, build_dir, results, runs = _run(case_file, out, "kinematics", force)
        if q_values is None:
            if as_json:
                emit_json(results["kinematics"].document)
            else:
                _report(build_dir, runs)
            return
        document = pose_document(results["kinematics"].chain, q_values)
        payload = {
            "q": document["q"],
            "links": [{k: link[k] for k in KINEMATICS_LINK_KEYS} for link in document["links"]],
            "base_to_tip": document["base_to_tip"],
            "frames": case.frames,
        }
        if as_json:
            emit_json(payload)
        else:
            _print_pose(payload)

    run_guarded(action)


KINEMATICS_LINK_KEYS = ("index", "l_start", "l_end", "length", "transform", "poe")


def _q_values(text: str) -> list[float]:
    from softdesign.errors import ConfigError

    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        raise ConfigError(f"--q: expected numbers separated by commas (e.g. 0.5 or 0.2,0.8,1), got {text!r}") from None
    if not all(0.0 <= v <= 1.0 for v in values):
        raise ConfigError(f"--q: every value must lie in [0, 1], got {text!r}")
    return values


def _print_pose(payload: dict) -> None:
    typer.echo(f"q = {payload['q']} (frames {payload['frames']})")
    for link in payload["links"]:
        p = link["poe"]
        omega = "null" if p["omega"] is None else "[" + ", ".join(f"{v:.4f}" for v in p["omega"]) + "]"
        typer.echo(
            f"link {link['index']} l {link['l_start']:.3f}..{link['l_end']:.3f}: length {link['length']:.3f} mm, "
            f"theta1 {p['theta1']:.4f} mm, theta2 {p['theta2']:.5f} rad about {omega}"
        )
    typer.echo("base_to_tip:")
    for row in payload["base_to_tip"]:
        typer.echo("  " + "  ".join(f"{v:12.6f}" for v in row))


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
