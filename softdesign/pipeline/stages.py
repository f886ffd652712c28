"""The stages of a build, in order, and what each reads from the case."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from softdesign.config import Case
from softdesign.pipeline import ingest
from softdesign.pipeline.run import Results, Stage


def _ingest_compute(case: Case, results: Results) -> ingest.IngestResult:  # noqa: ARG001 - no upstream
    return ingest.run_ingest(case)


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


def _ingest_metrics(result: ingest.IngestResult) -> dict[str, Any]:
    return result.summary


INGEST = Stage(
    name="ingest",
    version=ingest.VERSION,
    sections=("units", "final", "initial", "intermediate"),
    upstream=(),
    compute=_ingest_compute,
    write=ingest.write_ingest,
    load=ingest.load_ingest,
    describe=_ingest_describe,
    metrics=_ingest_metrics,
)

#: Every stage, in build order.
STAGES: list[Stage] = [INGEST]


def stages_through(name: str) -> list[Stage]:
    """The stages up to and including ``name`` (its upstream, in order)."""
    names = [s.name for s in STAGES]
    return STAGES[: names.index(name) + 1]


def input_files(case: Case) -> list[Path]:
    """Files the build reads."""
    return ingest.input_files(case)
