"""A triangle mesh as plain arrays handed to VTK's filters, in memory: no files.

The meshing and centerline checks that lean on a VTK filter (enclosed points,
distances) build its input here, so they need nothing from ``io/``.
"""

from __future__ import annotations

import numpy as np


def polydata_from_triangles(vertices: np.ndarray, faces: np.ndarray):
    """A ``vtkPolyData`` of a triangle mesh: vertices (V, 3) float, faces (F, 3) int."""
    from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData

    poly = vtkPolyData()
    points = vtkPoints()
    points.SetData(numpy_to_vtk(np.ascontiguousarray(vertices, dtype=np.float64), deep=True))
    poly.SetPoints(points)
    cells = vtkCellArray()
    offsets = np.arange(0, 3 * len(faces) + 1, 3, dtype=np.int64)
    connectivity = np.ascontiguousarray(np.asarray(faces).reshape(-1), dtype=np.int64)
    cells.SetData(numpy_to_vtkIdTypeArray(offsets, deep=True), numpy_to_vtkIdTypeArray(connectivity, deep=True))
    poly.SetPolys(cells)
    return poly
