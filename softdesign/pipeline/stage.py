"""What a stage is, what can happen to it in a run, and the cache key that decides.

A stage's cache key is the sha256 of its name and version, the canonical
JSON of the case keys it reads (``reads``: dotted keys of the resolved case,
so ``export.q`` and not all of ``export``), and the keys of the stages it
depends on (ingest: the sha256 of its input files).  Nothing is reused
merely because a file exists: the runner also checks every recorded output's
hash.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softdesign.pipeline.notices import Judgement, Notice
from softdesign.pipeline.store import Staging, canonical_json, sha256_bytes

if TYPE_CHECKING:  # only annotations: the report loads stage results without the case file's models
    from softdesign.config import Case

Results = dict[str, Any]


class Status:
    """What happened to a stage in a run (the words the CLI prints and the manifest records)."""

    #: computed in this run
    RAN = "ran"
    #: its key and outputs matched: loaded from the build folder
    SKIPPED = "skipped"
    #: a stage after the target, not run; its outputs from an earlier run match what it would be built from now
    KEPT = "kept"
    #: a stage after the target, not run; its outputs were built from other inputs or settings
    STALE = "stale"


@dataclass(frozen=True)
class Stage:
    """One pipeline stage.

    Attributes
    ----------
    name, version : identify the code; bump ``version`` when outputs change
    reads : dotted keys of the resolved case whose values change the outputs
    upstream : stages whose results ``compute`` reads
    compute : (case, results of upstream stages) -> result; no file writes
    write : (result, staging) -> None; stages the outputs
    load : (build_dir, results of upstream stages) -> result, for a skipped stage
    describe : result -> short human summary lines
    metrics : result -> JSON-ready figures for the manifest
    figures : result -> {output path: figures} merged into the manifest's outputs
    log : result -> lines for the run log (``run.log.json``): how the computation went, e.g. each part's time
    warnings : result -> the stage's warnings and notes (:mod:`softdesign.pipeline.notices`); ``describe``
        leaves them out: the command line prints the manifest's list once
    judge : result -> what the stage says of the design (reasons it cannot be made, margins), or None
    """

    name: str
    version: int
    reads: tuple[str, ...]
    upstream: tuple[str, ...]
    compute: Callable[[Case, Results], Any]
    write: Callable[[Any, Staging], None]
    load: Callable[[Path, Results], Any]
    describe: Callable[[Any], list[str]]
    metrics: Callable[[Any], dict[str, Any]]
    figures: Callable[[Any], dict[str, dict[str, Any]]] = lambda result: {}
    #: result -> lines of how its computation went (each part's time) for the run log, never an output
    log: Callable[[Any], list[str]] = lambda result: []
    warnings: Callable[[Any], list[Notice]] = lambda result: []
    judge: Callable[[Any], Judgement | None] = lambda result: None


@dataclass
class StageRun:
    """What happened to one stage in a run."""

    name: str
    key: str
    status: str  # one of Status
    seconds: float
    lines: list[str] = field(default_factory=list)
    #: the stage's own log of this run (:attr:`Stage.log`), for the run log
    log: list[str] = field(default_factory=list)


def read_keys(resolved: dict[str, Any], keys: tuple[str, ...]) -> dict[str, Any]:
    """``{dotted key: value}`` of the resolved case (None for a key that is absent)."""
    found: dict[str, Any] = {}
    for key in keys:
        value: Any = resolved
        for part in key.split("."):
            value = value.get(part) if isinstance(value, dict) else None
        found[key] = value
    return found


def stage_key(stage: Stage, case: Case, upstream_keys: list[str], input_hashes: list[str]) -> str:
    """The content hash that decides whether ``stage`` must run again."""
    payload = {
        "stage": stage.name,
        "version": stage.version,
        "config": read_keys(case.resolved(), stage.reads),
        "upstream": upstream_keys,
        "inputs": input_hashes,
    }
    return sha256_bytes(canonical_json(payload).encode("utf-8"))
