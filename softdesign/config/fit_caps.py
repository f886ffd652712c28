"""The case file's ``fit.local_max_radius``: the body held thinner over stretches of the path only (issue 43).

A fold's refusal offers one entry per folding stretch
(:mod:`softdesign.fitting.local_cap` gives the meaning of each number); the
whole-path ``fit.max_radius_mm`` stays beside it.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field, model_validator

from softdesign.config.types import FiniteFloat
from softdesign.limits.shape import MAX_INITIAL_LENGTH_MM, MAX_INITIAL_RADIUS_MM, MIN_INITIAL_RADIUS_MM

#: The most stretches one case caps (a path has a few take-offs, not dozens).
MAX_LOCAL_CAPS = 16
#: The longest taper, mm (the widest aorta's diameter twice over).
MAX_TAPER_MM = 100.0


class LocalMaxRadius(BaseModel):
    """The body held at most ``radius_mm`` from ``from_mm`` to ``to_mm`` along the path, tapering over ``taper_mm``."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    from_mm: FiniteFloat = Field(ge=0.0, le=MAX_INITIAL_LENGTH_MM)
    """Start of the stretch, mm of the q = 1 centerline from the inlet."""
    to_mm: FiniteFloat = Field(gt=0.0, le=MAX_INITIAL_LENGTH_MM)
    """End of the stretch, mm from the inlet (more than from_mm)."""
    radius_mm: FiniteFloat = Field(ge=MIN_INITIAL_RADIUS_MM, le=MAX_INITIAL_RADIUS_MM)
    """The body's largest radius over the stretch, mm."""
    taper_mm: FiniteFloat = Field(2.0, ge=0.0, le=MAX_TAPER_MM)
    """Length over which the cap rises back to the fitted body on each side of the stretch, mm."""

    @model_validator(mode="after")
    def _ordered(self) -> LocalMaxRadius:
        if self.to_mm <= self.from_mm:
            raise ValueError(f"to_mm must be more than from_mm, got from_mm {self.from_mm:g}, to_mm {self.to_mm:g}; "
                             "give the stretch from the inlet's side first")
        return self
