"""The volume_mesh stage's swept mesher: one mesh in the body's parameter domain, placed at every q, with figures.

``export.volume_mesh.mesher: sweep`` (the default).  The mesh
(:mod:`softdesign.meshing.volume_mesh.sweep_mesh`) is laid out once on the body at q = 0,
its layers from :mod:`softdesign.pipeline.stages.volume_layers` (even, then
graded by the skin's stretch), the section's nodes on the export's angles,
its inside at ``size_mm``; :mod:`softdesign.meshing.volume_mesh.sweep_body` places it at each q.
Checks at each q: every tetrahedron positive (else MeshError naming the
worst one's section, l, angle and depth), the volume within
``VOLUME_RTOL`` of the export's surface mesh at that q, the boundary
watertight.  Figures: round 2's quality figures with the worst element
named, and the 3D strain and stress (:mod:`softdesign.meshing.volume_mesh.sweep_strain`)
at each q and over the morph's q samples
(:func:`softdesign.meshing.body.skin_stretch.morph_samples`), judged against the
material (stretch vs max_stretch, stress vs tensile strength).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from softdesign.config import Case
from softdesign.config import VolumeMesh as VolumeMeshSpec
from softdesign.continuum.kinematic_stress import ElementStrain, RestState, rest_inverses, rest_state, strains
from softdesign.continuum.laws import HyperelasticLaw
from softdesign.errors import MeshError
from softdesign.meshing.body.skin_stretch import morph_samples
from softdesign.meshing.topology import mesh_topology
from softdesign.meshing.volume_mesh.sweep_body import SweepReference, place_mesh, plan_mesh
from softdesign.meshing.volume_mesh.sweep_mesh import SweptMesh
from softdesign.meshing.volume_mesh.sweep_strain import extreme_of, free_directions, skin_stretches, tet_places
from softdesign.meshing.volume_mesh.tet_quality import tet_measures, tet_volumes
from softdesign.meshing.volume_tolerance import VOLUME_RTOL
from softdesign.pipeline.body_spec import body_spec
from softdesign.pipeline.item_progress import item_counter
from softdesign.pipeline.stages.export import solid_at
from softdesign.pipeline.stages.fit import FitResult
from softdesign.pipeline.stages.kinematics import KinematicsResult
from softdesign.pipeline.stages.volume_layers import floor_spacing_mm, sound_layers, swept_layers
from softdesign.types import FloatArray

#: Tetrahedra times q values of the morph's samples in one batch: one task of a worker and one part of the log
#: (its q measured one at a time, about 60 B a tetrahedron in flight: the strain works in chunks); a mesh larger
#: than this is one q a batch.
MORPH_BATCH_VALUES = 2_000_000
#: Tetrahedra times q values of the batches running at once on the morph's worker processes.
MORPH_WORKERS_VALUES = 4_000_000
#: Tetrahedra measured at once by the quality figures (:func:`_measures`).
QUALITY_CHUNK = 16_384


@dataclass(frozen=True)
class SweptBody:
    """The mesh at one q: its nodes, the mesh, and per-tetrahedron figures for the file."""

    q: float
    points: FloatArray
    mesh: SweptMesh
    tet_data: dict[str, FloatArray]


@dataclass(frozen=True)
class Material:
    """What the strain is judged against: the law (or None) and limits (None: not judged)."""

    law: HyperelasticLaw | None
    max_stretch: float | None
    tensile_strength_kpa: float | None
    name: str


Places = tuple[Any, FloatArray, FloatArray, FloatArray]


def _where(places: Places, index: int) -> dict[str, Any]:
    section, l, angle, depth = (p[index] for p in places)
    return {"tet": index, "section": int(section), "l": round(float(l), 5), "angle_rad": round(float(angle), 5),
            "depth": round(float(depth), 4)}


def _measures(points: FloatArray, tets: Any) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Volumes, least and largest dihedral angles (rad) and radius-edge ratios, each (T,), QUALITY_CHUNK
    tetrahedra at a time (:func:`~softdesign.meshing.volume_mesh.tet_quality.tet_measures`: the aorta with chambers'
    three q, 297k tetrahedra, 1.9 -> 0.5 s; the chunks keep its temporaries in the processor's cache)."""
    parts = [tet_measures(points, t) for t in (tets[k:k + QUALITY_CHUNK] for k in range(0, len(tets), QUALITY_CHUNK))]
    volumes, least, largest, ratio = (np.concatenate([p[i] for p in parts]) for i in range(4))
    return volumes, least, largest, ratio


def _quality(points: FloatArray, mesh: SweptMesh, places: Places) -> dict[str, Any]:
    volumes, least, largest, ratio = _measures(points, mesh.tets)
    worst = {"min_volume": int(np.argmin(volumes)), "min_dihedral": int(np.argmin(least)),
             "max_radius_edge": int(np.argmax(ratio))}
    return {"tets": len(mesh.tets), "points": len(points), "volume_mm3": float(volumes.sum()),
            "min_tet_volume_mm3": float(volumes.min()), "min_dihedral_deg": float(np.degrees(least.min())),
            "max_dihedral_deg": float(np.degrees(largest.max())), "max_radius_edge": float(ratio.max()),
            "worst": {k: _where(places, i) for k, i in worst.items()}}


def _check(figures: dict[str, Any], surface_mm3: float, q: float) -> None:
    figures["body_volume_mm3"] = surface_mm3
    figures["volume_rel_error"] = figures["volume_mm3"] / surface_mm3 - 1.0
    figures["volume_rtol"] = VOLUME_RTOL
    problems = []
    if figures["min_tet_volume_mm3"] <= 0:
        w = figures["worst"]["min_volume"]
        problems.append(f"tetrahedron {w['tet']} has volume {figures['min_tet_volume_mm3']:.3g} mm3 (inverted) at "
                        f"section {w['section']}, l={w['l']:.4f}, angle {np.degrees(w['angle_rad']):.0f} deg, "
                        f"depth {w['depth']:.2f}")
    if abs(figures["volume_rel_error"]) > VOLUME_RTOL:
        rel = 100 * figures["volume_rel_error"]
        problems.append(f"the tetrahedra hold {figures['volume_mm3']:.2f} mm3, {rel:+.3f} % of the surface mesh's "
                        f"{surface_mm3:.2f} mm3 (expected within {100 * VOLUME_RTOL:g} %)")
    if problems:
        raise MeshError(f"volume mesh at q={q:.3f}: " + "; ".join(problems) + "; this is a bug in the swept mesher, "
                        "please report it with the case file (or use export.volume_mesh.mesher: ftetwild)")


def _strain_figures(placed: _Placed, moved: FloatArray,
                    strain: ElementStrain) -> tuple[dict[str, Any], dict[str, FloatArray]]:
    """The figures of one exported q (extremes with their places, the skin's stretches) and the file's arrays."""
    places = placed.places
    lam1, lam2 = skin_stretches(placed.mesh, placed.rest, moved)
    most = _morph_figures(strain, places)
    least = extreme_of(-strain.stretches[:, 2], places).as_dict()
    out: dict[str, Any] = {
        "stretch_max": most["stretch_max"], "stretch_min": {**least, "value": -least["value"]},
        "green_strain_max": most["green_strain_max"], "skin_stretch_max": float(lam1.max()),
        "skin_stretch_min": float(lam2.min()), "stress_max_kpa": most["stress_max_kpa"],
    }
    data = {"stretch_max": strain.stretches[:, 0]}  # two arrays only: each adds seconds to an ASCII .vtu
    if strain.stress_max is not None:
        data["stress_max_kpa"] = strain.stress_max
    return out, data


def _morph_figures(strain: ElementStrain, places: Places) -> dict[str, Any]:
    """The largest stretch, Green strain and (with a law) stress of one q, with their places."""
    return {"stretch_max": extreme_of(strain.stretches[:, 0], places).as_dict(),
            "green_strain_max": extreme_of(strain.green_max, places).as_dict(),
            "stress_max_kpa": None if strain.stress_max is None else extreme_of(strain.stress_max, places).as_dict()}


def material_of(case: Case) -> Material:
    """The case's law and limits for the 3D figures (no material: figures only, not judged)."""
    from softdesign.materials.data import law_from, material_presets

    m = case.material
    if m is None:
        return Material(None, None, None, "none")
    limits = m.limits()
    if m.custom is not None:
        c = m.custom
        law = law_from(c.law.kind, c.law.c1_kpa, c.law.c2_kpa, c.law.c3_kpa, c.source)
        return Material(law, limits.max_stretch, 1000.0 * c.tensile_strength_mpa, limits.name)
    if m.name is None:
        return Material(None, limits.max_stretch, None, limits.name)
    preset = material_presets()[m.name]
    return Material(preset.law(), limits.max_stretch, preset.tensile_strength_kpa, limits.name)


def judge(figures: dict[str, Any], material: Material, where: str) -> list[str]:
    """One reason per limit the figures pass (stretch over max_stretch, stress over the tensile strength)."""
    reasons = []

    def place(e: dict[str, Any]) -> str:
        return (f"section {e['section']}, l={e['l']:.4f}, angle {np.degrees(e['angle_rad']):.0f} deg, "
                f"depth {e['depth']:.2f}")

    stretch = figures["stretch_max"]
    if material.max_stretch is not None and stretch["value"] > material.max_stretch:
        reasons.append(f"{where}: 3D stretch {stretch['value']:.4f} > max_stretch {material.max_stretch:g} "
                       f"({material.name}) at {place(stretch)}")
    stress = figures["stress_max_kpa"]
    if stress is not None and material.tensile_strength_kpa is not None and \
            stress["value"] > material.tensile_strength_kpa:
        reasons.append(f"{where}: 3D stress {stress['value']:.1f} kPa > tensile strength "
                       f"{material.tensile_strength_kpa:.1f} kPa ({material.name}) at {place(stress)}")
    return reasons


@dataclass(frozen=True)
class SweepRun:
    """The meshes at the requested q, the figures per q, over the morph, the verdict's reasons, and each part's
    time (``parts``: for the log, never in the summary: a build's outputs are a function of its inputs)."""

    bodies: tuple[SweptBody, ...]
    per_q: list[dict[str, Any]]
    morph: dict[str, Any]
    reasons: list[str]
    parts: list[dict[str, Any]]


@dataclass(frozen=True)
class _Placed:
    """What placing the mesh at a q and measuring it needs."""

    mesh: SweptMesh
    ref: SweepReference
    fit: FitResult
    shape: Any  # BlendedShape
    spec: Any  # BodySpec
    angular_count: int
    rest: FloatArray
    state: RestState
    material: Material
    places: Places

    def at(self, q: float) -> FloatArray:
        if q == 0.0:
            return self.rest
        return place_mesh(self.mesh, self.ref, self.shape.curve_at(q), self.fit.field, q, self.spec,
                          self.angular_count)

    def strain(self, points: FloatArray) -> tuple[dict[str, Any], dict[str, FloatArray]]:
        """The figures and file arrays of the mesh at ``points`` (V, 3)."""
        return _strain_figures(self, points, strains(self.state, points, self.material.law))

    def morph(self, q_values: list[float]) -> list[dict[str, Any]]:
        """The largest stretch, Green strain and stress at each of ``q_values`` (a batch of the morph's samples:
        one q at a time, which the chunked strain does faster than a (Q, V, 3) stack: 0.46 against 0.59 s for
        3 q of the chambered demo)."""
        return [_morph_figures(strains(self.state, self.at(q), self.material.law), self.places) for q in q_values]


def actuation_layout_of(case: Case, kinematics: KinematicsResult) -> Any:
    """Issue 31's chambers and feeds when the case has ``actuation:`` (its stage's own layout), else None.

    Written against issue 31's ``softdesign.pipeline.stages.actuation.actuation_layout``; on a tree without
    it (no actuation key in the case file) there is nothing to conform to.
    """
    if getattr(case, "actuation", None) is None:
        return None
    import importlib

    return importlib.import_module("softdesign.pipeline.stages.actuation").actuation_layout(case, kinematics)


def _plan(case: Case, kinematics: KinematicsResult, fit: FitResult, vm: VolumeMeshSpec,
          surface: dict[float, float] | None = None) -> _Placed:
    """The mesh planned with layers ``size_mm`` apart, closer where that is not sound at an exported q
    (:func:`~softdesign.pipeline.stages.volume_layers.sound_layers`; ``surface``: q -> the surface mesh's mm3)."""
    surface = surface or _surface_mm3(case, kinematics, fit, vm)

    def sound(placed: _Placed) -> bool:
        for q in vm.q:
            volumes = tet_volumes(placed.at(q), placed.mesh.tets)
            if volumes.min() <= 0 or abs(volumes.sum() / surface[q] - 1.0) > 0.5 * VOLUME_RTOL:
                return False
        return True

    return sound_layers(vm.size_mm, floor_spacing_mm(case, fit),
                        lambda spacing: _plan_at(case, kinematics, fit, vm, spacing), sound)


def _surface_mm3(case: Case, kinematics: KinematicsResult, fit: FitResult, vm: VolumeMeshSpec) -> dict[float, float]:
    """q -> the export's surface mesh's volume, mm3, at each exported q."""
    return {q: float(solid_at(kinematics, fit, q, case).figures["volume_mm3"]) for q in vm.q}


def _plan_at(case: Case, kinematics: KinematicsResult, fit: FitResult, vm: VolumeMeshSpec, spacing: float) -> _Placed:
    e, spec, shape = case.export, body_spec(case, fit), kinematics.chain.shape
    layers, even = swept_layers(case, kinematics, fit, vm, spacing)
    layout = actuation_layout_of(case, kinematics)
    mesh, ref = plan_mesh(shape.curve_at(0.0), fit.field, layers, spec, e.angular_count, vm.size_mm, layout,
                          even)
    rest = place_mesh(mesh, ref, shape.curve_at(0.0), fit.field, 0.0, spec, e.angular_count)
    inverses = rest_inverses(rest, mesh.tets)
    state = rest_state(rest, mesh.tets, free_directions(mesh, rest, inverses), inverses)
    return _Placed(mesh, ref, fit, shape, spec, e.angular_count, rest, state, material_of(case),
                   tet_places(mesh, ref, fit.field.link_of))


def morph_batches(samples: list[float], tets: int) -> list[tuple[float, ...]]:
    """The morph's q samples in batches of at most ``MORPH_BATCH_VALUES`` tetrahedra times q (at least one q)."""
    size = max(1, MORPH_BATCH_VALUES // max(1, tets))
    return [tuple(samples[k:k + size]) for k in range(0, len(samples), size)]


def run_sweep(case: Case, kinematics: KinematicsResult, fit: FitResult) -> SweepRun:
    """Plan the mesh at q = 0, place and check it at every q, and measure its strain (module notes)."""
    vm = case.export.volume_mesh or VolumeMeshSpec()
    log: list[dict[str, Any]] = []
    start = time.perf_counter()
    surface = _surface_mm3(case, kinematics, fit, vm)
    placed = _plan(case, kinematics, fit, vm, surface)
    batches = morph_batches([q for q in morph_samples() if q not in vm.q], len(placed.mesh.tets))
    tick = item_counter("volume_mesh", ["plan", *vm.q, *batches], _part_label)
    _tell(tick, "plan", time.perf_counter() - start, log)
    bodies, per_q, reasons = [], [], []
    for q in vm.q:
        start = time.perf_counter()
        points = placed.at(q)
        figures = _quality(points, placed.mesh, placed.places)
        _check(figures, surface[q], q)
        strain, data = placed.strain(points)
        figures.update({"q": q, "size_mm": vm.size_mm, "layers": len(placed.mesh.l),
                        "body_kind": _kind(placed.spec, placed.mesh), "strain": strain,
                        "boundary_watertight": bool(mesh_topology(points, placed.mesh.faces).watertight)})
        reasons += judge(strain, placed.material, f"q={q:.3f}")
        bodies.append(SweptBody(q, points, placed.mesh, data))
        per_q.append(figures)
        _tell(tick, q, time.perf_counter() - start, log)
    morph = _morph(placed, per_q, batches, lambda batch, seconds: _tell(tick, batch, seconds, log))
    if morph["stretch_max"] is not None:
        reasons += judge(morph, placed.material, f"over the morph, at q={morph['stretch_max']['q']:.3f}")
    return SweepRun(tuple(bodies), per_q, morph, reasons, log)


def _kind(spec: Any, mesh: SweptMesh) -> str:
    if spec.wall_mm == 0:
        return "chambered" if mesh.holes else "solid"
    return "ported" if spec.port_mm > 0 else "hollow"


def _part_name(part: Any) -> str:
    """``mesh plan``, ``q=0.500`` or a batch of the morph's samples ``q=0.050..0.950 (18 q)``."""
    if part == "plan":
        return "mesh plan"
    if isinstance(part, (tuple, list)):
        return f"q={part[0]:.3f}" if len(part) == 1 else f"q={part[0]:.3f}..{part[-1]:.3f} ({len(part)} q)"
    return f"q={part:.3f}"


def _part_label(item: Any) -> str:
    part, seconds = item
    return f"{_part_name(part)} ({seconds:.2f} s)"


def _tell(tick: Any, part: Any, seconds: float, log: list[dict[str, Any]]) -> None:
    """Tell the bar (on a terminal) and keep the part's time for the log (the build's printed lines)."""
    log.append({"part": part, "seconds": round(seconds, 3)})
    if tick is not None:
        tick((part, seconds), None)


def _morph(placed: _Placed, per_q: list[dict[str, Any]], batches: list[tuple[float, ...]],
           tell: Any) -> dict[str, Any]:
    """The largest stretch and stress over the exported q and the morph's q samples, with their q."""
    from softdesign.pipeline.parallel import map_items

    def task(batch: tuple[float, ...]) -> tuple[list[dict[str, Any]], float]:
        start = time.perf_counter()
        return placed.morph(list(batch)), time.perf_counter() - start

    # forked workers share the mesh; each holds its batch's arrays (MORPH_BATCH_VALUES, MORPH_WORKERS_VALUES)
    largest = max((len(b) for b in batches), default=1) * max(1, len(placed.mesh.tets))
    done = map_items(task, batches, most=max(1, MORPH_WORKERS_VALUES // largest),
                     on_result=lambda batch, result: tell(batch, result[1]))
    rows = [(row["q"], row["strain"]) for row in per_q] + [
        (q, figures) for batch, (found, _) in zip(batches, done, strict=True)
        for q, figures in zip(batch, found, strict=True)]
    out: dict[str, Any] = {"q_samples": sorted(q for q, _ in rows)}
    for key in ("stretch_max", "green_strain_max", "stress_max_kpa"):
        found = [(q, s[key]) for q, s in rows if s[key] is not None]
        if found:
            q, best = max(found, key=lambda item: item[1]["value"])
            out[key] = {**best, "q": q}
        else:
            out[key] = None
    return out


def _place_text(e: dict[str, Any]) -> str:
    return f"section {e['section']}, l={e['l']:.4f}, angle {np.degrees(e['angle_rad']):.0f} deg, depth {e['depth']:.2f}"


def part_lines(parts: list[dict[str, Any]]) -> list[str]:
    """A line per part of the stage with its time (the mesh plan, each q, each batch of the morph's samples)."""
    return [f"{_part_name(p['part'])}: {p['seconds']:.2f} s" for p in parts]


def describe_sweep(summary: dict[str, Any]) -> list[str]:
    """A line per mesh with its figures and strain, the morph's extremes, the material's limits crossed."""
    lines: list[str] = []
    for f in summary["per_q"]:
        w = f["worst"]["min_dihedral"]
        lines.append(f"q={f['q']:.3f} (.vtu, .msh): {f['tets']} tets, {f['volume_mm3']:.2f} mm3 "
                     f"({100 * f['volume_rel_error']:+.4f} % vs the surface mesh), min volume "
                     f"{f['min_tet_volume_mm3']:.3g} mm3, min dihedral {f['min_dihedral_deg']:.2f} deg "
                     f"(tet {w['tet']}, {_place_text(w)}), max radius-edge {f['max_radius_edge']:.2f}")
        st = f["strain"]
        stress = "" if st["stress_max_kpa"] is None else (f", stress max {st['stress_max_kpa']['value']:.1f} kPa at "
                                                           f"{_place_text(st['stress_max_kpa'])}")
        lines.append(f"  3D stretch max {st['stretch_max']['value']:.4f} at {_place_text(st['stretch_max'])}, min "
                     f"{st['stretch_min']['value']:.4f}{stress}")
    m = summary["morph"]
    if m["stretch_max"] is not None:
        stress = "" if m["stress_max_kpa"] is None else (f", stress max {m['stress_max_kpa']['value']:.1f} kPa at "
                                                         f"q={m['stress_max_kpa']['q']:.3f}")
        lines.append(f"over {len(m['q_samples'])} q: 3D stretch max {m['stretch_max']['value']:.4f} at "
                     f"q={m['stretch_max']['q']:.3f}{stress}")
    material = summary["material"]
    if material is not None:
        lines.append(f"material {material['name']} (max_stretch {material['max_stretch']}, tensile strength "
                     f"{material['tensile_strength_kpa']} kPa): {len(summary['reasons'])} limit(s) crossed in 3D "
                     "(the verdict below)")
    return lines
