"""The case file's ``simulate:`` block: estimate each section's chamber pressures in ``build`` (off by default).

With ``simulate: {enabled: true}`` the build's **simulate** stage solves, for
every requested q and section, the three chamber pressures whose deformed
section (hyperelastic finite elements, :mod:`softdesign.mechanics`) best
matches the section's designed arc at that q, and the actuation stage adds
them to ``actuation.csv`` as model estimates.  Each inverse takes many forward
solves (minutes per section on 2 cores), so it never runs unless asked for;
``softdesign simulate CASE --target q --write`` does the same for one section
and one q.  Every size is bounded here, before any work
(:mod:`softdesign.limits.simulate`).
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field, field_validator

from softdesign.config.types import FiniteFloat, Flag, Integer, q_in_range
from softdesign.limits import MAX_LINKS
from softdesign.limits.simulate import (
    MAX_ANGULAR_COUNT,
    MAX_INVERSE_SOLVES,
    MAX_PRESSURE_KPA,
    MAX_SIMULATE_Q,
    MAX_SIMULATE_SECONDS,
    MIN_ANGULAR_COUNT,
    MIN_SIZE_MM,
)

#: The coarsest element or layer size a section's mesh may ask for, mm (a section is a few to tens of mm long).
MAX_SIMULATE_SIZE_MM = 100.0
#: Two q values closer than this are one (actuation.csv names its rows by q with three decimals).
Q_RESOLUTION = 1e-3


class Simulate(BaseModel):
    """Chamber pressures per section and q from a finite-element inverse (the simulate stage): off unless enabled."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    enabled: Flag = False
    """Run the finite elements in `build`: each section's pressures per q (supply: per_chamber, minutes per
    section), or the whole device at every exported q (supply: single, minutes): false by default."""
    q: list[FiniteFloat] = Field([1.0], min_length=1, max_length=MAX_SIMULATE_Q)
    """The q values whose pressures are estimated, each in [0, 1], at least 0.001 apart (default [1])."""
    sections: list[Integer] | None = Field(None, min_length=1, max_length=MAX_LINKS)
    """The sections to solve, numbered from 1 at the base as in actuation.csv (default: every section)."""
    size_mm: FiniteFloat = Field(3.0, ge=MIN_SIZE_MM, le=MAX_SIMULATE_SIZE_MM)
    """Element size in a section's cross-section, mm."""
    layer_mm: FiniteFloat = Field(8.0, ge=MIN_SIZE_MM, le=MAX_SIMULATE_SIZE_MM)
    """Spacing of a section mesh's layers along the centerline, mm."""
    angular_count: Integer = Field(12, ge=MIN_ANGULAR_COUNT, le=MAX_ANGULAR_COUNT)
    """Nodes on a section mesh's outer circle."""
    max_pressure_kpa: FiniteFloat = Field(100.0, ge=1.0, le=MAX_PRESSURE_KPA)
    """Upper bound of the pressure search, kPa."""
    max_solves: Integer = Field(16, ge=1, le=MAX_INVERSE_SOLVES)
    """Forward solves one inverse (one section, one q) may take."""
    timeout_s: FiniteFloat = Field(600.0, gt=0.0, le=MAX_SIMULATE_SECONDS)
    """Longest time the solves of one section (every q) may take, s; the build then fails and says so."""
    shape_tolerance_mm: FiniteFloat = Field(2.0, gt=0.0, le=MAX_SIMULATE_SIZE_MM)
    """supply: single: the whole device's deformed centerline may lie this far from the designed chain at each
    exported q, mm (the design's 1 mm and as much again for the models' difference); further, pressure does not
    reach the shape and the verdict says NOT feasible."""

    @field_validator("q")
    @classmethod
    def _q_in_range(cls, values: list[float]) -> list[float]:
        q_in_range(values)
        ordered = sorted(values)
        if any(b - a < Q_RESOLUTION for a, b in zip(ordered, ordered[1:], strict=False)):
            raise ValueError(f"give each q once, at least 0.001 apart (actuation.csv's rows), got {values}")
        return ordered

    @field_validator("sections")
    @classmethod
    def _sections_counted_from_one(cls, values: list[int] | None) -> list[int] | None:
        if values is None:
            return None
        if min(values) < 1 or len(set(values)) != len(values):
            raise ValueError(f"sections are numbered from 1 at the base, each once, got {values}")
        return sorted(values)
