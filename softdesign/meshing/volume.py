"""Volume and area of a body integrated from its parametric surface, and the offset sections.

Volume (the exact integral the mesh checks compare against)
    Along a centerline c(s) with rotation-minimizing frames (N' = -k1 T,
    B' = -k2 T, T' = k1 N + k2 B per unit arc length s), the map
    ``X(s, r, a) = c + r (cos a N + sin a B)`` has ``X_s = (1 - r kn) T``
    (kn = k1 cos a + k2 sin a), ``X_r = u``, ``X_a = r w`` with (u, w, T)
    orthonormal and ``u x w = T``, so its Jacobian is ``r (1 - r kn)``,
    positive while the tube does not fold (rho * kn < 1).  The body
    ``{r < rho(s, a)}`` between the end planes therefore has

        V = int ds int da [rho^2 / 2 - rho^3 / 3 (k1 cos a + k2 sin a)].

    In Cartesian section coordinates (x, y) = r (cos a, sin a) this reads
    ``V = int ds [A(s) - k1 Mx(s) - k2 My(s)]``: the section's area minus
    the curvature times its first moment about the centerline (Pappus for
    a torus).  A, Mx, My come from Green's theorem on any closed section
    curve, which is how offset sections (not of the form rho e^{ia}) are
    integrated.  The end caps lie in the end planes s = 0, L and bound the
    same region, so they add nothing further to V.
Area
    ``|S_s x S_a|^2 = (1 - rho kn)^2 (rho^2 + rho_a^2) + rho^2 rho_s^2``;
    each planar cap adds ``int rho^2 / 2 da``.
Quadrature
    Gauss-Legendre in l on every interval between the breaks the caller
    gives (pass the spline knots and joints, where the integrand is not
    smooth), times ds/dl; the trapezoid rule in a, which is spectral for a
    periodic integrand; a-derivatives by FFT.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.types import FloatArray

#: Smallest radius an inward offset (a shrunk body or a chamber) may leave, mm.
MIN_RADIUS_MM = 0.2
#: Gauss-Legendre points per interval between breaks.
GAUSS_ORDER = 8
#: Newton iterations allowed to invert s(l), and their tolerance relative to the length.
NEWTON_STEPS, NEWTON_RTOL = 30, 1e-12
#: Per end (base, tip): the end's cut plane as (n_N, n_B, n_T, offset_mm): its outward unit normal in the end
#: frame's (N, B, T) coordinates and where it crosses the axis, mm along the outward tangent from the end ring's
#: centre; or None for a square end (:mod:`softdesign.meshing.end_cut`).
EndCuts = tuple[tuple[float, float, float, float] | None, tuple[float, float, float, float] | None]


@dataclass(frozen=True)
class BodySpec:
    """What solid to make of S(q) (the case file's ``export`` keys).

    Attributes
    ----------
    offset_mm : float
        Grow (> 0) or shrink (< 0) the body along its surface normal.
    wall_mm : float
        0 for a solid body; otherwise the wall of a closed chamber inside it,
        both ends sealed by caps ``wall_mm`` thick.
    port_mm : float
        0, or the diameter of an inlet channel through the base cap along the base tangent.
    min_radius_mm : float
        Smallest radius an inward offset or the chamber may keep; also the
        least chamber length and the least ledge left around the port.
    port_segments : int
        Polygon sides of the port channel; 0 takes the body's angular count.
    end_cuts : EndCuts
        Per end, the cut plane in the end frame, or None: square to the end tangent.
    """

    offset_mm: float = 0.0
    wall_mm: float = 0.0
    port_mm: float = 0.0
    min_radius_mm: float = MIN_RADIUS_MM
    port_segments: int = 0
    end_cuts: EndCuts = (None, None)


@dataclass(frozen=True)
class Stations:
    """The surface evaluated at n values of l (e.g. quadrature nodes).

    Attributes
    ----------
    rho : (n, na) float, mm, on :func:`angle_grid`
    rho_s : (n, na) float, d rho / ds (per unit arc length)
    curvature : (n, 2) float, 1/mm, (k1, k2) = (T'.N, T'.B) per unit arc length
    speed : (n,) float, mm, ds/dl
    """

    rho: FloatArray
    rho_s: FloatArray
    curvature: FloatArray
    speed: FloatArray


#: Evaluates the body at an array of l values; a pure function of l.  It may also have a
#: method ``speed(l)`` giving ``Stations.speed`` alone, which arc lengths then use.
SectionField = Callable[[FloatArray], Stations]


@dataclass(frozen=True)
class BodyIntegrals:
    """Figures of the body as the integrals give them.

    Attributes
    ----------
    volume : float, mm^3
    area : float or None, mm^2 (closed surface, caps included); None for offset or hollow bodies
    length : float, mm, centerline arc length
    """

    volume: float
    area: float | None
    length: float


def angle_grid(na: int) -> FloatArray:
    """Angles ``a_k = 2 pi k / na``, (na,) rad."""
    if na < 3:
        raise ValueError(f"angular count must be >= 3, got {na}")
    return 2.0 * np.pi * np.arange(na) / na


def polygon_area_ratio(na: int) -> float:
    """Area of the regular na-gon inscribed in a circle over the circle's: sin(2 pi/na) / (2 pi/na)."""
    h = 2.0 * np.pi / na
    return float(np.sin(h) / h)


def angular_derivative(values: npt.ArrayLike) -> FloatArray:
    """d/da of values on :func:`angle_grid` along the last axis (spectral; exact for trig polynomials)."""
    values = np.asarray(values, float)
    na = values.shape[-1]
    wavenumber = np.fft.rfftfreq(na, 1.0 / na)
    if na % 2 == 0:
        wavenumber[-1] = 0.0  # the Nyquist mode has no odd part to differentiate
    return np.fft.irfft(1j * wavenumber * np.fft.rfft(values, axis=-1), n=na, axis=-1)


def section_curves(
    rho: npt.ArrayLike, rho_s: npt.ArrayLike, curvature: npt.ArrayLike, offset_mm: float
) -> FloatArray:
    """Section curves of the tube offset by ``offset_mm`` along its surface normal.

    With ``S_s x S_a`` worked out as for the volume, the outward normal is
    ``n ~ (1 - rho kn)(rho u - rho_a w) - rho rho_s T``.  Its in-plane part
    is the section curve's own normal ``nu``.  A point moved by d along n,
    with the offset surface sliced again by the station's plane, moves by
    ``d / cos(beta)`` along ``nu``, ``tan(beta) = rho rho_s / ((1 - rho kn)
    |rho u - rho_a w|)``: exact for cylinders, cones and tori, first order in
    d times the surface's curvature along s otherwise.  Every section stays
    in its plane, and offsets add (a wall w inside an offset d is d - w).

    Parameters
    ----------
    rho : (n, na) float, mm
    rho_s : (n, na) float, d rho / ds
    curvature : (n, 2) float, 1/mm
    offset_mm : float

    Returns
    -------
    (n, na, 2) float, mm
        (x, y) along (N, B); ``offset_mm = 0`` gives ``rho (cos a, sin a)``.
    """
    rho, rho_s, curvature = (np.asarray(v, float) for v in (rho, rho_s, curvature))
    a = angle_grid(rho.shape[-1])
    u = np.stack([np.cos(a), np.sin(a)], axis=-1)
    w = np.stack([-np.sin(a), np.cos(a)], axis=-1)
    points = rho[..., None] * u
    if offset_mm == 0.0:
        return points
    in_plane = rho[..., None] * u - angular_derivative(rho)[..., None] * w
    span = np.linalg.norm(in_plane, axis=-1)
    stretch = 1.0 - rho * (curvature[:, :1] * np.cos(a) + curvature[:, 1:] * np.sin(a))
    tan_beta = rho * rho_s / (stretch * span)
    return points + (offset_mm * np.sqrt(1.0 + tan_beta**2) / span)[..., None] * in_plane


def gauss_legendre_nodes(breaks: npt.ArrayLike, order: int = GAUSS_ORDER) -> tuple[FloatArray, FloatArray]:
    """Gauss-Legendre nodes and weights, ``order`` per interval between consecutive breaks.

    Returns
    -------
    nodes, weights : ((len(breaks) - 1) * order,) float
    """
    breaks = np.asarray(breaks, float)
    if breaks.size < 2 or np.any(np.diff(breaks) <= 0):
        raise ValueError(f"breaks must be strictly increasing with >= 2 values, got {breaks.tolist()}")
    x, w = np.polynomial.legendre.leggauss(order)
    half = 0.5 * np.diff(breaks)[:, None]
    nodes = 0.5 * (breaks[:-1] + breaks[1:])[:, None] + half * x
    return nodes.ravel(), (half * w).ravel()


def section_moments(xy: npt.ArrayLike) -> tuple[FloatArray, FloatArray]:
    """Area and first moment (about the centerline) of closed section curves.

    Parameters
    ----------
    xy : (n, na, 2) float, mm, counter-clockwise on :func:`angle_grid`

    Returns
    -------
    area : (n,) float, mm^2
    moment : (n, 2) float, mm^3, (int x dA, int y dA)
    """
    xy = np.asarray(xy, float)
    x, y = xy[..., 0], xy[..., 1]
    xa, ya = angular_derivative(x), angular_derivative(y)
    da = 2.0 * np.pi / xy.shape[1]
    area = 0.5 * da * np.sum(x * ya - y * xa, axis=-1)
    moment = 0.5 * da * np.stack([np.sum(x * x * ya, axis=-1), -np.sum(y * y * xa, axis=-1)], axis=-1)
    return area, moment


def sweep_volume(xy: npt.ArrayLike, curvature: npt.ArrayLike, ds_weights: npt.ArrayLike) -> float:
    """``V = sum_i w_i [A_i - k_i . M_i]`` for section curves at quadrature nodes, mm^3."""
    area, moment = section_moments(xy)
    return float(np.asarray(ds_weights, float) @ (area - np.einsum("nj,nj->n", np.asarray(curvature, float), moment)))


def tube_volume(rho: npt.ArrayLike, curvature: npt.ArrayLike, ds_weights: npt.ArrayLike) -> float:
    """The module's volume integral in tube form, mm^3.

    Parameters
    ----------
    rho : (n, na) float, mm, at quadrature nodes
    curvature : (n, 2) float, 1/mm
    ds_weights : (n,) float, mm, arc-length quadrature weights
    """
    rho, curvature = np.asarray(rho, float), np.asarray(curvature, float)
    a = angle_grid(rho.shape[1])
    kn = curvature[:, :1] * np.cos(a) + curvature[:, 1:] * np.sin(a)
    inner = np.sum(rho**2 / 2.0 - rho**3 / 3.0 * kn, axis=1) * (2.0 * np.pi / rho.shape[1])
    return float(np.asarray(ds_weights, float) @ inner)


def tube_lateral_area(
    rho: npt.ArrayLike, rho_s: npt.ArrayLike, curvature: npt.ArrayLike, ds_weights: npt.ArrayLike
) -> float:
    """``int ds int da |S_s x S_a|`` of the tube wall (no caps), mm^2; arguments as :func:`tube_volume`."""
    rho, rho_s, curvature = (np.asarray(v, float) for v in (rho, rho_s, curvature))
    a = angle_grid(rho.shape[1])
    stretch = 1.0 - rho * (curvature[:, :1] * np.cos(a) + curvature[:, 1:] * np.sin(a))
    density = np.sqrt(stretch**2 * (rho**2 + angular_derivative(rho) ** 2) + (rho * rho_s) ** 2)
    return float(np.asarray(ds_weights, float) @ density.sum(axis=1) * (2.0 * np.pi / rho.shape[1]))


def section_area(rho: npt.ArrayLike) -> FloatArray:
    """``int rho^2 / 2 da`` of each section, (n,) mm^2, from rho (n, na)."""
    rho = np.asarray(rho, float)
    return np.sum(rho**2, axis=-1) * (np.pi / rho.shape[-1])


def _sub_breaks(breaks: FloatArray, lo: float, hi: float) -> FloatArray:
    inside = breaks[(breaks > lo) & (breaks < hi)]
    return np.concatenate([[lo], inside, [hi]])


def _speed(field: SectionField, l: FloatArray) -> FloatArray:
    """ds/dl at l, mm: from the field's ``speed`` method when it has one (no radii needed)."""
    speed = getattr(field, "speed", None)
    return speed(l) if callable(speed) else field(l).speed


def arclength_at(field: SectionField, breaks: npt.ArrayLike, l: float, order: int = GAUSS_ORDER) -> float:
    """Arc length from ``breaks[0]`` to ``l``, mm (Gauss-Legendre on ds/dl)."""
    breaks = np.asarray(breaks, float)
    if l <= breaks[0]:
        return 0.0
    nodes, weights = gauss_legendre_nodes(_sub_breaks(breaks, breaks[0], l), order)
    return float(weights @ _speed(field, nodes))


def l_at_arclength(field: SectionField, breaks: npt.ArrayLike, s: float, order: int = GAUSS_ORDER) -> float:
    """The l at which the arc length from ``breaks[0]`` reaches ``s`` mm (Newton on s(l))."""
    breaks = np.asarray(breaks, float)
    length = arclength_at(field, breaks, breaks[-1], order)
    if not 0.0 <= s <= length:
        raise ValueError(f"arc length {s} mm outside [0, {length}] mm")
    l = breaks[0] + (breaks[-1] - breaks[0]) * s / length
    for _ in range(NEWTON_STEPS):
        miss = arclength_at(field, breaks, l, order) - s
        if abs(miss) <= NEWTON_RTOL * length:
            break
        l = float(np.clip(l - miss / _speed(field, np.array([l]))[0], breaks[0], breaks[-1]))
    return l


def swept_volume(
    field: SectionField, breaks: FloatArray, span: tuple[float, float], offset_mm: float, order: int = GAUSS_ORDER
) -> float:
    """Volume swept by the sections offset by ``offset_mm`` for l in ``span``, mm^3."""
    nodes, weights = gauss_legendre_nodes(_sub_breaks(breaks, *span), order)
    st = field(nodes)
    return sweep_volume(section_curves(st.rho, st.rho_s, st.curvature, offset_mm), st.curvature, weights * st.speed)


def integrate_body(
    field: SectionField, breaks: npt.ArrayLike, spec: BodySpec = BodySpec(), order: int = GAUSS_ORDER
) -> BodyIntegrals:
    """Volume (and, for a plain body, area) of the solid that ``spec`` makes of the surface.

    Parameters
    ----------
    field : SectionField
        The surface at any l in [breaks[0], breaks[-1]].
    breaks : (m,) float
        Every l where the integrand may not be smooth (joints, spline knots), both ends included.
    spec : BodySpec
    order : int
        Gauss-Legendre points per interval.

    Returns
    -------
    BodyIntegrals
        Hollow: the outer body minus the chamber (the inward offset by
        ``wall_mm`` between arc lengths wall_mm and L - wall_mm) minus a port
        channel ``pi (port_mm/2)^2 wall_mm`` through the base cap.
    """
    breaks = np.asarray(breaks, float)
    # length, volume and area over the whole span share one evaluation of the field, at the
    # nodes arclength_at and swept_volume would pick (the breaks are their own sub-breaks)
    nodes, weights = gauss_legendre_nodes(breaks, order)
    st = field(nodes)
    length = float(weights @ st.speed)
    ds = weights * st.speed
    volume = sweep_volume(section_curves(st.rho, st.rho_s, st.curvature, spec.offset_mm), st.curvature, ds)
    if spec.wall_mm > 0:
        w = spec.wall_mm
        span = (l_at_arclength(field, breaks, w, order), l_at_arclength(field, breaks, length - w, order))
        volume -= swept_volume(field, breaks, span, spec.offset_mm - w, order)
        volume -= np.pi * (spec.port_mm / 2.0) ** 2 * w
    area = None
    if spec.offset_mm == 0 and spec.wall_mm == 0:
        caps = section_area(field(breaks[[0, -1]]).rho).sum()
        area = tube_lateral_area(st.rho, st.rho_s, st.curvature, ds) + float(caps)
    return BodyIntegrals(float(volume), area, length)
