"""The files a build reads, with the case field that names each (no numerical library: validate uses it).

Ingest (:mod:`softdesign.pipeline.stages.ingest`) reads these files; the
cache keys, the manifest, ``softdesign validate`` and the cohort's make rules
list them from here.
"""

from __future__ import annotations

from pathlib import Path

from softdesign.config import Case
from softdesign.io.input_checks import check_input_file


def input_fields(case: Case) -> list[tuple[str, Path]]:
    """Every file ingest reads, with the case field that names it."""
    named = [
        ("final.centerline", case.final.centerline),
        ("final.surface", case.final.surface),
        ("initial.centerline", case.initial.centerline),
        ("initial.surface", case.initial.surface),
    ]
    named += [(f"intermediate[{i}].centerline", k.centerline) for i, k in enumerate(case.intermediate)]
    return [(name, path) for name, path in named if isinstance(path, Path)]  # not None, not "auto"


def input_files(case: Case) -> list[Path]:
    """Every file ingest reads (for the cache key and the manifest).

    Raises
    ------
    InputDataError
        A named file does not exist.
    """
    for name, path in input_fields(case):
        check_input_file(path, name)
    return [path for _, path in input_fields(case)]
