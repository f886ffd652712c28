"""The manifest: software versions, inputs with sha256, the resolved case, stages, timing, metrics, outputs.

Outputs are those recorded by this run's stages and by earlier runs' stages
still in the folder, each with its sha256 and the figures its stage gives
(volume, area, ...); outputs of a stale stage are flagged ``"stale": true``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from softdesign.config import Case
from softdesign.pipeline import layout
from softdesign.pipeline.stage import Results, Stage, StageRun, Status
from softdesign.pipeline.store import Staging, read_record
from softdesign.versions import software_versions


def build_manifest(
    case: Case,
    build_dir: Path,
    stages: list[Stage],
    runs: list[StageRun],
    results: Results,
    inputs: list[Path],
    input_hashes: list[str],
    staging: Staging,
) -> dict[str, Any]:
    """The manifest: software, inputs with sha256, resolved case, stages, metrics, outputs."""
    figures: dict[str, dict[str, Any]] = {}
    for stage in stages:
        if stage.name in results:
            figures.update(stage.figures(results[stage.name]))
    stale = {r.name for r in runs if r.status == Status.STALE}
    outputs = [
        {**entry, **figures.get(entry["path"], {}), **({"stale": True} if entry["stage"] in stale else {})}
        for entry in _all_outputs(build_dir, stages, staging)
    ]
    for entry in outputs:
        del entry["stage"]
    return {
        "software": software_versions(),
        "case": case.resolved(),
        "inputs": [
            {"path": case.resolved_path(p), "sha256": h, "bytes": p.stat().st_size} for p, h in zip(inputs, input_hashes)
        ],
        "stages": [{"name": r.name, "status": r.status, "key": r.key} for r in runs]
        + [
            {"name": name, "status": Status.UNKNOWN, "key": _record(build_dir / layout.stage_record(name)).get("key")}
            for name in sorted(_kept_stage_names(build_dir) - {r.name for r in runs})
        ],
        "timing_s": {r.name: round(r.seconds, 3) for r in runs if r.status not in (Status.KEPT, Status.STALE)},
        "metrics": {s.name: s.metrics(results[s.name]) for s in stages if s.name in results},
        "outputs": outputs,
    }


def _all_outputs(build_dir: Path, stages: list[Stage], staging: Staging) -> list[dict[str, Any]]:
    """Outputs recorded by this run's stages, and by earlier runs' stages still in the folder, with their stage."""
    found: dict[str, tuple[str, str]] = {}
    for name in sorted(_kept_stage_names(build_dir) - {s.name for s in stages}):
        recorded = _record(build_dir / layout.stage_record(name)).get("outputs", {})
        found.update((rel, (name, sha)) for rel, sha in recorded.items())
    for stage in stages:
        record_path = layout.stage_record(stage.name)
        staged = record_path in staging.written
        source = _record(staging.staged_path(record_path) if staged else build_dir / record_path)
        if source:
            found.update((rel, (stage.name, sha)) for rel, sha in source.get("outputs", {}).items())
    return [{"path": rel, "sha256": sha, "stage": name} for rel, (name, sha) in sorted(found.items())]


def _kept_stage_names(build_dir: Path) -> set[str]:
    return {p.parent.name for p in build_dir.glob(layout.stage_record("*"))} if build_dir.is_dir() else set()


def _record(file: Path) -> dict[str, Any]:
    return read_record(file) or {}
