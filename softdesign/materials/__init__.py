"""Material limits a design is judged against: presets for the elastomers soft actuators are made of.

The presets are data, ``softdesign/data/materials.yaml`` (read by
:mod:`softdesign.materials.data`): each datasheet value with its document and
table, a hyperelastic law with its source, and the rules stated there: a
silicone's ``max_stretch`` is ``1 + design_fraction x elongation at break``
(half: the datasheet's elongation is one pull of a dumbbell to failure, an
actuator's skin is cycled and carries casting flaws); the TPU preset uses
the elongation at *yield* at full value (beyond yield a printed part sets).
No datasheet gives a compressive limit for a skin: ``min_stretch`` (where a
thin skin in axial compression wrinkles) is a rule of thumb, as is
``min_wall_mm`` (what a cast or printed wall fills without holes).

Explicit numbers in the case file override a preset's (see
:func:`resolve_material`); these figures describe stock material at room
temperature and are no substitute for a test of the cured part.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any, Literal, get_args

from softdesign.materials.data import MaterialPreset, material_presets

#: The preset names the case file accepts (``material.name``); :data:`PRESETS` has one entry for each.
PresetName = Literal[
    "ecoflex-00-10", "ecoflex-00-20", "ecoflex-00-30", "ecoflex-00-50", "dragon-skin-10", "dragon-skin-20",
    "dragon-skin-30", "elastosil-m4601", "smooth-sil-950", "sylgard-184", "tpu-85a",
]

#: Fraction of the datasheet's elongation at break a cyclically stretched skin may use (materials.yaml's rule).
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


def _limits(preset: MaterialPreset) -> MaterialLimits:
    source = (f"{preset.source}: elongation at break {preset.elongation_at_break_pct:g} %; {preset.rule}; "
              f"min_stretch {preset.min_stretch:g} and min_wall_mm {preset.min_wall_mm:g} are rules of thumb")
    return MaterialLimits(preset.name, preset.max_stretch, preset.min_stretch, preset.min_wall_mm, source)


#: The presets' limits, by the name the case file uses (the data file's every entry).
PRESETS: dict[str, MaterialLimits] = {name: _limits(p) for name, p in material_presets().items()}


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
    raise RuntimeError("softdesign.materials: PresetName and softdesign/data/materials.yaml name different materials")
if DESIGN_FRACTION != 0.5 or any(p.min_stretch != DEFAULT_MIN_STRETCH for p in material_presets().values()):
    raise RuntimeError("softdesign.materials: DESIGN_FRACTION or DEFAULT_MIN_STRETCH differ from materials.yaml")
