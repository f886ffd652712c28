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
    See :mod:`softdesign.meshing.body.pose_stitch`: rings on the rays of the joint frame, shared
    where they coincide, else closed by a planar annulus.
Hollow (``wall_mm``, ``port_mm``)
    The chamber is posed like the body: each link's piece offset inward by ``wall_mm``, stitched
    at the same joints and placed by the same moves, ``wall_mm`` short of the base and the tip;
    manifold3d subtracts it (and the port along the base tangent) as the export does, so with
    every q equal the pose is the export's hollow mesh.  At a radial step the chamber steps with
    the body, and the wall is thinnest across the joint plane, between one link's chamber ring
    and the other's outer ring: it is reported per joint, and a wall that would fall below the
    least radius an offset may keep is refused naming the joint.
Checks
    :func:`~softdesign.meshing.checks.check_solid`: watertight, consistently wound, vertex-manifold,
    no degenerate face, one body, the Euler characteristic of the kind (2 solid or ported, 4
    sealed hollow), and volume within 0.5 % of the sum over links of the volume integrated from
    the spline surface on each link's own segment (Gauss-Legendre in l between the link's joints
    and spline knots, trapezoid rule in the angle; an annulus is flat and encloses nothing), less
    the chamber's and the port's; that no two vertices become one in float32 coordinates (a mesh
    file's: one read back would no longer be closed); then manifold3d's status.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import numpy.typing as npt

from softdesign.errors import MeshError
from softdesign.fitting.radius_field import RadiusField
from softdesign.geometry.frames import FramedSpline
from softdesign.geometry.se3 import inverse_pose
from softdesign.kinematics.links import LinkChain
from softdesign.meshing.body.pose_stitch import JointStep, JointStitch, assemble, placed, resampled_joints
from softdesign.meshing.body.sections import body_breaks, body_stations, export_l_grid, sections_on_grid
from softdesign.meshing.checks import Expectation, MeshReport, check_solid
from softdesign.meshing.end_cut import CutPlane, cut_planes, end_cut_volume
from softdesign.meshing.solids import carve_chamber, manifold_from_mesh
from softdesign.meshing.tessellate import Sweep, TubeMesh, TubeSections, sweep_from_sections, trim_sweep
from softdesign.meshing.volume import (
    BodySpec,
    EndCuts,
    angle_grid,
    arclength_at,
    integrate_body,
    l_at_arclength,
    swept_volume,
)
from softdesign.types import FloatArray, IntArray, Pose


@dataclass(frozen=True)
class PoseSpec:
    """How to sample each link (``spacing_mm``, ``angular_count``) and what solid to make (the export's keys, mm)."""

    spacing_mm: float = 0.5
    angular_count: int = 64
    offset_mm: float = 0.0
    wall_mm: float = 0.0
    port_mm: float = 0.0
    end_cuts: EndCuts = (None, None)

    def body(self) -> BodySpec:
        """The solid's offset, wall, port and end cuts."""
        return BodySpec(offset_mm=self.offset_mm, wall_mm=self.wall_mm, port_mm=self.port_mm, end_cuts=self.end_cuts)


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
    kind: str = "solid"  # "solid", or "hollow" / "ported" with PoseSpec.wall_mm


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


def _link_breaks(field: RadiusField, link: int) -> FloatArray:
    """The link's ends and every spline knot between them (where the integrand may not be smooth)."""
    lo, hi = field.breaks[link], field.breaks[link + 1]
    knots = body_breaks(field)
    return np.concatenate([[lo], knots[(knots > lo) & (knots < hi)], [hi]])


def _link_volume(curve: FramedSpline, field: RadiusField, link: int, q: float, spec: PoseSpec) -> float:
    """The link's volume integrated from its spline surface (offset included), mm^3."""
    stations = body_stations(curve, field, q, spec.angular_count)
    return integrate_body(stations, _link_breaks(field, link), BodySpec(offset_mm=spec.offset_mm)).volume


def _link_sweeps(sections: list[TubeSections], offset_mm: float, key: str = "offset_mm") -> list[Sweep]:
    """Each link's sections offset by ``offset_mm``, checked (``key`` names the case-file key in errors)."""
    sweeps = []
    for j, sec in enumerate(sections):
        try:
            sweeps.append(sweep_from_sections(sec, offset_mm, field=key))
        except MeshError as err:
            raise MeshError(f"link {j}: {err}") from err
    return sweeps


def pose_body(chain: LinkChain, field: RadiusField, q: float | npt.ArrayLike, spec: PoseSpec = PoseSpec()) -> PoseBody:
    """S_robot(q_1..q_n): each link at its own q, placed by the links before it, as one checked solid.

    Parameters
    ----------
    chain : LinkChain, the blended shape and its link breaks
    field : RadiusField, rho(q) per link, on the same breaks
    q : float or (n_links,) float in [0, 1], one q for every link or one per link
    spec : PoseSpec; with ``wall_mm`` the body is hollowed as the export hollows it (see the
        module notes)

    Returns
    -------
    PoseBody

    Raises
    ------
    ConfigError
        q of the wrong count or outside [0, 1].
    MeshError
        Naming the link, q and l: a surface that folds, an offset the radius cannot take, a wall
        the joints' steps leave too thin, or a failed check of the solid (with its figures).
    """
    q = chain.q_per_link(q)
    if not np.array_equal(np.asarray(field.breaks, float), np.asarray(chain.breaks, float)):
        raise ValueError(f"field breaks {list(field.breaks)} differ from the chain's {list(chain.breaks)}")
    curves = {value: chain.shape.curve_at(value) for value in sorted(set(q.tolist()))}
    sections = [link_sections(curves[qj], field, j, qj, spec) for j, qj in enumerate(q.tolist())]
    sweeps, stitches = resampled_joints(_link_sweeps(sections, spec.offset_mm))
    volumes = [_link_volume(curves[qj], field, j, qj, spec) for j, qj in enumerate(q.tolist())]
    start2world = chain.base2world(q)
    links, moves = [], []
    for j, (qj, transform) in enumerate(zip(q.tolist(), chain.transforms(q), strict=True)):
        moves.append(start2world @ inverse_pose(curves[qj].poses([field.breaks[j]])[0]))
        sweep = placed(sweeps[j], moves[-1])
        length = float(sweep.s[-1] - sweep.s[0])
        l_range = (float(field.breaks[j]), float(field.breaks[j + 1]))
        links.append(PoseLink(j, qj, *l_range, length, start2world, sweep, volumes[j]))
        start2world = start2world @ transform
    planes = _end_planes(links[0].sweep, links[-1].sweep, spec.end_cuts, 0.0)
    vertices, faces, regions = assemble([link.sweep for link in links], stitches, planes, label="pose")
    label = "pose q=[" + ", ".join(f"{v:.3f}" for v in q) + "]"
    joints = [s.figures(j, float(field.breaks[j + 1])) for j, s in enumerate(stitches)]
    reach = max(s.max_rho_kappa for s in sweeps)
    expected, euler, kind = float(sum(volumes)) + _cut_volume(links[0].sweep, links[-1].sweep, planes), 2, "solid"
    if spec.wall_mm > 0:
        chamber, chamber_stitches = _chamber(sections, spec, label)
        joints = [replace(step, min_wall_mm=_joint_wall(outer, inner, step, spec))
                  for outer, inner, step in zip(stitches, chamber_stitches, joints, strict=True)]
        chamber = [placed(sweep, move) for sweep, move in zip(chamber, moves, strict=True)]
        inner = _end_planes(links[0].sweep, links[-1].sweep, spec.end_cuts, spec.wall_mm)
        cavity = TubeMesh(*assemble(chamber, chamber_stitches, inner, label="pose chamber"))
        expected -= _cut_volume(chamber[0], chamber[-1], inner)
        body = TubeMesh(vertices, faces, regions)
        solid = carve_chamber(body, cavity, links[0].sweep, chamber[0], spec.body(), label)
        vertices, faces, regions, euler, kind = solid.vertices, solid.faces, solid.regions, solid.euler, solid.kind
        expected -= _chamber_volume(curves, field, q.tolist(), spec)
    report = check_solid(vertices, faces, Expectation(volume=expected, euler=euler, bodies=1), label=label)
    check_distinct_when_written(vertices, label)
    if kind == "solid":
        manifold_from_mesh(vertices, faces, label)
    return PoseBody(q, tuple(links), tuple(joints), vertices, faces, regions, expected, report, reach, kind)


def check_distinct_when_written(vertices: FloatArray, label: str) -> None:
    """Raise when two vertices would become one in a mesh file (float32 coordinates), opening the written solid."""
    lost = vertices.shape[0] - np.unique(np.asarray(vertices, np.float32), axis=0).shape[0]
    if lost:
        which = "1 vertex lies" if lost == 1 else f"{lost} vertices lie"
        raise MeshError(
            f"{label}: {which} closer to another than a mesh file's float32 coordinates can tell apart, so the "
            "written solid would not be closed; this is a bug in the pose mesher, please report it with the case "
            "file and the q"
        )


def _end_planes(first: Sweep, last: Sweep, cuts: EndCuts, inset_mm: float) -> tuple[CutPlane | None, CutPlane | None]:
    """The cut planes at the base of the placed ``first`` link and the tip of the placed ``last``."""
    return cut_planes(first, (cuts[0], None), inset_mm)[0], cut_planes(last, (None, cuts[1]), inset_mm)[1]


def _cut_volume(first: Sweep, last: Sweep, planes: tuple[CutPlane | None, CutPlane | None]) -> float:
    """What the end cuts add to the volume between the end frames' planes, mm3 (the export's wedges)."""
    return end_cut_volume(first, (planes[0], None)) + end_cut_volume(last, (None, planes[1]))


def _chamber(sections: list[TubeSections], spec: PoseSpec, label: str) -> tuple[list[Sweep], list[JointStitch]]:
    """Each link's piece of the chamber (the inward offset by wall_mm), wall_mm short of the base and the tip.

    Unplaced, like the body's pieces; the first and the last link are trimmed (one link: both ends).
    """
    w = spec.wall_mm
    sweeps, stitches = resampled_joints(_link_sweeps(sections, spec.offset_mm - w, "wall_mm"))
    first, last = sweeps[0], sweeps[-1]
    start, end = first.s[0] + w, last.s[-1] - w
    for j, sweep, short in ((0, first, start >= first.s[-1]), (len(sweeps) - 1, last, end <= last.s[0])):
        if short or (len(sweeps) == 1 and end - start < BodySpec().min_radius_mm):
            raise MeshError(
                f"wall_mm: {label}: link {j} is {sweep.s[-1] - sweep.s[0]:.3f} mm long, too short for end caps "
                f"{w:g} mm thick at the body's ends; use a thinner wall or longer end links"
            )
    if len(sweeps) == 1:
        return [trim_sweep(first, start, end)], stitches
    sweeps[0], sweeps[-1] = trim_sweep(first, start, first.s[-1]), trim_sweep(last, last.s[0], end)
    return sweeps, stitches


def _joint_wall(outer: JointStitch, inner: JointStitch, step: JointStep, spec: PoseSpec) -> float:
    """Thinnest wall at a joint, mm: across the joint plane from one link's chamber edge to the other's outer ring.

    Raises
    ------
    MeshError
        Where it is below the least radius an offset may keep: the chamber would break through.
    """
    thinnest = float(min(np.min(outer.start_radius - inner.end_radius), np.min(outer.end_radius - inner.start_radius)))
    least = BodySpec().min_radius_mm
    if thinnest < least:
        raise MeshError(
            f"wall_mm: joint {step.index}|{step.index + 1} at l={step.l:.4f}: the links' radii step by up to "
            f"{step.max_step_mm:.3f} mm, which leaves a wall of {thinnest:.3f} mm of the {spec.wall_mm:g} mm asked "
            f"(least {least:g} mm); use a wall thicker than the step plus {least:g} mm, or closer q values"
        )
    return thinnest


def _chamber_volume(curves: dict, field: RadiusField, q: list[float], spec: PoseSpec) -> float:
    """The chamber's volume over every link and the port channel's, integrated like the export's, mm^3."""
    w, total = spec.wall_mm, np.pi * (spec.port_mm / 2.0) ** 2 * spec.wall_mm
    for j, qj in enumerate(q):
        stations = body_stations(curves[qj], field, qj, spec.angular_count)
        breaks = _link_breaks(field, j)
        lo, hi = float(breaks[0]), float(breaks[-1])
        if j == 0:
            lo = l_at_arclength(stations, breaks, w)
        if j == len(q) - 1:
            hi = l_at_arclength(stations, breaks, arclength_at(stations, breaks, hi) - w)
        total += swept_volume(stations, breaks, (lo, hi), spec.offset_mm - w)
    return total
