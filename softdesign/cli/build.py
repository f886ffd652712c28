"""`softdesign validate|build|ingest|blend|links|kinematics|fit|export|mould CASE.yaml`: the case file and its stages.

Parsing and printing live here; the stages are :mod:`softdesign.pipeline`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Any

import typer

from softdesign.cli.common import (
    CaseArg,
    ForceOpt,
    JsonOpt,
    OutOpt,
    emit_json,
    q_values_from_text,
    run_guarded,
)

ReportOpt = Annotated[bool, typer.Option("--report", help="Then write BUILD/report/index.html (softdesign report).")]
StrictOpt = Annotated[
    bool,
    typer.Option(
        "--strict", help="Exit 1 when the design is not feasible for the case's material (the build is kept)."
    ),
]
KinematicsQOpt = Annotated[
    str | None, typer.Option("--q", help="One q for every link ('0.5') or one per link ('0.2,0.8,1'), each in [0, 1].")
]
JobsOpt = Annotated[
    int | None,
    typer.Option("--jobs", "-j", help="Worker processes for the per-q work (meshes, feasibility) [default: the cores "
                 "available]; 1 runs everything in this process. The outputs are the same bytes whatever N.",
                 show_default=False),
]
#: The keys of each link in ``kinematics --q --json`` (DESIGN.md).
KINEMATICS_LINK_KEYS = ("index", "l_start", "l_end", "length", "transform", "poe")


def _run(case_file: Path, out: Path | None, target: str | None, force: bool, jobs: int | None = 1):
    """Load the case and run the stages through ``target`` (every stage when None); ``jobs`` None: every core."""
    from softdesign.cli.item_bar import build_progress
    from softdesign.pipeline.api import build_through
    from softdesign.pipeline.item_progress import items_told_to
    from softdesign.pipeline.parallel import checked_jobs

    workers = checked_jobs(jobs)
    with build_progress() as (stage_line, per_mesh), items_told_to(per_mesh):  # the mesh bar: on a terminal only
        outcome = build_through(case_file, out, target, force, progress=stage_line, jobs=workers)
    _warn_arc_misses(case_file, outcome.results)
    _warn_design_miss(case_file, outcome.results)
    return outcome


def _warn_design_miss(case_file: Path, results: dict[str, Any]) -> None:
    """On stderr: the case's design (design: block) misses its tolerance (issue 30)."""
    design = results.get("design")
    if design is None:
        return
    from softdesign.cli.common import note
    from softdesign.pipeline.stages.design import miss_text

    miss = miss_text(design.document)
    if miss is not None:
        note(f"warning: {case_file}: {miss}")


def _warn_arc_misses(case_file: Path, results: dict[str, Any]) -> None:
    """On stderr: every link one constant-curvature arc misses at q = 1 by more than the stated tolerance."""
    if "kinematics" not in results:
        return
    from softdesign.cli.common import note
    from softdesign.kinematics.arc_check import arc_misses, link_arcs_at_final_shape

    for line in arc_misses(link_arcs_at_final_shape(results["kinematics"].chain)):
        note(f"warning: {case_file}: {line}")


def _print_runs(build_dir: Path, runs) -> None:
    for run in runs:
        typer.echo(f"[{run.name}] {run.status} ({run.seconds:.2f} s)")
        for line in run.lines:
            typer.echo(f"  {line}")
    # the single-supply device's verdict (the actuation stage's "device: " line) is the build's last word
    for line in [line for run in runs if run.name == "actuation" for line in run.lines if line.startswith("device: ")]:
        typer.echo(line)
    typer.echo(f"build folder: {build_dir}")


def _stage_command(case_file: Path, out: Path | None, target: str, force: bool, jobs: int | None = 1) -> None:
    def action() -> None:
        outcome = _run(case_file, out, target, force, jobs)
        _print_runs(outcome.build_dir, outcome.runs)

    run_guarded(action)


def validate(case_file: CaseArg) -> None:
    """Check a case file (schema, ranges) and open every input file (type, counts, arrays, size in the units)."""

    def action() -> None:
        from softdesign.config import load_case
        from softdesign.errors import errors_named_for
        from softdesign.pipeline.input_report import open_inputs
        from softdesign.pipeline.inputs import input_files

        case = load_case(case_file)
        files = input_files(case)
        with errors_named_for(case_file):
            lines = open_inputs(case)
        typer.echo(f"{case_file}: valid (case '{case.name}', {len(files)} input file(s) opened)")
        for line in lines:
            typer.echo(f"  {line}")

    run_guarded(action)


def build(
    case_file: CaseArg, out: OutOpt = None, force: ForceOpt = False, with_report: ReportOpt = False,
    strict: StrictOpt = False, jobs: JobsOpt = None,
) -> None:
    """Run every stage (unchanged stages are skipped) and write the manifest; --report adds the HTML report."""

    def action() -> bool:
        from softdesign.cli.report import report_after_build

        outcome = _run(case_file, out, None, force, jobs)
        _print_runs(outcome.build_dir, outcome.runs)
        if with_report:
            report_after_build(outcome.build_dir, jobs=jobs)
        # the skin's stretch (feasibility), the chambers' walls and extension (actuation), the 3D figures (swept mesh)
        judged = [outcome.results.get(name) for name in ("feasibility", "actuation", "volume_mesh")]
        return any(r is not None and r.summary.get("feasible") is False for r in judged)

    infeasible = run_guarded(action)
    if strict and infeasible:
        typer.echo(f"error: {case_file}: the design is not feasible for its material (WARN lines above); "
                   "--strict exits 1: change the design or the material", err=True)
        raise typer.Exit(code=1)


def ingest(case_file: CaseArg, out: OutOpt = None, force: ForceOpt = False) -> None:
    """Read and check the inputs; keep them, in mm, under BUILD/ingest."""
    _stage_command(case_file, out, "ingest", force)


def blend(case_file: CaseArg, out: OutOpt = None, force: ForceOpt = False) -> None:
    """Smooth and resample the centerlines, blend c(q, l), frames; figures per export q."""
    _stage_command(case_file, out, "blend", force)


def links(case_file: CaseArg, out: OutOpt = None, force: ForceOpt = False) -> None:
    """Split the actuator into links (links.count, breaks or length_mm); keep the breaks under BUILD/links."""
    _stage_command(case_file, out, "links", force)


def fit(case_file: CaseArg, out: OutOpt = None, force: ForceOpt = False) -> None:
    """Fit rho(l, a) per link to the wall; print the metrics table (true distances, hold-out)."""
    _stage_command(case_file, out, "fit", force)


def export(case_file: CaseArg, out: OutOpt = None, force: ForceOpt = False, jobs: JobsOpt = None) -> None:
    """Checked watertight solids of S(q) at every export q (STL and the other formats asked for)."""
    _stage_command(case_file, out, "export", force, jobs)


def mould(case_file: CaseArg, out: OutOpt = None, force: ForceOpt = False) -> None:
    """A two-part casting mould of the body at q = 0 (and a core for a hollow body): export.mould in the case."""

    def action() -> None:
        from softdesign.config import load_case
        from softdesign.errors import ConfigError

        if load_case(case_file).export.mould is None:
            raise ConfigError(f"{case_file}: no export.mould in the case file, so there is no mould to build; add "
                              "e.g. `mould: {margin_mm: 10, clearance_mm: 0.2}` under export: (README: the case file)")
        outcome = _run(case_file, out, "mould", force)
        _print_runs(outcome.build_dir, outcome.runs)

    run_guarded(action)


def kinematics(
    case_file: CaseArg, out: OutOpt = None, force: ForceOpt = False, q: KinematicsQOpt = None, as_json: JsonOpt = False
) -> None:
    """Links, S_T_E and POE per link; with --q, the chain at that q (one per link allowed)."""

    def action() -> None:
        from softdesign.pipeline.stages.kinematics import pose_document

        q_values = None if q is None else q_values_from_text(q)
        outcome = _run(case_file, out, "kinematics", force)
        if q_values is None:
            if as_json:
                emit_json(outcome.results["kinematics"].document)
            else:
                _print_runs(outcome.build_dir, outcome.runs)
            return
        document = pose_document(outcome.results["kinematics"].chain, q_values)
        payload = {
            "q": document["q"],
            "links": [{k: link[k] for k in KINEMATICS_LINK_KEYS} for link in document["links"]],
            "base_to_tip": document["base_to_tip"],
            "frames": outcome.case.frames,
        }
        if as_json:
            emit_json(payload)
        else:
            _print_pose(payload)

    run_guarded(action)


def _print_pose(payload: dict[str, Any]) -> None:
    typer.echo(f"q = {payload['q']} (frames {payload['frames']})")
    for link in payload["links"]:
        p = link["poe"]
        omega = "null" if p["omega"] is None else "[" + ", ".join(f"{v:.4f}" for v in p["omega"]) + "]"
        typer.echo(
            f"link {link['index']} l {link['l_start']:.3f}..{link['l_end']:.3f}: length {link['length']:.3f} mm, "
            f"theta1 {p['theta1']:.4f} mm, theta2 {math.degrees(p['theta2']):.4f} deg about {omega}"
        )
    typer.echo("base_to_tip:")
    for row in payload["base_to_tip"]:
        typer.echo("  " + "  ".join(f"{v:12.6f}" for v in row))
