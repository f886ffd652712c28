"""The body with one q per link (the seed's S_robot), stitched into one checked watertight solid.

Placement
    Link j's piece of S(q_j) -- the centerline c(q_j, l), its frames and rho(q_j) for l in
    [l_j, l_{j+1}] -- is sampled exactly as the export samples S(q_j) (the same l grid from
    ``spacing_mm``, the same angle grid), then moved rigidly so that its start frame
    {S} = F(q_j, l_j) lands on the forward kinematics of the links before it::

        start2world_j = base2world(q_1) @ S_T_E^(1)(q_1) @ ... @ S_T_E^(j-1)(q_{j-1})
        build2world_j = start2world_j @ inv(F(q_j, l_j))     (applied to every point of the piece)

    Since S_T_E^(j)(q_j) = inv(F(q_j, l_j)) F(q_j, l_{j+1}), link j's end frame lands on
    start2world_{j+1}: the end ring of link j and the start ring of link j+1 lie in one plane,
    about one centre, with one N axis (angle 0), whatever the two q are.
Joints
    Both rings sit on the rays a_k = 2 pi k / na of the joint frame.  Where they coincide (to
    JOINT_MERGE_TOL_MM: equal q, or rho0 = rhof there) they share vertices.  Elsewhere a planar
    annulus closes the step: in each angular interval the quad between the rings is split into
    two triangles; where the step changes sign inside an interval the two chords cross, and the
    crossing point becomes a vertex of both walls and of the annulus.  A triangle where link j's
    ring is outside faces +T (the body narrows there), else -T, so the winding stays consistent.
    Offset sections (``offset_mm``) are not radial: at an unmerged joint both rings first slide
    along their own section polygon onto the rays (polar resampling).
Checks
    :func:`~softdesign.meshing.checks.check_solid`: watertight, consistently wound, vertex-manifold,
    no degenerate face, one body, Euler characteristic 2, and volume within 0.5 % of the sum over
    links of :func:`~softdesign.meshing.volume.integrate_body` on each link's own segment
    (Gauss-Legendre in l between the link's joints and spline knots, trapezoid rule in the angle;
    an annulus is flat and encloses nothing); then manifold3d's status.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt

from softdesign.errors import MeshError
from softdesign.fitting.radius_field import RadiusField
from softdesign.geometry.frames import FramedSpline
from softdesign.kinematics.links import LinkChain
from softdesign.kinematics.poe import inverse_pose
from softdesign.meshing.body import body_breaks, body_stations, export_l_grid, sections_on_grid
from softdesign.meshing.checks import Expectation, MeshReport, check_solid
from softdesign.meshing.solids import manifold_from_mesh
from softdesign.meshing.tessellate import (
    Region,
    Sweep,
    TubeMesh,
    TubeSections,
    sweep_from_sections,
    tessellate,
)
from softdesign.meshing.volume import BodySpec, angle_grid, integrate_body
from softdesign.types import POINT_TOL_MM, FloatArray, IntArray, Pose

#: Joint ring vertices closer than this are shared, mm (placement round-off is ~1e-13 mm).
JOINT_MERGE_TOL_MM = POINT_TOL_MM


@dataclass(frozen=True)
class PoseSpec:
    """How to sample each link: ring spacing ``spacing_mm`` (mm), ``angular_count`` angles, ``offset_mm`` (mm)."""

    spacing_mm: float = 0.5
    angular_count: int = 64
    offset_mm: float = 0.0


@dataclass(frozen=True)
class PoseLink:
    """One link placed in the pose.

    Attributes
    ----------
    index : int
    q : float
    l_start, l_end : float, normalized l of the link's ends
    length_mm : float, arc length of c(q, .) over the link
    start2world : (4, 4) float, the link's {S} in world (input-file) coordinates, mm
    sweep : Sweep, the link's rings in world coordinates (centers (n, 3), frames (n, 3, 3), xy (n, na, 2))
    volume_expected : float, mm^3, integrated over the link
    """

    index: int
    q: float
    l_start: float
    l_end: float
    length_mm: float
    start2world: Pose
    sweep: Sweep
    volume_expected: float


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

    def figures(self, index: int, l: float) -> "JointStep":
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


@dataclass(frozen=True)
class PoseBody:
    """The checked solid of S_robot(q_1..q_n): links, joints, mesh (vertices (V, 3) mm, faces (F, 3), regions (F,))."""

    q: FloatArray
    links: tuple[PoseLink, ...]
    joints: tuple[JointStep, ...]
    vertices: FloatArray
    faces: IntArray
    regions: npt.NDArray[np.int8]
    volume_expected: float
    report: MeshReport
    max_rho_kappa: float


def link_sections(curve: FramedSpline, field: RadiusField, link: int, q: float, spec: PoseSpec) -> TubeSections:
    """Link ``link``'s piece of S(q) in the coordinates of c(q, .), on the export's l grid.

    The l grid is the export's grid of the whole body at q restricted to the link (both joints
    included), and rho comes from the link's own spline, so with every q equal the pieces are the
    export's rings (a joint ring once from each side).
    """
    l_all = export_l_grid(curve, field, spec.spacing_mm)
    lo, hi = field.breaks[link], field.breaks[link + 1]
    l = l_all[(l_all >= lo) & (l_all <= hi)]
    a = angle_grid(spec.angular_count)
    spline = field.link_spline(link, q)
    return sections_on_grid(curve, q, l, spline.evaluate_grid(l, a), spline.evaluate_grid(l, a, dl=1))


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
    crossings, intervals, triangles = [], [], []
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


def _link_mesh(sweep: Sweep, base: bool, tip: bool) -> TubeMesh:
    """The link's wall, with the base cap only on the first link and the tip cap only on the last."""
    mesh = tessellate(sweep, caps=base or tip)
    if base == tip:
        return mesh
    hub = sweep.xy.shape[0] * sweep.xy.shape[1] + (1 if base else 0)  # the hub of the cap to drop
    keep = mesh.regions != (Region.TIP_CAP if base else Region.BASE_CAP)
    faces = mesh.faces[keep]
    return TubeMesh(np.delete(mesh.vertices, hub, axis=0), np.where(faces > hub, faces - 1, faces), mesh.regions[keep])


def _placed(sweep: Sweep, build2world: Pose) -> Sweep:
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


def _resampled_joints(sweeps: list[Sweep]) -> tuple[list[Sweep], list[JointStitch]]:
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


def _assemble(links: list[PoseLink], stitches: list[JointStitch]) -> tuple[FloatArray, IntArray, npt.NDArray[np.int8]]:
    """One mesh of the placed links, joined at every joint by shared vertices and annuli."""
    meshes = [_link_mesh(link.sweep, j == 0, j == len(links) - 1) for j, link in enumerate(links)]
    offsets = np.cumsum([0] + [m.vertices.shape[0] for m in meshes])
    vertices = [m.vertices for m in meshes]
    faces = np.concatenate([m.faces + off for m, off in zip(meshes, offsets)])
    regions = np.concatenate([m.regions for m in meshes])
    remap = np.arange(offsets[-1])
    added = offsets[-1]
    for j, stitch in enumerate(stitches):
        n_rings, na = links[j].sweep.xy.shape[:2]
        ring_a, ring_b = offsets[j] + (n_rings - 1) * na + np.arange(na), offsets[j + 1] + np.arange(na)
        crossing_ids = added + np.arange(len(stitch.crossings))
        frame, center = links[j + 1].sweep.frames[0], links[j + 1].sweep.centers[0]
        vertices.append(center + stitch.crossings @ frame[:, :2].T)
        added += len(stitch.crossings)
        for x, k in zip(crossing_ids, stitch.crossing_interval):
            k1 = (k + 1) % na
            faces = _split_edge(faces, ring_a[k1], ring_a[k], x)
            faces = _split_edge(faces, ring_b[k], ring_b[k1], x)
        split_halves = np.full(faces.shape[0] - regions.size, Region.WALL, np.int8)
        faces = np.vstack([faces, np.concatenate([ring_a, ring_b, crossing_ids])[stitch.triangles]])
        annulus = np.full(stitch.triangles.shape[0], Region.JOINT_STEP, np.int8)
        regions = np.concatenate([regions, split_halves, annulus])
        remap = np.concatenate([remap, crossing_ids])
        remap[ring_a[stitch.merged]] = ring_b[stitch.merged]
    faces = remap[faces]
    used, compact = np.unique(faces, return_inverse=True)
    return np.concatenate(vertices)[used], compact.reshape(-1, 3), regions


def _link_volume(curve: FramedSpline, field: RadiusField, link: int, q: float, spec: PoseSpec) -> float:
    """The link's volume integrated from its spline surface (offset included), mm^3."""
    lo, hi = field.breaks[link], field.breaks[link + 1]
    knots = body_breaks(field)
    breaks = np.concatenate([[lo], knots[(knots > lo) & (knots < hi)], [hi]])
    stations = body_stations(curve, field, q, spec.angular_count)
    return integrate_body(stations, breaks, BodySpec(offset_mm=spec.offset_mm)).volume


def pose_body(chain: LinkChain, field: RadiusField, q: float | npt.ArrayLike, spec: PoseSpec = PoseSpec()) -> PoseBody:
    """S_robot(q_1..q_n): each link at its own q, placed by the links before it, as one checked solid.

    Parameters
    ----------
    chain : LinkChain, the blended shape and its link breaks
    field : RadiusField, rho(q) per link, on the same breaks
    q : float or (n_links,) float in [0, 1], one q for every link or one per link
    spec : PoseSpec

    Returns
    -------
    PoseBody

    Raises
    ------
    ConfigError
        q of the wrong count or outside [0, 1].
    MeshError
        Naming the link, q and l: a surface that folds, an offset the radius cannot take, or a
        failed check of the stitched solid (with its figures).
    """
    q = chain.q_per_link(q)
    if not np.array_equal(np.asarray(field.breaks, float), np.asarray(chain.breaks, float)):
        raise ValueError(f"field breaks {list(field.breaks)} differ from the chain's {list(chain.breaks)}")
    curves = {value: chain.shape.curve_at(value) for value in sorted(set(q.tolist()))}
    sweeps, volumes = [], []
    for j, qj in enumerate(q.tolist()):
        sections = link_sections(curves[qj], field, j, qj, spec)
        try:
            sweeps.append(sweep_from_sections(sections, spec.offset_mm))
        except MeshError as err:
            raise MeshError(f"link {j}: {err}") from err
        volumes.append(_link_volume(curves[qj], field, j, qj, spec))
    sweeps, stitches = _resampled_joints(sweeps)
    start2world = chain.base2world(q)
    links = []
    for j, (qj, transform) in enumerate(zip(q.tolist(), chain.transforms(q))):
        start2build = curves[qj].poses([field.breaks[j]])[0]
        sweep = _placed(sweeps[j], start2world @ inverse_pose(start2build))
        length = float(sweep.s[-1] - sweep.s[0])
        l_range = (float(field.breaks[j]), float(field.breaks[j + 1]))
        links.append(PoseLink(j, qj, *l_range, length, start2world, sweep, volumes[j]))
        start2world = start2world @ transform
    vertices, faces, regions = _assemble(links, stitches)
    label = "pose q=[" + ", ".join(f"{v:.3f}" for v in q) + "]"
    report = check_solid(vertices, faces, Expectation(volume=float(sum(volumes)), euler=2, bodies=1), label=label)
    manifold_from_mesh(vertices, faces, label)
    joints = tuple(s.figures(j, float(field.breaks[j + 1])) for j, s in enumerate(stitches))
    reach = max(s.max_rho_kappa for s in sweeps)
    return PoseBody(q, tuple(links), joints, vertices, faces, regions, float(sum(volumes)), report, reach)
