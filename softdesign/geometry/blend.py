"""Shapes between q = 0 and q = 1: the seed's linear blend, keyframes, and an intrinsic blend.

Key shapes are (q, curve) pairs with q = 0 first and q = 1 last; between two
neighbours the blend weight is w = (q - q_a) / (q_b - q_a).

``linear`` (the seed): c(q, l) = (1 - w) c_a(l) + w c_b(l), exact on the spline
coefficients (every key shares the knot vector).  A straight line blended with
a curve of the same length is shorter than both; :meth:`BlendedShape.shortening`
says by how much.

``intrinsic``: the curvature vector in the rotation-minimizing frame,
(k1, k2) = (dT/ds . N, dT/ds . B), and the length L are blended linearly, then
the frame ODE dF/ds = F [w]x with body angular velocity w = (-k2, k1, 0) is
integrated from the common base pose with the fourth-order Magnus step

    Omega = h/2 (w_a + w_b) + sqrt(3)/12 h^2 (w_a x w_b)   (w at the 2 Gauss points)

and positions c = c(0) + integral of T ds (quintic spline antiderivative), so
every intermediate shape has length (1 - w) L_a + w L_b.  The base poses of
the keys are blended along the SE(3) geodesic (identical once registered).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
import numpy.typing as npt
from scipy.interpolate import make_interp_spline
from scipy.optimize import minimize_scalar

from softdesign.errors import ConfigError, GeometryError
from softdesign.geometry.curves import SmoothCurve, smooth_curve_from_samples
from softdesign.geometry.frames import (
    FramedSpline,
    FrameMode,
    accumulate_rotations,
    base_normal_from_tangent,
    framed_curve,
)
from softdesign.geometry.se3 import inverse_pose, pose_from_twist, rotation_from_rotvec, twist_from_pose
from softdesign.types import FloatArray

BlendMode = Literal["linear", "intrinsic", "pcc"]
#: The modes :func:`blend_shapes` builds; "pcc" (a designed chain) is built by :func:`sampled_shape`.
BLEND_MODES = ("linear", "intrinsic")
#: Gauss-Legendre points of the 2-point (fourth-order) Magnus step, on [0, 1].
_GAUSS2 = np.array([0.5 - np.sqrt(3.0) / 6.0, 0.5 + np.sqrt(3.0) / 6.0])
#: q samples for the search of the shortest blended shape (then refined by a bounded search).
SHORTENING_Q_SAMPLES = 41
#: A shape shorter than the shorter end shape by less than this fraction is as long as it: the
#: arc lengths agree to ~1e-13 relative, so an intrinsic blend of two equally long ends stays far below.
SHORTENING_RTOL = 1e-9


@dataclass(frozen=True)
class BlendStats:
    """Per-q figures: length mm, axial stretch |dc/dl|(q) / |dc/dl|(0) range, curvature range 1/mm."""

    q: float
    length_mm: float
    stretch_min: float
    stretch_max: float
    curvature_min_per_mm: float
    curvature_max_per_mm: float


@dataclass(frozen=True)
class Shortening:
    """The shortest shape over q against the shorter end shape: ``ratio = 1 - min_length / reference``."""

    q_at_min: float
    min_length_mm: float
    reference_length_mm: float
    ratio: float

    @property
    def intermediate_is_shorter(self) -> bool:
        """True when a shape strictly between q = 0 and q = 1 is shorter than both end shapes (beyond round-off).

        Otherwise the shortest shape is an end shape (a longer or shorter q = 0, an
        intrinsic blend) and there is no shortening to report.
        """
        return 0.0 < self.q_at_min < 1.0 and self.ratio > SHORTENING_RTOL


@dataclass(frozen=True)
class _Intrinsic:
    """Per key: length (k,), base pose (k, 4, 4), RMF curvature (k, intervals, 2 Gauss, 2)."""

    lengths: FloatArray
    base_poses: FloatArray
    curvatures: FloatArray


@dataclass(frozen=True)
class BlendedShape:
    """c(q, l) for q in [0, 1]; build it with :func:`blend_shapes`.

    Attributes
    ----------
    key_q : (k,) sorted q of the key shapes, 0 first, 1 last
    keys : the key curves, on one l grid
    mode : "linear" | "intrinsic"
    frames : "rmf" | "frenet"
    base_normal : (3,) reference normal shared by every q (from the final shape's base tangent)
    """

    key_q: FloatArray
    keys: tuple[SmoothCurve, ...]
    mode: BlendMode
    frames: FrameMode
    base_normal: FloatArray
    _intrinsic: _Intrinsic | None = field(default=None, repr=False)
    #: mode "pcc": c(q, .) as a function of q (:func:`sampled_shape`)
    _sampler: Callable[[float], SmoothCurve] | None = field(default=None, repr=False, compare=False)
    # c(q, .) and its frames are pure functions of q; links, stats and exports ask for the
    # same q many times, so each is built once (the shape is immutable)
    _smooth: dict[float, SmoothCurve] = field(default_factory=dict, repr=False, compare=False)
    _framed: dict[float, FramedSpline] = field(default_factory=dict, repr=False, compare=False)
    _targets: dict[str, FramedSpline] = field(default_factory=dict, repr=False, compare=False)
    #: work a stage did on this shape that a later stage may take instead of doing it again (:meth:`keep`)
    _kept: dict[str, object] = field(default_factory=dict, repr=False, compare=False)

    def smooth_curve_at(self, q: float) -> SmoothCurve:
        """The centerline c(q, .) as a :class:`SmoothCurve` (no frames)."""
        q = float(q)
        if q not in self._smooth:
            a, w = self._segment(q)
            if self._sampler is not None:
                self._smooth[q] = self._sampler(q)
            elif self._intrinsic is None:  # mode "linear": blend_shapes prepares the data of "intrinsic" only
                self._smooth[q] = _linear(self.keys[a], self.keys[a + 1], w)
            else:
                self._smooth[q] = _integrate_intrinsic(self.keys[0], self._intrinsic, a, w)
        return self._smooth[q]

    def curve_at(self, q: float) -> FramedSpline:
        """The centerline with its frames at q (a ``types.FramedCurve``)."""
        q = float(q)
        if q not in self._framed:
            try:
                framed = framed_curve(self.smooth_curve_at(q), self.frames, self.base_normal, label=f"q = {q:g}")
            except GeometryError as err:
                if self.mode != "linear" or q in (0.0, 1.0):
                    raise
                raise GeometryError(f"{err}; at an intermediate q the linear blend is the likelier cause (a straight-"
                                    "to-curved linear blend shortens and kinks the middle): use blend: intrinsic"
                                    ) from err
            self._framed[q] = framed
        return self._framed[q]

    def built_curve(self, q: float) -> FramedSpline | None:
        """:meth:`curve_at`'s curve at q if it is built already (in this process), else None; builds nothing."""
        return self._framed.get(float(q))

    def target_curve(self) -> FramedSpline:
        """The q = 1 centerline the body's wall is fitted around, with its frames.

        It is c(1, .) except for a sampled shape (``pcc``), whose q = 1 shape is the designed chain and whose
        wall is the vessel's, fitted around the final key (the vessel's centerline) and carried to the chain.
        """
        if self._sampler is None:
            return self.curve_at(1.0)
        if "target" not in self._targets:
            self._targets["target"] = framed_curve(self.keys[-1], self.frames, self.base_normal, label="q = 1 target")
        return self._targets["target"]

    def keep_curve(self, q: float, framed: FramedSpline) -> None:
        """Keep ``framed``, built from this shape by :meth:`curve_at` (in a worker process), as c(q, .) and its frames.

        A stage that builds the curves of its q values on worker processes hands them back to the
        shape of the build process this way, so later stages find them built, as when built here.
        """
        q = float(q)
        self._framed.setdefault(q, framed)
        self._smooth.setdefault(q, self._framed[q].curve)

    def keep(self, name: str, value: object) -> None:
        """Keep ``value``, work done on this shape (e.g. the blend's projection of the wall on its q = 1 curve), for a
        later stage of this build to take (:meth:`take`); the shape's own figures do not depend on it."""
        self._kept[name] = value

    def take(self, name: str) -> object | None:
        """The value kept as ``name`` (:meth:`keep`), once: it is dropped here; None when none was kept."""
        return self._kept.pop(name, None)

    def stats_at(self, q: float, l_range: tuple[float, float] = (0.0, 1.0)) -> BlendStats:
        """Length, stretch range and curvature range at q over ``l_range`` (dense grid): :meth:`stats_of_links` of
        the one link ``l_range``."""
        return self.stats_of_links(q, l_range)[0]

    def stats_of_links(self, q: float, breaks: npt.ArrayLike) -> list[BlendStats]:
        """Length, stretch range and curvature range at q of each link ``(breaks[j], breaks[j + 1])`` (``breaks``
        increasing), over the dense grid strictly inside it plus its two ends.

        Each value is a point's own (a spline evaluated point by point), so a link's figures are the same, bit for
        bit, whether it is asked alone or with its neighbours: the links share their ends, and one call evaluates
        every link's points at once (one small call per link and q was a fifth of the 1M-triangle benchmark's
        kinematics stage, mostly per-call overhead).
        """
        curve = self.smooth_curve_at(q)
        ends = np.asarray(breaks, float)
        dense = self.keys[-1].dense_l()
        l = np.unique(np.concatenate([dense[(dense > ends[0]) & (dense < ends[-1])], ends]))
        stretch = curve.speed(l) / self.keys[0].speed(l) if q > 0.0 else np.ones(len(l))
        kappa = curve.curvature(l)
        at = np.searchsorted(l, ends)  # each end is in l: its index
        out = []
        for lo, hi, first, last in zip(ends[:-1], ends[1:], at[:-1], at[1:], strict=True):
            s = curve.arc_length(np.array([lo, hi]))  # one call per link: its own ends' numbers
            part = slice(int(first), int(last) + 1)
            out.append(BlendStats(float(q), float(s[1] - s[0]), float(stretch[part].min()),
                                  float(stretch[part].max()), float(kappa[part].min()), float(kappa[part].max())))
        return out

    def shortening(self) -> Shortening:
        """Shortest c(q, .) over q in [0, 1] against min(L(0), L(1)) (grid, then bounded refinement)."""
        grid = np.linspace(0.0, 1.0, SHORTENING_Q_SAMPLES)
        lengths = np.array([self.smooth_curve_at(q).length for q in grid])
        best = int(np.argmin(lengths))
        q_min, l_min = float(grid[best]), float(lengths[best])
        lo, hi = grid[max(best - 1, 0)], grid[min(best + 1, len(grid) - 1)]
        if hi > lo:
            found = minimize_scalar(lambda q: self.smooth_curve_at(q).length, bounds=(lo, hi),
                                    method="bounded", options={"xatol": 1e-6})
            if found.fun < l_min:
                q_min, l_min = float(found.x), float(found.fun)
        reference = float(min(lengths[0], lengths[-1]))
        return Shortening(q_min, l_min, reference, max(0.0, 1.0 - l_min / reference))

    def _segment(self, q: float) -> tuple[int, float]:
        if not 0.0 <= q <= 1.0:
            raise ConfigError(f"q must lie in [0, 1], got {q}")
        a = int(np.clip(np.searchsorted(self.key_q, q, side="right") - 1, 0, len(self.key_q) - 2))
        return a, float((q - self.key_q[a]) / (self.key_q[a + 1] - self.key_q[a]))


def blend_shapes(
    initial: SmoothCurve,
    final: SmoothCurve,
    keyframes: tuple[tuple[float, SmoothCurve], ...] = (),
    mode: BlendMode = "linear",
    frames: FrameMode = "rmf",
) -> BlendedShape:
    """The blended shape from q = 0 (``initial``) to q = 1 (``final``) through ``keyframes``.

    Parameters
    ----------
    initial, final : key curves at q = 0 and 1, on the same l grid
    keyframes : (q, curve) pairs with 0 < q < 1, distinct
    mode : "linear" (the seed) or "intrinsic" (length-preserving)
    frames : "rmf" or "frenet"

    Raises
    ------
    ConfigError
        Bad mode or keyframe q values.
    GeometryError
        Key curves not on one l grid.
    """
    if mode not in BLEND_MODES:
        raise ConfigError(f"blend must be one of {', '.join(BLEND_MODES)}, got {mode!r}")
    pairs = sorted([(0.0, initial), *[(float(q), c) for q, c in keyframes], (1.0, final)], key=lambda p: p[0])
    key_q = np.array([p[0] for p in pairs])
    if np.any(np.diff(key_q) <= 0.0) or (keyframes and not all(0.0 < q < 1.0 for q, _ in keyframes)):
        raise ConfigError(f"intermediate shapes need distinct q strictly between 0 and 1, got {sorted(key_q[1:-1])}")
    keys = tuple(p[1] for p in pairs)
    _check_common_grid(keys, key_q)
    base_normal = base_normal_from_tangent(final.tangents([0.0])[0])
    intrinsic = _prepare_intrinsic(keys, base_normal) if mode == "intrinsic" else None
    return BlendedShape(key_q, keys, mode, frames, base_normal, intrinsic)


def sampled_shape(
    final: SmoothCurve, sampler: Callable[[float], SmoothCurve], mode: BlendMode, frames: FrameMode = "rmf"
) -> BlendedShape:
    """A shape whose c(q, .) is ``sampler(q)`` (l in [0, 1] proportional to arc length, as ``final``'s).

    ``final`` is the centerline the wall is fitted around (:meth:`BlendedShape.target_curve`); the keys are
    ``sampler(0)`` and ``final``.  The pipeline builds ``pcc`` this way (each section's curvature scaled by q,
    splined per section with its joints kept: :func:`~softdesign.geometry.curve_joints.grid_with_joints`).
    """
    initial = sampler(0.0)
    base_normal = base_normal_from_tangent(final.tangents([0.0])[0])
    return BlendedShape(np.array([0.0, 1.0]), (initial, final), mode, frames, base_normal, None, sampler)


def _check_common_grid(keys: tuple[SmoothCurve, ...], key_q: FloatArray) -> None:
    ref = keys[-1].spline
    for q, key in zip(key_q, keys, strict=True):
        if key.spline.k != ref.k or not np.array_equal(key.spline.t, ref.t):
            raise GeometryError(
                f"blend: the shape at q = {q:g} has {len(key.l_grid)} samples, the final shape "
                f"{len(keys[-1].l_grid)}; expected one l grid for every shape - resample it with "
                "the final shape's count (geometry.initial builds shapes that way)"
            )


def _linear(a: SmoothCurve, b: SmoothCurve, w: float) -> SmoothCurve:
    samples = (1.0 - w) * a.points(a.l_grid) + w * b.points(b.l_grid)
    return smooth_curve_from_samples(samples, b.joints)


def _prepare_intrinsic(keys: tuple[SmoothCurve, ...], base_normal: FloatArray) -> _Intrinsic:
    """Lengths, base poses and RMF curvature (k1, k2) at the Magnus Gauss points of each key."""
    l = keys[-1].dense_l()
    gauss = (l[:-1, None] + np.diff(l)[:, None] * _GAUSS2).ravel()
    lengths, poses, curvatures = [], [], []
    for key in keys:
        framed = framed_curve(key, "rmf", base_normal, label="intrinsic blend key")
        frames = framed.frames(gauss)
        kvec = key.curvature_vectors(gauss)
        k12 = np.stack([np.einsum("ni,ni->n", kvec, frames[:, :, 0]),
                        np.einsum("ni,ni->n", kvec, frames[:, :, 1])], axis=1)
        lengths.append(key.length)
        poses.append(framed.poses([0.0])[0])
        curvatures.append(k12.reshape(len(l) - 1, 2, 2))
    return _Intrinsic(np.array(lengths), np.array(poses), np.array(curvatures))


def _integrate_intrinsic(final_like: SmoothCurve, data: _Intrinsic, a: int, w: float) -> SmoothCurve:
    """Integrate the blended RMF curvature and length between keys a and a + 1 at weight w."""
    k12 = (1.0 - w) * data.curvatures[a] + w * data.curvatures[a + 1]
    length = (1.0 - w) * data.lengths[a] + w * data.lengths[a + 1]
    base = _blend_pose(data.base_poses[a], data.base_poses[a + 1], w)
    intervals = k12.shape[0]
    h = length / intervals
    omega = np.stack([-k12[..., 1], k12[..., 0], np.zeros(k12.shape[:2])], axis=-1)  # (intervals, 2, 3)
    step = 0.5 * h * (omega[:, 0] + omega[:, 1]) + np.sqrt(3.0) / 12.0 * h * h * np.cross(omega[:, 0], omega[:, 1])
    frames = base[:3, :3] @ accumulate_rotations(rotation_from_rotvec(step), "right")
    tangents = np.concatenate([base[None, :3, 2], frames[:, :, 2]], axis=0)
    s = np.linspace(0.0, length, intervals + 1)
    positions = make_interp_spline(s, tangents, k=5).antiderivative()(s) + base[:3, 3]
    per_sample = intervals // (len(final_like.l_grid) - 1)
    return smooth_curve_from_samples(positions[::per_sample], final_like.joints)


def _blend_pose(a: FloatArray, b: FloatArray, w: float) -> FloatArray:
    """a @ exp(w log(inv(a) @ b)): the SE(3) geodesic from pose a (w = 0) to b (w = 1)."""
    relative = inverse_pose(a) @ b
    if np.allclose(relative, np.eye(4), rtol=0.0, atol=1e-15):
        return a
    return a @ pose_from_twist(w * twist_from_pose(relative))
