"""The manifest: software versions, inputs with sha256, the resolved case, stages, timing, metrics, outputs.

Outputs are those recorded by the stages in the new folder (this run's, and
later stages kept from an earlier run), each with its sha256 and the figures
its stage gives (volume, area, ...); outputs of a stale stage are flagged
``"stale": true``.  With ``records`` (each ``<stage>/stage.json``), the
manifest lists every file of the folder but itself.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from softdesign.config import Case
from softdesign.pipeline import layout
from softdesign.pipeline.stage import Results, Stage, StageRun, Status
from softdesign.pipeline.store import read_record, sha256_file
from softdesign.pipeline.versions import software_versions


def build_manifest(
    case: Case,
    folder: Path,
    stages: list[Stage],
    runs: list[StageRun],
    results: Results,
    inputs: list[Path],
    input_hashes: list[str],
) -> dict[str, Any]:
    """The manifest of ``folder`` (the new build folder, complete but for the manifest).

    Software, inputs with sha256, resolved case, stages, metrics, outputs, and
    ``records``: each stage's ``stage.json`` with its sha256, so that the
    manifest lists every other file of the folder.
    """
    figures: dict[str, dict[str, Any]] = {}
    for stage in stages:
        if stage.name in results:
            figures.update(stage.figures(results[stage.name]))
    stale = {r.name for r in runs if r.status == Status.STALE}
    outputs = [
        {**entry, **figures.get(entry["path"], {}), **({"stale": True} if entry["stage"] in stale else {})}
        for entry in _all_outputs(folder, stages)
    ]
    for entry in outputs:
        del entry["stage"]
    return {
        "software": software_versions(),
        "case": case.resolved(),
        "inputs": [
            {"path": case.resolved_path(p), "sha256": h, "bytes": p.stat().st_size}
            for p, h in zip(inputs, input_hashes, strict=True)
        ],
        "stages": [{"name": r.name, "status": r.status, "key": r.key} for r in runs],
        "timing_s": {r.name: round(r.seconds, 3) for r in runs if r.status not in (Status.KEPT, Status.STALE)},
        "metrics": {s.name: s.metrics(results[s.name]) for s in stages if s.name in results},
        "outputs": outputs,
        "records": [
            {"path": layout.stage_record(s.name), "sha256": sha256_file(folder / layout.stage_record(s.name))}
            for s in stages
            if (folder / layout.stage_record(s.name)).is_file()
        ],
    }


def _all_outputs(folder: Path, stages: list[Stage]) -> list[dict[str, Any]]:
    """Outputs recorded by the stages whose records are in ``folder``, with their stage."""
    found: dict[str, tuple[str, str]] = {}
    for stage in stages:
        record = read_record(folder / layout.stage_record(stage.name)) or {}
        found.update((rel, (stage.name, sha)) for rel, sha in record.get("outputs", {}).items())
    return [{"path": rel, "sha256": sha, "stage": name} for rel, (name, sha) in sorted(found.items())]
