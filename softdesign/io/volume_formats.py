"""Tetrahedral meshes as simulators load them: ASCII XML .vtu and Gmsh .msh 2.2, read back through meshio.

SOFA's ``MeshVTKLoader`` reads only inline (ASCII) data of an XML ``.vtu``,
not the appended or base64 binary blocks most writers make, and SOFA's
``MeshGmshLoader`` reads Gmsh's format 2.2; FEBio and Abaqus users convert
from either.  So both are written as text: ``.vtu`` with every DataArray
``format="ascii"`` and ``.msh`` as ``$MeshFormat 2.2 0 8`` (ASCII), each
tetrahedron with physical and elementary tag 1 (the one body).  Node order
is VTK's, which is Gmsh's for linear tetrahedra.

Named sets (:class:`NamedSets`, the swept mesher's): each named surface's
triangles follow the tetrahedra as cells of their own; in ``.vtu`` the cell
array ``surface`` holds each cell's surface number (-1 for a tetrahedron,
numbers in the order of ``NamedSets.surfaces``), a point array per node set is
1 on its nodes, and per-tetrahedron figures are cell arrays (NaN on the
triangles).  The ``.vtu`` names its codes in a field-data table
(:func:`surface_name_table`): one integer array per name, ``[code, dimension]``
(``body``: ``[-1, 3]``, each surface ``[k, 2]``).  That is the form meshio gives
a Gmsh file's physical names (``mesh.field_data``), so a meshio user reads the
names of either file the same way, and ParaView lists field data under the
file's Information and in the spreadsheet view.  A table and not one 0/1 array
per set: the chambered demo has 39 surfaces, and an array each would add 39
numbers per cell to an ASCII file; and not VTK's string array (as the ``.vtp``
export's ``RegionNames``), which meshio's ``.vtu`` reader refuses
(``Illegal data type 'String'``), losing the whole file.  In ``.msh``
the body is physical group 1 (``body``, dimension 3), each surface a
physical group of dimension 2 numbered from 2, each node set a group of
dimension 0 (point elements), all named in ``$PhysicalNames``.  The writing is
:mod:`softdesign.io.volume_text`'s (VTK's writer for ``.vtu``, meshio's
bytes of ``.msh`` at C speed); neither format holds a timestamp, so the
bytes depend only on the arrays.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from softdesign.errors import InputDataError
from softdesign.io.volume_text import msh22_ascii, vtu_ascii

#: suffix -> meshio's name of the format and its reader's module (the reading side).
VOLUME_FORMATS: dict[str, tuple[str, str]] = {"vtu": ("vtu", "vtu"), "msh": ("gmsh22", "gmsh")}


@dataclass(frozen=True)
class NamedSets:
    """Named surfaces, node sets and per-tetrahedron figures to write with a tetrahedral mesh.

    Attributes
    ----------
    surfaces : name -> (k, 3) int triangles (node indices)
    node_sets : name -> (k,) int node indices
    tet_data : name -> (T,) float per-tetrahedron figures (``.vtu`` only)
    """

    surfaces: dict[str, np.ndarray] = field(default_factory=dict)
    node_sets: dict[str, np.ndarray] = field(default_factory=dict)
    tet_data: dict[str, np.ndarray] = field(default_factory=dict)


def volume_mesh_bytes(points: np.ndarray, tets: np.ndarray, suffix: str, sets: NamedSets | None = None,
                      memo: dict[str, str] | None = None) -> bytes:
    """The file of a tetrahedral mesh, ``suffix`` ``vtu`` or ``msh``, with its named sets (module notes).

    Parameters
    ----------
    points : (P, 3) float, mm
    tets : (T, 4) int, VTK order
    sets : named surfaces, node sets and per-tetrahedron figures, or None (the tetrahedra alone)
    memo : a dict the caller keeps between the meshes of one build: ``.msh``'s element text, formatted once per
        connectivity (:func:`~softdesign.io.volume_text.msh22_ascii`); the bytes are the same with or without
    """
    if suffix not in VOLUME_FORMATS:
        raise ValueError(f"volume mesh format must be one of {', '.join(VOLUME_FORMATS)}, got {suffix!r}")
    sets = sets or NamedSets()
    points, tets = np.asarray(points, np.float64), np.asarray(tets, np.int64)
    names = list(sets.surfaces)
    triangles = [np.asarray(sets.surfaces[n], np.int64).reshape(-1, 3) for n in names]
    if suffix == "msh":
        blocks = [("tetra", tets, 1)] + [("triangle", t, 2 + k) for k, t in enumerate(triangles)] + [
            ("vertex", np.asarray(v, np.int64).reshape(-1, 1), 2 + len(names) + k)
            for k, v in enumerate(sets.node_sets.values())]
        dims = [3] + [2] * len(triangles) + [0] * len(sets.node_sets)
        groups = {name: (tag, dim) for name, (_, _, tag), dim in
                  zip(["body", *names, *sets.node_sets], blocks, dims, strict=True)}
        return msh22_ascii(points, blocks, groups if len(blocks) > 1 else {}, memo)
    faces = np.concatenate(triangles) if triangles else np.zeros((0, 3), np.int64)
    cell_data: dict[str, np.ndarray] = {}
    if triangles:
        ids = np.concatenate([np.full(len(t), k, np.int64) for k, t in enumerate(triangles)])
        cell_data["surface"] = np.concatenate([np.full(len(tets), -1, np.int64), ids])
    field_data = surface_name_table(names) if triangles else {}
    for name, values in sets.tet_data.items():
        cell_data[name] = np.concatenate([np.asarray(values, np.float64), np.full(len(faces), np.nan)])
    point_data = {}
    for name, nodes in sets.node_sets.items():  # surfaces are named by the cell array (a point array per surface
        # cost the chambered demo's 39 surfaces 6 million ASCII numbers)
        flag = np.zeros(len(points), np.uint8)
        flag[np.asarray(nodes, np.int64).ravel()] = 1
        point_data[name] = flag
    return vtu_ascii(points, tets, faces, cell_data, point_data, field_data)


def surface_name_table(names: list[str]) -> dict[str, np.ndarray]:
    """The ``.vtu``'s field data naming its ``surface`` codes: name -> ``[code, dimension]`` (int64, (2,)).

    ``body`` is the tetrahedra's -1 (dimension 3); surface k (in ``NamedSets.surfaces`` order) is k, dimension 2.
    """
    table = {"body": np.array([-1, 3], np.int64)}
    table.update({name: np.array([k, 2], np.int64) for k, name in enumerate(names)})
    return table


def read_volume_mesh(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Points (P, 3) float64 mm and tetrahedra (T, 4) int64 of a .vtu or .msh file.

    Raises
    ------
    InputDataError
        An unknown suffix, an unreadable file, or no tetrahedra.
    """
    import importlib

    path = Path(path)
    suffix = path.suffix.lower().lstrip(".")
    if suffix not in VOLUME_FORMATS:
        raise InputDataError(f"{path}: unknown volume mesh format; expected .{', .'.join(VOLUME_FORMATS)}")
    try:
        # the format's own reader: meshio.read ends the process (sys.exit) when a file does not parse
        mesh = importlib.import_module(f"meshio.{VOLUME_FORMATS[suffix][1]}").read(str(path))
    except Exception as err:  # meshio raises many types (ReadError, ValueError, KeyError) for a bad file
        raise InputDataError(f"{path}: cannot read it as a volume mesh ({type(err).__name__}: {err})") from err
    blocks = [c.data for c in mesh.cells if c.type == "tetra"]
    if not blocks:
        raise InputDataError(f"{path}: the file holds no tetrahedra")
    return np.asarray(mesh.points, np.float64), np.concatenate(blocks).astype(np.int64)
