"""Continue each path straight from the Voronoi diagram's last vertex to its opening, as VMTK's do.

The least-cost path runs between Voronoi vertices, so it stops about one
inscribed radius inside each opening: the pole, whose empty sphere touches the
opening's centre.  VMTK's ``vmtkcenterlines`` appends the seed points (the cap
centres) to its paths (``-endpoints 1``, on by default with open profiles); so
does :func:`reach_ends`, with a straight run from the path's end to the
opening's centre, taken only when that run stays inside the surface (a ray
cast on the closed surface: the centre lies on the cap, so nothing is hit
before it).

A closed, rounded end (a domed cap, found as a graph extremity) has no centre
to reach.  The medial axis of a rounded end stops at the centre of the sphere
that touches its tip: the path is continued along its end tangent to the
point one inscribed radius short of where that tangent meets the wall, and
not at all when the path is already there.

The continuation of each end is reported in mm, so the summary can say how
much of a path is a straight extension rather than Voronoi diagram.

No files, no printing: numpy only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softdesign.types import FloatArray, IntArray, Points

#: A straight run to an opening's centre may pass within this fraction of a mean edge of the surface
#: before reaching it (the centre lies on the cap's fan, so the ray meets the cap at the centre itself).
INSIDE_TOL_REL = 0.5
#: The end tangent is the direction from the path's vertex this many inscribed radii back to its end.
TANGENT_RADII = 1.0


@dataclass(frozen=True)
class EndTargets:
    """Where one path should end, mm: an opening's centre at each end, or nothing to reach.

    Attributes
    ----------
    inlet, outlet : (3,) float or None -- the opening's centre; None: no opening there
    rounded : (inlet, outlet) -- an end with no opening that is a rounded end of the surface (continued to the
        centre of the sphere touching its tip); an end with neither (a point the user gave) is not continued
    """

    inlet: FloatArray | None
    outlet: FloatArray | None
    rounded: tuple[bool, bool] = (False, False)


@dataclass(frozen=True)
class Reached:
    """A path with its straight continuations, and their lengths.

    Attributes
    ----------
    points : (n, 3) float, mm -- continuation at the inlet, the Voronoi path, continuation at the outlet
    continued_mm : (inlet, outlet) length of each straight continuation, mm
    short_mm : (inlet, outlet) distance still left to each opening's centre (0 when reached or rounded), mm
    """

    points: Points
    continued_mm: tuple[float, float]
    short_mm: tuple[float, float]


def reach_ends(
    points: Points, radius: FloatArray, targets: EndTargets, surface: tuple[FloatArray, IntArray], step_mm: float
) -> Reached:
    """Continue the Voronoi path ``points`` (n, 3) mm, radii (n,) mm, straight to its ends' targets.

    Parameters
    ----------
    points : (n, 3) float, mm, inlet first
    radius : (n,) float, mm -- inscribed radius at each point
    targets : the openings' centres, or None for a rounded end
    surface : (V, 3) vertices mm and (F, 3) faces of the closed, outward-wound surface
    step_mm : spacing of the points added on a straight run

    Returns
    -------
    Reached
    """
    runs, continued, short = [], [], []
    for end, target, rounded in ((0, targets.inlet, targets.rounded[0]), (-1, targets.outlet, targets.rounded[1])):
        goal = points[end] if target is None and not rounded else _goal(points, radius, end, target, surface, step_mm)
        runs.append(straight_run(points[end], goal, step_mm))
        continued.append(float(np.linalg.norm(goal - points[end])))
        short.append(0.0 if target is None else float(np.linalg.norm(target - goal)))
    joined = np.concatenate([runs[0][::-1], points, runs[1]])
    return Reached(joined, (continued[0], continued[1]), (short[0], short[1]))


def _goal(
    points: Points, radius: FloatArray, end: int, target: FloatArray | None,
    surface: tuple[FloatArray, IntArray], step_mm: float,
) -> FloatArray:
    """Where the end ``end`` (0 or -1) of the path goes: its target if reachable, the rounded end's axis tip else."""
    tip = points[end]
    if target is not None:
        offset = target - tip
        distance = float(np.linalg.norm(offset))
        if distance <= step_mm * INSIDE_TOL_REL:
            return tip
        free = ray_to_surface(*surface, tip, offset / distance)
        return target if free >= distance - INSIDE_TOL_REL * step_mm else tip
    tangent = end_tangent(points, radius, end)
    free = ray_to_surface(*surface, tip, tangent)
    reach = free - float(radius[end])
    return tip + tangent * reach if np.isfinite(reach) and reach > 0.0 else tip


def end_tangent(points: Points, radius: FloatArray, end: int) -> FloatArray:
    """Unit direction (3,) out of the path at ``end`` (0: inlet, -1: outlet), over TANGENT_RADII radii of it."""
    backwards = points[::-1] if end == -1 else points  # from the end point into the path
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(backwards, axis=0), axis=1))])
    back = int(np.searchsorted(s, TANGENT_RADII * float(radius[end])))
    direction = backwards[0] - backwards[min(max(back, 1), len(backwards) - 1)]
    return direction / max(float(np.linalg.norm(direction)), 1e-12)


def straight_run(start: FloatArray, goal: FloatArray, step_mm: float) -> Points:
    """Points (k, 3) from ``start`` (excluded) to ``goal`` (included) at most ``step_mm`` apart; empty when equal."""
    length = float(np.linalg.norm(goal - start))
    if length <= 0.0:
        return np.zeros((0, 3))
    count = max(int(np.ceil(length / step_mm)), 1)
    return start + (goal - start) * (np.arange(1, count + 1) / count)[:, None]


def ray_to_surface(vertices: FloatArray, faces: IntArray, origin: FloatArray, direction: FloatArray) -> float:
    """Distance (mm) along the unit ``direction`` from ``origin`` to the first triangle hit, inf if none.

    Moller-Trumbore on every triangle at once (a vessel surface has at most MAX_TRIANGLES of them).
    """
    a = vertices[faces[:, 0]]
    e1, e2 = vertices[faces[:, 1]] - a, vertices[faces[:, 2]] - a
    p = np.cross(direction, e2)
    det = np.einsum("ij,ij->i", e1, p)
    ok = np.abs(det) > 1e-12
    inverse = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    t_vec = origin - a
    u = np.einsum("ij,ij->i", t_vec, p) * inverse
    q = np.cross(t_vec, e1)
    v = (q @ direction) * inverse
    t = np.einsum("ij,ij->i", e2, q) * inverse
    hit = ok & (u >= 0.0) & (v >= 0.0) & (u + v <= 1.0) & (t > 0.0)
    return float(t[hit].min()) if hit.any() else float("inf")
