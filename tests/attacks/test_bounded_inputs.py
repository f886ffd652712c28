"""Issue 36, unbounded or crashing inputs: every cause of the attack report ends in exit 2 with a message.

Each input is made here, small, and run through the real command (in-process
through CliRunner where nothing native can abort the process, otherwise in a
child under the memory budget); the answer must be exit 2, no traceback, and
the message must name what was wrong.
"""

from __future__ import annotations

import hashlib
import json
import os

import numpy as np
import pytest
from typer.testing import CliRunner

from softdesign.cli import app
from softdesign.cli.pcc_bounds import MAX_DESIGN_SAMPLES, MAX_LENGTH_MM, MAX_POINTS_PER_SECTION
from softdesign.io.vtk_header_bounds import MAX_DECLARED_ITEMS
from tests.helpers.attacks import assert_refused, demo_case, run_limited
from tests.helpers.cases import straight_tube, write_case

runner = CliRunner()


def _ascii_vtp(folder, name: str, lines: list[list[int]], points: int = 10) -> str:
    """A small ASCII .vtp with ``points`` points and the given polylines (indices as given, unchecked)."""
    from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter

    poly, cloud, cells = vtkPolyData(), vtkPoints(), vtkCellArray()
    cloud.SetData(numpy_to_vtk(np.linspace(0.0, 1.0, 3 * points).reshape(points, 3), deep=True))
    poly.SetPoints(cloud)
    offsets = np.cumsum([0] + [len(line) for line in lines]).astype(np.int64)
    ids = np.concatenate([np.asarray(line, np.int64) for line in lines])
    cells.SetData(numpy_to_vtkIdTypeArray(offsets, deep=True), numpy_to_vtkIdTypeArray(ids, deep=True))
    poly.SetLines(cells)
    writer = vtkXMLPolyDataWriter()
    writer.SetInputData(poly)
    writer.SetDataModeToAscii()
    writer.SetFileName(str(folder / name))
    writer.Write()
    return str(folder / name)


def test_a_vtp_declaring_a_huge_point_count_is_refused_before_vtk_allocates(tmp_path):
    path = _ascii_vtp(tmp_path, "huge.vtp", [[0, 1, 2]])
    text = open(path).read().replace('NumberOfPoints="10"', 'NumberOfPoints="100000000000000"')
    open(path, "w").write(text)
    result = run_limited("centerline", path, "--output", str(tmp_path / "out.vtp"))  # aborted natively before
    assert_refused(result, "100,000,000,000,000 points", f"{MAX_DECLARED_ITEMS:,}")
    _, surface = straight_tube(tmp_path)
    case = write_case(tmp_path, final={"centerline": path, "surface": str(surface)}, initial={"kind": "straight"},
                      name="huge")
    result = run_limited("build", str(case), "--out", str(tmp_path / "build"))
    assert_refused(result, "huge.vtp", "100,000,000,000,000 points")


def test_a_vtp_declaring_more_points_than_its_bytes_hold_is_refused(tmp_path):
    path = _ascii_vtp(tmp_path, "claims.vtp", [[0, 1, 2]])
    text = open(path).read().replace('NumberOfPoints="10"', 'NumberOfPoints="5000000"')
    open(path, "w").write(text)
    result = run_limited("centerline", path, "--output", str(tmp_path / "out.vtp"))
    assert_refused(result, "5,000,000 points", "truncated or corrupt")


def test_line_indices_out_of_range_are_refused(tmp_path):
    centerline = _ascii_vtp(tmp_path, "bad_lines.vtp", [[0, 5, 99]])
    _, surface = straight_tube(tmp_path)
    case = write_case(tmp_path, final={"centerline": centerline, "surface": str(surface)},
                      initial={"kind": "straight"})
    result = runner.invoke(app, ["build", str(case), "--out", str(tmp_path / "build")])
    assert_refused(result, "bad_lines.vtp", "out of range", "e.g. 99", "10 points")


@pytest.mark.parametrize(
    ("args", "needles"),
    [
        (["pcc", "forward", "--lengths", "1e308,1e308,1e307", "--d", "15", "--json"], ["1e+308", f"{MAX_LENGTH_MM:g}"]),
        (["pcc", "forward", "--lengths", ";".join(["100,100,100"] * 101), "--d", "15"], ["101 sections"]),
    ],
    ids=["huge-length", "too-many-sections"],
)
def test_pcc_forward_bounds(args, needles):
    assert_refused(runner.invoke(app, args), *needles)


def _readings(folder, rows: int = 3, sections: int = 1):
    header = ["t"] + [f"l{s}{c}" for s in range(sections) for c in range(3)]
    lines = [",".join(header)] + [",".join([str(r)] + ["100"] * 3 * sections) for r in range(rows)]
    path = folder / "readings.csv"
    path.write_text("\n".join(lines) + "\n")
    return path


def test_pcc_reconstruct_refuses_points_per_section_beyond_its_bound(tmp_path):
    readings = _readings(tmp_path)
    result = runner.invoke(app, ["pcc", "reconstruct", str(readings), "--d", "5", "--shapes-dir",
                                 str(tmp_path / "s"), "--points-per-section", "100000000"])
    assert_refused(result, "--points-per-section", str(MAX_POINTS_PER_SECTION))
    assert not (tmp_path / "s").exists()


def test_pcc_reconstruct_bounds_the_backbone_samples_of_a_large_readings_file(tmp_path):
    readings = _readings(tmp_path, rows=1000, sections=100)  # 1000 x 100 x 21 = 2.1 M samples
    result = runner.invoke(app, ["pcc", "reconstruct", str(readings), "--d", "5", "--shapes-dir", str(tmp_path / "s")])
    assert_refused(result, "2,100,000 backbone samples", "--points-per-section")
    assert not (tmp_path / "s" / "backbones.vtp").exists()


def test_pcc_reconstruct_names_a_fifo_as_a_fifo_and_a_file_as_shapes_dir(tmp_path):
    os.mkfifo(tmp_path / "readings.csv")
    result = run_limited("pcc", "reconstruct", str(tmp_path / "readings.csv"), "--d", "5", "--shapes-dir",
                         str(tmp_path / "s"))
    assert_refused(result, "FIFO", "not a regular file")
    assert "not found" not in result.stderr
    readings = _readings(tmp_path / "s", rows=3) if (tmp_path / "s").mkdir() is None else None
    (tmp_path / "a_file").write_text("x")
    result = runner.invoke(app, ["pcc", "reconstruct", str(readings), "--d", "5", "--shapes-dir",
                                 str(tmp_path / "a_file")])
    assert_refused(result, "--shapes-dir", "is a file, expected a folder")


def test_pcc_design_refuses_samples_beyond_its_bound(tmp_path):
    result = runner.invoke(app, ["pcc", "design", str(demo_case(tmp_path)), "--d", "4", "--samples", "100000000"])
    assert_refused(result, "--samples", str(MAX_DESIGN_SAMPLES))


def test_csv_fields_over_128_kb_are_refused(tmp_path):
    centerline = tmp_path / "centerline.csv"
    centerline.write_text("x,y,z\n" + "1" * 200_000 + ",0,0\n")
    _, surface = straight_tube(tmp_path)
    case = write_case(tmp_path, final={"centerline": str(centerline), "surface": str(surface)},
                      initial={"kind": "straight"})
    assert_refused(runner.invoke(app, ["build", str(case), "--out", str(tmp_path / "build")]),
                   "centerline.csv", "field larger than field limit")
    readings = tmp_path / "readings.csv"
    readings.write_text("t,a,b,c\n0," + "1" * 200_000 + ",1,1\n")
    assert_refused(runner.invoke(app, ["pcc", "reconstruct", str(readings), "--d", "5", "--shapes-dir",
                                       str(tmp_path / "s")]), "readings.csv", "field larger than field limit")


def test_proc_self_mem_as_an_input_is_refused(tmp_path):
    _, surface = straight_tube(tmp_path)
    case = write_case(tmp_path, final={"centerline": "/proc/self/mem", "surface": str(surface)},
                      initial={"kind": "straight"})
    result = run_limited("build", str(case), "--out", str(tmp_path / "build"))
    assert_refused(result, "/proc/self/mem", "cannot read this input file")


def test_design_output_naming_a_folder_is_refused(tmp_path):
    (tmp_path / "designs").mkdir()
    result = runner.invoke(app, ["design", str(demo_case(tmp_path)), "--tolerance-mm", "0.5",
                                 "--output", str(tmp_path / "designs")])
    assert_refused(result, "is a folder, expected the case file to write")


def test_a_crafted_stage_record_naming_a_file_outside_the_folder_is_not_followed(out, tmp_path):
    outside = tmp_path / "outside.txt"
    outside.write_text("not the build's\n")
    record_path = out / "ingest" / "stage.json"
    record = json.loads(record_path.read_text())
    # with the file's true hash: the old runner found the stage intact and linked the file from outside the folder
    record["outputs"] = {"../outside.txt": hashlib.sha256(outside.read_bytes()).hexdigest(), **record["outputs"]}
    record_path.write_text(json.dumps(record))
    result = runner.invoke(app, ["build", str(demo_case(tmp_path)), "--out", str(out), "--jobs", "1"])
    assert result.exit_code == 0, result.output
    assert "Traceback" not in result.output
    assert outside.read_text() == "not the build's\n"
    assert "../outside.txt" not in (out / "ingest" / "stage.json").read_text()  # ingest ran again


def test_a_reference_manifest_nested_100k_deep_is_refused(out, tmp_path):
    reference = tmp_path / "reference"
    reference.mkdir()
    (reference / "manifest.json").write_text("[" * 100_000 + "]" * 100_000)
    result = runner.invoke(app, ["check", str(out), "--reference", str(reference)])
    assert result.exit_code in (1, 2), result.output
    assert "Traceback" not in result.output and "nested too deep" in result.output, result.output


def test_an_unstructured_grid_centerline_declaring_a_huge_point_count_is_refused_before_vtk_allocates(tmp_path):
    # gmsh's centerlines come as .vtu unstructured grids (issue 29): their header is bounded like a .vtp's
    cells = "".join(f"{i} {i + 1} " for i in range(9))
    text = (
        '<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="0.1">\n<UnstructuredGrid>\n'
        '<Piece NumberOfPoints="100000000000000" NumberOfCells="9">\n'
        '<Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">'
        + " ".join(f"0 0 {i}" for i in range(10)) + "</DataArray></Points>\n"
        f'<Cells><DataArray type="Int64" Name="connectivity" format="ascii">{cells}</DataArray>'
        '<DataArray type="Int64" Name="offsets" format="ascii">' + " ".join(str(2 * (i + 1)) for i in range(9))
        + '</DataArray><DataArray type="UInt8" Name="types" format="ascii">' + " ".join(["3"] * 9)
        + "</DataArray></Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n"
    )
    path = tmp_path / "huge.vtu"
    path.write_text(text)
    _, surface = straight_tube(tmp_path)
    case = write_case(tmp_path, final={"centerline": str(path), "surface": str(surface)}, initial={"kind": "straight"},
                      name="huge")
    result = run_limited("build", str(case), "--out", str(tmp_path / "build"))
    assert_refused(result, "huge.vtu", "100,000,000,000,000 points")
