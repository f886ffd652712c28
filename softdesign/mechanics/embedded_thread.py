"""A thread embedded in the host elements: fibres whose points are interpolated by the 10-node tetrahedra's
shape functions, wherever the thread runs (no mesh node need lie on it).

Formulation
    The thread is a polyline through the material (the backbone: the
    body's centerline at rest).  It is cut into pieces at most ``piece_mm``
    long; each piece is one fibre, its one point the piece's middle X,
    located in the element e that holds it (barycentric coordinates L).
    The fibre vector there is the host's deformation carried along the
    piece's unit tangent t:

        a = F t = sum_b (dN_b/dX(L) . t) x_b          (b over e's ten nodes)

    so ``D_b = dN_b/dX . t``, and ``A = sum_b D_b X_b = t`` exactly (the
    shape functions reproduce linear fields).  Its energy is the hoop
    thread's law (:mod:`softdesign.mechanics.reinforcement`: Green strain e
    along t, stiffness ``E_t A_t``, compression up to the Winkler buckling
    strain) times the piece's length: the midpoint rule along the thread.
    This is the embedded-reinforcement (rebar) formulation of finite
    elements; a thread on the nodes' chain (:mod:`softdesign.mechanics.backbone`)
    is its special case where the pieces are the elements' edges.
Assumptions
    The thread is bonded to the silicone (no slip), straight between its
    polyline's points, thin (its bending stiffness is left out, as the rod
    model leaves it), and its strain is the host's along it (no shear lag).
    The midpoint rule is exact for a uniform strain; a piece that straddles
    two elements takes its middle's element's strain, an error that falls
    with ``piece_mm``.
Storage
    As :class:`~softdesign.mechanics.reinforcement.FibreMembrane`, with ten
    node slots per fibre instead of six (it is written for any number of
    slots), and the hoop thread's rule of one point per fibre (its weight the
    piece's length), so that both join in one set.  :class:`ThreadFibres` holds
    the hoop thread's six-slot fibres beside them (the six padded to ten
    with weightless slots) and assembles each kind at its own width.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from softdesign.errors import MeshError
from softdesign.mechanics import reinforcement
from softdesign.mechanics.quadratic import QuadraticMesh, curved_barycentric, curved_gradients_at
from softdesign.mechanics.reinforcement import FibreMembrane, HoopThread
from softdesign.mechanics.section import locate
from softdesign.mechanics.tets import TetMesh, make_tet_mesh
from softdesign.types import FloatArray, IntArray

#: Node slots of a fibre in a 10-node tetrahedron.
SLOTS = 10
#: Node slots of the hoop thread's fibres on 6-node faces.
FACE_SLOTS = 6
#: Thread points located per batch (each batch holds an (n, E, 4) array of barycentric coordinates).
LOCATE_BATCH = 16


def quadratic_gradients_at(linear_grads: FloatArray, bary: FloatArray) -> FloatArray:
    """``dN/dX`` (n, 10, 3) 1/mm of the 10-node tetrahedron at barycentric points ``bary`` (n, 4), from the
    element's corner gradients ``linear_grads`` (n, 4, 3) (node order of :class:`QuadraticMesh`'s cells)."""
    from softdesign.mechanics.quadratic import TET_EDGES

    corners = (4.0 * bary - 1.0)[:, :, None] * linear_grads
    i, j = TET_EDGES[:, 0], TET_EDGES[:, 1]
    edges = 4.0 * (bary[:, i, None] * linear_grads[:, j] + bary[:, j, None] * linear_grads[:, i])
    return np.concatenate([corners, edges], axis=1)


def thread_pieces(polyline: FloatArray, piece_mm: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The polyline (n, 3) mm cut into pieces at most ``piece_mm`` long: their middles (k, 3) mm, unit tangents
    (k, 3) and lengths (k,) mm (MeshError when two consecutive points coincide)."""
    polyline = np.asarray(polyline, float)
    steps = np.diff(polyline, axis=0)
    lengths = np.linalg.norm(steps, axis=1)
    if not (piece_mm > 0 and np.all(lengths > 0)):
        raise MeshError("embedded thread: its polyline's consecutive points must differ and pieces be > 0 mm long")
    counts = np.maximum(1, np.ceil(lengths / piece_mm).astype(np.int64))
    segment = np.repeat(np.arange(len(steps)), counts)
    within = (np.concatenate([np.arange(c) for c in counts]) + 0.5) / counts[segment]
    middles = polyline[segment] + within[:, None] * steps[segment]
    return middles, steps[segment] / lengths[segment, None], lengths[segment] / counts[segment]


def embedded_fibres(mesh: QuadraticMesh, polyline: FloatArray, thread: HoopThread, matrix_modulus_kpa: float,
                    piece_mm: float, elements: IntArray | None = None) -> ThreadFibres:
    """The thread along ``polyline`` (n, 3) mm, reference frame, as fibres embedded in ``mesh`` (module docstring).

    ``elements``: the elements to search (default all; a device passes one section's, so that a point on a
    joint's plane is held by the section the piece belongs to).

    Raises
    ------
    MeshError
        A piece's middle lies in no element (the thread leaves the material).
    """
    middles, tangents, lengths = thread_pieces(polyline, piece_mm)
    pool = np.arange(len(mesh.cells)) if elements is None else np.asarray(elements, np.int64)
    sub = _sub_mesh(mesh, pool)
    found = [locate(sub, middles[k:k + LOCATE_BATCH]) for k in range(0, len(middles), LOCATE_BATCH)]
    host = pool[np.concatenate([e for e, _ in found])]
    bary = np.concatenate([b for _, b in found])
    if mesh.curved_volumes is None:
        grads = quadratic_gradients_at(mesh.linear.grads[host], bary)  # (k, 10, 3)
    else:  # curved hosts (softdesign.mechanics.curved_walls): the points and gradients of their quadratic maps
        bary = curved_barycentric(mesh, host, bary, middles)
        grads = curved_gradients_at(mesh, host, bary)
    d = np.einsum("kbi,ki->kb", grads, tangents)
    q = len(reinforcement.FIBRE_WEIGHTS)  # the hoop thread's rule's count and kind, so that both sets join
    count = len(middles)
    reference = np.einsum("kb,kbi->ki", d, mesh.points[mesh.cells[host]])  # t, to rounding
    weights = np.zeros((count, q))
    weights[:, 0] = lengths  # the law at point 0, whatever the rule: the other points are copies of it
    return ThreadFibres(mesh.cells[host], np.repeat(d[:, None, :], q, axis=1),
                        np.repeat(reference[:, None, :], q, axis=1), weights,
                        np.full(count, thread.axial_stiffness_mn), np.full(count, thread.axial_stiffness_mn),
                        np.full(count, thread.buckling_strain(matrix_modulus_kpa)),
                        reinforcement.anchored_rule())


def _sub_mesh(mesh: QuadraticMesh, pool: IntArray) -> TetMesh:
    """The corner mesh of the elements ``pool`` (their indices in ``mesh``, in that order), for locating points."""
    used, inverse = np.unique(mesh.linear.tets[pool], return_inverse=True)
    return make_tet_mesh(mesh.linear.points[used], inverse.reshape(-1, 4))


@dataclass(frozen=True)
class ThreadFibres(FibreMembrane):
    """Fibres with up to ten node slots: the hoop thread's (six, padded with weightless slots) and the embedded
    thread's (ten), in one set; the force and tangent are assembled at each fibre's own width."""

    def force_and_tangent_at(self, displacement: FloatArray, want_tangent: bool, strain: FloatArray | None = None
                             ) -> tuple[FloatArray, sp.csr_matrix | None]:
        """:meth:`FibreMembrane.force_and_tangent_at`, each kind of fibre at its own width."""
        narrow = ~np.any(self.directions[:, :, FACE_SLOTS:] != 0.0, axis=(1, 2))
        n = displacement.size
        force, tangent = np.zeros(n), sp.csr_matrix((n, n)) if want_tangent else None
        for rows, width in ((np.flatnonzero(narrow), FACE_SLOTS), (np.flatnonzero(~narrow), SLOTS)):
            if rows.size:
                part = FibreMembrane(self.faces[rows, :width], self.directions[rows, :, :width], self.reference[rows],
                                     self.weights[rows], self.stiffness[rows], self.axial_stiffness_mn[rows],
                                     self.buckling_strain[rows], self.anchored)
                f, k = part.force_and_tangent_at(displacement, want_tangent, None if strain is None else strain[rows])
                force += f
                if tangent is not None and k is not None:
                    tangent = tangent + k
        return force, tangent


def thread_fibres(sets: Sequence[FibreMembrane | None]) -> ThreadFibres | None:
    """The fibre sets (six or ten slots each; None: none) as one :class:`ThreadFibres`, in order."""
    present = [s for s in sets if s is not None]
    if not present:
        return None
    if len({s.anchored for s in present}) > 1:
        raise ValueError("fibre sets to join must share one rule (all anchored or none)")
    keys = ("faces", "directions", "reference", "weights", "stiffness", "axial_stiffness_mn", "buckling_strain")
    parts: dict[str, list[np.ndarray]] = {k: [] for k in keys}
    for s in present:
        pad = SLOTS - s.faces.shape[1]
        parts["faces"].append(np.concatenate([s.faces, np.repeat(s.faces[:, :1], pad, axis=1)], axis=1))
        parts["directions"].append(np.concatenate([s.directions, np.zeros(s.directions.shape[:2] + (pad,))], axis=2))
        for k in ("reference", "weights", "stiffness", "axial_stiffness_mn", "buckling_strain"):
            parts[k].append(getattr(s, k))
    return ThreadFibres(**{k: np.concatenate(v) for k, v in parts.items()}, anchored=present[0].anchored)
