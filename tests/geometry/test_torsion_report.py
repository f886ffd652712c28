"""The reported torsion is the bend's, not the noise of a nearly straight stretch over kappa^2 (issue 34)."""

from __future__ import annotations

import numpy as np

from softdesign.geometry.curves import TORSION_REL_FLOOR, CurveOptions, smooth_curve_from_polyline


def _helix_then_straight(rng: np.random.Generator) -> np.ndarray:
    """A helix of radius 10 mm and pitch 2 pi 3 mm (torsion 3 / 109 /mm), then a straight run of 60 mm whose
    points wobble by 2 micrometres, as a centerline's placement noise does."""
    t = np.linspace(0.0, 1.5 * np.pi, 300)
    helix = np.column_stack([10.0 * np.cos(t), 10.0 * np.sin(t), 3.0 * t])
    tangent = np.array([-10.0 * np.sin(t[-1]), 10.0 * np.cos(t[-1]), 3.0])
    tangent /= np.linalg.norm(tangent)
    s = np.linspace(0.2, 60.0, 300)[:, None]
    straight = helix[-1] + s * tangent + rng.normal(0.0, 2e-3, (len(s), 3))
    return np.concatenate([helix, straight])


def test_the_largest_torsion_is_the_helixs_not_the_straight_runs_noise():
    points = _helix_then_straight(np.random.default_rng(7))
    curve = smooth_curve_from_polyline(points, CurveOptions(spacing_mm=0.5, smoothing_mm=0.1, end_straight_mm=0.0))
    report = curve.report()
    helix_torsion = 3.0 / (10.0**2 + 3.0**2)
    # the straight run's noise alone turns the osculating plane far faster than the helix does
    l = curve.dense_l()
    straight = curve.arc_length(l) > curve.length - 50.0
    assert np.nanmax(np.abs(curve.torsion(l))[straight]) > 10 * helix_torsion
    assert report.torsion_floor_per_mm == TORSION_REL_FLOOR * report.max_curvature_per_mm
    # the reported figure is the helix's (within its ends' spline ripple)
    assert abs(report.max_abs_torsion_per_mm - helix_torsion) < 0.25 * helix_torsion
