"""What the report checks of a build folder before it reads it: the manifest's shape, and files as built.

A manifest lacking a key, or holding a value of another type, and a stage file
changed after the build (by hand, by a script, by another version) made the
report end in a Python traceback deep in a figure.  The report reads only
files the manifest lists, with their sha256: one that differs is named
when it lacks what the report reads, naming it (exit 2; a build of another
version: exit 1), and the manifest's top-level keys are checked to be what a
build writes (exit 2).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from softdesign.errors import InputDataError, SoftdesignError
from softdesign.pipeline.layout import MANIFEST
from softdesign.pipeline.owned import safe_relative
from softdesign.pipeline.store import sha256_file

#: The manifest's top-level keys the report reads, with the JSON type a build writes for each.
MANIFEST_KEYS: dict[str, type] = {
    "software": dict, "case": dict, "inputs": list, "stages": list, "metrics": dict,
    "outputs": list,
}

#: The files of a stage the report loads (summaries, arrays), checked against their hashes.
READ_SUFFIXES = (".json", ".npz")


def check_manifest(root: Path, manifest: Any, fix: str) -> None:
    """InputDataError unless ``manifest`` has every key of MANIFEST_KEYS with its type, and well-formed entries."""
    if not isinstance(manifest, dict):
        raise InputDataError(f"{root / MANIFEST}: is not a JSON object; {fix}")
    wrong = [f"{key} ({kind.__name__})" for key, kind in MANIFEST_KEYS.items()
             if not isinstance(manifest.get(key), kind)]
    if wrong:
        raise InputDataError(f"{root / MANIFEST}: lacks what a build writes: {', '.join(wrong)} missing or of "
                             f"another type; {fix}")
    for key in ("outputs", "stages", "inputs"):
        if not all(isinstance(entry, dict) for entry in manifest[key]):
            raise InputDataError(f"{root / MANIFEST}: {key} holds an entry that is not an object; {fix}")
    if not all(isinstance(s.get("name"), str) for s in manifest["stages"]):
        raise InputDataError(f"{root / MANIFEST}: a stage entry lacks its name; {fix}")


def changed_since_build(root: Path, manifest: dict[str, Any]) -> list[str]:
    """The stage data files the report loads (.json, .npz) whose sha256 differs from the manifest's, relative.

    Not refused here: the report draws a tampered build and fails its "file as recorded" check; this list is the
    evidence when such a file then lacks what the report reads (:func:`unreadable_build`).  Meshes are left to the
    report's own output checks (they may be hundreds of MB).
    """
    changed = []
    for entry in manifest["outputs"]:
        rel, sha = entry.get("path"), entry.get("sha256")
        if safe_relative(rel) and str(rel).endswith(READ_SUFFIXES) and (root / str(rel)).is_file():
            if sha256_file(root / str(rel)) != sha:
                changed.append(str(rel))
    return changed


def unreadable_build(root: Path, changed: list[str], err: Exception) -> SoftdesignError:
    """The error for a report that found the build's files lacking what it reads (``err``: KeyError, TypeError...).

    With files changed since the build, they are named (bad input, exit 2); else the build is of another version
    or damaged in a way its hashes do not show, and the report failed (exit 1); both say to rebuild.
    """
    what = f"{type(err).__name__}: {err}"
    if changed:
        return InputDataError(f"{root}: {', '.join(changed)} changed since the build (sha256 differs from the "
                              f"manifest's) and lack(s) what the report reads ({what}); rebuild: softdesign build "
                              f"CASE.yaml --out {root} --force")
    return ReportFailed(f"{root}: the report could not read what it expects from the build's files ({what}); "
                        f"rebuild with this version: softdesign build CASE.yaml --out {root} --force")


class ReportFailed(SoftdesignError):
    """The report could not be drawn from a build folder whose files all match its manifest (exit 1)."""
