"""``final.centerline: auto`` end to end: the demo and the VMTK aorta built from their surfaces alone."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.config import load_case
from softdesign.errors import ConfigError
from softdesign.io.centerline import read_centerline_network
from softdesign.pipeline.layout import INGEST_CENTERLINE

runner = CliRunner()
DEMO_SURFACE = Path(__file__).resolve().parents[2] / "data" / "demo" / "surface.stl"


def _build(folder: Path, surface: Path, **final) -> tuple[dict, Path, str]:
    case = {"name": "auto", "final": {"centerline": "auto", "surface": str(surface), **final},
            "links": {"count": 2}, "export": {"q": [0.0, 1.0]}}
    path = folder / "auto.yaml"
    path.write_text(yaml.safe_dump(case, sort_keys=False))
    out = folder / "build"
    result = runner.invoke(app, ["build", str(path), "--out", str(out), "--jobs", "1"])
    assert result.exit_code == 0, result.output
    return json.loads((out / "manifest.json").read_text()), out, result.output


def test_auto_needs_a_surface(tmp_path):
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump({"name": "x", "final": {"centerline": "auto"}}))
    with pytest.raises(ConfigError, match="centerline: auto extracts the centerline from the surface: give surface"):
        load_case(path)


@pytest.mark.slow
def test_demo_builds_from_its_surface_alone_and_is_cached(tmp_path):
    manifest, out, _ = _build(tmp_path, DEMO_SURFACE)
    # the surface is the build's one input; the extracted centerline an output, listed with its hash
    assert [Path(i["path"]).name for i in manifest["inputs"]] == ["surface.stl"]
    listed = {o["path"]: o["sha256"] for o in manifest["outputs"]}
    assert INGEST_CENTERLINE in listed
    extracted = manifest["metrics"]["ingest"]["centerline"]["extracted"]
    assert extracted["endpoints"] == "planar caps" and len(extracted["outlets_mm"]) == 2
    network = read_centerline_network(out / INGEST_CENTERLINE)
    assert len(network.polylines) == 2 and all(p.radius is not None for p in network.polylines)
    # the sample's main vessel runs from (0, 0, 0) to (0, 0, 90): the largest cap is the inlet
    # the inlet cap's centre (issue 29: the path is continued from the pole, one radius (3.68 mm) in, to it)
    assert np.linalg.norm(network.polylines[0].points[0]) < 0.5
    assert all(min(ends) > 2.0 for ends in extracted["continued_mm"])
    assert all(o["watertight"] for o in manifest["outputs"] if o["path"].startswith("meshes/"))
    again = runner.invoke(app, ["build", str(tmp_path / "auto.yaml"), "--out", str(out), "--jobs", "1"])
    assert again.exit_code == 0 and "ingest: unchanged, skipped" in again.output
    assert json.loads((out / "manifest.json").read_text())["outputs"] == manifest["outputs"]


@pytest.mark.slow
@pytest.mark.parametrize("surface", ["aorta-surface.stl", "aorta-surface-open-ends.stl"])
def test_aorta_builds_from_its_surface_alone(tmp_path, aorta_dir, surface):
    manifest, _, output = _build(tmp_path, aorta_dir / surface)
    # the build says how far each end was continued past the Voronoi diagram (issue 29)
    assert "the ends continued straight past the Voronoi diagram" in output
    continued = manifest["metrics"]["ingest"]["centerline"]["extracted"]["continued_mm"]
    assert len(continued) == 2 and all(min(ends) > 2.0 for ends in continued)
    length = manifest["metrics"]["ingest"]["centerline"]["selected_length_mm"]
    assert 60.0 < length < 100.0  # VMTK's paths are 78 and 76 mm
    assert all(o["watertight"] for o in manifest["outputs"] if o["path"].startswith("meshes/"))
