"""A case `softdesign init` writes builds: the demo's files and the real VMTK aorta, capped and open, with and
without its centerline (issue 34)."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from tests.helpers.paths import REPO

#: Whole builds: `make test-fast` leaves them out.
pytestmark = pytest.mark.slow

runner = CliRunner()


def _init_and_build(tmp_path, *files) -> dict:
    case = tmp_path / "case.yaml"
    made = runner.invoke(app, ["init", *map(str, files), "--output", str(case)])
    assert made.exit_code == 0, made.output
    built = runner.invoke(app, ["build", str(case), "--out", str(tmp_path / "build"), "--jobs", "1"])
    assert built.exit_code == 0, built.output
    manifest = json.loads((tmp_path / "build" / "manifest.json").read_text())
    meshes = [o for o in manifest["outputs"] if o["path"].startswith("meshes/q_")]
    assert len(meshes) == 3 and all(m["watertight"] for m in meshes)
    return manifest


def test_init_case_builds_for_the_demo_files(tmp_path):
    demo = REPO / "data" / "demo"
    manifest = _init_and_build(tmp_path, demo / "surface.stl", demo / "centerline.vtp")
    assert "feasibility" in manifest["metrics"]  # a material is declared: the build gives a verdict


@pytest.mark.parametrize("surface", ["aorta-surface.stl", "aorta-surface-open-ends.stl"])
@pytest.mark.parametrize("with_centerline", [True, False], ids=["centerline", "auto"])
def test_init_case_builds_for_the_vmtk_aorta(tmp_path, aorta_dir, surface, with_centerline):
    files = [aorta_dir / surface] + ([aorta_dir / "aorta-centerline.vtp"] if with_centerline else [])
    manifest = _init_and_build(tmp_path, *files)
    assert manifest["case"]["units"] == "mm"
