"""Principal stretches of the skin: known answers (bent tube, growing tube), the closed form, the mesh cross-check."""

from __future__ import annotations

import numpy as np
import pytest

from softdesign.fitting import bspline_basis as bb
from softdesign.fitting import radius_rows, strain
from softdesign.fitting.bspline_surface import RadiusSpline
from softdesign.fitting.radius_field import RadiusField
from softdesign.fitting.strain import (
    metric_from_sections,
    principal_stretches,
    skin_metric,
    tube_metric,
    tube_sections,
)
from softdesign.geometry.blend import blend_shapes
from softdesign.geometry.curves import CurveOptions, smooth_curve_from_polyline
from softdesign.geometry.initial import straight_initial_shape
from softdesign.meshing.body.sections import sections_on_grid
from softdesign.meshing.body.skin_stretch import (
    START_ANGLES_PER_INTERVAL,
    START_SPACING_MM,
    STRETCH_TOL,
    converged_extremes,
    extremes_on,
    make_grid,
)
from softdesign.meshing.tessellate import sweep_from_sections, tessellate

#: The issue's bound for the known answers.
KNOWN_TOL = 1e-6
RADIUS_MM, BEND_RADIUS_MM, LENGTH_MM = 3.0, 40.0, 60.0


def _constant_field(radius_initial: float, radius_final: float, breaks=(0.0, 0.5, 1.0)) -> RadiusField:
    knots = bb.open_knots(list(breaks), [6] * (len(breaks) - 1))
    count = len(knots) - bb.DEGREE - 1
    links = []
    for lo, hi in zip(breaks[:-1], breaks[1:], strict=True):
        k = bb.open_knots([lo, hi], [6])
        links.append(RadiusSpline(k, np.full((len(k) - bb.DEGREE - 1, 16), radius_final)))
    assert count > 0
    field = RadiusField.from_links(breaks, tuple(links), radius_mm=radius_initial)
    return field


def _arc(length: float, radius: float) -> np.ndarray:
    s = np.linspace(0.0, length, 4001)
    return np.column_stack([radius * (1 - np.cos(s / radius)), np.zeros_like(s), radius * np.sin(s / radius)])


@pytest.fixture(scope="module")
def bent():
    """A straight tube bent into an arc of radius 40 mm by the intrinsic (length-preserving) blend."""
    final = smooth_curve_from_polyline(_arc(LENGTH_MM, BEND_RADIUS_MM), CurveOptions(spacing_mm=0.25, smoothing_mm=0.0))
    shape = blend_shapes(straight_initial_shape(final), final, mode="intrinsic")
    return shape, _constant_field(RADIUS_MM, RADIUS_MM)


def _stretches(shape, field, q, l, a):
    rest = skin_metric(shape.curve_at(0.0), field, 0.0, l, a)
    return principal_stretches(rest, skin_metric(shape.curve_at(q), field, q, l, a))


def test_a_bent_tube_stretches_as_one_minus_rho_kappa_cos_theta(bent):
    shape, field = bent
    l = np.linspace(0.05, 0.95, 37)
    a = np.linspace(0.0, 2 * np.pi, 48, endpoint=False)
    lam1, lam2 = _stretches(shape, field, 1.0, l, a)
    frames = shape.curve_at(1.0).frames(l)
    # theta from the centre of curvature: the arc bends towards +x, the centre lies at +x
    towards_centre = np.array([1.0, 0.0, 0.0])
    theta = np.arctan2(frames[:, :, 1] @ towards_centre, frames[:, :, 0] @ towards_centre)
    axial = 1.0 - RADIUS_MM / BEND_RADIUS_MM * np.cos(a[None, :] - theta[:, None])
    # the hoop stretch is 1: lambda1 is the axial one on the outer half, lambda2 on the inner
    np.testing.assert_allclose(np.maximum(axial, 1.0), lam1, rtol=0, atol=KNOWN_TOL)
    np.testing.assert_allclose(np.minimum(axial, 1.0), lam2, rtol=0, atol=KNOWN_TOL)


def test_bent_tube_extremes_are_one_plus_and_minus_r_kappa(bent):
    shape, field = bent
    rk = RADIUS_MM / BEND_RADIUS_MM
    rest = lambda l, a: skin_metric(shape.curve_at(0.0), field, 0.0, l, a)  # noqa: E731
    bent_metric = lambda l, a: skin_metric(shape.curve_at(1.0), field, 1.0, l, a)  # noqa: E731
    found = converged_extremes(rest, bent_metric, LENGTH_MM, field.breaks, 16)
    assert found.converged and found.change < STRETCH_TOL
    # the grid's angles include the exact extreme only up to its spacing: 1 - cos(da/2) ~ da^2/8
    grid_error = rk * (1 - np.cos(np.pi / found.grid.angles))
    assert abs(found.maximum.value - (1 + rk)) <= grid_error + KNOWN_TOL
    assert abs(found.minimum.value - (1 - rk)) <= grid_error + KNOWN_TOL
    # the first grid's extremes computed ahead (as the morph search does) are taken, and the answer is the same;
    # on another grid they are ignored
    first = extremes_on(make_grid(LENGTH_MM, field.breaks, START_SPACING_MM, START_ANGLES_PER_INTERVAL * 16),
                        rest, bent_metric, field.breaks)
    calls = []
    counted = lambda l, a: calls.append(len(l)) or bent_metric(l, a)  # noqa: E731
    again = converged_extremes(rest, counted, LENGTH_MM, field.breaks, 16, first=first)
    assert _figures(again) == _figures(found) and len(calls) == len(found.history) - 1
    inner = (0.1, 0.9)
    assert _figures(converged_extremes(rest, bent_metric, LENGTH_MM, field.breaks, 16, inner, first=first)) == (
        _figures(converged_extremes(rest, bent_metric, LENGTH_MM, field.breaks, 16, inner)))


def _figures(e):
    return e.maximum, e.minimum, e.per_link, e.grid.points, e.change, e.converged, e.history


def test_a_straight_tube_growing_in_radius_stretches_only_around():
    z = np.linspace(0.0, LENGTH_MM, 601)
    line = np.column_stack([np.zeros_like(z), np.zeros_like(z), z])
    final = smooth_curve_from_polyline(line, CurveOptions(spacing_mm=0.25, smoothing_mm=0.0))
    shape = blend_shapes(straight_initial_shape(final), final, mode="linear")
    r0, r1 = 2.0, 3.5
    field = _constant_field(r0, r1)
    l = np.linspace(0.0, 1.0, 41)
    a = np.linspace(0.0, 2 * np.pi, 32, endpoint=False)
    for q in (0.5, 1.0):
        lam1, lam2 = _stretches(shape, field, q, l, a)
        np.testing.assert_allclose(lam1, ((1 - q) * r0 + q * r1) / r0, rtol=0, atol=KNOWN_TOL)
        np.testing.assert_allclose(lam2, 1.0, rtol=0, atol=KNOWN_TOL)


def test_the_closed_form_matches_the_eigenvalues_of_g0_inverse_g():
    rng = np.random.default_rng(3)
    m0 = rng.normal(size=(200, 3, 2))
    m1 = rng.normal(size=(200, 3, 2))
    g0, g1 = m0.transpose(0, 2, 1) @ m0, m1.transpose(0, 2, 1) @ m1
    lam1, lam2 = principal_stretches(np.stack([g0[:, 0, 0], g0[:, 0, 1], g0[:, 1, 1]], -1),
                                     np.stack([g1[:, 0, 0], g1[:, 0, 1], g1[:, 1, 1]], -1))
    eig = np.sort(np.linalg.eigvals(np.linalg.solve(g0, g1)).real, axis=1)
    np.testing.assert_allclose(lam1, np.sqrt(eig[:, 1]), rtol=1e-9)
    np.testing.assert_allclose(lam2, np.sqrt(eig[:, 0]), rtol=1e-9)


def _triangle_stretches(rest_v, v, faces):
    """Principal stretches of the piecewise-linear map of each triangle (its deformation gradient)."""
    def edges(x):
        return np.stack([x[faces[:, 1]] - x[faces[:, 0]], x[faces[:, 2]] - x[faces[:, 0]]], axis=-1)  # (F, 3, 2)

    e0, e1 = edges(rest_v), edges(v)
    g0, g1 = e0.transpose(0, 2, 1) @ e0, e1.transpose(0, 2, 1) @ e1
    return principal_stretches(np.stack([g0[:, 0, 0], g0[:, 0, 1], g0[:, 1, 1]], -1),
                               np.stack([g1[:, 0, 0], g1[:, 0, 1], g1[:, 1, 1]], -1))


def test_mesh_triangles_agree_with_the_spline_stretches(bent):
    """Same (l, a) grid at q = 0 and q = 1 (same topology): the per-triangle stretches converge to the exact ones."""
    shape, field = bent
    errors = []
    for rings, na in ((121, 48), (241, 96)):
        l = np.linspace(0.0, 1.0, rings)
        a = 2 * np.pi * np.arange(na) / na
        meshes = []
        for q in (0.0, 1.0):
            curve = shape.curve_at(q)
            sections = sections_on_grid(curve, q, l, field.evaluate_grid(q, l, a), field.evaluate_grid(q, l, a, dl=1))
            meshes.append(tessellate(sweep_from_sections(sections), caps=False))
        lam1_mesh, lam2_mesh = _triangle_stretches(meshes[0].vertices, meshes[1].vertices, meshes[0].faces)
        # exact stretches at each quad's centre (both of its triangles share it)
        lc, ac = 0.5 * (l[1:] + l[:-1]), a + np.pi / na
        lam1, lam2 = _stretches(shape, field, 1.0, lc, ac)
        exact1, exact2 = np.repeat(lam1.reshape(-1), 2), np.repeat(lam2.reshape(-1), 2)
        errors.append(max(np.abs(lam1_mesh - exact1).max(), np.abs(lam2_mesh - exact2).max()))
    # first-order per triangle (its centroid is off the quad centre): halving both steps halves the error
    assert errors[1] < 0.6 * errors[0]
    assert errors[1] < 5e-3


class _FrenetHelix:
    """A helix that hands out its Frenet frames (twist = torsion) instead of the rotation-minimizing ones."""

    def __init__(self, helix):
        self.helix = helix

    def derivative(self, l, order=1):
        return self.helix.derivative(l, order)

    def frames(self, l):
        return self.helix.frenet_frames(l)

    def points(self, l):
        return self.helix.points(l)


@pytest.mark.parametrize("mode", ["rmf", "frenet"])
def test_the_metric_is_that_of_the_surface_points_by_finite_differences(mode):
    """A helix tube with a wavy rho: (E, F, G) against central differences of c + rho (cos a N + sin a B)."""
    from tests.helpers.analytic import Helix

    helix = Helix(r=8.0, h=3.0, turns=0.6)
    curve = helix if mode == "rmf" else _FrenetHelix(helix)
    rng = np.random.default_rng(7)
    knots = bb.open_knots([0.0, 1.0], [6])
    coef = 2.0 + 0.3 * rng.random((len(knots) - bb.DEGREE - 1, 12))
    spline = RadiusSpline(knots, coef)
    field = RadiusField(np.array([0.0, 1.0]), (spline,), (spline,))
    l = np.linspace(0.1, 0.9, 9)
    a = np.linspace(0.0, 2 * np.pi, 10, endpoint=False)
    metric = skin_metric(curve, field, 1.0, l, a, mode)

    def points(lv, av):
        frames = curve.frames(lv)
        rho = field.evaluate_grid(1.0, lv, av)
        ring = np.cos(av)[None, :, None] * frames[:, None, :, 0] + np.sin(av)[None, :, None] * frames[:, None, :, 1]
        return helix.points(lv)[:, None, :] + rho[..., None] * ring

    h = 1e-5
    x_l = (points(l + h, a) - points(l - h, a)) / (2 * h)
    x_a = (points(l, a + h) - points(l, a - h)) / (2 * h)
    expected = np.stack([np.einsum("...i,...i", x_l, x_l), np.einsum("...i,...i", x_l, x_a),
                         np.einsum("...i,...i", x_a, x_a)], axis=-1)
    # central differences: ~h^2 x third derivatives (E ~ 1e3 mm^2 here) plus rounding ~1e-16 x 1e3 / h
    np.testing.assert_allclose(metric, expected, rtol=1e-7, atol=1e-6)


@pytest.mark.parametrize(("p", "m"), [(7, 5), (120, 96), (33, 1)])
def test_the_tube_metric_is_the_metric_of_the_tube_sections_to_the_last_bit(p, m):
    """The fused metric skin_metric uses performs the sections' operations in their order: the same bits."""
    rng = np.random.default_rng(p * m)
    args = (rng.uniform(10.0, 300.0, p), rng.normal(0.0, 0.1, (p, 2)), rng.normal(0.0, 0.01, p),
            np.sort(rng.uniform(0.0, 2.0 * np.pi, m)), rng.uniform(1.0, 5.0, (p, m)), rng.normal(0.0, 30.0, (p, m)),
            rng.normal(0.0, 1.0, (p, m)))
    assert tube_metric(*args).tobytes() == metric_from_sections(tube_sections(*args)).tobytes()


def test_blocks_of_rows_change_no_bit_of_the_metric_or_the_stretches(bent, monkeypatch):
    """skin_metric and principal_stretches take a few rows at a time: the bits of the whole grid at once."""
    shape, field = bent
    l, a = np.linspace(0.0, 1.0, 53), np.linspace(0.0, 2 * np.pi, 24, endpoint=False)
    whole = [skin_metric(shape.curve_at(q), field, q, l, a) for q in (0.0, 0.6)]
    stretches = principal_stretches(*whole)
    monkeypatch.setattr(radius_rows, "BLOCK_POINTS", 5 * len(a))
    blocks = [skin_metric(shape.curve_at(q), field, q, l, a) for q in (0.0, 0.6)]
    assert [m.tobytes() for m in blocks] == [m.tobytes() for m in whole]
    assert [s.tobytes() for s in principal_stretches(*blocks)] == [s.tobytes() for s in stretches]
    assert [s.tobytes() for s in strain._principal_stretches(*whole)] == [s.tobytes() for s in stretches]


def _plain_metric(speed, curvature, twist, x, y, x_l, y_l, x_a, y_a):
    v, vt = speed[:, None], (speed * twist)[:, None]
    axial = v * (1.0 - x * curvature[:, :1] - y * curvature[:, 1:])
    along_n, along_b = x_l - vt * y, y_l + vt * x
    return np.stack([axial**2 + along_n**2 + along_b**2, along_n * x_a + along_b * y_a, x_a**2 + y_a**2], axis=-1)


def _plain_stretches(rest, deformed):
    e0, f0, g0 = np.moveaxis(rest, -1, 0)
    e, f, g = np.moveaxis(deformed, -1, 0)
    det0 = e0 * g0 - f0 * f0
    half_trace = 0.5 * (e0 * g + g0 * e - 2.0 * f0 * f) / det0
    det_ratio = (e * g - f * f) / det0
    mu1 = half_trace + np.sqrt(np.maximum(half_trace**2 - det_ratio, 0.0))
    mu2 = np.where(mu1 > 0.0, det_ratio / np.where(mu1 > 0.0, mu1, 1.0), 0.0)
    return np.sqrt(mu1), np.sqrt(np.maximum(mu2, 0.0))


def test_the_metric_and_the_stretches_in_place_are_the_plain_formulas_to_the_last_bit():
    """Written into few temporaries, the metric and the stretches keep the formulas' operations and order."""
    rng = np.random.default_rng(8)
    p, m = 40, 24
    sections = [rng.normal(0.0, 3.0, (p, m)) for _ in range(6)]
    centerline = (rng.uniform(10.0, 300.0, p), rng.normal(0.0, 0.1, (p, 2)), rng.normal(0.0, 0.01, p))
    metric = strain.metric_from_planes(*centerline, *sections)
    assert metric.tobytes() == _plain_metric(*centerline, *sections).tobytes()
    rest = strain.metric_from_planes(*centerline, *[0.9 * s for s in sections])
    degenerate = metric.copy()
    degenerate[3, 4] = [1.0, 1.0, 1.0]  # E G = F^2: a collapsed rest section
    with pytest.raises(ValueError, match="degenerate"):
        principal_stretches(degenerate, metric)
    for pair in ((rest, metric), (metric, rest), (metric, -rest)):  # -rest: negative roots, NaN and 0 as before
        with np.errstate(invalid="ignore"):
            expected, found = _plain_stretches(*pair), principal_stretches(*pair)
        assert [s.tobytes() for s in found] == [s.tobytes() for s in expected]
