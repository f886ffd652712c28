"""Array aliases and the conventions every module follows, written down once.

Units
    millimetres, radians, 1/mm inside the package.  The case file may declare
    ``units: cm`` or ``units: m`` for its input files; ingest converts.
Curves
    ``l`` is normalized arc length of the *final* shape's centerline in
    [0, 1]; ``q`` in [0, 1] morphs the insertion shape (q = 0) into the
    patient's shape (q = 1).  Points are ``(n, 3)`` float64, proximal
    (inlet, l = 0) to distal.
Frames
    ``(n, 3, 3)`` float64 with columns (N, B, T), so that a frame and its
    origin give the seed's ``F = [[N B T c], [0 0 0 1]]`` directly.
Poses
    ``(4, 4)`` or ``(n, 4, 4)`` homogeneous transforms, named ``A2B`` (maps
    coordinates in A into B): ``tip2base = link1_2base @ tip2link1``.  The
    link transform of the seed is ``S_T_E = inv(F(l_s)) @ F(l_e)`` = ``end2start``.
Meshes
    inside the core a mesh is plain arrays: vertices ``(V, 3)`` float64 and
    faces ``(F, 3)`` int64, counter-clockwise seen from outside.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]

Points = FloatArray  # (n, 3) mm
Frames = FloatArray  # (n, 3, 3) columns N, B, T
Pose = FloatArray  # (4, 4) or (n, 4, 4)

#: Length tolerance for "the same point", mm.
POINT_TOL_MM = 1e-9
#: Curvature below which a Frenet frame is undefined, 1/mm (a 1 km radius).
FRENET_KAPPA_TOL = 1e-6

UNIT_SCALE_TO_MM = {"mm": 1.0, "cm": 10.0, "m": 1000.0}

#: ``mapper(task, items)`` is ``[task(item) for item in items]``, perhaps on other processes (the build's
#: :func:`softdesign.pipeline.parallel.map_items`); the results in the order of ``items``.
Mapper = Callable[[Callable[[Any], Any], Sequence[Any]], list[Any]]


class FramedCurve(Protocol):
    """A smooth centerline with a frame field, parameterized by normalized l.

    Attributes
    ----------
    length : float
        Arc length of the curve, mm.
    """

    @property
    def length(self) -> float:
        """Arc length of the curve, mm (read-only)."""
        ...

    def points(self, l: npt.ArrayLike) -> Points:
        """Positions ``c(l)``, (n, 3) mm, for ``l`` (n,) in [0, 1]."""
        ...

    def derivative(self, l: npt.ArrayLike, order: int = 1) -> Points:
        """``d^k c / dl^k`` (n, 3), mm, with respect to normalized l."""
        ...

    def frames(self, l: npt.ArrayLike) -> Frames:
        """Frames (n, 3, 3), columns (N, B, T), T = c' / |c'|."""
        ...
