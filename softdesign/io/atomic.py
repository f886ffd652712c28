"""Files that appear whole or not at all: write under a temporary name beside the target, then rename.

Only a regular file is ever replaced: a target that exists as anything else (a
device such as ``/dev/null``, a FIFO, a folder, a symbolic link) is refused
before anything is written, so that running as root cannot turn a device into
a file and a planted link cannot redirect the output.  The temporary file is
made by :func:`tempfile.mkstemp` in the target's folder (an unpredictable name,
created with ``O_EXCL``: a link planted under a guessed name is never followed)
and given the permissions a plain ``open`` would (``0o666`` less the umask).
"""

from __future__ import annotations

import os
import stat
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from softdesign.errors import ConfigError
from softdesign.io.case_yaml import file_kind


def check_replaceable(path: str | Path) -> None:
    """ConfigError when ``path`` exists and is not a regular file (its link is not followed).

    Raises
    ------
    ConfigError
        Naming the path, what it is, and the fix.
    """
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return
    except OSError:
        return  # cannot look (a missing folder, no permission): the write itself says why
    if not stat.S_ISREG(mode):
        raise ConfigError(f"{path}: is {file_kind(mode)}, not a regular file; softdesign writes its output only as a "
                          "new file or over a regular file, never over a device, pipe, folder or link: "
                          "choose another file name")


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


@contextmanager
def atomic_target(path: str | Path) -> Iterator[Path]:
    """Yield a new temporary file beside ``path``; on success it is renamed to ``path``, else removed.

    For writers that need a file name (vtk); a reader never sees half a file.

    Raises
    ------
    ConfigError
        ``path`` exists and is not a regular file (checked before and again just before the rename).
    """
    path = Path(path)
    check_replaceable(path)
    fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    temporary = Path(name)
    try:
        try:
            os.fchmod(fd, 0o666 & ~_umask())
        finally:
            os.close(fd)
        yield temporary
        check_replaceable(path)
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)


def write_bytes_atomically(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically (a regular file or nothing there); returns ``path``."""
    with atomic_target(path) as temporary:
        temporary.write_bytes(data)
    return Path(path)
