"""Joining link pieces placed at different q: rings on rays, annuli across radial steps, one mesh.

Joints
    Both rings sit on the rays a_k = 2 pi k / na of the joint frame.  Where they coincide (to
    JOINT_MERGE_TOL_MM, a micron: equal q, or rho0 = rhof there) they share vertices.  Elsewhere a planar
    annulus closes the step: in each angular interval the quad between the rings is split into
    two triangles; where the step changes sign inside an interval the two chords cross, and the
    crossing point becomes a vertex of both walls and of the annulus.  A triangle where link j's
    ring is outside faces +T (the body narrows there), else -T, so the winding stays consistent.
    Offset sections (``offset_mm``) are not radial: at an unmerged joint both rings first slide
    along their own section polygon onto the rays (polar resampling).

:mod:`softdesign.meshing.body.pose` places the pieces and checks the solid.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt

from softdesign.errors import MeshError
from softdesign.meshing.end_cut import CutPlane, cut_ends
from softdesign.meshing.tessellate import Region, Sweep, TubeMesh, tessellate
from softdesign.meshing.topology import drop_unused_vertices
from softdesign.meshing.volume import angle_grid
from softdesign.types import FloatArray, IntArray, Pose

#: Joint ring vertices closer than this are shared, mm: a micron, far below any fabrication's resolution, and far
#: above the resolution of the files the pose is written to (float32 coordinates: 3e-5 mm at 500 mm).  Two vertices
#: closer than that resolution become one when a mesh file is read, and the edge between them with them: the
#: written solid was no longer closed (a five-link coil with rings 3e-7 mm apart at one joint read back with two
#: edges in four faces).  A crossing then lies at least (chord x 1 micron / the largest step) from the rings' vertices.
JOINT_MERGE_TOL_MM = 1e-3


@dataclass(frozen=True)
class JointStitch:
    """How two rings in one plane are joined.

    Local vertex ids: link j's ring k -> k, link j+1's ring k -> na + k, crossing c -> 2 na + c.

    Attributes
    ----------
    end_radius, start_radius : (na,) float, mm, link j's end ring and link j+1's start ring on the rays a_k
    merged : (na,) bool, vertices shared (|step| <= tolerance)
    crossings : (c, 2) float, mm, where the rings cross, in the joint frame's (N, B) coordinates
    crossing_interval : (c,) int, the angular interval k -> k + 1 of each crossing
    triangles : (t, 3) int, the annulus in local ids, counter-clockwise seen from outside
    """

    end_radius: FloatArray
    start_radius: FloatArray
    merged: npt.NDArray[np.bool_]
    crossings: FloatArray
    crossing_interval: IntArray
    triangles: IntArray

    def signed_areas(self) -> FloatArray:
        """Area of each annulus triangle, (t,) mm^2, > 0 when it faces +T (link j's ring outside)."""
        rays = _rays(self.end_radius.size)
        points = np.concatenate([self.end_radius[:, None] * rays, self.start_radius[:, None] * rays, self.crossings])
        p = points[self.triangles]
        e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
        return 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])

    def figures(self, index: int, l: float) -> JointStep:
        """The joint's figures for reports."""
        step = np.abs(self.end_radius - self.start_radius)
        area = float(np.sum(np.abs(self.signed_areas())))
        counts = (int(np.sum(self.merged)), len(self.crossings), int(self.triangles.shape[0]))
        return JointStep(index, l, float(np.max(step)), *counts, area)


@dataclass(frozen=True)
class JointStep:
    """What closing one joint took: the radial step (end minus start radius, mm) and the annulus."""

    index: int
    l: float
    max_step_mm: float
    shared_vertices: int
    crossings: int
    annulus_faces: int
    annulus_area_mm2: float
    min_wall_mm: float | None = None  # a hollow pose's thinnest wall at the joint (None: solid)


def radii_on_rays(xy: npt.ArrayLike) -> FloatArray:
    """Where the rays a_k = 2 pi k / na meet a section polygon, (na,) mm.

    Parameters
    ----------
    xy : (na, 2) float, mm, a polygon star-shaped about the origin, counter-clockwise (as
        :func:`~softdesign.meshing.tessellate.sweep_from_sections` guarantees)
    """
    xy = np.asarray(xy, float)
    na = xy.shape[0]
    phi = np.unwrap(np.arctan2(xy[:, 1], xy[:, 0]))
    phi_ext = np.concatenate([phi - 2 * np.pi, phi, phi + 2 * np.pi, phi + 4 * np.pi])
    xy_ext = np.tile(xy, (4, 1))
    i = np.searchsorted(phi_ext, angle_grid(na), side="right") - 1
    p0, d = xy_ext[i], xy_ext[i + 1] - xy_ext[i]
    u = _rays(na)
    return (p0[:, 0] * d[:, 1] - p0[:, 1] * d[:, 0]) / (u[:, 0] * d[:, 1] - u[:, 1] * d[:, 0])


def _rays(na: int) -> FloatArray:
    """Unit vectors (cos a_k, sin a_k), (na, 2)."""
    a = angle_grid(na)
    return np.column_stack([np.cos(a), np.sin(a)])


def _crossing(r_end: FloatArray, r_start: FloatArray, k: int) -> FloatArray:
    """Where chord k -> k+1 of the end ring crosses that of the start ring, (2,) mm (the steps differ in sign)."""
    k1 = (k + 1) % r_end.size
    # (1 - t) rA0 u0 + t rA1 u1 = (1 - t') rB0 u0 + t' rB1 u1, solved for t
    t = r_start[k1] * (r_start[k] - r_end[k]) / (r_end[k1] * r_start[k] - r_end[k] * r_start[k1])
    rays = _rays(r_end.size)
    return (1.0 - t) * r_end[k] * rays[k] + t * r_end[k1] * rays[k1]


def stitch_joint(
    end_radius: npt.ArrayLike, start_radius: npt.ArrayLike, tol: float = JOINT_MERGE_TOL_MM
) -> JointStitch:
    """Join link j's end ring to link j+1's start ring in their common plane (see the module notes).

    Parameters
    ----------
    end_radius, start_radius : (na,) float, mm, > 0, on the rays a_k = 2 pi k / na
    tol : float, mm, rings closer than this share the vertex

    Returns
    -------
    JointStitch
    """
    r_end, r_start = np.asarray(end_radius, float), np.asarray(start_radius, float)
    na = r_end.size
    step = r_end - r_start
    merged = np.abs(step) <= tol
    sign = np.where(merged, 0.0, np.sign(step))
    outer = np.where(merged, na + np.arange(na), np.arange(na))  # link j's ring, merged ids folded onto j+1's
    crossings: list[FloatArray] = []
    intervals, triangles = [], []
    for k in range(na):
        k1 = (k + 1) % na
        a0, a1, b0, b1 = outer[k], outer[k1], na + k, na + k1
        if sign[k] * sign[k1] < 0:
            x = 2 * na + len(crossings)
            crossings.append(_crossing(r_end, r_start, k))
            intervals.append(k)
            triangles += [(a0, x, b0), (a1, b1, x)]
        else:
            triangles += [(a0, a1, b0), (a1, b1, b0)]
    tri = np.array(triangles, np.int64).reshape(-1, 3)
    distinct = (tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 2] != tri[:, 0])
    return JointStitch(
        r_end, r_start, merged, np.array(crossings, float).reshape(-1, 2), np.array(intervals, np.int64), tri[distinct]
    )


def _link_mesh(sweep: Sweep, base: bool, tip: bool, planes: tuple[CutPlane | None, CutPlane | None],
               label: str) -> TubeMesh:
    """The link's wall, with the base cap only on the first link and the tip cap only on the last (cut at
    ``planes``)."""
    mesh = tessellate(sweep, caps=base or tip)
    if base or tip:
        mesh, _ = cut_ends(mesh, sweep, planes, label)
    if base == tip:
        return mesh
    hub = sweep.xy.shape[0] * sweep.xy.shape[1] + (1 if base else 0)  # the hub of the cap to drop
    keep = mesh.regions != (Region.TIP_CAP if base else Region.BASE_CAP)
    faces = mesh.faces[keep]
    return TubeMesh(np.delete(mesh.vertices, hub, axis=0), np.where(faces > hub, faces - 1, faces), mesh.regions[keep])


def placed(sweep: Sweep, build2world: Pose) -> Sweep:
    """``sweep`` moved rigidly by ``build2world`` (4, 4)."""
    rotation, shift = build2world[:3, :3], build2world[:3, 3]
    frames = np.einsum("ij,njk->nik", rotation, sweep.frames)
    return replace(sweep, centers=sweep.centers @ rotation.T + shift, frames=frames)


def _split_edge(faces: IntArray, u: int, v: int, x: int) -> IntArray:
    """Faces with the one face holding directed edge u -> v split at vertex x into two."""
    row, pos = np.nonzero((faces == u) & (np.roll(faces, -1, axis=1) == v))
    if row.size != 1:
        raise MeshError(
            f"pose: edge {u} -> {v} found in {row.size} faces, expected 1 where two links meet; "
            "this is a bug in the pose mesher, please report it with the case file"
        )
    w = faces[row[0], (pos[0] + 2) % 3]
    out = faces.copy()
    out[row[0]] = (u, x, w)
    return np.vstack([out, [[x, v, w]]])


def resampled_joints(sweeps: list[Sweep]) -> tuple[list[Sweep], list[JointStitch]]:
    """Stitches of every joint; rings of unmerged joints moved onto the rays a_k first."""
    sweeps = list(sweeps)
    stitches = []
    for j in range(len(sweeps) - 1):
        end, start = sweeps[j].xy[-1], sweeps[j + 1].xy[0]
        if np.all(np.linalg.norm(end - start, axis=1) <= JOINT_MERGE_TOL_MM):
            stitches.append(stitch_joint(np.linalg.norm(end, axis=1), np.linalg.norm(end, axis=1)))
            continue
        stitch = stitch_joint(radii_on_rays(end), radii_on_rays(start))
        rays = _rays(end.shape[0])
        for index, row, radius in ((j, -1, stitch.end_radius), (j + 1, 0, stitch.start_radius)):
            xy = sweeps[index].xy.copy()
            xy[row] = radius[:, None] * rays
            sweeps[index] = replace(sweeps[index], xy=xy)
        stitches.append(stitch)
    return sweeps, stitches


def assemble(sweeps: list[Sweep], stitches: list[JointStitch],
             planes: tuple[CutPlane | None, CutPlane | None] = (None, None),
             label: str = "pose") -> tuple[FloatArray, IntArray, npt.NDArray[np.int8]]:
    """One mesh of the placed link sweeps, joined at every joint by shared vertices and annuli.

    ``planes`` cut the first link's base and the last link's tip (:mod:`softdesign.meshing.end_cut`).
    """
    last = len(sweeps) - 1
    meshes = [_link_mesh(sweep, j == 0, j == last, (planes[0] if j == 0 else None, planes[1] if j == last else None),
                         label) for j, sweep in enumerate(sweeps)]
    offsets = np.cumsum([0] + [m.vertices.shape[0] for m in meshes])
    vertices = [m.vertices for m in meshes]
    faces = np.concatenate([m.faces + off for m, off in zip(meshes, offsets[:-1], strict=True)])
    regions = np.concatenate([m.regions for m in meshes])
    remap = np.arange(offsets[-1])
    added = offsets[-1]
    for j, stitch in enumerate(stitches):
        n_rings, na = sweeps[j].xy.shape[:2]
        ring_a, ring_b = offsets[j] + (n_rings - 1) * na + np.arange(na), offsets[j + 1] + np.arange(na)
        crossing_ids = added + np.arange(len(stitch.crossings))
        frame, center = sweeps[j + 1].frames[0], sweeps[j + 1].centers[0]
        vertices.append(center + stitch.crossings @ frame[:, :2].T)
        added += len(stitch.crossings)
        for x, k in zip(crossing_ids, stitch.crossing_interval, strict=True):
            k1 = (k + 1) % na
            faces = _split_edge(faces, ring_a[k1], ring_a[k], x)
            faces = _split_edge(faces, ring_b[k], ring_b[k1], x)
        split_halves = np.full(faces.shape[0] - regions.size, Region.WALL, np.int8)
        faces = np.vstack([faces, np.concatenate([ring_a, ring_b, crossing_ids])[stitch.triangles]])
        annulus = np.full(stitch.triangles.shape[0], Region.JOINT_STEP, np.int8)
        regions = np.concatenate([regions, split_halves, annulus])
        remap = np.concatenate([remap, crossing_ids])
        remap[ring_a[stitch.merged]] = ring_b[stitch.merged]
    return *drop_unused_vertices(np.concatenate(vertices), remap[faces]), regions
