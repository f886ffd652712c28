"""pipelines/bench_centerline.py's pieces on a small tube: the worker's figures and the table (no timing asserted)."""

from __future__ import annotations

import importlib.util
import sys

from softdesign.io.formats import write_mesh
from tests.helpers.paths import REPO
from tests.helpers.vessels import straight_tube


def _module():
    spec = importlib.util.spec_from_file_location("softdesign_bench_centerline", REPO / "pipelines" /
                                                  "bench_centerline.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def test_worker_figures_and_table(tmp_path):
    bench = _module()
    vertices, faces = straight_tube(radius=3.0, length=30.0, edge=0.8)
    surface = write_mesh(tmp_path / "tube.stl", vertices, faces)
    figures = bench.run_worker(surface)
    assert figures["triangles"] == len(faces) and figures["paths"] == 1 and figures["endpoints"] == "openings"
    assert figures["wall_s"] > 0 and figures["cpu_s"] > 0 and figures["peak_mib"] > 0
    lines = bench.table([("tube", figures)])
    assert len(lines) == 3 and f"{len(faces):,}" in lines[2]
