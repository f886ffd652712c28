"""One call for commands: load a case and run its stages through a target, cached."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from softdesign.config import Case, load_case
from softdesign.errors import errors_named_for
from softdesign.io.input_checks import input_os_errors
from softdesign.pipeline.runner import RunOptions, run_stages
from softdesign.pipeline.stage import StageRun
from softdesign.pipeline.stage_order import STAGES, input_files, stages_through


@dataclass(frozen=True)
class BuildOutcome:
    """What a run produced: the case, where, each stage's result and what ran."""

    case: Case
    build_dir: Path
    results: dict[str, Any]
    runs: list[StageRun]


def default_build_dir(case: Case, out: Path | None) -> Path:
    """``out``, else ``build/<name>`` under the current directory (DESIGN.md)."""
    return out if out is not None else Path("build") / case.name


def build_through(
    case_file: Path,
    out: Path | None = None,
    target: str | None = None,
    force: bool = False,
    progress: Callable[[str], None] = lambda line: None,
    jobs: int = 1,
    case: Case | None = None,
) -> BuildOutcome:
    """Run the stages up to ``target`` (every stage when None), per-q work on ``jobs`` processes.

    ``case``: the case file's case as loaded and then changed by the caller (``softdesign design``'s options);
    default: loaded from ``case_file``.  Errors name the case file.
    """
    case = load_case(case_file) if case is None else case
    build_dir = default_build_dir(case, out)
    stages = STAGES if target is None else stages_through(target)
    later = tuple(s for s in STAGES if s not in stages)
    options = RunOptions(force=force, progress=progress, later=later, jobs=jobs)
    with errors_named_for(case_file):
        inputs = input_files(case)
        with input_os_errors(inputs):
            results, runs = run_stages(case, build_dir, stages, inputs, options)
    return BuildOutcome(case, build_dir, results, runs)
