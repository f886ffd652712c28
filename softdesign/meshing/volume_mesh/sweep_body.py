"""The swept mesh of :mod:`softdesign.meshing.volume_mesh.sweep_mesh` placed in space: the body at q, node by node.

Map
    Layer j at q is the export's section at ``l_j(q)``: centre c, frame (N, B),
    outer section curve ``O(a)`` (the body offset by ``offset_mm``) and, for a
    hollow body, the chamber's curve ``I(a)`` (offset by ``offset_mm -
    wall_mm``), both on the export's angle grid, from
    :func:`~softdesign.meshing.tessellate.sweep_from_sections` (so folds and
    walls too thick fail here as in the export).  A reference point at polar
    (t, a) of the unit disk goes to ``c + x N + y B`` with (x, y):

    - solid: ``t O(a)``;
    - hollow, chamber radius ``r_c`` in the reference: ``(t / r_c) I(a)`` for
      t <= r_c, ``I + (t - r_c) / (1 - r_c) (O - I)`` beyond (depth through the wall);
    - chambered (issue 31's layout, :func:`holes_from_layout`): a rigid core
      ``R0 (x, y)`` for t <= t_c, holding every chamber and feed as the exact
      circle in mm the layout gives, then ``C + (t - t_c) / (1 - t_c) (O - C)``
      out to the skin, C the core's circle ``t_c R0 u(a)``;

    ``O(a)``, ``I(a)`` linear between the grid's angles, so the outer circle's
    nodes (at the grid angles) are the surface mesh's vertices and the mesh's
    skin is the export's polygon surface.
Material points
    A node is one material point at every q (its l and reference (x, y) do
    not depend on q), so the change between two q is the material's strain.
    The chamber's ends are its layers at arc lengths ``wall_mm`` and ``L -
    wall_mm`` at q = 0 (the cast part); at another q the sealed caps are what
    that material becomes, where the export makes caps ``wall_mm`` thick at
    every q (on the demo the two volumes differ by 1e-4 of the body's).
End cuts
    The export's cut (:mod:`softdesign.meshing.end_cut`): every generator (a
    reference point's nodes through the layers) slides so the end layer lies
    in the cut plane; for a hollow body the chamber's end layer then slides
    into the plane moved ``wall_mm`` inward, and the layers of the sealed cap
    between are spaced evenly along the straight line joining the two.  A
    solid body's (not a hollow or chambered one's: their chambers' ends would
    move) layer before the end goes onto the end ring wherever the
    plane lies past it (:func:`~softdesign.meshing.end_cut.crease_targets`):
    there the surface, which deforms with q, meets its straight continuation,
    which the end frame carries rigidly, and a row of skin quads across that
    crease measured neither (the demo at q = 0.5: least stretch 0.6950,
    +1.34 % of the end ring's 0.6858, its last row 73 % continuation).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from softdesign.errors import MeshError
from softdesign.fitting.radius_field import RadiusField
from softdesign.geometry.frames import FramedSpline
from softdesign.meshing.body.sections import sections_on_grid
from softdesign.meshing.chambers.layout import ChamberLayout
from softdesign.meshing.end_cut import CutPlane, along_generators, crease_targets, cut_planes, cut_targets
from softdesign.meshing.tessellate import Sweep, sweep_from_sections
from softdesign.meshing.volume import BodySpec, angle_grid
from softdesign.meshing.volume_mesh.sweep_layout import MIN_FEED_NODES, check_resolvable, layout_holes
from softdesign.meshing.volume_mesh.sweep_mesh import Hole, SweptMesh
from softdesign.types import FloatArray


@dataclass(frozen=True)
class SweepReference:
    """What ties a swept mesh to the body: the reference chamber and where the chamber's end layers are.

    Attributes
    ----------
    chamber_radius : float, r_c, the chamber's circle in section radii (0: a solid body)
    chamber_layers : (j0, j1), the layers of the chamber's ends (hollow), else (0, 0)
    core : float, t_c, the rigid core's radius in reference units (0: none; chambered bodies)
    scale_mm : float, R0, mm per reference unit inside the core
    outer0 : the outer sweep at q = 0 (its arc lengths carry the cuts' targets to other q)
    cuts : the end cuts' targets found at q = 0 (:data:`CutTargets`)
    """

    chamber_radius: float = 0.0
    chamber_layers: tuple[int, int] = (0, 0)
    core: float = 0.0
    scale_mm: float = 0.0
    outer0: Sweep | None = None
    cuts: CutTargets | None = None


def l_at_arclength(curve: FramedSpline, s: FloatArray) -> FloatArray:
    """Normalized l where the arc length along ``curve`` reaches ``s`` (mm), by the curve's dense table."""
    l_dense = curve.curve.dense_l()
    return np.interp(np.asarray(s, float), curve.curve.arc_length(l_dense), l_dense)


def section_sweeps(mesh: SweptMesh, ref: SweepReference, curve: FramedSpline, field: RadiusField, q: float,
                   spec: BodySpec, angular_count: int) -> tuple[Sweep, Sweep | None]:
    """The outer sweep (and the chamber's, hollow) at the layers of this q."""
    l = mesh.l
    a = angle_grid(angular_count)
    sections = sections_on_grid(curve, q, l, field.evaluate_grid(q, l, a), field.evaluate_grid(q, l, a, dl=1))
    outer = sweep_from_sections(sections, spec.offset_mm, spec.min_radius_mm)
    if ref.chamber_radius == 0.0:
        return outer, None
    return outer, sweep_from_sections(sections, spec.offset_mm - spec.wall_mm, spec.min_radius_mm, field="wall_mm")


def _on_curve(xy: FloatArray, angles: FloatArray) -> FloatArray:
    """Section curves (n, na, 2) at ``angles`` (P,), linear between the grid's angles: (n, P, 2)."""
    na = xy.shape[1]
    where = np.mod(angles, 2.0 * np.pi) * na / (2.0 * np.pi)
    k = np.minimum(np.floor(where).astype(np.int64), na - 1)
    f = (where - k)[None, :, None]
    return (1.0 - f) * xy[:, k] + f * xy[:, (k + 1) % na]


def section_xy(points: FloatArray, outer: Sweep, inner: Sweep | None, ref: SweepReference) -> FloatArray:
    """The reference section ``points`` (P, 2) in every layer's (N, B) plane, (n, P, 2) mm."""
    t = np.linalg.norm(points, axis=1)
    angles = np.arctan2(points[:, 1], points[:, 0])
    o = _on_curve(outer.xy, angles)
    if ref.core > 0.0:
        tc, r0 = ref.core, ref.scale_mm
        reach = np.einsum("npk,pk->np", o, np.column_stack([np.cos(angles), np.sin(angles)]))
        skin = reach[:, t >= 1.0 - 1e-9]
        if np.any(skin <= tc * r0):
            row = int(np.argmin(np.min(skin, axis=1)))
            raise MeshError(f"volume mesh at q={outer.q:.3f}, l={outer.l[row]:.4f}: the skin comes within "
                            f"{tc * r0:.3f} mm of the centerline, inside the chambers' ring; the layout does not "
                            "fit this section: use smaller actuation.distance_mm or diameter_mm")
        core = r0 * points[None, :, :]
        rim = (tc * r0) * np.column_stack([np.cos(angles), np.sin(angles)])[None]
        out = rim + np.clip((t - tc) / (1.0 - tc), 0.0, None)[None, :, None] * (o - rim)
        return np.where((t <= tc)[None, :, None], core, out)
    if inner is None:
        return t[None, :, None] * o
    i = _on_curve(inner.xy, angles)
    rc = ref.chamber_radius
    depth = np.clip((t - rc) / (1.0 - rc), 0.0, None)[None, :, None]
    return np.where((t <= rc)[None, :, None], (t / rc)[None, :, None] * i, i + depth * (o - i))


def _grid_points(sweep: Sweep, xy: FloatArray) -> FloatArray:
    return (sweep.centers[:, None, :] + xy[..., :1] * sweep.frames[:, None, :, 0]
            + xy[..., 1:] * sweep.frames[:, None, :, 1])


#: Per cut (body base, body tip, chamber base, chamber tip): each node's arc length along its generator at
#: q = 0 after the cut (:func:`~softdesign.meshing.end_cut.cut_targets`, or for a solid body's own ends
#: :func:`~softdesign.meshing.end_cut.crease_targets`), or None where there is no cut.
CutTargets = tuple[FloatArray | None, FloatArray | None, FloatArray | None, FloatArray | None]


def _end_order(sweep: Sweep, end: int) -> tuple[slice, FloatArray, FloatArray, FloatArray]:
    """The grid's order with the cut end last, its arc lengths from the other end, the outward tangent, centre."""
    k = 0 if end == 0 else -1
    order = slice(None, None, -1) if end == 0 else slice(None)
    s = sweep.s[-1] - sweep.s[::-1] if end == 0 else sweep.s - sweep.s[0]
    return order, s, sweep.frames[k][:, 2] * (-1.0 if end == 0 else 1.0), sweep.centers[k]


def _carried(target0: FloatArray, s0: FloatArray, s: FloatArray) -> FloatArray:
    """Arc-length targets at q = 0 carried to this q: the same material fraction between rings, the same
    millimetres past the end ring (the end's section moves rigidly with its frame)."""
    return np.where(target0 > s0[-1], s[-1] + (target0 - s0[-1]), np.interp(target0, s0, s))


#: A solid body's last layer past a crease (:func:`~softdesign.meshing.end_cut.crease_targets`) is at least
#: this fraction of the last layer interval thick.
CREASE_THICKNESS = 0.5


def _cut(points: FloatArray, sweep: Sweep, sweep0: Sweep, end: int, plane: CutPlane | None,
         target0: FloatArray | None, label: str, crease: bool = False) -> tuple[FloatArray, FloatArray]:
    """``points`` (n, P, 3) with the generators slid: at q = 0 (``target0`` None) so the end layer lies in
    ``plane`` (``crease``: the layer before it on the end ring where the plane lies past it,
    :func:`~softdesign.meshing.end_cut.crease_targets`); at another q to the same material places (``target0``,
    found at q = 0)."""
    order, s, outward, _ = _end_order(sweep, end)
    grid = points[order]
    if target0 is None:
        if plane is None:
            raise ValueError("_cut: a plane is needed at q = 0")
        if crease and len(s) >= 3:
            target0 = crease_targets(grid, s, outward, plane, label, CREASE_THICKNESS * (s[-1] - s[-2]))
        else:
            target0 = cut_targets(grid, s, outward, plane, label)
        target = target0
    else:
        target = _carried(target0, _end_order(sweep0, end)[1], s)
    out = points.copy()
    out[order] = along_generators(grid, s, outward, target)
    return out, target0


def _cap_between(points: FloatArray, s0: FloatArray, first: int, last: int) -> FloatArray:
    """Layers strictly between ``first`` and ``last`` on the straight line joining them, spaced as at q = 0."""
    w = ((s0[first:last + 1] - s0[first]) / (s0[last] - s0[first]))[:, None, None]
    out = points.copy()
    out[first:last + 1] = (1.0 - w) * points[first][None] + w * points[last][None]
    return out


def cut_grid(points: FloatArray, outer: Sweep, outer0: Sweep, ref: SweepReference, spec: BodySpec,
             label: str) -> tuple[FloatArray, CutTargets]:
    """The layer grid (n, P, 3) cut at the body's end planes (and the chamber's, moved ``wall_mm`` in), as at
    q = 0 when ``ref.cuts`` holds the targets found there, else found here (``outer`` is then the q = 0 sweep)."""
    found: list[FloatArray | None] = [None, None, None, None]
    planes = cut_planes(outer, spec.end_cuts)
    known = ref.cuts or (None, None, None, None)
    for end, plane in enumerate(planes):
        if plane is not None:
            points, found[end] = _cut(points, outer, outer0, end, plane, known[end],
                                      f"{label}: the {('base', 'tip')[end]} end's cut plane",
                                      crease=ref.chamber_radius == 0.0 and ref.core == 0.0)
    if ref.chamber_radius == 0.0:
        return points, (found[0], found[1], found[2], found[3])
    j0, j1 = ref.chamber_layers
    inset = cut_planes(outer, spec.end_cuts, spec.wall_mm)
    s0 = outer0.s
    if inset[0] is not None:
        part, part0 = _sub_sweep(outer, j0, None), _sub_sweep(outer0, j0, None)
        points[j0:], found[2] = _cut(points[j0:], part, part0, 0, inset[0], known[2],
                                     f"{label}: the chamber's base cut plane")
        points = _cap_between(points, s0, 0, j0)
    if inset[1] is not None:
        part, part0 = _sub_sweep(outer, None, j1 + 1), _sub_sweep(outer0, None, j1 + 1)
        points[:j1 + 1], found[3] = _cut(points[:j1 + 1], part, part0, 1, inset[1], known[3],
                                         f"{label}: the chamber's tip cut plane")
        points = _cap_between(points, s0, j1, len(s0) - 1)
    return points, (found[0], found[1], found[2], found[3])


def _sub_sweep(sweep: Sweep, start: int | None, stop: int | None) -> Sweep:
    part = slice(start, stop)
    return Sweep(sweep.q, sweep.l[part], sweep.s[part], sweep.centers[part], sweep.frames[part], sweep.xy[part],
                 sweep.max_rho_kappa)


def place_mesh(mesh: SweptMesh, ref: SweepReference, curve: FramedSpline, field: RadiusField, q: float,
               spec: BodySpec, angular_count: int) -> FloatArray:
    """The mesh's nodes at q, (V, 3) mm (``ref`` from :func:`plan_mesh`, its cuts found at q = 0).

    Raises
    ------
    MeshError
        As the export would: a fold, a wall or offset the local radius cannot take, an end plane too far.
    """
    outer, inner = section_sweeps(mesh, ref, curve, field, q, spec, angular_count)
    grid = _grid_points(outer, section_xy(mesh.section.points, outer, inner, ref))
    if ref.outer0 is None:
        raise ValueError("place_mesh: the reference has no q = 0 sweep (make it with plan_mesh)")
    grid, _ = cut_grid(grid, outer, ref.outer0, ref, spec, f"volume mesh at q={q:.3f}")
    return grid[mesh.node_layer, mesh.node_point]


def _with_cuts(mesh: SweptMesh, ref: SweepReference, curve0: FramedSpline, field: RadiusField, spec: BodySpec,
               angular_count: int) -> SweepReference:
    """``ref`` with the q = 0 sweep and the end cuts' material targets found on it."""
    outer, inner = section_sweeps(mesh, ref, curve0, field, 0.0, spec, angular_count)
    grid = _grid_points(outer, section_xy(mesh.section.points, outer, inner, ref))
    _, cuts = cut_grid(grid, outer, outer, replace(ref, cuts=None), spec, "volume mesh at q=0.000")
    return replace(ref, outer0=outer, cuts=cuts)


def plan_mesh(curve0: FramedSpline, field: RadiusField, layers: FloatArray, spec: BodySpec, angular_count: int,
              size_mm: float, layout: ChamberLayout | None = None,
              reference_l: FloatArray | None = None) -> tuple[SweptMesh, SweepReference]:
    """The swept mesh of the body and its reference, laid out on the body at q = 0 (the cast state).

    Parameters
    ----------
    curve0 : the centerline at q = 0
    field : the radius field
    layers : (n,) float, l of the layers from 0 to 1 (the chamber's ends are put in)
    spec : offset, wall (a concentric chamber ``wall_mm`` short of each end), port (a concentric feed
        through the base cap)
    angular_count : nodes on the outer circle and on the chamber's and port's circles (the export's angles)
    size_mm : the largest edge inside the section, mm
    layout : issue 31's chambers and feeds (a solid body's), or None
    reference_l : (m,) float, the l at which the section's scale and the chamber's reference radius are taken
        (None: ``layers``); layers graded finer somewhere
        (:mod:`softdesign.meshing.volume_mesh.sweep_grading`) pass their even grid, so that where the layers
        crowd does not move the reference section

    The chamber's reference radius is the median ratio of the chamber's to the outer section's radius
    at q = 0 (so the depth coordinate is about uniform); the port's is its radius over the chamber's
    base section's mean radius, in the chamber's units.
    """
    from softdesign.meshing.volume_mesh.cross_section import Circle
    from softdesign.meshing.volume_mesh.sweep_mesh import Hole, swept_disk

    a = angle_grid(angular_count)
    even = layers if reference_l is None else np.asarray(reference_l, float)
    rho = field.evaluate_grid(0.0, layers, a)
    scale = float(np.median(field.evaluate_grid(0.0, even, a)))
    size = size_mm / scale
    if layout is not None:
        if spec.wall_mm > 0:
            raise MeshError("volume mesh: actuation chambers and export.wall_mm's single chamber together; give one")
        # the core must stay inside the skin at every q: the thinnest radius over the morph, not at q = 0 alone
        thinnest = min(float(np.min(field.evaluate_grid(q, layers, a))) for q in CORE_Q_SAMPLES)
        holes, ref = holes_from_layout(layout, scale, thinnest, size_mm)
        mesh = swept_disk(angular_count, holes, size, layers)
        return mesh, _with_cuts(mesh, ref, curve0, field, spec, angular_count)
    if spec.wall_mm == 0:
        mesh = swept_disk(angular_count, [], size, layers)
        return mesh, _with_cuts(mesh, SweepReference(), curve0, field, spec, angular_count)
    ends = l_at_arclength(curve0, np.array([spec.wall_mm, curve0.length - spec.wall_mm]))
    sections = sections_on_grid(curve0, 0.0, layers, rho, field.evaluate_grid(0.0, layers, a, dl=1))
    outer = sweep_from_sections(sections, spec.offset_mm, spec.min_radius_mm)
    inner = sweep_from_sections(sections, spec.offset_mm - spec.wall_mm, spec.min_radius_mm, field="wall_mm")
    rc = _chamber_ratio(layers if reference_l is None else even, ends, outer, inner, layers)
    holes = [Hole("chamber", Circle((0.0, 0.0), rc, angular_count), (float(ends[0]), float(ends[1])))]
    if spec.port_mm > 0:
        base = int(np.argmin(np.abs(layers - ends[0])))
        rp = rc * 0.5 * spec.port_mm / float(np.mean(np.linalg.norm(inner.xy[base], axis=-1)))
        # the chamber's spacing, not the export's angular count (a port of 64 sides in a 1 mm wide channel
        # made needles 1.5 degrees thin in the caps' layers); its polygon has the channel's area
        nodes = max(MIN_FEED_NODES, int(np.ceil(angular_count * rp / rc)))
        holes.append(Hole("port", Circle((0.0, 0.0), rp, nodes, equal_area=True), (0.0, float(ends[0])),
                          cavity="chamber"))
    mesh = swept_disk(angular_count, holes, size, layers)
    j = [int(np.argmin(np.abs(mesh.l - e))) for e in ends]
    return mesh, _with_cuts(mesh, SweepReference(rc, (j[0], j[1])), curve0, field, spec, angular_count)


def _chamber_ratio(even: FloatArray, ends: FloatArray, outer: Sweep, inner: Sweep, layers: FloatArray) -> float:
    """The median ratio of the chamber's to the outer section's radius over the layers at ``even`` (each one of
    ``layers``) within the chamber's ends ``ends`` (2,) l; 0.5 when none is."""
    picked = np.isin(layers, even) & (layers >= ends[0]) & (layers <= ends[1])
    ratio = np.linalg.norm(inner.xy[picked], axis=-1) / np.linalg.norm(outer.xy[picked], axis=-1)
    return float(np.median(ratio)) if ratio.size else 0.5


#: The q at which the thinnest radius is looked for, for the rigid core of a chambered body.
CORE_Q_SAMPLES = tuple(np.linspace(0.0, 1.0, 11))
#: The rigid core reaches this fraction of the way from the chambers' outer edge to the thinnest skin.
CORE_GAP_FRACTION = 0.5


def holes_from_layout(layout: ChamberLayout, scale_mm: float, rho_min_mm: float,
                      size_mm: float) -> tuple[list[Hole], SweepReference]:
    """Issue 31's chambers and feeds as holes of the reference section, and the rigid core holding them.

    Chamber j of section i (both counted from 1 at the base, as actuation.csv) is ``s{i}_c{j}`` (surfaces
    ``s{i}_c{j}_wall``, ``_cap``); its feed ``s{i}_c{j}_feed`` belongs to the same cavity and opens at the base
    (``s{i}_c{j}_feed_inlet``).
    ``scale_mm`` (R0) is mm per reference unit, ``rho_min_mm`` the thinnest section's radius over the morph,
    ``size_mm`` the element size the circles' nodes follow
    (:func:`~softdesign.meshing.volume_mesh.sweep_layout.circle_nodes`).
    """
    reach = max([c.distance_mm + 0.5 * c.diameter_mm for c in layout.chambers]
                + [f.ring_mm + 0.5 * f.diameter_mm for f in layout.feeds])
    core_mm = reach + CORE_GAP_FRACTION * (rho_min_mm - reach)
    if not reach < core_mm < rho_min_mm:
        raise MeshError(f"volume mesh: the chambers reach {reach:.3f} mm from the centerline, the thinnest section "
                        f"is {rho_min_mm:.3f} mm: no wall; use smaller actuation.distance_mm or diameter_mm")
    holes = check_resolvable(layout, layout_holes(layout, scale_mm, size_mm), scale_mm)
    return holes, SweepReference(core=core_mm / scale_mm, scale_mm=scale_mm)
