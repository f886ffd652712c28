"""`softdesign centerline`: VMTK's file layout, units, endpoints options, and bad surfaces refused with exit 2."""

from __future__ import annotations

import numpy as np
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.io.centerline import read_centerline_network
from softdesign.io.formats import write_mesh
from softdesign.io.vtk_polydata import polydata_arrays, read_polydata
from tests.helpers.vessels import straight_tube

runner = CliRunner()


def _tube_file(tmp_path, name="tube.stl", scale=1.0, faces_edit=None):
    vertices, faces = straight_tube(radius=3.0, length=40.0, edge=0.6)
    if faces_edit is not None:
        vertices, faces = faces_edit(vertices, faces)
    path = tmp_path / name
    write_mesh(path, vertices * scale, faces)
    return path


def test_writes_vmtk_layout_readable_by_ingest(aorta_dir, tmp_path):
    out = tmp_path / "cl.vtp"
    result = runner.invoke(app, ["centerline", str(aorta_dir / "aorta-surface-open-ends.stl"), "--output", str(out)])
    assert result.exit_code == 0, result.output
    assert "wound inwards" in result.output  # the note (stderr, mixed in by CliRunner)
    poly = read_polydata(out)
    _, point_arrays, cell_arrays = polydata_arrays(poly)
    assert poly.GetNumberOfLines() == 2
    assert list(cell_arrays["CenterlineIds"]) == [0, 1]
    network = read_centerline_network(out)
    starts = np.array([p.points[0] for p in network.polylines])
    np.testing.assert_allclose(starts[0], starts[1], rtol=0, atol=0.5)  # one shared inlet
    assert all(p.radius is not None and 2.5 < p.radius.min() and p.radius.max() < 8.0 for p in network.polylines)
    assert len(point_arrays["MaximumInscribedSphereRadius"]) == sum(len(p.points) for p in network.polylines)


def test_same_input_same_bytes(tmp_path):
    surface = _tube_file(tmp_path)
    for name in ("a.vtp", "b.vtp"):
        assert runner.invoke(app, ["centerline", str(surface), "--output", str(tmp_path / name)]).exit_code == 0
    assert (tmp_path / "a.vtp").read_bytes() == (tmp_path / "b.vtp").read_bytes()


def test_units_cm_writes_in_the_surface_units(tmp_path):
    surface = _tube_file(tmp_path, scale=0.1)  # the tube in cm
    out = tmp_path / "cl.vtp"
    result = runner.invoke(app, ["centerline", str(surface), "--units", "cm", "--output", str(out), "--json"])
    assert result.exit_code == 0, result.output
    (line,) = read_centerline_network(out).polylines
    np.testing.assert_allclose(np.median(line.radius), 0.3, rtol=0.01, atol=0)  # 3 mm = 0.3 cm


def test_inlet_option_and_bad_point(tmp_path):
    surface = _tube_file(tmp_path)
    out = tmp_path / "cl.vtp"
    result = runner.invoke(app, ["centerline", str(surface), "--inlet", "0,0,40", "--output", str(out)])
    assert result.exit_code == 0, result.output
    (line,) = read_centerline_network(out).polylines
    assert line.points[0, 2] > line.points[-1, 2]
    bad = runner.invoke(app, ["centerline", str(surface), "--inlet", "0,0", "--output", str(out)])
    assert bad.exit_code == 2 and "--inlet '0,0': 2 value(s), expected 3" in bad.output


def _two_pieces(vertices, faces):
    return np.concatenate([vertices, vertices + [20.0, 0.0, 0.0]]), np.concatenate([faces, faces + len(vertices)])


def _flipped_half(vertices, faces):
    faces = faces.copy()
    faces[: len(faces) // 2] = faces[: len(faces) // 2, ::-1]
    return vertices, faces


def _fin(vertices, faces):
    # a third triangle on an existing edge: neither closed nor open at clean openings
    a, b = faces[0, 1], faces[0, 2]  # the diagonal of the first quad: an interior edge
    return np.concatenate([vertices, [[10.0, 10.0, 10.0]]]), np.concatenate([faces, [[a, b, len(vertices)]]])


def test_bad_surfaces_exit_2_with_the_fix(tmp_path):
    cases = {
        "pieces.stl": (_two_pieces, "2 separate pieces"),
        "flipped.ply": (_flipped_half, "wound in opposite directions"),
        "fin.ply": (_fin, "shared by three or more triangles"),
    }
    for name, (edit, message) in cases.items():
        surface = _tube_file(tmp_path, name, faces_edit=edit)
        result = runner.invoke(app, ["centerline", str(surface), "--output", str(tmp_path / "x.vtp")])
        assert result.exit_code == 2, (name, result.output)
        assert message in result.output and "Traceback" not in result.output
    assert not (tmp_path / "x.vtp").exists()


def test_bad_options_exit_2(tmp_path):
    surface = _tube_file(tmp_path)
    for args, message in (
        (["--units", "inch"], "--units 'inch'"),
        (["--output", str(tmp_path / "cl.stl")], "expected a .vtp file"),
        (["--output", str(tmp_path / "nowhere" / "cl.vtp")], "does not exist"),
    ):
        result = runner.invoke(app, ["centerline", str(surface), *args])
        assert result.exit_code == 2 and message in result.output, result.output
    missing = runner.invoke(app, ["centerline", str(tmp_path / "none.stl")])
    assert missing.exit_code == 2 and "not found" in missing.output


def test_help():
    result = runner.invoke(app, ["centerline", "--help"])
    assert result.exit_code == 0 and "--outlet" in result.output


def test_labelled_caps_are_the_endpoints(tmp_path):
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk

    from softdesign.io.vtk_polydata import polydata_from_triangles, polydata_writer
    from tests.helpers.vessels import y_bifurcation

    vertices, faces, axes = y_bifurcation(4.0, 3.0, 30.0, np.radians(30.0), 0.8)
    centroids = vertices[faces].mean(axis=1)
    labels = np.ones(len(faces), np.int32)  # the wall
    for label, axis in enumerate(axes, start=2):  # each flat end: faces whose centroid lies at its far end
        end = np.abs(centroids @ axis - 30.0) < 1e-6
        labels[end] = label
    poly = polydata_from_triangles(vertices, faces)
    array = numpy_to_vtk(labels, deep=True)
    array.SetName("CellEntityIds")
    poly.GetCellData().AddArray(array)
    writer = polydata_writer(poly)
    writer.SetFileName(str(tmp_path / "y.vtp"))
    assert writer.Write() == 1 and vtk is not None
    result = runner.invoke(app, ["centerline", str(tmp_path / "y.vtp"), "--output", str(tmp_path / "cl.vtp"), "--json"])
    assert result.exit_code == 0, result.output
    assert '"endpoints": "face regions"' in result.output
    network = read_centerline_network(tmp_path / "cl.vtp")
    assert len(network.polylines) == 2
    assert all(p.points[0, 2] < -20.0 for p in network.polylines)  # from the trunk's (largest) cap


def test_outlet_option_gives_one_path_per_outlet(aorta_dir, tmp_path):
    out = tmp_path / "cl.vtp"
    surface = str(aorta_dir / "aorta-surface-open-ends.stl")
    result = runner.invoke(app, ["centerline", surface, "--outlet", "210.1,102.9,30.7", "--output", str(out)])
    assert result.exit_code == 0, result.output
    (line,) = read_centerline_network(out).polylines
    assert line.points[0, 1] > 165.0 and np.linalg.norm(line.points[-1] - [210.1, 102.9, 30.7]) < 8.0
