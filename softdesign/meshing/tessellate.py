"""Tessellation of one body S(q): rings of vertices on the (l, a) grid, caps in the end planes.

Geometry
    Station i along the centerline carries a point ``c_i``, a frame with
    columns (N, B, T) and a section curve ``p_i(a) = (x, y)`` in frame
    coordinates, so that a surface point is ``S = c + x N + y B``.  The tube
    of the seed has ``x + i y = rho e^{i a}`` on the angle grid
    ``a_k = 2 pi k / na``; offset bodies have general star-shaped sections.
    Every section lies in its station's normal plane, so the end rings lie
    exactly in the end-frame planes and a planar cap closes them.
Offset along the surface normal
    :func:`softdesign.meshing.volume.section_curves` (derivation there):
    every offset section stays in its station's plane, so the caps of an
    offset body are the 2-D offsets of the original caps, and offsets add up
    (a wall w inside an offset d is the offset d - w).
Winding
    ``S_a x S_s`` points outward, so each quad (i, k)-(i+1, k+1) of the grid
    gives the triangles [(i,k), (i,k+1), (i+1,k)] and [(i,k+1), (i+1,k+1),
    (i+1,k)], counter-clockwise seen from outside; the base cap faces -T, the
    tip cap +T.  Vertex ``i * na + k`` is ring i, angle k; the two cap
    centres follow the rings (base first).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntEnum

import numpy as np
import numpy.typing as npt

from softdesign.errors import MeshError
from softdesign.meshing.volume import MIN_RADIUS_MM, angle_grid, section_curves
from softdesign.types import FloatArray, IntArray

#: A surface folds where rho * kappa (the section's reach towards the centre of curvature) reaches this.
FOLD_LIMIT = 1.0
#: Largest |F^T F - I| accepted for a frame (columns N, B, T).
FRAME_TOL = 1e-6
#: A ring closer than this fraction of the local ring spacing to a trimmed end is dropped (no slivers).
TRIM_GAP_FRACTION = 0.25


class Region(IntEnum):
    """Face labels carried with every mesh (which face is wall, cap, chamber or port)."""

    WALL = 0
    BASE_CAP = 1
    TIP_CAP = 2
    CHAMBER = 3
    CHAMBER_CAP = 4
    PORT = 5
    JOINT_STEP = 6  # the annulus closing a radius step between links at different q (pose)


@dataclass(frozen=True)
class TubeSections:
    """The body S(q) sampled on its (l, a) grid, as callers hand it over.

    Attributes
    ----------
    q : float
        Joint value of this body, used in messages.
    l : (n,) float
        Normalized arc length of each ring, strictly increasing; joints included once.
    centers : (n, 3) float, mm
    frames : (n, 3, 3) float
        Columns (N, B, T), rotation-minimizing.
    rho : (n, na) float, mm
        Radius at angles ``a_k = 2 pi k / na``.
    s : (n,) float, mm, optional
        Arc length of each ring; default: cumulative chord length of ``centers``.
    rho_s : (n, na) float, optional
        d rho / ds; default: second-order finite differences in ``s``.
    curvature : (n, 2) float, 1/mm, optional
        (k1, k2) = (T'.N, T'.B) per unit arc length; default: from ``frames``.
    """

    q: float
    l: FloatArray
    centers: FloatArray
    frames: FloatArray
    rho: FloatArray
    s: FloatArray | None = None
    rho_s: FloatArray | None = None
    curvature: FloatArray | None = None


@dataclass(frozen=True)
class Sweep:
    """Section curves along the centerline, ready to tessellate.

    Attributes
    ----------
    q : float
    l : (n,) float
    s : (n,) float, mm
    centers : (n, 3) float, mm
    frames : (n, 3, 3) float, columns (N, B, T)
    xy : (n, na, 2) float, mm
        Section curves in frame coordinates (x along N, y along B).
    max_rho_kappa : float
        Largest reach towards the centre of curvature, max of (x k1 + y k2), of these sections.
    """

    q: float
    l: FloatArray
    s: FloatArray
    centers: FloatArray
    frames: FloatArray
    xy: FloatArray
    max_rho_kappa: float = 0.0


@dataclass(frozen=True)
class TubeMesh:
    """A triangle mesh with a region label per face.

    Attributes
    ----------
    vertices : (V, 3) float, mm
    faces : (F, 3) int64, counter-clockwise seen from outside
    regions : (F,) int8, values of :class:`Region`
    """

    vertices: FloatArray
    faces: IntArray
    regions: npt.NDArray[np.int8]


def l_grid_from_spacing(
    l_samples: npt.ArrayLike, s_samples: npt.ArrayLike, joints: npt.ArrayLike, spacing_mm: float
) -> FloatArray:
    """An l grid with rings about ``spacing_mm`` apart in arc length, every joint included once.

    Parameters
    ----------
    l_samples, s_samples : (m,) float
        Arc length ``s(l)`` (mm) of the centerline at this q, both strictly increasing.
    joints : (j,) float
        Link joints in l, strictly increasing, including both ends.
    spacing_mm : float
        Largest arc length between neighbouring rings inside a link, mm.

    Returns
    -------
    (n,) float
        Strictly increasing; contains every joint value exactly.
    """
    l_samples, s_samples = np.asarray(l_samples, float), np.asarray(s_samples, float)
    joints = np.asarray(joints, float)
    if not (spacing_mm > 0 and np.all(np.diff(s_samples) > 0) and np.all(np.diff(l_samples) > 0)):
        raise ValueError("spacing_mm must be > 0 and s(l) strictly increasing")
    if joints.size < 2 or np.any(np.diff(joints) <= 0):
        raise ValueError(f"joints must be strictly increasing with >= 2 values, got {joints.tolist()}")
    if joints[0] < l_samples[0] or joints[-1] > l_samples[-1]:
        raise ValueError(f"joints {joints.tolist()} leave the sampled range of l")
    s_joints = np.interp(joints, l_samples, s_samples)
    pieces = [joints[:1]]
    for j in range(joints.size - 1):
        count = max(1, math.ceil((s_joints[j + 1] - s_joints[j]) / spacing_mm - 1e-9))
        inner = np.linspace(s_joints[j], s_joints[j + 1], count + 1)[1:-1]
        pieces += [np.interp(inner, s_samples, l_samples), joints[j + 1 : j + 2]]
    return np.concatenate(pieces)


def arclength_from_centers(centers: npt.ArrayLike) -> FloatArray:
    """Cumulative chord length, (n,) mm, from (n, 3) points."""
    centers = np.asarray(centers, float)
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(centers, axis=0), axis=1))])


def curvature_from_frames(frames: npt.ArrayLike, s: npt.ArrayLike) -> FloatArray:
    """(k1, k2) = (T'.N, T'.B), (n, 2) 1/mm, by second-order finite differences of T in s."""
    frames, s = np.asarray(frames, float), np.asarray(s, float)
    dt = np.gradient(frames[:, :, 2], s, axis=0, edge_order=2 if s.size > 2 else 1)
    return np.einsum("ni,nij->nj", dt, frames[:, :, :2])


def _cross2(a: FloatArray, b: FloatArray) -> FloatArray:
    """z component of the cross product of (..., 2) vectors."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _where(q: float, l: float, a: float | None = None) -> str:
    angle = "" if a is None else f", a={np.degrees(a):.0f} deg"
    return f"q={q:.3f}, l={l:.4f}{angle}"


def _complete(sections: TubeSections) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Arc length, rho_s and curvature of ``sections``, computed where not given."""
    n, na = np.shape(sections.rho)
    if np.shape(sections.centers) != (n, 3) or np.shape(sections.frames) != (n, 3, 3) or np.shape(sections.l) != (n,):
        raise ValueError(f"sections: expected l (n,), centers (n, 3), frames (n, 3, 3) with n={n}")
    if n < 2 or na < 3:
        raise ValueError(f"sections: need >= 2 rings of >= 3 angles, got rho of shape {(n, na)}")
    frames = np.asarray(sections.frames, float)
    gram = np.einsum("nji,njk->nik", frames, frames) - np.eye(3)
    if not (np.all(np.abs(gram) <= FRAME_TOL) and np.all(np.linalg.det(frames) > 0)):
        raise ValueError("sections: frames must be orthonormal and right-handed (columns N, B, T)")
    s = arclength_from_centers(sections.centers) if sections.s is None else np.asarray(sections.s, float)
    if np.any(np.diff(s) <= 0) or np.any(np.diff(np.asarray(sections.l, float)) <= 0):
        raise ValueError("sections: l and s must be strictly increasing (a joint l value given twice?)")
    if sections.rho_s is None:
        rho_s = np.gradient(np.asarray(sections.rho, float), s, axis=0, edge_order=2 if n > 2 else 1)
    else:
        rho_s = np.asarray(sections.rho_s, float)
    given = sections.curvature
    curvature = curvature_from_frames(sections.frames, s) if given is None else np.asarray(given, float)
    return s, rho_s, curvature


def _refuse_fold(q: float, l: FloatArray, xy: FloatArray, curvature: FloatArray, field: str) -> float:
    """The largest rho * kappa of the sections; refused when >= FOLD_LIMIT; ``field`` prefixes the message."""
    reach = np.einsum("nkj,nj->nk", xy, curvature)
    i, k = np.unravel_index(np.argmax(reach), reach.shape)
    if reach[i, k] >= FOLD_LIMIT:
        a = angle_grid(xy.shape[1])[k]
        raise MeshError(
            f"{field}surface folds at {_where(q, l[i], a)}: rho * kappa = {reach[i, k]:.3f}, expected < "
            f"{FOLD_LIMIT:g} (radius {np.hypot(*xy[i, k]):.3f} mm, centerline curvature "
            f"{np.linalg.norm(curvature[i]):.4f} 1/mm); smooth the centerline more (resample.smoothing_mm) "
            "or use a smaller offset"
        )
    return float(reach[i, k])


def _refuse_bad_sections(q: float, l: FloatArray, xy: FloatArray, rho: FloatArray, limit: float, field: str) -> None:
    """Refuse offset sections that shrank below ``limit`` or stopped winding once around the centerline."""
    radius = np.linalg.norm(xy, axis=-1)
    turn = _cross2(xy, np.roll(xy, -1, axis=1))
    angles = angle_grid(xy.shape[1])
    i, k = np.unravel_index(np.argmin(radius), radius.shape)
    if radius[i, k] < limit:
        raise MeshError(
            f"{field}: at {_where(q, l[i], angles[k])} the inward offset leaves a radius of {radius[i, k]:.3f} mm, "
            f"expected >= {limit:g} mm; the local radius is {rho[i].min():.3f} mm, so the inward offset in total "
            f"(wall_mm - offset_mm) must stay below about {rho[i].min() - limit:.3f} mm here: {_inward_fix(field)}"
        )
    bad = np.argwhere(~(np.isfinite(turn) & (turn > 0)))
    if bad.size:
        i, k = bad[0]
        raise MeshError(
            f"{field}: at {_where(q, l[i], angles[k])} the offset section folds over itself (it no longer "
            f"winds once around the centerline; local radius {rho[i].min():.3f} mm, the section's own "
            f"curvature is too tight for this offset): make |{field}| smaller"
        )


def _inward_fix(field: str) -> str:
    """How to shrink an inward offset that is too deep: a thinner wall, or an offset closer to 0 (not 'smaller')."""
    if field == "wall_mm":
        return "make wall_mm thinner (or offset_mm larger)"
    return f"make {field} closer to 0 (less negative)"


def _refuse_ring_crossing(sweep: Sweep, field: str) -> None:
    """Refuse neighbouring rings whose vertices step backwards along the tangent (a fold between stations)."""
    points = ring_points(sweep)
    tangent = sweep.frames[:-1, :, 2] + sweep.frames[1:, :, 2]
    step = np.einsum("nkj,nj->nk", np.diff(points, axis=0), tangent)
    if np.any(step <= 0):
        i, k = np.argwhere(step <= 0)[0]
        raise MeshError(
            f"{field}: rings cross between {_where(sweep.q, sweep.l[i])} and l={sweep.l[i + 1]:.4f} "
            f"(a={np.degrees(angle_grid(points.shape[1])[k]):.0f} deg): the surface folds; "
            "use a smaller offset or smooth the centerline more"
        )


def sweep_from_sections(
    sections: TubeSections, offset_mm: float = 0.0, min_radius_mm: float = MIN_RADIUS_MM, field: str = "offset_mm"
) -> Sweep:
    """Offset the body along its normal and check that it neither folds nor collapses.

    Parameters
    ----------
    sections : TubeSections
    offset_mm : float
        > 0 grows, < 0 shrinks; see the module notes.
    min_radius_mm : float
        Smallest radius an inward offset may leave.
    field : str
        Case-file key named in messages (``offset_mm`` or ``wall_mm``).

    Raises
    ------
    MeshError
        Naming q and l where rho * kappa >= 1, an inward offset exceeds the
        local radius, or rings cross.
    """
    s, rho_s, curvature = _complete(sections)
    l = np.asarray(sections.l, float)
    rho = np.asarray(sections.rho, float)
    if not np.all(np.isfinite(rho) & (rho > 0)):
        i = int(np.argwhere(~(np.isfinite(rho) & (rho > 0)))[0, 0])
        raise MeshError(
            f"rho must be finite and > 0 mm on every ring; at {_where(sections.q, l[i])} its smallest value is "
            f"{rho[i].min()}; check the surface fit of this link"
        )
    _refuse_fold(sections.q, l, section_curves(rho, rho_s, curvature, 0.0), curvature, "")
    xy = section_curves(rho, rho_s, curvature, offset_mm)
    _refuse_bad_sections(sections.q, l, xy, rho, min_radius_mm if offset_mm < 0 else 0.0, field)
    reach = _refuse_fold(sections.q, l, xy, curvature, f"{field}={offset_mm:g} mm: offset ")
    centers, frames = np.asarray(sections.centers, float), np.asarray(sections.frames, float)
    sweep = Sweep(sections.q, l, s, centers, frames, xy, reach)
    _refuse_ring_crossing(sweep, field)
    return sweep


def _interpolate_station(sweep: Sweep, s_at: float) -> tuple[float, FloatArray, FloatArray, FloatArray]:
    """l, center, frame and section at arc length ``s_at``, linear between rings (the mesh's own resolution)."""
    i = int(np.clip(np.searchsorted(sweep.s, s_at, side="right") - 1, 0, sweep.s.size - 2))
    t = (s_at - sweep.s[i]) / (sweep.s[i + 1] - sweep.s[i])

    def lerp(v: FloatArray) -> FloatArray:
        return (1.0 - t) * v[i] + t * v[i + 1]

    frame = lerp(sweep.frames)
    tangent = frame[:, 2] / np.linalg.norm(frame[:, 2])
    normal = frame[:, 0] - (frame[:, 0] @ tangent) * tangent
    normal /= np.linalg.norm(normal)
    frame = np.column_stack([normal, np.cross(tangent, normal), tangent])
    return float(lerp(sweep.l)), lerp(sweep.centers), frame, lerp(sweep.xy)


def trim_sweep(sweep: Sweep, s_start: float, s_end: float) -> Sweep:
    """The part of ``sweep`` between arc lengths ``s_start`` and ``s_end`` (mm), with end rings there.

    Rings closer than ``TRIM_GAP_FRACTION`` of the local spacing to a new end are dropped.  An end
    that is not moved (``s_start`` or ``s_end`` at the sweep's own end) keeps its ring bit for bit,
    e.g. a joint ring another piece is stitched to.
    """
    if not sweep.s[0] <= s_start < s_end <= sweep.s[-1]:
        raise ValueError(f"trim range [{s_start}, {s_end}] mm must lie inside [0, {sweep.s[-1]}] mm")
    ends = [
        (sweep.l[k], sweep.centers[k], sweep.frames[k], sweep.xy[k]) if s == sweep.s[k]
        else _interpolate_station(sweep, s)
        for s, k in ((s_start, 0), (s_end, -1))
    ]
    gap = TRIM_GAP_FRACTION * np.diff(sweep.s).min()
    keep = (sweep.s > s_start + gap) & (sweep.s < s_end - gap)
    parts = [
        np.concatenate([[ends[0][j]], np.asarray(values)[keep], [ends[1][j]]])
        for j, values in enumerate((sweep.l, sweep.centers, sweep.frames, sweep.xy))
    ]
    s = np.concatenate([[s_start], sweep.s[keep], [s_end]])
    return Sweep(sweep.q, parts[0], s, parts[1], parts[2], parts[3], sweep.max_rho_kappa)


def ring_points(sweep: Sweep) -> FloatArray:
    """Surface points ``c + x N + y B`` of every ring, (n, na, 3) mm."""
    frames = sweep.frames
    return (
        sweep.centers[:, None, :]
        + sweep.xy[..., :1] * frames[:, None, :, 0]
        + sweep.xy[..., 1:] * frames[:, None, :, 1]
    )


def _cap_center(ring: FloatArray) -> FloatArray:
    """Area centroid of a section polygon (n, 2) when every fan triangle from it turns left, else the origin."""
    nxt = np.roll(ring, -1, axis=0)
    cross = _cross2(ring, nxt)
    centroid = ((ring + nxt) * cross[:, None]).sum(axis=0) / (3.0 * cross.sum())
    fan_ok = np.all(_cross2(ring - centroid, nxt - centroid) > 0)
    return centroid if fan_ok else np.zeros(2)


def tessellate(sweep: Sweep, caps: bool = True) -> TubeMesh:
    """Triangulate ``sweep``: one vertex per grid node (no seam duplicates), optional planar end caps.

    Returns
    -------
    TubeMesh
        ``n * na`` ring vertices (+2 cap centres), ``2 (n - 1) na`` wall
        triangles (+``2 na`` cap triangles), wound counter-clockwise seen from outside.
    """
    n, na = sweep.xy.shape[:2]
    vertices = ring_points(sweep).reshape(-1, 3)
    i, k = np.meshgrid(np.arange(n - 1), np.arange(na), indexing="ij")
    v00, v01 = i * na + k, i * na + (k + 1) % na
    quads = np.stack([v00, v01, v00 + na, v01, v01 + na, v00 + na], axis=-1)
    faces = [quads.reshape(-1, 3)]
    regions = [np.full(faces[0].shape[0], Region.WALL, np.int8)]
    if caps:
        frames = sweep.frames[[0, -1]]
        centers2d = np.stack([_cap_center(sweep.xy[0]), _cap_center(sweep.xy[-1])])
        hubs = sweep.centers[[0, -1]] + np.einsum("cj,cij->ci", centers2d, frames[:, :, :2])
        vertices = np.concatenate([vertices, hubs])
        ring = np.arange(na)
        base = np.column_stack([np.full(na, n * na), (ring + 1) % na, ring])
        tip = np.column_stack([np.full(na, n * na + 1), (n - 1) * na + ring, (n - 1) * na + (ring + 1) % na])
        faces += [base, tip]
        regions += [np.full(na, Region.BASE_CAP, np.int8), np.full(na, Region.TIP_CAP, np.int8)]
    return TubeMesh(vertices, np.concatenate(faces).astype(np.int64), np.concatenate(regions))
