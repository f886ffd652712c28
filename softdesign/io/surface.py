"""Read vessel surfaces into triangle arrays (mm).

Formats, by suffix: ``.stl`` (ASCII and binary), ``.ply``, ``.obj``, and
``.vtp``/``.vtk`` PolyData, read as :mod:`softdesign.io.formats` reads them:
polygons other than triangles are triangulated; vertices shared by faces are
merged, so a capped VMTK surface reads as a closed mesh.  The input is never
decimated.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from softdesign.errors import InputDataError
from softdesign.io.formats import FORMATS, Mesh
from softdesign.io.input_checks import check_input_file
from softdesign.types import FloatArray, Mapper

#: The formats vessel walls come in from VMTK, 3D Slicer or ParaView (.glb is an output for viewers).
SURFACE_FORMATS = ("stl", "ply", "obj", "vtp", "vtk")


def read_surface(path: str | Path, scale_to_mm: float = 1.0, mapper: Mapper | None = None) -> Mesh:
    """Vertices (V, 3) float64 mm and faces (F, 3) int64 of a surface file.

    ``mapper``: runs a large binary STL's vertex merge in two halves, perhaps on other processes (the build's
    workers); the same arrays (:class:`~softdesign.io.formats.MeshFormat`'s ``read``).

    Raises
    ------
    InputDataError
        Missing or unreadable file, unknown suffix, or a surface with no triangles.
    """
    path = Path(path)
    name = path.suffix.lower().lstrip(".")
    if name not in SURFACE_FORMATS:
        raise InputDataError(
            f"{path}: unknown surface format '{path.suffix}'; expected one of "
            + ", ".join(sorted(f".{f}" for f in SURFACE_FORMATS))
        )
    check_input_file(path, "surface")
    vertices, faces = FORMATS[name].read(path, scale_to_mm, mapper)
    check_surface_arrays(path, vertices, len(faces))
    return vertices * scale_to_mm, faces


def check_surface_arrays(path: Path, vertices: FloatArray, triangles: int) -> None:
    """Raise InputDataError for a surface with no triangles or with coordinates that are not finite.

    Parameters
    ----------
    path : the surface file, for the message
    vertices : (V, 3) float, its vertices (file units)
    triangles : its triangle count
    """
    if triangles == 0 or len(vertices) == 0:
        raise InputDataError(
            f"{path}: the surface is empty (0 triangles); expected the vessel wall from VMTK "
            "(e.g. vmtkmarchingcubes + vmtksurfacecapper output)"
        )
    bad = ~np.all(np.isfinite(vertices), axis=1)
    if bad.any():
        raise InputDataError(f"{path}: {int(bad.sum())} of its {len(vertices)} vertices have NaN or infinite "
                             f"coordinates (the first: vertex {int(np.argmax(bad))}); expected finite coordinates: "
                             "re-export the surface, or repair it (e.g. vmtksurfacecleaner)")
