"""The case file's ``actuation:`` block: Zou et al.'s three chambers per section, with their feed lines.

Sizes are absolute millimetres, not fractions of the local radius: Zou et al.'s
inverse (three lengths -> kappa, phi, L) takes one chamber distance ``d`` per
section, and the relation ``l_j = L - kappa L d cos(beta_j - phi)`` holds only
when the chamber runs at a constant distance from the backbone.  A fraction of
a radius that changes along the vessel (2.9 to 3.7 mm on the demo) would bend
each chamber away from that offset curve, make the mould's straight pins
impossible, and break the round trip through ``pcc reconstruct``.  The vessel
enters through the layout check instead: the build refuses a layout whose walls
do not fit the thinnest section, with the largest diameter that would.

The defaults fit the demo (radius 2.9-3.7 mm, four sections, nine feeds through
the first): ring at 2.0 mm, chambers 0.8 mm, feeds 0.4 mm, leaving 0.5 mm of
skin over a chamber, 0.44 mm between a chamber and a feed and 0.64 mm between
two feeds (30 degrees apart on the ring).  ``first_angle_deg`` 90 puts section 1's
chamber 1 where Zou et al.'s encoder 1 sits (90 degrees from N).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from pydantic import BaseModel, ConfigDict, Field, model_validator

from softdesign.config.types import FiniteFloat, Integer

if TYPE_CHECKING:  # numpy stays out of `softdesign validate`
    from softdesign.meshing.chamber_layout import ActuationSpec

#: The largest size any actuation key takes, mm (a vessel is at most 20 mm in median radius, limits at ingest).
MAX_ACTUATION_MM = 50.0


class Actuation(BaseModel):
    """Three chambers per section (link) at ``distance_mm`` from the backbone, one feed line each."""

    model_config = ConfigDict(extra="forbid", frozen=True, use_attribute_docstrings=True)

    chambers_per_section: Integer = Field(3, ge=3, le=3)
    """Chambers in each section (Zou et al.'s three)."""
    distance_mm: FiniteFloat = Field(2.0, gt=0.0, le=MAX_ACTUATION_MM)
    """Distance of the chambers' axes from the backbone, mm (absolute: Zou et al.'s d is one number per section)."""
    diameter_mm: FiniteFloat = Field(0.8, gt=0.0, le=MAX_ACTUATION_MM)
    """Diameter of each chamber, mm."""
    feed_diameter_mm: FiniteFloat = Field(0.4, gt=0.0, le=MAX_ACTUATION_MM)
    """Diameter of each chamber's feed line, mm."""
    end_wall_mm: FiniteFloat = Field(1.0, gt=0.0, le=MAX_ACTUATION_MM)
    """Wall at each end of a chamber, mm."""
    first_angle_deg: FiniteFloat = Field(90.0, ge=-360.0, le=360.0)
    """Angle of the first chamber from the section's base N, degrees (Zou et al.'s first encoder is at 90)."""

    @model_validator(mode="after")
    def _chambers_fit_their_ring(self) -> Actuation:
        d, big = self.distance_mm, self.diameter_mm
        if self.feed_diameter_mm > big:
            raise ValueError(
                f"feed_diameter_mm {self.feed_diameter_mm:g} is wider than diameter_mm {big:g}: a feed enters its "
                f"chamber along its axis and must be no wider; use feed_diameter_mm <= {big:g}"
            )
        if big >= 2.0 * d:
            raise ValueError(
                f"diameter_mm {big:g} reaches across the backbone from distance_mm {d:g} (needs diameter < 2 x "
                f"distance = {2 * d:g}); use a smaller diameter or a larger distance"
            )
        between = 2.0 * d * math.sin(math.pi / 3.0)
        if big >= between:
            raise ValueError(
                f"three chambers of diameter_mm {big:g} at distance_mm {d:g} overlap (centres {between:.3f} mm "
                f"apart, 2 d sin 60 deg); use diameter_mm < {between:.3f} or a larger distance"
            )
        return self

    def spec(self) -> ActuationSpec:
        """The layout's numbers."""
        from softdesign.meshing.chamber_layout import ActuationSpec

        return ActuationSpec(self.distance_mm, self.diameter_mm, self.feed_diameter_mm, self.end_wall_mm,
                             self.first_angle_deg, self.chambers_per_section)
