"""A build whose kept-point figures read well while much of the wall was dropped says so (issue 29, item 1)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.fitting.coverage import ALL_WALL_P95_FRACTION, FLAG_LONG_STRETCH, FLAG_P95
from tests.helpers.cases import write_case
from tests.helpers.vessels import straight_tube

pytestmark = pytest.mark.slow

runner = CliRunner()
R, LENGTH = 3.0, 40.0
#: The inlet's first BULGE_MM bulge on the +x side to BULGE_RHO, past twice the inscribed radius: the selection
#: drops them as outliers, and the inlet is held at the inscribed radius there.
BULGE_MM, BULGE_RHO = 12.0, 7.0


def write_bulged_vessel(folder: Path) -> tuple[Path, Path]:
    import trimesh

    from softdesign.io.polylines_vtp import write_polylines_vtp

    vertices, faces = straight_tube(R, LENGTH + 2.0, 0.5)
    vertices = vertices - [0.0, 0.0, 1.0]  # the wall runs 1 mm past both ends of the centerline
    out = (vertices[:, 2] < BULGE_MM) & (vertices[:, 0] > 0.0)
    vertices[out, :2] *= BULGE_RHO / R
    z = np.linspace(0.0, LENGTH, 81)
    folder.mkdir(parents=True, exist_ok=True)
    centerline = write_polylines_vtp(folder / "centerline.vtp", [np.column_stack([0 * z, 0 * z, z])],
                                     {"MaximumInscribedSphereRadius": [np.full(len(z), R)]})
    surface = folder / "surface.stl"
    trimesh.Trimesh(vertices, faces, process=False).export(surface)
    return centerline, surface


def test_dropped_wall_is_measured_flagged_and_warned_about_by_the_build(tmp_path: Path):
    centerline, surface = write_bulged_vessel(tmp_path / "bulge")
    case = write_case(tmp_path, "bulge", final={"centerline": str(centerline), "surface": str(surface)})
    result = runner.invoke(app, ["build", str(case), "--out", str(tmp_path / "out"), "--jobs", "1"])
    assert result.exit_code == 0, result.output
    fit = json.loads((tmp_path / "out" / "manifest.json").read_text())["metrics"]["fit"]
    # the kept points are on the body; the bulge's wall, dropped, is ~4 mm off it: the all-wall figures say so
    assert fit["max_mm"] == fit["kept"]["max_mm"] < 0.05
    assert fit["all_wall"]["p95_mm"] > ALL_WALL_P95_FRACTION * R and fit["all_wall"]["max_mm"] > 3.5
    assert fit["coverage"]["fraction"] < 0.95 and fit["coverage"]["own_wall_points"] == fit["all_wall"]["count"]
    [held] = [s for s in fit["coverage"]["unseen_stretches"] if s["held"]]
    assert held["from_mm"] == 0.0 and held["length_mm"] > 2 * R
    assert fit["flags"] == [FLAG_LONG_STRETCH, FLAG_P95]
    assert "true distance, all of the path's own wall" in result.output
    assert "warning: fit: no wall seen all round over" in result.output
    assert "the kept-point figures do not" in result.output
