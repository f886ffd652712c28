"""The benchmark script's pieces on tiny inputs: tables, slopes, verdicts, the synthetic vessel, one worker run.

No timing is asserted anywhere: figures are fed in by hand or only checked for shape.
"""

from __future__ import annotations

import importlib.util
import sys

import numpy as np
import pytest

from softdesign.samples.surfaces import grid_counts, synthetic_surface
from softdesign.samples.synthetic_vessel import SyntheticShape, make_synthetic_vessel
from tests.helpers.paths import REPO
from tests.helpers.shared_builds import one_core_cli

BENCH_FILE = REPO / "pipelines" / "bench.py"


@pytest.fixture(scope="module")
def bench():
    spec = importlib.util.spec_from_file_location("softdesign_bench", BENCH_FILE)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up by name
    spec.loader.exec_module(module)
    return module


def fake_result(bench, triangles: int, frames: int, per_stage: dict[str, float]) -> dict:
    wall = {name: per_stage.get(name, 0.1) for name in bench.STAGE_NAMES}
    stages = {name: {"wall_s": s, "cpu_s": 0.9 * s, "peak_mib": 300.0} for name, s in wall.items()}
    return {
        "label": f"fake {triangles} {frames}",
        "import_s": 1.0,
        "baseline_mib": 250.0,
        "jobs": 2,
        "worker_peak_mib": 200.0,
        "stages": stages,
        "total": {"wall_s": sum(wall.values()), "cpu_s": 0.9 * sum(wall.values()), "peak_mib": 310.0},
        "input": {"triangles": triangles, "vertices": triangles // 2},
        "output": {"meshes": frames, "triangles": 1000 * frames},
        "floor": {"read_s": 0.5, "write_s": 0.25},
        "size": {"triangles": triangles, "frames": frames},
    }


def test_stage_table_has_every_stage_the_total_and_the_ratio_to_the_floor(bench):
    result = fake_result(bench, 1000, 3, {"ingest": 1.0, "export": 0.5})
    lines = bench.stage_table(result)
    rows = {line.split()[0]: line.split() for line in lines[3:-1]}
    assert list(rows) == [*bench.STAGE_NAMES, "total"]
    assert rows["ingest"][-3:-1] == ["0.500", "2.0x"]  # 1.0 s against a 0.5 s read
    assert rows["export"][-3:-1] == ["0.250", "2.0x"]
    assert rows["fit"][-3:-1] == ["-", "-"]  # no I/O floor for a stage that reads and writes nothing required
    assert rows["total"][-2] == rows["total"][-1] == f"{result['total']['wall_s'] / 0.75:.1f}x"
    # every stage against the whole build's floor (0.5 s read + 0.25 s writes)
    assert rows["ingest"][-1] == f"{1.0 / 0.75:.1f}x" and rows["export"][-1] == f"{0.5 / 0.75:.1f}x"
    assert "shares add up to the total's ratio" in lines[-1]
    # each stage's share of the build's wall time (issue 46)
    assert rows["ingest"][3] == f"{100 * 1.0 / result['total']['wall_s']:.0f}%" and rows["total"][3] == "100%"
    assert "--jobs 2, largest worker's peak 200 MiB" in lines[1] and "at most 710 MiB" in lines[1]  # 310 + 2 x 200


def test_linear_fit_recovers_a_line(bench):
    slope, intercept = bench.linear_fit([0.25, 0.5, 1.0], [2.0 + 4.0 * x for x in (0.25, 0.5, 1.0)])
    assert slope == pytest.approx(4.0)
    assert intercept == pytest.approx(2.0)


@pytest.mark.parametrize(("power", "linear"), [(1.0, True), (2.0, False)])
def test_growth_with_triangles_is_judged_on_step_slopes(bench, power, linear):
    sizes = (250_000, 500_000, 1_000_000)
    runs = [fake_result(bench, t, 41, {"fit": 3.0 + 40.0 * (t / 1e6) ** power}) for t in sizes]
    lines, verdict = bench.growth_lines(runs, "triangles", "million triangles", 1e6)
    assert verdict is linear
    assert any(line.split()[0] == "total" for line in lines)


def test_growth_with_two_frame_counts_compares_ratios(bench):
    proportional = [fake_result(bench, 1000, f, {"export": 0.2 * f}) for f in (11, 41)]
    faster = [fake_result(bench, 1000, f, {"export": 0.01 * f * f}) for f in (11, 41)]
    assert bench.growth_lines(proportional, "frames", "frame", 1.0)[1] is True
    assert bench.growth_lines(faster, "frames", "frame", 1.0)[1] is False
    assert bench.growth_lines(proportional[:1], "frames", "frame", 1.0) == ([], None)


def test_scaling_table_and_targets(bench):
    runs = [fake_result(bench, t, 41, {}) for t in (1000, 2000)]
    assert len(bench.scaling_table(runs)) == 1 + len(runs)
    targets = bench.target_lines(runs[-1], True, None)
    assert "met" in targets[0] and "met" in targets[1]  # 0.6 s against a 0.75 s floor; 310 MiB
    assert targets[3].endswith("not measured")


def test_synthetic_surface_reaches_the_triangle_count_and_is_closed():
    vessel = make_synthetic_vessel(SyntheticShape(axial_length_mm=40.0))
    vertices, faces = synthetic_surface(vessel, 5000)
    rings, angles = grid_counts(vessel.length, float(vessel.radius.mean()), 5000)
    assert len(faces) == 2 * rings * angles >= 5000
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    _, uses = np.unique(edges, axis=0, return_counts=True)
    assert np.all(uses == 2)  # every edge shared by exactly two triangles: closed, no seam duplicates
    assert vertices.shape == (rings * angles + 2, 3)


@pytest.mark.slow
def test_worker_measures_a_tiny_synthetic_build(bench, tmp_path):
    case = bench.synthetic_case(tmp_path / "inputs", 20_000, 2)  # ~3 wall points per spline coefficient
    result = bench.run_worker(case.case_file, tmp_path / "run", None)
    assert set(result["stages"]) == set(bench.STAGE_NAMES)
    assert result["output"]["meshes"] == 2
    assert result["input"]["triangles"] >= 20_000
    assert all(row["peak_mib"] > 0 for row in result["stages"].values())
    result.update(label="tiny", size={"triangles": 20_000, "frames": 2})
    assert len(bench.stage_table(result)) == 3 + len(bench.STAGE_NAMES) + 2  # header, stages, total, note


def test_startup_lines_judge_each_median_against_its_target(bench):
    lines = bench.startup_lines({"help_s": 0.2, "validate_s": 0.9})
    help_line = next(line for line in lines if "--help" in line)
    validate_line = next(line for line in lines if "validate" in line)
    assert "0.20 s" in help_line and help_line.rstrip().endswith("met")
    assert "0.90 s" in validate_line and "MISSED" in validate_line


def test_a_failing_startup_command_stops_the_benchmark_with_its_error(bench):
    with pytest.raises(RuntimeError, match="exited 3"):
        bench.median_run_s([sys.executable, "-c", "import sys; sys.exit(3)"], repeats=2)


def test_the_startup_command_is_the_softdesign_entry_point(bench):
    import subprocess

    done = subprocess.run([*bench.softdesign_command(), "--help"], capture_output=True, text=True, cwd=REPO)
    assert done.returncode == 0 and "Usage" in done.stdout


def test_the_report_line_judges_the_ratio_against_its_cases_target(bench):
    figures = {"build_s": 2.0, "build_cpu_s": 2.5, "report_s": 2.5, "report_cpu_s": 4.0}
    judged = bench.report_line("large", figures, bench.TARGET_REPORT_RATIO_LARGE)
    assert "build  2.00 s" in judged and "report  2.50 s" in judged and "report/build 1.25" in judged
    assert judged.rstrip().endswith("MISSED")
    assert bench.report_line("sample", figures, bench.TARGET_REPORT_RATIO_DEMO).rstrip().endswith("met")
    assert bench.report_line("sample", {**figures, "report_s": 3.5}, 1.5).rstrip().endswith("MISSED")
    shown = bench.report_line("aorta", figures, None)
    assert "report/build 1.25" in shown and "MISSED" not in shown and "target" not in shown


@pytest.mark.slow
def test_report_figures_time_a_forced_build_and_its_report(bench, tmp_path, monkeypatch):
    # the figures' plumbing is the point, not the pool: the build and the report run on one core (their default
    # --jobs is then 1; the pool forked beside the other xdist worker cost 2-3 s of CPU), the entry point is the
    # startup test's
    monkeypatch.setattr(bench, "softdesign_command", one_core_cli)
    case = bench.synthetic_case(tmp_path / "inputs", 20_000, 2)
    figures = bench.report_figures(case.case_file, tmp_path / "run", repeats=1)
    assert figures["repeats"] == 1
    assert all(figures[key] > 0 for key in ("build_s", "build_cpu_s", "report_s", "report_cpu_s"))
    assert (tmp_path / "run" / "report" / "index.html").is_file()


def test_the_tree_lines_judge_ingest_and_fit_against_issue_43s_targets(bench):
    quick = fake_result(bench, 1_000_000, 0, {"ingest": 6.0, "fit": 18.0})
    slow = fake_result(bench, 1_000_000, 0, {"ingest": 16.0, "fit": 31.0})
    fast_lines, slow_lines = bench.tree_lines(quick), bench.tree_lines(slow)
    assert [line.split()[-1] for line in fast_lines[-2:]] == ["met", "met"]
    assert [line.split()[-1] for line in slow_lines[-2:]] == ["MISSED", "MISSED"]


def test_the_benchmark_tree_has_its_tracts_its_paths_and_one_closed_wall():
    import trimesh

    from softdesign.samples.tree_vessel import TreeShape, make_tree_vessel, tree_surface

    shape = TreeShape(depth=3)
    tree = make_tree_vessel(shape)
    assert len(tree.segments) == 2 ** (shape.depth + 1) - 1 and len(tree.paths) == 2 ** shape.depth
    for leaf in range(len(tree.paths)):
        points, radius = tree.path_points(leaf)
        step = np.diff(points, axis=0)
        unit = step / np.linalg.norm(step, axis=1, keepdims=True)
        # tangent-continuous through every junction: no turn between steps beyond a Bezier's own sampling
        assert np.min(np.einsum("ij,ij->i", unit[:-1], unit[1:])) > np.cos(np.radians(10.0))
        assert radius[0] == shape.root_radius_mm and np.all(np.diff(radius) <= 0)
    vertices, faces = tree_surface(tree, 60_000)
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    assert mesh.is_watertight and mesh.volume > 0 and 30_000 < len(faces) < 120_000
