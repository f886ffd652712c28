"""What softdesign wrote inside a build folder, file by file: everything else there is the user's.

A rebuild replaces the whole build folder, so a file softdesign did not write
(a note under ``meshes/``, a folder the user made under a stage folder, a
file beside the report's) would go with the old folder.  Such a folder is
refused before any work, naming the file (:func:`foreign_files`), rather than
its files carried over: a carried file would make the new folder hold what
its manifest does not list, and could collide with an output of a later
configuration; refusing leaves the user in charge of their file.

Ours are: ``manifest.json``; every path the manifest lists (outputs and stage
records) and every output a stage record lists; the report's files, listed by
its marker ``report/.softdesign-report.json``; and the report's temporary
folders ``.report-<pid>-<hex>`` (and ``-old``) that hold that marker.
"""

from __future__ import annotations

import json
import os
import re
from pathlib import Path, PurePosixPath
from typing import Any

from softdesign.pipeline.layout import MANIFEST, REPORT_DIR, RUN_LOG, STAGE_RECORD

#: The report's list of the files it wrote, inside ``report/`` and inside each of its temporary folders.
REPORT_MARKER = ".softdesign-report.json"
#: A report's temporary folder inside the build folder: ``.report-<pid>-<12 hex>``, or that name and ``-old``.
REPORT_TEMP = re.compile(r"\.report-(\d+)-([0-9a-f]{12})(-old)?")


def safe_relative(path: object, under: str | None = None) -> bool:
    """Whether ``path`` is a relative POSIX path that stays inside its folder (and inside ``under``/ if given)."""
    if not isinstance(path, str) or not path or "\\" in path or "\0" in path:
        return False
    parts = PurePosixPath(path).parts
    if path.startswith("/") or any(p in ("..", ".", "") for p in parts):
        return False
    return under is None or (len(parts) > 1 and parts[0] == under)


def _json(file: Path) -> dict[str, Any]:
    try:
        if file.is_symlink() or not file.is_file() or file.stat().st_size > 64 << 20:
            return {}
        payload = json.loads(file.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return {}
    return payload if isinstance(payload, dict) else {}


def report_marker_files(folder: Path) -> list[str] | None:
    """The files a report marker in ``folder`` lists (the marker included), or None when it has no valid marker."""
    files = _json(folder / REPORT_MARKER).get("files")
    if not isinstance(files, dict) or not all(safe_relative(name) and "/" not in name for name in files):
        return None
    return [REPORT_MARKER, *files]


#: What a report of a version before the marker wrote into report/: its page, images, animation and scripts.
LEGACY_REPORT_SUFFIXES = (".html", ".png", ".gif", ".js", ".log")


def legacy_report_files(folder: Path) -> list[str]:
    """The files of a report without a marker (an older version's), when report/ holds nothing else; else none."""
    report = folder / REPORT_DIR
    if report.is_symlink() or not report.is_dir():
        return []
    entries = list(report.iterdir())
    if any(e.is_symlink() or not e.is_file() or not e.name.endswith(LEGACY_REPORT_SUFFIXES) for e in entries):
        return []
    return [e.name for e in entries] if any(e.name == "index.html" for e in entries) else []


def owned_files(folder: Path) -> set[str]:
    """The paths (POSIX, relative to ``folder``) of the files softdesign wrote in build folder ``folder``."""
    manifest = _json(folder / MANIFEST)
    own = {MANIFEST, RUN_LOG}
    for key in ("outputs", "records"):
        entries = manifest.get(key)
        for entry in entries if isinstance(entries, list) else []:
            path = entry.get("path") if isinstance(entry, dict) else None
            if safe_relative(path):
                own.add(str(path))
    for record in folder.glob(f"*/{STAGE_RECORD}"):
        stage = record.parent.name
        own.add(f"{stage}/{STAGE_RECORD}")
        outputs = _json(record).get("outputs")
        own |= {str(p) for p in (outputs if isinstance(outputs, dict) else {}) if safe_relative(p)}
    own |= {f"{REPORT_DIR}/{name}" for name in report_marker_files(folder / REPORT_DIR) or legacy_report_files(folder)}
    for temp in folder.iterdir():
        if REPORT_TEMP.fullmatch(temp.name) and not temp.is_symlink() and temp.is_dir():
            own |= {f"{temp.name}/{name}" for name in report_marker_files(temp) or []}
    return own


def foreign_files(folder: Path) -> list[str]:
    """Every file, link or folder inside ``folder`` that softdesign did not write, sorted (a folder: ``name/``).

    A folder counts as the user's when it holds none of softdesign's files; its contents are then not listed.
    """
    own = owned_files(folder)
    own_dirs = {str(parent) for path in own for parent in PurePosixPath(path).parents} - {"."}
    found: list[str] = []
    for root, dirs, files in os.walk(folder):
        here = Path(root).relative_to(folder).as_posix()
        prefix = "" if here == "." else f"{here}/"
        for name in list(dirs):
            path = prefix + name
            if os.path.islink(os.path.join(root, name)):
                dirs.remove(name)
                files.append(name)
            elif path not in own_dirs:
                dirs.remove(name)
                found.append(path + "/")
        found += [prefix + name for name in files if prefix + name not in own]
    return sorted(found)
