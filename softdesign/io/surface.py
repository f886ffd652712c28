"""Read vessel surfaces into triangle arrays (mm).

Formats, by suffix: ``.stl`` (ASCII and binary), ``.ply``, ``.obj`` through
trimesh, and ``.vtp``/``.vtk`` PolyData through vtk.  Polygons other than
triangles are triangulated; vertices shared by faces are merged, so a capped
VMTK surface reads as a closed mesh.  The input is never decimated.
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

import numpy as np

from softdesign.errors import InputDataError
from softdesign.io.vtk_polydata import read_polydata, triangles_from_polydata

Mesh = tuple[np.ndarray, np.ndarray]


def read_surface(path: str | Path, scale_to_mm: float = 1.0) -> Mesh:
    """Vertices (V, 3) float64 mm and faces (F, 3) int64 of a surface file.

    Raises
    ------
    InputDataError
        Missing or unreadable file, unknown suffix, or a surface with no triangles.
    """
    path = Path(path)
    reader = _READERS.get(path.suffix.lower())
    if reader is None:
        raise InputDataError(
            f"{path}: unknown surface format '{path.suffix}'; expected one of {', '.join(sorted(_READERS))}"
        )
    if not path.is_file():
        raise InputDataError(f"{path}: surface file not found; check final.surface in the case file")
    vertices, faces = reader(path)
    if len(faces) == 0 or len(vertices) == 0:
        raise InputDataError(
            f"{path}: the surface is empty (0 triangles); expected the vessel wall from VMTK "
            "(e.g. vmtkmarchingcubes + vmtksurfacecapper output)"
        )
    if not np.all(np.isfinite(vertices)):
        raise InputDataError(f"{path}: the surface has NaN or infinite vertex coordinates; re-export it")
    return vertices * scale_to_mm, faces


def _read_trimesh(path: Path) -> Mesh:
    import trimesh

    try:
        mesh = trimesh.load(str(path), force="mesh", process=True)
    except Exception as err:  # trimesh raises many types for malformed files
        raise InputDataError(f"{path}: cannot read the surface ({type(err).__name__}: {err}); re-export it") from err
    if not isinstance(mesh, trimesh.Trimesh):
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64)
    return np.asarray(mesh.vertices, np.float64), np.asarray(mesh.faces, np.int64)


def _read_vtk_surface(path: Path) -> Mesh:
    vertices, faces = triangles_from_polydata(read_polydata(path))
    return _merge_duplicate_vertices(vertices, faces)


def _merge_duplicate_vertices(vertices: np.ndarray, faces: np.ndarray) -> Mesh:
    if len(vertices) == 0:
        return vertices, faces
    unique, inverse = np.unique(vertices, axis=0, return_inverse=True)
    used = np.unique(inverse[faces])
    remap = np.full(len(unique), -1, np.int64)
    remap[used] = np.arange(len(used))
    return unique[used], remap[inverse.reshape(-1)[faces]]


_READERS: dict[str, Callable[[Path], Mesh]] = {
    ".stl": _read_trimesh,
    ".ply": _read_trimesh,
    ".obj": _read_trimesh,
    ".vtp": _read_vtk_surface,
    ".vtk": _read_vtk_surface,
}
