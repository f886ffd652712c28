"""Closed solids of S(q) with manifold3d: plain or offset bodies, hollow actuators with an inlet port.

Kinds and the topology each must have (see :mod:`softdesign.meshing.checks`)
    solid    the tessellated body with planar end caps: one shell, Euler 2
    hollow   the body minus a chamber (its inward offset by ``wall_mm``,
             ``wall_mm`` shorter at each end so both ends are sealed by
             wall-thick caps): an outer shell and an inner shell wound
             inwards, one body with one void, Euler 2 + 2 = 4
    ported   hollow plus a channel of diameter ``port_mm`` along the base
             tangent from outside through the base cap into the chamber:
             chamber and outside join into one shell of genus 0, Euler 2
manifold3d reports invalid input through ``status()`` instead of raising;
every Manifold made here is checked and a bad one raises MeshError.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import manifold3d as m3
import numpy as np
import numpy.typing as npt

from softdesign.errors import MeshError
from softdesign.meshing.checks import Expectation
from softdesign.meshing.end_cut import cut_ends, cut_planes
from softdesign.meshing.tessellate import (
    Region,
    Sweep,
    TubeMesh,
    TubeSections,
    sweep_from_sections,
    tessellate,
    trim_sweep,
)
from softdesign.meshing.volume import BodySpec
from softdesign.types import FloatArray, IntArray

#: The port channel starts this many wall thicknesses outside the base plane (a clean cut, no coplanar faces).
PORT_OUTSIDE_WALLS = 1.0
#: ... and ends this far (in wall thicknesses, at most a quarter of the chamber) inside the chamber.
PORT_INSIDE_WALLS = 0.5


@dataclass(frozen=True)
class Solid:
    """A closed triangle mesh with face regions and the topology it must have.

    Attributes
    ----------
    vertices : (V, 3) float, mm
    faces : (F, 3) int64, counter-clockwise seen from outside
    regions : (F,) int8, values of :class:`~softdesign.meshing.tessellate.Region`
    euler : int
        Expected Euler characteristic (2 solid or ported, 4 sealed hollow).
    kind : str
        ``solid``, ``hollow`` or ``ported``.
    max_rho_kappa : float
        Largest rho * kappa of the outer surface (offset included); it folds at 1.
    volume_offset_mm3 : float
        What the end cuts add to the volume of the body between its end frames' planes, mm3
        (:mod:`softdesign.meshing.end_cut`; 0 for square ends).
    """

    vertices: FloatArray
    faces: IntArray
    regions: npt.NDArray[np.int8]
    euler: int
    kind: str
    max_rho_kappa: float
    volume_offset_mm3: float = 0.0

    def expectation(self, volume: float | None) -> Expectation:
        """What :func:`~softdesign.meshing.checks.check_solid` must find for this solid (``volume`` between the
        end frames' planes, to which the end cuts' volume is added)."""
        return Expectation(volume=None if volume is None else volume + self.volume_offset_mm3, euler=self.euler,
                           bodies=1)


def manifold_from_mesh(vertices: npt.ArrayLike, faces: npt.ArrayLike, label: str) -> tuple[m3.Manifold, int]:
    """A manifold3d Manifold of the mesh, checked, and the mesh id its faces carry through booleans.

    Face i keeps face_id i, so a boolean result traces every face to its source face.

    Raises
    ------
    MeshError
        When manifold3d's status is not NoError (not an oriented 2-manifold, non-finite vertex, ...).
    """
    faces = np.asarray(faces, np.int64)
    mesh_id = m3.Manifold.reserve_ids(1)
    mesh = m3.Mesh64(
        vert_properties=np.ascontiguousarray(vertices, dtype=np.float64),
        tri_verts=np.ascontiguousarray(faces, dtype=np.uint64),
        run_index=np.array([0, faces.size], np.uint64),
        run_original_id=np.array([mesh_id], np.uint32),
        face_id=np.arange(faces.shape[0], dtype=np.uint64),
    )
    return checked(m3.Manifold(mesh), label), int(mesh_id)


def checked(manifold: m3.Manifold, label: str) -> m3.Manifold:
    """``manifold`` itself when its status is NoError and it is not empty, else MeshError."""
    status = manifold.status()
    if status != m3.Error.NoError or manifold.is_empty():
        raise MeshError(
            f"{label}: manifold3d refused the mesh: status {status.name}"
            f"{', empty result' if status == m3.Error.NoError else ''}; expected an oriented, closed "
            "2-manifold; this is a bug in the mesher, please report it with the case file"
        )
    return manifold


Labels = npt.NDArray[np.int8]


def welded_as_written(vertices: FloatArray, faces: IntArray, regions: Labels) -> tuple[FloatArray, IntArray, Labels]:
    """The mesh as single precision writes it (STL, PLY, glTF): vertices that coincide once rounded to float32
    merged into the first of them (kept in float64), the faces that fold to a point or a segment dropped (with
    their regions); the arrays themselves when nothing coincides.

    manifold3d cuts faces wherever two inputs cross; where a crossing falls a hair (1e-5 mm) from an input's
    vertex or edge, it leaves an edge that float32 (about 1.5e-5 mm at 250 mm from the origin) folds to a point:
    two zero-area faces and, once a slicer merges coincident vertices, non-manifold edges and zero-volume parts
    (issue 43).  Merging here collapses that edge, as manifold3d's own edge collapse would; the caller's checks
    then judge the mesh that is written.
    """
    rounded = np.asarray(vertices, np.float32)
    unique, inverse = np.unique(rounded, axis=0, return_inverse=True)
    if len(unique) == len(rounded):
        return vertices, faces, regions  # nothing folds: the mesh as it was, to the last bit
    order = np.unique(inverse, return_index=True)[1]  # of those that coincide, the first in the file's order
    rank = np.empty(len(order), np.int64)
    rank[np.argsort(order)] = np.arange(len(order))
    merged = rank[inverse.reshape(-1)][faces]
    keep = (merged[:, 0] != merged[:, 1]) & (merged[:, 1] != merged[:, 2]) & (merged[:, 2] != merged[:, 0])
    return np.asarray(vertices, np.float64)[np.sort(order)], merged[keep], regions[keep]


def _regions_after(manifold: m3.Manifold, sources: dict[int, Labels]) -> tuple[FloatArray, IntArray, Labels]:
    """Vertices, faces and region labels of a boolean result, regions traced through runs and face ids."""
    mesh = manifold.to_mesh64()
    run_index = np.asarray(mesh.run_index, np.int64)
    run_source = np.asarray(mesh.run_original_id, np.int64)
    face_id = np.asarray(mesh.face_id, np.int64)
    regions = np.empty(face_id.size, np.int8)
    for run, source in enumerate(run_source):
        start, stop = run_index[run] // 3, run_index[run + 1] // 3
        labels = sources[int(source)]
        regions[start:stop] = labels[face_id[start:stop]] if labels.size > 1 else labels[0]
    vertices = np.asarray(mesh.vert_properties, np.float64)[:, :3].copy()
    return vertices, np.asarray(mesh.tri_verts, np.int64), regions


def _check_spec(spec: BodySpec, sections: TubeSections) -> None:
    where = f"q={sections.q:.3f}"
    values = {"offset_mm": spec.offset_mm, "wall_mm": spec.wall_mm, "port_mm": spec.port_mm}
    if not all(np.isfinite(v) for v in values.values()) or spec.wall_mm < 0 or spec.port_mm < 0:
        raise MeshError(f"{where}: export {values} must be finite, wall_mm and port_mm >= 0; fix the case file")
    if spec.port_mm > 0 and spec.wall_mm == 0:
        raise MeshError(
            f"{where}: export.port_mm={spec.port_mm:g} needs a chamber; set export.wall_mm > 0 or port_mm: 0"
        )


def _chamber(sections: TubeSections, outer: Sweep, spec: BodySpec) -> Sweep:
    """The chamber: the inward offset by wall_mm, trimmed wall_mm short of each end."""
    w = spec.wall_mm
    inner = sweep_from_sections(sections, spec.offset_mm - w, spec.min_radius_mm, field="wall_mm")
    length = outer.s[-1]
    if length - 2.0 * w < spec.min_radius_mm:
        middle = float(np.interp(0.5 * length, outer.s, outer.l))
        raise MeshError(
            f"wall_mm: at q={sections.q:.3f}, l={middle:.4f} a wall of {w:g} mm at both ends of a body "
            f"{length:.3f} mm long leaves a chamber {length - 2 * w:.3f} mm long, expected >= "
            f"{spec.min_radius_mm:g} mm; use a thinner wall"
        )
    return trim_sweep(inner, w, length - w)


def cut_body(outer: Sweep, spec: BodySpec, label: str) -> tuple[TubeMesh, float]:
    """``outer`` tessellated, its ends cut at ``spec.end_cuts``' planes; and the volume the cuts add, mm3."""
    return cut_ends(tessellate(outer), outer, cut_planes(outer, spec.end_cuts), label)


def cut_chamber(sections: TubeSections, outer: Sweep, spec: BodySpec, label: str) -> tuple[Sweep, TubeMesh, float]:
    """The chamber (:func:`_chamber`), tessellated with its ends cut at the body's planes moved ``wall_mm``
    inward (so the sealed ends stay ``wall_mm`` thick), and the volume the cuts add, mm3."""
    chamber = _chamber(sections, outer, spec)
    mesh, added = cut_ends(tessellate(chamber), chamber, cut_planes(outer, spec.end_cuts, spec.wall_mm), label)
    return chamber, mesh, added


def _port(outer: Sweep, chamber: Sweep, spec: BodySpec) -> tuple[m3.Manifold, int]:
    """The inlet channel along the base tangent, refused unless it fits inside the chamber's base section."""
    radius, w = 0.5 * spec.port_mm, spec.wall_mm
    base, axis = outer.centers[0], outer.frames[0][:, 2]
    frame, origin = chamber.frames[0], chamber.centers[0]
    # where the port axis meets the chamber's base plane, in that plane's (N, B) coordinates
    hit = base + axis * ((origin - base) @ frame[:, 2]) / (axis @ frame[:, 2])
    center2d = (hit - origin) @ frame[:, :2]
    ring = chamber.xy[0]
    seg = np.roll(ring, -1, axis=0) - ring
    t = np.clip(np.einsum("kj,kj->k", center2d - ring, seg) / np.einsum("kj,kj->k", seg, seg), 0.0, 1.0)
    clearance = float(np.min(np.linalg.norm(ring + t[:, None] * seg - center2d, axis=1)))
    if radius + spec.min_radius_mm > clearance:
        raise MeshError(
            f"port_mm: at q={outer.q:.3f}, l={chamber.l[0]:.4f} a port of diameter {spec.port_mm:g} mm does "
            f"not fit the chamber's base section (largest diameter about the port axis {2 * clearance:.3f} mm, "
            f"keeping a {spec.min_radius_mm:g} mm ledge); use port_mm <= {2 * (clearance - spec.min_radius_mm):.3f}"
        )
    lean = port_lean_mm(spec)
    outside = PORT_OUTSIDE_WALLS * w + lean
    inside = min(PORT_INSIDE_WALLS * w, 0.25 * (chamber.s[-1] - chamber.s[0])) + lean
    segments = spec.port_segments or outer.xy.shape[1]
    cylinder = m3.Manifold.cylinder(outside + w + inside, radius, radius, segments, False)
    pose = np.column_stack([outer.frames[0], base - outside * axis])
    return checked(cylinder.transform(pose), f"q={outer.q:.3f}: port"), cylinder.original_id()


def port_lean_mm(spec: BodySpec) -> float:
    """How far a base cut moves the outer and chamber caps along the port's axis within its radius, mm (tilt
    and offset; 0 for a square base): the port reaches this much farther out and in."""
    cut = spec.end_cuts[0]
    if cut is None or spec.port_mm == 0:
        return 0.0
    return float(0.5 * spec.port_mm * np.tan(np.arccos(-cut[2])) + spec.wall_mm * (1.0 / -cut[2] - 1.0)
                 + abs(cut[3]))


def build_solid(sections: TubeSections, spec: BodySpec = BodySpec()) -> Solid:
    """Close S(q) into a solid, offset, hollow or ported as ``spec`` says.

    Parameters
    ----------
    sections : TubeSections
        The body on its (l, a) grid.
    spec : BodySpec

    Returns
    -------
    Solid

    Raises
    ------
    MeshError
        Naming q and l: a surface that folds (rho * kappa >= 1), an inward
        offset or wall the local radius cannot take, a port wider than the
        chamber, or a mesh manifold3d refuses (hollow and ported solids; a
        plain solid is checked by :func:`~softdesign.meshing.checks.check_solid`).
    """
    _check_spec(spec, sections)
    label = f"q={sections.q:.3f}"
    outer = sweep_from_sections(sections, spec.offset_mm, spec.min_radius_mm)
    body, added = cut_body(outer, spec, label)
    if spec.wall_mm == 0:
        # no boolean, so no manifold3d: check_solid (which export runs on every solid) tests the same oriented
        # 2-manifold property and more; building the Manifold only to check it was half of export's time
        return Solid(body.vertices, body.faces, body.regions, 2, "solid", outer.max_rho_kappa, added)
    chamber, cavity, removed = cut_chamber(sections, outer, spec, f"{label}: chamber")
    return replace(carve_chamber(body, cavity, outer, chamber, spec, label), volume_offset_mm3=added - removed)


def carve_chamber(body: TubeMesh, cavity: TubeMesh, outer: Sweep, chamber: Sweep, spec: BodySpec, label: str) -> Solid:
    """``body`` minus ``cavity``, and minus the port when ``spec.port_mm`` > 0, with manifold3d, checked.

    Parameters
    ----------
    body, cavity : closed meshes with their regions; the cavity's wall becomes CHAMBER and its
        caps CHAMBER_CAP (a joint annulus stays JOINT_STEP)
    outer, chamber : sweeps whose first rings are the base section of the body and of the
        chamber: the port runs along the base tangent and must fit the chamber's base section
    spec : the wall and port
    label : names the solid in errors (e.g. ``q=0.500``)
    """
    body_manifold, body_id = manifold_from_mesh(body.vertices, body.faces, f"{label}: body")
    cavity_manifold, cavity_id = manifold_from_mesh(cavity.vertices, cavity.faces, f"{label}: chamber")
    caps = np.isin(cavity.regions, (Region.BASE_CAP, Region.TIP_CAP))
    labels = np.where(cavity.regions == Region.WALL, Region.CHAMBER, np.where(caps, Region.CHAMBER_CAP, cavity.regions))
    sources = {body_id: body.regions, cavity_id: labels.astype(np.int8)}
    hollow = body_manifold - cavity_manifold
    if spec.port_mm > 0:
        port, port_id = _port(outer, chamber, spec)
        sources[port_id] = np.array([Region.PORT], np.int8)
        hollow = hollow - port
    result = checked(hollow, f"{label}: hollow body")
    vertices, faces, regions = welded_as_written(*_regions_after(result, sources))
    kind, euler = ("ported", 2) if spec.port_mm > 0 else ("hollow", 4)
    return Solid(vertices, faces, regions, euler, kind, outer.max_rho_kappa)
