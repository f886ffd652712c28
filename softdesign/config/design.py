"""The case file's ``design:`` block: the bounds of the composed-chain design stage (issue 30).

Its own module so that :mod:`softdesign.config` only hooks it in.  The
numbers are mm and degrees as the keys say; the stage
(:mod:`softdesign.pipeline.stages.design`) turns them into the core's options.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

from softdesign.config.types import FiniteFloat, Integer
from softdesign.limits.design import MAX_DESIGN_LINKS


class Design(BaseModel):
    """Sections of constant curvature composed from the base frame, within these bounds of the q = 1 centerline."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    tolerance_mm: FiniteFloat = Field(1.0, gt=0.0, le=100.0)
    """Largest true distance between the composed chain and the q = 1 centerline, both ways, the tip included, mm."""
    tip_tolerance_mm: FiniteFloat | None = Field(None, gt=0.0, le=100.0)
    """Largest distance between the chain's tip and the centerline's end, mm (default: tolerance_mm)."""
    tip_tolerance_deg: FiniteFloat | None = Field(None, gt=0.0, le=180.0)
    """Largest angle between the chain's tip tangent and the centerline's end tangent, degrees (default: none)."""
    max_links: Integer = Field(20, ge=1, le=MAX_DESIGN_LINKS)
    """Most sections searched (k = 1, 2, ... up to this)."""
    min_link_mm: FiniteFloat | None = Field(None, gt=0.0)
    """Shortest section, mm (default: the vessel's median inscribed diameter)."""


def pcc_blend_problems(blend: str, design: Design | None, initial_kind: str, keyframes: int) -> list[str]:
    """Why ``blend: pcc`` cannot build this case (empty when it can): it morphs a designed chain from straight."""
    if blend != "pcc":
        return []
    problems = []
    if design is None:
        problems.append("blend: pcc morphs the designed chain of constant-curvature sections and needs a design: "
                        "add a design: block (e.g. design: {tolerance_mm: 1}), or use blend: auto")
    if initial_kind != "straight":
        problems.append(f"blend: pcc starts straight at q = 0 (every section's curvature is q * kappa), got "
                        f"initial.kind: {initial_kind}; use initial.kind: straight or another blend")
    if keyframes:
        problems.append("blend: pcc is set by the design alone and takes no intermediate: shapes; remove them or use "
                        "blend: linear or intrinsic")
    return problems
