"""The swept volume mesher on the chambered demo with five links (the most the actuation defaults' 0.2 mm walls
allow on it; every section's chambers in the one cross-section, neighbouring sections' 0.032 mm apart): every
tetrahedron positive, the volume within 0.5 % of the surface mesh's, the named sets covering the boundary once,
each chamber's surface closed with its analytic volume (and the same on the real aorta); and a layout whose
chambers cross in that cross-section refused with exit 2 before the export."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import meshio
import numpy as np
import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.io.formats import read_mesh
from softdesign.io.volume_formats import read_volume_mesh
from softdesign.meshing.topology import mesh_topology
from softdesign.meshing.volume_mesh.tet_quality import boundary_faces, tet_volumes
from tests.e2e.test_actuation_build import demo_case

runner = CliRunner()
pytestmark = pytest.mark.slow
#: the issue's bounds: the mesh within 0.5 % of the surface mesh's volume, a chamber's surface within 1 % of its own
VOLUME_RTOL, CHAMBER_RTOL = 0.005, 0.01


def _case(folder: Path, actuation: dict, links: int) -> Path:
    import yaml

    path = demo_case(folder, actuation, volume_mesh={"q": [0.0, 1.0]})
    data = yaml.safe_load(path.read_text())
    data["links"] = {"count": links}
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _keys(faces: np.ndarray) -> list[tuple[int, ...]]:
    return sorted(map(tuple, np.sort(faces, axis=1).tolist()))


def test_five_chambered_links_mesh(tmp_path: Path) -> None:
    out = tmp_path / "build"
    result = runner.invoke(app, ["build", str(_case(tmp_path, {}, 5)), "--out", str(out), "--jobs", "1"])
    assert result.exit_code == 0, result.output
    check_chambered(out, 5)


def test_five_chambered_links_of_the_aorta_mesh(tmp_path: Path, aorta_dir: Path) -> None:
    """The real aorta (VMTK) with the actuation defaults on five links, the same checks."""
    import yaml

    case = {"name": "aorta", "final": {"centerline": str(aorta_dir / "aorta-centerline.vtp"),
                                       "surface": str(aorta_dir / "aorta-surface.stl"), "path": 0},
            "links": {"count": 5}, "export": {"q": [0, 1], "volume_mesh": {"q": [0, 1]}}, "actuation": {}}
    path = tmp_path / "aorta.yaml"
    path.write_text(yaml.safe_dump(case, sort_keys=False))
    out = tmp_path / "build"
    result = runner.invoke(app, ["build", str(path), "--out", str(out), "--jobs", "1"])
    assert result.exit_code == 0, result.output
    check_chambered(out, 5)


def check_chambered(out: Path, sections: int) -> None:
    """Every tet positive and the volume within 0.5 % at each q, every chamber's wall and feed inlet named, the
    boundary named once, each chamber's surface closed with its analytic volume within 1 % (q = 0, straight)."""
    summary = json.loads((out / "volume_mesh" / "summary.json").read_text())
    names = summary["surfaces"]
    # sections and chambers counted from 1 at the base, as actuation.csv and simulate --section count them
    assert {f"s{i}_c{j}_wall" for i in range(1, sections + 1) for j in range(1, 4)} <= set(names)
    assert {f"s{i}_c{j}_feed_inlet" for i in range(1, sections + 1) for j in range(1, 4)} <= set(names)
    assert not any(n.startswith("s0_") or "_c0_" in n for n in names)
    places = [w for row in summary["per_q"] for w in row["worst"].values()] + [
        e for e in summary["morph"].values() if isinstance(e, dict)]
    assert places and all(1 <= e["section"] <= sections for e in places)
    for row in summary["per_q"]:
        assert row["min_tet_volume_mm3"] > 0 and abs(row["volume_rel_error"]) <= VOLUME_RTOL
    volume = out / "meshes" / "volume"
    for q in ("0.000", "1.000"):
        points, tets = read_volume_mesh(volume / f"q_{q}.vtu")
        assert tet_volumes(points, tets).min() > 0
        vtu = meshio.read(volume / f"q_{q}.vtu")
        surface = vtu.cell_data_dict["surface"]["triangle"]
        solid = np.isin(surface, [names.index(n) for n in names if not n.endswith(("_inlet", "_outlet"))])
        assert _keys(vtu.cells_dict["triangle"][solid]) == _keys(boundary_faces(tets))  # every face named once
    layout = json.loads((out / "actuation" / "summary.json").read_text())["layout"]
    rows = [r for r in csv.DictReader((out / "actuation.csv").open()) if float(r["q"]) == 0.0]
    # the straight q = 0 body's length: its sections' arcs (l is arc length over it)
    body_mm = sum(float(r["arc_length_mm"]) for r in rows if r["chamber"] == "1")
    for chamber in layout["chambers"]:
        name = f"s{chamber['section']}_c{chamber['chamber']}"  # the actuation stage's numbers, as they are
        v, f = read_mesh(volume / f"{name}_q_0.000.stl")
        topology = mesh_topology(v, f)
        assert topology.watertight and topology.winding_consistent
        feed = next(x for x in layout["feeds"] if (x["section"], x["chamber"]) == (chamber["section"],
                                                                                  chamber["chamber"]))
        expected = np.pi * body_mm * ((chamber["diameter_mm"] / 2) ** 2 * (chamber["l_end"] - chamber["l_start"])
                                      + (feed["diameter_mm"] / 2) ** 2 * chamber["l_start"])
        np.testing.assert_allclose(topology.volume, expected, rtol=CHAMBER_RTOL)


def test_chambers_crossing_in_the_cross_section_refused_before_the_export(tmp_path: Path) -> None:
    """1 mm chambers at 2 mm on five links: the layout's walls hold (chamber-feed 0.232 mm), but neighbouring
    sections' chambers are 2 x 2 sin 12 deg - 1 = -0.17 mm apart in the one cross-section."""
    out = tmp_path / "build"
    case = _case(tmp_path, {"diameter_mm": 1.0, "feed_diameter_mm": 0.2}, 5)
    result = runner.invoke(app, ["build", str(case), "--out", str(out), "--jobs", "1"])
    assert result.exit_code == 2, result.output
    text = " ".join(result.output.split())
    assert "cross in the swept mesher's cross-section" in text
    assert "actuation.diameter_mm <=" in text and "links.count <= 4" in text and "mesher: ftetwild" in text
    assert not (out / "volume_mesh").exists() and not (out / "export").exists()
    assert "Traceback" not in result.output
