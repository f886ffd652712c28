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
