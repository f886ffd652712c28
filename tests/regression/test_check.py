"""`softdesign check` through the CLI on small fake build folders (the format the pipeline writes)."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
import trimesh
import typer
from typer.testing import CliRunner

from softdesign.cli.check import check
from softdesign.meshing.compare import compare_meshes
from softdesign.regression import CheckOptions, check_build, decimation_entry

runner = CliRunner()
app = typer.Typer()
app.command()(check)
app.command("noop")(lambda: None)  # a second command keeps `check` a named subcommand, as in softdesign.cli

#: The default --tolerance-mm and --rotation-tol.
TOL_MM = CheckOptions().distance_mm
TOL_RAD = CheckOptions().rotation_rad
#: Binary STL stores float32: coordinates of ~20 mm round to ~1e-6 mm.
STL_TOL = 1e-5
LINK_LENGTH_MM = 25.0
Q_VALUES = (0.0, 0.5, 1.0)


def run_check(build: Path, reference: Path, *extra: str):
    return runner.invoke(app, ["check", str(build), "--reference", str(reference), *extra])


def cylinder() -> trimesh.Trimesh:
    return trimesh.creation.cylinder(radius=3.0, height=40.0, sections=32)


def capsule() -> trimesh.Trimesh:
    mesh = trimesh.creation.capsule(height=30.0, radius=2.5, count=[24, 24])
    mesh.apply_translation([1.0, 2.0, 20.0])
    return mesh


def arc_pose(q: float, index: int) -> np.ndarray:
    """A link bent by q * 0.4 * (index + 1) rad in the y-z plane, LINK_LENGTH_MM long: (4, 4)."""
    theta = q * 0.4 * (index + 1)
    c, s = np.cos(theta), np.sin(theta)
    pose = np.eye(4)
    pose[:3, :3] = [[1, 0, 0], [0, c, s], [0, -s, c]]
    chord = LINK_LENGTH_MM * (np.sinc(theta / (2 * np.pi)) if theta else 1.0)
    pose[:3, 3] = chord * np.array([0.0, np.sin(theta / 2), np.cos(theta / 2)])
    return pose


def kinematics_payload() -> dict:
    poses = []
    for q in Q_VALUES:
        links, tip = [], np.eye(4)
        for index in range(2):
            pose = arc_pose(q, index)
            tip = tip @ pose
            theta2 = q * 0.4 * (index + 1)
            theta1 = float(np.linalg.norm(pose[:3, 3]))
            poe = {"theta1": theta1, "xi1": (pose[:3, 3] / theta1).tolist(),
                   "theta2": theta2, "omega": [-1.0, 0.0, 0.0] if theta2 else None}
            links.append({"index": index, "length": LINK_LENGTH_MM, "transform": pose.tolist(), "poe": poe})
        # As the kinematics stage writes it: one q per link, and the base placed in the patient's frame.
        poses.append({"q": [q, q], "links": links, "base_to_tip": tip.tolist(), "base_to_world": np.eye(4).tolist()})
    links = [{"index": i, "l_start": i / 2, "l_end": (i + 1) / 2} for i in range(2)]
    return {"frames": "rmf", "links": links, "poses": poses}


def write_build(folder: Path, meshes: dict[str, trimesh.Trimesh], fit: dict | None = None) -> Path:
    """A build folder: meshes/*, manifest.json (outputs, fit metrics), kinematics.json."""
    (folder / "meshes").mkdir(parents=True)
    outputs = []
    for name, mesh in meshes.items():
        path = folder / "meshes" / name
        mesh.export(path)
        outputs.append({"path": f"meshes/{name}", "vertices": len(mesh.vertices), "faces": len(mesh.faces),
                        "volume_mm3": float(mesh.volume), "area_mm2": float(mesh.area),
                        "watertight": bool(mesh.is_watertight)})
    metrics = {} if fit is None else {"fit": fit}
    (folder / "manifest.json").write_text(json.dumps({"outputs": outputs, "metrics": metrics}))
    (folder / "kinematics.json").write_text(json.dumps(kinematics_payload()))
    return folder


FIT = {"rms_mm": 0.021, "p95_mm": 0.04, "p99_mm": 0.06, "max_mm": 0.09, "holdout_rms_mm": 0.025}


@pytest.fixture
def reference(tmp_path: Path) -> Path:
    return write_build(tmp_path / "reference", {"q_0.000.stl": cylinder(), "q_0.500.stl": capsule(),
                                                 "q_0.500.ply": capsule()}, dict(FIT))


@pytest.fixture
def build(tmp_path: Path, reference: Path) -> Path:
    return Path(shutil.copytree(reference, tmp_path / "build"))


def replace_mesh(build: Path, name: str, mesh: trimesh.Trimesh) -> None:
    mesh.export(build / "meshes" / name)


def edit_json(path: Path, edit) -> None:
    payload = json.loads(path.read_text())
    edit(payload)
    path.write_text(json.dumps(payload))


def failed_lines(output: str) -> list[str]:
    """The lines under 'check FAILED', one per regressed figure."""
    lines = output.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("check FAILED"))
    return [line.strip() for line in lines[start + 1:]]


def json_figures(build: Path, reference: Path, *extra: str) -> tuple[int, dict]:
    result = run_check(build, reference, "--json", *extra)
    return result.exit_code, json.loads(result.stdout)


def figure(payload: dict, item: str, name: str) -> dict:
    (found,) = [f for f in payload["figures"] if f["item"] == item and f["figure"] == name]
    return found


def test_a_build_passes_against_itself_with_every_item_compared(build, reference):
    result = run_check(build, reference)
    assert result.exit_code == 0, result.output
    assert "check PASSED" in result.output
    code, payload = json_figures(build, reference)
    assert code == 0 and payload["passed"] is True and payload["failures"] == 0
    items = {f["item"] for f in payload["figures"]}
    assert {"meshes/q_0.000.stl", "meshes/q_0.500.stl", "meshes/q_0.500.ply", "fit"} <= items
    assert {f"kinematics q={q:g} link {i}" for q in Q_VALUES for i in range(2)} <= items
    assert {f"kinematics q={q:g} {key}" for q in Q_VALUES for key in ("base_to_tip", "base_to_world")} <= items
    for line in result.stdout.splitlines()[1:len(payload["figures"]) + 1]:
        assert re.search(r"\sPASS(\s|$)", line) and "FAIL" not in line, line


def test_a_mesh_moved_by_twice_the_tolerance_fails_naming_mesh_and_figure(build, reference):
    replace_mesh(build, "q_0.500.stl", capsule().apply_translation([2 * TOL_MM, 0.0, 0.0]))
    result = run_check(build, reference)
    assert result.exit_code == 1, result.output
    failed = failed_lines(result.output)
    assert any(line.startswith("meshes/q_0.500.stl: distance_max_mm") for line in failed), failed
    assert not any("q_0.000" in line or "q_0.500.ply" in line for line in failed), failed


def test_a_mesh_moved_by_half_the_tolerance_passes_with_the_move_measured(build, reference):
    replace_mesh(build, "q_0.500.stl", capsule().apply_translation([0.5 * TOL_MM, 0.0, 0.0]))
    code, payload = json_figures(build, reference)
    assert code == 0, [f for f in payload["figures"] if not f["passed"]]
    moved = figure(payload, "meshes/q_0.500.stl", "distance_max_mm")["change"]
    # The capsule's +x pole moves straight out by the shift; float32 STL rounding on top.
    np.testing.assert_allclose(moved, 0.5 * TOL_MM, rtol=0, atol=STL_TOL)


def test_a_scaled_mesh_fails_on_volume(build, reference):
    mesh = cylinder()
    mesh.apply_scale(1.002)  # volume +0.6 %, six times the default --rtol
    replace_mesh(build, "q_0.000.stl", mesh)
    result = run_check(build, reference)
    assert result.exit_code == 1, result.output
    failed = failed_lines(result.output)
    assert any(line.startswith("meshes/q_0.000.stl: volume_rel_change 0.006") for line in failed), failed
    assert any(line.startswith("meshes/q_0.000.stl: area_rel_change") for line in failed), failed


def test_a_mesh_with_a_face_removed_fails_as_not_watertight(build, reference):
    mesh = cylinder()
    replace_mesh(build, "q_0.000.stl", trimesh.Trimesh(mesh.vertices, mesh.faces[1:], process=False))
    result = run_check(build, reference)
    assert result.exit_code == 1, result.output
    assert "meshes/q_0.000.stl: watertight build False, reference True" in failed_lines(result.output), result.output


@pytest.mark.parametrize("side, expected", [("build", "build missing, reference present"),
                                            ("reference", "build present, reference missing")])
def test_a_mesh_missing_on_either_side_fails_named(build, reference, side, expected):
    (build if side == "build" else reference).joinpath("meshes", "q_0.500.ply").unlink()
    result = run_check(build, reference)
    assert result.exit_code == 1, result.output
    assert f"meshes/q_0.500.ply: mesh file {expected}" in failed_lines(result.output)


def test_a_changed_link_transform_fails_naming_q_and_link(build, reference):
    def shift(payload):
        payload["poses"][1]["links"][1]["transform"][0][3] += 2 * TOL_MM

    edit_json(build / "kinematics.json", shift)
    result = run_check(build, reference)
    assert result.exit_code == 1, result.output
    assert failed_lines(result.output) == ["kinematics q=0.5 link 1: translation_mm 0.02 outside tolerance 0.01"]


@pytest.mark.parametrize("factor, passes", [(0.5, True), (2.0, False)])
def test_a_link_rotation_fails_past_the_rotation_tolerance_only(build, reference, factor, passes):
    def turn(payload):
        link = payload["poses"][2]["links"][0]
        angle = factor * TOL_RAD
        turn_z = np.array([[np.cos(angle), -np.sin(angle), 0, 0], [np.sin(angle), np.cos(angle), 0, 0],
                           [0, 0, 1, 0], [0, 0, 0, 1]])
        link["transform"] = (np.array(link["transform"]) @ turn_z).tolist()

    edit_json(build / "kinematics.json", turn)
    code, payload = json_figures(build, reference)
    rotation = figure(payload, "kinematics q=1 link 0", "rotation_rad")
    np.testing.assert_allclose(rotation["change"], factor * TOL_RAD, rtol=0, atol=1e-12)
    assert (code == 0) is passes and rotation["passed"] is passes


def test_poses_match_by_q_given_once_or_per_link(build, reference):
    def per_link(payload):
        payload["poses"][1]["q"] = 0.5  # the same pose as [0.5, 0.5]
        payload["poses"][2]["q"] = [0.25, 1.0]  # a different pose

    edit_json(build / "kinematics.json", per_link)
    result = run_check(build, reference)
    assert result.exit_code == 1, result.output
    assert failed_lines(result.output) == [
        "kinematics q=0.25,1: pose build present, reference missing",
        "kinematics q=1: pose build missing, reference present",
    ]


def test_fit_metrics_moved_or_missing_fail(build, reference):
    edit_json(build / "manifest.json", lambda m: m["metrics"]["fit"].update(p99_mm=FIT["p99_mm"] + 2 * TOL_MM))
    result = run_check(build, reference)
    assert result.exit_code == 1
    assert [line.split(" outside")[0] for line in failed_lines(result.output)] == ["fit: p99_mm 0.02"]
    edit_json(build / "manifest.json", lambda m: m["metrics"].pop("fit"))
    result = run_check(build, reference)
    assert failed_lines(result.output) == ["fit: metrics.fit build missing, reference present"]


def test_fit_absent_on_both_sides_is_noted_not_failed(build, reference):
    for folder in (build, reference):
        edit_json(folder / "manifest.json", lambda m: m["metrics"].pop("fit"))
    result = run_check(build, reference)
    assert result.exit_code == 0, result.output
    assert "note: no metrics.fit on either side" in result.output


@pytest.mark.parametrize(
    "which, expected",
    [("build", "BUILD_DIR {}: folder not found"), ("reference", "--reference {}: folder not found"),
     ("not-a-build", "--reference {}: not a build folder (no manifest.json)")],
)
def test_missing_folders_exit_2_naming_them(build, reference, tmp_path, which, expected):
    nowhere = tmp_path / "nowhere"
    args = {"build": (nowhere, reference), "reference": (build, nowhere), "not-a-build": (build, tmp_path)}[which]
    result = run_check(*args)
    assert result.exit_code == 2, result.output
    named = nowhere if which != "not-a-build" else tmp_path
    assert expected.format(named) in result.output


def test_bad_tolerance_exits_2(build, reference):
    result = run_check(build, reference, "--tolerance-mm", "-1")
    assert result.exit_code == 2
    assert "--tolerance-mm: expected a finite tolerance >= 0, got -1.0" in result.output


def test_json_output_parses_and_names_the_regression(build, reference):
    replace_mesh(build, "q_0.000.stl", cylinder().apply_translation([0.0, 0.0, 3 * TOL_MM]))
    code, payload = json_figures(build, reference)
    assert code == 1 and payload["passed"] is False
    assert payload["tolerances"] == {"distance_mm": TOL_MM, "rtol": 1e-3, "rotation_rad": TOL_RAD}
    failed = {(f["item"], f["figure"]) for f in payload["figures"] if not f["passed"]}
    assert ("meshes/q_0.000.stl", "distance_max_mm") in failed


def test_help_names_the_tolerances():
    result = runner.invoke(app, ["check", "--help"])
    assert result.exit_code == 0
    for option in ("--reference", "--tolerance-mm", "--rtol", "--rotation-tol", "--json"):
        assert option in result.output


def decimated_pair() -> tuple[trimesh.Trimesh, trimesh.Trimesh]:
    """A fine sphere (the build) and a coarser one standing in for its decimated golden copy."""
    return (trimesh.creation.icosphere(subdivisions=4, radius=8.0),
            trimesh.creation.icosphere(subdivisions=3, radius=8.0))


def test_golden_json_widens_the_tolerance_by_the_recorded_decimation_error(tmp_path):
    fine, coarse = decimated_pair()
    build = write_build(tmp_path / "build", {"q_1.000.stl": fine})
    reference = write_build(tmp_path / "golden", {"q_1.000.stl": coarse})
    assert run_check(build, reference).exit_code == 1, "a coarse reference alone differs by more than 0.01 mm"
    lost = compare_meshes(coarse.vertices, coarse.faces, fine.vertices, fine.faces)
    assert lost.distance_max_mm > TOL_MM
    (reference / "golden.json").write_text(json.dumps({"meshes": {"meshes/q_1.000.stl": decimation_entry(lost)}}))
    result = run_check(build, reference)
    assert result.exit_code == 0, result.output
    # A real move still fails: both meshes are inscribed in the 8 mm sphere, so a vertex moved 2 (tol + e) outward
    # (times the cosine to the move, near 1 for the most +x vertex) is that far from anything of the coarse one.
    replace_mesh(build, "q_1.000.stl", fine.copy().apply_translation([2 * (TOL_MM + lost.distance_max_mm), 0, 0]))
    assert run_check(build, reference).exit_code == 1


def test_malformed_golden_json_exits_2(build, reference):
    (reference / "golden.json").write_text(json.dumps({"meshes": {"meshes/q_0.000.stl": {"distance_max_mm": "big"}}}))
    result = run_check(build, reference)
    assert result.exit_code == 2
    assert "golden.json: meshes.meshes/q_0.000.stl.distance_max_mm must be a finite number, got 'big'" in result.output


def test_library_reports_the_same_figures_as_the_cli(build, reference):
    report = check_build(build, reference)
    code, payload = json_figures(build, reference)
    assert report.as_dict()["figures"] == payload["figures"]


def rows(output: str) -> list[str]:
    """The table's rows under its header (up to the blank line), or [] when no table was printed."""
    lines = output.splitlines()
    if not lines or not lines[0].startswith("item"):
        return []
    return lines[1:lines.index("")]


def test_failures_only_prints_just_the_failing_rows(build, reference):
    replace_mesh(build, "q_0.500.stl", capsule().apply_translation([2 * TOL_MM, 0.0, 0.0]))
    everything = rows(run_check(build, reference).stdout)
    result = run_check(build, reference, "--failures-only")
    assert result.exit_code == 1, result.output
    failing = rows(result.stdout)
    assert failing and all(re.search(r"\sFAIL(\s|$)", row) for row in failing), failing
    # the same rows as in the whole table (columns are sized to the rows shown)
    assert [row.split() for row in failing] == [row.split() for row in everything if re.search(r"\sFAIL(\s|$)", row)]
    assert len(everything) > len(failing)
    total = len(everything)
    assert f"check FAILED: {len(failing)} of {total} figure(s)" in result.stdout  # the verdict still counts all


def test_failures_only_on_a_passing_check_prints_the_verdict_without_a_table(build, reference):
    result = run_check(build, reference, "--failures-only")
    assert result.exit_code == 0, result.output
    assert rows(result.stdout) == [] and "PASS " not in result.stdout
    assert result.stdout.startswith("check PASSED")


def test_failures_only_with_json_lists_the_failures_and_counts_every_figure(build, reference):
    replace_mesh(build, "q_0.000.stl", cylinder().apply_translation([0.0, 0.0, 3 * TOL_MM]))
    code, everything = json_figures(build, reference)
    code_only, payload = json_figures(build, reference, "--failures-only")
    assert code == code_only == 1
    assert payload["figures"] == [f for f in everything["figures"] if not f["passed"]]
    assert payload["failures"] == len(payload["figures"]) and payload["compared"] == len(everything["figures"])


def set_case(folder: Path, name: str, centerline_sha256: str) -> None:
    """Give a fake build folder's manifest a case and inputs, as a real build writes them."""
    def edit(manifest):
        manifest["case"] = {"name": name, "units": "mm"}
        manifest["inputs"] = [{"path": "../data/centerline.vtp", "sha256": centerline_sha256, "bytes": 100},
                              {"path": "../data/surface.stl", "sha256": "b" * 64, "bytes": 200}]

    edit_json(folder / "manifest.json", edit)


def test_the_same_case_checks_without_a_warning(build, reference):
    for folder in (build, reference):
        set_case(folder, "arch", "a" * 64)
    result = run_check(build, reference)
    assert result.exit_code == 0 and "warning" not in result.output, result.output
    assert json_figures(build, reference)[1]["warnings"] == []


def test_different_case_names_warn_but_do_not_fail(build, reference):
    set_case(build, "arch", "a" * 64)
    set_case(reference, "coil", "a" * 64)
    result = run_check(build, reference)
    assert result.exit_code == 0, result.output  # a warning, not an error: every figure is still within tolerance
    expected = "warning: the build is case 'arch' and the reference case 'coil'"
    assert expected in result.stderr and expected not in result.stdout
    assert "give --reference a build of the same case" in result.stderr
    code, payload = json_figures(build, reference)
    assert code == 0 and payload["warnings"][0].startswith("the build is case 'arch'")


def test_the_same_case_built_from_other_input_files_warns_naming_them(build, reference):
    set_case(build, "arch", "a" * 64)
    set_case(reference, "arch", "c" * 64)
    result = run_check(build, reference, "--failures-only")
    assert result.exit_code == 0, result.output
    assert ("warning: case 'arch' was built from other input files than the reference (sha256 differs: "
            "../data/centerline.vtp, ../data/centerline.vtp (reference))") in result.stderr
    assert "surface.stl" not in result.stderr
