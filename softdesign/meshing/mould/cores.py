"""The mould of an actuated body: the two halves, a core plate at the base, one core per chamber and feed.

Parts (built on :func:`softdesign.meshing.mould.parts.build_mould`'s halves of the
outer body, then split and cored):

    cores    one per chamber: the chamber's tube united with its feed's, the
             feed continued straight along the base tangent out of the body,
             through the plate, and ``print_mm`` beyond (the core print)
    plate    the halves' material beyond the base plane (the plane normal to the
             base tangent through the body's outermost base point), one piece:
             it holds every core print in its hole, the way the two halves hold a
             single core's print on the parting plane; 3n prints around the axis
             cannot all lie on the parting plane
    halves   the rest of the two halves, minus the cores
    single   a single supply's chambers, joined in series by their channels,
             are one lost core (the supply line's print in the plate): wax,
             :data:`LOST_CORE_NOTE` says why
    thread   with an axis thread (``backbone: inextensible``) on a straight
             q = 0 body, a hole on the axis through each end of the mould
             (the plate at the base, the halves at the tip) to tension it
Demoulding (each step checked as the round-2 mould is, :func:`pull_check`):
    1. plate and cores together along the base tangent, out of the body: the
       plate and the prints (the cores outside the body) are checked against
       the halves; inside the cast part each pin passes its feed by stretching
       it (a core is as wide as its chamber, its feed narrower:
       ``stretch_to_release``, as round 2's single core passes its port); only
       when the q = 0 body is straight (straight pins).  Otherwise the cores
       are lost cores (wax or a dissolvable print), the build says so, and the
       plate is pulled alone after dissolving them;
    2. each half along the parting plane's normal, the cast part and the other
       half staying behind.
The pour and vent channels start ``CHANNEL_DEPTH_MM`` inside the cavity at its
edge (round 2's rule); the plate holds half of that nub from below, so the
sprue is trimmed before step 1 (those faces are counted, not refused).
The cavity check counts the plate and cores with the halves: box less every
part equals the cast part within ``CAVITY_RTOL``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import Any

import manifold3d as m3
import numpy as np

from softdesign.meshing.chambers.carve import Cavity, build_actuated, cavity_sweeps
from softdesign.meshing.chambers.layout import ChamberLayout
from softdesign.meshing.mould.checks import (
    CAVITY_RTOL,
    DISJOINT_RTOL,
    cavity_figures,
    facet_tolerance,
    part_figures,
    pull_check,
    shared_volume,
)
from softdesign.meshing.mould.frame import PartingFrame, parting_frame
from softdesign.meshing.mould.make import Mould, checks_passed, meshes_in_world
from softdesign.meshing.mould.parts import MouldParts, MouldRefused, MouldSpec, _cylinder, build_mould
from softdesign.meshing.solids import checked, cut_body, manifold_from_mesh
from softdesign.meshing.tessellate import Region, Sweep, TubeMesh, TubeSections, sweep_from_sections, tessellate
from softdesign.meshing.volume import BodySpec
from softdesign.types import FloatArray

#: A base face whose points lie within this of one plane normal to T(0) is square (not cut on a slant), mm.
SQUARE_TOL_MM = 1e-9
#: The axis thread's holes are this much wider than the thread, mm (it slides through under tension; the silicone,
#: thick when poured, does not run out through 0.05 mm round a thread: a rule of thumb, stated as such).
THREAD_HOLE_CLEARANCE_MM = 0.1
#: How far inside the body's end faces a thread hole starts, mm (it overlaps the cavity: no coplanar faces).
THREAD_HOLE_INSIDE_MM = 0.5
#: A single supply's lost core: what it is made of, and why.
LOST_CORE_MATERIAL = "wax"
LOST_CORE_NOTE = (
    "the chambers are joined in series by slanted channels, so no rigid pin can be drawn out of them: make the one "
    "core (the supply line, every chamber and channel) in wax (a jewellery casting or carving wax, printed on a wax "
    "printer or cast in a printed two-part mould of the core file), wind each chamber's hoop thread on it, seat its "
    "print in the core plate; after curing melt the wax at 70-90 C and blow it out through the supply port. Wax "
    "rather than a water-soluble print (PVA, BVOH): it leaves the whole series path as a liquid through the one "
    "port, where a solvent would have to reach every chamber through channels of a few tenths of a mm, and the "
    "platinum-cure silicones of the presets cure against it")


def _cores(curve, sections: TubeSections, layout: ChamberLayout, reach_mm: float) -> list[tuple[str, m3.Manifold]]:
    """(name, chamber united with its feed) per chamber, world frame; feeds start ``reach_mm`` before the base.

    A single supply's chambers, joined by their series channels, are one core (``core``): the supply line, every
    chamber and every channel united."""
    cavities = cavity_sweeps(curve, 0.0, layout, sections.l, reach_mm)
    if layout.channels:
        tubes = [manifold_from_mesh(*_mesh(c), f"mould core: section {c.section + 1} {c.kind}")[0] for c in cavities]
        return [("core", checked(m3.Manifold.batch_boolean(tubes, m3.OpType.Add), "mould core"))]
    by_chamber: dict[tuple[int, int], list[Cavity]] = {}
    for cavity in cavities:
        by_chamber.setdefault((cavity.section, cavity.chamber), []).append(cavity)
    out = []
    for (i, j), pair in sorted(by_chamber.items()):
        name = f"core_{i + 1}_{j + 1}"
        tubes = [manifold_from_mesh(*_mesh(c), f"mould {name}")[0] for c in pair]
        out.append((name, checked(m3.Manifold.batch_boolean(tubes, m3.OpType.Add), f"mould {name}")))
    return out


def _mesh(cavity: Cavity) -> tuple[FloatArray, np.ndarray]:
    mesh = tessellate(cavity.sweep)
    return mesh.vertices, mesh.faces


def _plate_plane(body_mesh: TubeMesh, base: FloatArray, outward: FloatArray) -> float:
    """Offset along ``outward`` of the plane through the base face's innermost point: beyond it no half holds a
    pin (a cut base face leans; the plate then takes the wedge between the face and the plane)."""
    cap = np.unique(body_mesh.faces[body_mesh.regions == Region.BASE_CAP])
    return float(np.min((body_mesh.vertices[cap] - base) @ outward))


def _base_prism(outer: Sweep, length_mm: float) -> m3.Manifold:
    """The body's base section extruded ``length_mm`` out of the body along -T(0), world frame (its inner ring is
    the body's own first ring, bit for bit, so it joins the body's square base face without a seam)."""
    frame, centre = outer.frames[0], outer.centers[0]
    prism = Sweep(outer.q, np.zeros(2), np.array([-length_mm, 0.0]),
                  np.stack([centre - length_mm * frame[:, 2], centre]), np.stack([frame, frame]),
                  np.stack([outer.xy[0], outer.xy[0]]))
    mesh = tessellate(prism)
    return manifold_from_mesh(mesh.vertices, mesh.faces, "mould: base prism")[0]


def _split(parts: MouldParts, frame: PartingFrame, plane: tuple[FloatArray, float], cores: m3.Manifold,
           prism: m3.Manifold | None) -> tuple[m3.Manifold, m3.Manifold, m3.Manifold]:
    """Halves A and B up to the base plane, and the plate beyond it (mould frame), each less body, channels, cores.

    The box is cut first and the body subtracted after, as round 2 cuts the box at the parting plane.  A square
    base face lies on the plane: the halves then lose the body extended through it (``prism``), and the plate
    the channels and cores only (it meets the body on the plane), so no face of a difference is coplanar.
    """
    n, offset = plane
    inner, outer = parts.box.trim_by_plane(tuple(-n), -offset), parts.box.trim_by_plane(tuple(n), offset)
    body = parts.body if prism is None else parts.body + prism
    voids = body + parts.channels + cores
    half_a = (inner.trim_by_plane((0.0, 0.0, 1.0), 0.0) + parts.bumps) - voids
    half_b = inner.trim_by_plane((0.0, 0.0, -1.0), 0.0) - parts.sockets - voids
    plate = outer - (parts.channels + cores if prism is not None else voids)
    return (checked(half_a, "mould half A"), checked(half_b, "mould half B"), checked(plate, "mould core plate"))


def _thread_holes(outer: Sweep, frame: PartingFrame, hole_mm: float, box_size: float, segments: int
                  ) -> m3.Manifold:
    """The axis thread's two holes (mould frame): from ``THREAD_HOLE_INSIDE_MM`` inside the body's base and tip
    faces, on the axis, out along -T(0) and T(1) through the box (the thread is tensioned through them)."""
    holes = []
    for at, outward in ((0, -outer.frames[0][:, 2]), (-1, outer.frames[-1][:, 2])):
        start = frame.to_frame(outer.centers[at] - THREAD_HOLE_INSIDE_MM * outward)
        holes.append(_cylinder(start, frame.direction_to_frame(outward), box_size + THREAD_HOLE_INSIDE_MM,
                               0.5 * hole_mm, segments))
    return checked(m3.Manifold.batch_boolean(holes, m3.OpType.Add), "mould: the axis thread's holes")


def make_actuated_mould(sections: TubeSections, body_spec: BodySpec, spec: MouldSpec, curve,
                        layout: ChamberLayout, link_of: Callable[[FloatArray], Any],
                        thread_mm: float | None = None) -> Mould:
    """The checked mould of the actuated body at q = 0 (see the module docstring).

    ``thread_mm``: the diameter of the axis thread (``backbone: inextensible``), None without one: holes of
    ``thread_mm + THREAD_HOLE_CLEARANCE_MM`` on the axis through both ends of the mould (a straight q = 0 body
    only: a curved axis cannot hold a tensioned thread, and the core figures say so).

    Raises
    ------
    MouldRefused
        A part that does not pull free (naming it), or a plate that would not hold together.
    MeshError
        A check construction should guarantee failed (a bug).
    """
    outer = sweep_from_sections(sections, body_spec.offset_mm, body_spec.min_radius_mm)
    body_mesh, _ = cut_body(outer, body_spec, "mould: body")
    body, _ = manifold_from_mesh(body_mesh.vertices, body_mesh.faces, "mould: body")
    solid = build_actuated(sections, body_spec, curve, layout)
    casting, _ = manifold_from_mesh(solid.vertices, solid.faces, "mould: cast part")
    frame = parting_frame(sections.centers, sections.frames[0])
    up = -sections.frames[0][:, 2] if spec.up == "base" else sections.frames[-1][:, 2]
    held = thread_mm is not None and frame.straight
    hole_mm = (thread_mm or 0.0) + THREAD_HOLE_CLEARANCE_MM
    keep_off = ((outer.centers[0], outer.frames[0][:, 2], 0.5 * hole_mm),) if held else ()
    parts = build_mould(body, casting, None, frame, spec, up, keep_off)
    base, outward = outer.centers[0], -outer.frames[0][:, 2]
    at = _plate_plane(body_mesh, base, outward)
    box_size = float(np.linalg.norm(np.subtract(*np.reshape(parts.box.bounding_box(), (2, 3)))))
    if held:  # the holes join the pour and vent: voids of every part that are not the cast body
        holes = _thread_holes(outer, frame, hole_mm, box_size, spec.segments)
        parts = replace(parts, channels=checked(parts.channels + holes, "mould: channels and thread holes"
                                                ).as_original())
    cores = [(name, core.transform(frame.frame_from_world()).as_original())
             for name, core in _cores(curve, sections, layout, at + box_size + spec.print_mm)]
    all_cores = m3.Manifold.batch_boolean([c for _, c in cores], m3.OpType.Add)
    n = frame.direction_to_frame(outward)
    square = -_plate_plane(body_mesh, base, -outward) - at <= SQUARE_TOL_MM  # the base face lies on the plane
    prism = _base_prism(outer, box_size).transform(frame.frame_from_world()) if square else None
    half_a, half_b, plate = _split(parts, frame, (n, float(frame.to_frame(base) @ n + at)), all_cores, prism)
    lost = bool(layout.channels) or not frame.straight
    figures = _check(parts, half_a, half_b, plate, cores, frame, frame.direction_to_frame(outward),
                     facet_tolerance(outer.xy.shape[1]), lost)
    figures["core"] = _core_note(frame, layout, cores)
    figures["thread"] = _thread_note(thread_mm, hole_mm, frame.straight)
    named = [("half_a", half_a), ("half_b", half_b), ("core_plate", plate), *cores]
    return Mould(meshes_in_world(named, frame), figures)


def _thread_note(thread_mm: float | None, hole_mm: float, straight: bool) -> dict[str, Any] | None:
    """How the axis thread is held in the mould (None without ``backbone: inextensible``)."""
    if thread_mm is None:
        return None
    if not straight:
        return {"diameter_mm": thread_mm, "hole_mm": None,
                "note": "the body is not straight at q = 0: a tensioned thread cannot follow its curved axis; no "
                        "thread holes (cast it straight, initial.kind: straight, or lay the thread in by hand)"}
    return {"diameter_mm": thread_mm, "hole_mm": hole_mm,
            "note": f"thread the {thread_mm:.2f} mm axis thread through the {hole_mm:.2f} mm holes on the axis at "
                    "both ends of the mould (core plate and halves' tip end; drill them to size, a printed hole that "
                    "small closes up), tension it by hand and tape it outside before pouring; cut it flush with the "
                    "base and tip faces after demoulding"}


def _core_note(frame: PartingFrame, layout: ChamberLayout, cores: list[tuple[str, m3.Manifold]]) -> dict[str, Any]:
    count = len(cores)
    stretch = layout.spec.diameter_mm / layout.spec.feed_diameter_mm
    if layout.channels:
        widest = max(float(np.max(np.asarray(c.profile)[:, 2])) if c.profile else c.diameter_mm
                     for c in layout.chambers)
        return {"process": "lost-core", "note": LOST_CORE_NOTE, "cores": 1, "material": LOST_CORE_MATERIAL,
                "stretch_to_release": None, "chamber_diameter_mm": widest,
                "feed_diameter_mm": layout.spec.feed_diameter_mm, "volume_mm3": float(cores[0][1].volume())}
    if frame.straight:
        process, note = "removable", (
            f"the body is straight at q = 0: the {count} cores are straight pins held in the core plate; pull the "
            "plate and pins together along the base tangent first (each feed stretches "
            f"{stretch:.2f}x over its chamber's pin), then open the halves")
    else:
        process, note = "lost-core", (
            f"the body is not straight at q = 0: a rigid pin cannot be drawn out of a curved chamber; cast the {count} "
            "cores in wax or a dissolvable material (lost cores), melt or dissolve them out through the feeds, then "
            "pull the core plate and open the halves")
    return {"process": process, "note": note, "cores": count, "stretch_to_release": stretch,
            "chamber_diameter_mm": layout.spec.diameter_mm, "feed_diameter_mm": layout.spec.feed_diameter_mm}


def _check(parts: MouldParts, half_a: m3.Manifold, half_b: m3.Manifold, plate: m3.Manifold,
           cores: list[tuple[str, m3.Manifold]], frame: PartingFrame, outward: FloatArray, facet_tol: float,
           lost: bool) -> dict[str, Any]:
    """The round-2 checks with the plate and cores: parts, disjoint, cavity, and the two pulls.

    The pulls come first: a part that does not pull free is refused (MouldRefused) before the seconds of the
    cavity's figures (6.2 of 8.9 s of the mould at 512 angles), which cannot change that verdict."""
    pins = m3.Manifold.batch_boolean([c for _, c in cores], m3.OpType.Add)
    # inside the cast part a pin passes its narrower feed by stretching it (figures["core"]); the plate slides off
    # the halves, and the pins are prisms along the pull
    pulls = _pulls(parts, half_a, half_b, plate, pins, frame, outward, facet_tol, lost)
    solids = {"half_a": half_a, "half_b": half_b, "core_plate": plate, **dict(cores)}
    figures: dict[str, Any] = {"parts": {k: part_figures(v) for k, v in solids.items()}}
    # the plate holds 3n prints and the channels: one body, its genus is its holes (not 0 as a half's)
    figures["parts"]["core_plate"]["ok"] = figures["parts"]["core_plate"]["bodies"] == 1
    body_volume = float(parts.casting.volume())
    names = list(solids)
    shared = {f"{a}/{b}": shared_volume(solids[a], solids[b]) for i, a in enumerate(names) for b in names[i + 1:]
              if not (a.startswith("core_") and b.startswith("core_") and a != "core_plate" and b != "core_plate")}
    figures["disjoint"] = {"shared_mm3": max(shared.values()), "pairs": len(shared),
                           "tolerance_mm3": DISJOINT_RTOL * body_volume,
                           "ok": all(v <= DISJOINT_RTOL * body_volume for v in shared.values())}
    figures["cavity"] = {**cavity_figures(half_a, half_b, plate + pins, parts.box, parts.body, parts.casting,
                                          parts.channels, parts.bumps, parts.sockets), "tolerance": CAVITY_RTOL}
    figures["pull"] = pulls
    checks_passed(figures, frame)
    return figures


def _name(source: int, face: int) -> str:
    return "a cavity face"


#: A straight pin's side faces may lean off the pull by the polygon's own facets only (numerical zero).
PIN_SIDE_TOL = 1e-6


def _pin_lean(pins: m3.Manifold, pull: FloatArray) -> float:
    """The largest |normal . pull| over the pins' side faces (caps and shoulders, |component| > 0.5, excluded)."""
    mesh = pins.to_mesh64()
    vertices = np.asarray(mesh.vert_properties, float)[:, :3]
    tri = vertices[np.asarray(mesh.tri_verts, np.int64)]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area = np.linalg.norm(normal, axis=1)
    component = np.abs(normal[area > 0] @ pull) / area[area > 0]
    side = component < 0.5
    return float(component[side].max(initial=0.0))


def _pulls(parts: MouldParts, half_a: m3.Manifold, half_b: m3.Manifold, plate: m3.Manifold, pins: m3.Manifold,
           frame: PartingFrame, outward: FloatArray, facet_tol: float, lost: bool) -> dict[str, Any]:
    """Step 1 (straight body): the plate along the base tangent, the halves staying; the pins' sides parallel to
    it (not for lost cores: they are melted out first, and the plate comes off their prints' holes alone).
    Step 2: each half along the parting plane's normal, the cast part and the other half staying."""
    pulls: dict[str, Any] = {}
    box_id = parts.box.original_id()
    if frame.straight:
        channel_id = parts.channels.original_id()
        result, failures = pull_check(plate, outward, half_a + half_b, box_id,
                                      lambda source, face: "sprue" if source == channel_id else "plate", facet_tol)
        # a channel starts CHANNEL_DEPTH_MM inside the cavity at its edge (round 2's rule): the plate holds the
        # half of that nub outside the cavity from below; it is trimmed off with the sprue before the plate is pulled
        sprue = [f for f in failures if f.where == "sprue" and not f.blocked]
        failures = [f for f in failures if f not in sprue]
        result = {**result, "ok": not failures, "against_pull": result["against_pull"] - len(sprue),
                  "sprue_nub_faces": len(sprue)}
        lean = 0.0 if lost else _pin_lean(pins, outward)
        if failures or lean > PIN_SIDE_TOL:
            worst = max((f.component for f in failures), default=0.0)
            raise MouldRefused(f"export.mould: the core plate does not pull free along the base tangent "
                               f"({len(failures)} faces against the pull or blocked by a half, leaning up to "
                               f"{worst:.3g} where a facet may lean {facet_tol:.3g}, sin(pi / export.angular_count); "
                               f"pins' sides lean {lean:.2e} off it): a slanted base face leaves the plate a wedge "
                               "of the body's wall to slide off; use fit.end_cut: normal (a square base face, which "
                               "the plate meets on one plane), or fewer export.angular_count")
        pulls["core_plate"] = {**result, "pin_side_lean": lean, "pull": (frame.axes.T @ outward).tolist()}
    for half, solid, other, pull in (("A", half_a, half_b, np.array([0.0, 0.0, 1.0])),
                                     ("B", half_b, half_a, np.array([0.0, 0.0, -1.0]))):
        result, failures = pull_check(solid, pull, parts.casting + other, box_id, _name, facet_tol)
        if failures:
            raise MouldRefused(f"export.mould: half {half} does not pull off along the parting plane's normal once "
                               f"the cores are out ({len(failures)} faces against the pull or blocked)")
        pulls[f"half_{half.lower()}"] = {**result, "pull": (frame.axes.T @ pull).tolist()}
    return pulls
