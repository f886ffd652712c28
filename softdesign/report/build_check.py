"""What the report checks of a build folder before it reads it: the manifest's shape, and files as built.

A manifest lacking a key, or holding a value of another type, and a stage file
changed after the build (by hand, by a script, by another version) made the
report end in a Python traceback deep in a figure.  The report reads only
files the manifest lists, with their sha256: one that differs is refused
before any figure, naming it (exit 2), and the manifest's top-level keys are
checked to be what a build writes.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from softdesign.errors import InputDataError
from softdesign.pipeline.layout import MANIFEST
from softdesign.pipeline.owned import safe_relative
from softdesign.pipeline.store import sha256_file

#: The manifest's top-level keys the report reads, with the JSON type a build writes for each.
MANIFEST_KEYS: dict[str, type] = {
    "software": dict, "case": dict, "inputs": list, "stages": list, "timing_s": dict, "metrics": dict,
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
    if not all(isinstance(s.get("name"), str) and isinstance(s.get("status"), str) for s in manifest["stages"]):
        raise InputDataError(f"{root / MANIFEST}: a stage entry lacks its name or status; {fix}")


def check_files_as_built(root: Path, manifest: dict[str, Any], fix: str) -> None:
    """InputDataError when a stage's data file the report loads (.json, .npz) differs from the manifest's sha256.

    Meshes are left to the report's own output checks (they may be hundreds of MB).
    """
    for entry in manifest["outputs"]:
        rel, sha = entry.get("path"), entry.get("sha256")
        if not (safe_relative(rel) and str(rel).endswith(READ_SUFFIXES)) or not (root / str(rel)).is_file():
            continue
        path = root / str(rel)
        if sha256_file(path) != sha:
            raise InputDataError(f"{path}: changed since the build (its sha256 differs from the one {MANIFEST} lists); "
                                 f"the report draws only what a build wrote: {fix} --force")
