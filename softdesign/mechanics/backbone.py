"""The backbone thread (``actuation.backbone: inextensible``) as a chain of fibres along the body's axis.

The thread is cast along the centerline, where every cross-section of the
swept mesh has a node: it runs through the axis's nodes (corners and the
midpoints between them), each piece between two consecutive nodes a straight
fibre of the thread's axial stiffness ``E_t A_t``.  It is written as the
hoop thread's fibres (:class:`~softdesign.mechanics.reinforcement.FibreMembrane`):
a piece from node a to node b of rest length L has the fibre vector
``(x_b - x_a) / L`` (its stretch), weight L (its length, where the membrane's
is an area) and stiffness ``E_t A_t`` (where the membrane's is per unit
width), so its energy is ``E_t A_t L e^2 / 2`` with the Green strain e, and
it takes compression up to its buckling strain on the silicone as the hoop
thread does (Winkler's foundation).  Its bending stiffness is left out, as
the rod model leaves it out.
"""

from __future__ import annotations

import numpy as np

from softdesign.errors import MeshError
from softdesign.mechanics.quadratic import QuadraticMesh, midpoint_nodes
from softdesign.mechanics.reinforcement import FIBRE_WEIGHTS, FibreMembrane, HoopThread
from softdesign.types import IntArray


def axis_chain(mesh: QuadraticMesh, corners: IntArray) -> IntArray:
    """The axis's nodes (n,) base to tip: the corners ``corners`` (k,) in order, with each edge's midpoint between.

    Raises MeshError when two consecutive corners share no edge (the thread would cut through elements).
    """
    pairs = np.column_stack([corners[:-1], corners[1:]])
    sorted_pairs = np.sort(pairs, axis=1)
    keys = mesh.edges[:, 0] * len(mesh.linear.points) + mesh.edges[:, 1]
    if not np.isin(sorted_pairs[:, 0] * len(mesh.linear.points) + sorted_pairs[:, 1], keys).all():
        raise MeshError("device mesh: the axis's nodes are not joined by edges; the backbone thread needs them")
    middles = midpoint_nodes(mesh, pairs)
    chain = np.empty(2 * len(corners) - 1, np.int64)
    chain[0::2], chain[1::2] = corners, middles
    return chain


def backbone_fibres(mesh: QuadraticMesh, chains: list[IntArray], thread: HoopThread,
                    matrix_modulus_kpa: float) -> FibreMembrane:
    """The thread along each chain of axis nodes (one per section, base to tip) as fibres (module docstring)."""
    a = np.concatenate([c[:-1] for c in chains])
    b = np.concatenate([c[1:] for c in chains])
    length = np.linalg.norm(mesh.points[b] - mesh.points[a], axis=1)
    if np.any(length <= 0.0):
        raise MeshError("device mesh: two consecutive axis nodes coincide; the backbone thread needs distinct nodes")
    q = len(FIBRE_WEIGHTS)
    faces = np.column_stack([a, b, a, a, a, a])  # the fibres' 6 slots: a and b carry it, the rest weigh nothing
    directions = np.zeros((len(a), q, 6))
    directions[:, :, 0] = -1.0 / length[:, None]
    directions[:, :, 1] = 1.0 / length[:, None]
    count = len(a)
    unit = (mesh.points[b] - mesh.points[a]) / length[:, None]
    reference = np.repeat(unit[:, None, :], q, axis=1)  # A = sum_b D_b X_b: the unit fibre at rest
    return FibreMembrane(faces, directions, reference, np.repeat(length[:, None] / q, q, axis=1),
                         np.full(count, thread.axial_stiffness_mn), np.full(count, thread.axial_stiffness_mn),
                         np.full(count, thread.buckling_strain(matrix_modulus_kpa)))


def joined(first: FibreMembrane | None, second: FibreMembrane) -> FibreMembrane:
    """Both sets of fibres as one (``first`` may be None)."""
    if first is None:
        return second
    return FibreMembrane(*(np.concatenate([getattr(first, k), getattr(second, k)])
                           for k in ("faces", "directions", "reference", "weights", "stiffness", "axial_stiffness_mn",
                                     "buckling_strain")))
