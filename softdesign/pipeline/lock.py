"""One run at a time per build folder: an exclusive ``flock`` on ``.<name>.lock`` beside it.

A second run into the same folder is refused at once, naming the first
run's process and machine, rather than waiting: two runs of one case at the same time
are a mistake in the recipe that starts them (``make -j`` with a duplicated
target, two cluster jobs), and waiting would repeat the work in silence or
hang a CI job.  The lock file stays beside the folder (removing it would let
a third run lock a new file while the second still waits on the old one);
the kernel releases the lock when the process ends, killed or not.
"""

from __future__ import annotations

import os
import platform
import sys
from pathlib import Path

from softdesign.errors import ConfigError
from softdesign.pipeline.layout import lock_name


class BuildLock:
    """Hold the lock of build folder ``build_dir`` for a with-block (ConfigError when another run holds it)."""

    def __init__(self, build_dir: Path) -> None:
        self.build_dir = Path(build_dir)
        self.path = self.build_dir.parent / lock_name(self.build_dir.name)
        self._fd: int | None = None

    def __enter__(self) -> BuildLock:
        if sys.platform == "win32":  # no flock there; runs are not serialized
            return self
        import fcntl

        self.path.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o666)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.read(fd, 200).decode("utf-8", "replace").strip() or "unknown"
            os.close(fd)
            raise ConfigError(
                f"{self.build_dir}: another softdesign run (pid {holder}) is writing this build folder "
                f"(it holds {self.path}); expected no other run into the same folder: wait for that run to end, "
                "or give this one another --out"
            ) from None
        except BaseException:
            os.close(fd)
            raise
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()} on {platform.node() or 'this machine'}\n".encode("utf-8", "replace"))
        self._fd = fd
        return self

    def __exit__(self, *exc: object) -> None:
        if self._fd is not None:
            os.close(self._fd)  # closing the only descriptor releases the flock
            self._fd = None
