"""A user's own material in the case file (``material.custom``): every figure the presets carry, all required.

A preset's numbers come from softdesign/data/materials.yaml with their
sources; a custom material must give the same figures and say where they
come from, or the case file is refused (pydantic names each missing key):
``material: {custom: {name, shore, tensile_strength_mpa,
elongation_at_break_pct, law: {kind, c1_kpa, c2_kpa, c3_kpa}, source}}``.
Its ``max_stretch`` follows the presets' rule (1 + design fraction x
elongation at break) unless ``material.max_stretch`` says otherwise.
"""

from __future__ import annotations

import unicodedata
from dataclasses import replace
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from softdesign.config.types import CaseBlock
from softdesign.materials import DESIGN_FRACTION, MaterialLimits, PresetName, resolve_material

#: The smallest C1 a law may have, kPa: a tenth of the softest silicone gels' (C1 about 1 kPa). Below it the finite
#: elements' shear stiffness vanishes beside their bulk term and the factorization is singular (c1_kpa: 1e-300
#: ended the solve in "Factor is exactly singular").
MIN_C1_KPA = 0.1


def _printable(value: str) -> str:
    """``value`` when it holds no control character (a name reaches the terminal, the report and the manifest)."""
    bad = [c for c in value if unicodedata.category(c) in ("Cc", "Cf", "Zl", "Zp")]
    if bad:
        raise ValueError(f"holds the control character {bad[0]!r}; write it on one line with printable characters")
    return value


class CustomLaw(BaseModel):
    """A hyperelastic law: Yeoh coefficients in kPa (neo-Hookean: c2 = c3 = 0, mu = 2 c1)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    kind: Literal["neo-hookean", "yeoh"]
    """neo-hookean or yeoh."""
    c1_kpa: float = Field(ge=MIN_C1_KPA, le=1.0e6)
    """C1 (mu / 2 for neo-Hookean), kPa; at least 0.1 (the softest silicone gels have about 1)."""
    c2_kpa: float = Field(ge=-1.0e6, le=1.0e6)
    """Yeoh's C2, kPa."""
    c3_kpa: float = Field(ge=-1.0e6, le=1.0e6)
    """Yeoh's C3, kPa."""

    @model_validator(mode="after")
    def _neo_hookean_has_one_term(self) -> CustomLaw:
        if self.kind == "neo-hookean" and (self.c2_kpa != 0 or self.c3_kpa != 0):
            raise ValueError("a neo-hookean law has c2_kpa = c3_kpa = 0 (use kind: yeoh for more terms)")
        return self


class CustomMaterial(BaseModel):
    """A material given in full in the case file, with its source."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    name: str = Field(min_length=1, max_length=80)
    """Your material's name, as the report names it."""
    shore: str = Field(min_length=1, max_length=20)
    """Its Shore hardness, as the datasheet gives it (e.g. 00-30, 10A)."""
    tensile_strength_mpa: float = Field(gt=0.0, le=1000.0)
    """Its tensile strength, MPa."""
    elongation_at_break_pct: float = Field(gt=0.0, le=10000.0)
    """Its elongation at break, percent."""
    law: CustomLaw
    """Its hyperelastic law and parameters."""
    #: the document and table the numbers come from (a test report, a datasheet)
    source: str = Field(min_length=3, max_length=500)
    """Where the numbers come from (document and table)."""

    @field_validator("name", "shore", "source")
    @classmethod
    def _no_control_characters(cls, value: str) -> str:
        return _printable(value)

    def limits(self) -> MaterialLimits:
        """The presets' rule applied to this material's elongation at break."""
        rule = (f"{self.source}: elongation at break {self.elongation_at_break_pct:g} %; max_stretch = 1 + "
                f"{DESIGN_FRACTION:g} x elongation at break (the presets' rule)")
        return MaterialLimits(self.name, 1.0 + DESIGN_FRACTION * self.elongation_at_break_pct / 100.0, None, None,
                              rule)


class Material(CaseBlock):
    """Limits the design is judged against: a preset (``name``) and/or explicit numbers, which win."""

    name: PresetName | None = None
    """A preset (softdesign materials lists them with their sources)."""
    #: a material of the user's own, every figure given (CustomMaterial above); not with ``name``
    custom: CustomMaterial | None = None
    """Your own material: every key required."""
    max_stretch: float | None = Field(None, gt=1.0, le=100.0)
    """The largest principal stretch allowed (overrides the preset's)."""
    min_stretch: float | None = Field(None, gt=0.0, lt=1.0)
    """The smallest principal stretch allowed before a thin skin wrinkles (overrides the preset's)."""
    min_wall_mm: float | None = Field(None, gt=0.0, le=100.0)
    """The thinnest wall allowed, mm (overrides the preset's)."""

    @model_validator(mode="after")
    def _one_source(self) -> Material:
        if self.name is not None and self.custom is not None:
            raise ValueError("give name (a preset) or custom (your own material), not both")
        return self

    def limits(self) -> MaterialLimits:
        """The preset's (or the custom material's) numbers with the explicit ones put over them."""
        explicit = (self.max_stretch, self.min_stretch, self.min_wall_mm)
        if self.custom is None:
            return resolve_material(self.name, *explicit)
        base = self.custom.limits()
        return replace(base, max_stretch=self.max_stretch or base.max_stretch, min_stretch=self.min_stretch,
                       min_wall_mm=self.min_wall_mm)
