"""Whole builds of bends that turn tighter than the inscribed radius allows (issue 29, item 0).

A real lumen is no circle at a tight bend: its inner side is flatter, so the fitted rho(l, a) there is
smaller than the inscribed radius r, and the body does not fold where ``r * kappa >= 1`` says it must.
The synthetic bend turns 135 degrees with ``r * kappa = 1.2`` on the inscribed radius (the build's smoothed
centerline reaches more), its inner side flattened so that ``rho * kappa_n <= 0.73``: round 3's ingest
refused it ("the centerline turns tighter than the vessel is wide ... expected < 0.7 after regularizing");
now it is warned about and builds, the body within 3 % of the radius from the wall.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.fitting.radius_field import FOLD_FIX_REACH
from tests.helpers.bend_vessels import inner_reach, write_flat_bend_vessel, write_takeoff_vessel
from tests.helpers.cases import write_case
from tests.helpers.robust_vessels import wall_to_body_mm

pytestmark = pytest.mark.slow

runner = CliRunner()
RADIUS = 3.0
#: r * kappa of the turn on the inscribed radius (the real cases that regressed reached 1.19 and 1.22).
INSCRIBED_REACH = 1.2
#: The inner side cut down by 40 % at its middle: rho * kappa_n at most 0.73 on the turn.
FLATTEN = 0.4
#: The q = 1 body's largest true distance from the input wall, as a fraction of the radius (issue 29: 3 %).
WALL_FRACTION = 0.03
#: Wall points this close to an end plane are the open end's rim, which the square-cut body does not reach, mm.
END_RIM_MM = 0.5


def test_a_bend_tighter_than_the_inscribed_radius_with_a_flatter_inner_side_builds_on_the_wall(tmp_path: Path):
    import trimesh

    assert inner_reach(RADIUS, INSCRIBED_REACH / RADIUS, FLATTEN) <= 0.8
    centerline, surface, axis = write_flat_bend_vessel(tmp_path / "bend", RADIUS, INSCRIBED_REACH, 135.0, FLATTEN)
    case = write_case(tmp_path, "bend", final={"centerline": str(centerline), "surface": str(surface)})
    result = runner.invoke(app, ["build", str(case), "--out", str(tmp_path / "out"), "--jobs", "1"])
    assert result.exit_code == 0, result.output
    assert "the centerline turns with r * kappa = " in result.output
    assert "on the inscribed radius 3.000 mm" in result.output
    manifest = json.loads((tmp_path / "out" / "manifest.json").read_text())
    backbone = manifest["metrics"]["ingest"]["backbone"]
    assert backbone["inscribed_reach"] >= INSCRIBED_REACH and backbone["fold_radius"] == "wall"
    assert not backbone["regularized"]  # the wall does not fold: the backbone is the centerline
    assert manifest["metrics"]["fit"]["max_rho_kappa"] < 1.0
    meshes = [o for o in manifest["outputs"] if o["path"].startswith("meshes/")]
    assert len(meshes) == 3 and all(m["watertight"] for m in meshes)
    wall = np.asarray(trimesh.load(surface, process=False).vertices)
    t0, t1 = (axis[1] - axis[0]), (axis[-1] - axis[-2])
    inside = ((wall - axis[0]) @ (t0 / np.linalg.norm(t0)) > END_RIM_MM) & (
        (wall - axis[-1]) @ (t1 / np.linalg.norm(t1)) < -END_RIM_MM)
    body = trimesh.load(tmp_path / "out" / "meshes" / "q_1.000.stl", process=False)
    distance = wall_to_body_mm(wall[inside], (np.asarray(body.vertices), np.asarray(body.faces)))
    assert inside.sum() > 1000
    assert distance.max() < WALL_FRACTION * RADIUS


def test_a_branch_take_off_is_refused_naming_the_body_radius_that_fits_and_building_with_it_succeeds(
        tmp_path: Path):
    # issue 29, items 2 and 6: a 6 mm trunk whose path turns 90 degrees on a 3 mm arc into a 2.5 mm branch, 3 mm
    # from the inlet: round 3 refused it at ingest with advice (resample.end_straight_mm) that does not work
    import re

    import yaml

    centerline, surface = write_takeoff_vessel(tmp_path / "takeoff", 6.0, 2.5, 3.0, 3.0, 90.0)
    final = {"centerline": str(centerline), "surface": str(surface), "path": 1}
    refused = runner.invoke(app, ["build", str(write_case(tmp_path, "takeoff", final=final)),
                                  "--out", str(tmp_path / "out"), "--jobs", "1"])
    assert refused.exit_code == 1
    assert "the tube folds through itself" in refused.output and "tighter than the body is wide" in refused.output
    assert "mm from the inlet" in refused.output and "resample." not in refused.output
    cap = float(re.search(r"set fit\.max_radius_mm: ([0-9.]+)", refused.output).group(1))
    assert 0.5 < cap < 6.0  # thinner than the trunk, not a thread
    fixed = write_case(tmp_path, "fixed", final=final, fit={"max_radius_mm": cap})
    result = runner.invoke(app, ["build", str(fixed), "--out", str(tmp_path / "fixed"), "--jobs", "1"])
    assert result.exit_code == 0, result.output
    manifest = json.loads((tmp_path / "fixed" / "manifest.json").read_text())
    assert yaml.safe_load(fixed.read_text())["fit"]["max_radius_mm"] == cap
    # held at most that wide, the body's rho * kappa stays at the 0.7 the fix states, at every exported q
    assert manifest["metrics"]["fit"]["max_rho_kappa"] <= FOLD_FIX_REACH + 1e-9
    meshes = [o for o in manifest["outputs"] if o["path"].startswith("meshes/")]
    assert len(meshes) == 3 and all(m["watertight"] for m in meshes)
    assert all(row["rho_kappa_max"] < 1.0 for row in manifest["metrics"]["feasibility"]["per_q"])


#: Issue 43, item 2: outside the capped stretch the all-wall p95 is within this fraction of the branch's radius.
OUTSIDE_P95_FRACTION = 0.1


def test_a_take_off_refusal_offers_a_local_cap_that_builds_on_the_wall_outside_it_and_the_path_that_avoids_it(
        tmp_path: Path):
    import re

    import trimesh
    import yaml

    trunk, branch = 6.0, 2.5
    centerline, surface = write_takeoff_vessel(tmp_path / "takeoff", trunk, branch, 3.0, 3.0, 90.0)
    final = {"centerline": str(centerline), "surface": str(surface), "path": 1}
    refused = runner.invoke(app, ["build", str(write_case(tmp_path, "takeoff", final=final)),
                                  "--out", str(tmp_path / "out"), "--jobs", "1"])
    assert refused.exit_code == 1
    text = " ".join(refused.output.split())
    where = re.search(r"it folds at ([0-9.]+)-([0-9.]+) mm from the inlet, where the body's radius goes from "
                      r"([0-9.]+) mm to ([0-9.]+) mm and the path turns ([0-9]+) deg", text)
    assert where is not None, text
    start, stop, before, after, turn = (float(v) for v in where.groups())
    assert start < 3.0 + 3.0 * np.pi / 2 and stop > 3.0  # the turn: 3 mm from the inlet, 4.7 mm of arc
    assert before > 0.8 * trunk and after < branch  # the trunk's radius before, the branch's after
    assert 80.0 <= turn <= 100.0  # a 90 degree take-off, measured on the smoothed centerline
    key = re.search(r"fit: \{local_max_radius: \[(\{.*?\})\]\}", text)
    assert key is not None and text.index(key.group(0)) < text.index("set fit.max_radius_mm:")  # offered first
    assert "does not pass through it (final.path): path 0 (40.0 mm long)" in text  # the trunk avoids the turn
    entry = yaml.safe_load(key.group(1))
    fixed = write_case(tmp_path, "fixed", final=final, fit={"local_max_radius": [entry]})
    result = runner.invoke(app, ["build", str(fixed), "--out", str(tmp_path / "fixed"), "--jobs", "1"])
    assert result.exit_code == 0, result.output
    manifest = json.loads((tmp_path / "fixed" / "manifest.json").read_text())
    fit = manifest["metrics"]["fit"]
    assert fit["max_rho_kappa"] <= FOLD_FIX_REACH + 1e-9
    assert all(o["watertight"] for o in manifest["outputs"] if o["path"].startswith("meshes/"))
    lo, hi = entry["from_mm"] - entry["taper_mm"], entry["to_mm"] + entry["taper_mm"]
    outside = fit["all_wall_outside_local_caps"]
    assert outside["spans_mm"] == [[lo, hi]] and outside["count"] > 1000
    assert outside["p95_mm"] <= OUTSIDE_P95_FRACTION * branch
    # the same, measured here: the branch's wall past the capped stretch (within a tenth of the branch's radius of
    # its tube, off its end cap) against the q = 1 body
    wall = np.asarray(trimesh.load(surface, process=False).vertices)
    body = trimesh.load(tmp_path / "fixed" / "meshes" / "q_1.000.stl", process=False)
    line = _path_points(centerline, 1)
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(line, axis=0), axis=1))])
    nearest = np.argmin(np.linalg.norm(wall[:, None, :] - line[None, :, :], axis=2), axis=1)
    gap = np.linalg.norm(wall - line[nearest], axis=1)
    own = (arc[nearest] > hi) & (arc[nearest] < arc[-1] - END_RIM_MM) & (np.abs(gap - branch) < 0.1 * branch)
    distance = wall_to_body_mm(wall[own], (np.asarray(body.vertices), np.asarray(body.faces)))
    assert own.sum() > 500
    assert np.percentile(distance, 95) <= OUTSIDE_P95_FRACTION * branch


def _path_points(centerline: Path, index: int) -> np.ndarray:
    from softdesign.io.centerline import read_centerline_network

    return np.asarray(read_centerline_network(centerline).polylines[index].points, float)


def test_a_bend_whose_fitted_body_kinks_on_the_linear_blend_builds_at_defaults_on_the_intrinsic_one(tmp_path: Path):
    # issue 43, item 3: an elliptical lumen (semi-axes 3 mm in the turn's plane, 1 mm across: the inscribed radius)
    # turning 160 degrees on an 8 mm radius.  The linear blend's mid-morph centerline reaches r * kappa 0.62 on the
    # inscribed radius (below the 0.8 that check switches at), but its fitted body folds near q = 0.58: round 3's
    # auto kept linear, and a mesh exported there failed.
    from tests.helpers.bend_vessels import write_elliptical_bend_vessel

    centerline, surface = write_elliptical_bend_vessel(tmp_path / "bend", 2.0, 0.5, 8.0, 160.0)
    final = {"centerline": str(centerline), "surface": str(surface)}
    case = write_case(tmp_path, "kink", final=final, export={"q": [0.0, 0.575, 1.0]})
    result = runner.invoke(app, ["build", str(case), "--out", str(tmp_path / "out"), "--jobs", "1"])
    assert result.exit_code == 0, result.output
    manifest = json.loads((tmp_path / "out" / "manifest.json").read_text())
    blend = manifest["metrics"]["blend"]
    assert blend["requested"] == "auto" and blend["mode"] == "intrinsic"
    assert blend["linear_morph"]["max_reach"] < 0.8  # the inscribed radius alone did not see it
    linear, intrinsic = blend["body_morph"]["linear"], blend["body_morph"]["intrinsic"]
    assert linear["max_rho_kappa"] >= 1.0 and 0.0 < linear["q"] < 1.0
    assert intrinsic["max_rho_kappa"] < 1.0
    assert "the fitted body of the linear blend folds mid-morph" in result.output
    meshes = [o for o in manifest["outputs"] if o["path"].startswith("meshes/")]
    assert len(meshes) == 3 and all(m["watertight"] for m in meshes)
    assert all(row["rho_kappa_max"] < 1.0 for row in manifest["metrics"]["feasibility"]["per_q"])
    assert manifest["metrics"]["fit"]["morph_fold"]["max_rho_kappa"] < 1.0
