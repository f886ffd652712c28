"""A chain of constant-curvature sections composed from a base frame, and true distances to it (seed 003).

Parameters of a chain of ``k`` sections
    ``w`` (..., k, 2), 1/mm: each section's curvature vector in its own base
    frame (x = N, y = B of that frame), ``w = kappa (cos phi, sin phi)``: the
    section bends towards ``phi`` (:mod:`softdesign.kinematics.pcc`).  It has
    no singularity at zero curvature (USERS.md item 13): a straight section
    is ``w = 0`` and every formula below is exact there.  ``length`` (..., k),
    mm: each section's backbone arc length L.
Composition
    Section 1 starts on ``base2world`` (4, 4), its z axis the tangent.  Each
    next section starts on the previous tip frame: seed 003's improved D-H,
    ``Rz(phi) Ry(theta/2) Tz(chord) Ry(theta/2) Rz(-phi)`` per section
    (:func:`pcc.transform_from_arc`), multiplied proximal first.
Distances
    :func:`feet_on_chain` finds, for every point, the closest point of the
    whole chain (every section tried, in closed form: the foot on the circle in
    the section's bending plane, or the nearer end of the arc when the foot
    falls outside it).  :func:`distances_to_polyline` is the exact distance
    from points to a polyline (KD-tree on its vertices, then projection on
    every segment that can hold the nearest point).  Both are true distances,
    not estimates.  No I/O.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softdesign.kinematics import pcc
from softdesign.types import FloatArray, Points, Pose

#: Below this curvature (1/mm, a 1000 km radius) a section's foot point is found as on a straight line.
STRAIGHT_KAPPA = 1e-12
#: Nearest polyline vertices looked at first per point (more when the bound in distances_to_polyline needs it).
POLYLINE_NEIGHBOURS = 8


def arcs_from_w(w: npt.ArrayLike) -> tuple[FloatArray, FloatArray]:
    """``(kappa, phi)`` of curvature vectors (..., 2): kappa >= 0, phi in (-pi, pi], 0 when straight."""
    w = np.asarray(w, float)
    kappa = np.hypot(w[..., 0], w[..., 1])
    return kappa, np.where(kappa > 0.0, np.arctan2(w[..., 1], w[..., 0]), 0.0)


def section_poses(base2world: npt.ArrayLike, w: npt.ArrayLike, length: npt.ArrayLike) -> tuple[Pose, Pose]:
    """Base and tip frame of every section in the world, each (..., k, 4, 4).

    Parameters
    ----------
    base2world : (4, 4) or (..., 4, 4), the pose where section 1 starts
    w : (..., k, 2) 1/mm;  length : (..., k) mm
    """
    kappa, phi = arcs_from_w(w)
    tips = np.asarray(base2world, float)[..., None, :, :] @ pcc.chain_transforms(
        pcc.transform_from_arc(kappa, phi, np.asarray(length, float)))
    bases = np.concatenate([np.broadcast_to(np.asarray(base2world, float)[..., None, :, :],
                                            tips[..., :1, :, :].shape), tips[..., :-1, :, :]], axis=-3)
    return bases, tips


def chain_points_at(base2world: npt.ArrayLike, w: npt.ArrayLike, length: npt.ArrayLike,
                    s: npt.ArrayLike) -> Points:
    """Backbone points (m, 3) mm at arc lengths ``s`` (m,) mm from the base, exact on every section.

    ``s`` beyond the chain's length continues the last section's arc; below 0 the first's.
    """
    w, length, s = (np.asarray(x, float) for x in (w, length, s))
    bases, _ = section_poses(base2world, w, length)
    starts = np.concatenate([[0.0], np.cumsum(length)[:-1]])
    section = np.clip(np.searchsorted(starts, s, side="right") - 1, 0, len(length) - 1)
    kappa, phi = arcs_from_w(w)
    local = pcc.tip_position_from_arc(kappa[section], phi[section], s - starts[section])
    return np.einsum("mij,mj->mi", bases[section, :3, :3], local) + bases[section, :3, 3]


def dense_chain_points(base2world: npt.ArrayLike, w: npt.ArrayLike, length: npt.ArrayLike,
                       step_mm: float) -> tuple[Points, FloatArray]:
    """Points every at most ``step_mm`` along the chain, every joint and both ends included; and their arc lengths."""
    length = np.asarray(length, float)
    joints = np.concatenate([[0.0], np.cumsum(length)])
    pieces = [np.linspace(a, b, max(int(np.ceil((b - a) / step_mm)), 1) + 1)[:-1]
              for a, b in zip(joints[:-1], joints[1:], strict=True)]
    s = np.concatenate([*pieces, joints[-1:]])
    return chain_points_at(base2world, w, length, s), s


def _feet_on_arc(local: FloatArray, w: FloatArray, length: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Closest points (..., m, 3) and their arc lengths (..., m) on arcs from the origin tangent to z.

    ``local`` (..., m, 3) are points in each arc's base frame; ``w`` (..., 2), ``length`` (...) the arcs.
    """
    kappa, phi = arcs_from_w(w)
    k = kappa[..., None]
    direction = np.stack([np.cos(phi), np.sin(phi)], axis=-1)  # towards the centre; x when straight
    u = np.einsum("...mi,...i->...m", local[..., :2], direction)
    z = local[..., 2]
    angle = np.arctan2(k * z, 1.0 - k * u)
    theta_end = (kappa * length)[..., None]
    angle = angle + 2.0 * np.pi * np.round((0.5 * theta_end - angle) / (2.0 * np.pi))
    safe = np.where(k > STRAIGHT_KAPPA, k, 1.0)
    along = np.clip(np.where(k > STRAIGHT_KAPPA, angle / safe, z), 0.0, length[..., None])
    inner = pcc.tip_position_from_arc(kappa[..., None], phi[..., None], along)
    tip = pcc.tip_position_from_arc(kappa, phi, length)[..., None, :]
    # the foot on the circle, clipped to the arc, or the nearer end when the foot falls outside it
    d2 = np.stack([np.sum((inner - local) ** 2, axis=-1), np.sum(local**2, axis=-1),
                   np.sum((tip - local) ** 2, axis=-1)], axis=0)
    pick = np.argmin(d2, axis=0)
    foot = np.where((pick == 0)[..., None], inner, np.where((pick == 1)[..., None], 0.0, tip))
    s_foot = np.where(pick == 0, along, np.where(pick == 1, 0.0, length[..., None]))
    return foot, s_foot


def feet_on_chain(points: npt.ArrayLike, bases: Pose, w: npt.ArrayLike, length: npt.ArrayLike,
                  sections: npt.ArrayLike | None = None) -> tuple[Points, FloatArray, npt.NDArray[np.int64]]:
    """The closest point of a chain to each point, exact.

    Parameters
    ----------
    points : (m, 3) mm, world
    bases : (..., k, 4, 4) each section's base frame in the world (:func:`section_poses`)
    w : (..., k, 2) 1/mm;  length : (..., k) mm
    sections : (m,) int, optional: look on these sections only, one per point (then ``feet`` is the closest
        point of that section, not of the chain)

    Returns
    -------
    feet : (..., m, 3) mm, world;  distance : (..., m) mm;  section : (..., m) the section holding each foot
    """
    points = np.asarray(points, float)
    w, length = np.asarray(w, float), np.asarray(length, float)
    if sections is not None:
        sections = np.asarray(sections, np.int64)
        feet = _feet_on_sections(points, bases[..., sections, :, :], w[..., sections, :], length[..., sections])
        return feet, np.linalg.norm(feet - points, axis=-1), np.broadcast_to(sections, feet.shape[:-1])
    count = length.shape[-1]
    every = _feet_on_sections(points[:, None, :], bases[..., None, :, :, :], w[..., None, :, :],
                              length[..., None, :])  # (..., m, k, 3)
    d2 = np.sum((every - points[:, None, :]) ** 2, axis=-1)
    best = np.argmin(d2, axis=-1) if count > 1 else np.zeros(d2.shape[:-1], np.int64)
    feet = np.take_along_axis(every, best[..., None, None], axis=-2)[..., 0, :]
    return feet, np.sqrt(np.take_along_axis(d2, best[..., None], axis=-1)[..., 0]), best


def _feet_on_sections(points: FloatArray, bases: Pose, w: FloatArray, length: FloatArray) -> Points:
    """Closest points (..., 3) world of points (..., 3) on arcs with poses (..., 4, 4), w (..., 2), length (...)."""
    rotation, origin = bases[..., :3, :3], bases[..., :3, 3]
    local = np.squeeze(np.swapaxes(rotation, -1, -2) @ (points - origin)[..., None], -1)
    foot_local, _ = _feet_on_arc(local[..., None, :], w, length)
    return np.squeeze(rotation @ foot_local[..., 0, :, None], -1) + origin


def distances_to_polyline(points: npt.ArrayLike, polyline: npt.ArrayLike, tree: object | None = None) -> FloatArray:
    """Exact distance (m,) mm from each point (m, 3) to the polyline (p, 3), p >= 2.

    The nearest point of the polyline lies on a segment with an end within
    ``sqrt(d_v^2 + h^2 / 4)`` of the point (``d_v`` its nearest vertex, ``h`` the
    longest segment): every segment at every vertex that close is projected on.
    ``tree`` is a ``scipy.spatial.cKDTree`` of ``polyline`` when the caller has one.
    """
    from scipy.spatial import cKDTree

    points, polyline = np.asarray(points, float), np.asarray(polyline, float)
    kd = cKDTree(polyline) if tree is None else tree
    h = float(np.max(np.linalg.norm(np.diff(polyline, axis=0), axis=1)))
    count = min(POLYLINE_NEIGHBOURS, len(polyline))
    while True:
        dist, index = kd.query(points, k=count)  # type: ignore[attr-defined]  # count >= 2: (m, count) arrays
        reach = np.sqrt(dist[:, 0] ** 2 + 0.25 * h * h)
        if count == len(polyline) or np.all(dist[:, -1] > reach):
            break
        count = min(2 * count, len(polyline))
    starts = np.clip(np.concatenate([index - 1, index], axis=1), 0, len(polyline) - 2)  # both segments at a vertex
    a, b = polyline[starts], polyline[starts + 1]
    ab = b - a
    t = np.clip(np.einsum("mni,mni->mn", points[:, None, :] - a, ab) / np.einsum("mni,mni->mn", ab, ab), 0.0, 1.0)
    return np.min(np.linalg.norm(points[:, None, :] - (a + t[..., None] * ab), axis=2), axis=1)
