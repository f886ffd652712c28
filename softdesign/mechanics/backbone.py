"""The backbone thread (``actuation.backbone: inextensible``) along the body's axis, embedded in the elements.

The thread is cast along the centerline.  It runs along each section's
reference centerline (the layers' centres, in the device's frame) and is
embedded in that section's 10-node tetrahedra
(:mod:`softdesign.mechanics.embedded_thread`): each piece's strain is the
host's along the thread, its energy ``E_t A_t L e^2 / 2`` with the Green
strain e, compression taken up to its buckling strain on the silicone as the
hoop thread does (Winkler's foundation).  Its bending stiffness is left out,
as the rod model leaves it out.

Why embedded, not a chain of nodes: the swept mesher puts a node on the axis
only when the cross-section's points happen to include the centre; a chamber
near the axis (the aorta's 3.9 mm chamber in its section 2) or an
area-matched polygon moves the points round it, and the axis then has no
node (the device was refused).  Embedded, the thread needs none.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from softdesign.mechanics.embedded_thread import ThreadFibres, embedded_fibres, thread_fibres
from softdesign.mechanics.quadratic import QuadraticMesh
from softdesign.mechanics.reinforcement import HoopThread
from softdesign.types import FloatArray, IntArray

#: Pieces of the thread per step between two layers: the midpoint rule along it, each piece's strain its host's
#: at its middle; 4 keeps a piece within about one element along a layer step (the elements are a layer long).
PIECES_PER_LAYER = 4


def backbone_fibres(mesh: QuadraticMesh, centerlines: Sequence[FloatArray], elements: Sequence[IntArray],
                    thread: HoopThread, matrix_modulus_kpa: float) -> ThreadFibres:
    """The thread along each section's ``centerlines`` (n_i, 3) mm, embedded in its ``elements`` (the section's
    element indices in ``mesh``), as one set of ten-slot fibres, base to tip.

    Raises
    ------
    MeshError
        A piece of the thread lies in no element of its section (it leaves the material).
    """
    sets = []
    for line, pool in zip(centerlines, elements, strict=True):
        step = float(np.min(np.linalg.norm(np.diff(line, axis=0), axis=1)))
        sets.append(embedded_fibres(mesh, line, thread, matrix_modulus_kpa, step / PIECES_PER_LAYER, pool))
    joined = thread_fibres(sets)
    assert joined is not None  # one set per section, and a device has one at least
    return joined
