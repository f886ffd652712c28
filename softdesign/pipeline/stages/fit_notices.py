"""The fit's warnings, each with its place (:mod:`softdesign.pipeline.notices`): read from the fit's summary.

The texts are the fit's own sentences (coverage, the fold over the morph,
ends held at the inscribed radius, thin end rings, a tilted end cut square,
a centerline that strays from the vessel's axis); here they get their stage,
code and place, so that the terminal, the manifest and the report list each
once.
"""

from __future__ import annotations

from typing import Any

from softdesign.fitting.end_checks import THIN_END_RATIO, thin_end_warnings
from softdesign.geometry.end_planes import RIM_GAP_TOLERANCE_MM, rim_gap_warnings
from softdesign.pipeline.notices import Notice

STAGE = "fit"


def fit_notices(summary: dict[str, Any]) -> list[Notice]:
    """Every warning of a fit's ``summary`` (``fit/summary.json``), in the order the fit found them."""
    notices = [Notice(STAGE, _coverage_code(text), "", text) for text in summary.get("warnings", [])]
    for end, held in summary.get("ends", {}).items():
        if end.endswith("_held"):
            name = end.removesuffix("_held")
            notices.append(Notice(STAGE, "end_held", name, (
                f"the fitted radius went to {held['rho_min_mm']:.3f} mm at {held['at_mm']:.1f} mm from the {name} "
                f"(its wall points lean inwards): that end is held at the inscribed radius over "
                f"{held['from_mm']:.1f}-{held['to_mm']:.1f} mm and fitted again")))
    ends = summary.get("ends", {})
    notices += [Notice(STAGE, "thin_end", name, text) for name, text in zip(
        [n for n, e in ends.items() if "ratio" in e and e["ratio"] < THIN_END_RATIO], thin_end_warnings(ends),
        strict=True)]
    square = {end: c for end, c in summary.get("end_cut", {}).items() if not c["applied"] and "rim_gap_mm" in c}
    gaps = rim_gap_warnings(square)
    notices += [Notice(STAGE, "tilted_end", name, text) for name, text in zip(
        [n for n, c in square.items() if c is not None and _gap_over(c)], gaps, strict=True)]
    stray = summary.get("centerline_stray")
    if stray is not None:
        notices.append(Notice(STAGE, "centerline_stray", "", stray))
    return notices


def _coverage_code(text: str) -> str:
    """The code of one of the summary's own warnings (coverage and morph fold), from the sentence's start."""
    if text.startswith("the fitted body folds mid-morph"):
        return "fold_mid_morph"
    if text.startswith("no wall seen all round"):
        return "unseen_wall"
    return "all_wall_distance"


def _gap_over(cut: dict[str, Any]) -> bool:
    """The end's rim gap is one :func:`rim_gap_warnings` names."""
    return bool(cut["rim_gap_mm"] > RIM_GAP_TOLERANCE_MM)
