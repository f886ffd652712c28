"""The case's ``resample`` block: arc-length resampling and smoothing of every centerline."""

from __future__ import annotations

from pydantic import Field, model_validator

from softdesign.config.types import CaseBlock, FiniteFloat, Integer
from softdesign.limits import MAX_CURVE_SAMPLES


class Resample(CaseBlock):
    """Arc-length resampling and smoothing of every centerline."""

    spacing_mm: FiniteFloat = Field(0.5, gt=0.0)
    """Arc length between resampled points, mm."""
    count: Integer | None = Field(None, ge=4, le=MAX_CURVE_SAMPLES)
    """A fixed number of resampled points instead of spacing_mm."""
    smoothing_mm: FiniteFloat = Field(0.1, ge=0.0)
    """Smoothing of the centerline (Gaussian width along arc length), mm; 0 keeps it as it is."""
    end_straight_mm: FiniteFloat = Field(2.0, ge=0.0)
    """Straighten this much of each end, mm (a centerline's last points bend towards the cap)."""

    @model_validator(mode="after")
    def _one_rule(self) -> Resample:
        if self.count is not None and "spacing_mm" in self.model_fields_set:  # count would win silently
            raise ValueError("give one of count, spacing_mm; got both")
        return self
