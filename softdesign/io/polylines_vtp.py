"""Write polylines (backbones, centerlines, frame fields) as VTK XML PolyData (.vtp).

One polyline cell per (n, 3) array, with optional per-point arrays (scalars
or k-component vectors, e.g. frame axes N, B, T) and per-line arrays.  The
file is binary with zlib compression, as VMTK writes it, and appears
atomically: it is written under a temporary name in the same folder and
renamed, so a reader never sees half a file.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import numpy.typing as npt

from softdesign.errors import InputDataError
from softdesign.io.atomic import atomic_target
from softdesign.io.vtk_polydata import polydata_writer


def write_polylines_vtp(
    path: str | Path,
    polylines: Sequence[npt.ArrayLike],
    point_arrays: Mapping[str, Sequence[npt.ArrayLike]] | None = None,
    cell_arrays: Mapping[str, npt.ArrayLike] | None = None,
) -> Path:
    """Write polylines and their data to a .vtp file, atomically.

    Parameters
    ----------
    path : file to write (any suffix; .vtp by convention); its folder must exist
    polylines : list of (n_i, 3) float, mm
        One polyline cell each, points in order; n_i >= 1.  An empty list
        writes a valid file with no points.
    point_arrays : {name: list of (n_i,) or (n_i, c) float}, optional
        One array per polyline, with one row per point of that polyline;
        the same c for every polyline (c = 3 for a vector such as a frame axis).
    cell_arrays : {name: (len(polylines),) or (len(polylines), c) float}, optional
        One value (or c-vector) per polyline, e.g. a time stamp.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    InputDataError
        A polyline is not (n, 3) or not finite, or an array does not match
        the polylines; names the array and the polyline.
    OSError
        The folder does not exist or vtk cannot write.
    """
    path = Path(path)
    _write_atomically(_checked_polydata(polylines, point_arrays, cell_arrays), path)
    return path


def polylines_vtp_bytes(
    polylines: Sequence[npt.ArrayLike],
    point_arrays: Mapping[str, Sequence[npt.ArrayLike]] | None = None,
    cell_arrays: Mapping[str, npt.ArrayLike] | None = None,
) -> bytes:
    """The file :func:`write_polylines_vtp` writes, as bytes (the same writer, to a string: the same bytes).

    For a caller that writes the file itself (the build's staging) or encodes it while other work runs.

    Raises
    ------
    InputDataError
        As :func:`write_polylines_vtp`.
    OSError
        vtk cannot encode the polydata.
    """
    writer = polydata_writer(_checked_polydata(polylines, point_arrays, cell_arrays))
    writer.WriteToOutputStringOn()
    if writer.Write() != 1:
        raise OSError("vtk could not encode the polylines as .vtp")
    return writer.GetOutputString().encode("ascii")  # binary mode writes base64 text inline


def _checked_polydata(
    polylines: Sequence[npt.ArrayLike],
    point_arrays: Mapping[str, Sequence[npt.ArrayLike]] | None,
    cell_arrays: Mapping[str, npt.ArrayLike] | None,
):
    """The checked polylines and their arrays as a ``vtkPolyData`` (InputDataError naming what does not fit)."""
    lines = [_check_polyline(p, i) for i, p in enumerate(polylines)]
    sizes = [len(p) for p in lines]
    points = np.concatenate(lines) if lines else np.zeros((0, 3))
    per_point = {name: _stack_point_array(name, arrays, sizes) for name, arrays in (point_arrays or {}).items()}
    per_cell = {name: _check_cell_array(name, values, len(lines)) for name, values in (cell_arrays or {}).items()}
    return _polydata(points, sizes, per_point, per_cell)


def _check_polyline(points: npt.ArrayLike, index: int) -> np.ndarray:
    points = np.asarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3 or len(points) == 0:
        raise InputDataError(f"polyline {index}: expected an (n, 3) array with n >= 1, got shape {points.shape}")
    if not np.all(np.isfinite(points)):
        raise InputDataError(f"polyline {index}: has non-finite coordinates (NaN or inf); fix the computation upstream")
    return points


def _stack_point_array(name: str, arrays: Sequence[npt.ArrayLike], sizes: list[int]) -> np.ndarray:
    if len(arrays) != len(sizes):
        raise InputDataError(
            f"point array '{name}': expected one array per polyline ({len(sizes)}), got {len(arrays)}"
        )
    checked = []
    for index, (values, size) in enumerate(zip(arrays, sizes, strict=True)):
        values = np.asarray(values, dtype=np.float64)
        if values.ndim not in (1, 2) or len(values) != size:
            raise InputDataError(
                f"point array '{name}', polyline {index}: expected ({size},) or ({size}, c), got shape {values.shape}"
            )
        checked.append(values)
    if len({v.shape[1:] for v in checked}) > 1:
        raise InputDataError(f"point array '{name}': component counts differ between polylines")
    if not checked:
        return np.zeros(0)
    return np.concatenate(checked)


def _check_cell_array(name: str, values: npt.ArrayLike, count: int) -> np.ndarray:
    values = np.asarray(values)
    # integer ids (VMTK's CenterlineIds, TractIds) stay integers; everything else is float64
    values = values.astype(np.int32 if np.issubdtype(values.dtype, np.integer) else np.float64)
    if values.ndim not in (1, 2) or len(values) != count:
        raise InputDataError(
            f"cell array '{name}': expected ({count},) or ({count}, c), one value per polyline, "
            f"got shape {values.shape}"
        )
    return values


def _polydata(points: np.ndarray, sizes: list[int], per_point: dict, per_cell: dict):
    """A ``vtkPolyData`` with one polyline cell per run of ``sizes`` points."""
    from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData

    poly = vtkPolyData()
    vtk_points = vtkPoints()
    vtk_points.SetDataTypeToDouble()
    if len(points):
        vtk_points.SetData(numpy_to_vtk(np.ascontiguousarray(points), deep=True))
    poly.SetPoints(vtk_points)
    offsets = np.concatenate([[0], np.cumsum(sizes, dtype=np.int64)]).astype(np.int64)
    cells = vtkCellArray()
    cells.SetData(
        numpy_to_vtkIdTypeArray(offsets, deep=True),
        numpy_to_vtkIdTypeArray(np.arange(offsets[-1], dtype=np.int64), deep=True),
    )
    poly.SetLines(cells)
    for data, arrays in ((poly.GetPointData(), per_point), (poly.GetCellData(), per_cell)):
        for name, values in arrays.items():
            array = numpy_to_vtk(np.ascontiguousarray(values), deep=True)
            array.SetName(name)
            data.AddArray(array)
    return poly


def _write_atomically(poly, path: Path) -> None:
    if not path.parent.is_dir():
        raise OSError(f"{path}: the folder {path.parent} does not exist; create it first")
    writer = polydata_writer(poly)
    with atomic_target(path) as temporary:
        writer.SetFileName(str(temporary))
        if writer.Write() != 1:
            raise OSError(f"{path}: vtk could not write the file (is the folder writable?)")
