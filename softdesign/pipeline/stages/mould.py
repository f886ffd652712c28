"""Stage, mould: a two-part casting mould of the body at q = 0, and a core for a hollow body (issue 16).

Runs only when the case has ``export.mould``; otherwise it writes nothing.
The body, its chamber and its port are the export's own (same grid, offset,
wall and port), at q = 0, the state the actuator is cast in.  Geometry and
checks: :mod:`softdesign.meshing.mould.make`.  Every part is checked again,
as written, by the project's own topology checks (watertight, consistently
wound, one body, Euler 2).  Outputs: ``meshes/mould/{half_a,half_b,core}.stl``
(and every other format of ``export.formats``), ``mould/summary.json``; the
manifest lists each part with sha256, volume and the checks.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from softdesign.config import Case
from softdesign.io.formats import mesh_bytes
from softdesign.meshing.body.sections import body_sections
from softdesign.meshing.checks import Expectation, check_solid
from softdesign.meshing.mould.cores import make_actuated_mould
from softdesign.meshing.mould.make import MouldMesh, make_mould
from softdesign.meshing.mould.parts import MouldSpec
from softdesign.pipeline import layout
from softdesign.pipeline.body_spec import body_spec
from softdesign.pipeline.item_progress import item_counter
from softdesign.pipeline.output_frame import base_pose, moved_points, moved_vectors, output_pose
from softdesign.pipeline.rod_free import body_curve_at
from softdesign.pipeline.stage import Stage
from softdesign.pipeline.stages.actuation import ActuationResult, actuation_layout
from softdesign.pipeline.stages.fit import FitResult
from softdesign.pipeline.stages.judges import mould_judgement
from softdesign.pipeline.stages.kinematics import KinematicsResult
from softdesign.pipeline.store import Staging

VERSION = 4  # 2: export.frame (the parts in the patient's or the base frame); 3: parts welded as float32 writes them;
#            4: supply: single's one lost core, the axis thread's holes


@dataclass(frozen=True)
class MouldResult:
    """The parts (empty after a cached load, or when no mould is asked for) and the figures."""

    parts: tuple[MouldMesh, ...]
    summary: dict[str, Any]


def mould_spec(case: Case) -> MouldSpec | None:
    """The case's ``export.mould`` as a :class:`~softdesign.meshing.mould.parts.MouldSpec`, None when absent."""
    m = case.export.mould
    if m is None:
        return None
    return MouldSpec(margin_mm=m.margin_mm, clearance_mm=m.clearance_mm, key_mm=m.key_mm, pour_mm=m.pour_mm,
                     vent_mm=m.vent_mm, print_mm=m.print_mm, up=m.up)


def axis_thread_mm(case: Case) -> float | None:
    """The axis thread's diameter (mm, the reinforcement's thread) with ``backbone: inextensible``, else None."""
    if case.actuation is None or case.actuation.backbone != "inextensible":
        return None
    from softdesign.materials.threads import thread_presets

    return float(thread_presets()[case.actuation.reinforcement.thread.name].diameter_mm)


def _formats(case: Case) -> list[str]:
    return ["stl", *(f for f in case.export.formats if f != "stl")]


def run_mould(case: Case, kinematics: KinematicsResult, fit: FitResult,
              sized: ActuationResult | None = None) -> MouldResult:
    """The checked mould of the body at q = 0, or nothing when the case asks for none."""
    spec = mould_spec(case)
    if spec is None:
        return MouldResult((), {"requested": False})
    e = case.export
    curve0 = body_curve_at(kinematics, None if sized is None else sized.summary, 0.0)  # backbone: free: rest lengths
    sections = body_sections(curve0, fit.field, 0.0, e.spacing_mm, e.angular_count)
    actuated = actuation_layout(case, kinematics, sized)  # supply: single: the chambers as the rod model sized them
    steps = ("the parts", "their checks")
    tick = item_counter("mould", steps)  # two steps of a bar (the parts take most of the time), when one listens
    if actuated is None:
        mould = make_mould(sections, body_spec(case, fit), spec, fit.field.link_of)
    else:
        mould = make_actuated_mould(sections, body_spec(case, fit), spec, curve0, actuated, fit.field.link_of,
                                    axis_thread_mm(case))
    if tick is not None:
        tick(steps[0], None)
    files: dict[str, Any] = {}
    for part in mould.parts:
        euler = 2 - 2 * mould.figures["parts"][part.name]["genus"]  # the core plate has a hole per core print
        report = check_solid(part.vertices, part.faces, Expectation(euler=euler, bodies=1), label=f"mould {part.name}")
        for fmt in _formats(case):
            files[layout.mould_path(part.name, fmt)] = {
                "part": part.name, "vertices": report.vertices, "faces": report.faces, "volume_mm3": report.volume,
                "area_mm2": report.area, "watertight": report.watertight, "bodies": report.bodies,
                "euler": report.euler}
    if tick is not None:
        tick(steps[1], None)
    pose = output_pose(case.export.frame, base_pose(kinematics.chain.shape))  # checked first, then moved rigidly
    parts = tuple(replace(p, vertices=moved_points(p.vertices, pose)) for p in mould.parts)
    figures = dict(mould.figures)
    if pose is not None and "frame" in figures:  # the parting frame (origin, axes as rows) moves with the parts
        parting = dict(figures["frame"])
        parting["origin"] = moved_points(np.asarray(parting["origin"], float), pose).tolist()
        parting["axes"] = moved_vectors(np.asarray(parting["axes"], float), pose).tolist()
        figures["frame"] = parting
    summary = {"requested": True, "spec": case.export.mould.model_dump(mode="json") if case.export.mould else None,
               "files": files, **figures, "output_frame": case.export.frame}
    return MouldResult(parts, summary)


def write_mould(result: MouldResult, staging: Staging) -> None:
    """Stage every part in every format, and the figures (nothing when no mould was asked for)."""
    if not result.summary["requested"]:
        return
    for name, f in result.summary["files"].items():
        part = next(p for p in result.parts if p.name == f["part"])
        staging.write_bytes(name, mesh_bytes(part.vertices, part.faces, name.rsplit(".", 1)[1]))
    staging.write_json(layout.MOULD_SUMMARY, result.summary)


def load_mould(build_dir: Path) -> MouldResult:
    """The figures of a kept mould (the meshes stay on disk)."""
    path = Path(build_dir) / layout.MOULD_SUMMARY
    if not path.is_file():
        return MouldResult((), {"requested": False})
    return MouldResult((), json.loads(path.read_text(encoding="utf-8")))


def describe_mould(result: MouldResult) -> list[str]:
    """One line per part, the checks, the core's process."""
    s = result.summary
    if not s["requested"]:
        return ["no export.mould in the case file: no mould"]
    lines = []
    for part, f in s["parts"].items():
        lines.append(f"{layout.mould_path(part, 'stl')}: {f['faces']} faces, volume {f['volume_mm3']:.2f} mm3, "
                     f"{f['bodies']} body, genus {f['genus']}")
    cavity = s["cavity"]
    lines.append(f"cavity vs body: {100 * cavity['rel_difference']:.2e} % of {cavity['body_mm3']:.2f} mm3 "
                 f"(within {100 * cavity['tolerance']:g} %); parts disjoint: {s['disjoint']['ok']}")
    pulls = ", ".join(f"{k} along {[round(v, 3) for v in p['pull']]} ({p['faces_checked']} faces, "
                      f"{p['against_pull']} against, {p['blocked_rays']} rays blocked)" for k, p in s["pull"].items())
    lines.append(f"pull: {pulls}")
    if s["core"] is not None:
        lines.append(f"core: {s['core']['process']}: {s['core']['note']}")
    if s.get("thread"):
        lines.append(f"axis thread: {s['thread']['note']}")
    return lines


def output_figures(result: MouldResult) -> dict[str, dict[str, Any]]:
    """Per mould file: its part's counts, volume and checks."""
    s = result.summary
    if not s["requested"]:
        return {}
    checks = {"cavity_ok": s["cavity"]["ok"], "disjoint_ok": s["disjoint"]["ok"]}
    out = {}
    for name, f in s["files"].items():
        pull = s["pull"].get(f["part"])
        out[name] = {**f, **checks, "pull_ok": None if pull is None else pull["ok"]}
    return out


STAGE = Stage(
    name="mould",
    version=VERSION,
    reads=("export.mould", "export.offset_mm", "export.wall_mm", "export.port_mm", "export.spacing_mm",
           "export.angular_count", "export.formats", "export.frame", "actuation"),
    upstream=("kinematics", "fit", "actuation"),
    compute=lambda case, results: run_mould(case, results["kinematics"], results["fit"], results["actuation"]),
    write=write_mould,
    load=lambda build_dir, results: load_mould(build_dir),
    describe=describe_mould,
    metrics=lambda result: {k: v for k, v in result.summary.items() if k != "files"},
    figures=output_figures,
    judge=lambda result: mould_judgement(result.summary),
)
