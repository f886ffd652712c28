"""The seed's POE split of a link transform (the SE(3) basics it uses are :mod:`softdesign.geometry.se3`).

The POE split of a link transform ``S_T_E = [[R, p], [0, 1]]`` (seed 000):

    S_T_E = exp(xi1 theta1) exp(xi2 theta2)
          = [[I, theta1 * xi1], [0, 1]] @ [[R, 0], [0, 1]]

``xi1`` is a prismatic twist (unit direction, no rotation) expressed in {S},
``theta1 = |p| = |c(l_e) - c(l_s)|`` (a rotation keeps lengths); ``xi2`` is a
pure rotation about the unit axis ``omega`` through {S}'s origin, ``theta2``
its angle in [0, pi].  Read right to left on a point of {E}: first rotate about
{S}'s origin, then translate; read left to right as moves of a frame: first
slide {S} by ``theta1 * xi1`` (along its own axes) to {E}'s origin, then turn it
about ``omega`` (now through {E}'s origin).  The product is exact, so the split
reproduces ``S_T_E`` to rounding.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.geometry.se3 import axis_angle_from_rotation, check_pose, rotation_from_rotvec
from softdesign.types import FloatArray, Pose

#: Translation length below which the direction xi1 is undefined and reported as None, mm.
TRANSLATION_ZERO_TOL = 1e-12


@dataclass(frozen=True)
class PoeSplit:
    """The seed's POE parameters of one link transform.

    Attributes
    ----------
    theta1 : float, mm -- translation length, >= 0
    xi1 : (3,) float or None -- unit translation direction in {S}; None when theta1 == 0
    theta2 : float, rad -- rotation angle in [0, pi]
    omega : (3,) float or None -- unit rotation axis in {S}; None when theta2 == 0
    """

    theta1: float
    xi1: FloatArray | None
    theta2: float
    omega: FloatArray | None


def poe_from_pose(pose: npt.ArrayLike) -> PoeSplit:
    """The seed's POE split of a link transform ``S_T_E`` (4, 4); see the module docstring."""
    pose = check_pose(pose)
    p = pose[:3, 3]
    theta1 = float(np.linalg.norm(p))
    xi1 = None if theta1 < TRANSLATION_ZERO_TOL else p / theta1
    omega, theta2 = axis_angle_from_rotation(pose[:3, :3])
    return PoeSplit(theta1 if xi1 is not None else 0.0, xi1, theta2, omega)


def pose_from_poe(split: PoeSplit) -> Pose:
    """``exp(xi1 theta1) @ exp(xi2 theta2)`` as a (4, 4) pose (a None axis or direction is identity)."""
    translate = np.eye(4)
    if split.xi1 is not None:
        translate[:3, 3] = split.theta1 * np.asarray(split.xi1, float)
    rotate = np.eye(4)
    if split.omega is not None:
        rotate[:3, :3] = rotation_from_rotvec(np.asarray(split.omega, float) * split.theta2)
    return translate @ rotate
