"""How the report's parts are drawn: each timed and told to the progress, independent ones ahead on forked
workers, with the garbage collector set for drawing.
"""

from __future__ import annotations

import gc
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any, TypeVar

from softdesign.pipeline.parallel import jobs_for_build, map_items, map_items_beside, working_on

if TYPE_CHECKING:
    from softdesign.report.build_folder import BuildData

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
def collector_for_figures(data: BuildData | None = None, jobs: int = 1) -> Iterator[None]:
    """Let the cyclic garbage collector skip what is already loaded and run less often while figures are drawn.

    Drawing makes hundreds of thousands of short-lived matplotlib objects, and each full collection walked the
    hundred thousand objects of the imported libraries as well: about 1 s of the demo's 7 s of drawing.
    :func:`gc.freeze` moves the objects alive now out of the collector's reach (forked workers inherit that, and
    no longer touch those pages, which the kernel would otherwise copy), and a higher first-generation threshold
    lets fewer collections run.  What the figures leave in reference cycles is still collected.

    With ``data`` and ``jobs`` >= 2 the vessel as the report shows it is found on a worker while the drawing
    libraries are imported here (:func:`vessel_beside_imports`).
    """
    vessel_beside_imports(data, jobs)  # the imports here, not once per forked worker, and frozen with the rest
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


def vessel_beside_imports(data: BuildData | None, jobs: int) -> None:
    """Import the drawing libraries; with ``jobs`` >= 2 and a vessel surface in ``data``, find its display
    (:attr:`BuildData.vessel_display <softdesign.report.build_folder.BuildData.vessel_display>`) on a worker
    meanwhile, and keep it on ``data`` before the figures' workers fork.

    The 3D view and the surface figure both show the decimated vessel, and each is a task of its own on the
    figures' workers (:meth:`PartTimer.prefetch`): on two workers each decimated it (1.6 and 1.9 s of CPU on the
    1M-triangle bench vessel), and on one it still waited for the imports, a second with a core idle.  Found
    once, beside the imports, the figures' workers inherit it: the same numbers (the same call on the same
    arrays).  A failure there is left to the figures, which find it again and fail as before.
    """
    if data is None or jobs < 2 or not len(data.ingest.faces):
        _import_drawing_libraries()
        return
    with jobs_for_build(jobs), working_on("the report", "the previous report is kept"):
        (shown,) = map_items_beside(lambda _: _vessel_display_or_none(data), [0], _import_drawing_libraries)
    if shown is not None:
        data.keep_vessel_display(shown)


def _vessel_display_or_none(data: BuildData) -> tuple[Any, Any, float] | None:
    """``data.vessel_display``, or None when finding it fails (the figures that show it then fail as before)."""
    try:
        return data.vessel_display
    except Exception:  # noqa: BLE001 - raised again, the same, by the figure that asks for it
        return None
