"""Run stages in order with a content-hash cache, then write the manifest.

A stage's cache key is the sha256 of its name and version, the canonical
JSON of the case sections it reads, and the keys of the stages it depends on
(ingest: the sha256 of its input files).  A stage whose key matches the one
recorded in ``DIR/<stage>/stage.json`` *and* whose recorded outputs are all
present with their recorded hashes is skipped; nothing is reused merely
because a file exists.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from softdesign import __version__
from softdesign.config import Case
from softdesign.pipeline.store import MANIFEST, Staging, canonical_json, sha256_bytes, sha256_file

Results = dict[str, Any]
#: Statuses of a later stage's outputs kept from an earlier run (RunOptions.later).
KEPT = "kept"
STALE = "stale"


@dataclass(frozen=True)
class Stage:
    """One pipeline stage.

    Attributes
    ----------
    name, version : identify the code; bump ``version`` when outputs change
    sections : case keys whose values change the outputs
    upstream : stages whose results ``compute`` reads
    compute : (case, results of upstream stages) -> result; no file writes
    write : (result, staging) -> None; stages the outputs under ``name/``
    load : (build_dir, results of upstream stages) -> result, for a skipped stage
    describe : result -> short human summary lines
    metrics : result -> JSON-ready figures for the manifest
    figures : result -> {output path: figures} merged into the manifest's outputs
    """

    name: str
    version: int
    sections: tuple[str, ...]
    upstream: tuple[str, ...]
    compute: Callable[[Case, Results], Any]
    write: Callable[[Any, Staging], None]
    load: Callable[[Path, Results], Any]
    describe: Callable[[Any], list[str]]
    metrics: Callable[[Any], dict[str, Any]]
    figures: Callable[[Any], dict[str, dict[str, Any]]] = lambda result: {}


@dataclass
class StageRun:
    """What happened to one stage in a run."""

    name: str
    key: str
    status: str  # "ran" | "skipped" | KEPT | STALE (a later stage, not run: see RunOptions.later)
    seconds: float
    lines: list[str] = field(default_factory=list)


def stage_key(stage: Stage, case: Case, upstream_keys: list[str], input_hashes: list[str]) -> str:
    """The content hash that decides whether ``stage`` must run again."""
    resolved = case.resolved()
    payload = {
        "stage": stage.name,
        "version": stage.version,
        "config": {s: resolved.get(s) for s in stage.sections},
        "upstream": upstream_keys,
        "inputs": input_hashes,
    }
    return sha256_bytes(canonical_json(payload).encode("utf-8"))


def _recorded(build_dir: Path, stage: Stage) -> dict[str, Any] | None:
    file = build_dir / stage.name / "stage.json"
    if not file.is_file():
        return None
    try:
        return json.loads(file.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError):
        return None


def _up_to_date(build_dir: Path, stage: Stage, key: str) -> bool:
    record = _recorded(build_dir, stage)
    if record is None or record.get("key") != key:
        return False
    outputs = record.get("outputs", {})
    return all((build_dir / rel).is_file() and sha256_file(build_dir / rel) == sha for rel, sha in outputs.items())


@dataclass(frozen=True)
class RunOptions:
    """How to run: which stages, forced or cached, where to report progress."""

    force: bool = False
    progress: Callable[[str], None] = lambda line: None
    #: stages after the target: not run, but their outputs kept from an earlier run are checked
    #: against what they would be built from now (``kept`` and loaded, or ``stale``)
    later: tuple[Stage, ...] = ()


def run_stages(
    case: Case, build_dir: Path, stages: list[Stage], inputs: list[Path], options: RunOptions = RunOptions()
) -> tuple[Results, list[StageRun]]:
    """Run ``stages`` (in order, upstream first) into ``build_dir``.

    All new files are staged and committed only when every stage succeeded;
    a failure leaves the previous build folder as it was.
    """
    build_dir = Path(build_dir)
    input_hashes = [sha256_file(p) for p in inputs]
    results: Results = {}
    keys: dict[str, str] = {}
    runs: list[StageRun] = []
    with Staging(build_dir) as staging:
        for index, stage in enumerate(stages):
            upstream = [keys[u] for u in stage.upstream]
            keys[stage.name] = stage_key(stage, case, upstream, input_hashes if not stage.upstream else [])
            step = RunOptions(options.force, _counted(options.progress, index, len(stages)))
            runs.append(_run_one(stage, case, build_dir, keys[stage.name], results, staging, step))
        for stage in options.later:
            if (build_dir / stage.name / "stage.json").is_file() and all(u in keys for u in stage.upstream):
                keys[stage.name] = stage_key(stage, case, [keys[u] for u in stage.upstream], [])
                runs.append(_kept_run(stage, build_dir, keys[stage.name], results))
        manifest = build_manifest(
            case, build_dir, [*stages, *options.later], runs, results, inputs, input_hashes, staging
        )
        staging.write_json(MANIFEST, manifest)
        staging.commit()
    return results, runs


def _counted(progress: Callable[[str], None], index: int, total: int) -> Callable[[str], None]:
    """Prefix progress lines with ``[done/total]`` (a terminal renders them as a bar)."""

    def report(line: str) -> None:
        done = index + (0 if line.endswith("running") else 1)
        progress(f"[{done}/{total}] {line}")

    return report


def _run_one(
    stage: Stage, case: Case, build_dir: Path, key: str, results: Results, staging: Staging, options: RunOptions
) -> StageRun:
    start = time.perf_counter()
    if not options.force and _up_to_date(build_dir, stage, key):
        results[stage.name] = stage.load(build_dir, results)
        options.progress(f"{stage.name}: unchanged, skipped")
        return StageRun(stage.name, key, "skipped", time.perf_counter() - start, stage.describe(results[stage.name]))
    options.progress(f"{stage.name}: running")
    results[stage.name] = stage.compute(case, results)
    before = set(staging.written)
    stage.write(results[stage.name], staging)
    outputs = {rel: staging.written[rel] for rel in sorted(set(staging.written) - before)}
    staging.write_json(f"{stage.name}/stage.json", {"stage": stage.name, "version": stage.version, "key": key, "outputs": outputs})
    seconds = time.perf_counter() - start
    options.progress(f"{stage.name}: done in {seconds:.2f} s")
    return StageRun(stage.name, key, "ran", seconds, stage.describe(results[stage.name]))


def _kept_run(stage: Stage, build_dir: Path, key: str, results: Results) -> StageRun:
    """A later stage's outputs from an earlier run: ``kept`` (loaded) if made from what is there now, else ``stale``."""
    start = time.perf_counter()
    if _up_to_date(build_dir, stage, key):
        results[stage.name] = stage.load(build_dir, results)
        return StageRun(stage.name, key, KEPT, time.perf_counter() - start, stage.describe(results[stage.name]))
    line = (f"{stage.name}/ and its outputs were built from other inputs or settings than this run's; "
            "they are out of date: run `softdesign build` to redo them")
    return StageRun(stage.name, key, STALE, time.perf_counter() - start, [line])


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
    stale = {r.name for r in runs if r.status == STALE}
    outputs = [
        {**entry, **figures.get(entry["path"], {}), **({"stale": True} if entry["stage"] in stale else {})}
        for entry in _all_outputs(build_dir, stages, staging)
    ]
    for entry in outputs:
        del entry["stage"]
    return {
        "software": {"softdesign": __version__},
        "case": case.resolved(),
        "inputs": [
            {"path": case.resolved_path(p), "sha256": h, "bytes": p.stat().st_size} for p, h in zip(inputs, input_hashes)
        ],
        "stages": [{"name": r.name, "status": r.status, "key": r.key} for r in runs]
        + [
            {"name": name, "status": "kept from an earlier run", "key": _read_record(build_dir / name / "stage.json").get("key")}
            for name in sorted(_kept_stage_names(build_dir) - {r.name for r in runs})
        ],
        "timing_s": {r.name: round(r.seconds, 3) for r in runs if r.status not in (KEPT, STALE)},
        "metrics": {s.name: s.metrics(results[s.name]) for s in stages if s.name in results},
        "outputs": outputs,
    }


def _all_outputs(build_dir: Path, stages: list[Stage], staging: Staging) -> list[dict[str, Any]]:
    """Outputs recorded by this run's stages, and by earlier runs' stages still in the folder, with their stage."""
    found: dict[str, tuple[str, str]] = {}
    for name in sorted(_kept_stage_names(build_dir) - {s.name for s in stages}):
        recorded = _read_record(build_dir / name / "stage.json").get("outputs", {})
        found.update((rel, (name, sha)) for rel, sha in recorded.items())
    for stage in stages:
        record = staging.written.get(f"{stage.name}/stage.json")
        source = _read_record(staging.staged_path(f"{stage.name}/stage.json")) if record else _recorded(build_dir, stage)
        if source:
            found.update((rel, (stage.name, sha)) for rel, sha in source.get("outputs", {}).items())
    return [{"path": rel, "sha256": sha, "stage": name} for rel, (name, sha) in sorted(found.items())]


def _kept_stage_names(build_dir: Path) -> set[str]:
    return {p.parent.name for p in build_dir.glob("*/stage.json")} if build_dir.is_dir() else set()


def _read_record(file: Path) -> dict[str, Any]:
    try:
        return json.loads(file.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError):
        return {}
