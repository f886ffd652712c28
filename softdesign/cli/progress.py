"""A progress bar on stderr for long work made of named parts (the report's figures), with rich.

Shown only on a terminal: a log, a pipe or ``--json`` output gets nothing from
here (the command's own summary line says what was done).  The bar is
transient: it disappears when the work ends, leaving the terminal as before.
It is redrawn at each part rather than by rich's refresh thread: ``report --jobs``
forks its workers while the bar is up, and a fork must not copy a thread that
may hold stderr's lock.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

#: Called after each part with its name and the seconds it took.
Tick = Callable[[str, float], None]


@contextmanager
def part_progress(label: str, enabled: bool | None = None, console: Any = None) -> Iterator[Tick | None]:
    """A rich progress bar for parts done one after another; yields the per-part callback, or None when silent.

    Parameters
    ----------
    label : what the work is (``report``)
    enabled : show the bar; default: when stderr is a terminal
    console : a rich Console to draw on (tests); default: stderr
    """
    if enabled is None:
        enabled = sys.stderr.isatty()
    if not enabled:
        yield None
        return
    from rich.console import Console
    from rich.progress import BarColumn, Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

    columns = (SpinnerColumn(), TextColumn("{task.description}"), BarColumn(), TextColumn("{task.completed} done"),
               TimeElapsedColumn())
    with Progress(*columns, console=console or Console(stderr=True), transient=True,
                  auto_refresh=False, redirect_stdout=False, redirect_stderr=False) as bar:
        task = bar.add_task(label, total=None)

        def tick(name: str, seconds: float) -> None:
            bar.update(task, advance=1, description=f"{label}: {name} ({seconds:.1f} s)", refresh=True)

        yield tick
