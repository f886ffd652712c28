"""A tessellated body whose ends are cut at tilted planes carried in its end frames.

:mod:`softdesign.geometry.end_cut` chooses, per end, the outward normal of the
cut plane in the end frame's (N, B, T) coordinates.  At a body's q the plane
is that normal turned by the end frame at q, through the end ring's centre
(for a chamber, moved ``wall_mm`` inward along its normal, so the sealed end
stays ``wall_mm`` thick measured square to the cut).

The cut moves the tessellated vertices, not the (l, a) grid, so faces and
vertex order are the tessellation's own (a morph target stays one mesh):

generator
    the polyline of ring vertices at one angle a_k, in ring order, linear
    between rings (the mesh's own surface), continued straight past the end
    along the outward end tangent with the end section held (the fit already
    holds its end rings at the inscribed radius).
shift
    d_k, the arc length along generator k from the end ring to the plane:
    ``> 0`` extends (plane past the end ring), ``< 0`` shortens; found where
    the generator's signed distance to the plane changes sign.
re-spacing
    the rings of the end zone, ``ZONE_FACTOR`` x max |d_k| long, slide along
    their generator by ``d_k w`` with w rising linearly from 0 at the zone's
    inner edge to 1 at the end ring, so the end ring lies in the plane and the
    rings keep their order (each step scales by 1 + d_k / zone > 0).
cap
    the end ring is a planar polygon; its hub is the polygon's area centroid
    in the plane when every fan triangle turns the right way, else the axis's
    crossing with the plane.

Volume: on a straight end with the section held, the cut adds
``int h dA`` with h the plane's height over the end section along the
outward tangent: ``((p - c).n A - n_N M_x - n_B M_y) / (n.u)`` for section
area A and first moments M_x, M_y about the axis (a wedge of a prism),
exact for the extension and, for a shortening, to the end zone's departure
from a straight prism.  Not in the papers.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from softdesign.errors import MeshError
from softdesign.geometry.end_cut import MAX_ZONE_FRACTION, ZONE_FACTOR
from softdesign.meshing.tessellate import Sweep, TubeMesh
from softdesign.meshing.volume import EndCuts
from softdesign.types import FloatArray


@dataclass(frozen=True)
class CutPlane:
    """A world plane ending the body: a point on it (mm) and its unit normal, pointing out of the body."""

    point: FloatArray
    normal: FloatArray


def cut_planes(outer: Sweep, cuts: EndCuts, inset_mm: float = 0.0) -> tuple[CutPlane | None, CutPlane | None]:
    """The base and tip cut planes of the body whose outer sweep is ``outer``, moved ``inset_mm`` inward.

    Parameters
    ----------
    outer : the body's outer sweep at this q (its end rings' centres and frames carry the planes)
    cuts : per end (base, tip), (n_N, n_B, n_T, offset_mm): the outward normal in the end frame's (N, B, T)
        coordinates and where the plane crosses the axis, mm along the outward tangent; or None
    inset_mm : how far inward along each normal the plane moves (a chamber's: ``wall_mm``)
    """
    planes: list[CutPlane | None] = []
    for k, cut, outward in ((0, cuts[0], -1.0), (-1, cuts[1], 1.0)):
        if cut is None:
            planes.append(None)
            continue
        normal = outer.frames[k] @ np.asarray(cut[:3], float)
        normal /= np.linalg.norm(normal)
        on_axis = outer.centers[k] + cut[3] * outward * outer.frames[k][:, 2]
        planes.append(CutPlane(on_axis - inset_mm * normal, normal))
    return planes[0], planes[1]


def cut_ends(mesh: TubeMesh, sweep: Sweep, planes: tuple[CutPlane | None, CutPlane | None],
             label: str) -> tuple[TubeMesh, float]:
    """``mesh`` (:func:`~softdesign.meshing.tessellate.tessellate` of ``sweep``, with caps) cut at ``planes``.

    Returns
    -------
    (TubeMesh, float)
        The same faces and regions with the ring vertices and cap hubs moved, and the volume the cuts
        add (mm3, negative when they remove more than they add).

    Raises
    ------
    MeshError
        A plane that no generator reaches within the body, or that needs an end zone longer than
        ``MAX_ZONE_FRACTION`` of the body (naming ``label``, the end and the shift).
    """
    n, na = sweep.xy.shape[:2]
    if mesh.vertices.shape[0] != n * na + 2:
        raise ValueError(f"cut_ends: expected the capped tessellation of the sweep ({n * na + 2} vertices)")
    if planes[0] is None and planes[1] is None:
        return mesh, 0.0
    points = mesh.vertices[: n * na].reshape(n, na, 3).copy()
    hubs = mesh.vertices[n * na:].copy()
    for end, plane in enumerate(planes):
        if plane is None:
            continue
        order = slice(None, None, -1) if end == 0 else slice(None)
        k = 0 if end == 0 else -1
        s = sweep.s[-1] - sweep.s[::-1] if end == 0 else sweep.s
        outward = sweep.frames[k][:, 2] * (-1.0 if end == 0 else 1.0)
        name = f"{label}: the {'base' if end == 0 else 'tip'} end's cut plane"
        points[order], hubs[end] = _cut_last_end(points[order], s, sweep.centers[k], outward, plane, name)
    vertices = np.concatenate([points.reshape(-1, 3), hubs])
    return TubeMesh(vertices, mesh.faces, mesh.regions), end_cut_volume(sweep, planes)


def end_cut_volume(sweep: Sweep, planes: tuple[CutPlane | None, CutPlane | None]) -> float:
    """The volume the cuts at ``planes`` add to the body of ``sweep`` (what :func:`cut_ends` returns), mm3."""
    added = 0.0
    for end, plane in enumerate(planes):
        if plane is not None:
            k = 0 if end == 0 else -1
            outward = sweep.frames[k][:, 2] * (-1.0 if end == 0 else 1.0)
            added += _wedge_volume(sweep.xy[k], sweep.centers[k], sweep.frames[k], outward, plane)
    return float(added)


def _cut_last_end(points: FloatArray, s: FloatArray, centre: FloatArray, outward: FloatArray, plane: CutPlane,
                  name: str) -> tuple[FloatArray, FloatArray]:
    """Rings (n, na, 3) whose last ring is moved into ``plane`` along each generator, and the cap's hub."""
    moved = along_generators(points, s, outward, cut_targets(points, s, outward, plane, name))
    return moved, _hub(moved[-1], plane, outward, centre)


def cut_targets(points: FloatArray, s: FloatArray, outward: FloatArray, plane: CutPlane, name: str) -> FloatArray:
    """Where each ring point (n, m, 3) goes along its generator, as arc length (n, m) mm: the last ring onto
    ``plane``, the end zone's rings re-spaced (module notes); :func:`along_generators` puts them there."""
    f = (points - plane.point) @ plane.normal
    along = float(outward @ plane.normal)
    shift = _shifts(f, s, along, name)
    zone = ZONE_FACTOR * float(np.max(np.abs(shift)))
    if zone > MAX_ZONE_FRACTION * s[-1]:
        raise MeshError(
            f"{name} lies up to {np.max(np.abs(shift)):.3f} mm from the body's end along its wall, too far for a "
            f"body {s[-1]:.3f} mm long (its end zone would be {zone:.3f} mm, more than {MAX_ZONE_FRACTION:g} of "
            "it); set fit.end_cut: normal"
        )
    weight = np.clip((s - (s[-1] - zone)) / zone, 0.0, 1.0) if zone > 0 else np.zeros_like(s)
    return np.asarray(s[:, None] + shift[None, :] * weight[:, None], np.float64)


def crease_targets(points: FloatArray, s: FloatArray, outward: FloatArray, plane: CutPlane, name: str,
                   thickness: float) -> FloatArray:
    """:func:`cut_targets` for a swept volume mesh, whose layers should keep the end ring: (n, m) arc lengths.

    Where the plane lies past the end ring, the body's material map has a crease at the ring: the generator's
    surface (which deforms with q) meets its straight continuation (which moves rigidly with the end frame,
    :func:`along_generators`).  A row of skin quads across the crease averages the two, so here the last ring
    goes into ``plane`` as in :func:`cut_targets`, the ring before it onto the end ring (arc ``s[-1]``, the
    crease) wherever that leaves the last row at least ``thickness`` mm thick, else ``thickness`` short of the
    plane (also where the plane shortens the generator); the ring before that moves with it (the row next to the
    end ring keeps its length) and the ``ZONE_FACTOR`` x largest move before are re-spaced to follow, as the
    module notes re-space the end zone.  Needs n >= 3 rings.
    """
    ends = cut_targets(points, s, outward, plane, name)[-1]
    ring = np.minimum(s[-1], ends - thickness)
    shift = ring - s[-2]
    zone = ZONE_FACTOR * float(np.max(np.abs(shift)))
    if s[-3] - zone < MAX_ZONE_FRACTION * s[-1]:
        raise MeshError(f"{name}: the volume mesh's layer before the end would move {np.max(np.abs(shift)):.3f} mm, "
                        f"too far for a body {s[-1]:.3f} mm long; set fit.end_cut: normal")
    # the ring before it moves with it (the row next to the end ring keeps its length), the zone before re-spaced
    weight = np.clip((s[:-1] - (s[-3] - zone)) / zone, 0.0, 1.0) if zone > 0 else np.zeros(len(s) - 1)
    return np.asarray(np.vstack([s[:-1, None] + shift[None, :] * weight[:, None], ends[None, :]]), np.float64)


def _shifts(f: FloatArray, s: FloatArray, along: float, name: str) -> FloatArray:
    """Per generator, the arc length from the end ring to where its signed distance ``f`` (n, na) is 0."""
    last = f[-1]
    inside = f <= 0.0
    if not inside.any(axis=0).all():
        raise MeshError(f"{name} cuts off the whole body along some generator; set fit.end_cut: normal")
    # the last ring at or behind the plane, and the step past it where the generator crosses
    i = f.shape[0] - 1 - np.argmax(inside[::-1], axis=0)
    i = np.minimum(i, f.shape[0] - 2)
    cols = np.arange(f.shape[1])
    f0, f1 = f[i, cols], f[i + 1, cols]
    crossing = s[i] + (s[i + 1] - s[i]) * np.clip(-f0 / np.where(f1 > f0, f1 - f0, 1.0), 0.0, 1.0)
    return np.where(last <= 0.0, -last / along, crossing - s[-1])


def along_generators(points: FloatArray, s: FloatArray, outward: FloatArray, target: FloatArray) -> FloatArray:
    """Points (n, na, 3) at arc lengths ``target`` (n, na) along each generator, straight past the end ring."""
    i = np.clip(np.searchsorted(s, target, side="right") - 1, 0, s.size - 2)
    t = np.clip((target - s[i]) / (s[i + 1] - s[i]), 0.0, 1.0)[..., None]
    cols = np.arange(points.shape[1])[None, :]
    inner = (1.0 - t) * points[i, cols] + t * points[i + 1, cols]
    beyond = points[-1][None] + np.maximum(target - s[-1], 0.0)[..., None] * outward
    return np.where((target > s[-1])[..., None], beyond, inner)


def _hub(ring: FloatArray, plane: CutPlane, outward: FloatArray, centre: FloatArray) -> FloatArray:
    """The cap's fan centre in the plane: the polygon's area centroid if every fan triangle turns left."""
    axis_point = centre + outward * float((plane.point - centre) @ plane.normal) / float(outward @ plane.normal)
    up = plane.normal * np.sign(plane.normal @ outward)
    e1 = np.cross(up, np.eye(3)[int(np.argmin(np.abs(up)))])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(up, e1)
    xy = np.column_stack([(ring - axis_point) @ e1, (ring - axis_point) @ e2])
    nxt = np.roll(xy, -1, axis=0)
    cross = xy[:, 0] * nxt[:, 1] - xy[:, 1] * nxt[:, 0]
    sign = np.sign(cross.sum())
    centroid = ((xy + nxt) * cross[:, None]).sum(axis=0) / (3.0 * cross.sum())
    turn = (xy[:, 0] - centroid[0]) * (nxt[:, 1] - centroid[1]) - (xy[:, 1] - centroid[1]) * (nxt[:, 0] - centroid[0])
    offset = centroid if np.all(sign * turn > 0) else np.zeros(2)
    return axis_point + offset[0] * e1 + offset[1] * e2


def _wedge_volume(xy: FloatArray, centre: FloatArray, frame: FloatArray, outward: FloatArray,
                  plane: CutPlane) -> float:
    """``int h dA`` over the end section ``xy`` (na, 2) (see the module notes), mm3."""
    nxt = np.roll(xy, -1, axis=0)
    cross = xy[:, 0] * nxt[:, 1] - xy[:, 1] * nxt[:, 0]
    area = 0.5 * cross.sum()
    mx, my = ((xy + nxt) * cross[:, None]).sum(axis=0) / 6.0
    n = plane.normal
    height = float((plane.point - centre) @ n) * area - float(n @ frame[:, 0]) * mx - float(n @ frame[:, 1]) * my
    return height / float(n @ outward)


def end_cuts_from_record(record: dict[str, Any] | None) -> EndCuts:
    """The (base, tip) cut planes of the fit's ``end_cut`` record (see :mod:`softdesign.geometry.end_cut`).

    None where an end is not cut, or when there is no record (a fit kept before end cuts existed).
    """
    if not record:
        return (None, None)
    ends = [record.get(end) or {} for end in ("inlet", "outlet")]
    cuts = [(*(float(x) for x in c["normal_local"]), float(c["offset_mm"])) if c.get("applied") else None
            for c in ends]
    return (cuts[0], cuts[1])  # type: ignore[return-value]
