"""`softdesign validate|ingest` through the CLI: happy path, every bad input (exit 2), untouched build folder."""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from tests.helpers.cases import straight_tube, write_case
from tests.helpers.paths import REPO
from tests.helpers.regeneration import REGENERATION_TOL_MM, assert_same_vessel_file, vessel_file_differences

runner = CliRunner()


def snapshot(folder: Path) -> dict[str, str]:
    """Every file under ``folder`` with its sha256."""
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


@pytest.fixture
def good(tmp_path):
    """A valid straight-tube case already ingested into ``out``."""
    centerline, surface = straight_tube(tmp_path)
    case = write_case(tmp_path, final={"centerline": centerline.name, "surface": surface.name})
    out = tmp_path / "out"
    result = runner.invoke(app, ["ingest", str(case), "--out", str(out)])
    assert result.exit_code == 0, result.output
    return tmp_path, out


def test_help_lists_the_commands():
    result = runner.invoke(app, ["--help"])
    assert result.exit_code == 0
    for command in ("build", "ingest", "validate", "sample", "pcc"):
        assert command in result.output


def test_ingest_reports_paths_surface_and_keeps_the_result(good):
    _, out = good
    assert (out / "ingest" / "path.npz").is_file() and (out / "manifest.json").is_file()
    again = runner.invoke(app, ["ingest", str(out.parent / "case.yaml"), "--out", str(out)])
    assert again.exit_code == 0
    assert "path 0: 81 points, 40.00 mm" in again.output
    assert "capped (watertight)" in again.output
    assert "[ingest] skipped" in again.output


def test_validate_accepts_a_good_case_and_rejects_a_missing_input(good):
    folder, _ = good
    assert runner.invoke(app, ["validate", str(folder / "case.yaml")]).exit_code == 0
    bad = write_case(folder, "bad", final={"centerline": "nowhere.vtp"})
    result = runner.invoke(app, ["validate", str(bad)])
    assert result.exit_code == 2 and "nowhere.vtp" in result.output


def _write_csv(path: Path, rows: list[list[float]]) -> Path:
    path.write_text("x,y,z\n" + "".join(",".join(str(v) for v in r) + "\n" for r in rows))
    return path


def _no_lines_vtp(path: Path) -> Path:
    import vtk

    poly = vtk.vtkPolyData()
    points = vtk.vtkPoints()
    for p in [(0, 0, 0), (1, 0, 0), (0, 1, 0)]:
        points.InsertNextPoint(p)
    poly.SetPoints(points)
    writer = vtk.vtkXMLPolyDataWriter()
    writer.SetFileName(str(path))
    writer.SetInputData(poly)
    assert writer.Write() == 1
    return path


def _bad_inputs(folder: Path) -> dict[str, tuple[dict, str]]:
    """name -> (final section, expected message fragment)."""
    (folder / "garbage.vtp").write_text("not a vtk file")
    (folder / "empty.stl").write_text("solid empty\nendsolid empty\n")
    (folder / "cl.xyz").write_text("0 0 0\n")
    far = folder / "far.stl"
    import trimesh

    trimesh.creation.cylinder(radius=3.0, height=40.0).apply_translation([500.0, 0.0, 0.0]).export(far)
    metres = folder / "metres"
    metres.mkdir()
    straight_tube(metres, scale=1e-3)
    nan_rows = [[0, 0, z] for z in range(10)]
    nan_rows[4][0] = float("nan")
    return {
        "missing file": ({"centerline": "absent.vtp"}, "final.centerline: file not found"),
        "unreadable file": ({"centerline": "garbage.vtp"}, "cannot read it as VTK PolyData"),
        "unknown format": ({"centerline": "cl.xyz"}, "unknown centerline format '.xyz'"),
        "no lines": ({"centerline": str(_no_lines_vtp(folder / "points.vtp"))}, "has no polylines"),
        "path out of range": ({"centerline": "centerline.vtp", "path": 3}, "final.path 3 is out of range"),
        "nan coordinates": ({"centerline": str(_write_csv(folder / "nan.csv", nan_rows))}, "NaN or infinite"),
        "too few points": (
            {"centerline": str(_write_csv(folder / "few.csv", [[0, 0, 0], [0, 0, 1], [0, 0, 1], [0, 0, 2]]))},
            "expected at least 4 distinct points, got 3",
        ),
        "surface elsewhere": (
            {"centerline": "centerline.vtp", "surface": "far.stl"},
            "does not surround the centerline",
        ),
        "surface in metres": (
            {"centerline": "centerline.vtp", "surface": "metres/surface.stl"},
            "a units mismatch would explain it (surface in m, centerline in mm)",
        ),
        "empty surface": ({"centerline": "centerline.vtp", "surface": "empty.stl"}, "the surface is empty"),
        "unknown surface format": ({"centerline": "centerline.vtp", "surface": "cl.xyz"}, "unknown surface format"),
    }


BAD_NAMES = [
    "missing file",
    "unreadable file",
    "unknown format",
    "no lines",
    "path out of range",
    "nan coordinates",
    "too few points",
    "surface elsewhere",
    "surface in metres",
    "empty surface",
    "unknown surface format",
]


@pytest.mark.parametrize("name", BAD_NAMES)
def test_bad_input_exits_2_with_a_message_and_leaves_the_build_untouched(good, name):
    folder, out = good
    final, expected = _bad_inputs(folder)[name]
    before = snapshot(out)
    case = write_case(folder, "bad", final=final)
    result = runner.invoke(app, ["ingest", str(case), "--out", str(out)])
    assert result.exit_code == 2, result.output
    assert expected in result.output
    assert "Traceback" not in result.output
    assert snapshot(out) == before


def test_bad_case_file_exits_2_through_build(good):
    folder, out = good
    case = write_case(folder, "typo", final={"centerline": "centerline.vtp"}, linkz={"count": 2})
    result = runner.invoke(app, ["build", str(case), "--out", str(out)])
    assert result.exit_code == 2
    assert "unknown key 'linkz'" in result.output and "did you mean 'links'" in result.output


def test_consecutive_duplicates_are_removed_with_a_note(tmp_path):
    rows = [[0, 0, z] for z in np.linspace(0, 10, 11)]
    rows.insert(5, rows[4])
    case = write_case(tmp_path, final={"centerline": str(_write_csv(tmp_path / "dup.csv", rows))})
    result = runner.invoke(app, ["ingest", str(case), "--out", str(tmp_path / "out")])
    assert result.exit_code == 0, result.output
    assert "removed 1 consecutive duplicate point(s)" in result.output
    assert "path 0: 11 points" in result.output


def test_the_same_vessel_in_mm_and_in_m_ingests_identically(tmp_path):
    from softdesign.pipeline.stages.ingest import load_ingest

    results = []
    for units, scale in (("mm", 1.0), ("m", 1e-3)):
        folder = tmp_path / units
        folder.mkdir()
        centerline, surface = straight_tube(folder, scale=scale)
        case = write_case(folder, units=units, final={"centerline": centerline.name, "surface": surface.name})
        result = runner.invoke(app, ["ingest", str(case), "--out", str(folder / "out")])
        assert result.exit_code == 0, result.output
        results.append(load_ingest(folder / "out"))
    mm, m = results
    # float32 STL and float64 scaling: agreement to float32 resolution of a ~40 mm coordinate
    np.testing.assert_allclose(m.path.points, mm.path.points, rtol=0, atol=1e-9)
    np.testing.assert_allclose(m.path.radius, mm.path.radius, rtol=0, atol=1e-9)
    np.testing.assert_allclose(m.vertices, mm.vertices, rtol=0, atol=1e-5)
    assert m.summary["surface"]["faces"] == mm.summary["surface"]["faces"]


def test_sample_generator_rebuilds_the_committed_demo_data(tmp_path):
    """data/demo is the generator's output within REGENERATION_TOL_MM (so it never goes stale)."""
    result = runner.invoke(app, ["sample", str(tmp_path)])
    assert result.exit_code == 0, result.output
    committed = REPO / "data" / "demo"
    for name in ("centerline.vtp", "surface.stl"):
        assert_same_vessel_file(tmp_path / name, committed / name)


def test_sample_generator_gives_the_same_bytes_twice(tmp_path):
    """Within one environment the generator is byte-for-byte repeatable."""
    for folder in ("a", "b"):
        assert runner.invoke(app, ["sample", str(tmp_path / folder)]).exit_code == 0
    assert snapshot(tmp_path / "a") == snapshot(tmp_path / "b")


def test_regeneration_check_sees_a_centerline_moved_by_1e_6_mm(tmp_path):
    """The committed centerline rewritten with one point and one radius moved: 1e-6 mm fails, 1e-12 mm passes."""
    from softdesign.io.centerline import RADIUS_KEY, read_centerline_network
    from softdesign.io.polylines_vtp import write_polylines_vtp

    committed = REPO / "data" / "demo" / "centerline.vtp"
    network = read_centerline_network(committed)
    for name, move in (("moved.vtp", 1e-6), ("rounded.vtp", 1e-3 * REGENERATION_TOL_MM)):
        lines = [line.points.copy() for line in network.polylines]
        radii = [line.radius.copy() for line in network.polylines]
        middle = len(lines[0]) // 2
        lines[0][middle, 1] += move
        radii[0][middle] += move
        write_polylines_vtp(tmp_path / name, lines, {RADIUS_KEY: radii})
    differences = vessel_file_differences(tmp_path / "moved.vtp", committed)
    assert len(differences) == 2, differences
    assert differences[0].startswith("points: 1 of")
    assert differences[1].startswith(f"point array {RADIUS_KEY}: 1 of")
    assert vessel_file_differences(tmp_path / "rounded.vtp", committed) == []


def test_regeneration_check_sees_an_stl_vertex_moved_past_its_float32_step(tmp_path):
    """A binary STL stores float32: one step is rounding, three are a real move."""
    import trimesh

    from softdesign.io.formats import write_mesh

    committed = REPO / "data" / "demo" / "surface.stl"
    mesh = trimesh.load(committed, process=False)
    corner = mesh.vertices[mesh.faces[0, 0]]
    step = np.spacing(np.abs(corner).astype(np.float32)).astype(np.float64)
    for name, move in (("rounded.stl", step), ("moved.stl", 3 * step)):
        vertices = mesh.vertices.copy()
        vertices[mesh.faces[0, 0]] += move
        write_mesh(tmp_path / name, vertices, mesh.faces)
    assert vessel_file_differences(tmp_path / "rounded.stl", committed) == []
    assert vessel_file_differences(tmp_path / "moved.stl", committed)[0].startswith("vertices: 3 of")


def test_sample_is_a_vmtk_style_network_with_a_capped_wall(tmp_path):
    from softdesign.geometry.network import select_path
    from softdesign.io.centerline import read_centerline_network
    from softdesign.io.surface import read_surface
    from softdesign.meshing.topology import describe_surface

    runner.invoke(app, ["sample", str(tmp_path)])
    network = read_centerline_network(tmp_path / "centerline.vtp")
    main, branch = (select_path(network, i) for i in (0, 1))
    # both start at the trunk's inlet: the widest end of each (issue 20's default), also the end they share
    assert "l = 0 at the widest end" in main.notes[-1] and "l = 0 at the widest end" in branch.notes[-1]
    np.testing.assert_array_equal(main.points[0], branch.points[0])
    assert np.linalg.norm(main.points[-1] - branch.points[-1]) > 20.0  # a real side branch
    assert 2.9 < main.radius.min() < main.radius.max() < 4.0  # minor semi-axis of the elliptical lumen
    info = describe_surface(*read_surface(tmp_path / "surface.stl"))
    assert info.capped and info.nonmanifold_edges == 0


def _demo_centerline_csv(path: Path, scale: float, radius: bool = True) -> Path:
    """The sample vessel's main path (data/demo) as a CSV, every coordinate (and radius) times ``scale``."""
    from softdesign.geometry.network import select_path
    from softdesign.io.centerline import read_centerline_network

    main = select_path(read_centerline_network(REPO / "data" / "demo" / "centerline.vtp"), 0)
    columns = [main.points * scale] + ([main.radius[:, None] * scale] if radius else [])
    header = "x,y,z" + (",radius" if radius else "")
    np.savetxt(path, np.hstack(columns), delimiter=",", header=header, comments="")
    return path


def _refused_at_ingest(case: Path, out: Path) -> str:
    result = runner.invoke(app, ["ingest", str(case), "--out", str(out)])
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    assert not out.exists()  # refused before anything was kept
    return result.output


def test_the_sample_vessel_declared_in_metres_is_refused_suggesting_mm(tmp_path):
    demo = REPO / "data" / "demo"
    case = write_case(tmp_path, units="m", final={"centerline": str(demo / "centerline.vtp"),
                                                  "surface": str(demo / "surface.stl")})
    output = _refused_at_ingest(case, tmp_path / "out")
    assert "centerline.vtp: with units: m the vessel is 104 m long with a 3.36 m median radius" in output
    assert "not a human vessel (expected a median radius of 0.3 to 20 mm and a length of 5 to 2000 mm)" in output
    assert "with units: mm it would be 104 mm long with a 3.36 mm median radius: set units: mm in the case" in output


def test_the_sample_vessel_in_metres_declared_in_mm_is_refused_suggesting_m(tmp_path):
    case = write_case(tmp_path, units="mm", final={"centerline": str(_demo_centerline_csv(tmp_path / "cl.csv", 1e-3))})
    output = _refused_at_ingest(case, tmp_path / "out")
    assert "with units: mm the vessel is 0.104 mm long with a 0.00336 mm median radius" in output
    assert "with units: m it would be 104 mm long with a 3.36 mm median radius: set units: m in the case file" in output


def test_without_radii_the_length_alone_is_judged(tmp_path):
    centerline = _demo_centerline_csv(tmp_path / "cl.csv", 1e-3, radius=False)
    output = _refused_at_ingest(write_case(tmp_path, final={"centerline": str(centerline)}), tmp_path / "out")
    assert "the vessel is 0.104 mm long, not a human vessel" in output and "median radius of" in output
    assert "with units: m it would be 104 mm long: set units: m" in output
    assert "with units: cm" not in output  # 1.04 mm long: no vessel either
    # ... and the same file declared in metres ingests
    in_metres = write_case(tmp_path, "m", units="m", final={"centerline": str(centerline)})
    result = runner.invoke(app, ["ingest", str(in_metres), "--out", str(tmp_path / "m")])
    assert result.exit_code == 0, result.output


def test_no_units_fit_a_vessel_that_is_not_human_in_any(tmp_path):
    rows = [[0.0, 0.0, z] for z in np.linspace(0.0, 10.0, 11)]
    centerline = tmp_path / "cl.csv"
    centerline.write_text("x,y,z,radius\n" + "".join(f"{x},{y},{z},25\n" for x, y, z in rows))  # wider than long
    output = _refused_at_ingest(write_case(tmp_path, final={"centerline": str(centerline)}), tmp_path / "out")
    assert "no units (mm, cm, m) make it plausible" in output


def test_the_real_aorta_still_ingests(aorta_dir, tmp_path):
    case = write_case(tmp_path, final={"centerline": str(aorta_dir / "aorta-centerline.vtp"),
                                       "surface": str(aorta_dir / "aorta-surface.stl")})
    result = runner.invoke(app, ["ingest", str(case), "--out", str(tmp_path / "out")])
    assert result.exit_code == 0, result.output
    assert "not a human vessel" not in result.output
