"""Progress of a stage's work item by item (export's meshes), told to a listener: the command line draws it.

The pipeline prints nothing.  A stage that maps its items with
:func:`~softdesign.pipeline.parallel.map_items` passes it the ``on_result``
hook :func:`item_counter` returns; the hook runs in this process as each
result arrives (forked workers or not, in the order of the items) and tells
the listener the command set with :func:`items_told_to`: ``(stage, done,
total, label)``, first with ``done`` 0 before any item, then once per item.
Nothing listens by default, and then the hook is None: the stage's work and
outputs are the same either way.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any, TypeVar

T = TypeVar("T")

#: ``(stage, done, total, label)``: ``done`` of ``total`` items finished, ``label`` names the last one ("" at 0).
ItemProgress = Callable[[str, int, int, str], None]

_LISTENER: ContextVar[ItemProgress | None] = ContextVar("softdesign_item_progress", default=None)


@contextmanager
def items_told_to(listener: ItemProgress | None) -> Iterator[None]:
    """Tell ``listener`` (None: nobody) of every stage's per-item progress inside the block."""
    token = _LISTENER.set(listener)
    try:
        yield
    finally:
        _LISTENER.reset(token)


def item_counter(stage: str, items: Sequence[T], label: Callable[[T], str] = str) -> Callable[[T, Any], None] | None:
    """The ``on_result`` hook counting ``items`` of ``stage`` for the current listener, or None when none listens.

    Tells the listener ``done`` 0 of ``len(items)`` now; each call of the hook tells one more, with the item's
    ``label``.
    """
    listener = _LISTENER.get()
    if listener is None:
        return None
    total = len(items)
    done = 0
    listener(stage, done, total, "")

    def on_result(item: T, result: Any) -> None:
        nonlocal done
        done += 1
        listener(stage, done, total, label(item))

    return on_result


def step_counter(stage: str, steps: Sequence[str]) -> Callable[[str], None]:
    """``step(name)``: tell the current listener that step ``name`` of ``stage``'s ``steps`` is done (one more of
    ``len(steps)``, in any order); a no-op when nobody listens.  For a stage made of a few long steps rather
    than many items (a big tree's ingest and fit, issue 43)."""
    hook = item_counter(stage, list(steps))
    if hook is None:
        return lambda name: None
    return lambda name: hook(name, None)
