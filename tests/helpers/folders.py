"""Build folders as the tests see them: every file with its hash, and what the manifest says is there."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path


def snapshot(folder: Path) -> dict[str, str]:
    """Every file under ``folder`` (POSIX path relative to it) with its sha256."""
    return {
        p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def listed_files(folder: Path) -> dict[str, str]:
    """The files the manifest of ``folder`` lists (outputs and stage records) with their sha256."""
    manifest = json.loads((folder / "manifest.json").read_text(encoding="utf-8"))
    return {entry["path"]: entry["sha256"] for entry in manifest["outputs"] + manifest.get("records", [])}


def assert_exactly_as_listed(folder: Path) -> None:
    """Every file of ``folder`` but the manifest and the run log is listed in it with its hash, and nothing listed is
    missing."""
    files = snapshot(folder)
    files.pop("manifest.json")
    files.pop("run.log.json")
    assert files == listed_files(folder)


def leftovers(parent: Path, name: str) -> list[str]:
    """Names of staging and trash folders of build folder ``name`` left in ``parent``."""
    return sorted(p.name for p in parent.iterdir() if p.name.startswith((f".{name}.staging-", f".{name}.trash-")))
