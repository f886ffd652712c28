"""`export.volume_mesh` end to end on a small hollow tube: files read back by meshio, figures, and the mesher's
crash, hang and failure reported cleanly with the previous build left as it was."""

from __future__ import annotations

import hashlib
import json
import os
import time
from pathlib import Path

import meshio
import numpy as np
import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.io.formats import read_mesh
from softdesign.io.polylines_vtp import write_polylines_vtp
from softdesign.io.volume_formats import read_volume_mesh
from softdesign.meshing.topology import mesh_topology
from softdesign.meshing.volume_mesh.tet_quality import tet_centroids, tet_volumes
from softdesign.pipeline.stages import volume_mesh
from softdesign.report.writer import ReportOptions, write_report
from tests.helpers.cases import write_case
from tests.helpers.vessels import straight_tube

runner = CliRunner()
#: The issue's bound on the tetrahedra's volume against the body's.
VOLUME_RTOL = 0.01
#: Coordinates read back: .vtu keeps 12 significant digits, STL float32 (the chamber), relative to ~10 mm.
VTU_ATOL_MM = 1e-9
STL_ATOL_MM = 1e-5
#: A centroid is in the chamber when its winding number is about 1, outside about 0.
HALF = 0.5


def abort_mesher(vertices, faces, settings):  # noqa: ARG001 - the mesher's signature
    os.abort()


def hanging_mesher(vertices, faces, settings):  # noqa: ARG001
    time.sleep(600)


def failing_mesher(vertices, faces, settings):  # noqa: ARG001
    raise RuntimeError("fTetWild: envelope check failed")


def tube_case(folder: Path, port_mm: float | None = 1.2, **volume) -> Path:
    """A straight hollow tube, radius 2.5 mm, 14 mm long, wall 0.8 mm, port 1.2 mm (None: sealed), meshed at 2 mm
    by fTetWild (the swept mesher's build is tests/e2e/test_swept_volume_mesh_build.py)."""
    vertices, faces = straight_tube(radius=2.5, length=14.0, edge=0.5)
    from softdesign.io.formats import write_mesh

    write_mesh(folder / "surface.stl", vertices, faces)
    z = np.linspace(0.0, 14.0, 29)
    write_polylines_vtp(folder / "centerline.vtp", [np.column_stack([0 * z, 0 * z, z])],
                        {"MaximumInscribedSphereRadius": [np.full(len(z), 2.5)]})
    return write_case(
        folder, "tube", final={"centerline": "centerline.vtp", "surface": "surface.stl"}, links={"count": 2},
        fit={"knot_spacing_mm": 2.0, "angular_intervals": 12},
        export={"q": [0, 1], "wall_mm": 0.8, "spacing_mm": 1.0, "angular_count": 40,
                "volume_mesh": {"mesher": "ftetwild", "size_mm": 2.0, **volume},
                **({} if port_mm is None else {"port_mm": port_mm})},
    )


def winding_numbers(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Generalized winding number of a closed surface at each point (van Oosterom and Strackee's solid angle)."""
    out = np.empty(len(points))
    for start in range(0, len(points), 256):
        p = points[start:start + 256]
        a, b, c = (vertices[faces[:, k]][None] - p[:, None] for k in range(3))
        la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))
        det = np.einsum("pfk,pfk->pf", a, np.cross(b, c))
        den = la * lb * lc + (a * b).sum(2) * lc + (b * c).sum(2) * la + (c * a).sum(2) * lb
        out[start:start + 256] = (2.0 * np.arctan2(det, den)).sum(1) / (4 * np.pi)
    return out


def files(folder: Path) -> dict[str, str]:
    return {p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.mark.parametrize(("volume", "message"), [
    ({"size_mm": 0.01}, "export.volume_mesh.size_mm must be >= 0.05"),
    ({"timeout_s": 0}, "export.volume_mesh.timeout_s must be > 0"),
    ({"timeout_s": 7200}, "export.volume_mesh.timeout_s must be <= 3600"),
    ({"envelope_mm": 2}, "export.volume_mesh.envelope_mm must be <= 1"),
    ({"q": [0, 0.0001]}, "give each q once"),
    ({"q": [1.5]}, "q values must lie in [0, 1]"),
    ({"size": 1}, "did you mean 'size_mm'"),
])
def test_volume_mesh_keys_are_bounded(tmp_path, volume, message):
    result = runner.invoke(app, ["validate", str(tube_case(tmp_path, **volume))])
    assert result.exit_code == 2 and message in result.output, result.output


@pytest.mark.slow
def test_hollow_tube_volume_mesh_files_figures_and_mesher_failures(tmp_path, monkeypatch):
    out = tmp_path / "build"
    case = tube_case(tmp_path)
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)  # where fTetWild would write files of its own
    result = runner.invoke(app, ["build", str(case), "--out", str(out), "--jobs", "1"])
    assert result.exit_code == 0, result.output
    assert "[volume_mesh] ran" in result.output
    manifest = json.loads((out / "manifest.json").read_text())
    listed = {o["path"]: o for o in manifest["outputs"] if o["path"].startswith("meshes/volume/")}
    assert set(listed) == {"meshes/volume/q_0.000.vtu", "meshes/volume/q_0.000.msh",
                           "meshes/volume/chamber_q_0.000.stl"}
    for path, entry in listed.items():
        assert entry["sha256"] == hashlib.sha256((out / path).read_bytes()).hexdigest()
    # both formats hold the same tetrahedra
    points, tets = read_volume_mesh(out / "meshes/volume/q_0.000.vtu")
    msh_points, msh_tets = read_volume_mesh(out / "meshes/volume/q_0.000.msh")
    np.testing.assert_array_equal(msh_tets, tets)
    np.testing.assert_allclose(msh_points, points, rtol=0, atol=VTU_ATOL_MM)
    text = (out / "meshes/volume/q_0.000.vtu").read_text()
    assert 'format="ascii"' in text and "appended" not in text.lower() and 'format="binary"' not in text
    assert (out / "meshes/volume/q_0.000.msh").read_text().startswith("$MeshFormat\n2.2 0 8\n")
    # the figures, recomputed from the files
    entry = listed["meshes/volume/q_0.000.vtu"]
    volumes = tet_volumes(points, tets)
    assert volumes.min() > 0 and entry["tets"] == len(tets)
    body_v, body_f = read_mesh(out / "meshes/q_0.000.stl")
    body = mesh_topology(body_v, body_f).volume
    assert abs(volumes.sum() / body - 1.0) <= VOLUME_RTOL
    assert entry["volume_mm3"] == pytest.approx(volumes.sum(), rel=1e-9)
    assert entry["size_mm"] == 2.0 and entry["min_dihedral_deg"] > 0 and entry["max_radius_edge"] >= np.sqrt(6) / 4
    # the report's fabrication section tables the mesh and its checks join the page's checks
    report = write_report(out, ReportOptions(gif_frames=3, view_frames=3, q_samples=5))  # not the frames' sampling
    page = report.page.read_text()
    assert 'id="fabrication"' in page and "Volume meshes (fTetWild)" in page and f">{len(tets)}<" in page
    assert report.checks_passed == report.checks_total and "volume mesh q=0.000" in page
    # the chamber: closed, normals outwards, and no tetrahedron in it (winding numbers, not the stage's vtk test)
    chamber_v, chamber_f = read_mesh(out / "meshes/volume/chamber_q_0.000.stl")
    chamber = mesh_topology(chamber_v, chamber_f)
    assert chamber.watertight and chamber.winding_consistent and chamber.shells == 1 and chamber.volume > 0
    assert listed["meshes/volume/chamber_q_0.000.stl"]["normals"] == "outward"
    # ... and meshio, which SOFA users convert with, reads the same closed surface
    stl = meshio.stl.read(str(out / "meshes/volume/chamber_q_0.000.stl"))
    triangles = stl.cells_dict["triangle"]
    assert len(triangles) == chamber.faces
    np.testing.assert_allclose(mesh_topology(stl.points, triangles).shell_volumes.sum(), chamber.volume,
                               rtol=0, atol=STL_ATOL_MM * chamber.area)
    assert np.all(winding_numbers(tet_centroids(points, tets), chamber_v, chamber_f) < HALF)
    assert entry["chamber_centroids_inside"] == 0
    # the chamber is about the tube's inside: radius 2.5 - 0.8, length 14 - 2 x 0.8 (the 40-gon's area: rel 1 %)
    assert chamber.volume == pytest.approx(np.pi * 1.7**2 * 12.4, rel=0.01)
    # no stray file of fTetWild's (__tracked_surface.stl) in the working folder
    assert list(work.iterdir()) == []

    # a crash, a hang and a failure of the mesher: exit 1, a clear message, the build folder left as it was
    before = files(out)
    for mesher, volume, message in [
        (abort_mesher, {"size_mm": 2.5}, "crashed (killed by signal SIGABRT) before answering"),
        (hanging_mesher, {"size_mm": 2.5, "timeout_s": 3}, "did not finish within 3 s and was stopped"),
        (failing_mesher, {"size_mm": 2.5}, "failed: RuntimeError: fTetWild: envelope check failed"),
    ]:
        monkeypatch.setattr(volume_mesh, "MESHER", mesher)
        result = runner.invoke(app, ["build", str(tube_case(tmp_path, **volume)), "--out", str(out), "--jobs", "1"])
        assert result.exit_code == 1, result.output
        assert "fTetWild on the body at q=0.000" in result.output and message in result.output, result.output
        assert "Traceback" not in result.output
        assert files(out) == before


@pytest.mark.slow
def test_a_sealed_chamber_stays_empty(tmp_path):
    # no port: the chamber is a closed void inside the body, which the mesher must leave empty
    out = tmp_path / "build"
    result = runner.invoke(app, ["build", str(tube_case(tmp_path, port_mm=None)), "--out", str(out), "--jobs", "1"])
    assert result.exit_code == 0, result.output
    points, tets = read_volume_mesh(out / "meshes/volume/q_0.000.vtu")
    chamber_v, chamber_f = read_mesh(out / "meshes/volume/chamber_q_0.000.stl")
    assert np.all(winding_numbers(tet_centroids(points, tets), chamber_v, chamber_f) < HALF)
    body_v, body_f = read_mesh(out / "meshes/q_0.000.stl")
    body = mesh_topology(body_v, body_f)
    assert body.shells == 2  # the outer skin and the void's, wound inwards
    assert abs(tet_volumes(points, tets).sum() / body.volume - 1.0) <= VOLUME_RTOL
    figures = json.loads((out / "manifest.json").read_text())["metrics"]["volume_mesh"]["per_q"][0]
    # the tetrahedra's boundary is two closed shells too: the skin and the chamber's wall (Euler 2 + 2)
    assert figures["boundary_shells"] == 2 and figures["boundary_euler"] == 4 and figures["body_kind"] == "hollow"
