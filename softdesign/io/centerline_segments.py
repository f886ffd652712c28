"""Centerlines written as line segments: VTK unstructured grids (.vtu, legacy .vtk) and 2-point polydata.

gmsh exports VMTK-computed centerlines as a legacy ``.vtk`` unstructured grid
of 2-point line cells, without ``MaximumInscribedSphereRadius``; other
writers put the same 2-point cells in polydata.  Both are read here into the
line cells and their arrays (:func:`read_line_cells`), and joined into one
path from the inlet to each outlet (:func:`polylines_from_segments`, with
:func:`softdesign.geometry.segment_chains.chain_segments`), so the rest of
the project sees VMTK's layout.  Point arrays follow the points (the radius
included, when the file has one); cell arrays, which belonged to the
segments, do not survive the joining.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from softdesign.errors import InputDataError
from softdesign.geometry.network import Polyline
from softdesign.types import FloatArray, IntArray

#: VTK cell types read as lines: VTK_LINE and VTK_POLY_LINE.
LINE_CELL_TYPES = (3, 4)


@dataclass(frozen=True)
class LineCells:
    """The line cells of a VTK file and its arrays.

    Attributes
    ----------
    kind : what the file is (``legacy VTK unstructured grid``), for messages and ``validate``
    points : (n, 3) float, the file's units
    cells : point ids of each line cell, in file order
    point_arrays, cell_arrays : by name (cell arrays have one row per line cell)
    other_cells : how many cells are not lines (triangles of a surface, vertices)
    """

    kind: str
    points: FloatArray
    cells: list[IntArray]
    point_arrays: dict[str, np.ndarray] = field(default_factory=dict)
    cell_arrays: dict[str, np.ndarray] = field(default_factory=dict)
    other_cells: int = 0


def is_unstructured_grid(path: Path) -> bool:
    """True for a .vtu file, or a legacy .vtk file whose dataset is an unstructured grid (from its header)."""
    if path.suffix.lower() != ".vtk":
        return path.suffix.lower() == ".vtu"
    from vtkmodules.vtkIOLegacy import vtkUnstructuredGridReader

    from softdesign.io.vtk_polydata import _silence_vtk_log

    _silence_vtk_log()
    reader = vtkUnstructuredGridReader()
    reader.SetFileName(str(path))
    return bool(reader.IsFileUnstructuredGrid())


def read_line_cells(path: Path) -> LineCells:
    """The line cells of an unstructured grid (.vtu or legacy .vtk).

    Raises
    ------
    InputDataError
        vtk cannot read the file as an unstructured grid.
    """
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOLegacy import vtkUnstructuredGridReader
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

    from softdesign.io.vtk_header_bounds import check_vtk_header
    from softdesign.io.vtk_polydata import _ErrorCatcher, _silence_vtk_log, polydata_arrays

    check_vtk_header(path)  # before vtk allocates what the header declares
    _silence_vtk_log()
    xml = path.suffix.lower() == ".vtu"
    reader: Any = vtkXMLUnstructuredGridReader() if xml else vtkUnstructuredGridReader()
    errors = _ErrorCatcher()
    reader.AddObserver("ErrorEvent", errors.catch)
    reader.SetFileName(str(path))
    reader.Update()
    grid = reader.GetOutput()
    if errors.messages or grid is None:
        detail = errors.messages[0] if errors.messages else "no grid"
        raise InputDataError(f"{path}: cannot read it as a VTK unstructured grid ({detail}); re-export it")
    kind = "VTK XML unstructured grid" if xml else "legacy VTK unstructured grid"
    points, point_arrays, cell_arrays = polydata_arrays(grid)  # any vtkPointSet: points and data arrays
    if grid.GetNumberOfCells() == 0:
        return LineCells(kind, points, [], point_arrays, {})
    types = vtk_to_numpy(grid.GetCellTypes()).astype(np.int64)
    offsets = vtk_to_numpy(grid.GetCells().GetOffsetsArray()).astype(np.int64)
    ids = vtk_to_numpy(grid.GetCells().GetConnectivityArray()).astype(np.int64)
    lines = np.flatnonzero(np.isin(types, LINE_CELL_TYPES))
    cells = [ids[offsets[c]:offsets[c + 1]] for c in lines]
    kept = {name: values[lines] for name, values in cell_arrays.items()}
    return LineCells(kind, points, cells, point_arrays, kept, int(len(types) - len(lines)))


def all_two_point(cells: list[IntArray]) -> bool:
    """True when every line cell is a 2-point segment (and there is at least one)."""
    return bool(cells) and all(len(c) == 2 for c in cells)


def polylines_from_segments(lines: LineCells, radius_key: str, where: str) -> tuple[list[Polyline], str]:
    """One polyline per path from the inlet to each outlet, joined from the line cells, and a note saying so.

    Raises
    ------
    InputDataError
        The segments close a loop, or join into no path of MIN_PATH_POINTS points.
    """
    from softdesign.geometry.network import MIN_PATH_POINTS
    from softdesign.geometry.segment_chains import chain_segments

    segments = [np.stack([c[:-1], c[1:]], axis=1) for c in lines.cells if len(c) >= 2]
    if not segments:
        return [], ""
    radius_all = lines.point_arrays.get(radius_key)
    radius = None if radius_all is None else np.asarray(radius_all, float).reshape(-1)
    chains = chain_segments(lines.points, np.concatenate(segments), radius, where)
    longest = max((len(p) for p in chains.paths), default=0)
    if longest < MIN_PATH_POINTS:
        raise InputDataError(
            f"{where}: its {len(lines.cells)} line cells are short segments that join into no path of "
            f"{MIN_PATH_POINTS} points or more (the longest joins {longest}); expected a centerline from the "
            "inlet to each outlet: export the centerline's polylines (VMTK's vmtkcenterlines -ofile x.vtp), or "
            "compute it from the surface (final.centerline: auto)"
        )
    polylines = [
        Polyline(chains.points[p], None if radius is None else radius[chains.first_ids[p]]) for p in chains.paths
    ]
    note = (f"{where}: {chains.segments} line segments ({lines.kind}) joined into {len(polylines)} path(s) from "
            "the inlet (the first point of the first segment, when it is an end) to each outlet")
    return polylines, note
