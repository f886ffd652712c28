"""Which folder a build may replace, and the build folder's OS errors as user errors.

A build replaces its whole folder, so ``--out`` must be a softdesign build
folder (``manifest.json`` of ours), an empty folder, or nothing yet; never a
file, a folder of other files, or a folder holding the case's input files.
A folder the file system refuses (no permission, full disk, a file in the
way) is a user error too: exit 2 with the path, no traceback.
"""

from __future__ import annotations

import errno
import json
import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from softdesign.errors import ConfigError
from softdesign.pipeline.layout import MANIFEST, lock_name, sibling_role
from softdesign.pipeline.owned import foreign_files

_OTHER_OUT = "give --out another folder"
_FIXES = {
    errno.EACCES: f"make it writable for this user, or {_OTHER_OUT}",
    errno.EPERM: f"make it writable for this user, or {_OTHER_OUT}",
    errno.EROFS: f"that file system is read-only: {_OTHER_OUT} on a writable disk",
    errno.ENOSPC: f"free space on that disk, or {_OTHER_OUT} on another disk",
    errno.EDQUOT: f"free space within your disk quota, or {_OTHER_OUT} on another disk",
    errno.ENOTDIR: f"a file is in the way of that folder: move the file, or {_OTHER_OUT}",
    errno.EEXIST: f"a file is in the way of that folder: move the file, or {_OTHER_OUT}",
    errno.EISDIR: f"a folder is in the way of that file: {_OTHER_OUT}",
}


def check_out_folder(build_dir: Path, inputs: list[Path]) -> None:
    """Refuse a ``--out`` the build must not replace (ConfigError naming it, what is there and the fix).

    Parameters
    ----------
    build_dir : the build folder, as given
    inputs : the case's input files; none may lie inside the build folder
    """
    real = Path(os.path.realpath(build_dir))
    for item in inputs:
        folder = Path(os.path.realpath(item)).parent
        if folder == real or real in folder.parents:
            raise ConfigError(
                f"build folder {build_dir}: holds the input file {item}, and a build replaces its whole folder; "
                f"expected a build folder apart from the inputs: {_OTHER_OUT} (e.g. build/<name>)"
            )
    if not os.path.lexists(build_dir):
        return
    if not real.is_dir():
        raise ConfigError(
            f"build folder {build_dir}: is a file, expected a build folder; {_OTHER_OUT}, or move the file away"
        )
    entries = sorted(p.name for p in real.iterdir())
    if not entries:
        return
    if not is_softdesign_build(real):
        raise ConfigError(
            f"build folder {build_dir}: is a folder of other files ({_listed(entries)}) with no softdesign "
            "manifest.json, and a build replaces its whole folder; expected an empty folder or a softdesign build "
            f"folder: {_OTHER_OUT}"
        )
    foreign = foreign_files(real)
    if foreign:
        raise ConfigError(
            f"build folder {build_dir}: is a softdesign build folder that also holds files softdesign did not write "
            f"({_listed(foreign)}), which a new build would drop; move them out of the build folder, or {_OTHER_OUT}"
        )


def _listed(names: list[str]) -> str:
    shown = ", ".join(names[:3])
    return shown + (f" and {len(names) - 3} more" if len(names) > 3 else "")


#: The largest manifest.json read to tell whether a folder is a build (the demo's is about 60 kB).
MAX_MANIFEST_BYTES = 64 << 20


def _manifest(folder: Path) -> dict | None:
    file = folder / MANIFEST
    try:
        if not file.is_file() or file.stat().st_size > MAX_MANIFEST_BYTES:  # never a FIFO: reading it would wait
            return None
        payload = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    return payload if isinstance(payload, dict) else None


def build_folder_holding(folder: Path) -> Path | None:
    """The softdesign build folder that is ``folder`` or holds it (real paths), or None."""
    real = Path(os.path.realpath(folder))
    return next((p for p in (real, *real.parents) if is_softdesign_build(p)), None)


def is_softdesign_build(folder: Path) -> bool:
    """Whether ``folder`` holds a manifest.json that softdesign wrote (its ``software`` names softdesign)."""
    manifest = _manifest(folder)
    return manifest is not None and isinstance(manifest.get("software"), dict) and "softdesign" in manifest["software"]


@contextmanager
def folder_errors(build_dir: Path) -> Iterator[None]:
    """Turn an OSError on the build folder, the folders beside it or its parents into a ConfigError naming the path."""
    try:
        yield
    except OSError as err:
        path = _ours(err, Path(os.path.realpath(build_dir)))
        if path is None:
            raise
        reason = err.strerror or str(err)
        fix = _FIXES.get(err.errno or 0, _OTHER_OUT)
        raise ConfigError(
            f"build folder {build_dir}: cannot write {path} ({reason}); expected a writable folder; {fix}"
        ) from err


def _ours(err: OSError, build_dir: Path) -> str | None:
    """The path of ``err`` when it is the build folder's (inside it, beside it, a parent of it), else None."""
    for name in (err.filename, err.filename2):
        if name is None:
            continue
        path = Path(os.path.realpath(os.fsdecode(name)))
        beside = path.parent == build_dir.parent and (
            sibling_role(build_dir.name, path.name) is not None or path.name == lock_name(build_dir.name)
        )
        inside = any(sibling_role(build_dir.name, p.name) for p in path.parents if p.parent == build_dir.parent)
        if path == build_dir or build_dir in path.parents or path in build_dir.parents or beside or inside:
            return str(path)
    return None
