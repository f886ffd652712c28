"""The top of the page: the design's figures in one table, and every warning in a banner (issue 17, item 1).

Each figure is read from ``manifest.json`` (with its JSON pointer, so the page
can be traced like the key-figure table) except the diameter range, which is
computed here from the kept radius field: the mean caliper diameter
rho(l, a) + rho(l, a + pi) averaged over a, at q = 1, its smallest and largest
over l.  The warnings are the manifest's (every stage's, each once: the
terminal printed the same list).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

import numpy as np

from softdesign.pipeline.notices import NOTE, WARNING
from softdesign.report.build_folder import BuildData
from softdesign.report.html_page import Cell, Table
from softdesign.report.tables import format_value, resolve_or, resolve_pointer

#: Samples along l and around a for the diameter range (the fit's knots are about 1.5 mm apart).
DIAMETER_L_SAMPLES, DIAMETER_ANGLES = 801, 96


@dataclass(frozen=True)
class Fact:
    """One line of the summary table: label, value text, unit, and the manifest pointer of the value the text
    shows ("" when the text is computed here or combines values)."""

    label: str
    text: str
    unit: str = ""
    pointer: str = ""


def diameter_range_mm(data: BuildData) -> tuple[float, float] | None:
    """(smallest, largest) mean caliper diameter over l at q = 1, mm; None without a fit."""
    if data.fit is None:
        return None
    l = np.linspace(0.0, 1.0, DIAMETER_L_SAMPLES)
    a = np.linspace(0.0, 2.0 * np.pi, DIAMETER_ANGLES, endpoint=False)  # even count: a + pi is on the grid
    rho = data.fit.field.evaluate_grid(1.0, l, a)
    diameter = (rho + np.roll(rho, DIAMETER_ANGLES // 2, axis=1)).mean(axis=1)
    return float(diameter.min()), float(diameter.max())


def summary_facts(data: BuildData) -> list[Fact]:
    """The summary's figures that this build has, in page order."""
    m = data.manifest
    facts = [Fact("length at q = 1", _num(resolve_or(m, "/metrics/blend/final_path/length_mm", None)), "mm",
                  "/metrics/blend/final_path/length_mm"),
             Fact("links", str(data.link_count))]
    diameters = diameter_range_mm(data)
    if diameters is not None:
        facts.append(Fact("diameter range at q = 1 (mean caliper)", f"{diameters[0]:.3g} to {diameters[1]:.3g}", "mm"))
    for i, entry in enumerate(m.get("outputs", [])):
        if "volume_mm3" in entry and entry["path"].endswith(".stl") and entry["path"].count("/") == 1:
            facts.append(Fact(f"volume of {entry['path']}", _num(entry["volume_mm3"]), "mm^3",
                              f"/outputs/{i}/volume_mm3"))
    facts += _feasibility_facts(m)
    facts += _actuation_facts(m)
    rho_kappa = resolve_or(m, "/metrics/fit/max_rho_kappa", None)
    if rho_kappa is not None:
        facts.append(Fact("largest rho * kappa at q = 1 (folds at 1)", _num(rho_kappa), "",
                          "/metrics/fit/max_rho_kappa"))
    arc = resolve_or(m, "/metrics/kinematics/arc_check", None)
    if isinstance(arc, dict) and arc.get("max_deviation_mm"):
        worst = max(arc["max_deviation_mm"])
        j = arc["max_deviation_mm"].index(worst)
        facts.append(Fact(f"one arc per link: largest miss (link {j}, q = {format_value(arc.get('q'))})", _num(worst),
                          "mm", f"/metrics/kinematics/arc_check/max_deviation_mm/{j}"))
    return facts


def _feasibility_facts(m: dict[str, Any]) -> list[Fact]:
    block = resolve_or(m, "/metrics/feasibility", None)
    if not isinstance(block, dict) or "morph" not in block:
        return []
    base = "/metrics/feasibility/morph"
    high, low = block["morph"]["stretch_max"], block["morph"]["stretch_min"]
    facts = [Fact("skin stretch over the morph: smallest", _num(low["value"]), "", f"{base}/stretch_min/value"),
             Fact("skin stretch over the morph: largest", _num(high["value"]), "", f"{base}/stretch_max/value")]
    rows = block.get("per_q", [])
    walls = [(row["wall_min_mm"], i) for i, row in enumerate(rows) if row.get("wall_min_mm") is not None]
    if walls:
        wall, i = min(walls)
        facts.append(Fact(f"thinnest wall (q = {format_value(block['per_q'][i]['q'])})", _num(wall), "mm",
                          f"/metrics/feasibility/per_q/{i}/wall_min_mm"))
    verdict = block.get("feasible")
    text = "not judged (no material: in the case file)" if verdict is None else format_value(verdict)
    pointer = "/metrics/feasibility/feasible" if verdict is not None else ""
    facts.append(Fact("feasible for its material", text, "", pointer))
    return facts


def _actuation_facts(m: dict[str, Any]) -> list[Fact]:
    """The thinnest wall of each kind and the chambers' extension range, with where (actuated builds only)."""
    block = resolve_or(m, "/metrics/actuation", None)
    if not isinstance(block, dict) or "thinnest" not in block:
        return []
    facts = [Fact(f"actuation: thinnest {kind} wall (section {w['section']}"
                  + (f", chamber {w['chamber']}" if w["chamber"] else "")
                  + (f", q = {format_value(w['q'])}" if w["q"] is not None else "") + ")",
                  _num(w["thickness_mm"]), "mm", f"/metrics/actuation/thinnest/{kind}/thickness_mm")
             for kind, w in block["thinnest"].items()]
    ext = block["extensions"]
    low, high = min(ext, key=lambda e: e["min"]), max(ext, key=lambda e: e["max"])
    facts.append(Fact("actuation: chamber extension (length at q over q = 0)",
                      f"{format_value(low['min'])} to {format_value(high['max'])}", ""))
    verdict = block.get("feasible")
    facts.append(Fact("actuation feasible for its material", "not judged (no material)" if verdict is None
                      else format_value(verdict), "", "/metrics/actuation/feasible" if verdict is not None else ""))
    return facts


def summary_warnings(manifest: dict[str, Any]) -> tuple[list[str], list[str]]:
    """The build's warnings and notes as the manifest records them (each once, the terminal's same lines).

    The verdict's reasons are the verdict box's (:mod:`softdesign.report.verdict`), not repeated here; failed
    checks are the checks' (:func:`softdesign.report.verdict.checks_html`).
    """
    record = [w for w in manifest.get("warnings", []) if isinstance(w, dict)]
    warnings = [f"{w['stage']}: {w['text']}" for w in record if w.get("kind", WARNING) == WARNING]
    notes = [f"{w['stage']}: {w['text']}" for w in record if w.get("kind") == NOTE]
    return warnings, notes


def _num(value: Any) -> str:
    return format_value(float(value)) if isinstance(value, (int, float)) and not isinstance(value, bool) else "-"


def facts_table(facts: list[Fact], manifest: dict[str, Any]) -> Table:
    """The summary table; a fact with a pointer carries it and the exact JSON value, as the key-figure table does."""
    rows = []
    for f in facts:
        trace: tuple[tuple[str, str], ...] = ()
        if f.pointer:
            trace = (("data-pointer", f.pointer), ("data-value", json.dumps(resolve_pointer(manifest, f.pointer))))
        rows.append((Cell(f.label), Cell(f.text, "num" if f.pointer else "", trace), Cell(f.unit)))
    return Table("Summary", ("figure", "value", "unit"), rows)
