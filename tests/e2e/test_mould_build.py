"""`export.mould` end to end: the demo hollow and solid, the real aorta; files, manifest, checks, untouched outputs."""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import pytest
import yaml
from PIL import Image
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.io.formats import read_mesh
from softdesign.meshing.checks import inspect_mesh
from softdesign.meshing.mould.checks import CAVITY_RTOL
from softdesign.meshing.solids import manifold_from_mesh
from softdesign.report.mould_figures import mould_figure_png
from softdesign.report.writer import EXPECTED_SIZES, ReportOptions, write_report
from tests.helpers.paths import REPO

runner = CliRunner()
#: Volume of a part read back from its STL (float32 coordinates) against the manifest's, relative.
STL_VOLUME_RTOL = 1e-5
#: Volume a mould part and the exported solid, both read back from float32 STLs, may share, relative to the
#: solid's (their coordinates round at ~1e-6 mm: measured ~1e-7 mm3 on the demo's ~2,100 mm3).
STL_OVERLAP_RTOL = 1e-6


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


@pytest.fixture(scope="module")
def hollow_mould(tmp_path_factory) -> tuple[str, Path]:
    """`softdesign mould` on the demo built hollow (1 mm wall, 1.5 mm port, 8 mm margin), run once for the two tests
    that read it: its terminal output and its build folder (only read; a test that writes into it copies it)."""
    folder = tmp_path_factory.mktemp("hollow-mould")
    out = folder / "build"
    text = run("mould", str(demo_case(folder, wall_mm=1.0, port_mm=1.5, mould={"margin_mm": 8})), "--out", str(out))
    return text, out


@pytest.mark.slow
def test_demo_hollow_mould_is_written_listed_and_checked(hollow_mould, tmp_path):
    text, out = hollow_mould
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
    # the report's fabrication section shows it, with the parts' checks in its caption (in a copy: the report is
    # written into the build folder, which the next test reads as the mould command left it)
    out = shutil.copytree(out, tmp_path / "build")
    report = write_report(out, ReportOptions(gif_frames=3, view_frames=3, q_samples=5))  # not the frames' sampling
    page = report.page.read_text()
    assert 'id="fabrication"' in page and 'src="mould.png"' in page and "core: removable" in page.lower()
    with Image.open(report.page.parent / "mould.png") as image:
        assert image.size == EXPECTED_SIZES["mould.png"]


@pytest.mark.slow
def test_a_mould_changes_only_the_cuts_it_must_and_adds_its_parts(tmp_path):
    # with a mould, fit.end_cut: auto turns each cut into the parting plane (a lean out of it is an undercut):
    # every stage before the fit is untouched, the fit's record says by how much each cut was turned, and the
    # mould's own files are added
    plain, moulded = tmp_path / "plain", tmp_path / "moulded"
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    run("build", str(demo_case(tmp_path / "a")), "--out", str(plain), "--jobs", "1")
    run("build", str(demo_case(tmp_path / "b", mould={"up": "tip"})), "--out", str(moulded), "--jobs", "1")
    before, after = files(plain), files(moulded)
    assert set(after) - set(before) == {"mould/summary.json", "meshes/mould/half_a.stl", "meshes/mould/half_b.stl"}
    for stage in ("ingest/", "blend/", "links/", "kinematics.json"):
        kept = [k for k in before if k.startswith(stage) and not k.endswith("stage.json")]
        assert kept and all(before[k] == after[k] for k in kept), stage
    free = json.loads((plain / "fit" / "summary.json").read_text())["end_cut"]
    cuts = json.loads((moulded / "fit" / "summary.json").read_text())["end_cut"]
    for end, c in cuts.items():
        assert c["applied"] and free[end]["applied"] and c["parting_lean_deg"] > 0
        assert "turned into the mould's parting plane" in c["reason"]
        assert c["normal_local"] != free[end]["normal_local"]
    assert mould_figure_png(plain) is None


@pytest.mark.slow
def test_demo_hollow_mould_casts_the_cut_body(hollow_mould):
    # the default fit.end_cut (auto) cuts the demo's tilted caps: the mould is built around that cut body, its
    # checks pass, the cast equals the export's q = 0 volume expected from the surface integral plus the cuts'
    # wedges, and no mould part enters the exported q = 0 solid (a square-ended body would: ~1.6 mm3 per part)
    _, out = hollow_mould
    cuts = json.loads((out / "fit" / "summary.json").read_text())["end_cut"]
    assert all(c["applied"] for c in cuts.values())
    block = json.loads((out / "manifest.json").read_text())["metrics"]["mould"]
    assert block["cavity"]["ok"] and block["disjoint"]["ok"] and all(p["ok"] for p in block["pull"].values())
    start = json.loads((out / "export" / "summary.json").read_text())["meshes"]["meshes/q_0.000.stl"]
    assert block["cavity"]["cast_mm3"] == pytest.approx(start["volume_expected_mm3"], rel=CAVITY_RTOL)
    solid = manifold_from_mesh(*read_mesh(out / "meshes" / "q_0.000.stl"), "q=0")[0]
    for part in ("half_a", "half_b", "core"):
        mould_part = manifold_from_mesh(*read_mesh(out / "meshes" / "mould" / f"{part}.stl"), part)[0]
        assert (solid ^ mould_part).volume() <= STL_OVERLAP_RTOL * solid.volume(), part


def test_a_mould_with_cap_plane_cuts_is_refused_before_building(tmp_path):
    case = demo_case(tmp_path, mould={}, fit={"end_cut": "cap_plane"})
    result = runner.invoke(app, ["validate", str(case)])
    assert result.exit_code == 2 and "cannot be drawn off a cap plane" in result.output, result.output


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
