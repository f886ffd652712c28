"""Centerline files as gmsh and other mesh writers make them: 2-point line segments, in three containers."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def segments_of(polylines: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Points (n, 3) and 2-point segments (k, 2) of polylines, each polyline's points written again (VMTK's
    trunk is repeated in every path, as gmsh's export of vmtkcenterlines repeats it)."""
    points, segments, offset = [], [], 0
    for line in polylines:
        n = len(line)
        points.append(line)
        segments.append(np.stack([np.arange(offset, offset + n - 1), np.arange(offset + 1, offset + n)], axis=1))
        offset += n
    return np.concatenate(points), np.concatenate(segments)


def write_segments(path: Path, points: np.ndarray, segments: np.ndarray, radius: np.ndarray | None = None) -> Path:
    """Write the segments as VTK_LINE cells: legacy unstructured grid (.vtk), XML grid (.vtu) or polydata (.vtp)."""
    from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData, vtkUnstructuredGrid
    from vtkmodules.vtkIOLegacy import vtkUnstructuredGridWriter
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter, vtkXMLUnstructuredGridWriter

    vtk_points = vtkPoints()
    vtk_points.SetData(numpy_to_vtk(np.ascontiguousarray(points, float), deep=True))
    cells = vtkCellArray()
    cells.SetData(numpy_to_vtkIdTypeArray(np.arange(0, 2 * len(segments) + 1, 2, dtype=np.int64), deep=True),
                  numpy_to_vtkIdTypeArray(np.ascontiguousarray(segments, np.int64).reshape(-1), deep=True))
    if path.suffix == ".vtp":
        data = vtkPolyData()
        data.SetLines(cells)
        writer = vtkXMLPolyDataWriter()
    else:
        data = vtkUnstructuredGrid()
        data.SetCells(3, cells)  # VTK_LINE
        writer = vtkUnstructuredGridWriter() if path.suffix == ".vtk" else vtkXMLUnstructuredGridWriter()
    data.SetPoints(vtk_points)
    if radius is not None:
        array = numpy_to_vtk(np.ascontiguousarray(radius, float), deep=True)
        array.SetName("MaximumInscribedSphereRadius")
        data.GetPointData().AddArray(array)
    writer.SetInputData(data)
    writer.SetFileName(str(path))
    assert writer.Write() == 1
    return path
