"""pipelines/bench_volume.py's pieces: each case's volume mesh request, and a measured row of the table with its
verdict against issue 32's 10 s (the aorta, the smallest case; no timing asserted but its verdict's arithmetic)."""

from __future__ import annotations

import importlib.util
import sys

import pytest

from tests.helpers.paths import REPO

pytestmark = pytest.mark.slow


def _module():
    spec = importlib.util.spec_from_file_location("softdesign_bench_volume", REPO / "pipelines" / "bench_volume.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def test_cases_ask_for_the_swept_volume_mesh():
    bench = _module()
    solid, hollow, chambered = (bench.case_data(name) for name in ("solid", "hollow", "chambered"))
    assert solid["export"]["volume_mesh"] == {"q": [0.0, 0.5, 1.0]} and "wall_mm" not in solid["export"]
    assert hollow["export"]["wall_mm"] == 1.0 and hollow["export"]["port_mm"] == 1.2
    assert chambered["actuation"] == {"supply": "per_chamber"} and chambered["export"]["volume_mesh"] == {}
    # as configs/actuator-per-chamber.yaml
    assert "mould" not in chambered["export"]


def test_a_measured_row_and_its_verdict(tmp_path, aorta_dir):
    bench = _module()
    data = bench.case_data("aorta")
    assert data is not None
    row = bench.measure("aorta", data, tmp_path, jobs=1)
    assert row["tets"] > 0 and row["q"] == [0.0, 0.5, 1.0] and row["cpu_s"] > 0 and row["megabytes"] > 0
    assert row["morph"]["stretch_max"]["value"] > 1.0 and row["material"]["name"] == "ecoflex-00-30"
    line = bench.row(row)
    assert line.startswith("aorta") and ("met" if row["cpu_s"] <= bench.TARGET_S else "MISSED") in line
    assert bench.row({**row, "cpu_s": bench.TARGET_S + 1}).count("MISSED") == 1
