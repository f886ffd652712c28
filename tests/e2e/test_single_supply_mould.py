"""`export.mould` on single-supply devices (issue 41): one lost wax core of the supply line, chambers and series
channels, the axis thread's holes, and the mould's own checks, on the demo and the real VMTK aorta."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.io.formats import read_mesh
from softdesign.meshing.checks import inspect_mesh
from softdesign.meshing.mould.checks import CAVITY_RTOL
from tests.helpers.cases import case_from, write_case
from tests.helpers.paths import REPO

#: Whole builds with a mould: `make test-fast` leaves them out.
pytestmark = pytest.mark.slow

runner = CliRunner()


def _build(case: Path, out: Path) -> dict:
    result = runner.invoke(app, ["build", str(case), "--out", str(out), "--jobs", "1"])
    assert result.exit_code == 0, result.output
    return json.loads((out / "manifest.json").read_text())


def _check_single_mould(out: Path, manifest: dict) -> None:
    mould = manifest["metrics"]["mould"]
    assert set(mould["parts"]) == {"half_a", "half_b", "core_plate", "core"}
    assert all(p["ok"] for p in mould["parts"].values())
    assert mould["cavity"]["ok"] and mould["cavity"]["rel_difference"] <= CAVITY_RTOL and mould["disjoint"]["ok"]
    assert all(p["ok"] and p["against_pull"] == 0 and p["blocked_rays"] == 0 for p in mould["pull"].values())
    core = mould["core"]
    assert (core["process"], core["cores"], core["material"]) == ("lost-core", 1, "wax")
    thread = json.loads((out / "actuation" / "summary.json").read_text())["reinforcement"]["thread"]
    assert mould["thread"]["diameter_mm"] == thread["diameter_mm"]
    assert mould["thread"]["hole_mm"] > thread["diameter_mm"]
    # the one core is one closed body: the supply line, every chamber and every channel joined
    report = inspect_mesh(*read_mesh(out / "meshes" / "mould" / "core.stl"))
    assert report.watertight and report.bodies == 1 and report.euler == 2
    sheet = (out / "fabrication.md").read_text()
    assert "one lost wax core" in sheet and "Wax rather than a water-soluble print" in sheet
    assert manifest["verdict"]["feasible"] is True


def test_the_single_supply_demo_is_cast_on_one_lost_core(tmp_path: Path) -> None:
    case = case_from(tmp_path, REPO / "configs" / "actuator.yaml", {"export": {"q": [0.0, 1.0], "mould": {}}})
    out = tmp_path / "build"
    _check_single_mould(out, _build(case, out))


def test_the_vmtk_aorta_as_a_single_supply_device_is_cast_on_one_lost_core(tmp_path: Path, aorta_dir: Path) -> None:
    # the demo's resample and fit keys are the demo's; the aorta builds at the defaults
    case = write_case(tmp_path, "aorta-single",
                      final={"centerline": str(aorta_dir / "aorta-centerline.vtp"),
                             "surface": str(aorta_dir / "aorta-surface.stl"), "path": 0},
                      blend="pcc", design={"tolerance_mm": 1.0}, actuation={"supply": "single", "end_wall_mm": 1.5},
                      export={"q": [0.0, 1.0], "mould": {}}, material={"name": "ecoflex-00-30"})
    out = tmp_path / "build"
    _check_single_mould(out, _build(case, out))
