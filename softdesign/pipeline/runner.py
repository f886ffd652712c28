"""Run stages in order with a content-hash cache, then write the manifest, all in one commit.

A stage whose key (:func:`~softdesign.pipeline.stage.stage_key`) matches the
one recorded in ``DIR/<stage>/stage.json`` *and* whose recorded outputs are
all present with their recorded hashes is skipped (its files are carried
into the new folder); nothing is reused merely because a file exists.  The
new folder holds exactly what its manifest lists: outputs of an earlier
configuration (a mesh for a q no longer asked for) go with the old folder.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from softdesign.config import Case
from softdesign.pipeline import layout
from softdesign.pipeline.bounds import check_sizes
from softdesign.pipeline.lock import BuildLock
from softdesign.pipeline.manifest import build_manifest, run_log
from softdesign.pipeline.out_folder import check_out_folder, folder_errors
from softdesign.pipeline.owned import safe_relative
from softdesign.pipeline.parallel import jobs_for_build, working_on
from softdesign.pipeline.report_keep import carry_report
from softdesign.pipeline.stage import Results, Stage, StageRun, Status, stage_key
from softdesign.pipeline.store import Staging, read_record, sha256_file
from softdesign.pipeline.swap import repair


def _intact(build_dir: Path, record: dict[str, Any]) -> bool:
    """Whether every output ``record`` lists is in ``build_dir`` with its recorded hash."""
    outputs = record.get("outputs", {})
    return all((build_dir / rel).is_file() and sha256_file(build_dir / rel) == sha for rel, sha in outputs.items())


def _record(build_dir: Path, stage: Stage) -> dict[str, Any] | None:
    """The stage's record in ``build_dir``, or None when missing, unreadable, or naming an output outside its folder.

    A record is only trusted to name files inside the stage's own folder (or, for export, the meshes and series it
    writes beside them): one naming ``../x`` or an absolute path is not ours, and its stage runs again.
    """
    record = read_record(build_dir / layout.stage_record(stage.name))
    outputs = record.get("outputs") if isinstance(record, dict) else None
    if not isinstance(outputs, dict) or not all(safe_relative(r) and isinstance(h, str) for r, h in outputs.items()):
        return None
    return record


def _up_to_date(build_dir: Path, stage: Stage, key: str) -> dict[str, Any] | None:
    """The stage's record in ``build_dir`` when its key is ``key`` and its outputs are intact, else None."""
    record = _record(build_dir, stage)
    if record is None or record.get("key") != key or not _intact(build_dir, record):
        return None
    return record


def _keep(staging: Staging, stage: Stage, record: dict[str, Any]) -> None:
    """Carry a stage's record and outputs, checked intact, from the current folder into the new one."""
    staging.keep(layout.stage_record(stage.name), sha256_file(staging.target / layout.stage_record(stage.name)))
    for rel, sha in record.get("outputs", {}).items():
        staging.keep(rel, sha)


@dataclass(frozen=True)
class RunOptions:
    """How to run: which stages, forced or cached, where to report progress."""

    force: bool = False
    progress: Callable[[str], None] = lambda line: None
    #: stages after the target: not run, but their outputs kept from an earlier run are checked
    #: against what they would be built from now (``kept`` and loaded, or ``stale``)
    later: tuple[Stage, ...] = ()
    #: worker processes for the per-q work of a stage (:mod:`softdesign.pipeline.parallel`); outputs do not depend on it
    jobs: int = 1


def run_stages(
    case: Case, build_dir: Path, stages: list[Stage], inputs: list[Path], options: RunOptions = RunOptions()
) -> tuple[Results, list[StageRun]]:
    """Run ``stages`` (in order, upstream first) into ``build_dir``.

    Holding the folder's lock, the whole next folder is staged beside it
    (new files written, kept stages' files linked) and swapped in only when
    every stage succeeded; a failure leaves the previous build folder as it
    was.  ConfigError when ``build_dir`` may not be replaced
    (:func:`~softdesign.pipeline.out_folder.check_out_folder`), is locked by
    another run, or cannot be written.
    """
    build_dir = Path(build_dir)
    input_hashes = [sha256_file(p) for p in inputs]
    target = Path(os.path.realpath(build_dir))
    with folder_errors(build_dir):
        check_out_folder(build_dir, inputs)  # before the lock: a refused --out gets no lock file beside it
    with folder_errors(build_dir), BuildLock(target) as lock:
        for line in lock.notes + repair(target):
            options.progress(line)
        with Staging(build_dir) as staging, jobs_for_build(options.jobs):
            results, runs = _run_all(case, staging, stages, input_hashes, options)
            stages_run = [*stages, *options.later]
            manifest = build_manifest(case, staging.folder, stages_run, runs, results, inputs, input_hashes)
            staging.write_json(layout.MANIFEST, manifest)
            staging.write_json(layout.RUN_LOG, run_log(runs))
            _check_listed(manifest, staging.written)
            dropped = carry_report(staging, manifest)
            staging.commit()
        if dropped is not None:
            options.progress(dropped)
    return results, runs


def _run_all(
    case: Case, staging: Staging, stages: list[Stage], input_hashes: list[str], options: RunOptions
) -> tuple[Results, list[StageRun]]:
    """Run or keep ``stages``, then keep what ``options.later`` has in the current folder; fills ``staging``."""
    results: Results = {}
    keys: dict[str, str] = {}
    runs: list[StageRun] = []
    for index, stage in enumerate(stages):
        upstream = [keys[u] for u in stage.upstream]
        keys[stage.name] = stage_key(stage, case, upstream, input_hashes if not stage.upstream else [])
        step = RunOptions(options.force, _counted(options.progress, index, len(stages)))
        with working_on(stage.name):  # a dead worker's message names the stage
            runs.append(_run_one(stage, case, keys[stage.name], results, staging, step))
        if stage.name == "ingest":  # the vessel is measured: refuse spacings it cannot afford before they run
            check_sizes(case, results["ingest"])
    for stage in options.later:
        record = _record(staging.target, stage)
        if record is not None and all(u in keys for u in stage.upstream):
            keys[stage.name] = stage_key(stage, case, [keys[u] for u in stage.upstream], [])
            runs.append(_kept_run(stage, record, keys[stage.name], results, staging))
    return results, runs


def _check_listed(manifest: dict[str, Any], files: dict[str, str]) -> None:
    """The manifest lists every file of the new folder but itself and the run log, with its hash, and nothing else
    (else a bug)."""
    listed = {entry["path"]: entry["sha256"] for entry in manifest["outputs"] + manifest["records"]}
    if listed != {rel: sha for rel, sha in files.items() if rel not in (layout.MANIFEST, layout.RUN_LOG)}:
        raise RuntimeError("the manifest does not list exactly the files of the new build folder")


def _counted(progress: Callable[[str], None], index: int, total: int) -> Callable[[str], None]:
    """Prefix progress lines with ``[done/total]`` (a terminal renders them as a bar)."""

    def report(line: str) -> None:
        done = index + (0 if line.endswith("running") else 1)
        progress(f"[{done}/{total}] {line}")

    return report


def _run_one(
    stage: Stage, case: Case, key: str, results: Results, staging: Staging, options: RunOptions
) -> StageRun:
    start = time.perf_counter()
    record = None if options.force else _up_to_date(staging.target, stage, key)
    if record is not None:
        results[stage.name] = stage.load(staging.target, results)
        _keep(staging, stage, record)
        options.progress(f"{stage.name}: unchanged, skipped")
        seconds = time.perf_counter() - start
        return StageRun(stage.name, key, Status.SKIPPED, seconds, stage.describe(results[stage.name]))
    options.progress(f"{stage.name}: running")
    results[stage.name] = stage.compute(case, results)
    before = set(staging.written)
    stage.write(results[stage.name], staging)
    outputs = {rel: staging.written[rel] for rel in sorted(set(staging.written) - before)}
    done = {"stage": stage.name, "version": stage.version, "key": key, "outputs": outputs}
    staging.write_json(layout.stage_record(stage.name), done)
    seconds = time.perf_counter() - start
    options.progress(f"{stage.name}: done in {seconds:.2f} s")
    result = results[stage.name]
    return StageRun(stage.name, key, Status.RAN, seconds, stage.describe(result), stage.log(result))


def _kept_run(stage: Stage, record: dict[str, Any], key: str, results: Results, staging: Staging) -> StageRun:
    """A later stage's outputs from an earlier run: ``kept`` (loaded) if made from what is there now, else ``stale``.

    Either way they go into the new folder, unless some are missing or changed on disk: then none do.
    """
    start = time.perf_counter()
    if not _intact(staging.target, record):
        line = (f"{stage.name}/: outputs of an earlier run are missing or changed on disk, so none are kept; "
                "run `softdesign build` to redo them")
        return StageRun(stage.name, key, Status.STALE, time.perf_counter() - start, [line])
    _keep(staging, stage, record)
    if record.get("key") == key:
        results[stage.name] = stage.load(staging.target, results)
        return StageRun(stage.name, key, Status.KEPT, time.perf_counter() - start, stage.describe(results[stage.name]))
    line = (f"{stage.name}/ and its outputs were built from other inputs or settings than this run's; "
            "they are out of date: run `softdesign build` to redo them")
    return StageRun(stage.name, key, Status.STALE, time.perf_counter() - start, [line])
