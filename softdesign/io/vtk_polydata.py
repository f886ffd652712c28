"""VTK PolyData files (XML .vtp and legacy .vtk) through the vtk package.

VMTK writes zlib-compressed binary XML; vtk's own readers handle every
variant, so nothing here parses bytes by hand.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softdesign.errors import InputDataError
from softdesign.io.vtk_header_bounds import check_cell_indices, check_vtk_header

if TYPE_CHECKING:
    from softdesign.io.vtp_xml import PolyDataArrays


def read_polydata(path: Path):
    """Read a .vtp or legacy .vtk file into a ``vtkPolyData``.

    Raises
    ------
    InputDataError
        The file is missing, not PolyData, or vtk reports a read error.
    """
    if not path.is_file():
        raise InputDataError(f"{path}: file not found; check the path in the case file")
    check_vtk_header(path)  # before vtk allocates what the header declares
    _silence_vtk_log()
    reader: Any  # VTK's stubs type AddObserver's event as an int id; vtk takes the event's name too
    if path.suffix.lower() == ".vtp":  # each reader's module alone (the legacy one adds about 0.1 s)
        from vtkmodules.vtkIOXML import vtkXMLPolyDataReader

        reader = vtkXMLPolyDataReader()
    else:
        from vtkmodules.vtkIOLegacy import vtkPolyDataReader

        reader = vtkPolyDataReader()
    errors = _ErrorCatcher()
    reader.AddObserver("ErrorEvent", errors.catch)
    reader.SetFileName(str(path))
    reader.Update()
    poly = reader.GetOutput()
    if errors.messages or poly is None or (path.suffix.lower() == ".vtk" and not reader.IsFilePolyData()):
        detail = errors.messages[0] if errors.messages else "not VTK PolyData"
        raise InputDataError(f"{path}: cannot read it as VTK PolyData ({detail}); re-export it from VMTK or ParaView")
    check_cell_indices(poly, path)
    return poly


def simple_vtp(path: Path) -> PolyDataArrays | None:
    """A .vtp's arrays read without vtk (:mod:`softdesign.io.vtp_xml`), after the same header check as
    :func:`read_polydata`; None for another suffix, a missing file or a layout vtk must read (then call it)."""
    from softdesign.io.vtp_xml import read_simple_vtp

    if path.suffix.lower() != ".vtp" or not path.is_file():
        return None
    check_vtk_header(path)
    return read_simple_vtp(path)


def _silence_vtk_log() -> None:
    """vtk prints parser errors to stderr itself; we report them as one clear message."""
    from vtkmodules.vtkCommonCore import vtkLogger

    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)


class _ErrorCatcher:
    """Collects vtk error events instead of letting vtk print them."""

    def __init__(self) -> None:
        self.messages: list[str] = []

    def catch(self, caller, event, calldata=None) -> None:  # noqa: ARG002 - vtk's observer signature
        text = str(calldata or f"{event} in {caller.GetClassName()}").strip()
        text = re.sub(r" \(0x[0-9a-fA-F]+\)", "", text.splitlines()[-1] if text else str(event))
        self.messages.append(text)

    # vtk passes the error text to an observer whose function has CallDataType "string0" (what
    # vtkmodules.util.misc.calldata_type sets); mypy does not model attributes set on functions
    catch.CallDataType = "string0"  # type: ignore[attr-defined]


def polydata_arrays(poly) -> tuple[np.ndarray, dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Points (n, 3) float64 and the point and cell data arrays by name."""
    from vtkmodules.util.numpy_support import vtk_to_numpy

    if poly.GetPoints() is None or poly.GetNumberOfPoints() == 0:
        return np.zeros((0, 3)), {}, {}
    points = vtk_to_numpy(poly.GetPoints().GetData()).astype(np.float64)

    def arrays(data) -> dict[str, np.ndarray]:
        found = {}
        for i in range(data.GetNumberOfArrays()):
            array = data.GetArray(i)
            if array is not None and data.GetArrayName(i):
                found[data.GetArrayName(i)] = vtk_to_numpy(array)
        return found

    return points, arrays(poly.GetPointData()), arrays(poly.GetCellData())


def triangles_from_polydata(poly) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) float64 and triangles (F, 3) int64 of a surface, polygons triangulated."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkFiltersCore import vtkTriangleFilter

    tri = vtkTriangleFilter()
    tri.SetInputData(poly)
    tri.PassLinesOff()
    tri.PassVertsOff()
    tri.Update()
    out = tri.GetOutput()
    if out.GetNumberOfPolys() == 0:
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64)
    cells = out.GetPolys()
    offsets = vtk_to_numpy(cells.GetOffsetsArray())
    conn = vtk_to_numpy(cells.GetConnectivityArray()).astype(np.int64)
    if not np.all(np.diff(offsets) == 3):
        raise InputDataError("surface: triangulation left non-triangle cells; clean the surface (vmtksurfacecleaner)")
    vertices = vtk_to_numpy(out.GetPoints().GetData()).astype(np.float64)
    return vertices, conn.reshape(-1, 3)



def polydata_writer(poly):
    """A ``vtkXMLPolyDataWriter`` of ``poly``: binary, zlib-compressed, as VMTK writes its files."""
    from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter

    writer = vtkXMLPolyDataWriter()
    writer.SetInputData(poly)
    writer.SetDataModeToBinary()
    writer.SetCompressorTypeToZLib()
    return writer
