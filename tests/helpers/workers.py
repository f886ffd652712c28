"""A mapper for tests of work handed to the build's worker processes."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from softdesign.pipeline.parallel import jobs_for_build, map_items


def two_worker_mapper() -> tuple[Callable[[Callable[[Any], Any], Sequence[Any]], list[Any]], list[int]]:
    """A mapper running its items on two forked workers (:func:`map_items`), and the item count of each call."""
    calls: list[int] = []

    def mapper(task: Callable[[Any], Any], items: Sequence[Any]) -> list[Any]:
        calls.append(len(items))
        with jobs_for_build(2):
            return map_items(task, items)

    return mapper, calls
