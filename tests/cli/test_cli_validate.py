"""`softdesign validate` refuses, with exit 2 and a located message, what a build is bound to fail on."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.meshing.checks import MIN_ANGULAR_COUNT, VOLUME_RTOL
from softdesign.meshing.volume import polygon_area_ratio
from softdesign.pipeline.layout import EXPORT_SUMMARY
from tests.helpers.paths import DEMO, REPO

runner = CliRunner()


def demo_case(folder: Path, name: str = "demo", **sections) -> Path:
    """configs/demo.yaml with absolute input paths and ``sections`` merged in (a None value drops the key)."""
    case = yaml.safe_load(DEMO.read_text())
    for key in ("centerline", "surface"):
        case["final"][key] = str((DEMO.parent / case["final"][key]).resolve())
    for key, value in sections.items():
        if value is None:
            case.pop(key, None)
        elif isinstance(value, dict) and isinstance(case.get(key), dict):
            case[key] = {**case[key], **value}
        else:
            case[key] = value
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump(case, sort_keys=False))
    return path


def line_of(path: Path, key: str) -> int:
    """1-based line of the top-level ``key:`` in a case file."""
    return next(i for i, line in enumerate(path.read_text().splitlines(), 1) if line.startswith(f"{key}:"))


def refused(case: Path) -> str:
    result = runner.invoke(app, ["validate", str(case)])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    return result.output


ARC = {"kind": "arc", "bend_radius_mm": 80.0}


def test_frenet_with_a_straight_initial_shape_is_refused_at_the_frames_line(tmp_path):
    case = demo_case(tmp_path, frames="frenet")  # the demo: initial.kind straight, end_straight_mm 0
    output = refused(case)
    assert f"{case}:{line_of(case, 'frames')}: frames: frenet needs curvature everywhere" in output
    assert "initial.kind: straight makes the q = 0 shape a straight line" in output
    assert "Use frames: rmf" in output and "initial.kind: arc" in output
    assert "end_straight_mm" not in output  # only what is wrong is named


def test_frenet_with_straightened_ends_is_refused_naming_end_straight_mm(tmp_path):
    case = demo_case(tmp_path, frames="frenet", initial=ARC, resample={"end_straight_mm": 1.5})
    output = refused(case)
    assert "resample.end_straight_mm: 1.5 makes the last 1.5 mm at both ends of every shape straight" in output
    assert "set resample.end_straight_mm: 0" in output
    assert "initial.kind" not in output


def test_the_default_end_straight_mm_is_named_as_the_default(tmp_path):
    case = demo_case(tmp_path, frames="frenet", initial=ARC, resample=None)  # resample.end_straight_mm: 2 by default
    output = refused(case)
    assert "resample.end_straight_mm: 2 (the default)" in output


def test_frenet_with_curvature_everywhere_and_rmf_with_straight_parts_are_valid(tmp_path):
    for name, sections in {
        "frenet_arc": {"frames": "frenet", "initial": ARC},
        "rmf_straight": {"frames": "rmf", "resample": {"end_straight_mm": 2.0}},
    }.items():
        result = runner.invoke(app, ["validate", str(demo_case(tmp_path, name, **sections))])
        assert result.exit_code == 0, result.output
        assert "valid" in result.output


def test_build_stops_at_validation_before_any_stage_runs(tmp_path):
    case = demo_case(tmp_path, frames="frenet")
    out = tmp_path / "out"
    result = runner.invoke(app, ["build", str(case), "--out", str(out)])
    assert result.exit_code == 2, result.output
    assert "frames: frenet needs curvature everywhere" in result.output
    assert not out.exists()


def test_min_angular_count_is_the_fewest_sides_the_volume_check_can_accept():
    assert 1.0 - polygon_area_ratio(MIN_ANGULAR_COUNT) <= VOLUME_RTOL < 1.0 - polygon_area_ratio(MIN_ANGULAR_COUNT - 1)
    assert MIN_ANGULAR_COUNT == 37  # the figure the docstring and README quote


def test_angular_count_below_the_minimum_is_refused_by_validate(tmp_path):
    case = demo_case(tmp_path, export={"angular_count": MIN_ANGULAR_COUNT - 1})
    output = refused(case)
    assert f"export.angular_count must be >= {MIN_ANGULAR_COUNT}, got {MIN_ANGULAR_COUNT - 1}" in output
    assert "cannot pass the mesh volume check" in output


def test_angular_count_at_the_minimum_builds_a_round_body_that_passes_the_volume_check(tmp_path):
    # q = 0 with initial.radius_mm is a straight round tube: the mesh holds exactly the polygon's share
    case = demo_case(tmp_path, initial={"kind": "straight", "radius_mm": 3.0},
                     export={"q": [0], "angular_count": MIN_ANGULAR_COUNT, "spacing_mm": 1.0})
    out = tmp_path / "out"
    result = runner.invoke(app, ["build", str(case), "--out", str(out), "--jobs", "1"])
    assert result.exit_code == 0, result.output
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["metrics"]["export"]["resolution"]["angular_count"] == MIN_ANGULAR_COUNT
    (mesh,) = [o for o in manifest["outputs"] if o["path"] == "meshes/q_0.000.stl"]
    figures = json.loads((out / EXPORT_SUMMARY).read_text())["meshes"]["meshes/q_0.000.stl"]
    # the integral is exact for a round tube, so the whole difference is the polygon's
    np.testing.assert_allclose(figures["volume_rel_error"], polygon_area_ratio(MIN_ANGULAR_COUNT) - 1.0,
                               rtol=0, atol=1e-6)
    assert abs(figures["volume_rel_error"]) <= VOLUME_RTOL and mesh["watertight"] is True


@pytest.mark.parametrize("path", sorted(REPO.glob("configs/**/*.yaml")), ids=lambda p: p.stem)
def test_every_shipped_config_still_validates(path):
    result = runner.invoke(app, ["validate", str(path)])
    assert result.exit_code == 0, result.output
