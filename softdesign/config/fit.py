"""The case's ``fit`` block: the least-squares spline surface rho(l, a) fitted to the wall, per link."""

from __future__ import annotations

import math
from typing import Any, Literal

from pydantic import Field, field_validator

from softdesign.config.fit_caps import MAX_LOCAL_CAPS, LocalMaxRadius
from softdesign.config.types import CaseBlock, FiniteFloat, Integer
from softdesign.limits import MAX_ANGULAR_INTERVALS, MAX_HOLDOUT_FOLDS

#: The largest fit.end_margin_mm (a path's end cap region is a few millimetres; ingest also keeps it within a
#: quarter of the path's length, pipeline/bounds.py).
MAX_END_MARGIN_MM = 20.0


class Fit(CaseBlock):
    """Least-squares spline surface rho(l, a) per link."""

    # defaults measured on the VMTK aorta (mean edge 0.97 mm): 1.5 mm x 24 keeps ~3 points per
    # coefficient; 1e-5 is the least penalty that bridges the other iliac's opening; the aorta's
    # elliptical inlet wall reaches 1.79x the inscribed radius, so outliers start at 2x
    knot_spacing_mm: float | Literal["auto"] = 1.5
    """Knot spacing of the spline along l, mm, or auto."""
    angular_intervals: Integer = Field(24, ge=4, le=MAX_ANGULAR_INTERVALS)
    """Knot intervals of the spline around the body."""
    smoothing: FiniteFloat = Field(1.0e-5, ge=0.0)
    """Weight of the smoothing penalty of the least-squares fit."""
    holdout_folds: Integer = Field(5, ge=2, le=MAX_HOLDOUT_FOLDS)
    """Folds of the k-fold hold-out error of the fit."""
    outlier_factor: FiniteFloat = Field(2.0, gt=1.0)
    """A wall point beyond this factor (or its inverse) of the reference radius is an outlier."""
    # wall points within this of either end are not fitted (a tilted cap's rim, one-sided ends); the end's
    # rings are then held at the inscribed radius by the end prior (fitting/end_prior.py)
    end_margin_mm: FiniteFloat = Field(0.0, ge=0.0, le=MAX_END_MARGIN_MM)
    """Wall points within this of either end are not fitted; the end's rings are held at the inscribed radius, mm."""
    # where the body ends: at each end's detected cap plane or boundary loop (auto, cap_plane) or square to the
    # end tangent (normal); see geometry/end_cut.py
    end_cut: Literal["auto", "cap_plane", "normal"] = "auto"
    """Where the body ends: auto (at a detected cap plane or open loop, else square), cap_plane, or normal (square to
    the end tangent).
    """
    # the body's radius is held at most this along the whole path (a thinner body makes a turn the vessel's
    # width cannot: a branch's take-off); a fold's message offers the value (fitting/radius_field.py)
    max_radius_mm: FiniteFloat | None = Field(None, gt=0.0)
    """A cap on the fitted body's radius, mm: a thinner body that can make a turn tighter than the vessel is wide (the
    fix a fold's message names).
    """
    # the same cap over stretches of the path only, tapering back to the fit (config/fit_caps.py)
    local_max_radius: list[LocalMaxRadius] = Field(default_factory=list, max_length=MAX_LOCAL_CAPS)
    """Caps on the body's radius over stretches of the path only, each {from_mm, to_mm, radius_mm, taper_mm} (the fix
    a fold at a take-off offers first).
    """

    @field_validator("knot_spacing_mm", mode="before")
    @classmethod
    def _spacing(cls, value: Any) -> Any:
        if value == "auto":
            return value
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueError(f"must be a number of mm or 'auto', got {value!r}")
        if not math.isfinite(value):
            raise ValueError(f"must be a finite number of mm or 'auto', got {value}")
        if value <= 0:
            raise ValueError(f"must be > 0 mm, got {value}")
        return float(value)
