"""Per-q work of a stage on several processes: the same results, in the same order, whatever the number of jobs.

A build runs with ``jobs`` worker processes (``--jobs N``; default: the cores
this process may run on).  The stages whose work is one independent
computation per export q (kinematics' poses, export's solids, feasibility's
figures) hand it to :func:`map_per_q`, and the fit its blocks of points to
:func:`map_items`; every other stage is unchanged.

Why processes started by ``fork``: the per-q work is numpy, scipy, vtk and
manifold3d code that holds the GIL in places, so threads would not use the
cores; a forked worker starts in milliseconds with those libraries already
imported and the stage's inputs (the blended shape and the radius field,
splines and arrays of hundreds of MB) already in memory, shared copy-on-write.
``spawn`` would re-import the libraries in every worker (2 to 3 s each on the
benchmark machine) and pickle the inputs to each.  Only a q goes to a worker
and only its result comes back.  Where ``fork`` is not available (not Linux
or macOS) the work runs in this process.

Left running: none.  Each worker asks the kernel to kill it when the build's
process ends (:func:`die_with_parent`), so a build killed mid-stage leaves no
worker holding its memory or the build folder's lock.

Same bytes: each q is computed by the same code on the same inputs wherever
it runs, and the results come back in the order of the q values, so the
outputs do not depend on ``jobs`` (``tests/pipeline/test_parallel.py``
builds with 1 and 2 jobs and compares every file).
"""

from __future__ import annotations

import os
import signal
import sys
from collections.abc import Callable, Iterator, MutableMapping, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any, TypeVar

from softdesign.errors import ConfigError, SoftdesignError

T = TypeVar("T")

#: Most worker processes a build may ask for (``--jobs``): far above any machine this runs on, and a bound
#: on the processes one command can start.
MAX_JOBS = 256

_JOBS: ContextVar[int] = ContextVar("softdesign_jobs", default=1)
#: What the current parallel work is (a stage's name, "report") and what a failure keeps, for a dead worker's message.
_WORK: ContextVar[tuple[str, str]] = ContextVar("softdesign_work", default=("the build", "the previous build is kept"))
#: The function the forked workers call: inherited by fork, never pickled (it may be a closure).
_TASK: Callable[[Any], Any] | None = None


#: The environment variable that sets OpenBLAS's thread count (numpy's and scipy's wheels ship OpenBLAS); read once,
#: when the library loads.
BLAS_THREADS_VARIABLE = "OPENBLAS_NUM_THREADS"


def one_blas_thread(environ: MutableMapping[str, str] = os.environ) -> None:
    """Ask for one OpenBLAS thread per process, unless the user's environment says otherwise; before numpy loads.

    The build's parallel work runs on worker processes (``--jobs``); OpenBLAS would start threads of its own in
    each, which wait on the others' cores.  Its calls here are small (the fit's sparse solves, short products),
    so its threads speed nothing up: the demo's build and report take the same wall time with one, 7 % and 5 %
    less CPU, and the sample cohort on ``make -j2`` 10 % less wall time.
    """
    environ.setdefault(BLAS_THREADS_VARIABLE, "1")


def available_cores() -> int:
    """The cores this process may run on (its CPU affinity, which a batch scheduler sets), at least 1."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not Linux
        return max(1, os.cpu_count() or 1)


def checked_jobs(jobs: int | None, option: str = "--jobs", note: Callable[[str], None] | None = None) -> int:
    """``jobs`` at most the available cores (None: the cores); ConfigError outside 1 to MAX_JOBS.

    Each worker is a forked copy of the build (about 30 MB, and its own meshes): more workers than cores run no
    faster and multiply the memory (``--jobs 256`` reached 7.2 GB in 2.3 s), so a larger count is capped at the
    cores, and ``note`` is told so.
    """
    cores = min(available_cores(), MAX_JOBS)
    if jobs is None:
        return cores
    if not 1 <= jobs <= MAX_JOBS:
        raise ConfigError(f"{option} must be 1 to {MAX_JOBS} worker processes, got {jobs}; "
                          f"leave it out for the {available_cores()} core(s) available, or give {option} 1")
    if jobs > cores:
        if note is not None:
            note(f"{option} {jobs}: capped at the {cores} core(s) this process may run on (more workers than "
                 "cores only add memory)")
        return cores
    return jobs


@contextmanager
def jobs_for_build(jobs: int) -> Iterator[None]:
    """Let :func:`map_per_q` use ``jobs`` processes inside the block (the runner wraps a build in it)."""
    token = _JOBS.set(jobs)
    try:
        yield
    finally:
        _JOBS.reset(token)


@contextmanager
def working_on(what: str, kept: str = "the previous build is kept") -> Iterator[None]:
    """Name the parallel work inside the block (``what``: a stage's name) and what a failure keeps, for messages."""
    token = _WORK.set((what, kept))
    try:
        yield
    finally:
        _WORK.reset(token)


def current_jobs() -> int:
    """The number of processes the current build may use (1 outside :func:`jobs_for_build`)."""
    return _JOBS.get()


#: prctl's option asking the kernel to send a signal to this process when its parent ends (Linux).
_PR_SET_PDEATHSIG = 1


def die_with_parent(parent_pid: int) -> None:
    """In a worker: be killed (SIGKILL) when the process that started it ends, killed or not; Linux only.

    A worker of a killed build would otherwise live on, asleep on its pipe,
    holding the memory it inherited and the build folder's lock, so that every
    later build is refused.  Where prctl is missing (not Linux) nothing is asked.
    """
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        except (OSError, AttributeError):
            return
        if os.getppid() != parent_pid:  # the parent ended before the request was made: end now
            os._exit(1)


def _call(item: Any) -> Any:
    if _TASK is None:
        raise RuntimeError("a softdesign worker started without its task")
    return _TASK(item)


def map_per_q(task: Callable[[float], T], q_values: Sequence[float], most: int | None = None) -> list[T]:
    """``[task(q) for q in q_values]``, on up to :func:`current_jobs` processes (and at most ``most``).

    Parameters
    ----------
    task : the work for one q; may be a closure (the workers inherit it by fork)
    q_values : the export q values, in output order
    most : a bound of the stage's own (e.g. how many of its meshes fit in memory at once), or None

    Returns
    -------
    list, the results in the order of ``q_values``.  An exception raised by a task is raised here.
    """
    return map_items(task, q_values, most)


def map_items(
    task: Callable[[Any], T], items: Sequence[Any], most: int | None = None,
    on_result: Callable[[Any, T], None] | None = None,
) -> list[T]:
    """``[task(item) for item in items]`` on up to :func:`current_jobs` forked processes (and at most ``most``).

    As :func:`map_per_q` for any picklable items and results (the report's figures by name);
    ``on_result(item, result)`` is called in this process as each result arrives, in the order of ``items``.
    """
    workers = min(current_jobs(), len(items), most if most is not None else len(items))
    if workers > 1:
        import multiprocessing  # here, not at import: the command line's start-up (validate, --help) skips them

        if "fork" in multiprocessing.get_all_start_methods():
            return _map_forked(task, items, workers, on_result)
    results = []
    for item in items:
        results.append(task(item))
        if on_result is not None:
            on_result(item, results[-1])
    return results


def map_items_beside(task: Callable[[Any], T], items: Sequence[Any], beside: Callable[[], Any]) -> list[T]:
    """``[task(item) for item in items]`` on up to :func:`current_jobs` forked processes while this process runs
    ``beside()`` (work of its own that needs none of their results, e.g. imports); the results in order.

    Unlike :func:`map_items`, a single item goes to a worker too when jobs allow, so that it runs beside; with one
    job (or no ``fork``) ``beside()`` runs first, then the items here.  An error of ``beside`` stops the workers
    (every one reaped) before it goes on; an item's error is raised once ``beside`` is done.
    """
    workers = min(current_jobs(), len(items))
    if workers >= 1 and current_jobs() > 1:
        import multiprocessing

        if "fork" in multiprocessing.get_all_start_methods():
            return _map_forked(task, items, workers, None, beside)
    beside()
    return [task(item) for item in items]


def _map_forked(
    task: Callable[[Any], T], items: Sequence[Any], workers: int, on_result: Callable[[Any, T], None] | None,
    beside: Callable[[], Any] | None = None,
) -> list[T]:
    """:func:`map_items` on ``workers`` forked processes (``beside``: run here once the items are handed out)."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures.process import BrokenProcessPool

    global _TASK
    _TASK = task
    processes: dict[int, Any] = {}
    try:
        pool = ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("fork"),
                                   initializer=die_with_parent, initargs=(os.getpid(),))
        try:
            found = getattr(pool, "_processes", None)  # the workers (filled as they start), to say how one died
            processes = found if isinstance(found, dict) else {}
            results = []
            arriving = pool.map(_call, items)  # every item handed out now; the results come in order below
            if beside is not None:
                beside()
            for item, result in zip(items, arriving, strict=True):
                results.append(result)
                if on_result is not None:
                    on_result(item, result)
        except BaseException:
            pool.shutdown(wait=True)  # every worker stopped and reaped before the error goes on
            raise
        # every result is here: the workers end on their own (told to by the pool's thread, which reaps them; the
        # interpreter joins it at exit), while this process goes on, instead of waiting on their exits
        _ENDING[:] = [thread for thread in _ENDING if thread.is_alive()]
        thread = getattr(pool, "_executor_manager_thread", None)
        pool.shutdown(wait=False)
        if thread is not None:
            _ENDING.append(thread)
        return results
    except BrokenProcessPool:  # the pool has stopped and reaped every worker by now
        what, kept = _WORK.get()
        raise SoftdesignError(f"a worker died ({_how_died(list(processes.values()))}) during {what}; {kept} "
                              "(a worker killed by the system is often out of memory: give --jobs 1, or free "
                              "memory)") from None
    finally:
        _TASK = None


#: The threads of pools whose workers were told to end without a wait (each reaps its pool's workers, then ends).
_ENDING: list[Any] = []


def settle_workers() -> None:
    """Wait until every worker told to end has ended and been reaped.

    A build does not wait on its workers' exits (:func:`map_items`); a measurement of the CPU time of this
    process's children (``RUSAGE_CHILDREN`` counts reaped ones only) calls this first, so that a stage's
    workers are counted in that stage.
    """
    while _ENDING:
        _ENDING.pop().join()


def _how_died(processes: list[Any]) -> str:
    """``signal 9`` for the first worker that ended by a signal other than the pool's own SIGTERM, else a guess."""
    codes = [p.exitcode for p in processes if getattr(p, "exitcode", None) is not None]
    killed = [-c for c in codes if c < 0 and -c != signal.SIGTERM] or [-c for c in codes if c < 0]
    if killed:
        return f"signal {killed[0]}"
    ended = [c for c in codes if c > 0]
    return f"exit code {ended[0]}" if ended else "no exit status"
