"""The build folder: staged atomic writes, canonical JSON, hashes.

A run writes every new file into a staging folder beside the build folder
(``.<name>.staging-XXXX`` in the same parent, so renames stay on one file
system) and moves the files into place only when the whole run has
succeeded (``manifest.json`` last).  A run that fails, or is killed, leaves
the previous good build folder untouched; its staging folder is removed on
failure, or cleared by the next run after a kill.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from softdesign.pipeline.layout import MANIFEST, STAGING_PREFIX



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
        for chunk in iter(lambda: handle.read(1 << 20), b""):
            digest.update(chunk)
    return digest.hexdigest()


def npz_bytes(**arrays: np.ndarray) -> bytes:
    """An uncompressed .npz archive as bytes (numpy writes fixed zip timestamps)."""
    buffer = io.BytesIO()
    np.savez(buffer, **{k: np.asarray(v) for k, v in sorted(arrays.items())})
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
        return json.loads(file.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError):
        return None


def process_alive(pid: str) -> bool:
    """Whether process ``pid`` (digits) runs on this machine (the owner of a staging folder)."""
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
    """Files of one run, written under a staging folder and committed together.

    Use as a context manager: on an exception the staging folder is removed
    and the build folder is left as it was.
    """

    def __init__(self, build_dir: Path) -> None:
        self.build_dir = Path(build_dir)
        self.root: Path | None = None
        self.written: dict[str, str] = {}

    def __enter__(self) -> "Staging":
        parent = self.build_dir.resolve().parent
        parent.mkdir(parents=True, exist_ok=True)
        prefix = f".{self.build_dir.name}{STAGING_PREFIX}"
        for stale in parent.glob(prefix + "*"):
            if not process_alive(stale.name.removeprefix(prefix).split("-", 1)[0]):
                shutil.rmtree(stale, ignore_errors=True)
        self.root = Path(tempfile.mkdtemp(prefix=f"{prefix}{os.getpid()}-", dir=parent))
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if self.root is not None:
            shutil.rmtree(self.root, ignore_errors=True)
            self.root = None

    def write_bytes(self, relative: str, data: bytes) -> str:
        """Stage ``data`` for ``build_dir/relative``; returns its sha256."""
        if self.root is None:
            raise RuntimeError("Staging used outside its with-block")
        target = self.root / relative
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(data)
        self.written[relative] = sha256_bytes(data)
        return self.written[relative]

    def write_json(self, relative: str, payload: Any) -> str:
        """Stage canonical JSON."""
        return self.write_bytes(relative, canonical_json(payload).encode("utf-8"))

    def staged_path(self, relative: str) -> Path:
        """Where a file is staged (for writers that need a path, e.g. vtk)."""
        if self.root is None:
            raise RuntimeError("Staging used outside its with-block")
        target = self.root / relative
        target.parent.mkdir(parents=True, exist_ok=True)
        return target

    def record(self, relative: str) -> str:
        """Register a file a writer put at :meth:`staged_path`; returns its sha256."""
        self.written[relative] = sha256_file(self.staged_path(relative))
        return self.written[relative]

    def commit(self) -> None:
        """Move every staged file into the build folder, the manifest last."""
        if self.root is None:
            raise RuntimeError("Staging used outside its with-block")
        ordered = sorted(self.written, key=lambda rel: (rel == MANIFEST, rel))
        self.build_dir.mkdir(parents=True, exist_ok=True)
        for relative in ordered:
            target = self.build_dir / relative
            target.parent.mkdir(parents=True, exist_ok=True)
            os.replace(self.root / relative, target)
