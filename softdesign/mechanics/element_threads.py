"""Element loops split over threads, each writing its own rows of the result.

numpy releases the interpreter's lock inside its array loops (ufuncs, batched
``matmul``, ``einsum``), so the elements of a mesh split into contiguous parts
are computed side by side on the cores the process may use.  Each element's
arithmetic is the same whichever part holds it (the loops run along the
element axis), so the result is the same, bit for bit, with one thread or
several: the number of threads changes the time, never the answer.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from functools import cache

#: At most this many threads (the element loops' memory traffic gains little past it).
MAX_THREADS = 4
#: Below this many elements a loop runs in the calling thread (a part's start-up would cost more than it saves).
MIN_PART_ELEMENTS = 512


def _cores() -> int:
    """The cores this process may run on (its CPU affinity), at least 1."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not Linux
        return max(1, os.cpu_count() or 1)


@cache
def _pool(threads: int, pid: int) -> ThreadPoolExecutor:
    """The threads of process ``pid``: a forked child has none of its parent's threads, and a pool copied with a
    lock held at the fork would never run its work; the child makes its own."""
    return ThreadPoolExecutor(max_workers=threads, thread_name_prefix="softdesign-elements")


def in_parts(count: int, work: Callable[[slice], None]) -> None:
    """Run ``work(part)`` over contiguous parts (slices) that cover ``range(count)``, on up to the process's cores
    (at most MAX_THREADS), and return when every part is done.  ``work`` writes its part's rows of its outputs and
    nothing else; an exception in any part is raised here."""
    threads = min(_cores(), MAX_THREADS, max(1, count // MIN_PART_ELEMENTS))
    if threads == 1:
        work(slice(0, count))
        return
    bounds = [count * k // threads for k in range(threads + 1)]
    pool = _pool(threads, os.getpid())
    futures = [pool.submit(work, slice(lo, hi)) for lo, hi in zip(bounds[:-1], bounds[1:], strict=True)]
    for future in futures:
        future.result()
