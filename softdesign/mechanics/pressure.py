"""Follower pressure on a cavity's wall: nodal forces on the deformed surface and their consistent tangent.

A uniform pressure ``p`` on a flat triangle ``x1 x2 x3`` whose normal
``n = (x2 - x1) x (x3 - x1)`` points out of the cavity (into the material)
pushes each corner with ``f = p n / 6`` (a third of ``p`` times the area
vector ``n / 2``), evaluated on the *deformed* triangle, so the load turns with
the wall.  Its derivative, with ``a = x2 - x1``, ``b = x3 - x1`` and ``[v]x``
the cross-product matrix, is for every corner

    df/dx1 = p/6 ([b]x - [a]x),   df/dx2 = -p/6 [b]x,   df/dx3 = p/6 [a]x,

which enters the Newton tangent as ``K - dF_ext/dx`` (the consistent
tangent; not symmetric face by face, symmetric summed over a closed cavity,
where the load has the potential ``p * volume``).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from softdesign.mechanics.tets import node_dofs, summed
from softdesign.types import FloatArray, IntArray


def _cross_matrices(v: FloatArray) -> FloatArray:
    """``[v]x`` (n, 3, 3) with ``[v]x w = v x w``."""
    m = np.zeros((len(v), 3, 3))
    m[:, 0, 1], m[:, 0, 2], m[:, 1, 2] = -v[:, 2], v[:, 1], -v[:, 0]
    m[:, 1, 0], m[:, 2, 0], m[:, 2, 1] = v[:, 2], -v[:, 1], v[:, 0]
    return m


def face_dofs(faces: IntArray) -> IntArray:
    """Global unknowns (F, 9) of each triangle, node-major."""
    return node_dofs(faces)


def pressure_load(
    positions: FloatArray, faces: IntArray, face_pressure: FloatArray, want_tangent: bool
) -> tuple[FloatArray, sp.csr_matrix | None]:
    """Nodal forces (3V,) mN of pressures on deformed triangles, and ``dF/dx`` (3V, 3V) mN/mm if asked.

    Parameters
    ----------
    positions : (V, 3) float, mm -- deformed node positions
    faces : (F, 3) int -- wall triangles, normals out of the cavity into the material
    face_pressure : (F,) float, kPa -- each face's cavity pressure
    want_tangent : bool
    """
    n_dof = 3 * len(positions)
    x1, x2, x3 = (positions[faces[:, k]] for k in range(3))
    a, b = x2 - x1, x3 - x1
    force = (face_pressure / 6.0)[:, None] * np.cross(a, b)  # (F, 3), the same on each corner
    dofs = face_dofs(faces)
    f = summed(dofs, np.tile(force, (1, 3)), n_dof)
    if not want_tangent:
        return f, None
    ca, cb = _cross_matrices(a), _cross_matrices(b)
    per_corner = np.stack([cb - ca, -cb, ca], axis=1) * (face_pressure / 6.0)[:, None, None, None]  # (F, 3, 3, 3)
    # block (corner r, corner c) = d f_r / d x_c = per_corner[c], the same for every r
    blocks = np.broadcast_to(per_corner.transpose(0, 2, 1, 3)[:, None], (len(faces), 3, 3, 3, 3))
    blocks = blocks.reshape(len(faces), 9, 9)
    rows = np.broadcast_to(dofs[:, :, None], blocks.shape).ravel()
    cols = np.broadcast_to(dofs[:, None, :], blocks.shape).ravel()
    return f, sp.csr_matrix((blocks.ravel(), (rows, cols)), shape=(n_dof, n_dof))
