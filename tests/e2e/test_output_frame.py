"""export.frame: base puts the q = 0 body's base at the origin with z along its axis, the move recorded (issue 34)."""

from __future__ import annotations

import json

import numpy as np
import pytest
import trimesh
from typer.testing import CliRunner

from softdesign.cli import app
from tests.helpers.attacks import demo_case

pytestmark = pytest.mark.slow

runner = CliRunner()
#: A rigid move of a float mesh: the same figures to round-off, mm / mm^3.
RIGID_TOL_MM = 1e-9


def test_the_base_frame_puts_the_straight_body_on_the_z_axis_and_records_the_move(tmp_path):
    outs = {}
    for frame in ("patient", "base"):
        (tmp_path / frame).mkdir()
        case = demo_case(tmp_path / frame, export={"frame": frame, "mould": {}})
        outs[frame] = tmp_path / frame / "build"
        result = runner.invoke(app, ["build", str(case), "--out", str(outs[frame]), "--jobs", "1"])
        assert result.exit_code == 0, result.output
    patient = trimesh.load(outs["patient"] / "meshes" / "q_0.000.stl")
    base = trimesh.load(outs["base"] / "meshes" / "q_0.000.stl")
    # the straight q = 0 body: its axis is z, its base at z = 0, centred on the axis (scanner x was 213-240 mm)
    lo, hi = base.bounds
    assert abs(lo[2]) < 0.5 and hi[2] > 50.0
    assert np.all(np.abs(0.5 * (lo[:2] + hi[:2])) < 1.0)
    # the same body, moved rigidly: the manifest's pose maps one onto the other
    manifest = json.loads((outs["base"] / "manifest.json").read_text())
    record = manifest["metrics"]["export"]["frame"]
    assert record["name"] == "base"
    pose = np.array(record["output_from_patient"])
    moved = patient.vertices @ pose[:3, :3].T + pose[:3, 3]
    np.testing.assert_allclose(moved, base.vertices, rtol=0, atol=1e-4)  # STL stores float32
    np.testing.assert_allclose(np.array(record["patient_from_output"]) @ pose, np.eye(4), rtol=0, atol=1e-12)
    assert base.volume == pytest.approx(patient.volume, rel=1e-6) and base.is_watertight
    # the mould's parts move with it
    half = trimesh.load(outs["base"] / "meshes" / "mould" / "half_a.stl")
    half_patient = trimesh.load(outs["patient"] / "meshes" / "mould" / "half_a.stl")
    np.testing.assert_allclose(half_patient.vertices @ pose[:3, :3].T + pose[:3, 3], half.vertices, rtol=0,
                               atol=1e-4)
    # the mould's parting frame moved with its parts: the report's exploded view reads both (it failed when not)
    parting = manifest["metrics"]["mould"]["frame"]
    patient_manifest = json.loads((outs["patient"] / "manifest.json").read_text())
    origin = np.array(patient_manifest["metrics"]["mould"]["frame"]["origin"])
    np.testing.assert_allclose(parting["origin"], origin @ pose[:3, :3].T + pose[:3, 3], rtol=0, atol=1e-9)
    report = runner.invoke(app, ["report", str(outs["base"]), "--jobs", "1"])
    assert report.exit_code == 0, report.output
    default = json.loads((outs["patient"] / "manifest.json").read_text())["metrics"]["export"]["frame"]
    assert default["name"] == "patient" and np.allclose(default["output_from_patient"], np.eye(4))
