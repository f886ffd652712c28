"""Principal stretches of the skin S(q, l, a) against its rest state S(0, l, a), from the surface's derivatives.

The material is cast at q = 0, so the point (l, a) of the body at q = 0 is
the same material point at every q (the seed's S(q, l, a) is the motion).  A
surface point in frame coordinates is ``X = c(l) + x(l, a) N + y(l, a) B``;
with frames moving by ``N' = v (-k1 T + t B)``, ``B' = v (-k2 T - t N)``
(v = |dc/dl| mm, (k1, k2) = (T'.N, T'.B) per mm of arc, t the frame's twist
per mm: 0 for rotation-minimizing frames, the torsion for Frenet)::

    X_l = v (1 - x k1 - y k2) T + (x_l - v t y) N + (y_l + v t x) B
    X_a = x_a N + y_a B

and the first fundamental form is ``G = [[X_l.X_l, X_l.X_a], [X_l.X_a, X_a.X_a]]``.
For the seed's tube, (x, y) = rho (cos a, sin a), so
``X_l.X_l = v^2 (1 - rho kn)^2 + rho_l^2 + (rho v t)^2`` with
kn = k1 cos a + k2 sin a (the same ``1 - rho kn`` as the volume integral of
:mod:`softdesign.meshing.volume`).

The principal stretches lambda1 >= lambda2 are the square roots of the
eigenvalues of ``G0^-1 G`` (the right Cauchy-Green tensor of the surface
map in the rest metric): the roots mu of ``det(G - mu G0) = 0``, a quadratic
solved in closed form, vectorised.  Seed 000 names "realistic stress and
strain metrics" as future work; this is its kinematic half (no constitutive
model): a silicone is judged by its stretch against its elongation at break.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
import numpy.typing as npt

from softdesign.fitting.radius_field import RadiusField
from softdesign.fitting.radius_rows import SlopeRows, row_blocks
from softdesign.types import FloatArray, Frames, Points


class FramedDerivatives(Protocol):
    """What the metric needs of a centerline: its l-derivatives and frames (a ``types.FramedCurve`` has both)."""

    def derivative(self, l: npt.ArrayLike, order: int = 1) -> Points:
        """d^k c / dl^k (n, 3), mm."""
        ...

    def frames(self, l: npt.ArrayLike) -> Frames:
        """Frames (n, 3, 3), columns (N, B, T)."""
        ...

#: A rest metric whose determinant is below this fraction of (E0 G0) is degenerate (a collapsed section).
DEGENERATE_RTOL = 1e-12


@dataclass(frozen=True)
class SectionDerivatives:
    """A surface ``c + x N + y B`` on a grid l (p,) x a (m,) with what its metric needs.

    Attributes
    ----------
    speed : (p,) float, mm, v = |dc/dl|
    curvature : (p, 2) float, 1/mm, (k1, k2) per unit arc length
    twist : (p,) float, 1/mm, the frame's rotation about T per unit arc length (0 for rmf)
    xy, xy_l, xy_a : (p, m, 2) float, mm; the section coordinates and their l and a derivatives
    """

    speed: FloatArray
    curvature: FloatArray
    twist: FloatArray
    xy: FloatArray
    xy_l: FloatArray
    xy_a: FloatArray


def metric_from_sections(d: SectionDerivatives) -> FloatArray:
    """First fundamental form (E, F, G) in (l, a), (p, m, 3): mm^2 per unit l^2, per unit l rad, per rad^2."""
    return metric_from_planes(d.speed, d.curvature, d.twist, d.xy[..., 0], d.xy[..., 1], d.xy_l[..., 0],
                              d.xy_l[..., 1], d.xy_a[..., 0], d.xy_a[..., 1])


def metric_from_planes(speed: FloatArray, curvature: FloatArray, twist: FloatArray, x: FloatArray, y: FloatArray,
                       x_l: FloatArray, y_l: FloatArray, x_a: FloatArray, y_a: FloatArray,
                       out: FloatArray | None = None) -> FloatArray:
    """(E, F, G) (p, m, 3) of the surface ``c + x N + y B`` from its section coordinates and their l and a
    derivatives (p, m) and the centerline's speed (p,), curvature (p, 2) and twist (p,).

    Returned as a view of (3, p, m) planes (``out`` when given), so that E, F and G are each contiguous
    for :func:`principal_stretches`; the operations are those of the plain expressions, in their order.
    """
    v = speed[:, None]
    vt = (speed * twist)[:, None]
    axial = x * curvature[:, :1]  # v (1 - x k1 - y k2)
    np.subtract(1.0, axial, out=axial)
    axial -= y * curvature[:, 1:]
    axial *= v
    along_n = vt * y  # x_l - vt y
    np.subtract(x_l, along_n, out=along_n)
    along_b = vt * x  # y_l + vt x
    np.add(y_l, along_b, out=along_b)
    planes = np.empty((3,) + x.shape) if out is None else out
    e, f, g = planes
    term = np.empty(x.shape)
    np.square(axial, out=e)  # E = axial^2 + along_n^2 + along_b^2
    e += np.square(along_n, out=term)
    e += np.square(along_b, out=term)
    np.multiply(along_n, x_a, out=f)  # F = along_n x_a + along_b y_a
    f += np.multiply(along_b, y_a, out=term)
    np.square(x_a, out=g)  # G = x_a^2 + y_a^2
    g += np.square(y_a, out=term)
    return _last_axis(planes)


def tube_sections(
    speed: npt.ArrayLike, curvature: npt.ArrayLike, twist: npt.ArrayLike,
    angles: npt.ArrayLike, rho: npt.ArrayLike, rho_l: npt.ArrayLike, rho_a: npt.ArrayLike,
) -> SectionDerivatives:
    """The seed's tube, (x, y) = rho (cos a, sin a), with its exact derivatives; rho arrays (p, m) mm."""
    a = np.asarray(angles, float)
    u = np.stack([np.cos(a), np.sin(a)], axis=-1)
    w = np.stack([-np.sin(a), np.cos(a)], axis=-1)
    rho, rho_l, rho_a = (np.asarray(v, float)[..., None] for v in (rho, rho_l, rho_a))
    return SectionDerivatives(
        np.asarray(speed, float), np.asarray(curvature, float), np.asarray(twist, float),
        rho * u, rho_l * u, rho_a * u + rho * w,
    )


def tube_metric(
    speed: npt.ArrayLike, curvature: npt.ArrayLike, twist: npt.ArrayLike,
    angles: npt.ArrayLike, rho: npt.ArrayLike, rho_l: npt.ArrayLike, rho_a: npt.ArrayLike,
    out: FloatArray | None = None,
) -> FloatArray:
    """``metric_from_sections(tube_sections(...))`` without the (p, m, 2) section arrays, (p, m, 3).

    The same operations on the same numbers in the same order, so the same bits; it skips stacking
    x and y into arrays only to slice them apart again (most of a metric's time on large grids).
    ``out`` (3, p, m), when given, receives E, F and G (the result is its view).
    """
    a = np.asarray(angles, float)
    cos, sin = np.cos(a), np.sin(a)
    rho, rho_l, rho_a = (np.asarray(v, float) for v in (rho, rho_l, rho_a))
    x, y = rho * cos, rho * sin
    x_a, y_a = rho_a * cos + rho * -sin, rho_a * sin + rho * cos
    return metric_from_planes(np.asarray(speed, float), np.asarray(curvature, float), np.asarray(twist, float), x, y,
                              rho_l * cos, rho_l * sin, x_a, y_a, out)


def principal_stretches(rest: npt.ArrayLike, deformed: npt.ArrayLike) -> tuple[FloatArray, FloatArray]:
    """lambda1 >= lambda2 (dimensionless) from metrics (..., 3) = (E, F, G) at rest and deformed.

    The squares are the roots of ``det G0 mu^2 - (E0 G + G0 E - 2 F0 F) mu + det G = 0``.
    Metrics of the same shape are taken a block of rows (first axis) at a time.

    Raises
    ------
    ValueError
        A rest metric is degenerate (det G0 <= DEGENERATE_RTOL E0 G0): no stretch is defined there.
    """
    rest, deformed = np.asarray(rest, float), np.asarray(deformed, float)
    if rest.shape != deformed.shape or rest.ndim < 2:
        return _principal_stretches(rest, deformed)
    lam1, lam2 = np.empty(rest.shape[:-1]), np.empty(rest.shape[:-1])
    for rows in row_blocks(len(rest), rest[0].size // 3):
        lam1[rows], lam2[rows] = _principal_stretches(rest[rows], deformed[rows])
    return lam1, lam2


def _principal_stretches(rest: FloatArray, deformed: FloatArray) -> tuple[FloatArray, FloatArray]:
    """:func:`principal_stretches` on arrays at once: the operations of the formulas in the comments, in their
    order, into few temporaries."""
    e0, f0, g0 = rest[..., 0], rest[..., 1], rest[..., 2]  # views, as np.moveaxis(rest, -1, 0) unpacks them
    e, f, g = deformed[..., 0], deformed[..., 1], deformed[..., 2]
    scale = e0 * g0  # det0 = e0 g0 - f0 f0, degenerate unless det0 > DEGENERATE_RTOL |e0 g0|
    det0 = f0 * f0
    np.subtract(scale, det0, out=det0)
    np.abs(scale, out=scale)
    scale *= DEGENERATE_RTOL
    if not np.all(det0 > scale):
        raise ValueError("principal_stretches: a rest metric is degenerate (collapsed or folded rest surface)")
    term = scale
    half_trace = e0 * g  # 0.5 (e0 g + g0 e - 2 f0 f) / det0
    half_trace += np.multiply(g0, e, out=term)
    np.multiply(2.0, f0, out=term)
    term *= f
    half_trace -= term
    half_trace *= 0.5
    half_trace /= det0
    det_ratio = e * g  # (e g - f f) / det0
    det_ratio -= np.multiply(f, f, out=term)
    det_ratio /= det0
    mu1 = np.square(half_trace, out=term)  # half_trace + sqrt(max(half_trace^2 - det_ratio, 0))
    mu1 -= det_ratio
    np.maximum(mu1, 0.0, out=mu1)
    np.sqrt(mu1, out=mu1)
    mu1 += half_trace
    # the smaller root as det / mu1 keeps its digits when mu2 << mu1
    positive = mu1 > 0.0
    mu2 = np.where(positive, mu1, 1.0)
    np.divide(det_ratio, mu2, out=mu2)
    mu2[~positive] = 0.0
    np.maximum(mu2, 0.0, out=mu2)
    return np.sqrt(mu1, out=mu1), np.sqrt(mu2, out=mu2)


def _last_axis(planes: FloatArray) -> FloatArray:
    """``np.moveaxis(planes, 0, -1)`` (the same view), without its per-call checks: a metric is made a block of
    rows at a time, a thousand blocks and more per build."""
    return planes.transpose(*range(1, planes.ndim), 0)


def frame_twist(curve: FramedDerivatives, l: npt.ArrayLike, frames_mode: str) -> FloatArray:
    """The frames' twist per mm: 0 for rotation-minimizing frames, the torsion of the curve for Frenet."""
    l = np.asarray(l, float)
    if frames_mode == "rmf":
        return np.zeros(len(l))
    c1, c2, c3 = (curve.derivative(l, k) for k in (1, 2, 3))
    cross = np.cross(c1, c2)
    # torsion (c' x c'') . c''' / |c' x c''|^2 is per unit arc length whatever the parameter
    return np.einsum("ni,ni->n", cross, c3) / np.maximum(np.einsum("ni,ni->n", cross, cross), 1e-300)


def curve_terms(
    curve: FramedDerivatives, l: npt.ArrayLike, frames_mode: str
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """speed (p,) mm, curvature (k1, k2) (p, 2) 1/mm and twist (p,) 1/mm of a framed centerline at l."""
    l = np.asarray(l, float)
    d1, d2 = curve.derivative(l, 1), curve.derivative(l, 2)
    frames = curve.frames(l)
    speed2 = np.einsum("ni,ni->n", d1, d1)
    tangent = d1 / np.sqrt(speed2)[:, None]
    kvec = (d2 - np.einsum("ni,ni->n", d2, tangent)[:, None] * tangent) / speed2[:, None]
    curvature = np.einsum("ni,nij->nj", kvec, frames[:, :, :2])
    return np.sqrt(speed2), curvature, frame_twist(curve, l, frames_mode)


def skin_metric(curve: FramedDerivatives, field: RadiusField, q: float, l: npt.ArrayLike, a: npt.ArrayLike,
                frames_mode: str = "rmf") -> FloatArray:
    """(E, F, G) of the outer skin S(q) on the grid l (p,) x a (m,), (p, m, 3), from the spline's derivatives.

    ``curve`` is c(q, .) with its frames; rho, rho_l and rho_a come from the
    radius field's own basis derivatives (no finite differences).
    """
    l = np.asarray(l, float).reshape(-1)
    speed, curvature, twist = curve_terms(curve, l, frames_mode)
    rows = SlopeRows(field, q, l, a)
    planes = np.empty((3, len(l), np.size(a)))
    for block in row_blocks(len(l), np.size(a)):
        tube_metric(speed[block], curvature[block], twist[block], a, *rows(block.start, block.stop),
                    out=planes[:, block])
    return np.moveaxis(planes, 0, -1)
