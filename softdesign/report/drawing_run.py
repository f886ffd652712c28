"""How the report's parts are drawn: each timed and told to the progress, independent ones ahead on forked
workers, with the garbage collector set for drawing.
"""

from __future__ import annotations

import gc
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any, TypeVar

from softdesign.pipeline.parallel import jobs_for_build, map_items, working_on

T = TypeVar("T")


#: Called after each part of the report with its name and the seconds it took (the CLI prints progress).
Progress = Callable[[str, float], None]


class PartTimer:
    """Runs each part of the report, records its time and tells ``progress``.

    :meth:`prefetch` draws independent parts on ``jobs`` forked workers
    (:func:`softdesign.pipeline.parallel.map_items`) ahead of their turn; the
    part's later call returns the worker's result.  Each part is drawn by the
    same code on the same data wherever it runs, so the files do not depend on ``jobs``.
    """

    def __init__(self, progress: Progress | None, jobs: int = 1) -> None:
        self.progress = progress
        self.jobs = jobs
        self.seconds: dict[str, float] = {}
        self._ready: dict[str, Any] = {}

    def __call__(self, name: str, action: Callable[[], T]) -> T:
        if name in self._ready:
            ready: T = self._ready.pop(name)
            return ready
        start = time.perf_counter()
        result = action()
        self._record(name, time.perf_counter() - start)
        return result

    def prefetch(self, parts: dict[str, Callable[[], Any]]) -> None:
        """Draw ``parts`` (name: action; slowest first balances the workers best) on the workers now."""

        def timed(name: str) -> tuple[Any, float]:
            start = time.perf_counter()
            return parts[name](), time.perf_counter() - start

        def arrived(name: str, outcome: tuple[Any, float]) -> None:
            self._ready[name] = outcome[0]
            self._record(name, outcome[1])

        with jobs_for_build(self.jobs), working_on("the report", "the previous report is kept"):
            map_items(timed, list(parts), on_result=arrived)

    def _record(self, name: str, seconds: float) -> None:
        self.seconds[name] = seconds
        if self.progress is not None:
            self.progress(name, seconds)


#: Python's cyclic garbage collector runs after this many new container objects while figures are drawn (its
#: default, 700, had it run some 600 times over the demo's figures).
GC_THRESHOLD = 5000


@contextmanager
def collector_for_figures() -> Iterator[None]:
    """Let the cyclic garbage collector skip what is already loaded and run less often while figures are drawn.

    Drawing makes hundreds of thousands of short-lived matplotlib objects, and each full collection walked the
    hundred thousand objects of the imported libraries as well: about 1 s of the demo's 7 s of drawing.
    :func:`gc.freeze` moves the objects alive now out of the collector's reach (forked workers inherit that, and
    no longer touch those pages, which the kernel would otherwise copy), and a higher first-generation threshold
    lets fewer collections run.  What the figures leave in reference cycles is still collected.
    """
    _import_drawing_libraries()  # here, not once per forked worker, and frozen with the rest
    threshold = gc.get_threshold()
    gc.freeze()
    gc.set_threshold(GC_THRESHOLD, *threshold[1:])
    try:
        yield
    finally:
        gc.set_threshold(*threshold)
        gc.unfreeze()


def _import_drawing_libraries() -> None:
    """Import what the figures draw with (about half a second): forked workers inherit it, none imports it again."""
    import matplotlib.backends.backend_agg  # noqa: F401
    import matplotlib.collections  # noqa: F401
    import matplotlib.figure  # noqa: F401
    import PIL.Image  # noqa: F401
    import plotly.io  # noqa: F401

    import softdesign.report.flat_triangles  # noqa: F401
