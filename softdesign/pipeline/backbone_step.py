"""The backbone check made at ingest: a centerline that turns tighter than the vessel is wide is regularized there.

:func:`softdesign.geometry.backbone.regularize_backbone` smooths the final
path where ``r * kappa`` of the curve the build will make reaches the limit;
the regularized path then replaces the input one for every later stage (the
blend, the links and the wall fit around it).  This takes seconds, so a turn
that cannot be regularized is refused before any fit, naming the place and
the fixes.  Without inscribed radii nothing is checked.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from softdesign.errors import InputDataError
from softdesign.fitting.metrics import closest_surface_points
from softdesign.fitting.wall_fit import WallFit
from softdesign.geometry.backbone import TARGET_REACH, BackboneError, regularize_backbone
from softdesign.geometry.curves import CurveOptions
from softdesign.geometry.network import SelectedPath
from softdesign.limits import MAX_CURVE_SAMPLES
from softdesign.types import FramedCurve

if TYPE_CHECKING:  # only annotations: the report loads stage results without the case file's models
    from softdesign.config import Case


def curve_options(case: Case, count: int | None = None) -> CurveOptions:
    """The case's resampling settings (``count`` forces the final shape's sample count)."""
    r = case.resample
    return CurveOptions(
        spacing_mm=r.spacing_mm,
        count=count if count is not None else r.count,
        smoothing_mm=r.smoothing_mm,
        end_straight_mm=r.end_straight_mm,
    )


def regularized_path(case: Case, path: SelectedPath) -> tuple[SelectedPath, dict[str, Any] | None]:
    """The path with its too-tight turns regularized, and the ``backbone`` summary (None without radii).

    Raises
    ------
    InputDataError
        A turn that the widest smoothing tried does not bring below the target reach.
    """
    if path.radius is None:
        return path, None
    if case.resample.count is None and path.length / case.resample.spacing_mm > MAX_CURVE_SAMPLES:
        return path, None  # the runner refuses this spacing right after ingest (pipeline/bounds.py), before any work
    try:
        reg = regularize_backbone(path.points, path.radius, curve_options(case))
    except BackboneError as err:
        to_end = min(err.arc_mm, path.length - err.arc_mm)
        raise InputDataError(
            f"final.centerline: the centerline turns tighter than the vessel is wide at {err.arc_mm:.1f} mm from the "
            f"inlet (l = {err.arc_mm / path.length:.4f}, {to_end:.1f} mm from the nearer end): r * kappa "
            f"= {err.reach:.3f} with the inscribed radius {err.radius_mm:.3f} mm, expected < {TARGET_REACH:g} after "
            "regularizing the backbone, and smoothing it over up to twice the radius does not bring it lower; "
            "straighten that end (resample.end_straight_mm), or choose another final.path or final.inlet"
        ) from err
    if not reg.regularized:
        return path, reg.summary()
    note = (
        f"backbone regularized: the centerline turns tighter than the vessel is wide (largest r * kappa "
        f"{reg.reach_before:.3f}, now {reg.reach_after:.3f}); moved by up to {reg.moved_mm.max():.2f} mm over "
        + ", ".join(f"{s.from_mm:.1f}-{s.to_mm:.1f} mm" for s in reg.stretches)
        + " from the inlet (ingest/summary.json: backbone); the wall is fitted around it"
    )
    return replace(path, points=reg.points, notes=(*path.notes, note)), reg.summary()


def stretch_fit_errors(backbone: dict[str, Any] | None, wall: WallFit, curve: FramedCurve) -> list[dict[str, float]]:
    """True distances of the kept wall points to the fitted surface on each regularized stretch.

    Empty when nothing was regularized.  ``from_l`` and ``to_l`` are normalized l on the backbone.
    """
    if not backbone or not backbone["regularized"]:
        return []
    kept = wall.polar.subset(wall.selection.keep)
    out = []
    for s in backbone["stretches"]:
        lo, hi = np.clip([s["from_mm"] / curve.length, s["to_mm"] / curve.length], 0.0, 1.0)
        on = kept.subset((kept.l >= lo) & (kept.l <= hi))
        d = closest_surface_points(curve, wall.surface.whole, on)[0] if len(on) else np.zeros(0)
        out.append({"from_l": float(lo), "to_l": float(hi), "points": int(len(on)),
                    "rms_mm": float(np.sqrt(np.mean(d**2))) if len(d) else float("nan"),
                    "max_mm": float(d.max(initial=0.0))})
    return out


def describe_backbone_fit(stretches: list[dict[str, float]]) -> list[str]:
    """The fit stage's lines on the regularized stretches."""
    return [
        f"regularized backbone, l {s['from_l']:.3f}-{s['to_l']:.3f}: true distance of its {s['points']} wall points "
        f"RMS {s['rms_mm']:.4f} mm, max {s['max_mm']:.4f} mm"
        for s in stretches
    ]
