"""Stage fabrication: ``fabrication.md``, how to make the body, from this build's own figures.

It gathers, from the stages before it, what a maker needs (the material and
its mixing note, the mould's parts, the cores with their sizes, the supply
ports, the thread winding when the actuation gives one, the casting
orientation, vent and pour, the demoulding order) into one JSON-ready dict
(the manifest's ``metrics.fabrication``, kept in ``fabrication/figures.json``),
and writes the sheet :mod:`softdesign.pipeline.fabrication_sheet` makes of it.
The report's "make it" section shows the same lines.

The actuation's ``reinforcement`` (kind, pitch_mm, thread {name, diameter_mm,
breaking_load_n, source}, safety_factor), its ``supply`` and
``design_pressure_kpa``, and each chamber's ``turns``, ``tension_per_turn_n``
and ``tension_limit_n`` (``sections[i].chambers[j]``) are read when the
actuation's summary has them; the winding is left out otherwise.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softdesign.pipeline import layout
from softdesign.pipeline.fabrication_sheet import core_make, sheet_lines
from softdesign.pipeline.stage import Results, Stage
from softdesign.pipeline.store import Staging

if TYPE_CHECKING:  # only annotations: the report loads stage results without the case file's models
    from softdesign.config import Case

VERSION = 2  # 2: the reinforcement's chamber ends (bare or patched)


@dataclass(frozen=True)
class FabricationResult:
    """The sheet's figures (JSON-ready)."""

    figures: dict[str, Any]


def fabrication_figures(case: Case, results: Results) -> dict[str, Any]:
    """Everything the sheet says, from the case and the blend's, actuation's and mould's results (mm, kPa, N)."""
    length = float(results["blend"].summary["initial_length_mm"])
    actuation = results.get("actuation")
    act = None if actuation is None else actuation.summary
    return {"name": case.name, "body_length_mm": length, "material": _material(case),
            "mould": _mould(results["mould"].summary), "cores": _cores(act, length),
            "supply": _supply(case, act),
            "reinforcement": _reinforcement(act, case.chamber_ends)}


def _material(case: Case) -> dict[str, Any] | None:
    """The material's name, source, mixing note and whether its figures were read at their source."""
    material = case.material
    if material is None:
        return None
    if material.custom is not None:
        return {"name": material.custom.name, "source": material.custom.source, "checked": True,
                "mixing": "as its maker's datasheet says (a material of the case file's own)"}
    if material.name is None:
        return {"name": "limits given in the case file", "source": "the case file", "checked": True, "mixing": ""}
    from softdesign.materials.data import material_presets

    preset = material_presets()[material.name]
    return {"name": preset.name, "source": preset.source, "checked": preset.checked, "mixing": preset.mixing}


def _mould(summary: dict[str, Any]) -> dict[str, Any] | None:
    """The mould's parts (one file each), its casting and core figures, each half's pull direction."""
    if not summary.get("requested"):
        return None
    files: dict[str, str] = {}
    for name, f in sorted(summary["files"].items(), key=lambda item: (not item[0].endswith(".stl"), item[0])):
        files.setdefault(f["part"], name)  # the STL where the build writes several formats
    spec, core = summary["spec"], summary.get("core") or {}
    return {"parts": [{"part": part, "file": files[part], "volume_mm3": summary["parts"][part]["volume_mm3"]}
                      for part in summary["parts"] if part in files],
            "up": spec["up"], "pour_mm": spec["pour_mm"], "vent_mm": spec["vent_mm"], "key_mm": spec["key_mm"],
            "clearance_mm": spec["clearance_mm"], "plate": "core_plate" in summary["parts"],
            "cores": core.get("cores", 0), "process": core.get("process", ""), "note": core.get("note", ""),
            "pull": {part: p["pull"] for part, p in summary["pull"].items()}}


def _cores(act: dict[str, Any] | None, length_mm: float) -> list[dict[str, Any]]:
    """Per chamber its core: the chamber's part and its feed's, each with its diameter, length and make."""
    if act is None:
        return []
    feeds = {(f["section"], f["chamber"]): f for f in act["layout"]["feeds"]}
    cores = []
    for c in act["layout"]["chambers"]:
        parts = [("chamber", c), *((("feed", feeds[key]),) if (key := (c["section"], c["chamber"])) in feeds else ())]
        segments = [{"what": what, "diameter_mm": p["diameter_mm"],
                     "length_mm": (p["l_end"] - p["l_start"]) * length_mm} for what, p in parts]
        for s in segments:
            s["make"] = core_make(s["diameter_mm"], s["length_mm"])
        cores.append({"name": f"core_{c['section']}_{c['chamber']}", "segments": segments})
    return cores


def _supply(case: Case, act: dict[str, Any] | None) -> dict[str, Any] | None:
    """The ports at the base face: one feed per chamber, or the hollow body's port; None for a solid body."""
    if act is not None:
        feeds = act["layout"]["feeds"]
        return {"count": len(feeds), "diameter_mm": min(f["diameter_mm"] for f in feeds),
                "what": "one feed per chamber", "mode": act.get("supply"),
                "design_pressure_kpa": act.get("design_pressure_kpa")}
    if case.export.port_mm is not None:
        return {"count": 1, "diameter_mm": case.export.port_mm, "what": "the port into the body's chamber",
                "mode": None, "design_pressure_kpa": None}
    return None


def _reinforcement(act: dict[str, Any] | None, ends: str) -> dict[str, Any] | None:
    """The actuation's thread winding and each chamber's turns and tensions, when it gives them, and its chambers'
    ends (``actuation.reinforcement.ends``: bare, or a woven patch on each)."""
    block = None if act is None else act.get("reinforcement")
    if not isinstance(block, dict) or block.get("kind") in (None, "none") or "thread" not in block:
        return None
    keys = ("turns", "tension_per_turn_n", "tension_limit_n")
    windings = [{"section": i + 1, "chamber": j + 1, **{k: chamber[k] for k in keys}}
                for i, section in enumerate(act.get("sections", []) if act else [])
                for j, chamber in enumerate(section.get("chambers", [])) if all(k in chamber for k in keys)]
    return {k: block[k] for k in ("kind", "pitch_mm", "thread", "safety_factor")} | {"windings": windings,
                                                                                    "ends": ends}


def sheet_text(figures: dict[str, Any]) -> str:
    """``fabrication.md``'s text."""
    return "\n".join(sheet_lines(figures)).rstrip("\n") + "\n"


def write_fabrication(result: FabricationResult, staging: Staging) -> None:
    """The sheet, and its figures for a later run that skips this stage."""
    staging.write_bytes(layout.FABRICATION, sheet_text(result.figures).encode("utf-8"))
    staging.write_json(layout.FABRICATION_FIGURES, result.figures)


def load_fabrication(build_dir: Path) -> FabricationResult:
    """The kept figures."""
    return FabricationResult(json.loads((Path(build_dir) / layout.FABRICATION_FIGURES).read_text(encoding="utf-8")))


def describe_fabrication(result: FabricationResult) -> list[str]:
    """One line: what the sheet covers."""
    f = result.figures
    wires = sum(s["make"] == "wire" for c in f["cores"] for s in c["segments"])
    mould = f["mould"]
    parts = "no mould" if mould is None else f"{len(mould['parts'])} mould part(s)"
    return [f"{layout.FABRICATION}: {parts}, {len(f['cores'])} core(s) ({wires} wire part(s)), "
            f"{'no supply port' if f['supply'] is None else str(f['supply']['count']) + ' supply port(s)'}"
            + ("" if f["reinforcement"] is None else ", thread winding")]


STAGE = Stage(
    name="fabrication",
    version=VERSION,
    reads=("name", "material", "export.mould", "export.port_mm", "export.wall_mm", "actuation"),
    upstream=("blend", "actuation", "mould"),
    compute=lambda case, results: FabricationResult(fabrication_figures(case, results)),
    write=write_fabrication,
    load=lambda build_dir, results: load_fabrication(build_dir),
    describe=describe_fabrication,
    metrics=lambda result: result.figures,
)
