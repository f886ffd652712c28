"""`simulate: {enabled: true}` in a build: the simulate stage's pressures land in actuation.csv labelled as model
estimates, a forward solve at those pressures gives back the arc error the table reports, the stage is cached, the
report draws it, and without it actuation.csv keeps its columns and rows.

Kept small so that it runs in seconds: the demo's first section only, q = 1 only, a coarse mesh (4 mm, layers
10 mm, 8 nodes around: 450 corner nodes) and one search evaluation (``max_solves: 1``: the pressures are the
search's start, the linear answer scaled into its first step of 25 % of ``max_pressure_kpa``).  It checks the
plumbing and the honesty of the reported error, not how close the inverse gets (tests/mechanics and issue 33's
note do that).
"""

from __future__ import annotations

import csv
import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml

from softdesign.config import load_case
from softdesign.pipeline.api import build_through
from softdesign.pipeline.simulate_estimates import ESTIMATE_COLUMNS
from softdesign.pipeline.stages.actuation import COLUMNS
from tests.helpers.paths import REPO

pytestmark = pytest.mark.slow

SIMULATE = {"enabled": True, "q": [1], "sections": [1], "size_mm": 4.0, "layer_mm": 10.0, "angular_count": 8,
            "max_solves": 1, "max_pressure_kpa": 100.0}
#: A fresh forward solve (load steps from zero) and the search's (continued from its last equilibrium) stop at
#: residuals near 1e-8 mN: their arcs agree far below this, mm.
ERROR_TOL_MM = 1e-4
#: The fresh solve's load steps, and the residual those before the last stop at (NewtonSettings.path_rtol).
FRESH_LOAD_STEPS, PATH_RTOL = 4, 1e-4


def case_file(folder: Path, simulate: dict | None) -> Path:
    case = yaml.safe_load((REPO / "configs" / "actuator-per-chamber.yaml").read_text())
    for key in ("centerline", "surface"):
        case["final"][key] = str((REPO / "configs" / case["final"][key]).resolve())
    case["export"] = {"q": [0, 1], "formats": ["stl"]}
    if simulate is not None:
        case["simulate"] = simulate
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "case.yaml"
    path.write_text(yaml.safe_dump(case, sort_keys=False))
    return path


def rows(path: Path) -> tuple[list[str], list[dict[str, str]]]:
    with path.open(newline="") as handle:
        reader = csv.DictReader(handle)
        return list(reader.fieldnames or []), list(reader)


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    folder = tmp_path_factory.mktemp("simulate-stage")
    case = case_file(folder / "on", SIMULATE)
    build_through(case, folder / "on" / "build", "actuation")
    return case, folder / "on" / "build"


def test_the_pressures_are_in_actuation_csv_labelled_as_model_estimates(built: tuple[Path, Path]) -> None:
    _, build_dir = built
    header, table = rows(build_dir / "actuation.csv")
    assert tuple(header) == COLUMNS + ESTIMATE_COLUMNS
    solved = [r for r in table if float(r["q"]) == 1.0 and r["section"] == "1"]
    assert [r["chamber"] for r in solved] == ["1", "2", "3"]
    mesh = json.loads((build_dir / "simulate" / "summary.json").read_text())["solves"][0]["mesh"]
    assert mesh["size_mm"] == 4 and mesh["nodes"] > 0
    # one evaluation: the search's start, the linear answer scaled into its first step (25 % of the 100 kPa bound):
    # q = 1 is far beyond the linear answer's reach, so the largest pressure is that step's
    assert max(float(r["fe_pressure_kpa"]) for r in solved) == pytest.approx(25.0)
    for r in solved:
        assert float(r["fe_pressure_kpa"]) >= 0.0
        assert "model estimate" in r["fe_pressure_source"] and "ecoflex-00-30" in r["fe_pressure_source"]
        assert f"section mesh {mesh['nodes']} nodes {mesh['tets']} tets, size 4 mm" in r["fe_pressure_source"]
    others = [r for r in table if r not in solved]
    assert others and all(r[c] == "" for r in others for c in ESTIMATE_COLUMNS)


def test_a_forward_solve_at_the_tabled_pressures_gives_the_tabled_arc_error(built: tuple[Path, Path]) -> None:
    from softdesign.mechanics.inverse import arc_vector, weighted_error
    from softdesign.mechanics.newton import NewtonSettings, solve_pressures
    from softdesign.mechanics.section import measure_section, prepare_section
    from softdesign.pipeline.simulate_run import SimulateOptions, section_mesh_of, thread_of
    from softdesign.pipeline.stages.volume_sweep import material_of

    case_path, build_dir = built
    _, table = rows(build_dir / "actuation.csv")
    solved = [r for r in table if float(r["q"]) == 1.0 and r["section"] == "1"]
    outcome = build_through(case_path, build_dir, "fit")
    case = load_case(case_path)
    mesh = section_mesh_of(case, outcome.results["kinematics"], outcome.results["fit"], 0, 4.0, 8, 10.0)
    defaults = SimulateOptions(0, (0.0, 0.0, 0.0), None)
    # the stage's model (the case's hoop thread), load-stepped from zero: with the kevlar thread at 10, 10, 10 kPa on
    # this coarse mesh, the command's volume-controlled path (simulate_section) stops at 0.53 kPa (issue 42, open).
    # The equilibrium does not depend on the path to it: four load steps, those before the last to PATH_RTOL, reach
    # it in 21 factorizations (6.5 s of CPU) where the command's two, whose first fails and is halved, took 37
    # (11.4 s); the arc error the same to 1e-13 mm
    prepared = prepare_section(mesh, material_of(case).law, thread_of(case))
    pressures = np.array([float(r["fe_pressure_kpa"]) for r in solved])
    u, record = solve_pressures(prepared.problem, pressures, NewtonSettings(
        load_steps=FRESH_LOAD_STEPS, max_iterations=defaults.max_iterations, path_rtol=PATH_RTOL))
    result = measure_section(prepared, u, pressures, record)
    target = arc_vector(*(float(solved[0][k]) for k in ("arc_kappa", "arc_phi", "arc_length_mm")))
    error = weighted_error(arc_vector(result.kappa, result.phi, result.length), target)
    assert math.hypot(*error) == pytest.approx(float(solved[0]["fe_pressure_arc_error_mm"]), abs=ERROR_TOL_MM)


def test_the_stage_is_cached_and_the_report_draws_it(built: tuple[Path, Path], tmp_path: Path) -> None:
    from softdesign.report.writer import ReportOptions, write_report

    case, build_dir = built
    runs = {r.name: r.status for r in build_through(case, build_dir, "actuation").runs}
    assert runs["simulate"] == "skipped" and runs["actuation"] == "skipped"
    # the report on a copy (the module's build is the other tests'); the simulate panel is the point, not the figures'
    # sampling: 3 morph frames, 3 views, 5 q of the kinematics plot
    copy = shutil.copytree(build_dir, tmp_path / "build")
    report = write_report(copy, ReportOptions(gif_frames=3, view_frames=3, q_samples=5))
    assert "simulate.png" in report.files
    page = report.page.read_text(encoding="utf-8")
    assert 'id="simulate"' in page and "Model estimates:" in page
    assert page.index("verdict") < page.index('id="simulate"')  # the page still opens on its verdict


def test_without_simulate_the_table_keeps_its_columns_and_rows(built: tuple[Path, Path], tmp_path: Path) -> None:
    _, build_dir = built
    plain = case_file(tmp_path / "on", {**SIMULATE, "enabled": False})  # the block kept but off: the same as none
    # on a copy of the simulated build: the stages before simulate are kept (the same case but for its simulate
    # block, as deep as the module's: the stage keys name the inputs relative to it), simulate and actuation rerun
    shutil.copytree(build_dir, tmp_path / "build")
    runs = {r.name: r.status for r in build_through(plain, tmp_path / "build", "actuation").runs}
    assert runs["fit"] == "skipped" and runs["simulate"] == runs["actuation"] == "ran"
    header, table = rows(tmp_path / "build" / "actuation.csv")
    assert tuple(header) == COLUMNS
    _, simulated = rows(build_dir / "actuation.csv")
    assert table == [{k: r[k] for k in COLUMNS} for r in simulated]  # q = 1 is on the dense grid: no new rows


def test_simulate_write_puts_one_sections_pressures_in_the_table(built: tuple[Path, Path], tmp_path: Path) -> None:
    from softdesign.pipeline.simulate_command import write_to_table
    from softdesign.pipeline.simulate_run import SimulateOptions

    case = case_file(tmp_path / "on", None)  # no simulate block: --write enables it for this run's section and q
    shutil.copytree(built[1], tmp_path / "build")  # the stages before simulate kept (as above): this section solved
    options = SimulateOptions(1, None, 0.5, size_mm=4.0, layer_mm=10.0, angular_count=8, max_pressure_kpa=50.0,
                              max_solves=1)
    solve = write_to_table(case, tmp_path / "build", options, lambda line: None)
    assert solve["section"] == 2 and solve["q"] == 0.5 and solve["written"].endswith("actuation.csv")
    _, table = rows(tmp_path / "build" / "actuation.csv")
    solved = [r for r in table if r["fe_pressure_kpa"]]
    assert [(float(r["q"]), r["section"]) for r in solved] == [(0.5, "2")] * 3  # 0-based in the options
    assert [float(r["fe_pressure_kpa"]) for r in solved] == pytest.approx(solve["pressures_kpa"], abs=0)
