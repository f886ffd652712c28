"""The actuated body: S(q) with every chamber and feed line of a :class:`ChamberLayout` cut out (manifold3d).

Each chamber and feed is a tube swept in the body's own parameter domain: at
every ring l of the export grid within its l-range, a circle of its diameter
centred at ``(distance cos beta, distance sin beta)`` in the body's (N, B)
plane at l.  Those planes are normal to the centerline and therefore normal
to the offset axis too (its tangent is ``(1 - kappa . offset) T``), so the tube
is a true tube of that radius about the offset curve, and its flat caps lie
in the body's normal planes: it bends with the body at every q, with no
resampling that could differ from q to q.  The rings share the body's l-grid,
so the same inputs give the same bytes.  The polygon's circumradius is raised so
that its area is the circle's (``AREA_RADIUS``): the cavity's volume is then the
analytic ``pi r^2 x axis length`` within the chords' sagitta along l.

A feed starts ``feed_extension_mm`` before the base plane (along -T(0)) so it
opens through the base face (also when the base is cut on a tilted plane), and
ends inside its chamber, coaxial and narrower, so each chamber and its feed
form one blind cavity open only at the base face: the result is one shell of
genus 0 (Euler 2), with 3n dents.  A single supply's chambers are one cavity:
the supply line into section 1's chamber, each next chamber reached by its
series channel (:class:`~softdesign.meshing.chamber_layout.Channel`), swept on
its course's own samples with the feeds' polygon; still Euler 2, one dent.  Manifold booleans: the union of every
cavity, subtracted from the body once.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass, replace

import manifold3d as m3
import numpy as np
import numpy.typing as npt

from softdesign.geometry.frames import FramedSpline
from softdesign.meshing.body.sections import curvature_components
from softdesign.meshing.chambers.layout import Chamber, ChamberLayout, Channel, Feed, offset_points
from softdesign.meshing.solids import Solid, _regions_after, checked, cut_body, manifold_from_mesh, welded_as_written
from softdesign.meshing.tessellate import Region, Sweep, TubeMesh, TubeSections, sweep_from_sections, tessellate
from softdesign.meshing.volume import BodySpec
from softdesign.types import FloatArray

#: Polygon sides of a chamber's and a feed's section.
CHAMBER_SEGMENTS = 32
FEED_SEGMENTS = 16
#: A feed's polygon is turned by half a chamber step: coaxial with its chamber, its vertices would otherwise
#: run along the spokes of the chamber's fan-triangulated end (16 of the 32 angles), and the boolean would cut
#: faces of a few 1e-6 mm there, which single precision (STL) folds to zero area (issue 43).
FEED_PHASE = np.pi / CHAMBER_SEGMENTS
#: How far a feed reaches out of the base plane, mm, at least (the base cut's lean is added).
FEED_EXTENSION_MM = 1.0
#: Gauss-Legendre nodes per ring interval for the analytic cavity volume.
VOLUME_NODES = 4


def area_radius(radius_mm: float, segments: int) -> float:
    """Circumradius of the regular ``segments``-gon whose area is that of a circle of ``radius_mm``."""
    angle = 2.0 * np.pi / segments
    return float(radius_mm * np.sqrt(angle / np.sin(angle)))


@dataclass(frozen=True)
class Cavity:
    """One chamber or feed as a sweep, named for messages and regions."""

    kind: str  # "chamber" or "feed"
    section: int
    chamber: int
    sweep: Sweep


def _grid(l_body: FloatArray, l_start: float, l_end: float) -> FloatArray:
    """The body's rings strictly inside (l_start, l_end), away from the ends by a quarter ring, and the ends."""
    gap = 0.25 * float(np.min(np.diff(l_body)))
    inside = l_body[(l_body > l_start + gap) & (l_body < l_end - gap)]
    return np.concatenate([[l_start], inside, [l_end]])


def _tube(curve: FramedSpline, q: float, l: FloatArray, distance: npt.ArrayLike, angle: npt.ArrayLike,
          diameter: npt.ArrayLike, segments: int, before_mm: float = 0.0, phase: float = 0.0) -> Sweep:
    """A tube of ``diameter`` about the offset curve over ``l``; ``before_mm`` > 0 starts it ``before_mm`` before
    ``l[0]`` along -T, in place of the ring at ``l[0]``.

    ``distance``, ``diameter`` (mm) and ``angle`` (rad) are one number, or one per ring of ``l`` (a tapered
    chamber, a series channel's course).
    The ring at ``l[0]`` (the base, l = 0) is dropped when ``before_mm`` > 0: it would lie in the base cap's plane,
    and the boolean cuts the tube there into faces of a few 1e-7 mm that single precision (STL) folds to zero
    area, leaving non-manifold edges once coincident vertices are merged (issue 43).  The tube runs straight from
    outside the base to the first ring inside.  ``phase`` turns the polygon's vertices by that angle, rad.
    """
    centers, frames = curve.points(l), curve.frames(l)
    s = curve.curve.arc_length(l)
    distance = np.broadcast_to(np.asarray(distance, float), l.shape)
    diameter = np.broadcast_to(np.asarray(diameter, float), l.shape)
    angle = np.broadcast_to(np.asarray(angle, float), l.shape)[:, None]
    if before_mm > 0.0:
        centers = np.concatenate([[centers[0] - before_mm * frames[0][:, 2]], centers[1:]])
        s = np.concatenate([[s[0] - before_mm], s[1:]])
    t = 2.0 * np.pi * np.arange(segments) / segments + phase
    r = np.array([area_radius(0.5 * d, segments) for d in diameter])[:, None]
    xy = np.stack([distance[:, None] * np.cos(angle) + r * np.cos(t),
                   distance[:, None] * np.sin(angle) + r * np.sin(t)], axis=2)
    return Sweep(float(q), l, s, centers, frames, xy)


def cavity_sweeps(curve: FramedSpline, q: float, layout: ChamberLayout, l_body: FloatArray,
                  feed_extension_mm: float = FEED_EXTENSION_MM) -> tuple[Cavity, ...]:
    """Every chamber and feed of ``layout`` on the body's ring grid ``l_body`` at q, chambers first, then the
    series channels on their courses' own samples (kind ``channel``, ``section`` the chamber each one feeds)."""
    out = []
    for c in layout.chambers:
        l = _grid(l_body, c.l_start, c.l_end)
        out.append(Cavity("chamber", c.section, c.index,
                          _tube(curve, q, l, c.distance_at(l), c.angle, c.diameter_at(l), CHAMBER_SEGMENTS)))
    starts = {(c.section, c.index): c.l_start for c in layout.chambers}
    out += [Cavity("feed", f.section, f.chamber,
                   _tube(curve, q, _clear_of(_grid(l_body, f.l_start, f.l_end), starts[f.section, f.chamber], l_body),
                         f.ring_mm, f.angle, f.diameter_mm, FEED_SEGMENTS, before_mm=feed_extension_mm,
                         phase=FEED_PHASE))
            for f in layout.feeds]
    ends = {c.section: (c.l_start, c.l_end) for c in layout.chambers}
    for channel in layout.channels:
        l = np.asarray([p[0] for p in channel.course], float)
        for plane in (ends[channel.section - 1][1], ends[channel.section][0]):  # off both chambers' flat ends
            l = _clear_of(l, plane, l_body)
        out.append(Cavity("channel", channel.section, 0,
                          _tube(curve, q, l, channel.ring_at(l), channel.angle_at(l), channel.diameter_mm,
                                FEED_SEGMENTS, phase=FEED_PHASE)))
    return tuple(out)


def _clear_of(l: FloatArray, plane_l: float, l_body: FloatArray) -> FloatArray:
    """The rings ``l`` less any within a quarter ring of ``plane_l`` (a chamber's flat proximal end, which the feed
    crosses): a ring there would put the feed's vertices a hair from that plane, and the boolean's faces between
    them fold to zero area in single precision (issue 43).  The two ends of ``l`` are kept."""
    gap = 0.25 * float(np.min(np.diff(l_body)))
    near = np.abs(l - plane_l) < gap
    near[[0, -1]] = False
    return l[~near]


def carve_cavities(body: TubeMesh, cavities: Sequence[Cavity], max_rho_kappa: float, label: str) -> Solid:
    """``body`` minus the union of ``cavities``: one shell, Euler 2 (each cavity opens at the base face through its
    feed; a chamber without a feed is a closed void, Euler 2 more each).

    Regions: a chamber's wall CHAMBER, its flat ends CHAMBER_CAP; a feed's and a series channel's faces PORT.
    """
    body_manifold, body_id = manifold_from_mesh(body.vertices, body.faces, f"{label}: body")
    sources = {body_id: body.regions}
    tubes = []
    for cavity in cavities:
        mesh = tessellate(cavity.sweep)
        name = f"{label}: section {cavity.section + 1} {cavity.kind} {cavity.chamber + 1}"
        manifold, mesh_id = manifold_from_mesh(mesh.vertices, mesh.faces, name)
        if cavity.kind == "chamber":
            caps = mesh.regions != Region.WALL
            sources[mesh_id] = np.where(caps, Region.CHAMBER_CAP, Region.CHAMBER).astype(np.int8)
        else:  # a feed or a series channel
            sources[mesh_id] = np.array([Region.PORT], np.int8)
        tubes.append(manifold)
    union = checked(m3.Manifold.batch_boolean(tubes, m3.OpType.Add), f"{label}: chambers and feeds")
    result = checked(body_manifold - union, f"{label}: actuated body")
    vertices, faces, regions = welded_as_written(*_regions_after(result, sources))
    # a chamber with no feed and no series channel into it is a closed void: one more sphere-like shell, Euler 2
    fed = {(c.section, c.chamber) for c in cavities if c.kind in ("feed", "channel")}
    closed = sum(1 for c in cavities if c.kind == "chamber" and (c.section, c.chamber) not in fed)
    return Solid(vertices, faces, regions, 2 + 2 * closed, "actuated", max_rho_kappa)


@functools.lru_cache(maxsize=4)
def _gauss_legendre(nodes: int) -> tuple[FloatArray, FloatArray]:
    """Gauss-Legendre nodes and weights on [-1, 1], (nodes,) each, made once (numpy's leggauss solves an
    eigenproblem: 0.15 s of the aorta's three surface meshes with chambers went to remaking them)."""
    return np.polynomial.legendre.leggauss(nodes)


def axis_lengths(curve: FramedSpline, l_start: float, l_end: float, distance: float, angle: float,
                 nodes: int = 64) -> float:
    """Length of the offset curve ``c + distance (cos angle N + sin angle B)`` over [l_start, l_end], mm.

    ``|d/ds offset| = 1 - distance (k1 cos angle + k2 sin angle)`` in the RMF (the offset's tangent is T);
    Gauss-Legendre on ``nodes`` points per link-free interval (the integrand is smooth there).
    """
    x, w = _gauss_legendre(nodes)
    l = 0.5 * (l_end - l_start) * (x + 1.0) + l_start
    k = curvature_components(curve, l, curve.frames(l))
    stretch = 1.0 - distance * (k[:, 0] * np.cos(angle) + k[:, 1] * np.sin(angle))
    return float(0.5 * (l_end - l_start) * (w @ (stretch * curve.curve.speed(l))))


def piecewise_axis_length(curve: FramedSpline, breaks: Sequence[float], l_start: float, l_end: float, distance: float,
            angle: float) -> float:
    """:func:`axis_lengths` summed over the pieces between link breaks (the centerline's joints)."""
    cuts = [b for b in breaks if l_start < b < l_end]
    ends = [l_start, *cuts, l_end]
    return sum(axis_lengths(curve, a, b, distance, angle) for a, b in zip(ends[:-1], ends[1:], strict=True))


def cavity_volume_mm3(curve: FramedSpline, layout: ChamberLayout) -> float:
    """Analytic volume of every chamber and of each feed's part inside the body (base face to its chamber), mm3.

    A tube of radius r about an offset curve holds ``pi r^2 x (axis length)`` (Pappus, the sections are normal
    to the axis); a feed's last stretch lies inside its chamber and is not counted twice.
    """
    total = 0.0
    starts = {(c.section, c.index): c.l_start for c in layout.chambers}
    for c in layout.chambers:
        # a tapered chamber piece by piece between its profile's samples (trapezoid rule on the area)
        cuts = np.unique(np.clip([c.l_start, *(p[0] for p in c.profile), c.l_end], c.l_start, c.l_end))
        for a, b in zip(cuts[:-1], cuts[1:], strict=True):
            middle = 0.5 * (a + b)
            axis = piecewise_axis_length(curve, layout.breaks, a, b, float(c.distance_at(middle)), c.angle)
            total += np.pi * 0.125 * float(c.diameter_at(a) ** 2 + c.diameter_at(b) ** 2) * axis
    for f in layout.feeds:
        reach = piecewise_axis_length(curve, layout.breaks, 0.0, starts[f.section, f.chamber], f.ring_mm, f.angle)
        total += np.pi * (0.5 * f.diameter_mm) ** 2 * reach
    ends = {c.section: (c.l_start, c.l_end) for c in layout.chambers}
    for channel in layout.channels:  # between the two chambers' flat ends (inside them it is not counted twice)
        a, b = ends[channel.section - 1][1], ends[channel.section][0]
        joints = [a, *(x for x in layout.breaks if a < x < b), b]
        total += np.pi * (0.5 * channel.diameter_mm) ** 2 * sum(
            _course_length(curve, channel, u, v) for u, v in zip(joints[:-1], joints[1:], strict=True))
    return float(total)


def _course_length(curve: FramedSpline, channel: Channel, l_start: float, l_end: float, nodes: int = 64) -> float:
    """``integral (1 - ring (k1 cos angle + k2 sin angle)) ds`` along a channel's course over [l_start, l_end], mm:
    times the channel's area, the volume of its normal-plane sections (as :func:`axis_lengths`, the offset varying)."""
    x, w = _gauss_legendre(nodes)
    l = 0.5 * (l_end - l_start) * (x + 1.0) + l_start
    k = curvature_components(curve, l, curve.frames(l))
    angle, ring = channel.angle_at(l), channel.ring_at(l)
    stretch = 1.0 - ring * (k[:, 0] * np.cos(angle) + k[:, 1] * np.sin(angle))
    return float(0.5 * (l_end - l_start) * (w @ (stretch * curve.curve.speed(l))))


def member_axis(curve: FramedSpline, member: Chamber | Feed, l: FloatArray) -> FloatArray:
    """Points (n, 3) mm of a chamber's or feed's axis at ``l``."""
    distance = member.distance_mm if isinstance(member, Chamber) else member.ring_mm
    return offset_points(curve.points(l), curve.frames(l), distance, member.angle)


def feed_extension_mm(spec: BodySpec, layout: ChamberLayout) -> float:
    """How far the feeds start before the base plane: ``FEED_EXTENSION_MM`` plus the base cut's lean at the ring."""
    cut = spec.end_cuts[0]
    if cut is None:
        return FEED_EXTENSION_MM
    reach = max(f.ring_mm + 0.5 * f.diameter_mm for f in layout.feeds)
    return float(FEED_EXTENSION_MM + reach * np.tan(np.arccos(min(1.0, -cut[2]))) + abs(cut[3]))


def build_actuated(sections: TubeSections, spec: BodySpec, curve: FramedSpline, layout: ChamberLayout) -> Solid:
    """The body S(q) (``sections``, on the curve it was sampled from) with its chambers and feeds cut out.

    The expected volume offset is the end cuts' less :func:`cavity_volume_mm3`.

    Raises
    ------
    MeshError
        A fold, or a mesh manifold3d refuses (naming q and the cavity).
    """
    label = f"q={sections.q:.3f}"
    outer = sweep_from_sections(sections, spec.offset_mm, spec.min_radius_mm)
    body, added = cut_body(outer, spec, label)
    cavities = cavity_sweeps(curve, sections.q, layout, sections.l, feed_extension_mm(spec, layout))
    solid = carve_cavities(body, cavities, outer.max_rho_kappa, label)
    return replace(solid, volume_offset_mm3=added - cavity_volume_mm3(curve, layout))


def measured_skin_walls(sections: TubeSections, spec: BodySpec, curve: FramedSpline, layout: ChamberLayout
                        ) -> list[tuple[str, float, int, int, float]]:
    """The thinnest skin over each chamber and over each feed as meshed at this q: the true distance from the
    vertices of its tube to the body's outer mesh, mm.

    Returns (kind, thickness_mm, section, chamber, l) with kind ``chamber-skin (mesh)`` (to the whole outer
    mesh: a chamber's end walls count, cut on a slant or not), ``feed-skin (mesh)`` (to the side wall only:
    a feed opens through the base face) or ``channel-skin (mesh)`` (a series channel's, every ring whole).
    Along a tube the skin's nearest point faces away from the backbone, so the outer half of each ring is
    measured, and the end rings whole.  A check of the exported geometry itself beside the in-section figures
    of :mod:`~softdesign.meshing.chambers.walls`: the tubes' polygons are area-matched, so a vertex lies up to
    ``r (sqrt(2 pi / (n sin(2 pi / n))) - 1)`` outside the design circle (0.3 % of r at 32 sides) and the figure
    errs low by that much.
    """
    from softdesign.meshing.compare import squared_distances
    from softdesign.meshing.tessellate import ring_points

    outer = sweep_from_sections(sections, spec.offset_mm, spec.min_radius_mm)
    body, _ = cut_body(outer, spec, f"q={sections.q:.3f}")
    targets = {"chamber": body.faces, "feed": body.faces[body.regions == Region.WALL], "channel": body.faces}
    picked: dict[str, list[tuple[Cavity, FloatArray, FloatArray]]] = {"chamber": [], "feed": [], "channel": []}
    for cavity in cavity_sweeps(curve, sections.q, layout, sections.l, 0.0):
        sweep = cavity.sweep
        centre = sweep.xy[0].mean(axis=0)
        half = (sweep.xy[0] - centre) @ centre >= -1e-12
        if cavity.kind == "channel":  # its centre moves round the axis: every ring whole
            half = np.ones(len(half), bool)
        rings = ring_points(sweep)
        points = np.concatenate([rings[1:-1, half].reshape(-1, 3), rings[[0, -1]].reshape(-1, 3)])
        owner = np.concatenate([np.repeat(sweep.l[1:-1], half.sum()), np.repeat(sweep.l[[0, -1]], rings.shape[1])])
        picked[cavity.kind].append((cavity, points, owner))
    out = []
    for kind, tubes in picked.items():
        if not tubes:
            continue
        gaps = np.sqrt(squared_distances(np.concatenate([p for _, p, _ in tubes]), body.vertices, targets[kind]))
        start = 0  # one locator for every tube of the kind
        for cavity, points, l in tubes:
            gap = gaps[start:start + len(points)]
            start += len(points)
            i = int(np.argmin(gap))
            out.append((f"{kind}-skin (mesh)", float(gap[i]), cavity.section, cavity.chamber, float(l[i])))
    return out
