"""The case's ``links`` block: how the body is split into links (sections)."""

from __future__ import annotations

from pydantic import Field, model_validator

from softdesign.config.types import CaseBlock, FiniteFloat, Integer
from softdesign.limits import MAX_LINKS


class Links(CaseBlock):
    """How the actuator is split into links: exactly one of the three keys."""

    count: Integer | None = Field(None, ge=1, le=MAX_LINKS)
    """The number of links of equal length."""
    breaks: list[FiniteFloat] | None = Field(None, max_length=MAX_LINKS + 1)
    """Link breaks in normalized l, from 0 to 1, strictly increasing."""
    length_mm: FiniteFloat | None = Field(None, gt=0.0)
    """Links of about this length, mm."""

    @model_validator(mode="after")
    def _one_rule(self) -> Links:
        given = [k for k in ("count", "breaks", "length_mm") if getattr(self, k) is not None]
        if len(given) > 1:
            raise ValueError(f"give one of count, breaks, length_mm; got {', '.join(given)}")
        if not given:
            raise ValueError("give one of count, breaks (normalized l), length_mm")
        if self.breaks is not None:
            _check_breaks(self.breaks)
        return self


def _check_breaks(breaks: list[float]) -> None:
    if len(breaks) < 2 or breaks[0] != 0.0 or breaks[-1] != 1.0:
        raise ValueError(f"breaks must start at 0 and end at 1 (normalized l), got {breaks}")
    if any(nxt <= prev for prev, nxt in zip(breaks[:-1], breaks[1:], strict=True)):
        raise ValueError(f"breaks must be strictly increasing, got {breaks}")
