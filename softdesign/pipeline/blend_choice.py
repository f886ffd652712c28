"""Which blend the build uses, and the morph-fold checks made before any fit (seconds, not minutes).

``blend: auto`` (the default) is the seed's linear blend unless some shape
of it folds where neither end shape does; then it is the intrinsic blend,
whose curvature never exceeds the end shapes' (:mod:`softdesign.geometry.morph_fold`).
When the linear blend does not fold, ``auto`` builds exactly what
``blend: linear`` builds.  An explicit ``blend: linear`` that folds is
warned about (the meshes of exported q values away from the
fold still build), naming the q, the place and the fix; a q = 1 centerline that turns
tighter than the vessel is wide is refused whatever the blend.

Without inscribed radii (a centerline file without
``MaximumInscribedSphereRadius``) nothing is checked here and ``auto`` is linear.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from softdesign.fitting.radius_field import RadiusField
from softdesign.geometry.blend import BlendedShape, BlendMode, blend_shapes
from softdesign.geometry.curves import SmoothCurve, l_from_points
from softdesign.geometry.frames import FrameMode
from softdesign.geometry.morph_fold import MORPH_REACH_LIMIT, MorphReach, morph_reach, radius_profile_on
from softdesign.geometry.network import SelectedPath
from softdesign.pipeline.blend_body import body_folds, body_morph
from softdesign.pipeline.notices import Notice

#: A q = 1 shape whose reach r * kappa (r the inscribed radius) is at least this is warned about: a tube of
#: that radius would fold, but a real lumen is flatter on a bend's inner side (the fit decides).
SURE_FOLD = 1.0

@dataclass(frozen=True)
class BlendChoice:
    """The shape built, the blend asked for, the reach of the shape (None without radii), and why."""

    shape: BlendedShape
    requested: str
    reach: MorphReach | None
    linear_reach: MorphReach | None
    reason: str
    warning: str | None = None
    #: ``auto``'s look at the fitted body over each blend's morph, when it switched on it
    body_morph: dict[str, Any] | None = None
    #: the shape ``auto`` judged on the body (``shape`` rebuilt by :func:`choose_blend`'s ``rebuild``), with the
    #: curves of the morph's q grid built; None when no body was judged
    judged: BlendedShape | None = None

    def summary(self) -> dict[str, Any]:
        """The blend summary's extra keys: ``requested``, ``morph`` (reach figures), ``choice`` (text)."""
        return {
            "requested": self.requested,
            "morph": None if self.reach is None else self.reach.as_dict(),
            "linear_morph": None if self.linear_reach is None else self.linear_reach.as_dict(),
            "choice": self.reason,
            "warning": self.warning,
        } | ({} if self.body_morph is None else {"body_morph": self.body_morph})

def choose_blend(
    initial: SmoothCurve,
    final: SmoothCurve,
    keyframes: tuple[tuple[float, SmoothCurve], ...],
    requested: str,
    frames: FrameMode,
    path: SelectedPath,
    body: Callable[[BlendedShape], RadiusField | None] | None = None,
    rebuild: Callable[[BlendedShape], BlendedShape] | None = None,
) -> BlendChoice:
    """Build the blend ``requested`` ("auto", "linear" or "intrinsic") and check its morph for folds.

    A q = 1 centerline that turns tighter than the inscribed radius gives a warning, not a refusal: the
    fitted wall, not the inscribed sphere, decides whether the body folds.  ``body`` gives the wall fitted
    around a shape's q = 1 centerline (:func:`softdesign.pipeline.blend_body.body_field`): ``auto`` judges
    the linear blend's body over the morph on it, and switches to intrinsic when it folds.  ``rebuild`` gives the
    shape the build keeps for a blended shape (the blend stage's, from its key curves' samples): the body is
    judged on that one, returned as ``judged`` with its morph's curves built (None: on the shape as blended).
    """
    mode: BlendMode = "intrinsic" if requested == "intrinsic" else "linear"
    shape = blend_shapes(initial, final, keyframes, mode, frames)
    profile = None if path.radius is None else radius_profile_on(l_from_points(final, path.points), path.radius)
    reach = None if profile is None else morph_reach(shape, *profile)
    # the inscribed radius is no bound of the fitted wall on a bend's flatter inner side: a warning, and the
    # fit tests the fitted body itself (issue 29)
    tight = _final_fold_message(reach, final) if reach is not None and reach.final_reach >= SURE_FOLD else None
    figure = "no inscribed radii to check folds" if reach is None else _figure(reach)
    if mode == "intrinsic":
        return BlendChoice(shape, requested, reach, None, f"intrinsic (asked for: {figure})", tight)
    if reach is not None and profile is not None and reach.blend_folds:
        if requested == "linear":
            warning = (f"blend: linear {_fold_text(reach)}; meshes at export q near {reach.q:.3f} will fail: use "
                       "blend: intrinsic (or auto, the default), whose curvature stays within the end shapes'")
            return BlendChoice(shape, requested, reach, None, f"linear (asked for: {figure})", warning)
        intrinsic = blend_shapes(initial, final, keyframes, "intrinsic", frames)
        fold = morph_reach(intrinsic, *profile)
        why = f"intrinsic (auto: the linear blend {_fold_text(reach)}; intrinsic: {_figure(fold)})"
        return BlendChoice(intrinsic, requested, fold, reach, why, tight)
    judged = None
    if requested == "auto" and body is not None:
        rebuilt = rebuild or (lambda blended: blended)
        judged = rebuilt(shape)
        switched = _judged_on_body(judged, body, (initial, final, keyframes, frames, rebuilt), profile, reach, tight)
        if switched is not None:
            return switched
    why = "asked for" if requested == mode else "the linear blend does not fold"
    return BlendChoice(shape, requested, reach, None, f"linear ({why}: {figure})", tight, judged=judged)


def _judged_on_body(judged: BlendedShape, body: Callable[[BlendedShape], RadiusField | None],
                    ends: tuple[Any, ...], profile: tuple[Any, Any] | None, reach: MorphReach | None,
                    tight: str | None) -> BlendChoice | None:
    """``auto``: the intrinsic blend when the linear blend's fitted body folds mid-morph and the intrinsic one's
    folds less; else None (linear stays).  ``judged`` is the linear blend as the build keeps it, ``ends`` the key
    curves, the frames and the rebuild that gave it."""
    field = body(judged)
    if field is None:
        return None
    linear = body_morph(judged, field)
    if not body_folds(linear):
        return None
    initial, final, keyframes, frames, rebuilt = ends
    intrinsic = blend_shapes(initial, final, keyframes, "intrinsic", frames)
    kept = rebuilt(intrinsic)
    fold = body_morph(kept, field)
    if fold.report.max_rho_kappa >= linear.report.max_rho_kappa:
        return None
    r = linear.report
    why = (f"intrinsic (auto: the fitted body of the linear blend folds mid-morph: rho * kappa = "
           f"{r.max_rho_kappa:.3f} at q = {linear.q:.3f}, {r.arc_mm:.1f} mm from the inlet (folds at 1); intrinsic: "
           f"largest rho * kappa {fold.report.max_rho_kappa:.3f} at q = {fold.q:.3f})")
    intrinsic_reach = None if profile is None else morph_reach(intrinsic, *profile)
    return BlendChoice(intrinsic, "auto", intrinsic_reach, reach, why, tight,
                       {"linear": linear.as_dict(), "intrinsic": fold.as_dict()}, kept)


def pcc_choice(shape: BlendedShape, path: SelectedPath, design: dict[str, Any]) -> dict[str, Any]:
    """The blend summary's extra keys for ``blend: pcc``: the reach of the chain's morph and the design's breaks.

    Each section's curvature is q * kappa, so the morph's largest reach r * kappa is the chain's at q = 1; it is
    reported (and warned about at the fold limit), not refused: the design's tolerance is the user's choice.
    """
    reach = None
    warning = None
    if path.radius is not None:
        reach = morph_reach(shape, *radius_profile_on(l_from_points(shape.keys[-1], path.points), path.radius))
        if reach.reach >= SURE_FOLD:
            warning = (f"blend: pcc: the designed chain turns tighter than the vessel is wide at l = {reach.l:.4f} "
                       f"(r * kappa = {reach.reach:.3f} at q = {reach.q:.3f}): the body folds there; design with a "
                       "smaller design.tolerance_mm or a larger design.min_link_mm")
    reason = (f"pcc (each of the design's {len(design['links'])} section(s) an arc of its own length, curvature "
              "q * kappa, composed from the base"
              + ("" if reach is None else f"; {_figure(reach)}") + ")")
    return {"requested": "pcc", "morph": None if reach is None else reach.as_dict(), "linear_morph": None,
            "choice": reason, "warning": warning, "design_breaks": design["breaks"]}


def describe_choice(summary: dict[str, Any]) -> list[str]:
    """The blend stage's line on the chosen blend (summaries of builds before ``choice`` existed have none)."""
    if "choice" not in summary:
        return []
    return [f"blend chosen: {summary['choice']}"]  # its warning: :func:`blend_notices`


def blend_notices(summary: dict[str, Any]) -> list[Notice]:
    """The chosen blend's warning (a fold over the morph), if any."""
    warning = summary.get("warning")
    return [] if warning is None else [Notice("blend", "fold_mid_morph", "", warning)]

def _figure(reach: MorphReach) -> str:
    return f"largest r * kappa {reach.reach:.3f} at q = {reach.q:.3f}"

def _fold_text(reach: MorphReach) -> str:
    return (
        f"folds mid-morph: at q = {reach.q:.3f}, l = {reach.l:.4f} ({reach.arc_mm:.1f} mm from the inlet) the "
        f"centerline's curvature is {reach.curvature_per_mm:.4f} 1/mm where the inscribed radius is "
        f"{reach.radius_mm:.3f} mm (r * kappa = {reach.reach:.3f}, the tube folds at 1; both end shapes stay "
        f"below {reach.end_reach:.3f}): the straight-to-curved linear blend shortens and kinks the middle"
    )

def _final_fold_message(reach: MorphReach, final: SmoothCurve) -> str:
    l = reach.final_l
    s = float(final.arc_length([l])[0])
    kappa = float(final.curvature([l])[0])
    return (
        f"the q = 1 centerline turns tighter than the inscribed radius: at l = {l:.4f} ({s:.1f} mm from the inlet) "
        f"its radius of curvature is {1.0 / kappa:.3f} mm where the inscribed radius is "
        f"{reach.final_reach / kappa:.3f} mm (r * kappa = {reach.final_reach:.3f}); a lumen is flatter on a bend's "
        "inner side than its inscribed sphere, so the fit tests whether the fitted body folds there "
        "(1 - rho * kappa_n > 0)"
    )


__all__ = ["MORPH_REACH_LIMIT", "BlendChoice", "choose_blend", "describe_choice", "pcc_choice"]
