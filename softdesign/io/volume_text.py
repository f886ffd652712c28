"""The text (ASCII) forms of a tetrahedral mesh that SOFA's loaders read, written at C speed.

SOFA's ``MeshVTKLoader`` reads an XML ``.vtu`` only with inline ``ascii``
data (its ``binary`` branch copies the element's text as raw bytes, so
VTK's base64, compressed or not, does not load), and its
``MeshGmshLoader`` parses Gmsh 2.2 as text (``file >> index >> x >> y >>
z``).  So both files stay text; what is fast here is the writing.  meshio's
text writers format one number per Python call (46 s of the demo's stage
went there); here:

``.vtu``
    VTK's own ``vtkXMLUnstructuredGridWriter`` in ASCII mode, into a string
    (no file): doubles with 17 significant digits (exact on reading back,
    where meshio's ``{:.11e}`` kept 12), connectivity, offsets and types as
    VTK writes them, and the cell and point arrays; no time or path in it, so
    the bytes depend only on the arrays.
``.msh``
    Gmsh 2.2 ASCII, the same bytes as meshio's ``gmsh22`` writer (a test
    compares them): each block of lines formatted by one ``%`` of a repeated
    line pattern over all its numbers (C's formatting, ``%.16e`` for
    coordinates as meshio's ``.16e``).
"""

from __future__ import annotations

import numpy as np

#: Gmsh 2.2's element types of the cells written (meshio's numbers).
GMSH_TYPES = {"tetra": 4, "triangle": 2, "vertex": 15}
#: VTK's cell types (vtkCellType.h).
VTK_TETRA, VTK_TRIANGLE = 10, 5


Blocks = list[tuple[str, np.ndarray, int]]


def msh22_ascii(points: np.ndarray, blocks: Blocks, names: dict[str, tuple[int, int]],
                memo: dict[str, str] | None = None) -> bytes:
    """Gmsh 2.2 ASCII of ``points`` (P, 3) and cell ``blocks`` (type, (k, n) 0-based nodes, physical tag).

    Each element carries two tags, physical and elementary, both the block's tag; ``names`` maps a physical
    group's name to (tag, dimension) for ``$PhysicalNames`` (empty: none written).  ``memo`` (kept by the
    caller between calls): the ``$Elements`` text by its blocks' digest, so one connectivity written at several
    q is formatted once (the aorta with chambers: 2.7 million integers a file, most of the .msh's time).
    """
    out = ["$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"]
    if names:
        entries = sorted((dim, tag, name) for name, (tag, dim) in names.items())
        out.append(f"$PhysicalNames\n{len(entries)}\n" + "".join(f'{d} {t} "{n}"\n' for d, t, n in entries)
                   + "$EndPhysicalNames\n")
    points = np.asarray(points, np.float64)
    numbered = np.column_stack([np.arange(1, len(points) + 1), points]).ravel().tolist()
    out.append(f"$Nodes\n{len(points)}\n" + ("%d %.16e %.16e %.16e\n" * len(points)) % tuple(numbered)
               + "$EndNodes\n")
    blocks = [(kind, np.asarray(cells, np.int64).reshape(len(cells), -1), tag) for kind, cells, tag in blocks]
    if memo is None:
        out.append(_elements(blocks))
    else:
        key = _digest(blocks)
        if key not in memo:
            memo[key] = _elements(blocks)
        out.append(memo[key])
    return "".join(out).encode("ascii")


def _digest(blocks: Blocks) -> str:
    """What the ``$Elements`` text depends on (each block's type, tag, shape and nodes), as a sha256."""
    import hashlib

    h = hashlib.sha256()
    for kind, cells, tag in blocks:
        h.update(f"{kind} {tag} {cells.shape}\n".encode("ascii"))
        h.update(np.ascontiguousarray(cells).tobytes())
    return h.hexdigest()


def _elements(blocks: Blocks) -> str:
    """The ``$Elements`` section of ``blocks`` ((k, n) int64 nodes each), numbered from 1 in order."""
    out = [f"$Elements\n{sum(len(cells) for _, cells, _ in blocks)}\n"]
    first = 1
    for kind, cells, tag in blocks:
        k = len(cells)
        rows = np.column_stack([np.arange(first, first + k), np.full(k, GMSH_TYPES[kind]), np.full(k, 2),
                                np.full(k, tag), np.full(k, tag), cells + 1])
        out.append((" ".join(["%d"] * rows.shape[1]) + "\n") * k % tuple(rows.ravel().tolist()))
        first += k
    out.append("$EndElements\n")
    return "".join(out)


def vtu_ascii(points: np.ndarray, tets: np.ndarray, triangles: np.ndarray, cell_data: dict[str, np.ndarray],
              point_data: dict[str, np.ndarray], field_data: dict[str, np.ndarray] | None = None) -> bytes:
    """XML ``.vtu`` with inline ASCII data, by VTK: tetrahedra then ``triangles``, and the arrays.

    Parameters
    ----------
    points : (P, 3) float, mm
    tets : (T, 4) int, VTK order
    triangles : (S, 3) int (may be empty)
    cell_data : name -> (T + S,) array (int64 or float64)
    point_data : name -> (P,) uint8
    field_data : name -> (k,) int64, arrays of the whole file (the names of the ``surface`` codes)
    """
    from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkUnstructuredGrid
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridWriter

    tets, triangles = np.asarray(tets, np.int64), np.asarray(triangles, np.int64).reshape(-1, 3)
    grid = vtkUnstructuredGrid()
    vtk_points = vtkPoints()
    vtk_points.SetData(numpy_to_vtk(np.ascontiguousarray(points, np.float64), deep=True))
    grid.SetPoints(vtk_points)
    offsets = np.concatenate([np.arange(0, 4 * len(tets) + 1, 4),
                              4 * len(tets) + np.arange(3, 3 * len(triangles) + 1, 3)]).astype(np.int64)
    cells = vtkCellArray()
    cells.SetData(numpy_to_vtkIdTypeArray(offsets, deep=True),
                  numpy_to_vtkIdTypeArray(np.concatenate([tets.ravel(), triangles.ravel()]), deep=True))
    types = np.concatenate([np.full(len(tets), VTK_TETRA), np.full(len(triangles), VTK_TRIANGLE)]).astype(np.uint8)
    grid.SetCells(numpy_to_vtk(types, deep=True), cells)
    for target, arrays in ((grid.GetCellData(), cell_data), (grid.GetPointData(), point_data),
                           (grid.GetFieldData(), field_data or {})):
        for name, values in arrays.items():
            array = numpy_to_vtk(np.ascontiguousarray(values), deep=True)
            array.SetName(name)
            target.AddArray(array)
    writer = vtkXMLUnstructuredGridWriter()
    writer.SetInputData(grid)
    writer.SetDataModeToAscii()
    writer.SetWriteToOutputString(True)
    if not writer.Write():
        raise RuntimeError("vtkXMLUnstructuredGridWriter failed on a volume mesh (a bug)")
    text: str = writer.GetOutputString()
    return text.encode("ascii")
