"""Write centerlines as VMTK's ``vmtkcenterlines`` writes them, and read a surface's face labels.

The file is VTK XML PolyData (binary, zlib-compressed, through the project's
one configured writer, :func:`softdesign.io.polylines_vtp.write_polylines_vtp`):
one polyline per outlet, each from the shared inlet, points proximal to
distal; the point array ``MaximumInscribedSphereRadius`` and the cell array
``CenterlineIds`` (0, 1, ...), so :mod:`softdesign.io.centerline`, VMTK,
morphMan and svMorph read it as they read VMTK's own.  VMTK's paths also
share the trunk's points by id; here each polyline holds its own copy, which
every reader of the format accepts.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from softdesign.io.centerline import RADIUS_KEY
from softdesign.io.polylines_vtp import write_polylines_vtp

if TYPE_CHECKING:
    from softdesign.centerline.extract import Centerlines  # its module imports scipy

#: Face-label cell arrays, in the order they are looked for: SimVascular's, then VMTK's mesh generator's.
REGION_KEYS = ("ModelFaceID", "CellEntityIds")


def write_centerlines_vtp(path: str | Path, centerlines: Centerlines, scale_from_mm: float = 1.0) -> Path:
    """Write ``centerlines`` (mm) to ``path``, in the surface's units (``scale_from_mm``: 0.1 for cm)."""
    return write_polylines_vtp(
        path,
        [p * scale_from_mm for p in centerlines.paths],
        point_arrays={RADIUS_KEY: [r * scale_from_mm for r in centerlines.radii]},
        cell_arrays={"CenterlineIds": np.arange(len(centerlines.paths), dtype=np.int64)},
    )


def read_face_regions(path: str | Path) -> np.ndarray | None:
    """One label per triangle (in the order :func:`softdesign.io.surface.read_surface` gives them), or None.

    Only .vtp and .vtk files carry labels (``REGION_KEYS``); other formats, and files without them, give None.
    """
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkFiltersCore import vtkTriangleFilter

    from softdesign.io.vtk_polydata import read_polydata

    path = Path(path)
    if path.suffix.lower() not in (".vtp", ".vtk"):
        return None
    triangles = vtkTriangleFilter()  # as triangles_from_polydata does, so labels follow the faces
    triangles.SetInputData(read_polydata(path))
    triangles.PassLinesOff()
    triangles.PassVertsOff()
    triangles.Update()
    cells = triangles.GetOutput().GetCellData()
    for key in REGION_KEYS:
        array = cells.GetArray(key)
        if array is not None and array.GetNumberOfComponents() == 1:
            return vtk_to_numpy(array).astype(np.int64)
    return None
