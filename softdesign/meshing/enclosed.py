"""Which points lie inside a closed triangle mesh (vtk's vtkSelectEnclosedPoints), e.g. tet centroids in a chamber.

vtk casts rays from each point through a static cell locator and counts the
crossings with the surface; for a closed, consistently wound surface and a
point not on it, the parity answers inside or outside.  The surface is
checked closed first (vtk would otherwise call every point outside).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softdesign.errors import MeshError
from softdesign.meshing.topology import mesh_topology
from softdesign.types import FloatArray

#: vtk's intersection tolerance, as a fraction of the surface's bounding box diagonal (vtk's default 1e-3 is
#: coarse next to a 1 mm wall on a 100 mm body).
_RAY_TOLERANCE = 1e-6


def points_inside(points: npt.ArrayLike, vertices: npt.ArrayLike, faces: npt.ArrayLike, label: str) -> np.ndarray:
    """Whether each point lies inside the closed surface ``(vertices, faces)``: (n,) bool.

    Parameters
    ----------
    points : (n, 3) float, mm
    vertices : (V, 3) float, mm
    faces : (F, 3) int, one or more closed shells
    label : names the surface in errors

    Raises
    ------
    MeshError
        The surface is not closed (not watertight).
    """
    from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkPolyData
    from vtkmodules.vtkFiltersModeling import vtkSelectEnclosedPoints

    from softdesign.meshing.vtk_triangles import polydata_from_triangles

    p: FloatArray = np.ascontiguousarray(points, np.float64).reshape(-1, 3)
    topology = mesh_topology(vertices, faces)
    if not topology.watertight:
        raise MeshError(f"{label}: the surface is not closed, so inside and outside are undefined")
    if len(p) == 0:
        return np.zeros(0, bool)
    cloud = vtkPolyData()
    cloud_points = vtkPoints()
    cloud_points.SetData(numpy_to_vtk(p, deep=True))
    cloud.SetPoints(cloud_points)
    select = vtkSelectEnclosedPoints()
    select.SetInputData(cloud)
    select.SetSurfaceData(polydata_from_triangles(np.asarray(vertices, float), np.asarray(faces)))
    select.SetTolerance(_RAY_TOLERANCE)
    select.Update()
    return vtk_to_numpy(select.GetOutput().GetPointData().GetArray("SelectedPoints")).astype(bool)
