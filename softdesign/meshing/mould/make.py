"""The mould of the body at q = 0: body and core from the export's own solids, the parts, their checks.

:func:`make_mould` joins :mod:`~softdesign.meshing.solids` (the body, its
chamber and port, exactly as the export builds them), the parting frame,
:func:`~softdesign.meshing.mould.parts.build_mould` and the checks of
:mod:`~softdesign.meshing.mould.checks`.  An undercut refuses the mould
(:class:`~softdesign.meshing.mould.parts.MouldRefused`, exit 2) naming the link, l
and angle of the body's faces that cause it; any other failed check is a bug
(MeshError).  Returns the parts as plain arrays in the body's coordinates.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from softdesign.errors import MeshError
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
from softdesign.meshing.mould.parts import Core, MouldParts, MouldRefused, MouldSpec, build_mould, inside_mm
from softdesign.meshing.solids import (
    build_solid,
    cut_body,
    cut_chamber,
    manifold_from_mesh,
    port_lean_mm,
    welded_as_written,
)
from softdesign.meshing.tessellate import Region, TubeSections, sweep_from_sections
from softdesign.meshing.volume import BodySpec
from softdesign.types import FloatArray, IntArray

#: At most this many faces are named in a refusal (the worst first).
NAMED_FACES = 5


@dataclass(frozen=True)
class MouldMesh:
    """One part in the body's coordinates: vertices (V, 3) mm, faces (F, 3) int64, outward."""

    name: str
    vertices: FloatArray
    faces: IntArray


@dataclass(frozen=True)
class Mould:
    """The parts (half_a, half_b and, for a hollow body, core) and every figure and check."""

    parts: tuple[MouldMesh, ...]
    figures: dict[str, Any] = field(default_factory=dict)


def _namer(sections: TubeSections, body_id: int, link_of: Callable[[FloatArray], IntArray], angular_count: int,
           regions: np.ndarray, features: dict[int, str]) -> Callable[[int, int], str]:
    """(source id, face id) -> where: link, l and angle of a body face, or the mould feature's name."""
    def name(source: int, face: int) -> str:
        if source != body_id:
            return features.get(source, "the parting face")
        if regions[face] != Region.WALL:
            return Region(int(regions[face])).name.lower().replace("_", " ")
        ring, k = divmod(face // 2, angular_count)
        l = float(sections.l[ring])
        return f"link {int(link_of(np.array([l]))[0])}, l={l:.4f}, angle {360.0 * k / angular_count:.0f} deg"
    return name


def _core(sections: TubeSections, spec: BodySpec) -> tuple[Core | None, dict[str, Any]]:
    if spec.wall_mm == 0:
        return None, {}
    if spec.port_mm == 0:
        raise MouldRefused("export.mould: a hollow body without a port (export.port_mm) has a sealed chamber, "
                           "which no core can form: the core needs an opening to be held and removed; "
                           "set export.port_mm")
    outer = sweep_from_sections(sections, spec.offset_mm, spec.min_radius_mm)
    # the chamber cut as the export's solid cuts it (its planes wall_mm inside the body's), the port as long
    chamber, cavity, _ = cut_chamber(sections, outer, spec, "mould core: chamber")
    manifold, _ = manifold_from_mesh(cavity.vertices, cavity.faces, "mould core: chamber")
    length = float(chamber.s[-1] - chamber.s[0])
    core = Core(manifold, outer.centers[0], outer.frames[0][:, 2], 0.5 * spec.port_mm,
                inside_mm(spec.wall_mm, length) + port_lean_mm(spec), spec.wall_mm,
                spec.port_segments or outer.xy.shape[1])
    widest = float(2.0 * np.max(np.linalg.norm(chamber.xy, axis=-1)))
    return core, {"chamber_length_mm": length, "chamber_widest_mm": widest,
                  "port_stretch_to_release": widest / spec.port_mm}


def _refuse_undercut(half: str, pull: FloatArray, frame: PartingFrame, failures: list, total: int) -> None:
    world = frame.axes.T @ pull
    worst: dict[str, Any] = {}
    for f in failures:  # worst first: keep each place's worst face
        worst.setdefault(f.where, f)
    named = "; ".join(f"{f.where} (normal {f.component:+.3f} along the pull{', ray blocked' if f.blocked else ''})"
                      for f in list(worst.values())[:NAMED_FACES])
    raise MouldRefused(
        f"export.mould: half {half} cannot be pulled off along {np.round(world, 4).tolist()} (the parting plane's "
        f"normal): {total} face(s) of the cavity face against the pull or lie under the body, worst first: {named}. "
        "The body has undercuts for this parting plane; change the q = 0 shape (initial:) or the body there"
    )


def make_mould(sections: TubeSections, body_spec: BodySpec, spec: MouldSpec,
               link_of: Callable[[FloatArray], IntArray]) -> Mould:
    """The mould of the body on ``sections`` (q = 0), checked.

    Parameters
    ----------
    sections : the body at q = 0 on its (l, a) grid (the export's grid)
    body_spec : the export's solid (offset, wall, port, end cuts)
    spec : the mould keys
    link_of : normalized l -> link index, for the messages

    Raises
    ------
    MouldRefused
        An undercut (naming link, l, angle), no port on a hollow body, no room for keys or channels.
    MeshError
        A check failed that construction should guarantee (a bug).
    """
    outer = sweep_from_sections(sections, body_spec.offset_mm, body_spec.min_radius_mm)
    # the body's ends cut as the export's solid's are (same faces and regions, moved vertices)
    body_mesh, _ = cut_body(outer, body_spec, "mould: body")
    body, body_id = manifold_from_mesh(body_mesh.vertices, body_mesh.faces, "mould: body")
    solid = build_solid(sections, body_spec)
    casting, _ = manifold_from_mesh(solid.vertices, solid.faces, "mould: cast part")
    core, core_figures = _core(sections, body_spec)
    frame = parting_frame(sections.centers, sections.frames[0])
    up = -sections.frames[0][:, 2] if spec.up == "base" else sections.frames[-1][:, 2]
    parts = build_mould(body, casting, core, frame, spec, up)
    features = {parts.channels.original_id(): "the pour or vent channel", parts.bumps.original_id(): "a key bump",
                parts.sockets.original_id(): "a key socket"}
    if parts.core is not None:
        features[parts.core.original_id()] = "the core print"
    name = _namer(sections, body_id, link_of, outer.xy.shape[1], body_mesh.regions, features)
    figures = _check(parts, frame, name, facet_tolerance(outer.xy.shape[1]))
    figures["core"] = None if core is None else {
        **core_figures, "process": "removable" if frame.straight else "lost-core",
        "note": ("the chamber is straight at q = 0: the core slides out along the chamber's axis through the port "
                 "(the base cap stretches over it)") if frame.straight else
                ("the chamber is not straight at q = 0: a rigid core cannot be drawn out; cast it in a dissolvable "
                 "or wax material (lost core) and melt or dissolve it out through the port")}
    named = [("half_a", parts.half_a), ("half_b", parts.half_b)] + ([("core", parts.core)] if parts.core else [])
    return Mould(meshes_in_world(named, frame), figures)


def meshes_in_world(named: list[tuple[str, Any]], frame: PartingFrame) -> tuple[MouldMesh, ...]:
    """The named solids (manifold3d) moved from the parting frame to the case's, welded as STL keeps them."""
    to_world = frame.world_from_frame()
    meshes = []
    for part_name, part in named:
        mesh = part.transform(to_world).to_mesh64()
        faces = np.asarray(mesh.tri_verts, np.int64)
        vertices, faces, _ = welded_as_written(np.asarray(mesh.vert_properties, float)[:, :3], faces,
                                               np.zeros(len(faces), np.int8))  # as STL keeps it (issue 43)
        meshes.append(MouldMesh(part_name, vertices, faces.copy()))
    return tuple(meshes)


def checks_passed(figures: dict[str, Any], frame: PartingFrame) -> None:
    """Refuse (MeshError, a bug) a mould whose parts, disjointness or cavity check failed; then add the frame."""
    bad = [k for k, v in figures["parts"].items() if not v["ok"]]
    bad += [k for k in ("disjoint", "cavity") if not figures[k]["ok"]]
    if bad:
        raise MeshError(f"mould: checks failed for {', '.join(bad)}: {figures}; this is a bug, please report it "
                        "with the case file")
    figures["frame"] = {"origin": frame.origin.tolist(), "axes": frame.axes.tolist(), "straight": frame.straight,
                        "out_of_plane_mm": frame.out_of_plane_mm}


def _check(parts: MouldParts, frame: PartingFrame, name: Callable[[int, int], str], facet_tol: float) -> dict:
    """Every check of :mod:`~softdesign.meshing.mould.checks`; refuse an undercut, MeshError on anything else.

    The pulls come first: an undercut is refused before the seconds of the cavity's figures, which cannot change
    that verdict."""
    whole = parts.box + parts.core if parts.core is not None else parts.box
    pulls = {}
    for half, solid, pull in (("A", parts.half_a, np.array([0.0, 0.0, 1.0])),
                              ("B", parts.half_b, np.array([0.0, 0.0, -1.0]))):
        result, failures = pull_check(solid, pull, whole - solid, parts.box.original_id(), name, facet_tol)
        if failures:
            _refuse_undercut(half, pull, frame, failures, len(failures))
        pulls[f"half_{half.lower()}"] = {**result, "pull": (frame.axes.T @ pull).tolist()}
    solids = {"half_a": parts.half_a, "half_b": parts.half_b}
    if parts.core is not None:
        solids["core"] = parts.core
    figures: dict[str, Any] = {"parts": {k: part_figures(v) for k, v in solids.items()}}
    body_volume = float(parts.casting.volume())
    names = list(solids)
    shared = {f"{a}/{b}": shared_volume(solids[a], solids[b]) for i, a in enumerate(names) for b in names[i + 1:]}
    figures["disjoint"] = {"shared_mm3": shared, "tolerance_mm3": DISJOINT_RTOL * body_volume,
                           "ok": all(v <= DISJOINT_RTOL * body_volume for v in shared.values())}
    figures["cavity"] = {**cavity_figures(parts.half_a, parts.half_b, parts.core, parts.box, parts.body,
                                          parts.casting, parts.channels, parts.bumps, parts.sockets),
                         "tolerance": CAVITY_RTOL}
    figures["pull"] = pulls
    checks_passed(figures, frame)
    figures["casting"] = {"up": (frame.axes.T @ parts.up).tolist(), "pour_at": (frame.axes.T @ parts.pour_at
                          + frame.origin).tolist(), "vent_at": (frame.axes.T @ parts.vent_at + frame.origin).tolist()}
    return figures

