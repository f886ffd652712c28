"""Sanity checks across inputs: does the surface surround the centerline, are radii plausible.

The commonest silent failure with vessel data is a unit mismatch (a surface
in metres beside a centerline in millimetres) or a wrong file; both are
caught here with a hint naming the factor that would explain them.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from softdesign.errors import InputDataError
from softdesign.types import FloatArray, Points

#: Fraction of centerline points that must lie inside the surface's bounding box.
INSIDE_FRACTION = 0.9
#: Median centerline-to-wall distance over median inscribed radius must lie in this band.
WALL_RATIO_BAND = (0.2, 5.0)
#: Unit factors tried when the check fails, with what each would mean.
UNIT_FACTORS = (
    (1000.0, "surface in m, centerline in mm"),
    (0.001, "surface in mm, centerline in m"),
    (10.0, "surface in cm, centerline in mm"),
    (0.1, "surface in mm, centerline in cm"),
    (100.0, "surface in m, centerline in cm"),
    (0.01, "surface in cm, centerline in m"),
)
#: Vessel radii outside this range (mm) suggest wrong units.
PLAUSIBLE_RADIUS_MM = (0.1, 60.0)


def surrounds(points: Points, radius: FloatArray | None, vertices: Points) -> bool:
    """True when the surface plausibly encloses the centerline.

    Most centerline points must lie inside the surface's bounding box, and
    the median distance from a centerline point to its nearest wall vertex
    must be of the order of the inscribed radius (or, without radii, small
    against the surface's extent).
    """
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    pad = 0.05 * (hi - lo)
    inside = np.all((points >= lo - pad) & (points <= hi + pad), axis=1).mean()
    if inside < INSIDE_FRACTION:
        return False
    distance = np.median(cKDTree(vertices).query(points)[0])
    if radius is not None and np.all(np.isfinite(radius)) and np.median(radius) > 0:
        ratio = distance / float(np.median(radius))
        return WALL_RATIO_BAND[0] <= ratio <= WALL_RATIO_BAND[1]
    return bool(distance < 0.25 * float(np.min(hi - lo)))


def check_surface_surrounds(
    points: Points, radius: FloatArray | None, vertices: Points, where: str
) -> None:
    """Raise InputDataError when the surface does not surround the centerline.

    When scaling the surface by a unit factor would make it surround the
    centerline, the message names that factor and the likely units.
    """
    if surrounds(points, radius, vertices):
        return
    hint = next((why for factor, why in UNIT_FACTORS if surrounds(points, radius, vertices * factor)), None)
    extent_c = float(np.ptp(points, axis=0).max())
    extent_s = float(np.ptp(vertices, axis=0).max())
    message = (
        f"{where}: the surface does not surround the centerline (centerline extent {extent_c:.4g}, "
        f"surface extent {extent_s:.4g}, in the case's units converted to mm)"
    )
    if hint is not None:
        message += (
            f"; a units mismatch would explain it ({hint}): export both in the same units "
            "or set final.surface_units"
        )
    else:
        message += "; check that final.surface and final.centerline belong to the same vessel"
    raise InputDataError(message)


def radius_note(radius: FloatArray | None, where: str) -> str | None:
    """A warning when inscribed radii are implausible for a vessel in mm, else None."""
    if radius is None or len(radius) == 0:
        return None
    median = float(np.median(radius))
    lo, hi = PLAUSIBLE_RADIUS_MM
    if lo <= median <= hi:
        return None
    return (
        f"warning: {where}: median MaximumInscribedSphereRadius is {median:.4g} mm, outside the "
        f"plausible {lo}..{hi} mm for a vessel; check units: in the case file"
    )
