"""Checks of the analytic bodies the meshing tests use (tests/helpers/bodies.py)."""

from __future__ import annotations

import numpy as np

from softdesign.meshing.volume import angle_grid
from tests.helpers.bodies import FRAME_TOL, circle_rho, circular_arc, helix, straight_line


def test_frames_are_rotation_minimizing_and_curvature_matches():
    """The builders' frames are orthonormal, right-handed, T = c', and N' = -k1 T, B' = -k2 T."""
    h = 1e-5
    for line in (straight_line(10.0), circular_arc(15.0, 1.2), helix(6.0, 9.0, 1.5)):
        s = np.linspace(0.1, line.length - 0.1, 7)
        f = line.frames(s)
        identity = np.broadcast_to(np.eye(3), f.shape)
        np.testing.assert_allclose(np.einsum("nji,njk->nik", f, f), identity, rtol=0, atol=FRAME_TOL)
        np.testing.assert_allclose(np.linalg.det(f), 1.0, rtol=0, atol=FRAME_TOL)
        tangent = (line.points(s + h) - line.points(s - h)) / (2 * h)
        np.testing.assert_allclose(tangent, f[:, :, 2], rtol=0, atol=1e-8)  # central difference, O(h^2)
        df = (line.frames(s + h) - line.frames(s - h)) / (2 * h)
        k = line.curvature(s)
        np.testing.assert_allclose(df[:, :, 0], -k[:, :1] * f[:, :, 2], rtol=0, atol=1e-8)
        np.testing.assert_allclose(df[:, :, 1], -k[:, 1:] * f[:, :, 2], rtol=0, atol=1e-8)


def test_eccentric_circle_rho_traces_the_circle():
    """rho(a) (cos a, sin a) lies on the circle of radius r about (e, 0)."""
    a = angle_grid(32)
    rho = circle_rho(2.0, 0.7, 32)
    np.testing.assert_allclose(np.hypot(rho * np.cos(a) - 0.7, rho * np.sin(a)), 2.0, rtol=0, atol=FRAME_TOL)
