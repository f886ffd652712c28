"""Tetrahedra inside a closed triangle mesh with fTetWild (through pytetwild), as plain arrays.

fTetWild (Hu et al., "Fast Tetrahedral Meshing in the Wild", SIGGRAPH 2020)
fills the volume a closed surface bounds, keeping its boundary within an
envelope of the input surface; a closed inner shell (a hollow body's chamber)
stays empty, since it fills by winding number.  Its target edge length and
envelope are given here in mm (pytetwild takes the envelope relative to the
bounding box diagonal).  The result is in VTK's and Gmsh's node order (every
tetrahedron positive, :mod:`softdesign.meshing.volume_mesh.tet_quality`).

fTetWild is not deterministic: two runs on the same surface give different
tetrahedra (the same volume, within the envelope), as pytetwild's maintainers
note (pytetwild pull request 38).  It runs native code that may crash or
take long: callers run :func:`tetrahedralize` in a child process
(:mod:`softdesign.pipeline.child`).
"""

from __future__ import annotations

import sys
import types
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.types import FloatArray, IntArray


@dataclass(frozen=True)
class TetSettings:
    """What fTetWild is asked for.

    Attributes
    ----------
    size_mm : target edge length, mm
    envelope_mm : largest distance of the mesh's boundary from the input surface, mm
    """

    size_mm: float
    envelope_mm: float


def _import_pytetwild() -> types.ModuleType:
    # pytetwild 0.4 imports pyvista on import only to register an optional accessor, though its package
    # metadata leaves pyvista to the "all" extra; its accessor module is a documented no-op when pyvista has no
    # accessor registry.  An empty stand-in takes that path: in the child process only, and only when pyvista
    # is not installed, so nothing else sees it.
    try:
        import pyvista  # noqa: F401
    except ImportError:
        sys.modules.setdefault("pyvista", types.ModuleType("pyvista"))
    import pytetwild

    return pytetwild


def tetrahedralize(vertices: npt.ArrayLike, faces: npt.ArrayLike, settings: TetSettings) -> tuple[FloatArray, IntArray]:
    """Tetrahedra filling the closed surface ``(vertices, faces)``.

    Parameters
    ----------
    vertices : (V, 3) float, mm
    faces : (F, 3) int, wound outwards; several shells (a body and its chamber) are fine
    settings : target size and envelope, mm

    Returns
    -------
    points : (P, 3) float64, mm
    tets : (T, 4) int64, VTK / Gmsh order (positive volumes)
    """
    v = np.ascontiguousarray(vertices, np.float64)
    f = np.ascontiguousarray(faces, np.int32)
    diagonal = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    pytetwild = _import_pytetwild()
    # one thread: the machine is shared, and more threads do not make fTetWild deterministic either
    points, tets = pytetwild.tetrahedralize(
        v, f, edge_length_abs=settings.size_mm, epsilon=settings.envelope_mm / diagonal, num_threads=1,
        vtk_ordering=True, quiet=True,
    )
    return np.asarray(points, np.float64), np.asarray(tets, np.int64)
