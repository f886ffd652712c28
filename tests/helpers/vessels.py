"""Vessel surfaces of known axis and radius for the centerline tests: tubes along curves, a Y bifurcation."""

from __future__ import annotations

import numpy as np


def tube_along(points: np.ndarray, normals: np.ndarray, radius: float, around: int) -> tuple[np.ndarray, np.ndarray]:
    """Open tube of rings about ``points`` (n, 3) with ring normals ``normals`` (n, 3) unit; faces wound outwards.

    Consecutive rings are turned by half a step so the triangles are nearly equilateral.
    """
    tangent = np.gradient(points, axis=0)
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    binormal = np.cross(tangent, normals)
    n = len(points)
    angle = 2 * np.pi * (np.arange(around)[None, :] + 0.5 * (np.arange(n)[:, None] % 2)) / around
    rings = points[:, None, :] + radius * (np.cos(angle)[..., None] * normals[:, None, :]
                                           + np.sin(angle)[..., None] * binormal[:, None, :])
    ids = np.arange(n * around).reshape(n, around)
    faces = []
    for i in range(n - 1):
        a, b = ids[i], ids[i + 1]
        a1, b1 = np.roll(a, -1), np.roll(b, -1)
        if i % 2 == 0:
            faces += [np.stack([a, a1, b], 1), np.stack([a1, b1, b], 1)]
        else:
            faces += [np.stack([a, b1, b], 1), np.stack([a, a1, b1], 1)]
    return rings.reshape(-1, 3), np.concatenate(faces)


def straight_tube(radius: float, length: float, edge: float) -> tuple[np.ndarray, np.ndarray]:
    """Open tube along +z from the origin, edges about ``edge`` mm."""
    around = int(np.ceil(2 * np.pi * radius / edge))
    z = np.linspace(0.0, length, int(np.ceil(length / (edge * np.sqrt(3) / 2))) + 1)
    points = np.column_stack([np.zeros_like(z), np.zeros_like(z), z])
    return tube_along(points, np.tile([1.0, 0.0, 0.0], (len(z), 1)), radius, around)


def torus_section(bend: float, radius: float, angle: float, edge: float) -> tuple[np.ndarray, np.ndarray]:
    """Open tube of ``radius`` about the arc of radius ``bend`` in the xy plane centred at the origin,
    from (bend, 0, 0) through ``angle`` radians counter-clockwise."""
    around = int(np.ceil(2 * np.pi * radius / edge))
    t = np.linspace(0.0, angle, int(np.ceil(bend * angle / (edge * np.sqrt(3) / 2))) + 1)
    points = bend * np.column_stack([np.cos(t), np.sin(t), np.zeros_like(t)])
    normals = -points / bend
    return tube_along(points, normals, radius, around)


def y_bifurcation(trunk: float, branch: float, length: float, half_angle: float, edge: float):
    """Capped Y: a trunk of radius ``trunk`` along -z to (0, 0, -length) and two branches of radius ``branch``
    from the origin to length along (+-sin(half_angle), 0, cos(half_angle)); manifold3d union, flat caps.

    Returns vertices, faces and the three axis directions (trunk first, pointing away from the origin).
    """
    import manifold3d

    segments = int(np.ceil(2 * np.pi * trunk / edge))
    # the trunk starts a branch radius above the origin so the union has no coplanar faces there
    trunk_part = manifold3d.Manifold.cylinder(length + branch, trunk, trunk, segments).translate((0, 0, -length))
    body = trunk_part
    directions = [np.array([0.0, 0.0, -1.0])]
    for sign in (-1.0, 1.0):
        part = manifold3d.Manifold.cylinder(length, branch, branch, int(np.ceil(2 * np.pi * branch / edge)))
        body = body + part.rotate((0.0, sign * np.degrees(half_angle), 0.0))
        directions.append(np.array([sign * np.sin(half_angle), 0.0, np.cos(half_angle)]))
    body = body.refine_to_length(edge)
    mesh = body.to_mesh()
    return np.asarray(mesh.vert_properties[:, :3], float), np.asarray(mesh.tri_verts, np.int64), directions
