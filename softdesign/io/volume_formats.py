"""Tetrahedral meshes as simulators load them, through meshio: ASCII XML .vtu and Gmsh .msh 2.2.

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
numbers in the order of ``NamedSets.surfaces``, their names in the summary),
a point array per named set (surface or node set) is 1 on its nodes, and
per-tetrahedron figures are cell arrays (NaN on the triangles); in ``.msh``
the body is physical group 1 (``body``, dimension 3), each surface a
physical group of dimension 2 numbered from 2, each node set a group of
dimension 0 (point elements), all named in ``$PhysicalNames``.  meshio writes only to
file names, so the bytes are written in a temporary folder and read back;
neither format holds a timestamp, so the bytes depend only on the arrays.
"""

from __future__ import annotations

import contextlib
import io
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from softdesign.errors import InputDataError

#: suffix -> meshio's name of the format for writing, its reader's module, and the writer's options.
VOLUME_FORMATS: dict[str, tuple[str, str, dict[str, object]]] = {
    "vtu": ("vtu", "vtu", {"binary": False}),
    "msh": ("gmsh22", "gmsh", {"binary": False}),
}


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


def _mesh(points: np.ndarray, tets: np.ndarray, suffix: str, sets: NamedSets):  # -> meshio.Mesh
    import meshio

    names = list(sets.surfaces)
    triangles = [np.asarray(sets.surfaces[n], np.int64).reshape(-1, 3) for n in names]
    if suffix == "msh":
        cells = [("tetra", tets)] + [("triangle", t) for t in triangles] + [
            ("vertex", np.asarray(v, np.int64).reshape(-1, 1)) for v in sets.node_sets.values()]
        tags = [1] + list(range(2, 2 + len(cells) - 1))
        blocks = [np.full(len(c[1]), tag, np.int64) for c, tag in zip(cells, tags, strict=True)]
        dims = [3] + [2] * len(triangles) + [0] * len(sets.node_sets)
        field_data = {name: np.array([tag, dim]) for name, tag, dim in
                      zip(["body", *names, *sets.node_sets], tags, dims, strict=True)}
        return meshio.Mesh(points, cells, cell_data={"gmsh:physical": blocks, "gmsh:geometrical": blocks},
                           field_data=field_data if len(cells) > 1 else {})
    cells = [("tetra", tets)] + ([("triangle", np.concatenate(triangles))] if triangles else [])
    cell_data: dict[str, list[np.ndarray]] = {}
    if triangles:
        ids = np.concatenate([np.full(len(t), k, np.int64) for k, t in enumerate(triangles)])
        cell_data["surface"] = [np.full(len(tets), -1, np.int64), ids]
    for name, values in sets.tet_data.items():
        cell_data[name] = [np.asarray(values, np.float64)] + ([np.full(len(ids), np.nan)] if triangles else [])
    point_data = {}
    for name, nodes in [*zip(names, triangles, strict=True), *sets.node_sets.items()]:
        flag = np.zeros(len(points), np.uint8)
        flag[np.asarray(nodes, np.int64).ravel()] = 1
        point_data[name] = flag
    return meshio.Mesh(points, cells, cell_data=cell_data, point_data=point_data)


def volume_mesh_bytes(points: np.ndarray, tets: np.ndarray, suffix: str, sets: NamedSets | None = None) -> bytes:
    """The file of a tetrahedral mesh, ``suffix`` ``vtu`` or ``msh``, with its named sets (module notes).

    Parameters
    ----------
    points : (P, 3) float, mm
    tets : (T, 4) int, VTK order
    sets : named surfaces, node sets and per-tetrahedron figures, or None (the tetrahedra alone)
    """
    import meshio

    if suffix not in VOLUME_FORMATS:
        raise ValueError(f"volume mesh format must be one of {', '.join(VOLUME_FORMATS)}, got {suffix!r}")
    file_format, _, options = VOLUME_FORMATS[suffix]
    tets = np.asarray(tets, np.int64)
    mesh = _mesh(np.asarray(points, np.float64), tets, suffix, sets or NamedSets())
    with tempfile.TemporaryDirectory(prefix="softdesign-volume-") as folder:
        path = Path(folder) / f"mesh.{suffix}"
        # meshio warns on stderr that ASCII .vtu is "only meant for debugging": it is what SOFA reads
        with contextlib.redirect_stderr(io.StringIO()):
            meshio.write(path, mesh, file_format=file_format, **options)
        return path.read_bytes()


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
