"""Stage: simulate -- each section's chamber pressures for the requested q, by finite elements (off by default).

With ``simulate: {enabled: true}`` in the case (and ``actuation:``, a
``material:`` with a hyperelastic law), this stage, before actuation:

1. refuses a chamber layout that does not fit (the actuation stage's own check,
   exit 2) and meshes every requested section alone at q = 0
   (:func:`~softdesign.pipeline.simulate_run.section_mesh_of`), each mesh's
   node count checked against :data:`~softdesign.limits.simulate.MAX_SECTION_NODES`
   before any solve;
2. for each section, in a child process with ``simulate.timeout_s`` and the
   solve's memory limit (:func:`~softdesign.pipeline.child.run_in_child`),
   finds at every requested q the three pressures whose deformed section best
   matches the section's designed arc at q (the best arc the actuation table
   gives that section, :data:`~softdesign.pipeline.stages.actuation.ARC_SAMPLES`
   samples), :func:`~softdesign.mechanics.inverse.find_pressures`;
3. keeps every solve's figures (:func:`~softdesign.pipeline.simulate_run.payload`:
   pressures, remaining error, best arc, deformed centerline, largest stretch
   and stress, convergence) in ``simulate/summary.json`` and the manifest.

The actuation stage then adds the pressures to ``actuation.csv`` as model
estimates (:func:`~softdesign.pipeline.simulate_estimates.estimate_cells`).  A solve that fails (a timeout, a Newton
solve that does not converge at the search's start) fails the build with its
message (exit 1); an inverse that stops above its tolerance is kept with its
remaining error and ``converged: false``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softdesign.errors import ConfigError, MeshError, SolveError
from softdesign.pipeline.simulate_estimates import SimulateResult, arc_error_mm
from softdesign.pipeline.stage import Stage
from softdesign.pipeline.stages.judges import simulate_notices
from softdesign.pipeline.store import Staging

if TYPE_CHECKING:
    from softdesign.config import Case
    from softdesign.pipeline.stages.fit import FitResult
    from softdesign.pipeline.stages.kinematics import KinematicsResult

VERSION = 8  # 2: the section meshes three-fold symmetric; 3: the case's hoop thread (reinforcement) in the model;
# 4: the section mesh's polygons (chambers, feeds, skin) have their circles' areas; 5: the thread's stabilised rule
# and patched ends (actuation.reinforcement.ends); 6: the thread's hourglass control a penalty, load steps
# bounded by length; 7: the search starts from the linear answer and stops at its best within the bounds; 8: curved
# chamber walls (mechanics.curved_walls), a step the mixed fibre strain fails retried by the plain method
SUMMARY = "simulate/summary.json"


def _options(case: Case, section: int) -> Any:
    from softdesign.pipeline.simulate_run import SimulateOptions, thread_of

    s = case.simulate
    assert s is not None  # only called when enabled
    return SimulateOptions(section, None, s.q[0], s.size_mm, s.layer_mm, s.angular_count,
                           max_pressure_kpa=s.max_pressure_kpa, max_solves=s.max_solves, timeout_s=s.timeout_s,
                           thread=thread_of(case))


def _sections(case: Case, count: int) -> list[int]:
    """The requested sections, 0 at the base (ConfigError naming the key for one the body has not)."""
    assert case.simulate is not None
    wanted = case.simulate.sections or list(range(1, count + 1))
    beyond = [i for i in wanted if i > count]
    if beyond:
        raise ConfigError(f"simulate.sections: got {beyond}, the body has sections 1 to {count} (links.count); "
                          "name existing sections or leave sections out for all")
    return [i - 1 for i in wanted]


def _meshes(case: Case, kinematics: KinematicsResult, fit: FitResult) -> dict[int, Any]:
    """Every requested section's mesh, the layout checked first and each mesh's size before any solve."""
    from softdesign.pipeline.simulate_run import check_node_count, section_mesh_of
    from softdesign.pipeline.stages.actuation import actuation_layout, check_layout, section_radii, unsized_single

    unsized_single(case, "simulate")
    layout = actuation_layout(case, kinematics)
    if layout is None:
        raise ConfigError("simulate.enabled needs actuation chambers; add an `actuation:` block")
    check_layout(layout, section_radii(fit, layout))
    s = case.simulate
    assert s is not None
    meshes = {}
    for i in _sections(case, layout.sections):
        meshes[i] = section_mesh_of(case, kinematics, fit, i, s.size_mm, s.angular_count, s.layer_mm)
        check_node_count(meshes[i], i + 1, "raise simulate.size_mm or simulate.layer_mm")
    return meshes


def _solve_section(case: Case, kinematics: KinematicsResult, mesh: Any, index: int, law: Any
                   ) -> list[tuple[float, tuple[float, float, float], dict[str, Any]]]:
    """(q, target arc, answer) at every requested q of one section, solved in a child process (SolveError)."""
    from softdesign.kinematics.pcc_fit import fit_links
    from softdesign.limits.simulate import SIMULATE_MEMORY_BYTES
    from softdesign.pipeline.child import HUGE_PAGES, run_in_child
    from softdesign.pipeline.simulate_run import inverses_in_child
    from softdesign.pipeline.stages.actuation import ARC_SAMPLES

    s = case.simulate
    assert s is not None
    targets = []
    for q in s.q:
        arc = fit_links(kinematics.chain, q, ARC_SAMPLES)[index]
        targets.append((q, (arc.kappa, arc.phi, arc.length)))
    what = (f"simulate: the pressure search of section {index + 1} at q = {', '.join(f'{q:g}' for q in s.q)} "
            f"({len(mesh.points)} nodes)")
    fix = "raise simulate.size_mm or simulate.layer_mm, lower simulate.max_pressure_kpa, or raise simulate.timeout_s"
    try:
        answers = run_in_child(inverses_in_child, (mesh, law, _options(case, index), targets), s.timeout_s, what,
                               fix, SIMULATE_MEMORY_BYTES, HUGE_PAGES)
    except MeshError as err:  # the child's failures, a non-converging Newton solve among them
        raise SolveError(str(err)) from err
    return [(q, target, answer) for (q, target), answer in zip(targets, answers, strict=True)]


def run_simulate_stage(case: Case, kinematics: KinematicsResult, fit: FitResult) -> SimulateResult | None:
    """Every requested section's pressures at every requested q; None unless ``simulate.enabled``."""
    from dataclasses import replace

    from softdesign.pipeline.simulate_run import LEAVES_OUT, no_law_error, payload, thread_of
    from softdesign.pipeline.stages.volume_sweep import material_of

    if case.simulate is None or not case.simulate.enabled:
        return None
    if case.actuation is not None and case.actuation.supply == "single":
        return None  # the whole device is solved after its sizing (the device_fe stage), not per section
    material = material_of(case)
    if material.law is None:
        raise no_law_error(case, "simulate.enabled")
    solves = []
    for index, mesh in _meshes(case, kinematics, fit).items():
        for q, target, answer in _solve_section(case, kinematics, mesh, index, material.law):
            figures = payload(replace(_options(case, index), target_q=q), mesh, material, answer, target, 0.0)
            del figures["seconds"]  # the same build gives the same bytes: times go to the manifest's timing
            solves.append({**figures, "section": index + 1, "q": q, "source": source_label(figures)})
    leaves_out = list(LEAVES_OUT if thread_of(case) is None else LEAVES_OUT[1:])  # the thread is in the model
    return SimulateResult({"solves": solves, "leaves_out": leaves_out, "settings": case.simulate.model_dump(),
                           "numbering": "sections from 1 at the base and chambers from 1, as in actuation.csv"})


def source_label(figures: dict[str, Any]) -> str:
    """What an estimate is: the model, the material and the mesh (actuation.csv's ``pressure_source``)."""
    m, mesh = figures["material"], figures["mesh"]
    return (f"model estimate (finite elements, not measured): {m['name']} {m['law']}; section mesh {mesh['nodes']} "
            f"nodes {mesh['tets']} tets, size {mesh['size_mm']:g} mm, layers {mesh['layer_mm']:g} mm, "
            f"{mesh['angular_count']} around; {figures['formulation']}")


def write_simulate(result: SimulateResult | None, staging: Staging) -> None:
    """``simulate/summary.json`` (nothing when the stage is off)."""
    if result is not None:
        staging.write_json(SUMMARY, result.summary)


def load_simulate(build_dir: Path) -> SimulateResult | None:
    """The kept figures, or None when the build has no simulation."""
    path = Path(build_dir) / SUMMARY
    if not path.is_file():
        return None
    return SimulateResult(json.loads(path.read_text(encoding="utf-8")))


def describe_simulate(result: SimulateResult | None) -> list[str]:
    """One line per solve: section, q, pressures, remaining error, largest stress against the tensile strength."""
    if result is None:
        return []
    lines = []
    for solve in result.summary["solves"]:
        strength = solve["tensile_strength_kpa"]
        versus = f" of {strength:.0f} kPa tensile strength" if strength else ""
        status = "" if solve["target"]["converged"] else " (NOT converged: " + solve["target"]["how"] + ")"
        lines.append(f"section {solve['section']} q={solve['q']:g}: pressures "
                     + ", ".join(f"{p:.2f}" for p in solve["pressures_kpa"])
                     + f" kPa, arc error {arc_error_mm(solve):.4f} mm, largest stress "
                     f"{solve['max_stress_kpa']:.1f} kPa{versus}{status}")
    return lines


STAGE = Stage(
    name="simulate",
    version=VERSION,
    reads=("simulate", "actuation", "material"),
    upstream=("kinematics", "fit"),
    compute=lambda case, results: run_simulate_stage(case, results["kinematics"], results["fit"]),
    write=write_simulate,
    load=lambda build_dir, results: load_simulate(build_dir),
    describe=describe_simulate,
    metrics=lambda result: {} if result is None else result.summary,
    warnings=lambda result: simulate_notices(None if result is None else result.summary),
)
