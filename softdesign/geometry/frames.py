"""Frames (N, B, T) along a smooth curve: rotation-minimizing (rmf) or Frenet.

``rmf`` is the double-reflection method of Wang, Juettler, Zheng and Liu
(ACM TOG 27(1), 2008) on a dense uniform grid of the curve (steps of at most
``DENSE_STEP_MM``), its global error O(h^4).  Each reflection pair is a
rotation that depends on the curve only, so the frames are a cumulative
product of rotations, computed as a parallel prefix product.  A frame at any
other l is one more double-reflection step from the nearest dense sample.  The
base frame is ``(N0, T0 x N0, T0)`` with N0 a given reference normal projected
off the base tangent, by default the world axis least aligned with T0.

``frenet`` is the seed's: T = c'/|c'|, B = c' x c'' / |c' x c''|, N = B x T.
Where kappa < FRENET_KAPPA_TOL it is undefined and :class:`GeometryError` names
the l range; no normal is made up.

Both modes check that adjacent dense frames differ by a small rotation (no
flips) and report the largest one.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Literal, TypeVar

import numpy as np
import numpy.typing as npt

from softdesign.errors import ConfigError, GeometryError
from softdesign.geometry.curves import SmoothCurve, checked_l
from softdesign.types import FRENET_KAPPA_TOL, FloatArray, Frames, Points, Pose

T = TypeVar("T")

FrameMode = Literal["rmf", "frenet"]
FRAME_MODES = ("rmf", "frenet")
#: Largest rotation between adjacent dense frames (steps <= 0.05 mm) before it counts as a flip, rad.
FLIP_LIMIT_RAD = 0.5
#: A reference normal closer than this (sine of the angle) to the tangent cannot define N0.
PARALLEL_TOL = 1e-6
#: Squared reflection-vector length below which a reflection is the identity (coincident inputs).
REFLECTION_EPS = 1e-30
#: Frames found together: each l's frame is its own, and the (n, 3, 3) temporaries of this many stay in
#: cache (500k frames in one go took ~1.6 times as long).
FRAME_CHUNK = 1 << 14


def base_normal_from_tangent(tangent: npt.ArrayLike) -> FloatArray:
    """Deterministic initial normal (3,): the world axis least aligned with the tangent, projected.

    Ties (e.g. T = z: x and y) go to the lower axis index, so T = z gives N0 = x.
    """
    t = _unit(np.asarray(tangent, float).reshape(3))
    axis = np.zeros(3)
    axis[int(np.argmin(np.abs(t)))] = 1.0
    return _unit(axis - (axis @ t) * t)


def frame_from_tangent(tangent: npt.ArrayLike, reference_normal: npt.ArrayLike) -> FloatArray:
    """Frame (3, 3), columns (N, B, T): N = reference projected off T, B = T x N.

    Raises
    ------
    GeometryError
        The reference normal is (nearly) parallel to the tangent.
    """
    t = _unit(np.asarray(tangent, float).reshape(3))
    n_ref = np.asarray(reference_normal, float).reshape(3)
    n = n_ref - (n_ref @ t) * t
    if np.linalg.norm(n) < PARALLEL_TOL * max(float(np.linalg.norm(n_ref)), 1e-300):
        raise GeometryError(
            f"base frame: the reference normal {n_ref.round(6).tolist()} is parallel to the base tangent "
            f"{t.round(6).tolist()}; give a reference normal at an angle to the tangent"
        )
    n = _unit(n)
    return np.column_stack([n, np.cross(t, n), t])


def reflection_rotations(chords: Points, tangents: Points) -> FloatArray:
    """The double-reflection rotation of each step i -> i+1, (n-1, 3, 3).

    Parameters
    ----------
    chords : (n-1, 3) float, mm, x[i+1] - x[i] between samples of the curve
    tangents : (n, 3) float, unit tangents at the samples
    """
    return reflection_rotations_between(chords, tangents[:-1], tangents[1:])


def reflection_rotations_between(chords: Points, tangents_a: Points, tangents_b: Points) -> FloatArray:
    """Double-reflection rotations (n, 3, 3) from tangents_a to tangents_b across chords (n, 3) mm."""
    h1 = _reflections(chords)
    t_left = np.einsum("nij,nj->ni", h1, tangents_a)
    return _reflections(tangents_b - t_left) @ h1


def taylor_sum(derivatives: Sequence[Points] | FloatArray, dl: FloatArray) -> Points:
    """``sum_k dl^k / k! d^k c / dl^k``, (n, 3) mm, from the derivatives (n, 3) of orders 1, 2, ... at the start
    (a sequence of them, or one (orders, n, 3) array).

    With every order of the spline's pieces this is c(l + dl) - c(l) without cancellation for tiny dl, exact
    while l + dl does not pass a knot (true from a dense sample to anywhere before the next one).
    """
    chord = np.zeros((len(dl), 3))
    power = np.ones(len(dl))
    for order, derivative in enumerate(derivatives, start=1):
        power = power * dl / order
        chord += power[:, None] * derivative
    return chord


def accumulate_rotations(steps: FloatArray, side: Literal["left", "right"]) -> FloatArray:
    """Prefix products of (k, 3, 3) matrices in log2(k) batched rounds.

    ``side="left"``: out[i] = steps[i] @ ... @ steps[0] (world-frame steps);
    ``side="right"``: out[i] = steps[0] @ ... @ steps[i] (body-frame steps).
    """
    out = np.array(steps, float)
    shift = 1
    while shift < len(out):
        if side == "left":
            out[shift:] = out[shift:] @ out[:-shift]
        else:
            out[shift:] = out[:-shift] @ out[shift:]
        shift *= 2
    return out


def adjacent_rotation_angles(frames: Frames) -> FloatArray:
    """Rotation angle between consecutive frames, (n-1,) rad in [0, pi]."""
    relative = np.swapaxes(frames[:-1], 1, 2) @ frames[1:]
    cos_t = 0.5 * (np.trace(relative, axis1=1, axis2=2) - 1.0)
    sin_t = 0.5 * np.linalg.norm(
        np.stack([relative[:, 2, 1] - relative[:, 1, 2], relative[:, 0, 2] - relative[:, 2, 0],
                  relative[:, 1, 0] - relative[:, 0, 1]], axis=1), axis=1)
    return np.arctan2(sin_t, cos_t)


#: The fix for a flip of Frenet frames, and for one of rotation-minimizing frames (already rmf: only the curve helps).
FLIP_FIXES = {
    "frenet": "use frames: rmf, or smooth the centerline more (resample.smoothing_mm)",
    "rmf": "the centerline turns this sharply between two samples: smooth it more (resample.smoothing_mm) "
    "or check the input centerline for a kink there",
}


def check_no_flips(
    frames: Frames, l: FloatArray, label: str, limit_rad: float = FLIP_LIMIT_RAD, why: str = "",
    fix: str = FLIP_FIXES["frenet"],
) -> float:
    """Largest adjacent rotation, rad; GeometryError naming the l interval if it exceeds ``limit_rad``.

    ``why`` is appended to the message (the likely cause for the frame mode), then ``fix``.
    """
    return _largest_step(frames, l, label, limit_rad, why, fix)[0]


def _largest_step(frames: Frames, l: FloatArray, label: str, limit_rad: float, why: str, fix: str
                  ) -> tuple[float, int]:
    """:func:`check_no_flips`' largest adjacent rotation (rad) and the index of the step's first frame."""
    angles = adjacent_rotation_angles(frames)
    worst = int(np.argmax(angles))
    if angles[worst] > limit_rad:
        raise GeometryError(
            f"frames: {label}: adjacent frames at l = {l[worst]:.6f} and {l[worst + 1]:.6f} differ by "
            f"{angles[worst]:.3g} rad (limit {limit_rad:g}): the frame flips there{why}; {fix}"
        )
    return float(angles[worst]), worst


@dataclass(frozen=True)
class FramedSpline:
    """A :class:`SmoothCurve` with its frame field; implements ``types.FramedCurve``.

    Build it with :func:`framed_curve`.  ``dense_l`` (k,) with ``dense_frames``
    (k, 3, 3) are the stored samples; ``max_frame_step`` (rad) is the largest
    rotation between adjacent ones, at ``max_frame_step_l``.
    """

    curve: SmoothCurve
    mode: FrameMode
    label: str
    dense_l: FloatArray
    dense_frames: Frames
    max_frame_step: float
    max_frame_step_l: float

    @property
    def length(self) -> float:
        """Arc length, mm."""
        return self.curve.length

    def points(self, l: npt.ArrayLike) -> Points:
        """Positions c(l), (n, 3) mm."""
        return self.curve.points(l)

    def derivative(self, l: npt.ArrayLike, order: int = 1) -> Points:
        """d^k c / dl^k (n, 3), mm."""
        return self.curve.derivative(l, order)

    def frames(self, l: npt.ArrayLike) -> Frames:
        """Frames (n, 3, 3), columns (N, B, T), T = c'/|c'|, at any l in [0, 1]."""
        l = checked_l(l)
        if self.mode == "frenet":
            return frenet_frames(self.curve, l, self.label)
        if len(l) > FRAME_CHUNK:
            return np.concatenate([self._rmf_frames(l[lo : lo + FRAME_CHUNK]) for lo in range(0, len(l), FRAME_CHUNK)])
        return self._rmf_frames(l)

    def frames_and_derivative(self, l: npt.ArrayLike) -> tuple[Frames, Points]:
        """:meth:`frames` and :meth:`derivative` (order 1) at l, c' evaluated once for both (the frames' unit
        tangents are c' / |c'|): the same numbers as the two calls, one spline evaluation fewer."""
        l = checked_l(l)
        d1 = self.curve.derivative(l)
        if self.mode == "frenet":
            return frenet_frames(self.curve, l, self.label), d1
        tangents = d1 / np.linalg.norm(d1, axis=1, keepdims=True)  # SmoothCurve.tangents' operations
        if len(l) > FRAME_CHUNK:
            return np.concatenate([self._rmf_frames(l[lo : lo + FRAME_CHUNK], tangents[lo : lo + FRAME_CHUNK])
                                   for lo in range(0, len(l), FRAME_CHUNK)]), d1
        return self._rmf_frames(l, tangents), d1

    def _rmf_frames(self, l: FloatArray, tangents: Points | None = None) -> Frames:
        # one double-reflection step from the dense sample at or before l (``tangents``: the unit tangents at l)
        start = np.clip(np.searchsorted(self.dense_l, l, side="right") - 1, 0, len(self.dense_l) - 2)
        dense_tangents, dense_derivatives = self.dense_jets
        tangents = self.curve.tangents(l) if tangents is None else tangents
        # every order's rows in one gather (a third of the time of one per order), each order (n, 3) contiguous
        chords = taylor_sum(np.take(dense_derivatives, start, axis=1), l - self.dense_l[start])
        rotations = reflection_rotations_between(chords, dense_tangents[start], tangents)
        return _orthonormal_with_tangent(rotations @ self.dense_frames[start], tangents)

    @cached_property
    def dense_jets(self) -> tuple[Points, FloatArray]:
        """Unit tangents (k, 3) and the derivatives of orders 1 .. degree (degree, k, 3) at the dense samples.

        Every :meth:`frames` call steps from dense samples: their values are
        found once per curve (the same numbers as at each call, only not again);
        :func:`framed_curve` fills them in from the evaluations its rmf frames are made of.
        """
        orders = range(1, self.curve.spline.k + 1)
        return self.curve.tangents(self.dense_l), np.stack([self.curve.derivative(self.dense_l, k) for k in orders])

    def poses(self, l: npt.ArrayLike) -> Pose:
        """F(l) = [[N B T c], [0 0 0 1]], (n, 4, 4)."""
        return poses_from_frames(self.frames(l), self.points(l))

    def kept(self, key: Hashable, make: Callable[[], T]) -> T:
        """``make()``, made once per ``key`` for this curve and kept with it: figures of the curve alone that
        several stages ask for (the fold check's curvature on its grid, in the blend's look at the body and
        again in the fit).  Kept as :attr:`dense_jets` is (the curve's ``__dict__``), so a curve built on a
        worker process comes back with them; the caller keeps what it gets read-only.
        """
        memo = self.__dict__.setdefault("_kept", {})
        if key not in memo:
            memo[key] = make()
        return memo[key]


def framed_curve(
    curve: SmoothCurve,
    mode: FrameMode = "rmf",
    base_normal: npt.ArrayLike | None = None,
    label: str = "curve",
) -> FramedSpline:
    """Attach rmf or Frenet frames to a curve, checked for flips.

    Parameters
    ----------
    curve : the smooth centerline
    mode : "rmf" (default) or "frenet"
    base_normal : (3,) reference for N at l = 0 (rmf only); default from the base tangent
    label : names the curve in error messages, e.g. "q = 0.5"

    Raises
    ------
    GeometryError
        Frenet where the curvature vanishes (naming the l ranges), or a frame flip.
    """
    if mode not in FRAME_MODES:
        raise ConfigError(f"frames must be one of {', '.join(FRAME_MODES)}, got {mode!r}")
    l = curve.dense_l()
    jets = None
    if mode == "frenet":
        frames = frenet_frames(curve, l, label)
    else:
        frames, jets = _rmf_along(curve, l, base_normal)
    why = " (the Frenet normal reverses where the curvature passes through zero)" if mode == "frenet" else ""
    worst, step = _largest_step(frames, l, f"{mode}, {label}", FLIP_LIMIT_RAD, why, FLIP_FIXES[mode])
    framed = FramedSpline(curve, mode, label, l, frames, worst, float(l[step]))
    if jets is not None:  # the dense samples' jets, as dense_jets would evaluate them again
        framed.__dict__["dense_jets"] = jets
    return framed


def _rmf_along(curve: SmoothCurve, l: FloatArray, base_normal: npt.ArrayLike | None
               ) -> tuple[Frames, tuple[Points, FloatArray]]:
    """Double-reflection frames on the grid l, chords from Taylor sums (exact on dense steps), and the unit
    tangents and derivatives of orders 1 .. degree at l they are made from (:attr:`FramedSpline.dense_jets`).

    Each value is a point's own: the chords' derivatives are those at l without the last, the tangents
    ``SmoothCurve.tangents``' operations on the first derivative, the same numbers as evaluated apart.
    """
    derivatives = [curve.derivative(l, order) for order in range(1, curve.spline.k + 1)]
    tangents = derivatives[0] / np.linalg.norm(derivatives[0], axis=1, keepdims=True)
    reference = base_normal_from_tangent(tangents[0]) if base_normal is None else base_normal
    base = frame_from_tangent(tangents[0], reference)
    chords = taylor_sum([d[:-1] for d in derivatives], np.diff(l))
    steps = accumulate_rotations(reflection_rotations(chords, tangents), "left")
    jets = tangents, np.stack(derivatives)
    return _orthonormal_with_tangent(np.concatenate([base[None], steps @ base]), tangents), jets


def frenet_frames(curve: SmoothCurve, l: npt.ArrayLike, label: str = "curve") -> Frames:
    """Frenet frames (n, 3, 3), columns (N, B, T).

    Raises
    ------
    GeometryError
        kappa < FRENET_KAPPA_TOL somewhere in ``l``: the l ranges are named.
    """
    l = checked_l(l)
    d1, d2 = curve.derivative(l, 1), curve.derivative(l, 2)
    cross = np.cross(d1, d2)
    kappa = np.linalg.norm(cross, axis=1) / np.linalg.norm(d1, axis=1) ** 3
    flat = kappa < FRENET_KAPPA_TOL
    if np.any(flat):
        raise GeometryError(
            f"frames: frenet, {label}: curvature below {FRENET_KAPPA_TOL:g} /mm for l in "
            f"{_ranges_text(l, flat)} (min {kappa.min():.3g} /mm); the Frenet normal is undefined on a "
            "straight run; use frames: rmf (or an initial shape with curvature, initial.kind: arc)"
        )
    t = d1 / np.linalg.norm(d1, axis=1, keepdims=True)
    b = cross / np.linalg.norm(cross, axis=1, keepdims=True)
    return np.stack([np.cross(b, t), b, t], axis=2)


def poses_from_frames(frames: Frames, points: Points) -> Pose:
    """Homogeneous poses (n, 4, 4) [[N B T c], [0 0 0 1]] from frames (n, 3, 3) and origins (n, 3) mm."""
    poses = np.zeros((len(frames), 4, 4))
    poses[:, :3, :3] = frames
    poses[:, :3, 3] = points
    poses[:, 3, 3] = 1.0
    return poses


def _ranges_text(l: FloatArray, mask: npt.NDArray[np.bool_], shown: int = 3) -> str:
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(np.int8), [0]])))
    runs = [(float(l[a]), float(l[b - 1])) for a, b in zip(edges[::2], edges[1::2], strict=True)]
    text = ", ".join(f"[{a:.4f}, {b:.4f}]" for a, b in runs[:shown])
    return text + (f" and {len(runs) - shown} more range(s)" if len(runs) > shown else "")


def _reflections(v: Points) -> FloatArray:
    """Householder reflections I - 2 v v^T / v.v, (n, 3, 3); the identity where v vanishes."""
    norm2 = np.einsum("ni,ni->n", v, v)
    scale = np.where(norm2 > REFLECTION_EPS, 2.0 / np.where(norm2 > REFLECTION_EPS, norm2, 1.0), 0.0)
    return np.eye(3) - scale[:, None, None] * np.einsum("ni,nj->nij", v, v)


def _orthonormal_with_tangent(frames: Frames, tangents: Points) -> Frames:
    """Re-orthonormalize: T column from the analytic tangent, N projected off it, B = T x N."""
    t = tangents / np.linalg.norm(tangents, axis=1, keepdims=True)
    n = frames[:, :, 0] - np.einsum("ni,ni->n", frames[:, :, 0], t)[:, None] * t
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    return np.stack([n, np.cross(t, n), t], axis=2)


def _unit(v: FloatArray) -> FloatArray:
    norm = np.linalg.norm(v)
    if not norm > 0.0 or not np.isfinite(norm):
        raise GeometryError(f"frames: expected a non-zero finite direction, got {v.tolist()}")
    return v / norm
