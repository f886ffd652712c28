"""What the rod model adds to the actuation stage: the single-supply layout and rows, or the per-chamber pressures.

``supply: single``: the chambers sized for P* (:mod:`softdesign.pipeline.rod_single`) replace the layout's
three-chamber rule, its ring walls and its table rows; ``per_chamber``: the layout stays seed 003's and every row
gets the chamber's pressure from the rod model's inverse (:func:`~softdesign.pipeline.rod_device.per_chamber_rows`).
Without a hoop reinforcement or a material law the rows' ``pressure_kpa`` is empty and a note says why.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from softdesign.errors import ConfigError
from softdesign.io.format_names import q_label
from softdesign.kinematics.pcc_fit import fit_links
from softdesign.meshing.chambers.walls import Wall
from softdesign.pipeline.rod_device import (
    RodSetup,
    layout_body,
    layout_stations,
    outlines_at,
    per_chamber_rows,
    rod_setup,
    section_rest_lengths,
)
from softdesign.pipeline.rod_file import rod_document
from softdesign.pipeline.rod_single import (
    SingleDesign,
    rod_extra,
    single_layout,
    single_rows,
    single_summary,
    size_case,
    verdict_line,
)

if TYPE_CHECKING:
    from softdesign.config import Case
    from softdesign.meshing.chambers.layout import ChamberLayout
    from softdesign.pipeline.stages.design import DesignResult
    from softdesign.pipeline.stages.fit import FitResult
    from softdesign.pipeline.stages.kinematics import KinematicsResult

#: Backbone samples per section for its best arc (as the stage's).
ARC_SAMPLES = 201
#: A series channel narrower than this fraction of its diameter across its slanted stretch (a slant over 60 deg)
#: is named in a warning: its part of the wax core is that much thinner than the supply line's.
MIN_CHANNEL_WIDTH_FRACTION = 0.5
#: A lost core's strand (the monofilament a slender part is cast over) is this fraction of the narrowest width
#: across a series channel, so that it can be drawn out along them (a rule of thumb).
STRAND_FRACTION = 0.5
#: Longest core, in diameters, the mould prints as a pin: a printed pin more slender than this bends under the
#: pour and breaks on release (a rule of thumb, stated as such); a longer core is a steel wire or rod.
MAX_PIN_ASPECT = 20.0


def core_figures(lengths_mm: list[float], diameters_mm: list[float], lost: bool = False,
                 strand_mm: float | None = None) -> list[dict[str, Any]]:
    """Per chamber its core: length, (smallest) diameter, aspect ratio and what to make it of.

    ``lost``: tapered chambers joined in series (``supply: single``) are parts of one lost wax core (the mould's
    note: :mod:`softdesign.meshing.mould.cores`); a part past ``MAX_PIN_ASPECT`` is cast over a nylon monofilament
    of ``strand_mm`` running the whole core (wax alone that slender breaks when the hoop thread is wound on it; a
    flexible strand, unlike a steel wire, can be drawn out along the slanted channels through the supply port once
    the wax is melted: a rule of thumb, stated as such).  Else a straight pin, printed or, past ``MAX_PIN_ASPECT``,
    a steel wire or rod of the chamber's diameter.
    """
    out = []
    for length, diameter in zip(lengths_mm, diameters_mm, strict=True):
        aspect = length / diameter if diameter > 0 else float("inf")
        slender = aspect > MAX_PIN_ASPECT
        if lost:
            make = "part of the one lost wax core, tapered as the chamber's profile" + (
                f", cast over a nylon monofilament of {strand_mm or 0.0:.2f} mm through the whole core (aspect ratio "
                f"{aspect:.1f} > {MAX_PIN_ASPECT:g}), drawn out through the supply port after the wax is melted"
                if slender else "")
        else:
            make = ("printed pin (the mould's core)" if not slender else
                    f"steel wire or rod of {diameter:.2f} mm, {length:.1f} mm long (aspect ratio {aspect:.0f} > "
                    f"{MAX_PIN_ASPECT:g}: a printed pin this slender bends or breaks)")
        out.append({"length_mm": length, "diameter_mm": diameter, "aspect_ratio": aspect, "make": make})
    return out


@dataclass(frozen=True)
class RodFigures:
    """The rod model's part of the actuation stage.

    ``sections``, ``rows``, ``walls``: None where the stage's own (seed 003) figures stand; ``fill`` puts the
    pressures into the rows and returns the summary's per-q pressures; ``rod_file`` makes the build's rod file of
    the filled rows (:mod:`softdesign.pipeline.rod_file`; None when the rod model does not apply).
    """

    layout: ChamberLayout
    sections: list[dict[str, Any]] | None
    rows: list[dict[str, Any]] | None
    walls: list[Wall] | None
    summary: dict[str, Any]
    reasons: list[str]
    warnings: list[str]
    fill: Callable[[list[dict[str, Any]]], dict[str, Any]] = field(default=lambda rows: {})
    rod_file: Callable[[list[dict[str, Any]]], dict[str, Any] | None] = field(default=lambda rows: None)


def rod_figures(case: Case, kinematics: KinematicsResult, fit: FitResult, design: DesignResult | None,
                layout: ChamberLayout, grid: list[tuple[float, bool]]) -> RodFigures:
    """The single-supply device, or the per-chamber pressures, of the case (see the module notes)."""
    setup = rod_setup(case)
    if case.actuation is not None and case.actuation.supply == "single":
        if isinstance(setup, str):
            raise ConfigError(f"actuation.supply: single: {setup}")
        if design is None:
            raise ConfigError("actuation.supply: single sizes each designed section: add design: {tolerance_mm: 1} "
                              "and blend: pcc")
        return _single(case, kinematics, fit, design, layout, grid, setup)
    head = {"supply": "per_chamber", "backbone": case.actuation.backbone if case.actuation else None,
            "design_pressure_kpa": None}
    if isinstance(setup, str):
        def empty(rows: list[dict[str, Any]]) -> dict[str, Any]:
            for r in rows:
                r["pressure_kpa"] = None
            return {}
        return RodFigures(layout, None, None, None, {**head, "body_modulus_kpa": None, "rod_model": setup}, [],
                          [f"no pressures: {setup}"], empty)
    stations = layout_stations(layout, section_rest_lengths(kinematics))
    body = layout_body(layout, stations, outlines_at(kinematics, fit, stations.s), setup)
    rest = section_rest_lengths(kinematics)
    export = [q for q, e in grid if e]

    def fill(rows: list[dict[str, Any]]) -> dict[str, Any]:
        per_chamber_rows(rows, body, rest)
        return {"pressures_kpa": {q_label(q): [[r["pressure_kpa"] for r in rows if r["q"] == q and r["section"] == i]
                                               for i in range(1, layout.sections + 1)] for q in export}}

    def rod_file(rows: list[dict[str, Any]]) -> dict[str, Any]:
        qs = sorted({r["q"] for r in rows})
        arcs = [[q, [[r["arc_kappa"], r["arc_phi"], r["arc_length_mm"]] for r in rows
                     if r["q"] == q and r["chamber"] == 1]] for q in qs]
        lengths = [[[r["length_mm"] for r in rows if r["q"] == q and r["section"] == i + 1]
                    for i in range(layout.sections)] for q in qs]
        return rod_document(case, body, stations.chamber, {"supply": "per_chamber", "per_chamber": {
            "rest_lengths_mm": rest.tolist(), "arcs": arcs, "chamber_lengths_mm": lengths}})

    inner = [float(stations.ds[(stations.section == c.section) & stations.chamber].sum()) for c in layout.chambers]
    cores = core_figures(inner, [c.diameter_mm for c in layout.chambers])
    return RodFigures(layout, None, None, None, {**head, "body_modulus_kpa": setup.modulus_kpa,
                                                 "reinforcement": setup.reinforcement(), "cores": cores}, [],
                      _core_notes(cores), fill, rod_file)


def _single(case: Case, kinematics: KinematicsResult, fit: FitResult, design: DesignResult, layout: ChamberLayout,
            grid: list[tuple[float, bool]], setup: RodSetup) -> RodFigures:
    single = size_case(case, kinematics, fit, design, setup)
    summary = single_summary(case, single, setup)
    arcs = {q: fit_links(kinematics.chain, q, ARC_SAMPLES) for q, _ in grid}
    rows = single_rows(single, grid, arcs)
    st, dev = single.problem.stations, single.device
    walls = []
    for i in range(int(st.section.max()) + 1):  # between cavities and against the thread (the skin is measured)
        inner = [(float(dev.walls[k]), dev.wall_kind[k]) for k in np.flatnonzero(st.section == i)
                 if not dev.wall_kind[k].endswith("-skin")]
        if inner:
            value, kind = min(inner)
            walls.append(Wall(kind, value, i + 1, 0, None, None, None))
    warnings: list[str] = []
    if summary["rest_lengths_mm"] is not None:
        warnings.append("backbone: free: each section is cast shorter, at " + ", ".join(
            f"{v:.2f}" for v in summary["rest_lengths_mm"]) + " mm, and reaches its designed length at P* (the meshes "
            "and the mould are at these rest lengths at q = 0, the rod model's lengths at every q)")
    sections = summary.pop("sections")
    meshed = single_layout(layout, single, single.l_of(kinematics))
    summary["channels"] = channel_figures(single)
    narrowest = min((c["width_mm"] for c in summary["channels"]), default=case.actuation.feed_diameter_mm
                    if case.actuation is not None else 0.0)
    summary["cores"] = core_figures([s["chambers"][0]["length_mm"] for s in sections],
                                    [min(s["chambers"][0]["diameter_mm"].values()) for s in sections], lost=True,
                                    strand_mm=STRAND_FRACTION * narrowest)
    warnings += _core_notes(summary["cores"])
    warnings += _end_notes(float(summary["design_pressure_kpa"]), setup.modulus_kpa, case.chamber_ends)
    warnings += [_slant_note(c) for c in summary["channels"]
                 if c["width_mm"] < MIN_CHANNEL_WIDTH_FRACTION * c["diameter_mm"]]
    document = rod_document(case, single.device.body, single.problem.stations.chamber, rod_extra(single))
    return RodFigures(meshed, sections, rows, walls, summary, list(summary["model_reasons"]), warnings,
                      rod_file=lambda rows: document)


def channel_figures(single: SingleDesign) -> list[dict[str, Any]]:
    """Per series channel: the sections it joins, its diameter (normal plane), length along the body (between the
    chambers' flat ends), largest slant and its width across its course there (``D cos(slant)``), mm and rad."""
    out = []
    for course in single.device.channels:
        slant = course.slant_max()
        out.append({"from_section": course.index + 1, "to_section": course.index + 2,
                    "diameter_mm": course.diameter_mm, "length_mm": course.between[1] - course.between[0],
                    "slant_max_rad": slant, "width_mm": course.diameter_mm * float(np.cos(slant))})
    return out


#: A cavity in an incompressible neo-Hookean solid grows without bound at this pressure over the shear modulus
#: (5 / 2: the spherical cavity in an infinite solid); a chamber's end carries no thread.
END_LIMIT_MU = 2.5


def _end_notes(pressure_kpa: float, modulus_kpa: float, ends: str, what: str = "P*") -> list[str]:
    """A warning when ``what`` (P*, or the per-chamber table's highest pressure) passes what a chamber's bare end
    holds; none for patched ends (``ends``), which no closed form bounds: the whole-device FE is their check.

    Model: the end is taken as a cavity in an incompressible neo-Hookean solid of shear modulus ``E / 3``, which
    has no equilibrium above ``END_LIMIT_MU`` mu (a spherical cavity in an infinite body: a scale, not a bound for
    a cylinder's flat end).  The finite elements' bare ends give way near it: the 12 mm test section's at 2.4 mu
    (tests/mechanics/test_chamber_ends.py), the whole sample single-supply device's (``softdesign simulate
    --all``) near 3.7 mu and the VMTK aorta's at 2.9 mu.  The pressure scales with E, so a stiffer silicone does
    not help: the design must ask less pressure, or the ends be patched (``actuation.reinforcement.ends``).
    """
    mu = modulus_kpa / 3.0
    if ends == "patch" or pressure_kpa <= END_LIMIT_MU * mu:
        return []
    return [f"{what} {pressure_kpa:.1f} kPa is {pressure_kpa / mu:.1f} times the silicone's shear modulus "
            f"({mu:.1f} kPa): a chamber's end carries no thread, and a cavity in this rubber has no equilibrium "
            f"past {END_LIMIT_MU:g} times it, so the ends are likely to balloon before it (a stiffer silicone "
            "raises the pressure alike); check with `softdesign simulate CASE --all`, which reports the largest "
            "pressure it reaches, and patch the ends (actuation.reinforcement.ends: patch) or ask less curvature per "
            "pressure (larger chambers further from the axis, a thinner material.min_wall_mm)"]


def table_end_notes(rows: list[dict[str, Any]], modulus_kpa: float | None, ends: str) -> list[str]:
    """``supply: per_chamber``'s end-limit warning (:func:`_end_notes`) on the table's highest pressure."""
    pressured = [r for r in rows if r.get("pressure_kpa") is not None]
    if modulus_kpa is None or not pressured:
        return []
    top = max(pressured, key=lambda r: r["pressure_kpa"])
    return _end_notes(float(top["pressure_kpa"]), modulus_kpa, ends,
                      f"the table's highest pressure (section {top['section']}, chamber {top['chamber']}, "
                      f"q = {top['q']:g})")


def _slant_note(channel: dict[str, Any]) -> str:
    """A warning for a series channel that slants steeply between its chambers."""
    slant = float(np.rad2deg(channel["slant_max_rad"]))
    return (f"the series channel from section {channel['from_section']} to {channel['to_section']} slants "
            f"{slant:.0f} deg round the axis between their chambers: {channel['width_mm']:.2f} mm across (of "
            f"{channel['diameter_mm']:g} mm), a fragile part of the wax core; a longer end wall "
            "(actuation.end_wall_mm) lowers the slant")


def _core_notes(cores: list[dict[str, Any]]) -> list[str]:
    """One note when some cores are too slender to print: how many, and what to use."""
    steel = [c for c in cores if c["aspect_ratio"] > MAX_PIN_ASPECT]
    if not steel:
        return []
    worst = max(steel, key=lambda c: c["aspect_ratio"])
    return [f"{len(steel)} of {len(cores)} chamber cores are longer than {MAX_PIN_ASPECT:g} diameters (up to "
            f"{worst['aspect_ratio']:.0f}): {worst['make']} (actuation/summary.json: cores)"]


def device_line(summary: dict[str, Any]) -> str | None:
    """The single-supply device's verdict (None for other supplies): the rod model's line when every judged figure
    is within its limits, else ``device: NOT feasible:`` and every reason (each names the key to change)."""
    if summary.get("supply") != "single":
        return None
    if summary.get("material") is not None and summary.get("reasons"):
        return "device: NOT feasible: " + "; ".join(summary["reasons"])
    return verdict_line(summary)


def describe_rod(summary: dict[str, Any]) -> list[str]:
    """The rod model's lines: the single-supply device's chambers and verdict line, or the per-chamber pressures."""
    if summary.get("supply") == "single":
        lines = [f"section {s['section']}: chamber at {s['chambers'][0]['angle_rad']['middle']:.3f} rad, "
                 f"{s['chambers'][0]['distance_mm']['middle']:.3f} mm out, diameter "
                 f"{s['chambers'][0]['diameter_mm']['start']:.3f}-{s['chambers'][0]['diameter_mm']['end']:.3f} mm, "
                 f"{s['chambers'][0]['turns']} turns" for s in summary.get("sections", [])]
        return lines + [summary.get("verdict_line") or verdict_line(summary)]
    pressures = summary.get("pressures_kpa")
    if not pressures:
        return [f"pressures: none ({summary.get('rod_model', 'no rod model')})"]
    top = max((p for per_q in pressures.values() for sec in per_q for p in sec if p is not None), default=0.0)
    return [f"pressures (rod model, per chamber): up to {top:.1f} kPa over the export q"]
