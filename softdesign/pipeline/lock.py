"""One run at a time per build folder: an exclusive ``flock`` on ``.<name>.lock`` beside it.

A second run into the same folder is refused at once, naming the first
run's process and machine, rather than waiting: two runs of one case at the same time
are a mistake in the recipe that starts them (``make -j`` with a duplicated
target, two cluster jobs), and waiting would repeat the work in silence or
hang a CI job.  The kernel releases the lock when the process ends, killed
or not (and the build's forked workers die with it:
:mod:`softdesign.pipeline.parallel`).

A run that ends removes the file while it still holds the lock, so no lock
file outlives its run; a run that locked a file removed under it (it opened
the file just before) finds the path gone or another file there, and starts
over on the path's file, so two runs never hold two different files.  A
later run that finds the file of a killed run (still naming its process) says
so and proceeds.  The file is opened without
following a symbolic link and must be a regular file of this user, so a link
planted beside the build folder (in a shared /tmp) cannot make a run write
outside it; nor can a hard link (a lock file with more than one name is refused).
"""

from __future__ import annotations

import errno
import os
import platform
import stat
import sys
from pathlib import Path

from softdesign.errors import ConfigError
from softdesign.pipeline.layout import lock_name
from softdesign.pipeline.store import process_alive

#: How many times a run starts over on a lock file removed under it before it gives up (each a few system calls).
LOCK_ATTEMPTS = 20


class BuildLock:
    """Hold the lock of build folder ``build_dir`` for a with-block (ConfigError when another run holds it)."""

    def __init__(self, build_dir: Path) -> None:
        self.build_dir = Path(build_dir)
        self.path = self.build_dir.parent / lock_name(self.build_dir.name)
        self._fd: int | None = None
        #: what the run should be told (a previous run that was killed), filled on entry
        self.notes: list[str] = []

    def __enter__(self) -> BuildLock:
        if sys.platform == "win32":  # no flock there; runs are not serialized
            return self
        import fcntl

        self.path.parent.mkdir(parents=True, exist_ok=True)
        for _ in range(LOCK_ATTEMPTS):
            fd = self._open()
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = os.read(fd, 200).decode("utf-8", "replace").strip() or "unknown"
                os.close(fd)
                raise ConfigError(self._held_message(holder)) from None
            except BaseException:
                os.close(fd)
                raise
            if self._still_the_path(fd):
                break
            os.close(fd)  # the run that held it removed it as it ended: lock the path's file instead
        else:
            raise ConfigError(f"{self.build_dir}: its lock file {self.path} was replaced {LOCK_ATTEMPTS} times while "
                              "this run took it; expected one run at a time: run again")
        previous = os.read(fd, 200).decode("utf-8", "replace").strip()
        if previous:  # a run that ends clears the file: this one was killed, and the kernel released its lock
            self.notes.append(f"{self.build_dir}: the previous run ({previous}) ended without finishing (killed?); "
                              "its lock was released when it ended, and this run proceeds")
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()} on {_machine()}\n".encode("utf-8", "replace"), 0)
        self._fd = fd
        return self

    def _open(self) -> int:
        """The lock file, opened without following a link; refused unless a regular file of this user."""
        flags = os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
        fix = f"remove {self.path} (softdesign makes it anew), or give --out another folder"
        try:
            fd = os.open(self.path, flags | getattr(os, "O_NONBLOCK", 0), 0o666)
        except OSError as err:
            if err.errno == errno.ELOOP or os.path.islink(self.path):
                raise ConfigError(f"{self.build_dir}: its lock file {self.path} is a symbolic link (to "
                                  f"{os.readlink(self.path)}); softdesign does not follow it, so that nothing outside "
                                  f"the build folder is written; {fix}") from None
            raise
        info = os.fstat(fd)
        what = None
        if not stat.S_ISREG(info.st_mode):
            what = "not a regular file"
        elif info.st_uid != os.geteuid():
            what = f"owned by user id {info.st_uid}"
        elif info.st_nlink > 1:  # a hard link to another file: the run would write its pid into that file
            what = f"a file with {info.st_nlink} names (a hard link to a file elsewhere)"
        if what is not None:
            os.close(fd)
            raise ConfigError(f"{self.build_dir}: its lock file {self.path} is {what}; expected a regular file of "
                              f"this user with no other name (id {os.geteuid()}); {fix}")
        return fd

    def _held_message(self, holder: str) -> str:
        pid, _, machine = holder.partition(" on ")
        ended = machine == _machine() and pid.isdigit() and not process_alive(pid)
        if ended:
            who = (f"pid {pid}, which has ended; a process it started still holds {self.path} (list it with "
                   f"`fuser {self.path}`)")
            fix = "end that process, then run again"
        else:
            who, fix = f"pid {holder}", "wait for that run to end, or give this one another --out"
        return (f"{self.build_dir}: another softdesign run ({who}) is writing this build folder "
                f"(it holds {self.path}); expected no other run into the same folder: {fix}")

    def _still_the_path(self, fd: int) -> bool:
        """Whether the locked file is still the one at :attr:`path` (not removed or replaced meanwhile)."""
        try:
            here = os.lstat(self.path)
        except FileNotFoundError:
            return False
        mine = os.fstat(fd)
        return (here.st_dev, here.st_ino) == (mine.st_dev, mine.st_ino)

    def __exit__(self, *exc: object) -> None:
        if self._fd is not None:
            try:
                if self._still_the_path(self._fd):
                    os.unlink(self.path)  # while still held: no lock file outlives its run
            except OSError:
                os.ftruncate(self._fd, 0)  # cannot remove it: the next run finds it empty (ended, not killed)
            finally:
                os.close(self._fd)  # closing the only descriptor releases the flock
            self._fd = None


def _machine() -> str:
    return platform.node() or "this machine"
