"""The fabrication sheet's text (``fabrication.md``, the report's "make it" section) from the build's figures.

Pure: :func:`sheet_lines` turns the figures the fabrication stage gathered
(:func:`softdesign.pipeline.stages.fabrication.fabrication_figures`, all in
the manifest's ``metrics.fabrication``) into Markdown lines; every number in
the text is one of those figures.  Two rules of thumb, stated as such:

- a core longer than :data:`WIRE_ASPECT_LIMIT` times its diameter is a
  straight steel wire of that diameter, not a printed pin: a printed pin that
  slender bends under the silicone's weight or breaks when drawn out;
- a supply tube goes into a port as a press fit of :data:`PRESS_FIT_FRACTION`
  of the port's diameter and is sealed with a silicone adhesive.
"""

from __future__ import annotations

from typing import Any

#: Length over diameter above which a core is a wire (rule of thumb, not a measured limit).
WIRE_ASPECT_LIMIT = 20.0
#: A tube's outer diameter over the port's, less 1: the press fit of a tube into a silicone port (rule of thumb).
PRESS_FIT_FRACTION = 0.1


def core_make(diameter_mm: float, length_mm: float) -> str:
    """``wire`` when the core is longer than :data:`WIRE_ASPECT_LIMIT` diameters, else ``printed``."""
    return "wire" if length_mm > WIRE_ASPECT_LIMIT * diameter_mm else "printed"


def sheet_lines(figures: dict[str, Any]) -> list[str]:
    """The sheet as Markdown lines: material, mould and assembly, cores, supply, winding, casting, demoulding."""
    lines = [f"# How to make {figures['name']}", "",
             "Every figure below is this build's (manifest.json: metrics.fabrication); sizes in mm, the body at q = 0 "
             f"({figures['body_length_mm']:.1f} mm long).", ""]
    lines += _material(figures.get("material"))
    mould = figures.get("mould")
    lines += _mould(mould) if mould else ["## Mould", "", "No mould in the case (add `export.mould: {}`).", ""]
    lines += _cores(figures.get("cores", []), (figures.get("supply") or {}).get("mode") == "single")
    lines += _supply(figures.get("supply"))
    lines += _winding(figures.get("reinforcement"))
    if mould:
        lines += _casting(mould) + _demoulding(mould)
    return lines


def _material(material: dict[str, Any] | None) -> list[str]:
    if material is None:
        return ["## Material", "", "No material in the case: choose one (`softdesign materials`) and build again.", ""]
    check = "" if material["checked"] else "; check its figures against the current datasheet before relying on them"
    return ["## Material", "", f"- {material['name']}: {material['source']}{check}",
            f"- mixing: {material['mixing'] or 'not given in the presets'}",
            "- degas the mixed silicone (vacuum) before pouring: a bubble in a thin wall is where it tears", ""]


def _mould(mould: dict[str, Any]) -> list[str]:
    lines = ["## Mould parts", ""]
    lines += [f"- `{p['file']}`: {p['part'].replace('_', ' ')}, {p['volume_mm3']:.0f} mm3" for p in mould["parts"]]
    lines += ["", "## Assembly (in this order)", ""]
    steps = []
    if mould["plate"]:
        steps.append(f"Set the {mould['cores']} cores (below) in the core plate, each to the bottom of its hole.")
    steps.append(f"Close half a on half b on their keys ({mould['key_mm']:g} mm, clearance {mould['clearance_mm']:g} "
                 "mm) and clamp them.")
    if mould["plate"]:
        steps.append("Slide the core plate with its cores into the halves' base face until it seats.")
    elif mould["process"]:
        steps.append("Seat the core in its prints in the halves before closing them.")
    lines += [f"{k}. {step}" for k, step in enumerate(steps, 1)]
    return [*lines, ""]


def _cores(cores: list[dict[str, Any]], single: bool = False) -> list[str]:
    if not cores:
        return []
    if single:  # one lost core: the supply line, the chambers and the series channels joining them
        lines = ["## Core (one lost wax core)", "",
                 "The supply line, every chamber and the series channels between them are one core "
                 "(`meshes/mould/core.stl`), made in wax and melted out after curing (the demoulding steps below "
                 "say how, and why wax). Its parts:", "",
                 "| part | diameter mm | length mm | length / diameter |", "|---|---|---|---|"]
        lines += [f"| {core['name']} {s['what']} | {s['diameter_mm']:.2f} | {s['length_mm']:.1f} | "
                  f"{s['length_mm'] / s['diameter_mm']:.0f} |" for core in cores for s in core["segments"]]
        return [*lines, ""]
    lines = ["## Cores", "",
             f"A core longer than {WIRE_ASPECT_LIMIT:g} times its diameter is a straight steel wire of that diameter "
             "(a printed pin that slender bends or breaks); shorter ones are printed with the mould. Where the table "
             "says wire, use the wire in place of that part of the printed core file.", "",
             "| core | part | diameter mm | length mm | length / diameter | make |", "|---|---|---|---|---|---|"]
    for core in cores:
        lines += [f"| {core['name']} | {s['what']} | {s['diameter_mm']:.2f} | {s['length_mm']:.1f} | "
                  f"{s['length_mm'] / s['diameter_mm']:.0f} | {_make_text(s)} |" for s in core["segments"]]
    stepped = [c for c in cores if len(c["segments"]) == 2 and c["segments"][1]["make"] == "wire"]
    if stepped:
        chamber, feed = stepped[0]["segments"]
        lines += ["", f"Each core steps from its chamber ({chamber['diameter_mm']:.2f} mm) to its feed "
                  f"({feed['diameter_mm']:.2f} mm): a {feed['diameter_mm']:.2f} mm wire the whole length, with a "
                  f"sleeve of {chamber['diameter_mm']:.2f} mm outer diameter over the chamber's "
                  f"{chamber['length_mm']:.1f} mm."]
    return [*lines, ""]


def _make_text(segment: dict[str, Any]) -> str:
    return f"wire, {segment['diameter_mm']:.2f} mm" if segment["make"] == "wire" else "printed"


def _supply(supply: dict[str, Any] | None) -> list[str]:
    if supply is None:
        return []
    tube = supply["diameter_mm"] * (1.0 + PRESS_FIT_FRACTION)
    lines = ["## Supply", "",
             f"- {supply['count']} port(s) of {supply['diameter_mm']:.2f} mm at the base face ({supply['what']})",
             f"- tubing: outer diameter {tube:.2f} mm (a press fit of {100 * PRESS_FIT_FRACTION:.0f} % into the port), "
             "pushed in after demoulding and sealed with a silicone adhesive; let it cure before pressurising"]
    if supply.get("mode"):
        pressure = supply.get("design_pressure_kpa")
        at = f" at {pressure:.1f} kPa" if isinstance(pressure, (int, float)) else ""
        lines.append(f"- supply: {supply['mode']}{at} (actuation.supply)")
    return [*lines, ""]


def _winding(reinforcement: dict[str, Any] | None) -> list[str]:
    if not reinforcement:
        return []
    thread = reinforcement["thread"]
    lines = ["## Thread winding", "",
             f"- {reinforcement['kind']} winding of {thread['name']} ({thread['diameter_mm']:.2f} mm, breaking load "
             f"{thread['breaking_load_n']:g} N: {thread['source']}) at a pitch of {reinforcement['pitch_mm']:.2f} mm, "
             f"safety factor {reinforcement['safety_factor']:g}", "",
             "| section | chamber | turns | tension per turn N | limit N |", "|---|---|---|---|---|"]
    lines += [f"| {w['section']} | {w['chamber']} | {w['turns']} | {w['tension_per_turn_n']:.2f} | "
              f"{w['tension_limit_n']:.2f} |" for w in reinforcement["windings"]]
    if reinforcement.get("ends") == "patch":
        lines += ["", f"- end patches: on each end of every chamber core, before casting, a disc woven of "
                      f"{thread['name']} in two crossed layers at the pitch ({reinforcement['pitch_mm']:.2f} mm), as "
                      "wide as the core's end (actuation.reinforcement.ends); their tension is the finite elements' "
                      "(`softdesign simulate CASE --all`), not the table's P r pitch"]
    return [*lines, ""]


def _casting(mould: dict[str, Any]) -> list[str]:
    return ["## Casting", "",
            f"- stand the mould with the body's {mould['up']} up: the pour channel ({mould['pour_mm']:g} mm) and the "
            f"vent ({mould['vent_mm']:g} mm) open at the top",
            "- pour slowly into the pour channel until the silicone rises in the vent; cure as the datasheet says", ""]


def _demoulding(mould: dict[str, Any]) -> list[str]:
    """The core plate and its cores come out before the halves open (its note says how); a hollow body's core after."""
    pulls = ", ".join(f"{part.replace('_', ' ')} along [{', '.join(f'{round(v, 3) + 0.0:.3f}' for v in vector)}]"
                      for part, vector in mould["pull"].items() if part.startswith("half"))
    steps = [f"Open the halves: {pulls} (unit vectors in the build's output frame)."]
    if mould["note"]:
        core = f"{mould['note'][0].upper()}{mould['note'][1:]}."
        steps = [core, *steps] if mould["plate"] else [*steps, core]
    return ["## Demoulding (in this order)", "", *(f"{k}. {s}" for k, s in enumerate(steps, 1)), ""]
