"""Material limits a design is judged against: presets for the elastomers soft actuators are made of.

A preset's ``max_stretch`` is ``1 + DESIGN_FRACTION * elongation at break``
(the manufacturer's datasheet figure, as a fraction: 900 % -> 9.0).  The
design fraction is a rule of thumb, not a sourced number: a skin cycled many
times should stay well short of the strain at which a tensile bar breaks
once, and half of it is the margin used here.  The TPU preset uses the
datasheet's elongation at *yield* instead, at full value: beyond yield a TPU
part sets permanently, so break is the wrong reference.  No datasheet gives a
compressive limit for a skin: ``min_stretch`` (where a thin skin in axial
compression wrinkles or buckles) is a rule of thumb, as is ``min_wall_mm``
(what a cast or printed wall of that material reliably fills without holes).

Explicit numbers in the case file override a preset's (see
:func:`resolve_material`); these figures describe stock material at room
temperature and are no substitute for a test of the cured part.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any, Literal, get_args

#: The preset names the case file accepts (``material.name``); :data:`PRESETS` has one entry for each.
PresetName = Literal[
    "ecoflex-00-30", "ecoflex-00-50", "dragon-skin-10", "dragon-skin-30", "smooth-sil-950", "sylgard-184", "tpu-85a"
]

#: Fraction of the datasheet's elongation at break a cyclically stretched skin may use (rule of thumb).
DESIGN_FRACTION = 0.5
#: Smallest stretch (axial compression) before a thin elastomer skin wrinkles (rule of thumb, no source).
DEFAULT_MIN_STRETCH = 0.7


@dataclass(frozen=True)
class MaterialLimits:
    """What a material allows, and where the numbers come from.

    Attributes
    ----------
    name : preset name, or ``custom``
    max_stretch : largest principal stretch allowed (> 1)
    min_stretch : smallest principal stretch allowed (< 1), or None (not judged)
    min_wall_mm : thinnest wall allowed, mm, or None (not judged)
    source : the datasheet figure and the rule applied to it
    """

    name: str
    max_stretch: float | None
    min_stretch: float | None
    min_wall_mm: float | None
    source: str

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return asdict(self)


def _silicone(name: str, elongation_pct: float, datasheet: str, min_wall_mm: float) -> MaterialLimits:
    source = (f"{datasheet}: elongation at break {elongation_pct:g} %; max_stretch = 1 + {DESIGN_FRACTION:g} x "
              f"{elongation_pct / 100:g} (design fraction, rule of thumb); min_stretch {DEFAULT_MIN_STRETCH:g} and "
              f"min_wall_mm {min_wall_mm:g} are rules of thumb")
    return MaterialLimits(name, 1.0 + DESIGN_FRACTION * elongation_pct / 100.0, DEFAULT_MIN_STRETCH, min_wall_mm,
                          source)


#: The presets, by the name the case file uses.
PRESETS: dict[str, MaterialLimits] = {
    "ecoflex-00-30": _silicone("ecoflex-00-30", 900, "Smooth-On Ecoflex Series technical bulletin (00-30)", 1.0),
    "ecoflex-00-50": _silicone("ecoflex-00-50", 980, "Smooth-On Ecoflex Series technical bulletin (00-50)", 1.0),
    "dragon-skin-10": _silicone("dragon-skin-10", 1000, "Smooth-On Dragon Skin Series technical bulletin (10)", 0.8),
    "dragon-skin-30": _silicone("dragon-skin-30", 364, "Smooth-On Dragon Skin Series technical bulletin (30)", 0.8),
    "smooth-sil-950": _silicone("smooth-sil-950", 250, "Smooth-On Smooth-Sil 950 technical bulletin", 0.8),
    "sylgard-184": _silicone("sylgard-184", 140, "Dow SYLGARD 184 Silicone Elastomer technical data sheet", 0.5),
    "tpu-85a": MaterialLimits(
        "tpu-85a", 1.65, DEFAULT_MIN_STRETCH, 0.8,
        "NinjaTek NinjaFlex (TPU, Shore 85A) technical data sheet: elongation at yield 65 %, at break 660 %; "
        "max_stretch = 1 + 0.65 (yield, not break: beyond it the print sets); min_stretch "
        f"{DEFAULT_MIN_STRETCH:g} and min_wall_mm 0.8 (two 0.4 mm perimeters) are rules of thumb",
    ),
}


def resolve_material(name: str | None, max_stretch: float | None, min_stretch: float | None,
                     min_wall_mm: float | None) -> MaterialLimits:
    """The preset ``name`` (or no limits), with every explicit number put over the preset's.

    Raises
    ------
    ValueError
        An unknown preset name (the case file's schema refuses it first).
    """
    if name is not None and name not in PRESETS:
        raise ValueError(f"material.name must be one of {', '.join(PRESETS)}, got {name!r}")
    base = PRESETS[name] if name is not None else MaterialLimits("custom", None, None, None, "the case file's numbers")
    explicit = {"max_stretch": max_stretch, "min_stretch": min_stretch, "min_wall_mm": min_wall_mm}
    given = {k: v for k, v in explicit.items() if v is not None}
    source = base.source + ("" if not given or name is None else
                            "; overridden by the case file: " + ", ".join(f"{k} {v:g}" for k, v in given.items()))
    merged = {**asdict(base), **given, "source": source}
    return MaterialLimits(**merged)


if set(PRESETS) != set(get_args(PresetName)):  # one list of names, checked at import
    raise RuntimeError("softdesign.materials: PresetName and PRESETS name different materials")
