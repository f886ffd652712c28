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


def test_lengths_are_printed_with_three_figures_and_mm_beside_other_units(tmp_path):
    """Issue 43 item 8: the 40 mm tube in m printed "0.04 m" and "continued by 0.00 m"; now "0.04xx m (4x.x mm)"."""
    import re

    surface = _tube_file(tmp_path, scale=0.001)  # the tube in m
    out = tmp_path / "cl.vtp"
    result = runner.invoke(app, ["centerline", str(surface), "--units", "m", "--output", str(out)])
    assert result.exit_code == 0, result.output
    line = next(t for t in result.output.splitlines() if "centerline 0:" in t)
    in_m, in_mm = re.search(r"points, ([0-9.]+) m \(([0-9.]+) mm\)", line).groups()
    assert len(re.sub(r"^0\.0*", "", in_m)) == 3  # three significant figures in m ...
    np.testing.assert_allclose(float(in_m) * 1000.0, float(in_mm), rtol=0, atol=0.5)  # ... the same length in mm
    radius = re.search(r"radius ([0-9.]+) m \(([0-9.]+) mm\)", line)
    np.testing.assert_allclose(float(radius.group(2)), 3.0, rtol=0, atol=0.1)  # the tube's 3 mm radius, in mm
    ends = next(t for t in result.output.splitlines() if "ends continued" in t)
    assert re.search(r"by [0-9.]+ m \([0-9.]+ mm\) \(inlet\) and [0-9.]+ m \([0-9.]+ mm\) \(outlet\)", ends), ends
    assert not re.search(r"[0-9] m\b(?! \()", result.output)  # every length in m has its mm beside it


def test_lengths_in_mm_are_not_repeated():
    from softdesign.pipeline.length_text import length_text

    assert length_text(70.31, "mm") == "70.3 mm"
    assert length_text(70.31, "m") == "0.0703 m (70.3 mm)"
    assert length_text(70.31, "cm") == "7.03 cm (70.3 mm)"
    assert length_text(1234.0, "mm") == "1230 mm"  # no exponent
    assert length_text(40.0, "m") == "0.0400 m (40.0 mm)"  # the zeros that are figures stay
    assert length_text(0.0, "m") == "0.00 m (0.00 mm)"


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


def _labelled_y(tmp_path, wall_patch: bool, wall_patches: int = 1):
    """The capped Y with CellEntityIds: wall 1, the three flat ends 2, 3, 4, and with ``wall_patch`` a patch of
    the trunk's wall labelled 9, larger than any cap (as SimVascular models label wall faces), cut along the
    trunk into ``wall_patches`` labels 9, 10, ..."""
    from vtk.util.numpy_support import numpy_to_vtk

    from softdesign.io.vtk_polydata import polydata_writer
    from softdesign.meshing.vtk_triangles import polydata_from_triangles
    from tests.helpers.vessels import y_bifurcation

    vertices, faces, axes = y_bifurcation(4.0, 3.0, 30.0, np.radians(30.0), 0.8)
    centroids = vertices[faces].mean(axis=1)
    labels = np.ones(len(faces), np.int32)  # the wall
    for label, axis in enumerate(axes, start=2):  # each flat end: faces whose centroid lies at its far end
        end = np.abs(centroids @ axis - 30.0) < 1e-6
        labels[end] = label
    if wall_patch:  # half the trunk's wall from z = -25 to -10: 188 mm^2 against the trunk cap's 50
        patch = (labels == 1) & (centroids[:, 0] > 0.0) & (centroids[:, 2] > -25.0) & (centroids[:, 2] < -10.0)
        labels[patch] = 9 + np.minimum(((centroids[patch, 2] + 25.0) / 15.0 * wall_patches).astype(int),
                                       wall_patches - 1)
    poly = polydata_from_triangles(vertices, faces)
    array = numpy_to_vtk(labels, deep=True)
    array.SetName("CellEntityIds")
    poly.GetCellData().AddArray(array)
    writer = polydata_writer(poly)
    path = tmp_path / "y.vtp"
    writer.SetFileName(str(path))
    assert writer.Write() == 1
    return path


def test_labelled_caps_are_the_endpoints(tmp_path):
    surface = _labelled_y(tmp_path, wall_patch=False)
    result = runner.invoke(app, ["centerline", str(surface), "--output", str(tmp_path / "cl.vtp"), "--json"])
    assert result.exit_code == 0, result.output
    assert '"endpoints": "face regions"' in result.output and "face label" not in result.output
    network = read_centerline_network(tmp_path / "cl.vtp")
    assert len(network.polylines) == 2
    assert all(p.points[0, 2] < -20.0 for p in network.polylines)  # from the trunk's (largest) cap


def test_a_labelled_wall_face_is_not_taken_for_an_opening(tmp_path):
    """Issue 29 item 3: the wall patch (label 9) is larger than every cap; unchecked, it was the inlet."""
    surface = _labelled_y(tmp_path, wall_patch=True)
    out = tmp_path / "cl.vtp"
    result = runner.invoke(app, ["centerline", str(surface), "--output", str(out), "--json"])
    assert result.exit_code == 0, result.output
    assert '"endpoints": "face regions"' in result.output
    # a wall label is expected: said once, no warning
    assert "1 face label is a wall, not an opening (label 9: not planar" in result.output
    assert "warning:" not in result.output and "face label 2" not in result.output
    network = read_centerline_network(out)
    assert len(network.polylines) == 2  # two outlets: the branch caps, not the patch
    for line in network.polylines:  # from the trunk's cap centre, (0, 0, -30), to a branch cap's centre
        np.testing.assert_allclose(line.points[0], [0.0, 0.0, -30.0], rtol=0, atol=0.2)
        assert line.points[-1, 2] > 20.0


def test_many_wall_labels_are_reported_once(tmp_path):
    """Issue 43 item 8: a SimVascular model's wall faces gave one warning each; they are one note."""
    surface = _labelled_y(tmp_path, wall_patch=True, wall_patches=3)
    result = runner.invoke(app, ["centerline", str(surface), "--output", str(tmp_path / "cl.vtp"), "--json"])
    assert result.exit_code == 0, result.output
    assert result.output.count("face label") == 1, result.output
    assert "3 face labels are walls, not openings (labels 9, 10, 11: not planar" in result.output
    assert "warning:" not in result.output
    assert len(read_centerline_network(tmp_path / "cl.vtp").polylines) == 2


def test_label_checks_name_each_reason():
    """A flat disc of the lumen's width is a cap; a curved wall patch, a flat strip and an oversized or tiny flat
    disc are not, each for its own stated reason."""
    from softdesign.centerline.endpoints import label_not_a_cap
    from softdesign.centerline.voronoi import VoronoiGraph

    def disc(radius, around=24, rings=4):
        r = np.repeat(np.linspace(0.0, radius, rings + 1)[1:], around)
        t = np.tile(np.linspace(0.0, 2 * np.pi, around, endpoint=False), rings)
        points = np.column_stack([np.r_[0.0, r * np.cos(t)], np.r_[0.0, r * np.sin(t)], np.zeros(len(r) + 1)])
        from scipy.spatial import Delaunay

        return points, Delaunay(points[:, :2]).simplices.astype(np.int64)

    def area(v, f):
        return float(0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1).sum())

    def touching(v, lumen):  # one inscribed sphere of radius ``lumen`` touching every vertex of the patch
        return VoronoiGraph(np.zeros((1, 3)), np.array([lumen]), np.array([[0, 1, 2, 3]]), np.zeros((0, 2), int))

    v, f = disc(3.0)
    assert label_not_a_cap(v, f, area(v, f), touching(v, 3.0)) is None
    assert "wider than the vessel" in label_not_a_cap(v, f, area(v, f), touching(v, 1.5))
    assert "narrower than the vessel" in label_not_a_cap(v, f, area(v, f), touching(v, 9.0))
    bent = v.copy()
    bent[:, 2] = bent[:, 0] ** 2 / (2 * 4.0)  # the disc laid on a cylinder of radius 4 mm: a wall patch
    assert "not planar" in label_not_a_cap(bent, f, area(bent, f), touching(v, 3.0))
    strip = v * [1.0, 0.1, 1.0]
    assert "not disc-like" in label_not_a_cap(strip, f, area(strip, f), touching(v, 3.0))


def test_outlet_option_gives_one_path_per_outlet(aorta_dir, tmp_path):
    out = tmp_path / "cl.vtp"
    surface = str(aorta_dir / "aorta-surface-open-ends.stl")
    result = runner.invoke(app, ["centerline", surface, "--outlet", "210.1,102.9,30.7", "--output", str(out),
                                 "--json"])
    assert result.exit_code == 0, result.output
    (line,) = read_centerline_network(out).polylines
    # the point lies within the left iliac's opening: the path ends at that opening's centre (issue 29)
    centre = [210.102643, 102.861336, 30.738235]
    assert line.points[0, 1] > 165.0 and np.linalg.norm(line.points[-1] - centre) < 0.2
    assert '"short_of_opening": [\n        0.0,\n        0.0\n      ]' in result.output
