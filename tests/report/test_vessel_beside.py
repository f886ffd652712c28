"""The report finds the vessel's display once, on a worker, while it imports the drawing libraries; the figures'
workers inherit it (the 3D view and the surface figure each decimated it again before)."""

from __future__ import annotations

import numpy as np
import pytest

import softdesign.report.display_mesh as display_mesh
from softdesign.report.build_folder import load_build
from softdesign.report.drawing_run import vessel_beside_imports
from tests.helpers.shared_builds import demo_build

#: Both read the README's demo build with its report (a whole build in a child, made once per run): slow, as the
#: other tests of that build are (make test-fast had made it for these two alone).
pytestmark = pytest.mark.slow


def _counted(monkeypatch) -> list[int]:
    calls: list[int] = []
    original = display_mesh.decimated_vessel

    def counted(*args, **kwargs):
        calls.append(1)
        return original(*args, **kwargs)

    monkeypatch.setattr(display_mesh, "decimated_vessel", counted)
    return calls


def test_the_display_is_found_on_a_worker_and_kept_with_the_same_numbers(tmp_path_factory, monkeypatch):
    build = demo_build(tmp_path_factory)
    expected = load_build(build).vessel_display  # found here, the figures' way
    calls = _counted(monkeypatch)
    data = load_build(build)
    vessel_beside_imports(data, jobs=2)
    assert calls == []  # found by the worker (its own copy of the counter), not here
    assert "vessel_display" in data.__dict__
    kept = data.vessel_display
    assert calls == []  # kept, not found again
    np.testing.assert_array_equal(kept[0], expected[0])
    np.testing.assert_array_equal(kept[1], expected[1])
    assert kept[2] == expected[2]


def test_one_job_keeps_the_display_to_the_figures_and_a_failure_is_left_to_them(tmp_path_factory, monkeypatch):
    build = demo_build(tmp_path_factory)
    data = load_build(build)
    vessel_beside_imports(data, jobs=1)
    assert "vessel_display" not in data.__dict__  # found by the first figure that shows it, as before

    def fails(*args, **kwargs):
        raise RuntimeError("decimation failed")

    monkeypatch.setattr(display_mesh, "decimated_vessel", fails)
    data = load_build(build)
    vessel_beside_imports(data, jobs=2)
    assert "vessel_display" not in data.__dict__  # the figure asks again, and fails there as before
