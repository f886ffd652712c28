"""Per-item progress (issue 17): the listener hears every item once, in the parent, forked workers or not."""

from __future__ import annotations

import os

import pytest

from softdesign.pipeline.item_progress import item_counter, items_told_to
from softdesign.pipeline.parallel import jobs_for_build, map_items


def _pid_and_square(q: float) -> tuple[int, float]:
    return os.getpid(), q * q


def test_nobody_listening_gives_no_hook():
    assert item_counter("export", [0.0, 1.0]) is None
    with items_told_to(None):
        assert item_counter("export", [0.0, 1.0]) is None


@pytest.mark.parametrize("jobs", [1, 2])
def test_every_item_is_told_once_in_this_process_after_a_zero(jobs):
    heard: list[tuple[str, int, int, str, int]] = []
    q_values = [i / 4 for i in range(5)]
    with items_told_to(lambda *event: heard.append((*event, os.getpid()))), jobs_for_build(jobs):
        results = map_items(_pid_and_square, q_values, on_result=item_counter("export", q_values, lambda q: f"q={q}"))
    assert [square for _, square in results] == [q * q for q in q_values]
    if jobs == 2:
        assert {pid for pid, _ in results} - {os.getpid()}, "no item ran in a worker process"
    assert heard == [("export", 0, 5, "", os.getpid())] + [
        ("export", i + 1, 5, f"q={q}", os.getpid()) for i, q in enumerate(q_values)]


def test_the_listener_is_gone_after_the_block():
    with items_told_to(lambda *event: None):
        assert item_counter("export", [1.0]) is not None
    assert item_counter("export", [1.0]) is None


def test_a_stage_made_of_long_steps_tells_each_step_and_the_fit_tells_all_of_its_own():
    # issue 43, item 7: a big tree's ingest and fit take seconds per step; a terminal is told each one
    import numpy as np

    from softdesign.fitting.selection import NetworkContext
    from softdesign.fitting.wall_fit import FIT_STEPS, WallFitOptions, fit_wall
    from softdesign.pipeline.item_progress import step_counter
    from tests.helpers.analytic import Arc
    from tests.helpers.vessels import torus_section

    heard: list[tuple[str, int, int, str]] = []
    step_counter("ingest", ("a", "b"))("a")  # nobody listens: nothing happens
    with items_told_to(lambda *event: heard.append(event)):
        step = step_counter("ingest", ("surface", "end planes"))
        step("surface")
        step("end planes")
    assert heard == [("ingest", 0, 2, ""), ("ingest", 1, 2, "surface"), ("ingest", 2, 2, "end planes")]
    told: list[str] = []
    vertices, _ = torus_section(bend=20.0, radius=3.0, angle=1.5, edge=0.5)
    curve = Arc(20.0, 1.5)
    fit_wall(curve, vertices, NetworkContext(curve.points(np.linspace(0, 1, 50))), WallFitOptions(progress=told.append),
             np.random.default_rng(0))
    assert tuple(told) == FIT_STEPS
