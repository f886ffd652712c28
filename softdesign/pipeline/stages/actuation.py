"""Stage: actuation -- the chambers' layout (refused when it cannot fit), lengths per q, walls and extensions.

With ``actuation:`` in the case, every link is a seed 003 section with three
chambers and their feeds (:mod:`softdesign.meshing.chambers.layout`).  This
stage, before export:

1. lays them out and refuses (exit 2) a layout whose walls cannot fit the
   body's thinnest section (radius over q = 0 and 1, every angle), naming the
   section, the walls and the largest chamber diameter, feed diameter and
   section count that fit;
2. at every export q and on a dense grid (``DENSE_Q`` values, q = 0 ... 1),
   fits each section's best arc at that q (:func:`~softdesign.kinematics.pcc_fit.fit_links`,
   started on the section's base frame; exact for a body whose sections are
   arcs, and its misfit stated otherwise) and writes seed 003's chamber
   lengths on it: ``actuation.csv`` and the same rows in the manifest;
3. measures the thinnest walls (chamber-skin, feed-skin at every q;
   chamber-chamber, chamber-feed, feed-feed once: they do not change with q)
   and each chamber's extension (its axis length at q over q = 0, on the body
   itself), and judges them against ``material:`` (``--strict`` exits 1).
"""

from __future__ import annotations

import csv
import io
import json
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softdesign.errors import ConfigError
from softdesign.io.format_names import q_label
from softdesign.kinematics.chamber_lengths import chamber_lengths_from_arc
from softdesign.kinematics.pcc_fit import fit_links
from softdesign.meshing.body.sections import body_sections
from softdesign.meshing.chambers.carve import measured_skin_walls
from softdesign.meshing.chambers.layout import ChamberLayout, Channel, analytic_walls, chamber_angles, plan_layout
from softdesign.meshing.chambers.walls import Wall, chamber_lengths_mm, ring_walls, skin_walls
from softdesign.meshing.volume_mesh.sweep_layout import check_resolvable, layout_holes
from softdesign.pipeline.actuation_judge import judge
from softdesign.pipeline.body_spec import body_spec
from softdesign.pipeline.bounds import export_workers
from softdesign.pipeline.item_progress import item_counter
from softdesign.pipeline.parallel import map_items
from softdesign.pipeline.rod_actuation import describe_rod, device_line, rod_figures, table_end_notes
from softdesign.pipeline.rod_file import ROD_FILE
from softdesign.pipeline.rod_free import body_curve_at
from softdesign.pipeline.simulate_estimates import ESTIMATE_COLUMNS, SimulateResult, estimate_cells
from softdesign.pipeline.stage import Stage
from softdesign.pipeline.stages.design import DesignResult
from softdesign.pipeline.stages.fit import FitResult
from softdesign.pipeline.stages.judges import actuation_judgement, rule_notices
from softdesign.pipeline.stages.kinematics import KinematicsResult
from softdesign.pipeline.store import Staging

if TYPE_CHECKING:
    from softdesign.config import Case

VERSION = 8  # 2: one reason per cause (a kind of wall, a bound of extension); 3: the simulate stage's pressures;
#            4: angles in (-180, 180] degrees; 5: the rod model (supply, pressure_kpa); 6: series channels,
#            the rod file (actuation/rod.json); 7: the chambers' end-limit warnings (P* and the per-chamber
#            table's highest pressure); 8: the end-limit warning offers patched ends, and is not given for them
SUMMARY = "actuation/summary.json"
TABLE = "actuation.csv"
#: The dense q grid's size (q = 0, 0.05, ..., 1).
DENSE_Q = 21
#: Backbone samples per section for its best arc.
ARC_SAMPLES = 201
#: The thinnest wall a layout may have anywhere, mm: below it the booleans and a cast leave no material to speak
#: of (rule of thumb); ``material.min_wall_mm`` then judges the design as feasible or not.
MIN_LAYOUT_WALL_MM = 0.2
#: Columns of actuation.csv.
COLUMNS = ("q", "export", "section", "chamber", "angle_deg", "distance_mm", "length_mm", "extension", "arc_kappa",
           "arc_phi", "arc_length_mm", "arc_misfit_mm", "pressure_kpa")


@dataclass(frozen=True)
class ActuationResult:
    """The figures (JSON-ready, rows included) and the CSV text."""

    summary: dict[str, Any]
    table: str
    rod: dict[str, Any] | None = None  # the rod file (actuation/rod.json) the pressure command reads


def actuation_layout(case: Case, kinematics: KinematicsResult,
                     sized: ActuationResult | None = None) -> ChamberLayout | None:
    """The case's chambers and feeds on its links (None without ``actuation:``); end walls on the q = 0 body.

    ``supply: single``: the chambers this stage sized (``sized``, its result: the summary's layout with each
    chamber's taper); a step that does not take them (the volume mesh, the finite elements) is refused.
    """
    if case.actuation is None:
        return None
    curve0 = kinematics.chain.shape.curve_at(0.0)
    l = curve0.curve.dense_l()
    spec = case.actuation.spec()
    if case.actuation.supply == "single":  # one chamber per section, placed and sized by the rod model
        spec = replace(spec, chambers_per_section=1)
    try:
        planned = plan_layout(spec, kinematics.chain.breaks, l, curve0.curve.arc_length(l))
    except ValueError as err:
        raise ConfigError(f"actuation.end_wall_mm: {err}; use a thinner end wall or fewer links") from err
    if case.actuation.supply != "single" or sized is None:
        return planned
    return sized_layout(planned, sized.summary["layout"])


def unsized_single(case: Case, what: str) -> None:
    """Refuse a step that would lay out ``supply: single``'s chambers without the actuation stage's sizing."""
    if case.actuation is not None and case.actuation.supply == "single":
        raise ConfigError(f"{what}: actuation.supply: single's chambers are sized and tapered by the rod model in the "
                          f"actuation stage, and {what} does not take them yet; use actuation.supply: per_chamber "
                          "for it")


def sized_layout(planned: ChamberLayout, document: dict[str, Any]) -> ChamberLayout:
    """The layout kept in the summary (:func:`layout_document`) over the planned one: angles, sizes, tapers."""
    chambers = tuple(replace(c, angle=float(np.deg2rad(d["angle_deg"])), distance_mm=d["distance_mm"],
                             diameter_mm=d["diameter_mm"], profile=tuple(tuple(p) for p in d.get("profile", ())))
                     for c, d in zip(planned.chambers, document["chambers"], strict=True))
    feeds = tuple(replace(f, angle=float(np.deg2rad(d["angle_deg"])), ring_mm=d["ring_mm"])
                  for f, d in zip((f for f in planned.feeds if f.section == 0), document["feeds"], strict=True))
    spec = replace(planned.spec, distance_mm=max(c.distance_mm for c in chambers),
                   diameter_mm=min(c.diameter_mm for c in chambers))
    channels = tuple(Channel(d["section"] - 1, d["diameter_mm"], tuple(tuple(p) for p in d["course"]))
                     for d in document.get("channels", ()))
    return replace(planned, spec=spec, chambers=chambers, feeds=feeds, channels=channels)


def q_grid(case: Case) -> list[tuple[float, bool]]:
    """(q, is an export q) for the dense grid, the export q values and the simulated ones, sorted, once per label."""
    export = case.export.q_values()
    chosen = {q_label(q): (q, True) for q in export}
    simulated = case.simulate.q if case.simulate is not None and case.simulate.enabled else []
    for q in [*np.linspace(0.0, 1.0, DENSE_Q), *simulated]:
        chosen.setdefault(q_label(float(q)), (float(q), False))
    return sorted(chosen.values())


def section_radii(fit: FitResult, layout: ChamberLayout) -> list[float]:
    """The smallest body radius of each section at q = 0 and 1 (every angle), mm."""
    a = np.linspace(0.0, 2.0 * np.pi, 360, endpoint=False)
    radii = []
    for i in range(layout.sections):
        l = np.linspace(layout.breaks[i], layout.breaks[i + 1], 101)
        radii.append(float(min(fit.field.evaluate_grid(q, l, a).min() for q in (0.0, 1.0))))
    return radii


def _largest(spec, sections: int, radius: float, wall: float) -> str:
    """The largest chamber diameter, feed diameter and section count that fit a section of ``radius``."""
    d, big, small = spec.distance_mm, spec.diameter_mm, spec.feed_diameter_mm
    chord = 2.0 * d * np.sin(np.pi / (3.0 * sections)) if sections > 1 else np.inf
    most_big = min(2.0 * (radius - d - wall), 2.0 * d * np.sin(np.pi / 3.0) - wall, 2.0 * (chord - wall) - small)
    most_small = min(2.0 * (radius - d - wall), 2.0 * (chord - wall) - big, chord - wall, big)
    count = 1
    for n in range(2, 101):
        gap = 2.0 * d * np.sin(np.pi / (3.0 * n))
        if gap - 0.5 * (big + small) < wall or gap - small < wall:
            break
        count = n
    fits = [f"diameter_mm <= {most_big:.3f}" if most_big > 0 else "no chamber diameter (move distance_mm)",
            f"feed_diameter_mm <= {most_small:.3f}" if most_small > 0 else "no feed diameter",
            f"at most {count} sections (links) at these diameters"]
    return "; ".join(fits)


def check_layout(layout: ChamberLayout, radii: list[float]) -> list[dict[str, Any]]:
    """Each section's analytic walls; ConfigError (exit 2) naming the section and walls when one is too thin."""
    rows, problems = [], []
    for i, radius in enumerate(radii):
        walls = analytic_walls(layout.spec, layout.sections, i, radius)
        row = {"section": i + 1, "radius_min_mm": radius, "chamber_skin_mm": walls.chamber_skin,
               "chamber_chamber_mm": walls.chamber_chamber, "chamber_feed_mm": _finite(walls.chamber_feed),
               "feed_feed_mm": _finite(walls.feed_feed), "feed_skin_mm": _finite(walls.feed_skin),
               "feeds_through": len(layout.feeds_through(i))}
        rows.append(row)
        thin = {k: v for k, v in row.items() if k.endswith("_mm") and k != "radius_min_mm" and v is not None
                and v < MIN_LAYOUT_WALL_MM}
        if thin:
            named = ", ".join(f"{k.removesuffix('_mm').replace('_', '-')} {v:.3f} mm" for k, v in thin.items())
            problems.append(f"section {i + 1} (radius {radius:.3f} mm, {row['feeds_through']} feeds through it): "
                            f"{named}; largest that fit: "
                            f"{_largest(layout.spec, layout.sections, radius, MIN_LAYOUT_WALL_MM)}")
    if problems:
        s = layout.spec
        raise ConfigError(
            f"actuation: the layout (distance_mm {s.distance_mm:g}, diameter_mm {s.diameter_mm:g}, feed_diameter_mm "
            f"{s.feed_diameter_mm:g}, {layout.sections} sections) leaves walls under {MIN_LAYOUT_WALL_MM:g} mm: "
            + " | ".join(problems) + "; change the actuation block (or links.count)"
        )
    return rows


def _finite(value: float) -> float | None:
    return float(value) if np.isfinite(value) else None


def _rows_at(kinematics: KinematicsResult, layout: ChamberLayout, q: float, export: bool,
             reference: np.ndarray | None) -> tuple[list[dict[str, Any]], np.ndarray]:
    """The table's rows at one q (seed 003's lengths on each section's best arc) and the (n, 3) lengths."""
    fits = fit_links(kinematics.chain, q, ARC_SAMPLES)
    first = chamber_angles(layout.spec, layout.sections)
    d = layout.spec.distance_mm
    lengths = np.array([chamber_lengths_from_arc(f.kappa, f.phi, f.length, d, first[i, 0])
                        for i, f in enumerate(fits)])
    base = lengths if reference is None else reference
    rows = [{"q": q, "export": int(export), "section": i + 1, "chamber": j + 1,
             "angle_deg": degrees_wrapped(first[i, j]), "distance_mm": d, "length_mm": float(lengths[i, j]),
             "extension": float(lengths[i, j] / base[i, j]), "arc_kappa": f.kappa, "arc_phi": f.phi,
             "arc_length_mm": f.length, "arc_misfit_mm": f.backbone_max_mm}
            for i, f in enumerate(fits) for j in range(layout.spec.chambers_per_section)]
    return rows, lengths


def table_text(rows: list[dict[str, Any]], estimates: bool = False) -> str:
    """actuation.csv: a header, then one row per (q, section, chamber); floats as repr (exact round trip).

    ``estimates``: add the simulate stage's columns (:data:`~softdesign.pipeline.simulate_estimates.ESTIMATE_COLUMNS`),
    empty in the rows it did not solve.
    """
    columns = COLUMNS + (ESTIMATE_COLUMNS if estimates else ())
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(columns)
    writer.writerows([[_cell(r.get(k)) for k in columns] for r in rows])
    return buffer.getvalue()


def _cell(value: Any) -> Any:
    """A table cell: a float as repr, None (an estimate not solved) as empty."""
    if value is None:
        return ""
    return repr(float(value)) if isinstance(value, float) else value


def _add_estimates(rows: list[dict[str, Any]], simulated: SimulateResult | None) -> None:
    """Put the simulate stage's pressures into the rows it solved (the rest get None), when there is a stage result."""
    if simulated is None:
        return
    for r in rows:
        cells = estimate_cells(simulated, r["q"], r["section"])
        r["fe_pressure_kpa"] = None if cells is None else float(cells["pressure_kpa"][r["chamber"] - 1])
        r["fe_pressure_arc_error_mm"] = None if cells is None else cells["pressure_arc_error_mm"]
        r["fe_pressure_source"] = None if cells is None else cells["pressure_source"]


def _extensions(kinematics: KinematicsResult, layout: ChamberLayout, grid: list[float],
                rod: dict[str, Any] | None = None) -> list[dict[str, Any]]:
    """Each chamber's axis length over the grid (on the body itself, as the meshes take it: the rod model's
    summary ``rod``): its largest and smallest extension."""
    lengths = np.array([chamber_lengths_mm(body_curve_at(kinematics, rod, q), layout) for q in grid])
    ratio = lengths / lengths[grid.index(0.0)]
    out = []
    for c in layout.chambers:
        series = ratio[:, c.section, c.index]
        hi, lo = int(np.argmax(series)), int(np.argmin(series))
        out.append({"section": c.section + 1, "chamber": c.index + 1, "length_q0_mm": float(lengths[0, c.section,
                    c.index]), "max": float(series[hi]), "q_max": grid[hi], "min": float(series[lo]),
                    "q_min": grid[lo]})
    return out


def _skin(kinematics: KinematicsResult, fit: FitResult, layout: ChamberLayout, grid: list[float],
          offset_mm: float, rod: dict[str, Any] | None = None) -> list[Wall]:
    """The thinnest chamber-skin, feed-skin and (series) channel-skin wall at every q of the grid (on the body the
    meshes take: :func:`~softdesign.pipeline.rod_free.body_curve_at` of the rod model's summary ``rod``)."""
    out: list[Wall] = []
    for q in grid:
        walls = skin_walls(body_curve_at(kinematics, rod, q), fit.field, q, layout, offset_mm)
        for kind in ("chamber-skin", "feed-skin", "channel-skin"):
            of_kind = [w for w in walls if w.kind == kind]
            if of_kind:
                out.append(min(of_kind, key=lambda w: w.thickness_mm))
    return out


def _meshed(case: Case, kinematics: KinematicsResult, fit: FitResult, layout: ChamberLayout,
            rod: dict[str, Any] | None = None) -> list[Wall]:
    """At every export q (on the build's worker processes), the thinnest skin over chambers and feeds measured
    on the meshes the export makes."""
    e, spec = case.export, body_spec(case, fit)

    def at(q: float) -> list[Wall]:
        curve = body_curve_at(kinematics, rod, q)
        sections = body_sections(curve, fit.field, q, e.spacing_mm, e.angular_count)
        walls = [Wall(kind, value, section + 1, chamber + 1, q, l, None)
                 for kind, value, section, chamber, l in measured_skin_walls(sections, spec, curve, layout)]
        return [min((w for w in walls if w.kind == kind), key=lambda w: w.thickness_mm)
                for kind in dict.fromkeys(w.kind for w in walls)]

    longest = max(key.length for key in kinematics.chain.shape.keys)
    counted = item_counter("actuation", e.q_values(), lambda q: f"walls at q = {q:g}")  # a bar, when one listens
    return [w for walls in map_items(at, e.q_values(), most=export_workers(case, longest), on_result=counted)
            for w in walls]


def degrees_wrapped(angle_rad: float) -> float:
    """An angle in degrees in (-180, 180] (the one convention of the CSV and JSON outputs), rounded to 1e-9 deg so
    that 30 and 390 - 360 are written as the same number."""
    degrees = float(np.rad2deg(angle_rad)) % 360.0
    return round(degrees - 360.0 if degrees > 180.0 else degrees, 9) + 0.0


def layout_document(layout: ChamberLayout) -> dict[str, Any]:
    """The layout as JSON: the spec, every chamber and feed (angles in degrees)."""
    return {
        "rule": "section i chamber j at first_angle + 120 j + i 120/n deg in the body's RMF (0 along N); feeds on "
                "the chambers' ring at their chamber's angle, from the base face into the chamber",
        "chambers": [{"section": c.section + 1, "chamber": c.index + 1, "angle_deg": degrees_wrapped(c.angle),
                      "distance_mm": c.distance_mm, "diameter_mm": c.diameter_mm, "l_start": c.l_start,
                      "l_end": c.l_end, **({"profile": [list(p) for p in c.profile]} if c.profile else {})}
                     for c in layout.chambers],
        "feeds": [{"section": f.section + 1, "chamber": f.chamber + 1, "angle_deg": degrees_wrapped(f.angle),
                   "ring_mm": f.ring_mm, "diameter_mm": f.diameter_mm, "l_start": f.l_start, "l_end": f.l_end}
                  for f in layout.feeds],
        **({"channels": [{"section": c.section + 1, "from_section": c.section, "diameter_mm": c.diameter_mm,
                          "l_start": c.l_start, "l_end": c.l_end, "course": [list(p) for p in c.course],
                          "course_columns": ["l", "angle_rad (continuous)", "ring_mm"]}
                         for c in layout.channels]} if layout.channels else {}),
    }


def _check_sweep(case: Case, fit: FitResult, layout: ChamberLayout) -> None:
    """The swept volume mesher's check of the layout
    (:func:`~softdesign.meshing.volume_mesh.sweep_layout.check_resolvable`), made here too so that a layout it
    cannot mesh is refused before the export, mould and volume stages run."""
    volume = case.export.volume_mesh
    if volume is None or volume.mesher != "sweep":
        return
    if any(c.profile for c in layout.chambers):
        raise ConfigError("export.volume_mesh (mesher sweep): the swept mesher meshes one cross-section for the "
                          "whole body, and actuation.supply: single tapers its chambers and sets each section's "
                          "own angle; use export.volume_mesh.mesher: ftetwild, or drop export.volume_mesh")
    a = np.linspace(0.0, 2.0 * np.pi, case.export.angular_count, endpoint=False)
    scale = float(np.median(fit.field.evaluate_grid(0.0, np.linspace(0.0, 1.0, 65), a)))
    check_resolvable(layout, layout_holes(layout, scale, volume.size_mm), scale)


def run_actuation(case: Case, kinematics: KinematicsResult, fit: FitResult, simulated: SimulateResult | None = None,
                  design: DesignResult | None = None) -> ActuationResult | None:
    """Layout (or refusal), the lengths table with the rod model's pressures (and the simulate stage's), the walls
    and extensions and their verdict; None without actuation."""
    layout = actuation_layout(case, kinematics)
    if layout is None:
        return None
    grid = q_grid(case)
    rod = rod_figures(case, kinematics, fit, design, layout, grid)
    layout = rod.layout
    sections = rod.sections if rod.sections is not None else check_layout(layout, section_radii(fit, layout))
    _check_sweep(case, fit, layout)
    rows = rod.rows if rod.rows is not None else _per_chamber_rows(kinematics, layout, grid)
    filled = rod.fill(rows)
    # per_chamber: the pressures are the table's (single: P*, warned of in rod.warnings)
    table_warnings = (table_end_notes(rows, rod.summary.get("body_modulus_kpa"), case.chamber_ends)
                      if rod.summary.get("supply") == "per_chamber" else [])
    _add_estimates(rows, simulated)
    qs = [q for q, _ in grid]
    walls = (rod.walls if rod.walls is not None else ring_walls(layout)) + _skin(kinematics, fit, layout, qs,
                                                                                 case.export.offset_mm, rod.summary)
    walls += _meshed(case, kinematics, fit, layout, rod.summary)
    extensions = _extensions(kinematics, layout, qs, rod.summary)
    limits = case.material.limits().as_dict() if case.material is not None else None
    reasons, warnings = judge(walls, extensions, limits)
    reasons += rod.reasons
    thinnest = {kind: min((w for w in walls if w.kind == kind), key=lambda w: w.thickness_mm).as_dict()
                for kind in dict.fromkeys(w.kind for w in walls)}
    summary = {
        "spec": case.actuation.model_dump() if case.actuation is not None else None,
        **rod.summary,
        **filled,
        "layout": layout_document(layout),
        "sections": sections,
        "thinnest": thinnest,
        "walls": [w.as_dict() for w in walls],
        "extensions": extensions,
        "arc_misfit_max_mm": [max(r["arc_misfit_mm"] for r in rows if r["section"] == i + 1)
                              for i in range(layout.sections)],
        "rows": rows,
        "table": TABLE,
        "material": limits,
        "feasible": None if limits is None else not reasons,
        "reasons": reasons if limits is not None else ["no material: in the case file: figures only, not judged"],
        "warnings": warnings + rod.warnings + table_warnings,
        "method": "lengths: Zou et al. on each section's best arc at q (backbone started on the section's base "
                  "frame), or with supply: single the rod model's chamber axis at q P*; pressure_kpa: the rod model "
                  "(softdesign/kinematics/rod.py); extension: the chamber's axis on the body at q over q = 0; walls "
                  "in the sections' normal planes (chamber-skin, feed-skin at every q; between tubes constant over "
                  "q), and at every export q the skin over each tube measured on the mesh (end caps included)",
    }
    summary["verdict_line"] = device_line(summary)
    return ActuationResult(summary, table_text(rows, estimates=simulated is not None), rod.rod_file(rows))


def _per_chamber_rows(kinematics: KinematicsResult, layout: ChamberLayout,
                      grid: list[tuple[float, bool]]) -> list[dict[str, Any]]:
    """Seed 003's lengths on each section's best arc at every q of the grid (q = 0 first: the reference)."""
    rows, reference = _rows_at(kinematics, layout, 0.0, any(q == 0.0 and e for q, e in grid), None)
    for q, export in grid:
        if q != 0.0:
            rows += _rows_at(kinematics, layout, q, export, reference)[0]
    return rows


def write_actuation(result: ActuationResult | None, staging: Staging) -> None:
    """``actuation.csv`` and ``actuation/summary.json`` (nothing without actuation)."""
    if result is None:
        return
    staging.write_bytes(TABLE, result.table.encode("utf-8"))
    staging.write_json(SUMMARY, result.summary)
    if result.rod is not None:
        staging.write_json(ROD_FILE, result.rod)


def load_actuation(build_dir: Path) -> ActuationResult | None:
    """The kept figures and table, or None when the build has no actuation."""
    summary_path = Path(build_dir) / SUMMARY
    if not summary_path.is_file():
        return None
    table = (Path(build_dir) / TABLE).read_text(encoding="utf-8")
    return ActuationResult(json.loads(summary_path.read_text(encoding="utf-8")), table)


def describe_actuation(result: ActuationResult | None) -> list[str]:
    """The thinnest walls and the extension range."""
    if result is None:
        return []
    s = result.summary
    lines = [f"{TABLE}: {len(s['rows'])} rows ({len({r['q'] for r in s['rows']})} q values), arc misfit max "
             + ", ".join(f"{m:.3f}" for m in s["arc_misfit_max_mm"]) + " mm per section"]
    lines += [f"thinnest {kind}: {w['thickness_mm']:.3f} mm at {Wall(**w).place()}"
              for kind, w in s["thinnest"].items()]
    ext = s["extensions"]
    hi, lo = max(ext, key=lambda e: e["max"]), min(ext, key=lambda e: e["min"])
    lines.append(f"chamber extension {lo['min']:.4f} (section {lo['section']} chamber {lo['chamber']}, "
                 f"q={lo['q_min']:.3f}) to {hi['max']:.4f} (section {hi['section']} chamber {hi['chamber']}, "
                 f"q={hi['q_max']:.3f})")
    # the rod model's figures; its verdict (the "device: " line) is in the build's one verdict (the manifest's)
    lines += [line for line in describe_rod(s) if not line.startswith("device: ")]
    return lines


STAGE = Stage(
    name="actuation",
    version=VERSION,
    reads=("actuation", "export.q", "export.frames", "export.offset_mm", "export.spacing_mm", "export.angular_count",
           "material", "blend"),
    upstream=("design", "kinematics", "fit", "simulate"),
    compute=lambda case, results: run_actuation(case, results["kinematics"], results["fit"], results["simulate"],
                                                results["design"]),
    write=write_actuation,
    load=lambda build_dir, results: load_actuation(build_dir),
    describe=describe_actuation,
    metrics=lambda result: {} if result is None else result.summary,
    figures=lambda result: {} if result is None else {TABLE: {"rows": len(result.summary["rows"])}},
    warnings=lambda result: [] if result is None else rule_notices("actuation", result.summary),
    judge=lambda result: None if result is None else actuation_judgement(result.summary),
)
