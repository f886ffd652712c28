"""A build's progress on a terminal: the stage line, and while export makes its meshes a rich bar in its place.

:class:`~softdesign.cli.common.StageProgress` rewrites one line on stderr
(``[####----] 5/9 export: running``).  While a stage works item by item
(export's meshes, :mod:`softdesign.pipeline.item_progress`), the bar of
:class:`ItemBar` takes that line over, stage count kept
(``[5/9] export: mesh q = 0.5 done ━━━━━━━━━━╸━━━━━ 3/5 0:00:04``), counting
each mesh as it comes back to this process, from forked workers or not; when
the last one is in, the bar goes and the stage line follows on the same line.
A log, a pipe or ``--json`` output gets nothing from here.

The bar is redrawn at each mesh rather than by rich's refresh thread: the
workers are forked while it is up, and a fork must not copy a thread that may
hold stderr's lock.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from softdesign.cli.common import StageProgress


class ItemBar:
    """Listener (:data:`~softdesign.pipeline.item_progress.ItemProgress`) drawing a transient rich bar per stage.

    Parameters
    ----------
    stages : the build's stage line; its last ``[done/total]`` prefixes the bar
    console : a rich Console on the same terminal (tests); default: stderr
    """

    def __init__(self, stages: StageProgress, console: Any = None) -> None:
        self.stages = stages
        self.console = console
        self.bar: Any = None
        self.task: Any = None
        self.prefix = ""

    def stage_line(self, line: str) -> None:
        """Pass a stage line on to the stage progress, keeping its ``[done/total]`` for the bar."""
        counts, _, _ = line.partition("] ")
        self.prefix = counts + "] " if counts.startswith("[") else ""
        self.stages(line)

    def __call__(self, stage: str, done: int, total: int, label: str) -> None:
        if done == 0:
            self._start(stage, total)
        elif self.bar is not None:
            self.bar.update(self.task, completed=done, description=f"{self.prefix}{stage}: {label} done", refresh=True)
            if done >= total:
                self.stop()

    def _start(self, stage: str, total: int) -> None:
        from rich.console import Console
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

        self.stop()
        self.stages.stream.write("\r\x1b[2K")  # the stage line gives its place to the bar
        self.stages.stream.flush()
        columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn())
        self.bar = Progress(*columns, console=self.console or Console(stderr=True), transient=True,
                            auto_refresh=False, redirect_stdout=False, redirect_stderr=False)
        self.task = self.bar.add_task(f"{self.prefix}{stage}: {total} to make", total=total)
        self.bar.start()

    def stop(self) -> None:
        """Take the bar away (at its last item, and when the build ends early)."""
        if self.bar is not None:
            self.bar.stop()
            self.bar = None


@contextmanager
def build_progress(enabled: bool = True, stream: Any = None, console: Any = None) -> Iterator[tuple[Any, Any]]:
    """The stage-line callback and the per-item listener (None when silent) for one build.

    Parameters
    ----------
    enabled : False for ``--json``; the bar is drawn only when, besides, ``stream`` is a terminal
    stream : where the stage lines go; default: stderr
    console : a rich Console for the bar (tests); default: stderr
    """
    stages = StageProgress(stream if stream is not None else sys.stderr)
    if not (enabled and stages.tty):
        yield stages, None
        return
    bar = ItemBar(stages, console)
    try:
        yield bar.stage_line, bar
    finally:
        bar.stop()
