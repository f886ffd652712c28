"""`export.mould` end to end: the demo hollow and solid, the real aorta; files, manifest, checks, untouched outputs."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pytest
import yaml
from PIL import Image
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.io.formats import read_mesh
from softdesign.meshing.checks import inspect_mesh
from softdesign.report.mould_figures import mould_figure_png
from softdesign.report.writer import EXPECTED_SIZES, write_report
from tests.helpers.paths import REPO

runner = CliRunner()
#: Volume of a part read back from its STL (float32 coordinates) against the manifest's, relative.
STL_VOLUME_RTOL = 1e-5


def demo_case(folder: Path, fit: dict | None = None, **export) -> Path:
    case = yaml.safe_load((REPO / "configs" / "demo.yaml").read_text())
    for key in ("centerline", "surface"):
        case["final"][key] = str((REPO / "configs" / case["final"][key]).resolve())
    case["export"] = {"q": [0, 1], "angular_count": 48, "spacing_mm": 1.0, **export}
    if fit is not None:
        case["fit"] = {**case.get("fit", {}), **fit}
    path = folder / "demo.yaml"
    path.write_text(yaml.safe_dump(case, sort_keys=False))
    return path


def run(*args: str) -> str:
    result = runner.invoke(app, list(args))
    assert result.exit_code == 0, result.output
    return result.output


def files(folder: Path) -> dict[str, str]:
    return {p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def test_a_hollow_body_without_port_is_refused_before_building(tmp_path):
    result = runner.invoke(app, ["validate", str(demo_case(tmp_path, wall_mm=1.0, mould={}))])
    assert result.exit_code == 2 and "needs port_mm" in result.output, result.output


def test_mould_command_needs_export_mould(tmp_path):
    case = demo_case(tmp_path)
    result = runner.invoke(app, ["mould", str(case), "--out", str(tmp_path / "b")])
    assert result.exit_code == 2 and "no export.mould" in result.output and "Traceback" not in result.output


@pytest.mark.parametrize(("mould", "message"), [
    ({"margin_mm": 0}, "export.mould.margin_mm must be > 0"),
    ({"clearance_mm": 9}, "export.mould.clearance_mm must be <= 5"),
    ({"up": "side"}, "export.mould.up"),
    ({"margin": 5}, "did you mean 'margin_mm'"),
    ({"margin_mm": 6, "key_mm": 6}, "needs margin_mm >= 8.4"),
])
def test_mould_keys_are_bounded(tmp_path, mould, message):
    result = runner.invoke(app, ["validate", str(demo_case(tmp_path, mould=mould))])
    assert result.exit_code == 2 and message in result.output, result.output


@pytest.mark.slow
def test_demo_hollow_mould_is_written_listed_and_checked(tmp_path):
    out = tmp_path / "build"
    text = run("mould", str(demo_case(tmp_path, wall_mm=1.0, port_mm=1.5, mould={"margin_mm": 8})), "--out", str(out))
    assert "[mould] ran" in text and "core: removable" in text
    manifest = json.loads((out / "manifest.json").read_text())
    listed = {o["path"]: o for o in manifest["outputs"] if o["path"].startswith("meshes/mould/")}
    assert set(listed) == {f"meshes/mould/{p}.stl" for p in ("half_a", "half_b", "core")}
    for path, entry in listed.items():
        assert entry["sha256"] == hashlib.sha256((out / path).read_bytes()).hexdigest()
        vertices, faces = read_mesh(out / path)
        report = inspect_mesh(vertices, faces)
        assert report.watertight and report.bodies == 1 and report.euler == 2
        assert report.volume == pytest.approx(entry["volume_mm3"], rel=STL_VOLUME_RTOL)
        assert entry["cavity_ok"] and entry["disjoint_ok"]
    block = manifest["metrics"]["mould"]
    assert block["cavity"]["rel_difference"] <= 0.005 and block["disjoint"]["ok"]
    assert all(p["ok"] and p["against_pull"] == 0 and p["blocked_rays"] == 0 for p in block["pull"].values())
    assert block["core"]["process"] == "removable"
    png = mould_figure_png(out)
    assert png is not None and png.startswith(b"\x89PNG") and png == mould_figure_png(out)  # same bytes each time
    # the report's fabrication section shows it, with the parts' checks in its caption
    report = write_report(out)
    page = report.page.read_text()
    assert 'id="fabrication"' in page and 'src="mould.png"' in page and "core: removable" in page.lower()
    with Image.open(report.page.parent / "mould.png") as image:
        assert image.size == EXPECTED_SIZES["mould.png"]


@pytest.mark.slow
def test_a_mould_leaves_every_other_output_byte_for_byte(tmp_path):
    # the mould casts square ends, so with a mould fit.end_cut: auto keeps the demo's tilted-cap ends square: the
    # meshes equal those of a plain build with square ends (normal)
    plain, moulded = tmp_path / "plain", tmp_path / "moulded"
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    run("build", str(demo_case(tmp_path / "a", fit={"end_cut": "normal"})), "--out", str(plain))
    run("build", str(demo_case(tmp_path / "b", mould={"up": "tip"})), "--out", str(moulded))
    before, after = files(plain), files(moulded)
    assert set(after) - set(before) == {"mould/summary.json", "meshes/mould/half_a.stl", "meshes/mould/half_b.stl"}
    # the case differs (the manifest holds it; the fit reads export.mould, so the fit's and its followers' cache
    # keys differ) and the fit's record says why each end stayed square; every mesh and figure is the same
    changed = {k for k in before if before[k] != after[k]}
    assert {k for k in changed if not k.endswith("stage.json")} == {"manifest.json", "fit/summary.json"}
    assert not any(k.startswith("meshes/") for k in changed)
    cuts = json.loads((moulded / "fit" / "summary.json").read_text())["end_cut"]
    assert all(not c["applied"] and c["reason"].startswith("export.mould casts square ends") for c in cuts.values())
    assert mould_figure_png(plain) is None


def test_a_mould_with_cap_plane_cuts_is_refused_before_building(tmp_path):
    case = demo_case(tmp_path, mould={}, fit={"end_cut": "cap_plane"})
    result = runner.invoke(app, ["validate", str(case)])
    assert result.exit_code == 2 and "fit.end_cut: auto or normal" in result.output, result.output


@pytest.mark.slow
def test_aorta_mould_without_core(tmp_path, aorta_dir):
    case = {"name": "aorta", "final": {"centerline": str(aorta_dir / "aorta-centerline.vtp"),
                                        "surface": str(aorta_dir / "aorta-surface.stl"), "path": 0},
            "export": {"q": [0, 1], "mould": {"margin_mm": 10}}}
    path = tmp_path / "aorta.yaml"
    path.write_text(yaml.safe_dump(case, sort_keys=False))
    run("mould", str(path), "--out", str(tmp_path / "build"))
    block = json.loads((tmp_path / "build" / "manifest.json").read_text())["metrics"]["mould"]
    assert set(block["parts"]) == {"half_a", "half_b"} and block["core"] is None
    assert block["cavity"]["ok"] and block["disjoint"]["ok"] and all(p["ok"] for p in block["pull"].values())
