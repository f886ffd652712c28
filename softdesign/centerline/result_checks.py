"""Whether extracted centerlines mean anything: refused, with the evidence, when they cannot be a vessel's axis.

The extraction always returns something: a closed sphere gave a 0.16 mm
line, a coarse capped cylinder of radius 3 a radius of 30, a thick-walled
tube no line at all, a surface in the wrong units a 0.00 mm line.  Each
path is checked against the surface it came from (:func:`check_centerlines`):

* the surface is at least :data:`SMALLEST_SURFACE_MM` across (else its units are not the ones given);
* there is at least one path;
* a path is longer than its own widest inscribed sphere (a vessel between an
  inlet and an outlet is longer than it is wide; a surface with no opening
  yields a stub at its middle);
* every radius is at most the point's true distance to the wall (to the
  nearest triangle, not vertex) times :data:`RADIUS_OVER_WALL_MOST` (an
  inscribed sphere touches the wall, it does not pass through it);
* the surface's median edge is at most :data:`EDGE_OVER_RADIUS_MOST` times
  the median radius (a surface too coarse to resolve the radius it implies).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from softdesign.errors import InputDataError

#: Largest radius over distance-to-wall accepted (the Voronoi radius is measured to sampled wall points).
RADIUS_OVER_WALL_MOST = 1.1
#: Largest median surface edge over the median radius: beyond it the wall is not sampled finely enough.
EDGE_OVER_RADIUS_MOST = 2.0
#: Smallest surface extent accepted, mm: a vessel the centerline command can trace is at least this wide.
SMALLEST_SURFACE_MM = 1.0
#: Points per path checked against the wall (evenly spaced): enough to find a radius through the wall.
CHECKED_POINTS = 200


def check_centerlines(
    paths: tuple[npt.NDArray[np.float64], ...], radii: tuple[npt.NDArray[np.float64], ...],
    vertices: npt.NDArray[np.float64], faces: npt.NDArray[np.int64], where: str,
    continued_mm: tuple[tuple[float, float], ...] = (),
) -> None:
    """InputDataError naming the first path that cannot be a vessel's axis, and why (mm in, mm in messages).

    ``continued_mm``: per path, how far each end was continued straight to its opening's centre (its radius held
    there, :mod:`.ends`); those runs reach the opening's plane by design and are not held to the wall's distance.
    """
    fix = ("expected a vessel surface open at its inlet and outlets, or capped (vmtksurfacecapper), in the units "
           "given by --units, finely enough meshed for its radius (vmtksurfaceremeshing)")
    extent = float(np.ptp(vertices, axis=0).max()) if len(vertices) else 0.0
    if extent < SMALLEST_SURFACE_MM:
        raise InputDataError(f"{where}: the surface is {extent:.4g} mm across, smaller than any vessel "
                             f"({SMALLEST_SURFACE_MM:g} mm): its units are not the ones given (--units); {fix}")
    if not paths:
        raise InputDataError(f"{where}: no centerline could be traced through the surface; {fix}")
    edges = vertices[faces[:, [1, 2, 0]]] - vertices[faces]
    median_edge = float(np.median(np.linalg.norm(edges, axis=2)))
    for k, (points, radius) in enumerate(zip(paths, radii, strict=True)):
        length = float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum()) if len(points) > 1 else 0.0
        widest = float(np.max(radius)) if len(radius) else 0.0
        ends = continued_mm[k] if k < len(continued_mm) else (0.0, 0.0)
        _check_inside_wall(k, points, radius, _inner(points, ends), vertices, faces, where, fix)
        if length <= widest:
            raise InputDataError(f"{where}: path {k} is {length:.4g} mm long but {widest:.4g} mm wide in radius: "
                                 f"no opening to run between (a closed surface, or a stub); {fix}")
        if median_edge > EDGE_OVER_RADIUS_MOST * float(np.median(radius)):
            raise InputDataError(
                f"{where}: the surface's median edge is {median_edge:.4g} mm, more than {EDGE_OVER_RADIUS_MOST:g} "
                f"times path {k}'s median radius {float(np.median(radius)):.4g} mm: too coarse to give that radius; "
                f"{fix}")


def _inner(points: npt.NDArray[np.float64], ends: tuple[float, float]) -> npt.NDArray[np.bool_]:
    """The points of a path outside its straight end continuations (``ends``: mm at the inlet and the outlet)."""
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    return (s >= ends[0]) & (s <= s[-1] - ends[1])


def _check_inside_wall(k: int, points: npt.NDArray[np.float64], radius: npt.NDArray[np.float64],
                       inner: npt.NDArray[np.bool_], vertices: npt.NDArray[np.float64], faces: npt.NDArray[np.int64],
                       where: str, fix: str) -> None:
    from vtkmodules.vtkFiltersCore import vtkImplicitPolyDataDistance

    from softdesign.meshing.vtk_triangles import polydata_from_triangles

    candidates = np.flatnonzero(inner) if inner.any() else np.arange(len(points))
    pick = candidates[np.unique(np.linspace(0, len(candidates) - 1, min(CHECKED_POINTS, len(candidates))).astype(int))]
    wall: Any = vtkImplicitPolyDataDistance()  # vtk's stubs type EvaluateFunction's answer as None
    wall.SetInput(polydata_from_triangles(vertices, faces))
    distance = np.abs(np.array([float(wall.EvaluateFunction(*map(float, p))) for p in points[pick]]))
    over = radius[pick] / np.maximum(distance, 1e-300)
    worst = int(np.argmax(over))
    if over[worst] > RADIUS_OVER_WALL_MOST:
        raise InputDataError(
            f"{where}: path {k} has radius {radius[pick][worst]:.4g} mm at point {int(pick[worst])}, which is "
            f"{distance[worst]:.4g} mm from the wall: an inscribed sphere cannot reach through the wall; {fix}")
