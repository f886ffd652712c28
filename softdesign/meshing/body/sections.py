"""The body S(q, l, a) = c(q, l) + rho(q, l, a) (cos a N + sin a B) sampled for meshing and integration.

Joins a framed centerline at one q with the radius field: rings on an l grid
(arc-length spacing, joints and ends included once) for the tessellation, and
the same quantities at any l for the volume integral, so the mesh and the
integral it is checked against see one surface.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from softdesign.fitting.radius_field import RadiusField
from softdesign.geometry.frames import FramedSpline
from softdesign.meshing.tessellate import TubeSections, l_grid_from_spacing
from softdesign.meshing.volume import SectionField, Stations, angle_grid
from softdesign.types import FloatArray


def curvature_components(curve: FramedSpline, l: FloatArray, frames: FloatArray) -> FloatArray:
    """(k1, k2) = (T'.N, T'.B) per unit arc length, (n, 2) 1/mm."""
    kvec = curve.curve.curvature_vectors(l)
    return np.column_stack([np.einsum("ni,ni->n", kvec, frames[:, :, 0]), np.einsum("ni,ni->n", kvec, frames[:, :, 1])])


@dataclass(frozen=True)
class BodyStations:
    """The body at q as a function of l (a :data:`~softdesign.meshing.volume.SectionField`).

    rho comes from :meth:`~softdesign.fitting.radius_field.RadiusField.blend_grid`:
    the quadrature nodes do not depend on q, so rho0 and rhof there are
    evaluated once for every q.  :meth:`speed` alone serves the arc lengths.
    """

    curve: FramedSpline
    field: RadiusField
    q: float
    angles: FloatArray

    def __call__(self, l: npt.ArrayLike) -> Stations:
        l = np.asarray(l, float)
        speed = self.curve.curve.speed(l)
        rho_l = self.field.blend_grid(self.q, l, self.angles, dl=1)
        return Stations(
            rho=self.field.blend_grid(self.q, l, self.angles),
            rho_s=rho_l / speed[:, None],
            curvature=curvature_components(self.curve, l, self.curve.frames(l)),
            speed=speed,
        )

    def speed(self, l: npt.ArrayLike) -> FloatArray:
        """ds/dl at l, mm: the stations' speed without the radii."""
        return self.curve.curve.speed(np.asarray(l, float))


def body_stations(curve: FramedSpline, field: RadiusField, q: float, angular_count: int) -> SectionField:
    """The body at q as a function of l (for :func:`~softdesign.meshing.volume.integrate_body`)."""
    return BodyStations(curve, field, q, angle_grid(angular_count))


def body_breaks(field: RadiusField) -> FloatArray:
    """Every l where the integrand may not be smooth: link joints and the radius splines' knots."""
    knots = np.concatenate([np.asarray(s.knots) for s in field.final] + [np.asarray(field.breaks)])
    return np.unique(np.clip(knots, 0.0, 1.0))


def export_l_grid(curve: FramedSpline, field: RadiusField, spacing_mm: float) -> FloatArray:
    """The export's ring parameters at this q: about ``spacing_mm`` apart, every joint once."""
    l_dense = curve.curve.dense_l()
    return l_grid_from_spacing(l_dense, curve.curve.arc_length(l_dense), field.breaks, spacing_mm)


def sections_on_grid(curve: FramedSpline, q: float, l: FloatArray, rho: FloatArray, rho_l: FloatArray) -> TubeSections:
    """Rings at ``l`` with radii ``rho`` (n, na) mm and their l-derivative ``rho_l`` (mm per unit l)."""
    frames = curve.frames(l)
    return TubeSections(
        q=float(q),
        l=l,
        centers=curve.points(l),
        frames=frames,
        rho=rho,
        s=curve.curve.arc_length(l),
        rho_s=rho_l / curve.curve.speed(l)[:, None],
        curvature=curvature_components(curve, l, frames),
    )


def body_sections(
    curve: FramedSpline, field: RadiusField, q: float, spacing_mm: float, angular_count: int
) -> TubeSections:
    """Rings of the body at q about ``spacing_mm`` apart, every joint included once."""
    l = export_l_grid(curve, field, spacing_mm)
    a = angle_grid(angular_count)
    return sections_on_grid(curve, q, l, field.evaluate_grid(q, l, a), field.evaluate_grid(q, l, a, dl=1))
