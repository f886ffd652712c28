"""A cap on the body's radius over one stretch of the path only, and the stretches a fold needs capped (issue 43).

Where a path turns from a wide trunk into a branch tighter than the trunk is
wide, the fitted tube folds (``rho * kappa_n >= 1``,
:mod:`softdesign.fitting.radius_field`).  Holding the whole body thinner
(``fit.max_radius_mm``) removes the fold and takes the body off the wall
everywhere else.  A *local cap* holds it thinner over the folding stretch only:

    cap(s) = radius_mm                                       from_mm <= s <= to_mm
    cap(s) = radius_mm + (d / taper_mm) (top - radius_mm)    d = distance from the stretch, 0 < d < taper_mm
    cap(s) = no cap                                          beyond the taper

s the arc length of the q = 1 centerline from the inlet (mm), ``top`` the
largest coefficient of the fitted spline (where the cap reaches it, it no longer
binds).  Each coefficient C[i, :] of the whole path's spline is clamped to the
least cap over its B-spline's support [t_i, t_{i+4}] (the bases are non-negative
and sum to one), so ``rho(s, a) <= cap(s)`` everywhere and rho is never raised;
links are then split from the capped spline, so joints stay C2.  A coefficient
whose support only touches the stretch is held at ``radius_mm`` too, so the body
is a little thinner up to one support width (4 knot intervals) past each end
of the stretch before the taper: the capped stretch a user reads is
``from_mm - taper_mm`` to ``to_mm + taper_mm``.

:func:`fold_stretches` gives, for a field that folds, the stretches (runs of
the fold grid's rows where ``rho * kappa_n`` exceeds the fix's reach) and the
cap radius each needs: the least ``reach / kappa_n`` over the run's points where
it is exceeded, as :func:`~softdesign.fitting.radius_field.fold_fix_radius`
does for the whole path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from softdesign.fitting.bspline_surface import RadiusSpline, SurfaceFit, split_at_breaks
from softdesign.fitting.radius_field import FOLD_FIX_REACH, RadiusField, curve_curvature, fold_grid
from softdesign.types import FloatArray, FramedCurve

#: Runs of folding rows closer than this are one stretch, mm (one take-off, not two).
MERGE_GAP_MM = 2.0
#: The taper offered is at least this, mm, and at least the drop from the radius before or after to the cap
#: (a cone no steeper than 45 degrees).
MIN_TAPER_MM = 2.0


@dataclass(frozen=True)
class LocalCap:
    """The body held at most ``radius_mm`` from ``from_mm`` to ``to_mm`` (mm from the inlet), tapering over
    ``taper_mm``."""

    from_mm: float
    to_mm: float
    radius_mm: float
    taper_mm: float

    def as_key(self) -> dict[str, float]:
        """The case file's entry of ``fit.local_max_radius``."""
        return {"from_mm": self.from_mm, "to_mm": self.to_mm, "radius_mm": self.radius_mm, "taper_mm": self.taper_mm}

    def key_text(self) -> str:
        """The entry as YAML flow text a user can paste."""
        return (f"{{from_mm: {self.from_mm:g}, to_mm: {self.to_mm:g}, radius_mm: {self.radius_mm:g}, "
                f"taper_mm: {self.taper_mm:g}}}")

    @property
    def span_mm(self) -> tuple[float, float]:
        """Where the body differs from the fit: the stretch and its tapers, mm from the inlet."""
        return self.from_mm - self.taper_mm, self.to_mm + self.taper_mm


def cap_over(caps: tuple[LocalCap, ...], lo_mm: FloatArray, hi_mm: FloatArray, top_mm: float) -> FloatArray:
    """The least cap over each interval [lo, hi] (k,) mm; ``top_mm`` where no cap binds (k,) mm."""
    lo, hi = np.asarray(lo_mm, float), np.asarray(hi_mm, float)
    out = np.full(lo.shape, float(top_mm))
    for cap in caps:
        # the cap falls to radius_mm towards the stretch: its least value on [lo, hi] is at the point nearest it
        distance = np.maximum(np.maximum(cap.from_mm - hi, lo - cap.to_mm), 0.0)
        if cap.taper_mm > 0.0:
            value = cap.radius_mm + distance * ((top_mm - cap.radius_mm) / cap.taper_mm)
        else:  # a step: the cap binds on the stretch only
            value = np.where(distance > 0.0, top_mm, cap.radius_mm)
        out = np.minimum(out, value)
    return out


def capped_locally(spline: RadiusSpline, caps: tuple[LocalCap, ...], length_mm: float) -> RadiusSpline:
    """``spline`` (the whole path's, knots in normalized l), each coefficient row held at its support's least cap."""
    top = float(spline.coefficients.max())
    knots = spline.knots * float(length_mm)
    count = spline.coefficients.shape[0]
    limit = cap_over(caps, knots[:count], knots[4:count + 4], top)
    return RadiusSpline(spline.knots.copy(), np.minimum(spline.coefficients, limit[:, None]))


def surface_capped_locally(surface: SurfaceFit, caps: tuple[LocalCap, ...], length_mm: float,
                           breaks: tuple[float, ...]) -> SurfaceFit:
    """The fitted surface with the local caps: the whole path's spline capped, the links split from it again."""
    if not caps:
        return surface
    whole = capped_locally(surface.whole, caps, length_mm)
    return replace(surface, whole=whole, links=split_at_breaks(whole, breaks))


def check_caps_on_path(caps: tuple[LocalCap, ...], length_mm: float) -> list[str]:
    """What is wrong with caps that lie outside a path of ``length_mm`` (empty when none)."""
    return [f"fit.local_max_radius[{i}]: from_mm {c.from_mm:g} is at or past the path's end ({length_mm:.1f} mm "
            "from the inlet); expected a stretch within the path" for i, c in enumerate(caps) if c.from_mm >= length_mm]


@dataclass(frozen=True)
class FoldStretch:
    """A stretch where the body folds: its cap, and the turn there.

    Attributes
    ----------
    cap : the local cap that brings rho * kappa_n to the fix's reach there
    radius_before_mm, radius_after_mm : the body's mean radius at the stretch's start and end, mm
    turn_deg : the angle between the centerline's tangents at the start and the end, degrees
    bend_radius_mm : the tightest radius of curvature in the stretch, mm
    """

    cap: LocalCap
    radius_before_mm: float
    radius_after_mm: float
    turn_deg: float
    bend_radius_mm: float

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready (mm, degrees)."""
        return {"local_max_radius": self.cap.as_key(), "radius_before_mm": self.radius_before_mm,
                "radius_after_mm": self.radius_after_mm, "turn_deg": self.turn_deg,
                "bend_radius_mm": self.bend_radius_mm}

    def text(self) -> str:
        """Where, how wide before and after, and the turn."""
        return (f"{self.cap.from_mm:g}-{self.cap.to_mm:g} mm from the inlet, where the body's radius goes from "
                f"{self.radius_before_mm:.2f} mm to {self.radius_after_mm:.2f} mm and the path turns "
                f"{self.turn_deg:.0f} deg (tightest radius of curvature {self.bend_radius_mm:.2f} mm)")


def fold_stretches(curve: FramedCurve, field: RadiusField, q: float = 1.0,
                   reach: float = FOLD_FIX_REACH) -> tuple[FoldStretch, ...]:
    """The stretches where ``rho * kappa_n > reach`` at q, each with the local cap that brings it to ``reach``.

    Parameters
    ----------
    curve : the centerline at q, l normalized
    field : the radius field
    q : blend parameter in [0, 1]
    reach : the rho * kappa_n the cap brings the body to
    """
    l, a, k_n_row, k_b_row = fold_grid(curve, field)
    k_n = k_n_row[:, None] * np.cos(a)[None, :] + k_b_row[:, None] * np.sin(a)[None, :]
    rho = field.evaluate_grid(q, l, a)
    over = rho * k_n > reach
    rows = np.flatnonzero(over.any(axis=1))
    if rows.size == 0:
        return ()
    s = l * curve.length
    splits = np.flatnonzero(np.diff(s[rows]) > MERGE_GAP_MM) + 1
    mean = rho.mean(axis=1)
    step = max(1, int(round(MERGE_GAP_MM / max(s[1] - s[0], 1e-12))))
    out = []
    for run in np.split(rows, splits):
        first, last = int(run[0]), int(run[-1])
        block = over[first:last + 1]
        radius = math.floor(100.0 * float(np.min(reach / k_n[first:last + 1][block])) + 1e-9) / 100.0
        # the rows either side of the run, rounded outwards to 0.1 mm: the fold starts and ends between rows
        start = math.floor(10.0 * s[max(first - 1, 0)]) / 10.0
        stop = math.ceil(10.0 * s[min(last + 1, len(s) - 1)]) / 10.0
        # the body's radius a little outside the stretch (the trunk before a take-off, the branch after)
        before, after = float(mean[max(first - step, 0)]), float(mean[min(last + step, len(s) - 1)])
        taper = max(MIN_TAPER_MM, math.ceil(2.0 * (max(before, after) - radius)) / 2.0)
        tangents = curve.derivative(np.clip(np.array([start, stop]) / curve.length, 0.0, 1.0), 1)
        cosine = float(np.dot(tangents[0], tangents[1]) / np.prod(np.linalg.norm(tangents, axis=1)))
        kappa = float(np.max(curve_curvature(curve, l[first:last + 1])))
        out.append(FoldStretch(LocalCap(start, stop, radius, taper), before, after,
                               float(np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))), 1.0 / kappa))
    return tuple(out)


def fold_advice(message: str, stretches: tuple[FoldStretch, ...]) -> str:
    """A fold's refusal with the local caps offered first, before the whole-path cap the message already names."""
    if not stretches:
        return message
    keys = ", ".join(s.cap.key_text() for s in stretches)
    where = "; ".join(s.text() for s in stretches)
    spans = ", ".join(f"{max(lo, 0.0):g}-{hi:g} mm" for lo, hi in (s.cap.span_mm for s in stretches))
    local = (f"it folds at {where}. Hold the body thinner there only, tapering back to the fitted wall over "
             f"taper_mm on each side: fit: {{local_max_radius: [{keys}]}} (the body differs from the fitted wall "
             f"over {spans} only, and is on it elsewhere)")
    head, found, whole = message.partition("; a body of radius at most")
    if not found:
        return f"{message}; {local}"
    return f"{head}; {local}; or, along the whole path, a body of radius at most{whole}"


__all__ = ["FoldStretch", "LocalCap", "cap_over", "capped_locally", "check_caps_on_path", "fold_advice",
           "fold_stretches", "surface_capped_locally"]
