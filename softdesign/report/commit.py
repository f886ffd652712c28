"""Put the report's files in place of ``BUILD_DIR/report/`` in one step; own only what the report wrote.

The files are written into a hidden temporary folder ``.report-<pid>-<hex>``
beside ``report/`` and moved into place only when all of them exist: a failed
or killed run leaves the previous report as it was.  Every such folder, and
``report/`` itself, holds the marker :data:`~softdesign.pipeline.owned.REPORT_MARKER`
listing the report's files, written first: a later run removes only a
temporary folder with that marker (a killed run's), never a ``.report-*``
folder the user made, and refuses a ``report/`` that is a symbolic link or
holds a file the report did not write.  Call it holding the build folder's lock.
"""

from __future__ import annotations

import os
import shutil
import uuid
from pathlib import Path

from softdesign.errors import ConfigError
from softdesign.pipeline.layout import REPORT_DIR
from softdesign.pipeline.owned import REPORT_MARKER, REPORT_TEMP, legacy_report_files, report_marker_files
from softdesign.pipeline.store import canonical_json, process_alive, sha256_bytes

TEMP_PREFIX = ".report-"


def commit_folder(target: Path, files: dict[str, bytes]) -> None:
    """Write ``files`` into a temporary folder beside ``target``, then swap it in for ``target``; hold the lock.

    Temporary folders are named ``.report-<pid>-<hex>`` and hold the marker
    :data:`~softdesign.pipeline.owned.REPORT_MARKER` listing the files, written
    first; only such a folder (ours, and under the lock a killed run's) is
    removed as a leftover.  ``target`` must be a folder of the report's own
    files (its marker lists them) or nothing: a symbolic link there, or a file
    the report did not write, is refused before anything changes.
    """
    parent = target.parent
    _check_report_folder(target)
    for stale in sorted(parent.iterdir()):
        match = REPORT_TEMP.fullmatch(stale.name)
        if match and not stale.is_symlink() and report_marker_files(stale) is not None \
                and not process_alive(match.group(1)):
            shutil.rmtree(stale, ignore_errors=True)
    temp = parent / f"{TEMP_PREFIX}{os.getpid()}-{uuid.uuid4().hex[:12]}"
    temp.mkdir()  # unlike mkdtemp, honours the umask: the report is as readable as the rest of the build
    old = temp.with_name(temp.name + "-old")
    # a log (report.log: the folder's path and the times) is listed without its hash, so the marker is the same
    # bytes for the same build wherever and whenever it is drawn, as the page is
    marker = {"softdesign": "report", "files": {name: None if name.endswith(".log") else sha256_bytes(data)
                                                for name, data in sorted(files.items())}}
    try:
        (temp / REPORT_MARKER).write_text(canonical_json(marker), encoding="utf-8")
        for name, data in sorted(files.items()):
            (temp / name).write_bytes(data)
        if target.exists():
            os.rename(target, old)
        os.rename(temp, target)
    except BaseException:
        if old.exists() and not target.exists():
            os.rename(old, target)
        shutil.rmtree(temp, ignore_errors=True)
        raise
    shutil.rmtree(old, ignore_errors=True)


def _check_report_folder(target: Path) -> None:
    """ConfigError when ``target`` (``report/``) is a link, a file, or holds files the report did not write."""
    fix = "move it out of the build folder, then run softdesign report again"
    if target.is_symlink():
        raise ConfigError(f"{target}: is a symbolic link (to {os.readlink(target)}); the report writes {REPORT_DIR}/ "
                          f"as a folder of its own and does not follow links; {fix}")
    if not target.exists():
        return
    if not target.is_dir():
        raise ConfigError(f"{target}: is a file, expected the report's folder; {fix}")
    own = set(report_marker_files(target) or legacy_report_files(target.parent))
    foreign = sorted(p.name + ("/" if p.is_dir() and not p.is_symlink() else "") for p in target.iterdir()
                     if p.name not in own or p.is_symlink() or not p.is_file())
    if foreign:
        shown = ", ".join(foreign[:3]) + (f" and {len(foreign) - 3} more" if len(foreign) > 3 else "")
        raise ConfigError(f"{target}: holds files the report did not write ({shown}), which a new report would drop; "
                          f"expected only the report's own files; {fix}")
