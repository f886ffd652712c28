"""How the fit runs independent pieces: a :data:`Mapper`, serial here, perhaps on other processes in a build.

The fitting code never starts processes itself: the fit stage passes the
build's :func:`softdesign.pipeline.parallel.map_items`, and every other caller
(tests, the report) gets :func:`serial_map`.  Either way the results come back
in the order of the items, so the figures do not depend on the mapper.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from softdesign.fitting import bspline_basis as bb
from softdesign.types import FloatArray
from softdesign.types import Mapper as Mapper  # the fitting modules' name for it (softdesign.types')


def serial_map(task: Callable[[Any], Any], items: Sequence[Any]) -> list[Any]:
    """The :data:`Mapper` that runs every item here, in turn."""
    return [task(item) for item in items]


def mapped(mapper: Mapper, task: Callable[[Any], Any], items: Sequence[Any]) -> list[Any]:
    """``mapper(task, items)`` when there are several items; a single one (or none) runs here, without a pool."""
    return mapper(task, items) if len(items) > 1 else serial_map(task, items)


def mapped_blocks(values: Callable[[slice], FloatArray], count: int, size: int, mapper: Mapper) -> FloatArray:
    """``values(rows)`` over ``count`` items in blocks of ``size`` (slices, in order), joined; a single block runs
    here, more on ``mapper``.  The same numbers as one call over every item when each item's value is its own."""
    blocks = bb.chunks(count, size)
    if len(blocks) == 1:
        return values(slice(0, count))
    return np.concatenate(mapper(values, blocks))


Job = tuple[Callable[[Any], Any], Sequence[Any]]


def map_together(mapper: Mapper, *jobs: Job) -> list[list[Any]]:
    """Independent maps ``(task, items)`` as one call of ``mapper``: each one's results, in its items' order.

    The same results as a call each (every item is its own); on a pool of processes the later maps' items keep
    a worker busy while the earlier ones' last items run, where a few long items alone leave one idle.
    """
    tagged = [(j, item) for j, (_, items) in enumerate(jobs) for item in items]
    results = mapper(lambda pair: jobs[pair[0]][0](pair[1]), tagged)
    out, start = [], 0
    for _, items in jobs:
        out.append(list(results[start:start + len(items)]))
        start += len(items)
    return out
