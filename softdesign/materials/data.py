"""The material presets as data (``softdesign/data/materials.yaml``): datasheet values, sources, laws, limits.

The YAML file holds every number and its source (document and table); this
module reads it once, checks every entry, converts units (psi and MPa to
kPa) and derives what the file states as rules: the stretch limit from the
elongation at break, and a neo-Hookean law through the 100 % modulus where
no published fit is given (both rules are written at the top of the file).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from importlib import resources
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from softdesign.continuum.laws import HyperelasticLaw

#: kPa per unit of a datasheet's stress.
KPA_PER_UNIT = {"psi": 6.894757293168361, "MPa": 1000.0, "kPa": 1.0}
#: Nominal stress of an incompressible neo-Hookean bar at stretch 2 over its shear modulus: 2 - 2^-2.
NEO_HOOKEAN_NOMINAL_AT_100_PCT = 1.75
#: Bulk over shear modulus of the laws (near-incompressible; the morph's stress takes them incompressible).
BULK_RATIO = 1000.0


@dataclass(frozen=True)
class MaterialPreset:
    """One preset with every figure in kPa and %, and where each comes from.

    Attributes
    ----------
    name : the case file's ``material.name``
    shore : hardness as the datasheet gives it (``00-30``, ``10A``)
    tensile_strength_kpa, modulus_100_kpa : the datasheet's, or None when it gives none
    elongation_at_break_pct : the datasheet's
    max_stretch, min_stretch, min_wall_mm : the limits (max_stretch by the file's rule)
    law_params : (kind, C1, C2, C3) kPa of the hyperelastic law, or None (:meth:`law` builds it)
    source, law_source, rule : the document and table of the values, of the law, and the stretch rule applied
    checked : whether the values were read in the manufacturer's document itself
    mixing : the ratio of the parts and how they are measured, with its document (the fabrication sheet's)
    """

    name: str
    shore: str
    tensile_strength_kpa: float | None
    modulus_100_kpa: float | None
    elongation_at_break_pct: float
    max_stretch: float
    min_stretch: float
    min_wall_mm: float
    law_params: tuple[str, float, float, float] | None
    source: str
    law_source: str
    rule: str
    checked: bool
    mixing: str = ""

    def law(self) -> HyperelasticLaw | None:
        """The law (numpy is imported here, not when the presets are read), or None."""
        return None if self.law_params is None else law_from(*self.law_params, self.law_source)

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready (the law as its kind and coefficients)."""
        law = None if self.law_params is None else {
            "kind": self.law_params[0], **{f"c{k}_kpa": round(v, 4) for k, v in enumerate(self.law_params[1:], 1)},
            "source": self.law_source}
        return {"name": self.name, "shore": self.shore, "tensile_strength_kpa": _round(self.tensile_strength_kpa),
                "modulus_100_kpa": _round(self.modulus_100_kpa),
                "elongation_at_break_pct": self.elongation_at_break_pct,
                "max_stretch": self.max_stretch, "min_stretch": self.min_stretch, "min_wall_mm": self.min_wall_mm,
                "law": law, "rule": self.rule, "source": self.source, "checked": self.checked}


def _round(value: float | None) -> float | None:
    return None if value is None else round(value, 3)


def _stress_kpa(entry: dict[str, Any] | None, name: str, key: str) -> float | None:
    if entry is None:
        return None
    unit = entry.get("unit")
    if unit not in KPA_PER_UNIT or not float(entry["value"]) > 0:
        raise RuntimeError(f"softdesign/data/materials.yaml: {name}.{key} needs a value > 0 and a unit of "
                           f"{', '.join(KPA_PER_UNIT)}, got {entry}")
    return float(entry["value"]) * KPA_PER_UNIT[unit]


def law_from(kind: str, c1: float, c2: float, c3: float, source: str) -> HyperelasticLaw:
    """A law with the module's bulk modulus (``BULK_RATIO`` x mu)."""
    from softdesign.continuum.laws import HyperelasticLaw

    return HyperelasticLaw(kind, c1, c2, c3, BULK_RATIO * 2.0 * c1, source)


LawParams = tuple[str, float, float, float]


def _law(raw: Any, modulus_kpa: float | None, name: str) -> tuple[LawParams | None, str]:
    if raw is None:
        return None, "none: no fit given and no 100 % modulus to fit through"
    if raw == "from_modulus_100":
        if modulus_kpa is None:
            raise RuntimeError(f"softdesign/data/materials.yaml: {name}: law from_modulus_100 needs a modulus_100")
        c1 = modulus_kpa / NEO_HOOKEAN_NOMINAL_AT_100_PCT / 2.0
        source = (f"neo-Hookean through the datasheet's 100 % modulus {modulus_kpa:.1f} kPa: mu = M100 / 1.75 = "
                  f"{2 * c1:.2f} kPa")
        return ("neo-hookean", c1, 0.0, 0.0), source
    if raw.get("kind") not in ("neo-hookean", "yeoh") or not float(raw["c1_kpa"]) > 0:
        raise RuntimeError(f"softdesign/data/materials.yaml: {name}.law needs kind neo-hookean or yeoh and c1_kpa > 0")
    return (raw["kind"], float(raw["c1_kpa"]), float(raw["c2_kpa"]), float(raw["c3_kpa"])), str(raw["source"])


def _preset(name: str, raw: dict[str, Any], fraction: float, min_stretch: float) -> MaterialPreset:
    elongation = float(raw["elongation_at_break_pct"])
    if raw.get("rule") == "yield":
        yield_pct = float(raw["elongation_at_yield_pct"])
        max_stretch = 1.0 + yield_pct / 100.0
        rule = f"max_stretch = 1 + elongation at yield {yield_pct:g} % (beyond yield the part sets)"
    else:
        max_stretch = 1.0 + fraction * elongation / 100.0
        rule = f"max_stretch = 1 + {fraction:g} x elongation at break {elongation:g} % (materials.yaml)"
    modulus = _stress_kpa(raw.get("modulus_100"), name, "modulus_100")
    law, law_source = _law(raw.get("law"), modulus, name)
    return MaterialPreset(name, str(raw["shore"]), _stress_kpa(raw.get("tensile_strength"), name, "tensile_strength"),
                          modulus, elongation, max_stretch, min_stretch, float(raw["min_wall_mm"]), law,
                          str(raw["source"]), law_source, rule, bool(raw["checked"]), str(raw.get("mixing", "")))


@cache
def material_presets() -> dict[str, MaterialPreset]:
    """Every preset of the data file, by name (read once)."""
    import yaml

    text = resources.files("softdesign").joinpath("data/materials.yaml").read_text(encoding="utf-8")
    # libyaml's parser where PyYAML has it: the same data, in 7 ms instead of 45 (every command that loads a case
    # reads this file at import, ``softdesign validate`` among them)
    data = yaml.load(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    fraction, min_stretch = float(data["design_fraction"]), float(data["min_stretch"])
    return {name: _preset(name, raw, fraction, min_stretch) for name, raw in data["presets"].items()}
