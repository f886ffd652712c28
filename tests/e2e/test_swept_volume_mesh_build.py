"""`export.volume_mesh: {mesher: sweep}` end to end on a small hollow tube with a port: the files read back by
meshio with their named sets, the sets covering the boundary once, the chamber closed with its volume, the
same bytes on a second build."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import meshio
import numpy as np
import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.io.formats import read_mesh
from softdesign.io.volume_formats import read_volume_mesh
from softdesign.meshing.topology import mesh_topology
from softdesign.meshing.volume_mesh.tet_quality import boundary_faces, tet_volumes
from tests.e2e.test_volume_mesh_build import tube_case

runner = CliRunner()
pytestmark = pytest.mark.slow
RADIUS, LENGTH, WALL, PORT = 2.5, 14.0, 0.8, 1.2
#: the issue's bounds: the chamber's surface encloses its analytic volume within 1 %, the mesh the surface's 0.5 %
CHAMBER_RTOL, VOLUME_RTOL = 0.01, 0.005


def _swept(folder: Path) -> Path:
    return tube_case(folder, port_mm=PORT, mesher="sweep", size_mm=1.0, q=[0.0, 1.0])


def _keys(faces: np.ndarray) -> list[tuple[int, ...]]:
    return sorted(map(tuple, np.sort(faces, axis=1).tolist()))


def test_swept_mesh_of_a_hollow_tube(tmp_path):
    case = _swept(tmp_path)
    out = tmp_path / "build"
    result = runner.invoke(app, ["build", str(case), "--out", str(out), "--jobs", "1"])
    assert result.exit_code == 0, result.output
    # a line per part with its time in the build's log (its printed lines), none in the summary (issue 35)
    assert re.search(r"^  mesh plan: \d+\.\d\d s$", result.output, re.M), result.output
    assert re.search(r"^  q=0\.050\.\.0\.950 \(19 q\): \d+\.\d\d s$", result.output, re.M), result.output
    summary = json.loads((out / "volume_mesh" / "summary.json").read_text())
    assert "mesher_s" not in json.dumps(summary) and "seconds" not in json.dumps(summary)
    run = {row["name"]: row for row in json.loads((out / "run.log.json").read_text())["stages"]}
    assert re.fullmatch(r"mesh plan: \d+\.\d\d s", run["volume_mesh"]["log"][0]), run["volume_mesh"]
    assert len(run["volume_mesh"]["log"]) == 4  # the plan, q = 0 and 1, one batch of the morph's samples
    assert summary["deterministic"] and summary["surfaces"] == [
        "skin", "base", "tip", "chamber_wall", "chamber_cap", "port_wall", "port_inlet"]
    for row in summary["per_q"]:
        assert row["min_tet_volume_mm3"] > 0 and abs(row["volume_rel_error"]) <= VOLUME_RTOL
    volume = out / "meshes" / "volume"
    for q in ("0.000", "1.000"):
        points, tets = read_volume_mesh(volume / f"q_{q}.vtu")
        assert tet_volumes(points, tets).min() > 0
        vtu = meshio.read(volume / f"q_{q}.vtu")
        triangles = vtu.cells_dict["triangle"]
        surface = vtu.cell_data_dict["surface"]["triangle"]
        names = summary["surfaces"]
        solid = np.isin(surface, [names.index(n) for n in names if not n.endswith("_inlet")])
        # every boundary face of the tetrahedra is named exactly once, and nothing else is
        assert _keys(triangles[solid]) == _keys(boundary_faces(tets))
        base = np.flatnonzero(vtu.point_data["base_nodes"])
        np.testing.assert_array_equal(np.unique(triangles[surface == names.index("base")]), base[np.isin(
            base, triangles[surface == names.index("base")])])
        msh = meshio.read(volume / f"q_{q}.msh")
        assert set(msh.field_data) == {"body", *names, "base_nodes"}
        np.testing.assert_allclose(msh.points, points, rtol=0, atol=1e-9)
    chamber_v, chamber_f = read_mesh(volume / "chamber_q_0.000.stl")
    topology = mesh_topology(chamber_v, chamber_f)
    assert topology.watertight and topology.winding_consistent
    inner = RADIUS - WALL
    analytic = np.pi * inner**2 * (LENGTH - 2 * WALL) + np.pi * (PORT / 2) ** 2 * WALL
    np.testing.assert_allclose(topology.volume, analytic, rtol=CHAMBER_RTOL)

    again = tmp_path / "again"
    assert runner.invoke(app, ["build", str(case), "--out", str(again), "--jobs", "1"]).exit_code == 0
    for name in ("q_0.000.vtu", "q_0.000.msh", "q_1.000.vtu", "chamber_q_1.000.stl"):
        assert (volume / name).read_bytes() == (again / "meshes" / "volume" / name).read_bytes(), name
    assert (out / "volume_mesh" / "summary.json").read_bytes() == (again / "volume_mesh" / "summary.json").read_bytes()


def test_strict_fails_on_the_3d_stress_alone(tmp_path):
    """A bent tube of a material too weak for its stress but stretchy enough for the skin's limit: the skin's
    feasibility passes, the swept mesh's 3D stress does not, and --strict exits 1 saying so."""
    import yaml

    from tests.helpers.parts_cases import bent_solid_case

    case = bent_solid_case(tmp_path)
    data = yaml.safe_load(case.read_text())
    data["export"]["volume_mesh"] = {"q": [1.0], "size_mm": 1.5}
    data["material"] = {"custom": {"name": "weak", "shore": "00-10", "tensile_strength_mpa": 0.001,
                                   "elongation_at_break_pct": 800, "source": "a test",
                                   "law": {"kind": "neo-hookean", "c1_kpa": 15.0, "c2_kpa": 0.0, "c3_kpa": 0.0}},
                        "min_stretch": 0.01}
    case.write_text(yaml.safe_dump(data))
    out = tmp_path / "strict"
    result = runner.invoke(app, ["build", str(case), "--out", str(out), "--jobs", "1", "--strict"])
    assert result.exit_code == 1, result.output
    assert json.loads((out / "feasibility" / "summary.json").read_text())["feasible"] is True
    summary = json.loads((out / "volume_mesh" / "summary.json").read_text())
    assert summary["feasible"] is False and "3D stress" in summary["reasons"][0]
    manifest = json.loads((out / "manifest.json").read_text())
    assert "volume_mesh" in json.dumps(manifest) and "stress_max_kpa" in json.dumps(manifest)


#: Issue 32: the swept mesh's skin stretches agree with the feasibility stage's within 1 %.
SKIN_RTOL = 0.01


def test_the_demos_skin_stretches_agree_with_the_feasibility_stages(tmp_path):
    """configs/demo.yaml as it is, with a volume mesh at its exported q (0, 0.5 and 1): the skin quads' largest
    and least stretch against the feasibility stage's (its grid converged to 1e-4), within 1 %, at every one.

    At q = 0.5 the least stretch sits on the tip's end ring (l = 1, angle 77 deg), where the tip's cut plane lies
    0.20 mm past the ring: the mesh's body goes on past the ring, carried rigidly by the end frame, and a row of
    quads across that crease read 0.6950 (+1.34 %); with the layer before the end on the ring
    (softdesign/meshing/end_cut.py, crease_targets) the row inside it reads 0.6910 (+0.76 %).
    """
    import yaml

    from softdesign.pipeline.api import build_through
    from tests.helpers.paths import REPO

    data = yaml.safe_load((REPO / "configs" / "demo.yaml").read_text())
    for key in ("centerline", "surface"):
        data["final"][key] = str((REPO / "configs" / data["final"][key]).resolve())
    data["export"]["volume_mesh"] = {"q": data["export"]["q"]}
    case_file = tmp_path / "demo.yaml"
    case_file.write_text(yaml.safe_dump(data, sort_keys=False))
    outcome = build_through(case_file, tmp_path / "build")
    volume = outcome.results["volume_mesh"].summary["per_q"]
    feasibility = {row["q"]: row for row in outcome.results["feasibility"].summary["per_q"]}
    assert [row["q"] for row in volume] == [0.0, 0.5, 1.0]
    for row in volume:
        skin, surface = row["strain"], feasibility[row["q"]]
        np.testing.assert_allclose(skin["skin_stretch_max"], surface["stretch_max"], rtol=SKIN_RTOL)
        np.testing.assert_allclose(skin["skin_stretch_min"], surface["stretch_min"], rtol=SKIN_RTOL)
    assert feasibility[0.5]["where"]["stretch_min"]["l"] == 1.0  # the end ring's least stretch is the one met


def test_the_aortas_skin_stretches_agree_with_the_feasibility_stages(tmp_path, aorta_dir):
    """The VMTK aorta (path 0, pipelines/bench_volume.py's case) at the default settings, a volume mesh at q =
    0.5 and 1: the skin's largest and least stretch on the mesh against the feasibility stage's, within 1 %.

    The extremes are a narrow peak 2.5 mm from the base (at q = 1 the stretch rises from 1.29 to 1.59 and falls
    to 1.38 within 1.2 mm); even layers 1.9 mm apart gave 1.417 (-10.8 %), the layers graded by the skin's
    stretch (softdesign/meshing/volume_mesh/sweep_grading.py) meet it.
    """
    import yaml

    from softdesign.pipeline.api import build_through

    data = {"name": "aorta", "units": "mm",
            "final": {"centerline": str(aorta_dir / "aorta-centerline.vtp"),
                      "surface": str(aorta_dir / "aorta-surface.stl"), "path": 0},
            "export": {"q": [0.0, 0.5, 1.0], "volume_mesh": {"q": [0.5, 1.0]}}, "material": {"name": "ecoflex-00-30"}}
    case_file = tmp_path / "aorta.yaml"
    case_file.write_text(yaml.safe_dump(data, sort_keys=False))
    feasibility = build_through(case_file, tmp_path / "build", target="feasibility").results["feasibility"]
    surface = {row["q"]: row for row in feasibility.summary["per_q"]}
    volume = build_through(case_file, tmp_path / "build", target="volume_mesh").results["volume_mesh"]
    rows = volume.summary["per_q"]
    assert [row["q"] for row in rows] == [0.5, 1.0]
    for row in rows:
        skin, expected = row["strain"], surface[row["q"]]
        np.testing.assert_allclose(skin["skin_stretch_max"], expected["stretch_max"], rtol=SKIN_RTOL)
        np.testing.assert_allclose(skin["skin_stretch_min"], expected["stretch_min"], rtol=SKIN_RTOL)




def test_meshing_and_its_metrics_show_a_bar_on_a_terminal_and_a_line_per_part_with_its_time(tmp_path):
    """Issue 32 item 5: on a terminal the volume_mesh stage's bar counts its parts (the mesh plan, each q, each
    batch of the morph's samples, each with its time); the build's printed log has a line per part with its
    time; a pipe gets no bar."""
    from tests.e2e.test_export_progress import CODE, _on_a_terminal
    from tests.helpers.paths import REPO

    case = _swept(tmp_path)
    code, stdout, screen = _on_a_terminal("build", str(case), "--out", str(tmp_path / "tty"), "--jobs", "1")
    assert code == 0, screen
    parts = ["mesh plan", "q=0.000", "q=1.000", r"q=0\.050\.\.0\.950 \(19 q\)"]
    for done, part in enumerate(parts, start=1):
        assert re.search(rf"volume_mesh: {part} \(\d+\.\d\d s\) done .*{done}/{len(parts)}", screen), screen
        assert re.search(rf"^  {part}: \d+\.\d\d s$", stdout, re.M), stdout
    piped = subprocess.run([sys.executable, "-c", CODE, "build", str(case), "--out", str(tmp_path / "pipe"), "--jobs",
                            "1"], capture_output=True, text=True, cwd=REPO, timeout=600, stdin=subprocess.DEVNULL)
    assert piped.returncode == 0, piped.stderr
    assert "\x1b" not in piped.stderr and "mesh plan (" not in piped.stderr
    assert re.search(r"^  mesh plan: \d+\.\d\d s$", piped.stdout, re.M), piped.stdout
