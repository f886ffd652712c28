"""SE(3) and SO(3) basics: skew and vee, exponential and logarithm, the inverse of a rigid transform.

Conventions (DESIGN.md): a pose is a (4, 4) homogeneous transform; a twist is
``(v, omega)`` (6,), translation part first, so that ``pose_from_twist`` is the
SE(3) exponential of ``[[hat(omega), v], [0, 0]]``; a rotation vector is
``omega * theta`` (3,), radians.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from softdesign.errors import GeometryError
from softdesign.types import FloatArray, Pose

#: Rotation angle below which the axis is undefined and reported as None, rad.
ROTATION_ZERO_TOL = 1e-12
#: How far from a rotation matrix an input may be (max |R^T R - I|) before it is refused.
ORTHONORMAL_TOL = 1e-6


def skew_from_vector(w: npt.ArrayLike) -> FloatArray:
    """``hat(w)``: (..., 3) -> (..., 3, 3) with ``hat(w) @ x == cross(w, x)``."""
    w = np.asarray(w, float)
    out = np.zeros(w.shape + (3,))
    out[..., 0, 1], out[..., 0, 2] = -w[..., 2], w[..., 1]
    out[..., 1, 0], out[..., 1, 2] = w[..., 2], -w[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -w[..., 1], w[..., 0]
    return out


def vector_from_skew(m: npt.ArrayLike) -> FloatArray:
    """``vee(M)`` of the skew part of (..., 3, 3) -> (..., 3)."""
    m = np.asarray(m, float)
    return 0.5 * np.stack(
        [m[..., 2, 1] - m[..., 1, 2], m[..., 0, 2] - m[..., 2, 0], m[..., 1, 0] - m[..., 0, 1]], axis=-1
    )


def _rodrigues_coefficients(theta: FloatArray | np.floating) -> tuple[FloatArray, FloatArray, FloatArray]:
    """sin(t)/t, (1 - cos t)/t^2, (t - sin t)/t^3, with series where t is small."""
    small = theta < 1e-4
    t = np.where(small, 1.0, theta)
    t2 = theta * theta
    a = np.where(small, 1.0 - t2 / 6.0 + t2 * t2 / 120.0, np.sin(t) / t)
    b = np.where(small, 0.5 - t2 / 24.0 + t2 * t2 / 720.0, 2.0 * np.sin(0.5 * t) ** 2 / (t * t))
    c = np.where(small, 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0, (t - np.sin(t)) / (t * t * t))
    return a, b, c


def rotation_from_rotvec(rotvec: npt.ArrayLike) -> FloatArray:
    """SO(3) exponential: rotation vector (..., 3), rad -> rotation matrices (..., 3, 3)."""
    rotvec = np.asarray(rotvec, float)
    theta = np.linalg.norm(rotvec, axis=-1)
    a, b, _ = _rodrigues_coefficients(theta)
    k = skew_from_vector(rotvec)
    return np.eye(3) + a[..., None, None] * k + b[..., None, None] * (k @ k)


def axis_angle_from_rotation(rotation: npt.ArrayLike) -> tuple[FloatArray | None, float]:
    """Unit axis and angle in [0, pi] of one rotation matrix.

    The angle is the seed's ``acos((trace(R) - 1) / 2)``, evaluated as
    ``atan2(|vee(R - R^T)| / 2, (trace(R) - 1) / 2)`` so that it stays accurate
    near 0 and pi.  The axis comes from the skew part ``(R - R^T) / (2 sin)``
    below pi/2 and from the symmetric part ``(R + R^T) / 2 - cos I`` above
    (where ``sin`` vanishes), its sign taken from the skew part.

    Parameters
    ----------
    rotation : (3, 3) float, orthonormal with det +1

    Returns
    -------
    axis : (3,) float or None -- None when the angle is below ROTATION_ZERO_TOL
    angle : float, rad in [0, pi] (0.0 exactly when the axis is None)
    """
    r = check_rotation(rotation)
    skew = vector_from_skew(r)
    cos_t = 0.5 * (np.trace(r) - 1.0)
    theta = float(np.arctan2(np.linalg.norm(skew), cos_t))
    if theta < ROTATION_ZERO_TOL:
        return None, 0.0
    if theta < 0.5 * np.pi:
        return skew / np.linalg.norm(skew), theta
    outer = (0.5 * (r + r.T) - cos_t * np.eye(3)) / (1.0 - cos_t)
    column = int(np.argmax(np.diag(outer)))
    axis = outer[:, column] / np.sqrt(outer[column, column])
    axis /= np.linalg.norm(axis)
    if float(axis @ skew) < 0.0:
        axis = -axis
    return axis, theta


def rotvec_from_rotation(rotation: npt.ArrayLike) -> FloatArray:
    """SO(3) logarithm: (3, 3) rotation -> rotation vector (3,), angle in [0, pi]."""
    axis, theta = axis_angle_from_rotation(rotation)
    return np.zeros(3) if axis is None else axis * theta


def pose_from_twist(twist: npt.ArrayLike) -> Pose:
    """SE(3) exponential of a twist ``(v, omega)`` (6,): v in mm, omega in rad -> (4, 4)."""
    twist = np.asarray(twist, float)
    if twist.shape != (6,):
        raise GeometryError(f"pose_from_twist: expected a twist of shape (6,) as (v, omega), got {twist.shape}")
    v, w = twist[:3], twist[3:]
    _, b, c = _rodrigues_coefficients(np.linalg.norm(w))
    k = skew_from_vector(w)
    pose = np.eye(4)
    pose[:3, :3] = rotation_from_rotvec(w)
    pose[:3, 3] = (np.eye(3) + b * k + c * (k @ k)) @ v
    return pose


def twist_from_pose(pose: npt.ArrayLike) -> FloatArray:
    """SE(3) logarithm: (4, 4) pose -> twist ``(v, omega)`` (6,), rotation angle in [0, pi]."""
    pose = check_pose(pose)
    w = rotvec_from_rotation(pose[:3, :3])
    theta = float(np.linalg.norm(w))
    k = skew_from_vector(w)
    # d = (1 - t sin t / (2 (1 - cos t))) / t^2 = (1 - (t/2) cot(t/2)) / t^2, series when small
    if theta < 1e-3:
        d = 1.0 / 12.0 + theta**2 / 720.0 + theta**4 / 30240.0
    else:
        half = 0.5 * theta
        d = (1.0 - half * np.cos(half) / np.sin(half)) / theta**2
    v = (np.eye(3) - 0.5 * k + d * (k @ k)) @ pose[:3, 3]
    return np.concatenate([v, w])


def inverse_pose(pose: npt.ArrayLike) -> Pose:
    """Exact inverse of rigid transforms (..., 4, 4): ``[[R^T, -R^T p], [0, 1]]``."""
    pose = np.asarray(pose, float)
    out = np.zeros_like(pose)
    rt = np.swapaxes(pose[..., :3, :3], -1, -2)
    out[..., :3, :3] = rt
    out[..., :3, 3] = -(rt @ pose[..., :3, 3, None])[..., 0]
    out[..., 3, 3] = 1.0
    return out


def check_rotation(rotation: npt.ArrayLike) -> FloatArray:
    """The (3, 3) float array of ``rotation``; GeometryError unless it is finite, orthonormal and det +1."""
    r = np.asarray(rotation, float)
    if r.shape != (3, 3) or not np.all(np.isfinite(r)):
        raise GeometryError(f"rotation: expected a finite (3, 3) matrix, got shape {r.shape}")
    err = float(np.abs(r.T @ r - np.eye(3)).max())
    if err > ORTHONORMAL_TOL or np.linalg.det(r) < 0.0:
        raise GeometryError(
            f"rotation: expected an orthonormal matrix with det +1, got max|R^T R - I| = {err:.3g}, "
            f"det = {np.linalg.det(r):.6g}; re-orthonormalize the frames that produced it"
        )
    return r


def check_pose(pose: npt.ArrayLike) -> Pose:
    """The (4, 4) float array of ``pose``; GeometryError unless its rotation block passes :func:`check_rotation`."""
    pose = np.asarray(pose, float)
    if pose.shape != (4, 4):
        raise GeometryError(f"pose: expected a (4, 4) homogeneous transform, got shape {pose.shape}")
    check_rotation(pose[:3, :3])
    return pose
