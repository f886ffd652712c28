"""The stages of a build, in order, and what each reads from the case."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from softdesign.config import Case
from softdesign.pipeline import blend_stage, export_stage, fit_stage, ingest, kinematics_stage
from softdesign.pipeline.run import Stage


def _ingest_describe(result: ingest.IngestResult) -> list[str]:
    c = result.summary["centerline"]
    lines = [f"centerline {c['file']}: {c['polylines']} polyline(s), branch-split: {c['branch_split']}"]
    for p in c["paths"]:
        mark = "*" if p["path"] == c["selected"] else " "
        lines.append(f" {mark} path {p['path']}: {p['points']} points, {p['length_mm']:.2f} mm")
    if c["radius_range_mm"]:
        lo, hi = c["radius_range_mm"]
        lines.append(f"   radius {lo:.3f} .. {hi:.3f} mm (MaximumInscribedSphereRadius)")
    s = result.summary["surface"]
    if s:
        kind = "capped (watertight)" if s["capped"] else f"open, {s['boundary_loops']} boundary loop(s)"
        lines.append(f"surface {s['file']}: {s['vertices']} vertices, {s['faces']} triangles, {kind}")
    lines.append(f"units: {result.summary['units']} (converted to mm)")
    return lines + list(result.notes)


INGEST = Stage(
    name="ingest",
    version=ingest.VERSION,
    sections=("units", "final", "initial", "intermediate"),
    upstream=(),
    compute=lambda case, results: ingest.run_ingest(case),
    write=ingest.write_ingest,
    load=lambda build_dir, results: ingest.load_ingest(build_dir),
    describe=_ingest_describe,
    metrics=lambda result: result.summary,
)

BLEND = Stage(
    name="blend",
    version=blend_stage.VERSION,
    sections=("initial", "resample", "frames", "blend"),
    upstream=("ingest",),
    compute=lambda case, results: blend_stage.run_blend(case, results["ingest"]),
    write=blend_stage.write_blend,
    load=lambda build_dir, results: blend_stage.load_blend(build_dir),
    describe=blend_stage.describe_blend,
    metrics=lambda result: result.summary,
)

KINEMATICS = Stage(
    name="kinematics",
    version=kinematics_stage.VERSION,
    sections=("links", "export"),
    upstream=("blend",),
    compute=lambda case, results: kinematics_stage.run_kinematics(case, results["blend"]),
    write=kinematics_stage.write_kinematics,
    load=lambda build_dir, results: kinematics_stage.load_kinematics(build_dir, results["blend"]),
    describe=kinematics_stage.describe_kinematics,
    metrics=lambda result: {"links": len(result.document["links"]), "file": kinematics_stage.FILE},
)

FIT = Stage(
    name="fit",
    version=fit_stage.VERSION,
    sections=("fit", "initial", "links"),
    upstream=("ingest", "blend"),
    compute=lambda case, results: fit_stage.run_fit(case, results["ingest"], results["blend"]),
    write=fit_stage.write_fit,
    load=lambda build_dir, results: fit_stage.load_fit(build_dir),
    describe=fit_stage.describe_fit,
    metrics=fit_stage.fit_metrics,
)

EXPORT = Stage(
    name="export",
    version=export_stage.VERSION,
    sections=("export",),
    upstream=("kinematics", "fit"),
    compute=lambda case, results: export_stage.run_export(case, results["kinematics"], results["fit"]),
    write=export_stage.write_export,
    load=lambda build_dir, results: export_stage.load_export(build_dir),
    describe=export_stage.describe_export,
    metrics=lambda result: {k: v for k, v in result.summary.items() if k != "meshes"},
    figures=export_stage.output_figures,
)

#: Every stage, in build order.
STAGES: list[Stage] = [INGEST, BLEND, KINEMATICS, FIT, EXPORT]


def stages_through(name: str) -> list[Stage]:
    """The stages up to and including ``name`` (its upstream, in order)."""
    names = [s.name for s in STAGES]
    return STAGES[: names.index(name) + 1]


def input_files(case: Case) -> list[Path]:
    """Files the build reads."""
    return ingest.input_files(case)


__all__: list[Any] = ["STAGES", "stages_through", "input_files"]
