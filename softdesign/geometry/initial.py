"""The insertion shape at q = 0: straight, a circular arc, or another centerline.

Every shape is sampled on the final shape's l grid (the same sample count), so
its spline shares the final shape's knot vector and blends are exact on the
coefficients.  By default it is rigidly registered to the final shape: its
base point is c_f(0) and its base tangent is T_f(0), so the base of the
actuator stays put while it morphs.

Roll about the base tangent, deterministic in every case:

* straight: no roll to choose;
* arc: the bending direction is ``cos(phi) N0 + sin(phi) B0`` with (N0, B0) the
  final shape's base frame (N0 from ``base_normal``, by default the
  deterministic rule of :func:`frames.base_normal_from_tangent`);
* file: the smallest rotation taking its base tangent onto T_f(0) (a shape
  drawn in the patient's coordinates keeps its orientation), then ``roll_rad``
  about T_f(0).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt

from softdesign.errors import ConfigError
from softdesign.geometry.curves import CurveOptions, SmoothCurve, smooth_curve_from_polyline, smooth_curve_from_samples
from softdesign.geometry.frames import base_normal_from_tangent, frame_from_tangent
from softdesign.geometry.se3 import rotation_from_rotvec
from softdesign.types import FloatArray, Points

InitialKind = Literal["straight", "arc", "file"]


@dataclass(frozen=True)
class InitialSpec:
    """The q = 0 shape, as the case file's ``initial:`` gives it (lengths mm, angles rad).

    Attributes
    ----------
    kind : "straight" | "arc" | "file"
    length_mm : straight/arc length; default the final shape's length
    bend_radius_mm : arc radius of curvature (kind "arc")
    bend_plane_rad : arc bending-plane angle from the final shape's base normal N0 towards B0
    points : (n, 3) mm, the q = 0 centerline (kind "file")
    align_base : register base point and tangent onto the final shape's
    roll_rad : extra roll about the base tangent (kind "file")
    """

    kind: InitialKind = "straight"
    length_mm: float | None = None
    bend_radius_mm: float | None = None
    bend_plane_rad: float = 0.0
    points: Points | None = None
    align_base: bool = True
    roll_rad: float = 0.0


def build_initial_shape(
    final: SmoothCurve,
    spec: InitialSpec = InitialSpec(),
    options: CurveOptions = CurveOptions(),
    base_normal: npt.ArrayLike | None = None,
) -> SmoothCurve:
    """The q = 0 curve for ``spec``, on ``final``'s l grid.

    Parameters
    ----------
    final : the patient's shape (q = 1)
    spec : what the case file asks for
    options : smoothing and end handling for kind "file" (its count is set to final's)
    base_normal : (3,) reference for the final shape's base normal N0; default the deterministic rule

    Raises
    ------
    ConfigError
        A missing or invalid parameter for the kind.
    """
    if spec.kind == "straight":
        return straight_initial_shape(final, spec.length_mm)
    if spec.kind == "arc":
        if spec.bend_radius_mm is None:
            raise ConfigError("initial.kind: arc needs initial.bend_radius_mm (the arc's radius, mm)")
        return arc_initial_shape(final, spec.bend_radius_mm, spec.bend_plane_rad, spec.length_mm, base_normal)
    if spec.kind == "file":
        if spec.points is None:
            raise ConfigError("initial.kind: file needs initial.centerline (a path to the q = 0 centerline)")
        if spec.length_mm is not None:
            raise ConfigError(
                f"initial.length_mm = {spec.length_mm:g} applies to kind straight or arc; a kind: file shape "
                "keeps the length of its centerline - remove length_mm"
            )
        return initial_shape_from_polyline(final, spec.points, options, spec.align_base, spec.roll_rad)
    raise ConfigError(f"initial.kind must be one of straight, arc, file, got {spec.kind!r}")


def straight_initial_shape(final: SmoothCurve, length_mm: float | None = None) -> SmoothCurve:
    """A straight line from c_f(0) along T_f(0), ``length_mm`` long (default final's length)."""
    length = _checked_length(final, length_mm)
    base, tangent = final.points([0.0])[0], final.tangents([0.0])[0]
    return smooth_curve_from_samples(base + np.outer(final.l_grid * length, tangent), final.joints)


def arc_initial_shape(
    final: SmoothCurve,
    bend_radius_mm: float,
    bend_plane_rad: float = 0.0,
    length_mm: float | None = None,
    base_normal: npt.ArrayLike | None = None,
) -> SmoothCurve:
    """A circular arc from c_f(0), tangent T_f(0), bending towards cos(phi) N0 + sin(phi) B0.

    Parameters
    ----------
    final : the patient's shape
    bend_radius_mm : radius of curvature, mm (> 0)
    bend_plane_rad : phi, rad, measured from the final shape's base normal N0 towards B0
    length_mm : arc length, mm; default the final shape's length (at most one full turn)
    base_normal : (3,) reference for N0; default the deterministic rule
    """
    length = _checked_length(final, length_mm)
    if not bend_radius_mm > 0.0:
        raise ConfigError(f"initial.bend_radius_mm must be > 0 mm, got {bend_radius_mm}")
    if length > 2.0 * np.pi * bend_radius_mm:
        raise ConfigError(
            f"initial: an arc of length {length:.4g} mm and radius {bend_radius_mm:g} mm turns more than "
            f"once and runs through itself; use bend_radius_mm >= {length / (2.0 * np.pi):.4g} mm"
        )
    base, tangent = final.points([0.0])[0], final.tangents([0.0])[0]
    reference = base_normal_from_tangent(tangent) if base_normal is None else base_normal
    frame = frame_from_tangent(tangent, reference)
    towards = np.cos(bend_plane_rad) * frame[:, 0] + np.sin(bend_plane_rad) * frame[:, 1]
    angle = final.l_grid * length / bend_radius_mm
    # 1 - cos written as 2 sin^2(x/2) to keep it exact for small angles
    along = bend_radius_mm * np.sin(angle)
    across = 2.0 * bend_radius_mm * np.sin(0.5 * angle) ** 2
    return smooth_curve_from_samples(base + np.outer(along, tangent) + np.outer(across, towards), final.joints)


def initial_shape_from_polyline(
    final: SmoothCurve,
    points: npt.ArrayLike,
    options: CurveOptions = CurveOptions(),
    align_base: bool = True,
    roll_rad: float = 0.0,
) -> SmoothCurve:
    """Another centerline (mm) resampled on final's grid; registered to final's base unless told not to.

    Also serves intermediate keyframe shapes.
    """
    count_options = CurveOptions(options.spacing_mm, len(final.l_grid), options.smoothing_mm, options.end_straight_mm)
    shape = smooth_curve_from_polyline(points, count_options)
    if final.joints:  # on final's knots, so that the shapes blend on their coefficients
        shape = smooth_curve_from_samples(shape.points(shape.l_grid), final.joints)
    if not align_base:
        return shape
    return register_to_base(shape, final.points([0.0])[0], final.tangents([0.0])[0], roll_rad)


def register_to_base(
    curve: SmoothCurve, base_point: npt.ArrayLike, base_tangent: npt.ArrayLike, roll_rad: float = 0.0
) -> SmoothCurve:
    """Rigidly move ``curve`` so that c(0) = base_point and T(0) = base_tangent.

    The rotation is the smallest one taking T(0) onto ``base_tangent``, then
    ``roll_rad`` about ``base_tangent``; B-spline coefficients transform with
    the points, so the result is exact.
    """
    target = np.asarray(base_tangent, float).reshape(3)
    target = target / np.linalg.norm(target)
    rotation = rotation_from_rotvec(roll_rad * target) @ _smallest_rotation(curve.tangents([0.0])[0], target)
    origin = curve.points([0.0])[0]
    samples = (curve.points(curve.l_grid) - origin) @ rotation.T + np.asarray(base_point, float).reshape(3)
    return smooth_curve_from_samples(samples, curve.joints)


def _smallest_rotation(a: FloatArray, b: FloatArray) -> FloatArray:
    """Rotation (3, 3) about a x b taking unit a onto unit b (pi about a normal of a if opposite)."""
    axis = np.cross(a, b)
    sin_t, cos_t = np.linalg.norm(axis), float(a @ b)
    if sin_t < 1e-12 and cos_t < 0.0:
        return rotation_from_rotvec(np.pi * base_normal_from_tangent(a))
    if sin_t < 1e-300:
        return np.eye(3)
    return rotation_from_rotvec(axis / sin_t * np.arctan2(sin_t, cos_t))


def _checked_length(final: SmoothCurve, length_mm: float | None) -> float:
    if length_mm is None:
        return float(final.length)
    if not length_mm > 0.0:
        raise ConfigError(f"initial.length_mm must be > 0 mm, got {length_mm}")
    return float(length_mm)
