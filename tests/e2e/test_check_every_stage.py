"""`softdesign check` catches a 1 % change in any stage's figures (issue 35 item 2).

One real build of the demo with a design, a mould and a material (coarse, a
few seconds), copied as its own reference: it passes.  Then, one stage at a
time, a figure of that stage in the copy is moved by 1 % (a count by one, a
flag turned) and check must fail on that stage and nothing else.  The demo does not ask for a volume mesh
(fTetWild takes minutes and is not deterministic), so the volume-mesh figures
are a block of the manifest's shape added to both sides; the comparison is
the same table-driven code either way.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.io.formats import read_mesh, write_mesh
from softdesign.pipeline.api import build_through
from tests.helpers.paths import REPO

pytestmark = pytest.mark.slow
runner = CliRunner()
#: The injected change.
CHANGE = 1.01

#: A volume mesh's figures as the stage writes them (metrics.volume_mesh of a demo build at size_mm 3).
VOLUME_MESH = {"requested": True, "per_q": [{"q": 0.0, "volume_mm3": 4289.98, "body_volume_mm3": 4313.12,
                                            "boundary_watertight": True, "boundary_shells": 1}]}


@pytest.fixture(scope="module")
def reference(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("every-stage")
    case = yaml.safe_load((REPO / "configs" / "demo.yaml").read_text(encoding="utf-8"))
    for key in ("centerline", "surface"):
        case["final"][key] = str((REPO / "configs" / case["final"][key]).resolve())
    case["resample"]["spacing_mm"] = 1.0
    case["fit"] = {"knot_spacing_mm": 3.0, "angular_intervals": 12}
    case["export"] = {"q": [0, 1], "spacing_mm": 1.0, "angular_count": 40, "mould": {}}
    case["material"] = {"name": "dragon-skin-30"}
    case["design"] = {"tolerance_mm": 1.0}  # the design stage's figures (metrics.design); the blend stays linear
    (root / "demo.yaml").write_text(yaml.safe_dump(case), encoding="utf-8")
    build_through(root / "demo.yaml", root / "reference")
    edit_manifest(root / "reference", lambda m: m["metrics"].update(volume_mesh=json.loads(json.dumps(VOLUME_MESH))))
    return root / "reference"


def edit_manifest(folder: Path, edit: Callable[[dict], None]) -> None:
    manifest = json.loads((folder / "manifest.json").read_text(encoding="utf-8"))
    edit(manifest)
    (folder / "manifest.json").write_text(json.dumps(manifest), encoding="utf-8")


def scale_mesh(folder: Path) -> None:
    vertices, faces = read_mesh(folder / "meshes" / "q_1.000.stl")
    write_mesh(folder / "meshes" / "q_1.000.stl", vertices * CHANGE, faces)


def scale_kinematics(folder: Path) -> None:
    document = json.loads((folder / "kinematics.json").read_text(encoding="utf-8"))
    transform = document["poses"][-1]["links"][1]["transform"]
    for row in transform[:3]:
        row[3] *= CHANGE
    (folder / "kinematics.json").write_text(json.dumps(document), encoding="utf-8")


def moved(value: Any) -> Any:
    """A number by CHANGE, a count by one, a flag turned."""
    if isinstance(value, bool):
        return not value
    return value + 1 if isinstance(value, int) else value * CHANGE


def move(block: str, *path: str | int) -> Callable[[Path], None]:
    """Move the figure at ``metrics.<block>/<path>`` of a build folder's manifest (:func:`moved`)."""

    def edit(manifest: dict) -> None:
        node = manifest["metrics"][block]
        for key in path[:-1]:
            node = node[key]
        node[path[-1]] = moved(node[path[-1]])

    return lambda folder: edit_manifest(folder, edit)


#: injection -> (how one stage's figure is moved, the check's item that must fail): every stage's own figures
INJECTIONS: dict[str, tuple[Callable[[Path], None], str]] = {
    "meshes": (scale_mesh, "meshes/q_1.000.stl"),
    "kinematics.json": (scale_kinematics, "kinematics"),
    "kinematics.arc_check": (move("kinematics", "arc_check", "max_deviation_mm", 0), "kinematics"),
    "links": (move("links", "breaks", 1), "links"),
    "blend": (move("blend", "final_path", "length_mm"), "blend"),
    "fit": (move("fit", "rms_mm"), "fit"),
    "feasibility": (move("feasibility", "per_q", -1, "stretch_max"), "feasibility"),
    "design.tip_error_mm": (move("design", "tip_error_mm"), "design"),
    "design.tip_error_deg": (move("design", "tip_error_deg"), "design"),
    "design.chain_max_deviation_mm": (move("design", "chain_max_deviation_mm"), "design"),
    "design.breaks": (move("design", "breaks", 1), "design"),
    "design.links": (move("design", "links"), "design"),
    "design.meets_tolerance": (move("design", "meets_tolerance"), "design"),
    "mould": (move("mould", "cavity", "cast_mm3"), "mould"),
    "volume_mesh": (move("volume_mesh", "per_q", 0, "volume_mm3"), "volume_mesh"),
}


def failing_items(build: Path, reference: Path) -> tuple[int, set[str], dict]:
    result = runner.invoke(app, ["check", str(build), "--reference", str(reference), "--json", "--failures-only"])
    payload = json.loads(result.stdout)
    return result.exit_code, {f["item"].split(" ")[0] for f in payload["figures"]}, payload


def test_the_build_passes_against_itself_with_every_stage_compared(reference, tmp_path):
    build = Path(shutil.copytree(reference, tmp_path / "build"))
    result = runner.invoke(app, ["check", str(build), "--reference", str(reference), "--json"])
    assert result.exit_code == 0, result.output
    items = {f["item"].split(" ")[0] for f in json.loads(result.stdout)["figures"]}
    assert {"meshes/q_1.000.stl", "kinematics", "links", "blend", "fit", "feasibility", "design", "mould",
            "volume_mesh"} <= items
    design = {f["figure"] for f in json.loads(result.stdout)["figures"] if f["item"] == "design"}
    assert {"designed", "links", "meets_tolerance", "breaks/1", "chain_max_deviation_mm", "tip_error_mm",
            "tip_error_deg"} <= design
    assert any(item.startswith("meshes/mould/") for item in items)  # the mould's parts are meshes too


@pytest.mark.parametrize("stage", sorted(INJECTIONS))
def test_a_one_percent_change_of_any_stages_figures_is_caught(reference, tmp_path, stage):
    build = Path(shutil.copytree(reference, tmp_path / "build"))
    inject, item = INJECTIONS[stage]
    inject(build)
    code, failed, payload = failing_items(build, reference)
    assert code == 1 and failed == {item}, payload["figures"]
    assert all(np.isfinite(f["change"]) for f in payload["figures"] if f["change"] is not None)
