"""The backbone check made at ingest: a centerline that turns tighter than the wall allows is regularized there.

:func:`softdesign.geometry.backbone.regularize_backbone` smooths the final
path where ``r * kappa`` of the curve the build will make reaches the limit,
r the fold radius: the inscribed radius, or less where the path's own wall
is flatter on the inner side of the turn (a real bend's lumen is no circle);
the regularized path then replaces the input one for every later stage (the
blend, the links and the wall fit around it).  A turn that cannot be
regularized is not refused here: it is warned about with its place, and the
fit tests the fitted body itself (issue 29).  Without inscribed radii nothing
is checked.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from softdesign.fitting.closest import closest_surface_points
from softdesign.fitting.selection import NetworkContext, SelectionSettings, other_branch_mask
from softdesign.fitting.wall_fit import WallFit
from softdesign.geometry.backbone import (
    REGULARIZE_REACH,
    TARGET_REACH,
    WALL_REGULARIZE_REACH,
    BackboneError,
    reach_along,
    regularize_backbone,
    wall_fold_radius,
)
from softdesign.geometry.curves import CurveOptions
from softdesign.geometry.network import SelectedPath
from softdesign.limits import MAX_CURVE_SAMPLES
from softdesign.types import FloatArray, FramedCurve

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


def regularized_path(case: Case, path: SelectedPath, vertices: FloatArray | None = None,
                     others: tuple[SelectedPath, ...] = ()) -> tuple[SelectedPath, dict[str, Any] | None]:
    """The path with its too-tight turns regularized, and the ``backbone`` summary (None without radii).

    Where the inscribed radius says the tube folds (``r * kappa >= REGULARIZE_REACH``), the wall itself
    decides: the reach is measured with the fold radius, how far the path's own wall (``vertices`` nearer
    this path than the ``others``) reaches towards the centre of curvature.  A turn that no smoothing tried
    brings below the target is left as it is, with a warning naming the place: the fit checks the fitted
    body (``1 - rho * kappa_n > 0``) and says which body radius fits if it folds.  Never raises on a turn.
    """
    if path.radius is None:
        return path, None
    if case.resample.count is None and path.length / case.resample.spacing_mm > MAX_CURVE_SAMPLES:
        return path, None  # the runner refuses this spacing right after ingest (pipeline/bounds.py), before any work
    options = curve_options(case)
    inscribed, _ = reach_along(path.points, path.radius, options)
    fold = None
    if inscribed.max() >= REGULARIZE_REACH and vertices is not None and len(vertices):
        network = NetworkContext(path.points, tuple(p.points for p in others))
        own = np.asarray(vertices, float)[~other_branch_mask(vertices, network, SelectionSettings().shared_tol_mm)]
        fold = wall_fold_radius(path.points, path.radius, own, options)
    try:
        reg = regularize_backbone(path.points, path.radius, options, fold)
    except BackboneError as err:
        return _unresolved(case, path, path.radius, err, fold)
    summary = reg.summary()
    if fold is not None:
        summary |= {"trigger_reach": WALL_REGULARIZE_REACH, "fold_radius": "wall",
                    "inscribed_reach": float(inscribed.max())}
    notes = list(path.notes)
    if reg.regularized:
        notes.append(
            f"backbone regularized: the centerline turns tighter than the vessel is wide (largest r * kappa "
            f"{reg.reach_before:.3f}, now {reg.reach_after:.3f}); moved by up to {reg.moved_mm.max():.2f} mm over "
            + ", ".join(f"{s.from_mm:.1f}-{s.to_mm:.1f} mm" for s in reg.stretches)
            + " from the inlet (ingest/summary.json: backbone); the wall is fitted around it"
        )
    notes += _inscribed_warning(case, reg.points, path.radius, fold)
    if not reg.regularized and len(notes) == len(path.notes):
        return path, summary
    return replace(path, points=reg.points, notes=tuple(notes)), summary


def _unresolved(case: Case, path: SelectedPath, radius: FloatArray, err: BackboneError,
                fold: FloatArray | None) -> tuple[SelectedPath, dict[str, Any]]:
    """The path left as it is where no smoothing tried brings the reach below the target: a warning, not a refusal."""
    to_end = min(err.arc_mm, path.length - err.arc_mm)
    which = "the inscribed radius" if fold is None else "the wall's reach towards the centre of curvature"
    note = (
        f"warning: the centerline turns tighter than the vessel is wide at {err.arc_mm:.1f} mm from the inlet "
        f"(l = {err.arc_mm / path.length:.4f}, {to_end:.1f} mm from the nearer end): r * kappa = {err.reach:.3f} "
        f"with {which} {err.radius_mm:.3f} mm, and smoothing the backbone over up to twice the radius leaves "
        f"{err.smoothed:.3f} (expected < {TARGET_REACH:g}); the backbone is left as it is and the fit checks "
        "whether the fitted body folds there (if it does, it names the body radius that fits)"
    )
    summary = {"regularized": False, "trigger_reach": REGULARIZE_REACH, "target_reach": TARGET_REACH,
               "reach_before": err.reach, "reach_after": err.reach, "max_moved_mm": 0.0, "stretches": [],
               "unresolved": {"arc_mm": err.arc_mm, "l": err.arc_mm / path.length, "reach": err.reach,
                              "radius_mm": err.radius_mm, "smoothed_reach": err.smoothed}}
    if fold is not None:
        summary |= {"trigger_reach": WALL_REGULARIZE_REACH, "fold_radius": "wall"}
    return replace(path, notes=(*path.notes, note, *_inscribed_warning(case, path.points, radius, fold))), summary


def _inscribed_warning(case: Case, points: FloatArray, radius: FloatArray, fold: FloatArray | None) -> list[str]:
    """A warning where the backbone still turns with ``r * kappa >= 1`` on the inscribed radius (empty elsewhere)."""
    reach, arc = reach_along(points, radius, curve_options(case))
    worst = int(np.argmax(reach))
    if reach[worst] < 1.0:
        return []
    s, along = float(arc[worst]), _arc_of(points)
    wall = "" if fold is None else (
        f"; the wall there reaches {float(np.interp(s, along, fold)):.3f} mm towards the centre of curvature")
    return [
        f"warning: at {s:.1f} mm from the inlet (l = {s / along[-1]:.4f}) the centerline turns with r * kappa = "
        f"{reach[worst]:.3f} on the inscribed radius {float(np.interp(s, along, radius)):.3f} mm{wall}; the "
        "fitted body is checked for folds at the fit (1 - rho * kappa_n > 0)"
    ]


def _arc_of(points: FloatArray) -> FloatArray:
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])


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
