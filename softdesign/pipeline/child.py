"""Run one function in a child process with a time limit, so native code that crashes or hangs fails the stage cleanly.

A mesher written in C++ (fTetWild) can abort, segfault or loop inside one
call; in the build's own process that would kill it without a word or hang
it for ever.  :func:`run_in_child` starts a fresh interpreter (``spawn``: no
copy of the parent's threads or locks), calls the function there and waits
at most ``timeout_s`` for its answer.  A crash (the child died without
answering), a timeout (the child is killed) or an exception raised in the
child becomes a :class:`~softdesign.errors.MeshError` that says which, with
the child's exit signal or error, and what to change; a memory limit on the
child turns a runaway allocation into one of these too (Linux ``RLIMIT_AS``).
The child works in a scratch folder of its own, so files a library writes
into the working folder (fTetWild's ``__tracked_surface.stl``) go with it:
the parent makes it (``softdesign-child-<pid>-*`` in the temporary folder,
with a marker inside) and removes it once the child has ended, however it
ended; one left by a parent that was itself killed is removed by the next
call, once that parent's process is gone (:func:`remove_stale_scratch`).  The function and its
arguments and result travel by pickle, so the function must be importable
by name (a module-level function).

A child may be given variables of its own environment (``environment``): the
finite-element solves ask glibc's malloc for transparent huge pages
(:data:`HUGE_PAGES`).  Their Newton loops factor a matrix every iteration, and
SuperLU allocates the factors afresh each time (about 180 MB on the sample
device), which the kernel maps and zeroes again page by page: the sample
single-supply device at P* (curved walls, 252 factorizations) took 11.6 M page
faults and 53 s of system time, 306 s of CPU in all; with huge pages 2.4 M,
27 s and 269 s, the same steps and the same answer (the run's two processes side by side, load 4).
glibc reads the variable when a process starts (``glibc.malloc.hugetlb``,
glibc 2.35 and later; older ones and other C libraries ignore it, and with
the kernel's transparent huge pages off it changes nothing), so it is set
for the child only, which is a fresh interpreter.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import re
import resource
import shutil
import signal
import tempfile
from collections.abc import Callable, Iterator
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

from softdesign.errors import MeshError
from softdesign.pipeline.parallel import die_with_parent
from softdesign.pipeline.store import process_alive

#: How long a killed child may take to be reaped, s.
_REAP_S = 10.0
#: A child's scratch folder in the temporary folder: ``softdesign-child-<parent pid>-<random>``, holding the marker.
SCRATCH_PREFIX = "softdesign-child-"
SCRATCH_MARKER = ".softdesign-child"
_SCRATCH = re.compile(re.escape(SCRATCH_PREFIX) + r"(\d+)-[A-Za-z0-9_]+")
#: The environment of a finite-element solve's child: glibc's malloc backs its large blocks with transparent huge
#: pages (the module's docstring).  Added to a ``GLIBC_TUNABLES`` the user set, after it.
HUGE_PAGES = {"GLIBC_TUNABLES": "glibc.malloc.hugetlb=1"}


def remove_stale_scratch(folder: str | None = None) -> None:
    """Remove the scratch folders (marker inside, this user's) whose parent process has ended."""
    root = Path(folder or tempfile.gettempdir())
    try:
        entries = list(root.iterdir())
    except OSError:
        return
    for entry in entries:
        match = _SCRATCH.fullmatch(entry.name)
        try:
            ours = (match is not None and not entry.is_symlink() and entry.is_dir()
                    and entry.stat().st_uid == os.geteuid() and (entry / SCRATCH_MARKER).is_file())
        except OSError:
            continue
        if ours and match is not None and not process_alive(match.group(1)):
            shutil.rmtree(entry, ignore_errors=True)


def _child_main(
    send: Connection, target: Callable[..., Any], args: tuple[Any, ...], memory_bytes: int | None, parent: int,
    scratch: str,
) -> None:
    die_with_parent(parent)  # a mesher left running after its build was killed would run on for nothing
    try:
        if memory_bytes is not None:
            # address space, not resident memory: what a native allocation (malloc, new) is refused beyond
            resource.setrlimit(resource.RLIMIT_AS, (memory_bytes, memory_bytes))
        # native code may write files of its own into the working folder (fTetWild writes
        # __tracked_surface.stl): a scratch folder the parent removes once this child has ended takes them
        os.chdir(scratch)
        result = target(*args)
    except MemoryError as err:
        limit = "" if memory_bytes is None else f" of {memory_bytes / 2**30:.2f} GiB"
        send.send(("error", f"it ran out of memory (the child's limit{limit}): {type(err).__name__} {err}".strip()))
    except BaseException as err:  # noqa: BLE001 - every failure goes back to the parent as a message
        send.send(("error", f"{type(err).__name__}: {err}"))
    else:
        send.send(("ok", result))
    finally:
        send.close()


def _how_it_ended(exitcode: int | None) -> str:
    if exitcode is None:
        return "without an exit status"
    if exitcode < 0:
        try:
            return f"killed by signal {signal.Signals(-exitcode).name}"
        except ValueError:
            return f"killed by signal {-exitcode}"
    return f"with exit code {exitcode}"


def run_in_child(
    target: Callable[..., Any], args: tuple[Any, ...], timeout_s: float, what: str, fix: str,
    memory_bytes: int | None = None, environment: dict[str, str] | None = None,
) -> Any:
    """``target(*args)`` computed in a child process, waiting at most ``timeout_s`` seconds.

    Parameters
    ----------
    target : a module-level function (pickled by name)
    args : its arguments (pickled)
    timeout_s : the longest wait for the answer, s (> 0)
    what : names the work in messages, e.g. ``fTetWild on the body at q=0.000``
    fix : what the user can change, ending the messages of a timeout, a crash or a failure
    memory_bytes : the child's address space limit (``RLIMIT_AS``), bytes; None for none.  An
        allocation beyond it fails (MemoryError, or a native ``bad_alloc`` that may abort the child)
    environment : variables the child starts with besides the parent's (a ``GLIBC_TUNABLES`` the parent has is
        kept, this one's settings after it); the parent's own environment is as it was once the child has started

    Raises
    ------
    MeshError
        The child timed out (it is killed), died without answering (a crash in
        native code: its signal or exit code), ran out of its memory, or raised
        (its exception's type and message).
    """
    if not timeout_s > 0:
        raise ValueError(f"timeout_s must be > 0, got {timeout_s}")
    remove_stale_scratch()
    scratch = tempfile.mkdtemp(prefix=f"{SCRATCH_PREFIX}{os.getpid()}-")
    try:
        (Path(scratch) / SCRATCH_MARKER).write_bytes(b"")
        return _run_and_wait(target, args, timeout_s, what, fix, memory_bytes, scratch, environment or {})
    finally:
        shutil.rmtree(scratch, ignore_errors=True)  # the child has ended (reaped or killed): nothing writes there


@contextlib.contextmanager
def _started_with(environment: dict[str, str]) -> Iterator[None]:
    """The process's environment with ``environment`` added (``GLIBC_TUNABLES`` appended to), as it was after."""
    saved = {name: os.environ.get(name) for name in environment}
    try:
        for name, value in environment.items():
            before = saved[name]
            os.environ[name] = value if not before or name != "GLIBC_TUNABLES" else f"{before}:{value}"
        yield
    finally:
        for name, before in saved.items():
            if before is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = before


def _run_and_wait(
    target: Callable[..., Any], args: tuple[Any, ...], timeout_s: float, what: str, fix: str,
    memory_bytes: int | None, scratch: str, environment: dict[str, str],
) -> Any:
    """:func:`run_in_child`'s work, the child working in ``scratch``."""
    context = multiprocessing.get_context("spawn")
    receive, send = context.Pipe(duplex=False)
    process = context.Process(target=_child_main, args=(send, target, args, memory_bytes, os.getpid(), scratch),
                              daemon=True)
    with _started_with(environment):  # a spawned child starts with the process's environment as it is now
        process.start()
    send.close()  # the child holds the only writer: its death ends the pipe, and poll() sees it at once
    try:
        if not receive.poll(timeout_s):
            process.kill()
            process.join(_REAP_S)
            raise MeshError(f"{what} did not finish within {timeout_s:g} s and was stopped; {fix}")
        try:
            status, payload = receive.recv()
        except EOFError:
            process.join(_REAP_S)
            raise MeshError(f"{what} crashed ({_how_it_ended(process.exitcode)}) before answering; {fix}") from None
    finally:
        receive.close()
        if process.is_alive():
            process.join(_REAP_S)
        if process.is_alive():
            process.kill()
            process.join(_REAP_S)
    if status != "ok":
        raise MeshError(f"{what} failed: {payload}; {fix}")
    return payload
