"""Put a finished folder in place of the build folder in one step, and repair a swap a kill interrupted.

On Linux, ``renameat2(RENAME_EXCHANGE)`` exchanges two directory entries
atomically: at every instant the build folder's name holds the old folder or
the new one, never a mix and never nothing.  Where that call is missing
(another system, a libc older than 2.28) or refused by the file system (some
network file systems), the swap takes two renames, old -> ``.<name>.trash-*``
then new -> ``<name>``; a kill between them leaves the name missing beside a
complete trash folder, and :func:`repair` (the next run, under the lock) puts
that folder back.
"""

from __future__ import annotations

import ctypes
import errno
import os
import shutil
import sys
from collections.abc import Callable
from pathlib import Path

from softdesign.pipeline.layout import MANIFEST, STAGING_MARKER, sibling_role
from softdesign.pipeline.out_folder import is_softdesign_build

_AT_FDCWD = -100
_RENAME_EXCHANGE = 1 << 1
#: What renameat2 answers when this kernel or file system cannot exchange: the two-rename swap is used instead.
_UNSUPPORTED = {errno.ENOSYS, errno.EINVAL, errno.EOPNOTSUPP, errno.ENOTSUP}


def _load_renameat2() -> Callable[..., int] | None:
    """libc's renameat2, or None where there is none (not Linux, glibc < 2.28, musl < 1.2.2)."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        function = ctypes.CDLL(None, use_errno=True).renameat2
    except (OSError, AttributeError):
        return None
    function.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    function.restype = ctypes.c_int
    return function


_renameat2 = _load_renameat2()


def exchange(first: Path, second: Path) -> bool:
    """Exchange two existing directory entries atomically; False (nothing changed) where this system cannot."""
    if _renameat2 is None:
        return False
    if _renameat2(_AT_FDCWD, os.fsencode(first), _AT_FDCWD, os.fsencode(second), _RENAME_EXCHANGE) == 0:
        return True
    code = ctypes.get_errno()
    if code in _UNSUPPORTED:
        return False
    raise OSError(code, os.strerror(code), str(first), None, str(second))


def swap_in(new: Path, target: Path, trash: Path) -> Path | None:
    """Make folder ``new`` the folder at ``target``; returns where the previous folder now is, to remove.

    ``trash`` is the name the previous folder takes when the two cannot be
    exchanged in one step.  On an error the previous folder is left at ``target``.
    """
    if not os.path.lexists(target):
        os.rename(new, target)
        return None
    if exchange(new, target):
        return new  # the previous folder now has the staging name
    os.rename(target, trash)
    try:
        os.rename(new, target)
    except OSError:
        os.rename(trash, target)
        raise
    return trash


def leftovers(target: Path) -> dict[str, list[Path]]:
    """The staging and trash folders beside ``target`` (``{"staging": [...], "trash": [...]}``), by exact name."""
    found: dict[str, list[Path]] = {"staging": [], "trash": []}
    if not target.parent.is_dir():
        return found
    for entry in sorted(target.parent.iterdir()):
        role = sibling_role(target.name, entry.name)
        if role is not None:
            found[role].append(entry)
    return found


def repair(target: Path) -> list[str]:
    """Finish what a killed run left beside ``target``; call it holding the build folder's lock.

    When ``target`` is missing and a complete previous folder waits under a
    trash name (a two-rename swap cut between its renames), it is renamed
    back.  Every other staging or trash folder is a dead run's and is removed,
    but only when softdesign made it (:func:`made_by_softdesign`): a folder of
    the user's that happens to have such a name is left alone.

    Returns
    -------
    One line per repair made, for the progress output.
    """
    found = {role: [f for f in folders if made_by_softdesign(f)] for role, folders in leftovers(target).items()}
    done = []
    complete = [t for t in found["trash"] if (t / MANIFEST).is_file()]
    if not os.path.lexists(target) and complete:
        restored = max(complete, key=lambda t: t.stat().st_mtime)
        os.rename(restored, target)
        done.append(f"{target}: restored the previous build folder, which an interrupted run had set aside")
    for folder in found["staging"] + found["trash"]:
        if folder.exists():
            remove_folder(folder)
    return done


def made_by_softdesign(folder: Path) -> bool:
    """Whether ``folder`` (a staging or trash name) is a run's: it holds the staging marker or a build's manifest."""
    if folder.is_symlink() or not folder.is_dir():
        return False
    return (folder / STAGING_MARKER).is_file() or is_softdesign_build(folder)


def remove_folder(folder: Path) -> None:
    """Remove a folder of ours; what cannot be removed now is left for the next run's :func:`repair`."""
    shutil.rmtree(folder, ignore_errors=True)
