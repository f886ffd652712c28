"""Sanity checks across inputs: does the surface surround the centerline, is the vessel's size human.

The commonest silent failure with vessel data is a unit mismatch (a surface
in metres beside a centerline in millimetres, or a case declaring ``units: m``
for files in mm) or a wrong file; both are caught here, before any costly
stage, with a hint naming the factor or the units that would explain them.
"""

from __future__ import annotations

import numpy as np

from softdesign.errors import ConfigError, InputDataError
from softdesign.geometry.median import median as median_of
from softdesign.types import UNIT_SCALE_TO_MM, FloatArray, Points

#: Fraction of centerline points that must lie inside the surface's bounding box.
INSIDE_FRACTION = 0.9
#: Median centerline-to-wall distance over median inscribed radius must lie in this band.
WALL_RATIO_BAND = (0.2, 5.0)
#: The surface's extent over the centerline's for one vessel (the wall adds a diameter to the path's extent; a
#: short wide vessel reaches a few times): the unit hint needs the rescaled surface within it.
EXTENT_RATIO_BAND = (0.5, 10.0)
#: Unit factors tried when the check fails, with what each would mean.
UNIT_FACTORS = (
    (1000.0, "surface in m, centerline in mm"),
    (0.001, "surface in mm, centerline in m"),
    (10.0, "surface in cm, centerline in mm"),
    (0.1, "surface in mm, centerline in cm"),
    (100.0, "surface in m, centerline in cm"),
    (0.01, "surface in cm, centerline in m"),
)
#: Median inscribed radius of a human vessel, mm: from a small artery or vein (0.3 mm) to a wide
#: aorta (20 mm, a 40 mm lumen).  A unit slip scales it by 10, 100 or 1000, far outside this band.
PLAUSIBLE_RADIUS_MM = (0.3, 20.0)
#: Centerline length of a human vessel path, mm: the longest arterial path, heart to foot, is
#: about 1.5 m; a path between an inlet and an outlet shorter than 5 mm (eight diameters of the
#: narrowest vessel above) is no vessel segment worth an actuator.
PLAUSIBLE_LENGTH_MM = (5.0, 2000.0)
#: Nearest distances by measuring every pair up to this many (a (n, V) float64 array of 32 MB), a KD-tree beyond.
BRUTE_FORCE_PAIRS = 4_000_000
#: Points measured together by the direct method: on the sample case (352 points, 8,455 vertices) blocks of 16
#: took 6 ms of CPU, of 64 22 ms, all at once 48 ms (a block's table stays in the processor's cache, and its
#: product is too small for BLAS to spread over threads).
NEAREST_BLOCK = 16


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
    distance = median_of(nearest_distances(points, vertices))
    if radius is not None and np.all(np.isfinite(radius)) and median_of(radius) > 0:
        ratio = distance / median_of(radius)
        return bool(WALL_RATIO_BAND[0] <= ratio <= WALL_RATIO_BAND[1])
    return bool(distance < 0.25 * float(np.min(hi - lo)))


def nearest_distances(points: Points, vertices: Points) -> FloatArray:
    """Distance (n,) mm from each of ``points`` (n, 3) to its nearest of ``vertices`` (V, 3).

    Up to BRUTE_FORCE_PAIRS point-vertex pairs, every pair is measured (numpy alone: the sample case's check
    costs a few milliseconds, where importing scipy's KD-tree costs about 0.25 s); beyond, a KD-tree.  Both give
    the exact nearest distance, up to rounding.
    """
    points, vertices = np.asarray(points, dtype=float), np.asarray(vertices, dtype=float)
    if len(points) * len(vertices) > BRUTE_FORCE_PAIRS:
        from scipy.spatial import cKDTree

        # built for one query of a few hundred points: a median-split tree takes twice as long to build, and the
        # nearest distances do not depend on how the tree is split
        tree = cKDTree(vertices, balanced_tree=False, compact_nodes=False)
        return np.asarray(tree.query(points)[0], dtype=float)
    # |p - v|^2 = |p|^2 + min over v of (|v|^2 - 2 p.v), relative to the vertices' centre so that the rounding
    # stays small; NEAREST_BLOCK points at a time, so that each block's table stays in the processor's cache
    centre = vertices.mean(axis=0)
    p, v = points - centre, vertices - centre
    v_squared = np.einsum("ij,ij->i", v, v)
    least = np.empty(len(p))
    for start in range(0, len(p), NEAREST_BLOCK):
        block = p[start:start + NEAREST_BLOCK] @ (-2.0 * v.T)
        block += v_squared
        least[start:start + NEAREST_BLOCK] = block.min(axis=1)
    nearest: FloatArray = np.sqrt(np.maximum(least + np.einsum("ij,ij->i", p, p), 0.0))
    return nearest


def check_surface_surrounds(
    points: Points, radius: FloatArray | None, vertices: Points, where: str
) -> None:
    """Raise InputDataError when the surface does not surround the centerline.

    When scaling the surface by a unit factor would make it surround the
    centerline, the message names that factor and the likely units.
    """
    if surrounds(points, radius, vertices):
        return
    extent_c = float(np.ptp(points, axis=0).max())
    extent_s = float(np.ptp(vertices, axis=0).max())
    # a units mismatch explains it only when the rescaled surface is the centerline's size and surrounds it: a
    # surface 1000 times larger would contain a centerline that is merely elsewhere
    hint = next((why for factor, why in UNIT_FACTORS
                 if EXTENT_RATIO_BAND[0] <= extent_s * factor / max(extent_c, 1e-300) <= EXTENT_RATIO_BAND[1]
                 and surrounds(points, radius, vertices * factor)), None)
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


def plausible_vessel(length_mm: float, radius_mm: float | None) -> bool:
    """True when a path of this length (and median inscribed radius, if known), in mm, can be a human vessel."""
    length_ok = PLAUSIBLE_LENGTH_MM[0] <= length_mm <= PLAUSIBLE_LENGTH_MM[1]
    return length_ok and (radius_mm is None or PLAUSIBLE_RADIUS_MM[0] <= radius_mm <= PLAUSIBLE_RADIUS_MM[1])


def check_vessel_scale(length_mm: float, radius: FloatArray | None, units: str, where: str) -> None:
    """Raise ConfigError when the vessel's size in the declared ``units`` is not a human vessel's.

    Parameters
    ----------
    length_mm : the selected path's length, converted from ``units`` to mm
    radius : its inscribed radii (mm), or None when the file has none (then only the length is judged)
    units : the case's ``units`` ("mm", "cm" or "m")
    where : names the input in the message (e.g. ``final.centerline aorta.vtp``)

    The message gives the figures and every other unit in which the vessel would be plausible.
    """
    known = radius is not None and len(radius) > 0 and bool(np.all(np.isfinite(radius)))
    median = median_of(radius) if radius is not None and known else None
    if plausible_vessel(length_mm, median):
        return
    lo, hi = PLAUSIBLE_RADIUS_MM
    message = (
        f"{where}: with units: {units} the vessel is {_size_text(length_mm, median)}, not a human vessel "
        f"(expected a median radius of {lo:g} to {hi:g} mm and a length of {PLAUSIBLE_LENGTH_MM[0]:g} to "
        f"{PLAUSIBLE_LENGTH_MM[1]:g} mm)"
    )
    # the same numbers read in another unit: scaled by that unit's size over the declared one's
    factors = {other: scale / UNIT_SCALE_TO_MM[units] for other, scale in UNIT_SCALE_TO_MM.items() if other != units}
    rescaled = {other: (length_mm * f, None if median is None else median * f) for other, f in factors.items()}
    fits = {other: size for other, size in rescaled.items() if plausible_vessel(*size)}
    if fits:
        sizes = ", or ".join(f"with units: {other} it would be {_size_text(*size)}" for other, size in fits.items())
        which = f"set units: {next(iter(fits))} in the case file" if len(fits) == 1 else (
            "set the case file's units: to those the files are in"
        )
        message += f"; {sizes}: {which}"
    else:
        message += (
            f"; no units ({', '.join(UNIT_SCALE_TO_MM)}) make it plausible: check that the file is a vessel "
            "centerline and that the case file's units: are its units"
        )
    raise ConfigError(message)


def _size_text(length_mm: float, radius_mm: float | None) -> str:
    """``104 m long with a 3.36 m median radius``, ``40 mm long with a 3 mm median radius``."""
    radius = "" if radius_mm is None else f" with a {_length(radius_mm)} median radius"
    return f"{_length(length_mm)} long{radius}"


def _length(value_mm: float) -> str:
    """A length for a message, 3 significant digits: in m from 1000 mm up (no exponent), else in mm."""
    if abs(value_mm) >= 1000.0:
        metres = value_mm / 1000.0
        return f"{metres:.0f} m" if abs(metres) >= 1000.0 else f"{metres:.3g} m"
    return f"{value_mm:.3g} mm"
