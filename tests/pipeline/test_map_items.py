"""map_items: any items on forked workers, results and their callbacks in the order of the items."""

from __future__ import annotations

import os

from softdesign.pipeline.parallel import jobs_for_build, map_items


def _square_and_pid(item: int) -> tuple[int, int]:
    return item * item, os.getpid()


def test_results_come_back_in_order_from_other_processes_and_each_is_announced():
    items = list(range(7))
    arrived: list[int] = []
    with jobs_for_build(2):
        results = map_items(_square_and_pid, items, on_result=lambda item, _: arrived.append(item))
    assert [value for value, _ in results] == [i * i for i in items]
    assert arrived == items
    assert {pid for _, pid in results} - {os.getpid()}  # drawn by forked workers, not here


def test_one_job_runs_here_and_still_announces_each_result():
    arrived: list[str] = []
    results = map_items(lambda name: (name.upper(), os.getpid()), ["a", "b"],
                        on_result=lambda item, _: arrived.append(item))
    assert results == [("A", os.getpid()), ("B", os.getpid())] and arrived == ["a", "b"]


def test_beside_runs_here_while_a_single_item_runs_on_a_worker(tmp_path):
    """map_items_beside: the items are handed to the workers first, then ``beside`` runs here; one item is enough
    for a worker (the point is to overlap it with this process's own work).  ``beside`` waits until the item has
    started: run one after the other, it would wait in vain."""
    import time

    from softdesign.pipeline.parallel import map_items_beside

    started = tmp_path / "started"
    seen: list[bool] = []

    def item_task(item: int) -> tuple[int, int]:
        started.write_text("yes")
        return item + 1, os.getpid()

    def here() -> None:
        deadline = time.monotonic() + 30.0
        while not started.exists() and time.monotonic() < deadline:
            time.sleep(0.01)
        seen.append(started.exists())

    with jobs_for_build(2):
        ((value, pid),) = map_items_beside(item_task, [41], here)
    assert value == 42 and pid != os.getpid() and seen == [True]


def test_beside_with_one_job_runs_first_then_the_items_here():
    from softdesign.pipeline.parallel import map_items_beside

    order: list[str] = []
    results = map_items_beside(lambda item: (order.append(f"item {item}"), os.getpid())[1], [1, 2],
                               lambda: order.append("beside"))
    assert results == [os.getpid()] * 2 and order == ["beside", "item 1", "item 2"]


def test_an_error_beside_stops_the_workers_and_goes_on_and_an_items_error_comes_after_beside():
    import pytest

    from softdesign.pipeline.parallel import map_items_beside

    def fails() -> None:
        raise KeyError("beside")

    with jobs_for_build(2), pytest.raises(KeyError, match="beside"):
        map_items_beside(_square_and_pid, [1, 2], fails)
    ran: list[str] = []

    def broken(item: int) -> int:
        raise ValueError(f"item {item}")

    with jobs_for_build(2), pytest.raises(ValueError, match="item 1"):
        map_items_beside(broken, [1], lambda: ran.append("beside"))
    assert ran == ["beside"]
