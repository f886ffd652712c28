"""The build folder: caching by content hash, same bytes for the same inputs, atomic runs."""

from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.pipeline.versions import software_versions
from tests.helpers.paths import REPO

runner = CliRunner()
STAGES = ["ingest", "design", "blend", "links", "kinematics", "fit", "simulate", "actuation", "device_fe", "export",
          "mould", "volume_mesh", "feasibility", "fabrication"]


def snapshot(folder: Path) -> dict[str, str]:
    """Every file under ``folder`` with its sha256."""
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def statuses(output: str) -> dict[str, str]:
    """{stage: 'ran' | 'skipped'} from a build's report lines."""
    return dict(re.findall(r"^\[([a-z_]+)\] (ran|skipped|kept|stale)", output, flags=re.MULTILINE))


def write_demo_case(folder: Path) -> Path:
    """A copy of configs/demo.yaml pointing at the committed sample data, coarse enough to be quick."""
    case = yaml.safe_load((REPO / "configs" / "demo.yaml").read_text())
    for key in ("centerline", "surface"):
        case["final"][key] = str((REPO / "configs" / case["final"][key]).resolve())
    case["export"] = {"q": [0, 1], "angular_count": 48, "spacing_mm": 1.0}
    path = folder / "demo.yaml"
    path.write_text(yaml.safe_dump(case, sort_keys=False))
    return path


@pytest.fixture
def demo_case(tmp_path) -> Path:
    """:func:`write_demo_case` in the test's folder."""
    return write_demo_case(tmp_path)


def build(case: Path, out: Path, *extra: str) -> str:
    """``softdesign build CASE --out OUT EXTRA`` in-process on one process (the parallel path's bytes are
    tests/pipeline/test_parallel.py's: here a pool of two would add about a second of CPU per build)."""
    result = runner.invoke(app, ["build", str(case), "--out", str(out), "--jobs", "1", *extra])
    assert result.exit_code == 0, result.output
    return result.output


@pytest.fixture(scope="module")
def demo_built(tmp_path_factory) -> tuple[str, Path, str]:
    """The ``demo_case`` file's text, its build and the build's output, made once for the file (a fresh build: every
    stage ran)."""
    folder = tmp_path_factory.mktemp("demo-built")
    case = write_demo_case(folder)
    output = build(case, folder / "build")
    return case.read_text(), folder / "build", output


def built(demo_built: tuple[str, Path, str], case: Path, out: Path) -> None:
    """``out`` as ``build(case, out)`` leaves it, for a test whose ``case`` is still ``demo_case``'s: a copy of
    ``demo_built``'s build.  ``case`` names its inputs relative to itself and lies as deep as the module's case,
    so the stage keys are the same and a next build reuses what did not change, as on a build of its own."""
    text, source, _ = demo_built
    assert case.read_text() == text and len(case.parts) == len((source.parent / case.name).parts)
    shutil.copytree(source, out)


def edit(case: Path, section: str, **values) -> None:
    data = yaml.safe_load(case.read_text())
    data[section] = {**(data.get(section) or {}), **values}
    case.write_text(yaml.safe_dump(data, sort_keys=False))


@pytest.mark.slow
def test_cache_skips_what_did_not_change_and_force_redoes_all(demo_case, demo_built, tmp_path):
    out = tmp_path / "build"
    assert statuses(demo_built[2]) == dict.fromkeys(STAGES, "ran")  # the module's fresh build of this case
    built(demo_built, demo_case, out)
    assert statuses(build(demo_case, out)) == dict.fromkeys(STAGES, "skipped")
    # blend: auto judges the fitted body over the morph (issue 43), so the blend reads the fit's keys: a fit edit
    # redoes the blend and what follows it; ingest stays
    edit(demo_case, "fit", smoothing=2.0e-5)
    assert statuses(build(demo_case, out)) == {
        "ingest": "skipped", "design": "skipped", "blend": "ran", "links": "ran", "kinematics": "ran",
        "fit": "ran", "simulate": "ran",
        "actuation": "ran", "device_fe": "ran", "export": "ran", "mould": "ran", "volume_mesh": "ran",
        "feasibility": "ran", "fabrication": "ran",
    }
    edit(demo_case, "export", q=[0, 0.5, 1])
    assert statuses(build(demo_case, out)) == {
        "ingest": "skipped", "design": "skipped", "blend": "skipped", "links": "skipped", "kinematics": "ran",
        "fit": "skipped", "simulate": "ran",
        "actuation": "ran", "device_fe": "ran", "export": "ran", "mould": "ran", "volume_mesh": "ran",
        "feasibility": "ran", "fabrication": "ran",
    }
    # The mesh formats are read by export (and the mould's formats): kinematics, the fit and the feasibility
    # figures stay cached.
    edit(demo_case, "export", formats=["stl", "ply"])
    assert statuses(build(demo_case, out)) == {
        "ingest": "skipped", "design": "skipped", "blend": "skipped", "links": "skipped", "kinematics": "skipped",
        "fit": "skipped", "simulate": "skipped",
        "actuation": "skipped", "device_fe": "skipped", "export": "ran", "mould": "ran", "volume_mesh": "skipped",
        "feasibility": "skipped",
        "fabrication": "ran",
    }
    # A mould is read by the mould stage and by the fit (which turns the end cuts into the mould's parting
    # plane): the fit and what follows it are redone; ingest, blend, links and kinematics stay.
    edit(demo_case, "export", mould={"margin_mm": 8})
    assert statuses(build(demo_case, out)) == {
        "ingest": "skipped", "design": "skipped", "blend": "skipped", "links": "skipped", "kinematics": "skipped",
        "fit": "ran", "simulate": "ran",
        "actuation": "ran", "device_fe": "ran", "export": "ran", "mould": "ran", "volume_mesh": "ran",
        "feasibility": "ran", "fabrication": "ran",
    }
    assert (out / "meshes" / "mould" / "half_a.ply").is_file()
    # New link breaks: the blend (explicit breaks may be sharp joints of the path, geometry/curve_joints.py), the
    # links, their kinematics and the per-link fit are redone; ingest is not.
    edit(demo_case, "links", count=None, breaks=[0, 0.4, 1])
    assert statuses(build(demo_case, out)) == {
        "ingest": "skipped", "design": "skipped", "blend": "ran", "links": "ran", "kinematics": "ran",
        "fit": "ran", "simulate": "ran", "actuation": "ran", "device_fe": "ran",
        "export": "ran", "mould": "ran", "volume_mesh": "ran", "feasibility": "ran",
        "fabrication": "ran",
    }
    # A material is read by the verdicts (feasibility, the chambers' actuation, the volume mesh's 3D stress and
    # stretch), by the simulate stage's law (off here: it runs and does nothing) and by the rod model that sizes
    # the chambers (actuation): export and the mould cut the chambers the actuation stage gives, so they are redone
    # with it (the demo declares ecoflex-00-30).
    edit(demo_case, "material", name="dragon-skin-10")
    assert statuses(build(demo_case, out)) == {**dict.fromkeys(STAGES, "skipped"), "simulate": "ran",
                                               "actuation": "ran", "device_fe": "ran", "export": "ran", "mould": "ran",
                                               "volume_mesh": "ran", "feasibility": "ran", "fabrication": "ran"}
    assert statuses(build(demo_case, out, "--force")) == dict.fromkeys(STAGES, "ran")


@pytest.mark.slow
def test_a_single_stage_run_says_whether_later_outputs_still_match(demo_case, demo_built, tmp_path):
    out = tmp_path / "build"
    built(demo_built, demo_case, out)
    meshes = {"meshes/q_0.000.stl", "meshes/q_1.000.stl"}

    def run_fit() -> tuple[dict[str, str], dict]:
        result = runner.invoke(app, ["fit", str(demo_case), "--out", str(out)])
        assert result.exit_code == 0, result.output
        return statuses(result.output), json.loads((out / "manifest.json").read_text())

    # Nothing changed: the export on disk is what a build would make now, figures and metrics included.
    ran, manifest = run_fit()
    assert ran == {
        "ingest": "skipped", "design": "skipped", "blend": "skipped", "links": "skipped", "kinematics": "skipped",
        "fit": "skipped", "simulate": "kept",
        "actuation": "kept", "device_fe": "kept", "export": "kept", "mould": "kept", "volume_mesh": "kept",
        "feasibility": "kept",
        "fabrication": "kept",
    }
    outputs = {o["path"]: o for o in manifest["outputs"]}
    assert all(outputs[m]["watertight"] and outputs[m]["volume_mm3"] > 0 and "stale" not in outputs[m] for m in meshes)
    assert "export" in manifest["metrics"] and "timing_s" not in manifest
    run = {s["name"]: s for s in json.loads((out / "run.log.json").read_text())["stages"]}
    assert run["export"] == {"name": "export", "status": "kept"} and run["fit"]["status"] == "skipped"
    # A new fit: the meshes on disk were made from the old one, and the manifest says so.
    edit(demo_case, "fit", smoothing=2.0e-5)
    ran, manifest = run_fit()
    assert (ran["fit"], ran["export"], ran["feasibility"]) == ("ran", "stale", "stale")
    outputs = {o["path"]: o for o in manifest["outputs"]}
    assert all(outputs[m]["stale"] is True for m in meshes) and "stale" not in outputs["fit/surface.npz"]
    assert next(s for s in manifest["stages"] if s["name"] == "export")["stale"] is True
    assert not any("stale" in s for s in manifest["stages"] if s["name"] in ("ingest", "fit"))
    assert "export" not in manifest["metrics"]
    # A build brings them up to date.
    assert statuses(build(demo_case, out))["export"] == "ran"
    manifest = json.loads((out / "manifest.json").read_text())
    assert not any(o.get("stale") for o in manifest["outputs"])


@pytest.mark.slow
def test_a_stale_output_is_not_reused_because_it_exists(demo_case, demo_built, tmp_path):
    out = tmp_path / "build"
    built(demo_built, demo_case, out)
    (out / "fit" / "surface.npz").write_bytes(b"tampered")
    assert statuses(build(demo_case, out))["fit"] == "ran"


@pytest.mark.slow
def test_same_inputs_give_the_same_bytes(demo_case, demo_built, tmp_path):
    first, second = tmp_path / "a", tmp_path / "b"
    built(demo_built, demo_case, first)  # a build made in another folder; the second is forced here
    build(demo_case, second, "--force")
    one, two = snapshot(first), snapshot(second)
    assert one.keys() == two.keys()
    manifest = json.loads((first / "manifest.json").read_text())
    listed = {entry["path"]: entry["sha256"] for entry in manifest["outputs"]}
    assert {"meshes/q_0.000.stl", "meshes/q_1.000.stl", "kinematics.json"} <= listed.keys()
    for name, digest in listed.items():
        assert one[name] == two[name] == digest, name
    # the manifest is the same bytes too: how each run went (statuses, seconds) is in the run log only
    assert (first / "manifest.json").read_bytes() == (second / "manifest.json").read_bytes()
    assert {s["name"] for s in json.loads((first / "run.log.json").read_text())["stages"]} == set(STAGES)


@pytest.mark.slow
def test_stages_rerun_on_cached_results_give_a_fresh_builds_bytes(demo_case, demo_built, tmp_path):
    # the shape rebuilt from blend/curves.npz and the one the blend made equal each other to 1e-14 mm only, until
    # the blend handed on the rebuilt one: the stages after a cached blend wrote other bytes than a fresh build
    fresh, cached = tmp_path / "fresh", tmp_path / "cached"
    built(demo_built, demo_case, fresh)
    plain = demo_case.read_text()
    built(demo_built, demo_case, cached)
    edit(demo_case, "links", count=3)  # links and everything after re-run on the loaded ingest and blend
    build(demo_case, cached)
    demo_case.write_text(plain)
    assert statuses(build(demo_case, cached))["kinematics"] == "ran"
    listed = {o["path"]: o["sha256"] for o in json.loads((fresh / "manifest.json").read_text())["outputs"]}
    again = {o["path"]: o["sha256"] for o in json.loads((cached / "manifest.json").read_text())["outputs"]}
    assert {"kinematics.json", "fit/surface.npz", "meshes/q_1.000.stl", "feasibility/summary.json"} <= listed.keys()
    assert again == listed


@pytest.mark.slow
def test_manifest_records_inputs_case_metrics_and_outputs(demo_case, demo_built, tmp_path):
    out = tmp_path / "build"
    built(demo_built, demo_case, out)
    manifest = json.loads((out / "manifest.json").read_text())
    assert [i["path"].rsplit("/", 1)[-1] for i in manifest["inputs"]] == ["centerline.vtp", "surface.stl"]
    assert all(len(i["sha256"]) == 64 for i in manifest["inputs"])
    assert manifest["case"]["fit"]["knot_spacing_mm"] == 1.5  # defaults filled in
    assert manifest["software"] == software_versions()  # the installed versions, keys in order
    assert list(manifest["software"]) == ["softdesign", "python", "numpy", "scipy", "vtk", "trimesh", "manifold3d",
                                          "pydantic"]
    assert "timing_s" not in manifest and [s["name"] for s in manifest["stages"]] == list(STAGES)
    run = json.loads((out / "run.log.json").read_text())["stages"]
    assert [(s["name"], s["status"]) for s in run] == [(name, "ran") for name in STAGES]
    assert all(s["seconds"] >= 0 for s in run)
    fit = manifest["metrics"]["fit"]
    assert 0 < fit["p95_mm"] <= fit["p99_mm"] <= fit["max_mm"] and 0 < fit["rms_mm"] <= fit["max_mm"]
    meshes = [o for o in manifest["outputs"] if o["path"].startswith("meshes/")]
    assert len(meshes) == 2
    for mesh in meshes:
        assert mesh["watertight"] is True and mesh["volume_mm3"] > 0 and mesh["area_mm2"] > 0
        assert mesh["faces"] > 0 and mesh["vertices"] > 0


@pytest.mark.slow
def test_a_failed_run_leaves_the_previous_build_untouched(demo_case, demo_built, tmp_path, monkeypatch):
    out = tmp_path / "build"
    built(demo_built, demo_case, out)
    before = snapshot(out)
    edit(demo_case, "fit", smoothing=3.0e-5)
    from softdesign.pipeline.stages import export as export_stage

    calls = []

    def failing(*args, **kwargs):
        calls.append(1)
        if len(calls) > 1:
            raise OSError("disk full (simulated)")
        return original(*args, **kwargs)

    original = export_stage.mesh_bytes
    monkeypatch.setattr(export_stage, "mesh_bytes", failing)
    result = runner.invoke(app, ["build", str(demo_case), "--out", str(out), "--jobs", "1"])
    assert result.exit_code != 0 and len(calls) == 2
    assert snapshot(out) == before
    assert not list(tmp_path.glob(".build.staging-*"))


KILL_MID_EXPORT = """
import os, signal, sys
import softdesign.pipeline.stages.export as export_stage
original = export_stage.mesh_bytes
calls = []
def killing(*args, **kwargs):
    calls.append(1)
    if len(calls) > 1:
        os.kill(os.getpid(), signal.SIGKILL)
    return original(*args, **kwargs)
export_stage.mesh_bytes = killing
from softdesign.cli import app
from softdesign.pipeline.versions import software_versions
sys.argv = ["softdesign"] + sys.argv[1:]
app()
"""


@pytest.mark.slow
def test_a_build_killed_mid_export_leaves_the_previous_build_unchanged(demo_case, demo_built, tmp_path):
    out = tmp_path / "build"
    built(demo_built, demo_case, out)
    before = snapshot(out)
    edit(demo_case, "export", angular_count=56)
    killed = subprocess.run(
        [sys.executable, "-c", KILL_MID_EXPORT, "build", str(demo_case), "--out", str(out), "--jobs", "1"],
        capture_output=True, text=True, env={**os.environ, "PYTHONPATH": str(REPO)}, timeout=300,
    )
    assert killed.returncode == -9, killed.stderr
    assert snapshot(out) == before
    # the next run clears the dead run's staging folder and builds normally
    assert statuses(build(demo_case, out))["export"] == "ran"
    assert not list(tmp_path.glob(".build.staging-*"))
    shutil.rmtree(out)


@pytest.mark.slow
def test_split_regions_writes_one_stl_per_region_that_tiles_each_solid(demo_case, demo_built, tmp_path):
    import trimesh

    from softdesign.meshing.topology import surface_area

    out = tmp_path / "out"
    built(demo_built, demo_case, out)  # only export and what follows it run again (the cache test shows which)
    edit(demo_case, "export", split_regions=True)
    output = build(demo_case, out)
    assert "one STL per region: wall" in output
    manifest = json.loads((out / "manifest.json").read_text())
    outputs = {o["path"]: o for o in manifest["outputs"]}
    # the solids keep their names; the pieces sit in a folder per q
    assert sorted(p.name for p in (out / "meshes").glob("q_*.stl")) == ["q_0.000.stl", "q_1.000.stl"]
    for q in ("0.000", "1.000"):
        solid = trimesh.load(out / "meshes" / f"q_{q}.stl", force="mesh")
        pieces = sorted((out / "meshes" / f"q_{q}").glob("*.stl"))
        assert [p.stem for p in pieces] == ["base_cap", "tip_cap", "wall"]
        meshes = [trimesh.load(p, force="mesh", process=False) for p in pieces]
        assert sum(len(m.faces) for m in meshes) == len(solid.faces)
        area = sum(surface_area(m.vertices, m.faces) for m in meshes)
        assert area == pytest.approx(surface_area(solid.vertices, solid.faces), rel=1e-9)
        for piece in pieces:
            entry = outputs[f"meshes/q_{q}/{piece.name}"]
            assert entry["sha256"] == hashlib.sha256(piece.read_bytes()).hexdigest()
            assert entry["area_mm2"] > 0 and entry["faces"] > 0
    # a regression check of the build against itself passes, region files included (no volume for open surfaces)
    result = runner.invoke(app, ["check", str(out), "--reference", str(out)])
    assert result.exit_code == 0, result.output
    assert "meshes/q_1.000/wall.stl" in result.output


@pytest.mark.slow
def test_vtp_meshes_carry_the_region_of_every_face(demo_case, demo_built, tmp_path):
    from vtk.util.numpy_support import vtk_to_numpy

    from softdesign.io.vtk_polydata import read_polydata

    out = tmp_path / "out"
    built(demo_built, demo_case, out)
    edit(demo_case, "export", formats=["stl", "vtp"])
    build(demo_case, out)
    manifest = json.loads((out / "manifest.json").read_text())
    outputs = {o["path"]: o for o in manifest["outputs"]}
    for q in ("0.000", "1.000"):
        poly = read_polydata(out / "meshes" / f"q_{q}.vtp")
        regions = vtk_to_numpy(poly.GetCellData().GetArray("Region"))
        assert len(regions) == outputs[f"meshes/q_{q}.stl"]["faces"] == outputs[f"meshes/q_{q}.vtp"]["faces"]
        assert set(regions.tolist()) == {0, 1, 2}  # wall, base cap, tip cap
