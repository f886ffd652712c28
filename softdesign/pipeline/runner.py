"""Run stages in order with a content-hash cache, then write the manifest, all in one commit.

A stage whose key (:func:`~softdesign.pipeline.stage.stage_key`) matches the
one recorded in ``DIR/<stage>/stage.json`` *and* whose recorded outputs are
all present with their recorded hashes is skipped; nothing is reused merely
because a file exists.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from softdesign.config import Case
from softdesign.pipeline import layout
from softdesign.pipeline.manifest import build_manifest
from softdesign.pipeline.stage import Results, Stage, StageRun, Status, stage_key
from softdesign.pipeline.store import Staging, read_record, sha256_file


def _up_to_date(build_dir: Path, stage: Stage, key: str) -> bool:
    record = read_record(build_dir / layout.stage_record(stage.name))
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
            if (build_dir / layout.stage_record(stage.name)).is_file() and all(u in keys for u in stage.upstream):
                keys[stage.name] = stage_key(stage, case, [keys[u] for u in stage.upstream], [])
                runs.append(_kept_run(stage, build_dir, keys[stage.name], results))
        manifest = build_manifest(
            case, build_dir, [*stages, *options.later], runs, results, inputs, input_hashes, staging
        )
        staging.write_json(layout.MANIFEST, manifest)
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
        return StageRun(stage.name, key, Status.SKIPPED, time.perf_counter() - start, stage.describe(results[stage.name]))
    options.progress(f"{stage.name}: running")
    results[stage.name] = stage.compute(case, results)
    before = set(staging.written)
    stage.write(results[stage.name], staging)
    outputs = {rel: staging.written[rel] for rel in sorted(set(staging.written) - before)}
    staging.write_json(layout.stage_record(stage.name), {"stage": stage.name, "version": stage.version, "key": key, "outputs": outputs})
    seconds = time.perf_counter() - start
    options.progress(f"{stage.name}: done in {seconds:.2f} s")
    return StageRun(stage.name, key, Status.RAN, seconds, stage.describe(results[stage.name]))


def _kept_run(stage: Stage, build_dir: Path, key: str, results: Results) -> StageRun:
    """A later stage's outputs from an earlier run: ``kept`` (loaded) if made from what is there now, else ``stale``."""
    start = time.perf_counter()
    if _up_to_date(build_dir, stage, key):
        results[stage.name] = stage.load(build_dir, results)
        return StageRun(stage.name, key, Status.KEPT, time.perf_counter() - start, stage.describe(results[stage.name]))
    line = (f"{stage.name}/ and its outputs were built from other inputs or settings than this run's; "
            "they are out of date: run `softdesign build` to redo them")
    return StageRun(stage.name, key, Status.STALE, time.perf_counter() - start, [line])


