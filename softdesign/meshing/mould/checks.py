"""The checks every mould must pass before it is kept (issue 16), on manifold3d's results.

Parts
    each half and the core: manifold3d status NoError, not empty, one body
    (``decompose``), genus 0 and positive volume
Disjoint
    the volume two parts share (their boolean intersection): touching faces
    share none; at most ``DISJOINT_RTOL`` of the body's volume
Cavity
    box - half A - half B - core, less the pour and vent channels outside the
    body and the keys' clearance gaps, against the cast part (the export's
    solid at q = 0): the volume of their symmetric difference at most
    ``CAVITY_RTOL`` of the cast part's volume
Pull
    every face of a half but its box faces (cavity, channels, keys, the
    parting face): its outward normal (out of the mould's material) must not
    point along the half's pull by more than ``facet_tol`` (it would drag
    against what stays behind), and a ray from just inside the half's
    material along the pull must meet nothing that stays behind (cast part,
    core, other half)
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import manifold3d as m3
import numpy as np

from softdesign.types import FloatArray, IntArray

#: Largest volume two parts may share, as a fraction of the body's volume (touching faces share none:
#: what remains is manifold3d's rounding).
DISJOINT_RTOL = 1e-9
#: The cavity equals the cast part within this fraction of its volume (issue 16).
CAVITY_RTOL = 0.005
#: A ray starts this far inside the half's material, mm (off the face it starts from).
RAY_OFFSET_MM = 1e-4


def facet_tolerance(angular_count: int) -> float:
    """The largest pull component a facet straddling the parting line can have by tessellation alone.

    A chord between section vertices at angles a and a + 2 pi / na that the
    parting plane crosses is tilted from the plane by at most pi / na, so its
    normal leans against the pull by up to sin(pi / na) where the smooth
    surface does not (zero when the plane passes through section vertices,
    as it does for a straight body).
    """
    return float(np.sin(np.pi / angular_count))


def part_figures(part: m3.Manifold) -> dict[str, Any]:
    """Status, bodies, genus and volume of one part; ``ok`` when it is one closed body of positive volume."""
    status = part.status()
    empty = part.is_empty()
    bodies = 0 if empty else len(part.decompose())
    volume = 0.0 if empty else float(part.volume())
    ok = status == m3.Error.NoError and not empty and bodies == 1 and volume > 0
    mesh = part.to_mesh64()
    return {"status": status.name, "bodies": bodies, "genus": int(part.genus()), "volume_mm3": volume,
            "vertices": int(len(mesh.vert_properties)), "faces": int(len(mesh.tri_verts)), "ok": bool(ok)}


def shared_volume(a: m3.Manifold, b: m3.Manifold) -> float:
    """Volume of ``a`` and ``b``'s intersection, mm^3."""
    return float((a ^ b).volume())


def cavity_figures(half_a: m3.Manifold, half_b: m3.Manifold, core: m3.Manifold | None, box: m3.Manifold,
                   body: m3.Manifold, casting: m3.Manifold, channels: m3.Manifold, bumps: m3.Manifold,
                   sockets: m3.Manifold) -> dict[str, float | bool]:
    """What the parts leave empty in the box, against the cast part (see the module docstring)."""
    cavity = box - half_a - half_b
    if core is not None:
        cavity = cavity - core
    cast = cavity - (channels - body) - (sockets - bumps)
    extra, missing = float((cast - casting).volume()), float((casting - cast).volume())
    volume = float(casting.volume())
    rel = (extra + missing) / volume
    return {"cavity_mm3": float(cavity.volume()), "cast_mm3": float(cast.volume()), "body_mm3": volume,
            "extra_mm3": extra, "missing_mm3": missing, "rel_difference": rel, "ok": bool(rel <= CAVITY_RTOL)}


@dataclass(frozen=True)
class PullFailure:
    """A face that drags against the pull: its normal's component along the pull and where it is."""

    component: float
    blocked: bool
    where: str


def _faces(part: m3.Manifold) -> tuple[FloatArray, IntArray, IntArray, IntArray]:
    mesh = part.to_mesh64()
    vertices = np.asarray(mesh.vert_properties, float)[:, :3]
    faces = np.asarray(mesh.tri_verts, np.int64)
    run_index = np.asarray(mesh.run_index, np.int64) // 3
    source = np.repeat(np.asarray(mesh.run_original_id, np.int64), np.diff(run_index))
    return vertices, faces, source, np.asarray(mesh.face_id, np.int64)


def pull_check(half: m3.Manifold, pull: FloatArray, obstacles: m3.Manifold, skip_source: int,
               name_face: Callable[[int, int], str], facet_tol: float) -> tuple[dict[str, Any], list[PullFailure]]:
    """Normals and rays of every face of ``half`` not from ``skip_source`` (the box) along unit ``pull``.

    Parameters
    ----------
    half : the half, mould frame
    pull : (3,) float, the direction it is drawn off the casting
    obstacles : what stays behind (cast part and core, the other half), mould frame
    skip_source : manifold3d original id whose faces are not checked (the box's outside)
    name_face : (source id, face id) -> where that face is (link, l, angle; or the feature)
    facet_tol : normals may lean against the pull by this much (:func:`facet_tolerance`)
    """
    vertices, faces, source, face_id = _faces(half)
    keep = source != skip_source
    tri = vertices[faces[keep]]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area2 = np.linalg.norm(normal, axis=1)
    live = area2 > 0
    normal[live] /= area2[live, None]
    component = normal @ pull
    centroid = tri.mean(axis=1) - RAY_OFFSET_MM * normal
    lo, hi = (np.asarray(v, float) for v in np.reshape(obstacles.bounding_box(), (2, 3)))
    reach = 2.0 * float(np.linalg.norm(hi - lo)) + 1.0
    blocked = np.array([bool(obstacles.ray_cast(tuple(c), tuple(c + reach * pull))) for c in centroid], bool)
    against = live & (component > facet_tol)
    bad = np.flatnonzero(against | blocked)
    order = bad[np.argsort(-component[bad], kind="stable")]
    src, fid = source[keep], face_id[keep]
    failures = [PullFailure(float(component[i]), bool(blocked[i]), name_face(int(src[i]), int(fid[i])))
                for i in order]
    figures = {"faces_checked": int(keep.sum()), "against_pull": int(against.sum()), "blocked_rays": int(blocked.sum()),
               "largest_component": float(component.max(initial=0.0)), "facet_tolerance": facet_tol,
               "ok": not failures}
    return figures, failures
