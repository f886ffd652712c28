"""Reinforcement threads as data (``softdesign/data/threads.yaml``): breaking load, diameter, modulus, sources.

The YAML file holds every number and where it was read (or says "unverified");
this module reads it once, checks every entry and converts the breaking load to
newtons.  No numpy: ``softdesign validate`` checks thread names with it.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from importlib import resources
from typing import Any

#: Newtons per unit of a breaking load in the data file.
NEWTON_PER_UNIT = {"N": 1.0, "lbf": 4.4482216152605, "kgf": 9.80665}


@dataclass(frozen=True)
class Thread:
    """One thread: ``breaking_load_n`` (straight pull), ``diameter_mm``, ``modulus_gpa``, and their sources."""

    name: str
    material: str
    breaking_load_n: float
    diameter_mm: float
    modulus_gpa: float
    source: str

    def as_dict(self) -> dict[str, Any]:
        """The summary's ``thread`` entry."""
        return {"name": self.name, "diameter_mm": self.diameter_mm, "breaking_load_n": self.breaking_load_n,
                "source": self.source}


def _thread(name: str, raw: dict[str, Any]) -> Thread:
    load = raw["breaking_load"]
    unit = load["unit"]
    if unit not in NEWTON_PER_UNIT:
        raise ValueError(f"threads.yaml: {name}.breaking_load.unit {unit!r} is not one of {sorted(NEWTON_PER_UNIT)}")
    newtons = float(load["value"]) * NEWTON_PER_UNIT[unit]
    diameter, modulus = float(raw["diameter_mm"]), float(raw["modulus_gpa"])
    if not (newtons > 0 and diameter > 0 and modulus > 0):
        raise ValueError(f"threads.yaml: {name}: breaking load, diameter and modulus must be > 0")
    source = (f"breaking load: {raw['breaking_load_source']}; diameter: {raw['diameter_source']}; modulus: "
              f"{raw['modulus_source']}")
    return Thread(name, str(raw["material"]), newtons, diameter, modulus, source)


@cache
def thread_presets() -> dict[str, Thread]:
    """Every thread of the data file, by name (read once)."""
    import yaml

    text = resources.files("softdesign").joinpath("data/threads.yaml").read_text(encoding="utf-8")
    data = yaml.load(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))  # libyaml's parser, as materials'
    return {name: _thread(name, raw) for name, raw in data["threads"].items()}
