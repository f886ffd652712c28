"""Follower pressure on 6-node (quadratic) triangles: nodal forces on the deformed wall and their tangent.

A face's nodes are its corners ``c0 c1 c2`` and the midpoints of ``c0c1``,
``c1c2``, ``c2c0``; its position is ``x(xi, eta) = sum_b N_b x_b``.  The
pressure ``p`` on it, normal ``x_xi x x_eta`` out of the cavity, gives

    f_a = p integral N_a (x_xi x x_eta) dxi deta,
    df_a/dx_b = p integral N_a (N_b,eta [x_xi]x - N_b,xi [x_eta]x) dxi deta,

integrated exactly (degree 4) by Dunavant's six-point rule.  On a flat,
straight-edged face it is the linear triangle's ``p n / 6`` per corner spread
as a quadratic triangle's consistent load (corners 0, midpoints a third each).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from softdesign.mechanics.pressure import _cross_matrices
from softdesign.mechanics.tets import node_dofs, summed
from softdesign.types import FloatArray, IntArray

_A1, _B1 = 0.445948490915965, 0.091576213509771
_W1, _W2 = 0.223381589678011 / 2, 0.109951743655322 / 2
#: Dunavant's degree-4 rule on the reference triangle: (xi, eta) (6, 2) and weights (6,) summing to 1/2.
TRI_POINTS = np.array([[_A1, _A1], [1 - 2 * _A1, _A1], [_A1, 1 - 2 * _A1],
                       [_B1, _B1], [1 - 2 * _B1, _B1], [_B1, 1 - 2 * _B1]])
TRI_WEIGHTS = np.array([_W1, _W1, _W1, _W2, _W2, _W2])


def triangle_shapes(points: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The 6-node triangle's N (P points, 6 nodes), dN/dxi and dN/deta at reference ``points`` (P, 2) (xi, eta)."""
    xi, eta = points[:, 0], points[:, 1]
    L = np.stack([1 - xi - eta, xi, eta], axis=1)
    dL = np.array([[-1.0, 1.0, 0.0], [-1.0, 0.0, 1.0]])  # d L_i / d(xi, eta)
    pairs = [(0, 1), (1, 2), (2, 0)]
    N = np.concatenate([L * (2 * L - 1), np.stack([4 * L[:, i] * L[:, j] for i, j in pairs], axis=1)], axis=1)
    d = []
    for k in range(2):
        corners = (4 * L - 1) * dL[k][None, :]
        edges = np.stack([4 * (dL[k, i] * L[:, j] + dL[k, j] * L[:, i]) for i, j in pairs], axis=1)
        d.append(np.concatenate([corners, edges], axis=1))
    return N, d[0], d[1]


_N, _DXI, _DETA = triangle_shapes(TRI_POINTS)


def quadratic_face_dofs(faces: IntArray) -> IntArray:
    """Global unknowns (F, 18) of each 6-node face, node-major."""
    return node_dofs(faces)


def quadratic_pressure_load(positions: FloatArray, faces: IntArray, face_pressure: FloatArray, want_tangent: bool
                            ) -> tuple[FloatArray, sp.csr_matrix | None]:
    """Nodal forces (3N,) mN of pressures on deformed 6-node faces, and ``dF/dx`` (3N, 3N) mN/mm if asked.

    Parameters
    ----------
    positions : (N, 3) float, mm -- deformed node positions
    faces : (F, 6) int -- corners then midpoints of c0c1, c1c2, c2c0; normals out of the cavity into the material
    face_pressure : (F,) float, kPa
    want_tangent : bool
    """
    n_dof = 3 * len(positions)
    x = positions[faces]  # (F, 6, 3)
    x_xi = np.einsum("qb,fbi->fqi", _DXI, x)
    x_eta = np.einsum("qb,fbi->fqi", _DETA, x)
    normal = np.cross(x_xi, x_eta)  # (F, Q, 3)
    force = np.einsum("q,qa,fqi->fai", TRI_WEIGHTS, _N, normal) * face_pressure[:, None, None]
    dofs = quadratic_face_dofs(faces)
    f = summed(dofs, force.reshape(len(faces), 18), n_dof)
    if not want_tangent:
        return f, None
    F, Q = len(faces), len(TRI_WEIGHTS)
    c_xi = _cross_matrices(x_xi.reshape(-1, 3)).reshape(F, Q, 3, 3)
    c_eta = _cross_matrices(x_eta.reshape(-1, 3)).reshape(F, Q, 3, 3)
    blocks = (np.einsum("q,qa,qb,fqik->faibk", TRI_WEIGHTS, _N, _DETA, c_xi)
              - np.einsum("q,qa,qb,fqik->faibk", TRI_WEIGHTS, _N, _DXI, c_eta))
    blocks = blocks.reshape(F, 18, 18) * face_pressure[:, None, None]
    rows = np.broadcast_to(dofs[:, :, None], blocks.shape).ravel()
    cols = np.broadcast_to(dofs[:, None, :], blocks.shape).ravel()
    return f, sp.csr_matrix((blocks.ravel(), (rows, cols)), shape=(n_dof, n_dof))
