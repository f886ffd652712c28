"""The manifest: software versions, inputs with sha256, the resolved case, stages, metrics, outputs; and the run log.

Outputs are those recorded by the stages in the new folder (this run's, and
later stages kept from an earlier run), each with its sha256 and the figures
its stage gives (volume, area, ...); outputs of a stale stage are flagged
``"stale": true``.  With ``records`` (each ``<stage>/stage.json``), the
manifest lists every file of the folder but itself and the run log.

``warnings`` and ``verdict`` are :mod:`softdesign.pipeline.notices`'s: every stage's notices once, and
one verdict from every stage's judgement; the terminal and the report print these, nothing else.

The manifest is a function of the build's inputs: the same bytes after a fresh build and after any sequence
of incremental ones (issue 35).  How the run went, each stage's status and seconds, goes to
:data:`~softdesign.pipeline.layout.RUN_LOG` (:func:`run_log`), which no check or report compares.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from softdesign.config import Case
from softdesign.pipeline import layout
from softdesign.pipeline.notices import Notice, notices_record, verdict_record
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
        **({"case_file": case.source} if case.source is not None else {}),
        "inputs": [
            {"path": case.resolved_path(p), "sha256": h, "bytes": p.stat().st_size}
            for p, h in zip(inputs, input_hashes, strict=True)
        ],
        "stages": [{"name": r.name, "key": r.key, **({"stale": True} if r.status == Status.STALE else {})}
                   for r in runs],
        "metrics": {s.name: s.metrics(results[s.name]) for s in stages if s.name in results},
        "outputs": outputs,
        "warnings": notices_record(build_notices(stages, runs, results)),
        "verdict": verdict_record(_judgements(stages, results)),
        "records": [
            {"path": layout.stage_record(s.name), "sha256": sha256_file(folder / layout.stage_record(s.name))}
            for s in stages
            if (folder / layout.stage_record(s.name)).is_file()
        ],
    }


STALE_TEXT = ("its outputs here were built from other inputs or settings than this run's: run `softdesign build` "
              "to redo them")


def build_notices(stages: list[Stage], runs: list[StageRun], results: Results) -> list[Notice]:
    """Every stage's warnings and notes in stage order, then one per stage whose outputs are out of date."""
    notices = [n for s in stages if s.name in results for n in s.warnings(results[s.name])]
    return notices + [Notice(r.name, "stale", "", STALE_TEXT) for r in runs if r.status == Status.STALE]


def _judgements(stages: list[Stage], results: Results) -> list[tuple[str, Any]]:
    """``(stage, judgement)`` of every stage with a result that judges the design."""
    found = ((s.name, s.judge(results[s.name])) for s in stages if s.name in results)
    return [(name, j) for name, j in found if j is not None]


def _all_outputs(folder: Path, stages: list[Stage]) -> list[dict[str, Any]]:
    """Outputs recorded by the stages whose records are in ``folder``, with their stage."""
    found: dict[str, tuple[str, str]] = {}
    for stage in stages:
        record = read_record(folder / layout.stage_record(stage.name)) or {}
        found.update((rel, (stage.name, sha)) for rel, sha in record.get("outputs", {}).items())
    return [{"path": rel, "sha256": sha, "stage": name} for rel, (name, sha) in sorted(found.items())]


def run_log(runs: list[StageRun]) -> dict[str, Any]:
    """:data:`~softdesign.pipeline.layout.RUN_LOG`: each stage's status in this run and its seconds (none for a
    stage kept or stale from an earlier run), and the stage's own log lines when it ran (e.g. each part's time)."""
    return {"stages": [{"name": r.name, "status": r.status,
                        **({} if r.status in (Status.KEPT, Status.STALE) else {"seconds": round(r.seconds, 3)}),
                        **({"log": r.log} if r.log else {})}
                       for r in runs]}
