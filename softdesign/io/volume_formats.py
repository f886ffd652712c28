"""Tetrahedral meshes as simulators load them, through meshio: ASCII XML .vtu and Gmsh .msh 2.2.

SOFA's ``MeshVTKLoader`` reads only inline (ASCII) data of an XML ``.vtu``,
not the appended or base64 binary blocks most writers make, and SOFA's
``MeshGmshLoader`` reads Gmsh's format 2.2; FEBio and Abaqus users convert
from either.  So both are written as text: ``.vtu`` with every DataArray
``format="ascii"`` and ``.msh`` as ``$MeshFormat 2.2 0 8`` (ASCII), each
tetrahedron with physical and elementary tag 1 (the one body).  Node order
is VTK's, which is Gmsh's for linear tetrahedra.  meshio writes only to
file names, so the bytes are written in a temporary folder and read back;
neither format holds a timestamp, so the bytes depend only on the arrays.
"""

from __future__ import annotations

import contextlib
import io
import tempfile
from pathlib import Path

import numpy as np

from softdesign.errors import InputDataError

#: suffix -> meshio's name of the format for writing, its reader's module, and the writer's options.
VOLUME_FORMATS: dict[str, tuple[str, str, dict[str, object]]] = {
    "vtu": ("vtu", "vtu", {"binary": False}),
    "msh": ("gmsh22", "gmsh", {"binary": False}),
}


def volume_mesh_bytes(points: np.ndarray, tets: np.ndarray, suffix: str) -> bytes:
    """The file of a tetrahedral mesh, ``suffix`` ``vtu`` or ``msh``.

    Parameters
    ----------
    points : (P, 3) float, mm
    tets : (T, 4) int, VTK order
    """
    import meshio

    if suffix not in VOLUME_FORMATS:
        raise ValueError(f"volume mesh format must be one of {', '.join(VOLUME_FORMATS)}, got {suffix!r}")
    file_format, _, options = VOLUME_FORMATS[suffix]
    tets = np.asarray(tets, np.int64)
    ones = np.ones(len(tets), np.int64)
    cell_data = {"gmsh:physical": [ones], "gmsh:geometrical": [ones]} if suffix == "msh" else {}
    mesh = meshio.Mesh(np.asarray(points, np.float64), [("tetra", tets)], cell_data=cell_data)
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
