"""A closed-end thick tube as one slice of quadratic tetrahedra: Rivlin's inflation and extension in finite elements.

A full ring (no symmetry planes, so the cavity's end is a whole disc) one element layer thick, radially graded
towards the inner wall.  The slice stands for the middle of a long closed tube:

- its base plane is held in z, and one node on +x and one column on +y hold the rigid motions in the plane
  (uy = 0 on the +x ray, ux = 0 on the +y ray: the uniform solution satisfies both);
- its top plane stays a plane: every top node's z is tied to one top node's by a stiff spring (a penalty tie,
  its error a force over ``TIE_MN_PER_MM``, 1e-7 mm here);
- the cavity's far end is a lid: a fan of flat triangles over the top inner ring, carrying the cavity's pressure
  (``P pi a^2`` on the deformed end, as a closed end does), sent to the ring's nodes.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from softdesign.continuum.laws import HyperelasticLaw
from softdesign.mechanics.newton import PressureProblem
from softdesign.mechanics.quadratic import quadratic_faces, quadratic_fixed, quadratic_mesh
from softdesign.mechanics.tets import boundary_faces, make_tet_mesh
from softdesign.types import FloatArray
from tests.helpers.fe_meshes import grid_tets, oriented

#: The tie's spring, mN/mm: 1e4 times the tube's stiffness scale (mu times its outer radius, 55 mN/mm).
TIE_MN_PER_MM = 5.0e5


def ring_slice(inner: float, outer: float, height: float, radial: int, angular: int) -> tuple[FloatArray, np.ndarray]:
    """Points (V, 3) mm and tets (E, 4) of a full ring one layer thick, radii graded geometrically."""
    r = inner * (outer / inner) ** (np.arange(radial + 1) / radial)
    t = 2 * np.pi * np.arange(angular + 1) / angular
    R, T, Z = np.meshgrid(r, t, [0.0, height], indexing="ij")
    points = np.stack([R * np.cos(T), R * np.sin(T), Z], axis=-1).reshape(-1, 3)
    tets = grid_tets((radial, angular, 1))
    index = np.arange(len(points)).reshape(radial + 1, angular + 1, 2)
    merged = index.copy()
    merged[:, angular, :] = index[:, 0, :]  # the seam: the last angle is the first
    tets = merged.ravel()[tets]
    used = np.unique(tets)
    renumber = np.full(len(points), -1, np.int64)
    renumber[used] = np.arange(len(used))
    points = points[used]
    return points, oriented(points, renumber[tets])


def closed_tube_problem(law: HyperelasticLaw, inner: float, outer: float, height: float, radial: int,
                        angular: int) -> PressureProblem:
    """The slice's pressure problem: one cavity, its wall and lid (see the module's docstring)."""
    points, tets = ring_slice(inner, outer, height, radial, angular)
    mesh = quadratic_mesh(make_tet_mesh(points, tets))
    faces = boundary_faces(mesh.linear.tets)
    on_inner = np.all(np.isclose(np.hypot(points[faces][..., 0], points[faces][..., 1]), inner), axis=1)
    wall = quadratic_faces(mesh, faces[on_inner][:, [0, 2, 1]])  # normals out of the cavity
    fixed = np.zeros(points.shape, bool)
    fixed[np.isclose(points[:, 2], 0.0), 2] = True
    fixed[np.isclose(points[:, 1], 0.0) & (points[:, 0] > 0), 1] = True
    fixed[np.isclose(points[:, 0], 0.0) & (points[:, 1] > 0), 0] = True
    all_points = mesh.points
    top = np.flatnonzero(np.isclose(all_points[:, 2], height))
    ring = \
        np.unique(wall.ravel()[np.isclose(all_points[wall.ravel(), 2], height)])
    ring = ring[np.argsort(np.arctan2(all_points[ring, 1], all_points[ring, 0]))]
    lids = np.stack([np.full(len(ring) - 2, ring[0]), ring[1:-1], ring[2:]], axis=1)  # counter-clockwise: +z
    return PressureProblem(mesh, law, quadratic_fixed(mesh, fixed).ravel(), wall, np.zeros(len(wall), np.int64),
                           lids=lids, lid_cavity=np.zeros(len(lids), np.int64),
                           springs=_tie(3 * top + 2, 3 * len(all_points)))


def _tie(dofs: np.ndarray, size: int) -> sp.csr_matrix:
    """Springs ``k (u_i - u_0)^2 / 2`` from every unknown of ``dofs`` to the first: (size, size) mN/mm."""
    first, rest = dofs[0], dofs[1:]
    k = TIE_MN_PER_MM
    rows = np.concatenate([rest, rest, [first] * len(rest), [first] * len(rest)])
    cols = np.concatenate([rest, [first] * len(rest), rest, [first] * len(rest)])
    values = np.concatenate([np.full(len(rest), k), np.full(len(rest), -k), np.full(len(rest), -k),
                             np.full(len(rest), k)])
    return sp.csr_matrix((values, (rows, cols)), shape=(size, size))


def stretches(problem: PressureProblem, u: FloatArray, inner: float, height: float) -> tuple[float, float]:
    """Inner hoop stretch (the corner nodes' mean deformed radius over ``inner``) and the axial stretch."""
    corners = problem.mesh.linear.points
    on_inner = np.isclose(np.hypot(corners[:, 0], corners[:, 1]), inner)
    x = corners[on_inner] + u[:len(corners)][on_inner]
    top = np.isclose(corners[:, 2], height)
    return float(np.hypot(x[:, 0], x[:, 1]).mean() / inner), float(1 + u[:len(corners)][top, 2].mean() / height)
