"""The build folder as one transaction: a complete new folder swapped in whole; canonical JSON, hashes.

A run fills a staging folder beside the build folder
(``.<name>.staging-<pid>-<hex>`` in the same parent, so renames stay on one
file system) with the whole next build: the files it writes, and the files
of the stages it keeps, hard-linked from the current folder.  Only when every
stage has succeeded and the manifest lists every file is that folder swapped
in for the old one, in one step (:mod:`softdesign.pipeline.swap`); the old
folder, with anything the new manifest does not list, is then removed.  A
run that fails, or is killed, leaves the previous build folder as it was; its
staging folder is removed on failure, or by the next run after a kill.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import secrets
import shutil
from pathlib import Path
from typing import Any

import numpy as np

from softdesign.pipeline.layout import STAGING_MARKER, staging_name, trash_name
from softdesign.pipeline.swap import remove_folder, swap_in


def canonical_json(payload: Any) -> str:
    """JSON with a fixed layout (key order as built, 2-space indent, newline at end)."""
    return json.dumps(payload, indent=2, allow_nan=False, default=_json_default) + "\n"


def _json_default(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, (np.floating, np.integer, np.bool_)):
        return value.item()
    if isinstance(value, Path):
        return value.as_posix()
    raise TypeError(f"cannot write {type(value).__name__} to JSON")


def sha256_bytes(data: bytes) -> str:
    """Hex sha256 of bytes."""
    return hashlib.sha256(data).hexdigest()


def sha256_file(path: Path) -> str:
    """Hex sha256 of a file's contents, read in chunks."""
    digest = hashlib.sha256()
    with Path(path).open("rb") as handle:
        try:
            for chunk in iter(lambda: handle.read(1 << 20), b""):
                digest.update(chunk)
        except OSError as err:  # a failed read names no file (EIO from /proc/self/mem): name it, so callers can
            raise OSError(err.errno, err.strerror, str(path)) from err
    return digest.hexdigest()


def npz_bytes(**arrays: np.ndarray) -> bytes:
    """An uncompressed .npz archive as bytes (numpy writes fixed zip timestamps)."""
    buffer = io.BytesIO()
    # mypy: a spread dict might name savez's allow_pickle; the names here are the stages' array names
    np.savez(buffer, **{k: np.asarray(v) for k, v in sorted(arrays.items())})  # type: ignore[arg-type]
    return buffer.getvalue()


def load_npz(path: Path) -> dict[str, np.ndarray]:
    """All arrays of an .npz file."""
    with np.load(path, allow_pickle=False) as data:
        return {k: data[k] for k in data.files}


def read_record(file: Path) -> dict[str, Any] | None:
    """A JSON record (e.g. ``<stage>/stage.json``) as a dict, or None when missing or unreadable."""
    if not file.is_file():
        return None
    try:
        payload = json.loads(file.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):  # RecursionError: nested too deep to be one of ours
        return None
    return payload if isinstance(payload, dict) else None


def process_alive(pid: str) -> bool:
    """Whether process ``pid`` (digits) runs on this machine (the owner of a temporary folder)."""
    if not pid.isdigit():
        return False
    try:
        os.kill(int(pid), 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True  # it exists, owned by someone else
    return True


class Staging:
    """The next build folder, filled complete beside the current one and swapped in whole.

    Use as a context manager while holding the folder's lock
    (:class:`~softdesign.pipeline.lock.BuildLock`): on an exception the
    staging folder is removed and the build folder is left as it was.
    """

    def __init__(self, build_dir: Path) -> None:
        self.build_dir = Path(build_dir)
        #: where the folder really is: a symlinked build folder is replaced where it points, the link kept
        self.target = Path(os.path.realpath(self.build_dir))
        self.root: Path | None = None
        #: every file of the new folder (written by this run or kept from the current one) with its sha256
        self.written: dict[str, str] = {}

    def __enter__(self) -> Staging:
        self.target.parent.mkdir(parents=True, exist_ok=True)
        root = self.target.parent / staging_name(self.target.name, os.getpid(), secrets.token_hex(6))
        root.mkdir()  # unlike mkdtemp, honours the umask: the build is as readable as before
        self.root = root
        (root / STAGING_MARKER).write_bytes(b"")  # a killed run's folder is known as softdesign's by this
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if self.root is not None:
            remove_folder(self.root)
            self.root = None

    def _root(self) -> Path:
        if self.root is None:
            raise RuntimeError("Staging used outside its with-block")
        return self.root

    @property
    def folder(self) -> Path:
        """The new folder being filled (its files are :attr:`written`)."""
        return self._root()

    def write_bytes(self, relative: str, data: bytes) -> str:
        """Stage ``data`` for ``build_dir/relative``; returns its sha256."""
        target = self.staged_path(relative)
        try:
            target.write_bytes(data)
        except OSError as err:
            if err.filename is not None:
                raise
            # a failed write() (a full disk) names no file: name it, so the message can
            raise OSError(err.errno, err.strerror, str(target)) from err
        self.written[relative] = sha256_bytes(data)
        return self.written[relative]

    def write_json(self, relative: str, payload: Any) -> str:
        """Stage canonical JSON."""
        return self.write_bytes(relative, canonical_json(payload).encode("utf-8"))

    def staged_path(self, relative: str) -> Path:
        """Where a file is staged (for writers that need a path, e.g. vtk)."""
        target = self._root() / relative
        target.parent.mkdir(parents=True, exist_ok=True)
        return target

    def record(self, relative: str) -> str:
        """Register a file a writer put at :meth:`staged_path`; returns its sha256."""
        self.written[relative] = sha256_file(self.staged_path(relative))
        return self.written[relative]

    def keep(self, relative: str, sha256: str) -> None:
        """Carry ``build_dir/relative`` (checked: its hash is ``sha256``) into the new folder: hard link, else copy."""
        source, target = self.target / relative, self.staged_path(relative)
        try:
            os.link(source, target)
        except OSError:  # a file system without hard links (or at its link limit)
            shutil.copyfile(source, target)
        self.written[relative] = sha256

    def commit(self) -> None:
        """Swap the new folder in for the build folder in one step (:func:`~softdesign.pipeline.swap.swap_in`)."""
        root = self._root()
        (root / STAGING_MARKER).unlink()
        on_disk = {p.relative_to(root).as_posix() for p in root.rglob("*") if not p.is_dir()}
        if on_disk != set(self.written):  # a stage wrote a file it did not record: a bug
            raise RuntimeError(f"staged files not recorded: {sorted(on_disk ^ set(self.written))}")
        trash = self.target.parent / trash_name(self.target.name, os.getpid(), secrets.token_hex(6))
        previous = swap_in(root, self.target, trash)
        self.root = None
        if previous is not None:
            remove_folder(previous)
