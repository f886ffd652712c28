"""What an input file holds, as ``softdesign validate`` reports it: its type, point and cell counts, arrays.

Read with the same readers the build uses, so a file that validate describes
is one ingest can open; nothing is converted (counts and names only, the
coordinates' extent is taken by the caller in the declared units).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from softdesign.errors import InputDataError

#: Suffixes of surface meshes, which are no centerline (a user may give the STL by mistake).
MESH_SUFFIXES = {".stl": "STL", ".ply": "PLY", ".obj": "OBJ", ".glb": "glTF"}


@dataclass(frozen=True)
class FileFacts:
    """One input file's type and contents.

    Attributes
    ----------
    kind : e.g. ``VTK XML PolyData``, ``legacy VTK unstructured grid``, ``STL``, ``CSV``
    points : number of points (vertices)
    cells : number of cells by what they are (``lines``, ``triangles``, ``polygons``, ``vertices``, ``rows``)
    point_arrays, cell_arrays : names of the data arrays
    """

    kind: str
    points: int
    cells: dict[str, int] = field(default_factory=dict)
    point_arrays: tuple[str, ...] = ()
    cell_arrays: tuple[str, ...] = ()

    def text(self) -> str:
        """``VTK XML PolyData: 409 points, 2 lines; point arrays MaximumInscribedSphereRadius``"""
        cells = ", ".join(f"{count} {name}" for name, count in self.cells.items() if count)
        arrays = [f"{where} arrays {', '.join(names)}" for where, names in
                  (("point", self.point_arrays), ("cell", self.cell_arrays)) if names]
        return f"{self.kind}: {self.points} points" + (f", {cells}" if cells else "") + (
            "; " + "; ".join(arrays) if arrays else "; no data arrays")


def file_facts(path: Path) -> FileFacts:
    """The facts of a centerline or surface file (any suffix the project reads).

    Raises
    ------
    InputDataError
        The file cannot be read as its suffix says.
    """
    suffix = path.suffix.lower()
    if suffix in (".vtp", ".vtk", ".vtu"):
        return _vtk_facts(path)
    if suffix in MESH_SUFFIXES:
        from softdesign.io.formats import read_mesh

        vertices, faces = read_mesh(path)
        return FileFacts(MESH_SUFFIXES[suffix], len(vertices), {"triangles": len(faces)})
    if suffix in (".csv", ".npy"):
        from softdesign.io.centerline import read_centerline_network

        (line,) = read_centerline_network(path).polylines
        columns = ("x", "y", "z") + (("radius",) if line.radius is not None else ())
        return FileFacts(suffix[1:].upper(), len(line.points), {"rows": len(line.points)}, columns)
    raise InputDataError(f"{path}: unknown file type '{path.suffix}'")


def _vtk_facts(path: Path) -> FileFacts:
    from softdesign.io.centerline_segments import is_unstructured_grid, read_line_cells
    from softdesign.io.vtk_polydata import polydata_arrays, read_polydata, simple_vtp

    if is_unstructured_grid(path):
        grid = read_line_cells(path)
        return FileFacts(grid.kind, len(grid.points), {"lines": len(grid.cells), "other cells": grid.other_cells},
                         tuple(grid.point_arrays), tuple(grid.cell_arrays))
    kind = "VTK XML PolyData" if path.suffix.lower() == ".vtp" else "legacy VTK PolyData"
    simple = simple_vtp(path)  # without importing vtk where it can
    if simple is not None:
        return FileFacts(kind, len(simple.points), simple.cell_counts, tuple(simple.point_arrays),
                         tuple(simple.cell_arrays))
    poly = read_polydata(path)
    _, point_arrays, cell_arrays = polydata_arrays(poly)
    cells = {"lines": poly.GetNumberOfLines(), "polygons": poly.GetNumberOfPolys(),
             "triangle strips": poly.GetNumberOfStrips(), "vertices": poly.GetNumberOfVerts()}
    return FileFacts(kind, int(poly.GetNumberOfPoints()), cells, tuple(point_arrays), tuple(cell_arrays))
