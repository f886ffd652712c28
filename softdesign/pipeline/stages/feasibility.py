"""Stage 7, feasibility: can the body cast at q = 0 stretch into every q, and is its wall thick enough?

Reads the blended shape (kinematics) and the radius field (fit), and the
export keys that shape the solid (offset, wall, port, mesh resolution).
Per export q: the principal stretches of the outer skin (and of the chamber
of a hollow body) against q = 0, converged on a grid
(:mod:`softdesign.meshing.body.skin_stretch`), the largest rho * kappa, the true
wall thickness and the port's wall (:mod:`softdesign.meshing.body.wall`); over
the whole morph q in [0, 1], the extremes of the skin's stretches by a
search in q.  Judged against ``material:`` when the case has one
(:mod:`softdesign.materials`); without it ``feasible`` is null.
Output: ``feasibility/summary.json``; the manifest's ``metrics.feasibility``.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, cast

import numpy as np

from softdesign.config import Case
from softdesign.fitting.radius_field import RadiusField, known_fold_margin
from softdesign.fitting.strain import skin_metric
from softdesign.geometry.blend import BlendedShape
from softdesign.meshing.body.skin_stretch import (
    Q_SAMPLES,
    Q_XTOL,
    START_ANGLES_PER_INTERVAL,
    START_SPACING_MM,
    STRETCH_TOL,
    MetricAt,
    MorphExtreme,
    StretchExtremes,
    converged_extremes,
    extremes_on,
    make_grid,
    morph_samples,
    search_morph,
)
from softdesign.meshing.body.wall import FD_STEP_MM, offset_metric, port_wall_mm, thinnest, wall_map
from softdesign.meshing.tessellate import ring_points
from softdesign.meshing.volume import BodySpec
from softdesign.pipeline.body_spec import body_spec
from softdesign.pipeline.bounds import meshes_at_once
from softdesign.pipeline.feasibility_judge import judge, warnings_of
from softdesign.pipeline.item_progress import item_counter
from softdesign.pipeline.parallel import map_items
from softdesign.pipeline.stage import Stage
from softdesign.pipeline.stages.fit import FitResult
from softdesign.pipeline.stages.judges import material_judgement, rule_notices
from softdesign.pipeline.stages.kinematics import KinematicsResult
from softdesign.pipeline.store import Staging
from softdesign.types import FramedCurve

VERSION = 3  # 2: places in mm from the base (arc_mm), one reason per cause (causes); 3: min_stretch a warning
SUMMARY = "feasibility/summary.json"
#: Memory for the rest state's metrics a body keeps (:meth:`_Body.rest`), bytes: the finest grid's
#: (E, F, G) of the 1M-triangle benchmark case is 18 MB (729,600 points), and every q asks for the same grids.
REST_CACHE_BYTES = 64 * 2**20


@dataclass(frozen=True)
class FeasibilityResult:
    """The figures (JSON-ready) and the violations, one line each."""

    summary: dict[str, Any]


@dataclass(frozen=True)
class _Body:
    """What every evaluation needs: the shape, the field, the solid's spec, the frames mode."""

    shape: BlendedShape
    field: RadiusField
    spec: BodySpec
    frames: str
    #: the rest state's metrics by (offset, grid), least recently used first; per process (a worker fills its own)
    _rest: dict[tuple[float, bytes, bytes], np.ndarray] = dataclasses.field(
        default_factory=dict, compare=False, repr=False)
    #: the outer skin's (no offset) extremes on the first grid by q, from the morph search (:func:`_morph_search`);
    #: filled before the per-q work forks, so its workers start their grids from them
    _first: dict[float, StretchExtremes] = dataclasses.field(default_factory=dict, compare=False, repr=False)

    @property
    def length(self) -> float:
        return float(self.shape.keys[-1].length)

    def surface(self, q: float, offset_mm: float) -> MetricAt:
        curve = self.shape.curve_at(q)
        if offset_mm == 0.0:
            return lambda l, a: skin_metric(curve, self.field, q, l, a, self.frames)
        return lambda l, a: offset_metric(curve, self.field, q, l, len(a), offset_mm, self.frames)

    def rest(self, offset_mm: float) -> MetricAt:
        """``surface(0.0, offset_mm)``, each grid's metric computed once: the rest state is the same for every q.

        The same numbers as computing it afresh (the same call on the same grid); read-only.
        """
        at = self.surface(0.0, offset_mm)

        def cached(l: np.ndarray, a: np.ndarray) -> np.ndarray:
            key = (offset_mm, np.ascontiguousarray(l, float).tobytes(), np.ascontiguousarray(a, float).tobytes())
            metric = self._rest.pop(key, None)  # put back last: the dict runs from least to most recently used
            if metric is None:
                metric = at(l, a)
                metric.setflags(write=False)
            self._rest[key] = metric
            while len(self._rest) > 1 and sum(m.nbytes for m in self._rest.values()) > REST_CACHE_BYTES:
                self._rest.pop(next(iter(self._rest)))
            return metric

        return cached

    def span(self, q: float, margin_mm: float) -> tuple[float, float]:
        """The l range at least ``margin_mm`` of arc from both ends at q = 0 and at q."""
        lo, hi = 0.0, 1.0
        for at in (0.0, q):
            curve = self.shape.curve_at(at).curve
            l = curve.dense_l()
            s = curve.arc_length(l)
            lo = max(lo, float(np.interp(margin_mm, s, l)))
            hi = min(hi, float(np.interp(s[-1] - margin_mm, s, l)))
        return lo, hi


def _extremes(body: _Body, q: float, offset_mm: float, span: tuple[float, float]) -> StretchExtremes:
    first = body._first.get(q) if offset_mm == 0.0 else None  # the same metrics; used when on the same grid
    rest = body.rest(offset_mm)
    deformed = rest if q == 0.0 else body.surface(q, offset_mm)  # at q = 0 the same call on the same grids
    return converged_extremes(rest, deformed, body.length, body.field.breaks, body.field.final[0].angular_intervals,
                              span, first=first)


def _where(e) -> dict[str, Any]:
    return e.as_dict()


def _wall(body: _Body, q: float, spacing_mm: float, angular_count: int) -> dict[str, Any]:
    """True wall thickness chamber -> outer surface at q, per link, and the port's wall."""
    walls = wall_map(body.shape.curve_at(q), body.field, q, body.spec, spacing_mm, angular_count)
    distances, angles, outer = walls.thickness_mm, walls.a, walls.outer
    owner = body.field.link_of(walls.l)
    spot = thinnest(distances, walls.l, angles)
    per_link = [thinnest(distances, walls.l, angles, owner == j).thickness_mm if np.any(owner == j) else None
                for j in range(len(body.field.final))]
    out: dict[str, Any] = {
        "wall_min_mm": spot.thickness_mm,
        "where": {"link": int(body.field.link_of([spot.l])[0]), "l": spot.l, "angle_deg": float(np.degrees(spot.a))},
        "per_link_mm": per_link,
    }
    if body.spec.port_mm > 0:
        port = port_wall_mm(ring_points(outer), outer.centers[0], outer.frames[0][:, 2], body.spec.port_mm,
                            body.spec.wall_mm)
        out["port_wall_mm"] = port.thickness_mm
        out["port_where"] = {"l": float(outer.l[int(port.l)]), "angle_deg": float(np.degrees(angles[int(port.a)]))}
    return out


def _at_q(body: _Body, q: float, case: Case) -> dict[str, Any]:
    skin = _extremes(body, q, body.spec.offset_mm, (0.0, 1.0) if body.spec.offset_mm == 0 else
                     body.span(q, 2 * FD_STEP_MM))
    row: dict[str, Any] = {
        "q": q,
        "stretch_max": skin.maximum.value,
        "stretch_min": skin.minimum.value,
        "wall_min_mm": None,
        "rho_kappa_max": known_fold_margin(cast(FramedCurve, body.shape.curve_at(q)), body.field, q).max_rho_kappa,
        "where": {"stretch_max": _where(skin.maximum), "stretch_min": _where(skin.minimum)},
        "per_link": [{"stretch_max": hi, "stretch_min": lo} for hi, lo in skin.per_link],
        "grid": {"spacing_mm": skin.grid.spacing_mm, "angles": skin.grid.angles, "points": skin.grid.points,
                 "change": skin.change, "converged": skin.converged},
    }
    if body.spec.wall_mm > 0:
        span = body.span(q, body.spec.wall_mm + 2 * FD_STEP_MM)
        chamber = _extremes(body, q, body.spec.offset_mm - body.spec.wall_mm, span)
        row["chamber"] = {"stretch_max": chamber.maximum.value, "stretch_min": chamber.minimum.value,
                          "where": {"stretch_max": _where(chamber.maximum), "stretch_min": _where(chamber.minimum)}}
        wall = _wall(body, q, case.export.spacing_mm, case.export.angular_count)
        row["wall_min_mm"] = wall.pop("wall_min_mm")
        row["where"]["wall_min"] = wall.pop("where")
        row.update(wall)
        for j, mm in enumerate(row.pop("per_link_mm")):
            row["per_link"][j]["wall_min_mm"] = mm
    return row


def _morph_samples(body: _Body, most: int | None) -> Callable[[float], StretchExtremes]:
    """The outer skin's extremes on the first grid at the morph search's samples, on the build's workers; returns
    the search's ``at(q)``, which reads them and computes any other q (the bounded search's) on that grid.

    Every q's extremes stay in ``body._first``: the converged extremes of the outer skin at a q sampled here
    start from them (:func:`_extremes`); the per-q work forks after this, so its workers find them too.
    """
    g = make_grid(body.length, body.field.breaks, START_SPACING_MM,
                  START_ANGLES_PER_INTERVAL * body.field.final[0].angular_intervals)
    rest = body.rest(0.0)
    rest(g.l, g.a)  # once, before the workers start: they inherit it

    def on_grid(q: float) -> StretchExtremes:
        return extremes_on(g, rest, body.surface(q, 0.0), body.field.breaks)

    samples = morph_samples()
    cache = body._first
    cache.update(zip(samples, map_items(on_grid, samples, most=most), strict=True))

    def at(q: float) -> StretchExtremes:
        if q not in cache:
            cache[q] = on_grid(q)
        return cache[q]

    return at


def _morph_search(body: _Body, at: Callable[[float], StretchExtremes]
                  ) -> tuple[tuple[MorphExtreme, MorphExtreme], tuple[StretchExtremes, StretchExtremes]]:
    """Where over q in [0, 1] the skin's stretches are extreme (the bounded search on the first grid, from the
    samples ``at`` holds), and the converged extremes of the outer skin without offset at the two q found.

    One task of the per-q work (:func:`run_feasibility`): the search asks for one q at a time, so it runs on one
    worker while the others make the export q's figures; the two converged polishes follow it there, where the
    search's first grids at their q are kept.
    """
    found = search_morph(at)
    return found, (_extremes(body, found[0].q, 0.0, (0.0, 1.0)), _extremes(body, found[1].q, 0.0, (0.0, 1.0)))


def _morph(found: tuple[MorphExtreme, MorphExtreme], polished: tuple[StretchExtremes, StretchExtremes]
           ) -> dict[str, Any]:
    """Extremes of the skin's stretches over q in [0, 1]: the q found by the search, the value on a converged grid.

    ``polished`` holds the converged extremes of the outer skin without offset at each q found.
    """
    out: dict[str, Any] = {}
    for key, hit, at in zip(("stretch_max", "stretch_min"), found, polished, strict=True):
        e = at.maximum if key == "stretch_max" else at.minimum
        out[key] = {"value": e.value, "q": hit.q, "where": _where(e)}
    out["method"] = (f"{Q_SAMPLES} q samples, then a bounded search to {Q_XTOL:g} in q near the best, on the first "
                     "grid; the value at the q found on a converged grid; the outer skin without offset")
    return out


def run_feasibility(case: Case, kinematics: KinematicsResult, fit: FitResult) -> FeasibilityResult:
    """Every figure, then the verdict against the case's material (if any)."""
    body = _Body(kinematics.chain.shape, fit.field, body_spec(case), case.frames)
    most = meshes_at_once(case, max(key.length for key in body.shape.keys))  # a wall map is one mesh's rings
    at = _morph_samples(body, most)
    # the morph's bounded search and its polishes first, on one worker, beside the export q's figures
    work: list[tuple[str, float]] = [("morph", math.nan)] + [("q", q) for q in case.export.q_values()]

    def task(item: tuple[str, float]) -> Any:
        kind, q = item
        return _at_q(body, q, case) if kind == "q" else _morph_search(body, at)

    counted = item_counter("feasibility", work, lambda item: "skin over the morph" if item[0] == "morph" else
                           f"skin at q = {item[1]:.3g}")  # a bar, when one listens
    done = map_items(task, work, most=most, on_result=counted)
    (found, polished), rows = done[0], done[1:]
    per_link = []
    for j in range(len(fit.field.final)):
        links = [r["per_link"][j] for r in rows]
        walls = [p["wall_min_mm"] for p in links if p.get("wall_min_mm") is not None]
        per_link.append({"link": j, "stretch_max": max(p["stretch_max"] for p in links),
                         "stretch_min": min(p["stretch_min"] for p in links),
                         "wall_min_mm": min(walls) if walls else None})
    limits = case.material.limits().as_dict() if case.material is not None else None
    summary: dict[str, Any] = {
        "per_q": rows,
        "per_link": per_link,
        "morph": _morph(found, polished),
        "material": limits,
        "tolerance": {"stretch": STRETCH_TOL, "q": Q_XTOL},
    }
    _place_in_mm(body, summary)
    feasible, reasons, causes = judge(summary, limits)
    summary["feasible"] = feasible
    summary["reasons"] = reasons if limits is not None else ["no material: in the case file: figures only, not judged"]
    summary["causes"] = causes
    summary["warnings"] = warnings_of(causes)
    return FeasibilityResult(summary)


def _place_in_mm(body: _Body, summary: dict[str, Any]) -> None:
    """Add ``arc_mm`` (mm from the base along the body at that q) to every place of ``summary`` that has an l."""
    def add(where: dict[str, Any], q: float) -> None:
        if "l" in where:
            where["arc_mm"] = float(body.shape.curve_at(q).curve.arc_length(np.array([where["l"]], float))[0])

    for row in summary["per_q"]:
        for where in row["where"].values():
            add(where, row["q"])
        if row.get("port_where"):
            add(row["port_where"], row["q"])
    for key in ("stretch_max", "stretch_min"):
        add(summary["morph"][key]["where"], summary["morph"][key]["q"])


def write_feasibility(result: FeasibilityResult, staging: Staging) -> None:
    """Keep the figures."""
    staging.write_json(SUMMARY, result.summary)


def load_feasibility(build_dir: Path) -> FeasibilityResult:
    """The kept figures."""
    return FeasibilityResult(json.loads((Path(build_dir) / SUMMARY).read_text(encoding="utf-8")))


def describe_feasibility(result: FeasibilityResult) -> list[str]:
    """The feasibility table and the material's limits; the verdict is the build's one (the manifest's)."""
    s = result.summary
    lines = ["     q  stretch_max  stretch_min  rho*kappa  wall_min_mm  port_wall_mm"]
    for r in s["per_q"]:
        wall = "-" if r["wall_min_mm"] is None else f"{r['wall_min_mm']:.3f}"
        port = "-" if r.get("port_wall_mm") is None else f"{r['port_wall_mm']:.3f}"
        lines.append(f"{r['q']:6.3f}  {r['stretch_max']:11.4f}  {r['stretch_min']:11.4f}  {r['rho_kappa_max']:9.3f}  "
                     f"{wall:>11}  {port:>12}")
    m = s["morph"]
    lines.append(f"over q in [0, 1]: stretch max {m['stretch_max']['value']:.4f} at q={m['stretch_max']['q']:.3f}, "
                 f"min {m['stretch_min']['value']:.4f} at q={m['stretch_min']['q']:.3f}")
    material = s["material"]
    if material is None:
        lines.append("material: none given, not judged (add material: to the case file)")
        return lines
    limits = ", ".join(f"{k} {material[k]:g}" for k in ("max_stretch", "min_stretch", "min_wall_mm")
                       if material[k] is not None)
    lines.append(f"material {material['name']} ({limits}): {len(s['reasons'])} limit(s) crossed (the verdict below)")
    return lines


def feasibility_metrics(result: FeasibilityResult) -> dict[str, Any]:
    """The manifest's block: every figure and the verdict."""
    return result.summary


STAGE = Stage(
    name="feasibility",
    version=VERSION,
    reads=("export.q", "export.frames", "export.offset_mm", "export.wall_mm", "export.port_mm", "export.spacing_mm",
           "export.angular_count", "frames", "material"),
    upstream=("kinematics", "fit"),
    compute=lambda case, results: run_feasibility(case, results["kinematics"], results["fit"]),
    write=write_feasibility,
    load=lambda build_dir, results: load_feasibility(build_dir),
    describe=describe_feasibility,
    metrics=feasibility_metrics,
    warnings=lambda result: rule_notices("feasibility", result.summary),
    judge=lambda result: material_judgement(result.summary),
)
