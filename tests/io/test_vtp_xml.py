"""The vtk-free .vtp reader gives vtk's own arrays, or None (then vtk reads the file), never other numbers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from softdesign.io.centerline import read_centerline_network
from softdesign.io.file_facts import _vtk_facts
from softdesign.io.vtk_polydata import polydata_arrays, read_polydata
from softdesign.io.vtp_xml import read_simple_vtp
from tests.helpers.paths import REPO

VMTK = REPO.parent / "shared" / "data" / "vmtk-aorta"
FILES = [REPO / "data" / "demo" / "centerline.vtp", VMTK / "aorta-centerline.vtp",
         VMTK / "aorta-centerline-branches.vtp", VMTK / "aorta-surface.vtp"]


def _same_as_vtk(path: Path) -> None:
    simple = read_simple_vtp(path)
    assert simple is not None, path
    poly = read_polydata(path)
    points, point_arrays, cell_arrays = polydata_arrays(poly)
    np.testing.assert_array_equal(simple.points, points)
    assert simple.points.dtype == points.dtype
    for mine, theirs in ((simple.point_arrays, point_arrays), (simple.cell_arrays, cell_arrays)):
        assert list(mine) == list(theirs)
        for name in mine:
            assert mine[name].dtype == theirs[name].dtype and mine[name].shape == theirs[name].shape, name
            np.testing.assert_array_equal(mine[name], theirs[name])
    from vtkmodules.util.numpy_support import vtk_to_numpy

    offsets = vtk_to_numpy(poly.GetLines().GetOffsetsArray())
    ids = vtk_to_numpy(poly.GetLines().GetConnectivityArray())
    assert len(simple.lines) == poly.GetNumberOfLines()
    for k, cell in enumerate(simple.lines):
        np.testing.assert_array_equal(cell, ids[offsets[k]:offsets[k + 1]])
    assert simple.cell_counts == {"lines": poly.GetNumberOfLines(), "polygons": poly.GetNumberOfPolys(),
                                  "triangle strips": poly.GetNumberOfStrips(), "vertices": poly.GetNumberOfVerts()}


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_the_projects_and_vmtks_files_read_as_vtk_reads_them(path):
    if not path.is_file():
        pytest.skip(f"{path} not found (../shared/data is not in this checkout)")
    _same_as_vtk(path)


@pytest.mark.parametrize(("mode", "compressed", "header64"),
                         [("ascii", False, False), ("binary", False, False), ("binary", True, False),
                          ("binary", True, True), ("binary", False, True)])
def test_every_inline_layout_vtk_writes_reads_as_vtk_reads_it(tmp_path, mode, compressed, header64):
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter

    writer = vtkXMLPolyDataWriter()
    writer.SetInputData(read_polydata(FILES[0]))
    writer.SetDataModeToAscii() if mode == "ascii" else writer.SetDataModeToBinary()
    writer.SetCompressorTypeToZLib() if compressed else writer.SetCompressorTypeToNone()
    if compressed:
        writer.SetBlockSize(4096)  # several blocks, the last one short
    writer.SetHeaderTypeToUInt64() if header64 else writer.SetHeaderTypeToUInt32()
    writer.SetFileName(str(tmp_path / "line.vtp"))
    assert writer.Write() == 1
    _same_as_vtk(tmp_path / "line.vtp")


def test_appended_data_and_broken_bytes_are_left_to_vtk(tmp_path):
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter

    writer = vtkXMLPolyDataWriter()
    writer.SetInputData(read_polydata(FILES[0]))
    writer.SetDataModeToAppended()
    writer.SetFileName(str(tmp_path / "appended.vtp"))
    assert writer.Write() == 1
    assert read_simple_vtp(tmp_path / "appended.vtp") is None
    text = FILES[0].read_text()
    broken = tmp_path / "broken.vtp"
    broken.write_text(text.replace('format="binary" RangeMin="2"', 'format="binary" RangeMin="2" x="', 1))
    assert read_simple_vtp(broken) is None  # not XML
    cut = tmp_path / "cut.vtp"
    start = text.index("eF7t")
    cut.write_text(text[:start + 40] + text[start + 80:])  # a compressed block shortened
    assert read_simple_vtp(cut) is None


def test_the_centerline_and_its_facts_are_those_vtk_gives():
    network = read_centerline_network(FILES[0], 1.0)
    assert len(network.polylines) == 2
    facts = _vtk_facts(FILES[0])
    assert facts.points == 352 and facts.cells["lines"] == 2 and "MaximumInscribedSphereRadius" in facts.point_arrays
