"""Seed 003's lengths <-> arc relation for chambers at any first angle (not only 90, 210, 330 degrees).

A section's chambers sit at ``beta_j = beta_0 + 120 j`` degrees from its base
frame's N axis, ``d`` mm from the backbone.  On an arc (kappa, phi, L) chamber j
is ``l_j = L - kappa L d cos(beta_j - phi)`` long (seed eq. 1-2).  With
``beta_0 = 90`` degrees this is :func:`softdesign.kinematics.pcc.lengths_from_arcs`;
for another ``beta_0`` the chambers are the seed's encoders turned by
``beta_0 - 90`` degrees, so the seed's inverse (eq. 3-5) returns ``phi``
less that turn, which is added back here.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softdesign.kinematics import pcc
from softdesign.types import FloatArray

#: The seed's first encoder angle, rad.
SEED_FIRST_ANGLE = float(pcc.ENCODER_ANGLES_RAD[0])


def chamber_lengths_from_arc(kappa: npt.ArrayLike, phi: npt.ArrayLike, length: npt.ArrayLike, d: npt.ArrayLike,
                             first_angle: npt.ArrayLike) -> FloatArray:
    """Lengths (..., 3) mm of the chambers at ``first_angle + 120 j`` (rad) on arcs (...) of (kappa, phi, L)."""
    turn = np.asarray(first_angle, float) - SEED_FIRST_ANGLE
    return pcc.lengths_from_arcs(kappa, np.asarray(phi, float) - turn, length, d)


def arcs_from_chamber_lengths(lengths: npt.ArrayLike, d: npt.ArrayLike, first_angle: npt.ArrayLike
                              ) -> pcc.ArcParameters:
    """(kappa, phi, L, theta) of sections from chamber lengths (..., 3) at ``first_angle + 120 j`` (rad).

    ``phi`` is wrapped to (-pi, pi] and is 0 for a straight section, as :func:`pcc.arcs_from_lengths`.
    """
    arcs = pcc.arcs_from_lengths(lengths, d)
    turn = np.asarray(first_angle, float) - SEED_FIRST_ANGLE
    phi = np.angle(np.exp(1j * (arcs.phi + turn)))
    phi = np.where(arcs.kappa == 0.0, 0.0, phi)
    return pcc.ArcParameters(arcs.kappa, phi, arcs.length, arcs.theta)
