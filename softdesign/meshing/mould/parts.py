"""A two-part casting mould (and a core for a hollow body) around the body at q = 0, with manifold3d.

Built in the mould frame of :mod:`softdesign.meshing.mould.frame` (z the
parting plane's normal), then mapped back to the body's coordinates:

    box      the body's bounding box grown by ``margin_mm`` on every side
    halves   A = box above z = 0 plus the key bumps, B = box below minus the
             key sockets (``clearance_mm`` wider and deeper than the bumps);
             both minus the body, the core and the pour and vent channels
    keys     four cylinders of diameter ``key_mm`` across the parting plane
             (half in A's material, half protruding into B's socket), at a
             fifth and four fifths of the body's length, ``margin_mm / 2``
             beside its bounding box: off the cavity, so both halves stay
             single bodies
    core     for a hollow body: the chamber and the port channel, continued
             along the base tangent through the box and ``print_mm`` beyond
             (the core print: it lies across the parting plane, so each half
             holds half of it and the two locate it)
    channels pour and vent, cylinders along the stated up direction in the
             parting plane from the cavity's highest points to the box's top
Casting orientation: ``up: base`` stands the mould with the base end up, up
along -T at the base (the core print on top, the core hanging from it, the
channels parallel to it), ``up: tip`` along T at the tip; each in the parting
plane.
"""

from __future__ import annotations

from dataclasses import dataclass

import manifold3d as m3
import numpy as np
import numpy.typing as npt

from softdesign.errors import InputDataError, MeshError
from softdesign.meshing.mould.frame import PartingFrame
from softdesign.meshing.mould.spec import MIN_MOULD_WALL_MM, MouldSpec
from softdesign.meshing.solids import PORT_INSIDE_WALLS, checked
from softdesign.types import FloatArray

#: Where along the body's length (fractions) the keys sit, two on each side.
KEY_STATIONS = (0.2, 0.8)
#: How far channels and sockets reach past a surface they open through, mm (no coplanar faces).
OVERSHOOT_MM = 1.0
#: How far pour and vent reach into the cavity from its top, mm (an overlap, not a shared face; well
#: inside the thinnest wall a hollow body may have, so they stay off its core).
CHANNEL_DEPTH_MM = 0.05
#: Slice points within this height of the highest one count as the top of the cavity, mm.
PEAK_TOL_MM = 1e-3


__all__ = ["MIN_MOULD_WALL_MM", "Core", "MouldParts", "MouldRefused", "MouldSpec", "build_mould", "inside_mm"]


class MouldRefused(InputDataError):
    """The body cannot be moulded as asked (undercut, no opening for a core, no room for a key): exit 2."""


@dataclass(frozen=True)
class Core:
    """The chamber's core for a hollow body, as world-frame geometry.

    chamber : manifold3d Manifold of the chamber (closed)
    base, axis : (3,) float, the port's entry point (body base centre) and direction (base tangent)
    port_radius_mm, inside_mm : the port channel's radius and how far it runs past the base cap into the chamber
    wall_mm : the base cap's thickness
    """

    chamber: m3.Manifold
    base: FloatArray
    axis: FloatArray
    port_radius_mm: float
    inside_mm: float
    wall_mm: float
    segments: int


@dataclass(frozen=True)
class MouldParts:
    """The parts in the mould frame with what the checks need.

    half_a, half_b, core : Manifolds (core None for a solid body)
    box, body, casting : the box, the outer body and the cast part (the export's solid)
    channels : pour and vent; bumps, sockets : the keys
    pour_at, vent_at : (3,) float, mould-frame points where the channels meet the cavity
    up : (3,) float, mould-frame up direction of the stated casting orientation
    """

    half_a: m3.Manifold
    half_b: m3.Manifold
    core: m3.Manifold | None
    box: m3.Manifold
    body: m3.Manifold
    casting: m3.Manifold
    channels: m3.Manifold
    bumps: m3.Manifold
    sockets: m3.Manifold
    pour_at: FloatArray
    vent_at: FloatArray
    up: FloatArray


def _cylinder(start: FloatArray, direction: FloatArray, length: float, radius: float, segments: int) -> m3.Manifold:
    """A cylinder from ``start`` along unit ``direction`` (mould frame)."""
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    helper = np.array([1.0, 0.0, 0.0]) if abs(d[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(d, helper)
    u /= np.linalg.norm(u)
    pose = np.column_stack([u, np.cross(d, u), d, start])
    return m3.Manifold.cylinder(length, radius, radius, segments, False).transform(pose)


def _union(parts: list[m3.Manifold]) -> m3.Manifold:
    return m3.Manifold.batch_boolean(parts, m3.OpType.Add) if parts else m3.Manifold()


def _box(body: m3.Manifold, margin: float) -> tuple[m3.Manifold, FloatArray, FloatArray]:
    lo, hi = (np.asarray(v, float) for v in np.reshape(body.bounding_box(), (2, 3)))
    return m3.Manifold.cube(tuple(hi - lo + 2 * margin)).translate(tuple(lo - margin)).as_original(), lo, hi


def _keys(lo: FloatArray, hi: FloatArray, spec: MouldSpec) -> tuple[m3.Manifold, m3.Manifold]:
    """Bumps (A's material across the plane into B) and their sockets (cut from B), clearance on every side."""
    r, c = 0.5 * spec.key_mm, spec.clearance_mm
    if r + c + MIN_MOULD_WALL_MM > 0.5 * spec.margin_mm:
        raise MouldRefused(
            f"export.mould: a key of diameter key_mm={spec.key_mm:g} mm with clearance_mm={c:g} mm needs "
            f"margin_mm >= {2 * (r + c + MIN_MOULD_WALL_MM):g} mm (keys sit margin_mm / 2 beside the body, "
            f"{MIN_MOULD_WALL_MM:g} mm of mould between socket and cavity), got {spec.margin_mm:g}; raise margin_mm "
            "or lower key_mm"
        )
    bumps, sockets = [], []
    for f in KEY_STATIONS:
        x = lo[0] + f * (hi[0] - lo[0])
        for y in (lo[1] - 0.5 * spec.margin_mm, hi[1] + 0.5 * spec.margin_mm):
            bumps.append(_cylinder(np.array([x, y, -r]), np.array([0.0, 0.0, 1.0]), 2 * r, r, spec.segments))
            sockets.append(_cylinder(np.array([x, y, -(r + c)]), np.array([0.0, 0.0, 1.0]), r + c + OVERSHOOT_MM,
                                     r + c, spec.segments))
    return _union(bumps), _union(sockets)


def _exit_distance(start: FloatArray, direction: FloatArray, box_lo: FloatArray, box_hi: FloatArray) -> float:
    """How far from ``start`` (inside the box) along ``direction`` the box's surface is, mm."""
    with np.errstate(divide="ignore"):
        far = np.where(direction > 0, (box_hi - start) / direction,
                       np.where(direction < 0, (box_lo - start) / direction, np.inf))
    return float(np.min(far))


def _core(core: Core, frame: PartingFrame, box_lo: FloatArray, box_hi: FloatArray, spec: MouldSpec) -> m3.Manifold:
    """Chamber plus the port continued out through the box and ``print_mm`` beyond, mould frame."""
    chamber = core.chamber.transform(frame.frame_from_world())
    base, axis = frame.to_frame(core.base), frame.direction_to_frame(core.axis)
    end = base + (core.wall_mm + core.inside_mm) * axis  # where the solid's port ends, inside the chamber
    length = core.wall_mm + core.inside_mm + _exit_distance(base, -axis, box_lo, box_hi) + spec.print_mm
    return checked(chamber + _cylinder(end, -axis, length, core.port_radius_mm, core.segments), "mould core")


def _slice_points(body: m3.Manifold) -> FloatArray:
    """Vertices of the body's section by the parting plane z = 0, (k, 2) mm."""
    polygons = body.slice(0.0).to_polygons()
    points = [np.asarray(p, float) for p in polygons if len(p)]
    if not points:
        raise MeshError("mould: the parting plane does not cut the body; this is a bug, please report it")
    return np.concatenate(points)


def _channel_points(body: m3.Manifold, up: FloatArray, spec: MouldSpec,
                    print_lines: tuple[tuple[FloatArray, FloatArray, float], ...] = ()
                    ) -> tuple[FloatArray, FloatArray]:
    """Vent at the parting line's highest point; pour at the highest point far enough from the vent.

    ``print_lines`` (each a point and unit direction in the parting plane, and a radius, mm): a core print or a
    thread's hole running up beside the channels; a channel is kept off each (the build still checks that none
    meets the core).
    A square end's face is level, so its highest points include its rim; a cut end's face leans, and the
    highest point far enough from the vent is next to the print, on the face's middle.
    """
    pts = _slice_points(body)
    height = pts @ up[:2]
    across = np.array([-up[1], up[0]])

    def clear(radius: float) -> npt.NDArray[np.bool_]:
        ok = np.ones(len(pts), bool)
        for point, direction, print_radius in print_lines:
            off = pts - point
            distance = np.abs(off[:, 0] * direction[1] - off[:, 1] * direction[0])
            ok &= distance >= radius + print_radius
        return ok

    vent_ok, pour_ok = clear(0.5 * spec.vent_mm), clear(0.5 * spec.pour_mm)
    if not np.any(vent_ok):
        raise MouldRefused(
            f"export.mould: the vent (vent_mm={spec.vent_mm:g}) must run beside the core print, and the body's top "
            "end is narrower; lower vent_mm or cast the other end up (up: tip or base)"
        )
    vent = pts[vent_ok][int(np.argmax(height[vent_ok]))]
    apart = 0.5 * (spec.pour_mm + spec.vent_mm) + MIN_MOULD_WALL_MM
    far = (np.abs((pts - vent) @ across) >= apart) & pour_ok
    if not np.any(far):
        raise MouldRefused(
            f"export.mould: the pour channel (pour_mm={spec.pour_mm:g}) and the vent (vent_mm={spec.vent_mm:g}) "
            f"need {apart:g} mm between their axes on the parting line (each beside a core print), and the body is "
            "narrower; lower them"
        )
    # the highest of them; among equally high ones (a flat end face) the one farthest from the vent
    top = far & (height >= np.max(height[far]) - PEAK_TOL_MM)
    pour = pts[top][int(np.argmax(np.abs((pts[top] - vent) @ across)))]
    return np.append(pour, 0.0), np.append(vent, 0.0)


def _channel(at: FloatArray, up: FloatArray, radius: float, top: float, spec: MouldSpec) -> m3.Manifold:
    """A channel centred on the parting line's point ``at``, from ``CHANNEL_DEPTH_MM`` inside the cavity up through
    the box's top face (half of it beside the cavity's edge: a nub trimmed off with the sprue)."""
    start = at - CHANNEL_DEPTH_MM * up
    return _cylinder(start, up, float(top - start @ up) + OVERSHOOT_MM, radius, spec.segments)


def build_mould(body: m3.Manifold, casting: m3.Manifold, core: Core | None, frame: PartingFrame,
                spec: MouldSpec, up_world: FloatArray | None = None,
                keep_off: tuple[tuple[FloatArray, FloatArray, float], ...] = ()) -> MouldParts:
    """The mould's parts in the mould frame (see the module docstring).

    Parameters
    ----------
    body : the outer body (world), whose outside the halves take
    casting : the export's solid at q = 0 (world): the part the mould must leave
    core : the chamber and port of a hollow body, None for a solid one
    frame, spec : the parting frame and the case's mould keys
    up_world : (3,) float, the casting's up direction (its part in the parting plane is used); default the
        frame's -x (``spec.up == "base"``) or +x
    keep_off : lines the pour and vent keep off (world point, unit direction, radius mm): an axis thread's
        holes, the prints of an actuated body's cores
    """
    to_frame = frame.frame_from_world()
    body_f, casting_f = body.transform(to_frame), casting.transform(to_frame)
    box, lo, hi = _box(body_f, spec.margin_mm)
    up = np.array([-1.0, 0.0, 0.0]) if spec.up == "base" else np.array([1.0, 0.0, 0.0])
    if up_world is not None:
        up = frame.direction_to_frame(up_world) * np.array([1.0, 1.0, 0.0])
        up /= np.linalg.norm(up)
    box_lo, box_hi = lo - spec.margin_mm, hi + spec.margin_mm
    corners = np.array([[x, y, z] for x in (box_lo[0], box_hi[0]) for y in (box_lo[1], box_hi[1])
                        for z in (box_lo[2], box_hi[2])])
    top = float(np.max(corners @ up))
    core_f = None if core is None else _core(core, frame, box_lo, box_hi, spec).as_original()
    lines = []
    if core is not None:
        base, axis = frame.to_frame(core.base), frame.direction_to_frame(core.axis)
        if -axis @ up > 0:  # the core print runs up, beside the channels: keep them off it
            lines.append((base[:2], -axis[:2] / np.linalg.norm(axis[:2]), core.port_radius_mm))
    for point, direction, radius in keep_off:
        along = frame.direction_to_frame(direction)[:2]
        if np.linalg.norm(along) > 0.5:  # in (near) the parting plane: it runs beside the channels
            lines.append((frame.to_frame(point)[:2], along / np.linalg.norm(along), radius))
    pour_at, vent_at = _channel_points(body_f, up, spec, tuple(lines))
    channels = _union([_channel(pour_at, up, 0.5 * spec.pour_mm, top, spec),
                       _channel(vent_at, up, 0.5 * spec.vent_mm, top, spec)]).as_original()
    if core_f is not None and (channels ^ core_f).volume() > 0:
        raise MouldRefused(
            f"export.mould: the pour (pour_mm={spec.pour_mm:g}) or vent (vent_mm={spec.vent_mm:g}) channel meets the "
            "core print at the cavity's top; lower pour_mm and vent_mm or cast the other end up (up: tip or base)"
        )
    bumps, sockets = (k.as_original() for k in _keys(lo, hi, spec))
    voids = _union([body_f, channels] + ([core_f] if core_f is not None else []))
    half_a = checked((box.trim_by_plane((0.0, 0.0, 1.0), 0.0) + bumps) - voids, "mould half A")
    half_b = checked(box.trim_by_plane((0.0, 0.0, -1.0), 0.0) - sockets - voids, "mould half B")
    return MouldParts(half_a, half_b, core_f, box, body_f, casting_f, channels, bumps, sockets, pour_at, vent_at, up)


def inside_mm(wall_mm: float, chamber_length_mm: float) -> float:
    """How far the solid's port runs into the chamber (:func:`softdesign.meshing.solids._port`'s rule)."""
    return min(PORT_INSIDE_WALLS * wall_mm, 0.25 * chamber_length_mm)
