"""One section of a chambered body solved under chamber pressures, or for a designed arc: the pieces that
``softdesign simulate`` (:mod:`softdesign.pipeline.simulate_command`) and the build's simulate stage share.

The section's mesh is made (:mod:`softdesign.mechanics.layout_section`) and
checked against the bounds of :mod:`softdesign.limits.simulate` before any
solve; the solve runs in a child process with a time and memory limit
(:func:`~softdesign.pipeline.child.run_in_child`), so a runaway factorization
fails cleanly; :func:`payload` gives its figures as JSON.
"""

from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from softdesign.errors import ConfigError
from softdesign.limits.simulate import (
    MAX_ANGULAR_COUNT,
    MAX_INVERSE_SOLVES,
    MAX_LOAD_STEPS,
    MAX_NEWTON_ITERATIONS,
    MAX_PRESSURE_KPA,
    MAX_SECTION_NODES,
    MAX_SIMULATE_SECONDS,
    MIN_ANGULAR_COUNT,
    MIN_SIZE_MM,
)

#: What the model leaves out, stated with every answer.
LEAVES_OUT = (
    "fibre reinforcement (an unreinforced chamber balloons rather than lengthens)",
    "contact with the vessel wall",
    "viscoelasticity (the answer is the static, long-time equilibrium)",
    "the Mullins effect (softening after the first loading)",
    "the feed lines through the section (meshed solid) and the body's slanted end cuts",
    "the neighbouring sections (the section's base is clamped, its tip free)",
)
#: Samples of the designed link's backbone for its best arc.
ARC_SAMPLES = 65
#: Bounds of a --target-arc: a bend radius of at least 0.1 mm (1/mm), and a length (mm).
MAX_TARGET_KAPPA = 10.0
MAX_TARGET_LENGTH_MM = 10_000.0


@dataclass(frozen=True)
class SimulateOptions:
    """The command's choices (kPa, mm, s), each checked by :func:`check_options` before work."""

    #: the section, 0 at the base (the command line and every output number sections from 1)
    section: int
    pressures_kpa: tuple[float, ...] | None
    target_q: float | None
    size_mm: float = 3.0
    layer_mm: float = 8.0
    angular_count: int = 12
    load_steps: int = 2
    max_iterations: int = 12
    max_pressure_kpa: float = 100.0
    max_solves: int = 16
    timeout_s: float = 600.0
    #: the inverse stops after the trial that passes this many seconds, keeping its best (None: no limit)
    time_limit_s: float | None = None
    #: a context manager yielding the inverse's trial listener (the command line's progress), or None
    trial_progress: Any = None
    #: the chambers' hoop thread (:class:`softdesign.mechanics.reinforcement.HoopThread`), or None: unreinforced
    thread: Any = None
    #: the pressures of the feeds that cross the section (meshed as cavities), kPa; None: the feeds meshed solid
    feed_pressures_kpa: tuple[float, ...] | None = None
    #: the arc (kappa 1/mm, phi rad, L mm) to search the pressures for, instead of the design's at ``target_q``
    target_arc: tuple[float, float, float] | None = None


def thread_of(case: Any) -> Any:
    """The case's hoop thread as the finite elements take it (:class:`~softdesign.mechanics.reinforcement.HoopThread`:
    ``actuation.reinforcement``'s pitch, its thread's diameter and modulus), or None: no chambers, or
    ``reinforcement.kind: none`` (bare chambers, which balloon)."""
    actuation = getattr(case, "actuation", None)
    if actuation is None or actuation.reinforcement.kind != "hoop":
        return None
    return reinforcement_thread(actuation.reinforcement)


def reinforcement_thread(reinforcement: Any) -> Any:
    """``actuation.reinforcement``'s thread as the finite elements take it (a
    :class:`~softdesign.mechanics.reinforcement.HoopThread`): its pitch, the preset's diameter and modulus, its
    chambers' ends; the same thread for the winding and the backbone."""
    from softdesign.materials.threads import thread_presets
    from softdesign.mechanics.reinforcement import HoopThread

    data = thread_presets()[reinforcement.thread.name]
    return HoopThread(reinforcement.pitch_mm, data.diameter_mm, data.modulus_gpa * 1.0e6,
                      patched_ends=reinforcement.ends == "patch")


def no_law_error(case: Any, where: str) -> ConfigError:
    """The refusal of a simulate whose case has no hyperelastic law, naming the key to change and the presets to use.

    ``where`` starts the message (the case file for the command, ``simulate.enabled`` for the build's stage).
    """
    from softdesign.materials.data import material_presets

    with_law = ", ".join(name for name, preset in material_presets().items() if preset.law_params is not None)
    fix = f"give material.name one of the presets with a law ({with_law}), or material.custom with its law"
    name = getattr(case.material, "name", None)
    if name is not None:
        return ConfigError(f"{where}: material.name {name}: this preset has no hyperelastic law in "
                           f"softdesign/data/materials.yaml, which simulate needs; {fix}")
    return ConfigError(f"{where}: simulate needs a material with a hyperelastic law, and the case gives none; {fix}")


def check_options(o: SimulateOptions) -> None:
    """Refuse options outside the bounds (ConfigError: the option, the value, the bound, the fix)."""
    def bound(name: str, value: float, low: float, high: float) -> None:
        if not (math.isfinite(value) and low <= value <= high):
            raise ConfigError(f"simulate {name}: got {value:g}, expected a number in [{low:g}, {high:g}] "
                              "(softdesign/limits/simulate.py)")
    if sum(given is not None for given in (o.pressures_kpa, o.target_q, o.target_arc)) != 1:
        raise ConfigError("simulate: give one of --pressures P1,P2,P3 (kPa), --target q or --target-arc KAPPA,PHI,L "
                          "(not several, not none)")
    for k, p in enumerate(o.pressures_kpa or ()):
        bound(f"--pressures value {k + 1}", p, 0.0, MAX_PRESSURE_KPA)
    for k, p in enumerate(o.feed_pressures_kpa or ()):
        bound(f"--feed-pressures value {k + 1}", p, 0.0, MAX_PRESSURE_KPA)
    if o.feed_pressures_kpa is not None and o.pressures_kpa is None:
        raise ConfigError("simulate --feed-pressures: goes with --pressures (a forward solve); --target searches the "
                          "chambers' pressures with the feeds meshed solid")
    if o.target_q is not None:
        bound("--target", o.target_q, 0.0, 1.0)
    if o.target_arc is not None:
        bound("--target-arc curvature (1/mm)", o.target_arc[0], 0.0, MAX_TARGET_KAPPA)
        bound("--target-arc length (mm)", o.target_arc[2], MIN_SIZE_MM, MAX_TARGET_LENGTH_MM)
    bound("--size-mm", o.size_mm, MIN_SIZE_MM, 100.0)
    bound("--layer-mm", o.layer_mm, MIN_SIZE_MM, 100.0)
    bound("--angular-count", o.angular_count, MIN_ANGULAR_COUNT, MAX_ANGULAR_COUNT)
    bound("--load-steps", o.load_steps, 1, MAX_LOAD_STEPS)
    bound("--max-iterations", o.max_iterations, 1, MAX_NEWTON_ITERATIONS)
    bound("--max-pressure", o.max_pressure_kpa, 1.0, MAX_PRESSURE_KPA)
    bound("--max-solves", o.max_solves, 1, MAX_INVERSE_SOLVES)
    bound("--timeout", o.timeout_s, 1.0, MAX_SIMULATE_SECONDS)
    if o.time_limit_s is not None:
        bound("--time-limit", o.time_limit_s, 1.0, MAX_SIMULATE_SECONDS)
        if o.time_limit_s >= o.timeout_s:
            raise ConfigError(f"simulate --time-limit: got {o.time_limit_s:g} s, not below --timeout "
                              f"{o.timeout_s:g} s (the solve is stopped at the timeout); raise --timeout above it")


def solve_in_child(section: Any, law: Any, o: SimulateOptions, target: tuple[float, float, float] | None
                   ) -> dict[str, Any]:
    """The worker (module-level: pickled by name): the forward solve, or the inverse for ``target``."""
    from softdesign.mechanics.inverse import InverseSettings, find_pressures
    from softdesign.mechanics.newton import NewtonSettings
    from softdesign.mechanics.section import simulate_section

    newton = NewtonSettings(load_steps=o.load_steps, max_iterations=o.max_iterations)
    if target is None:
        feeds = None if o.feed_pressures_kpa is None else np.array(o.feed_pressures_kpa, float)
        result = simulate_section(section, law, np.array(o.pressures_kpa, float), newton, o.thread, feeds)
        return {"result": result, "inverse": None}
    # the search starts from the linear answer (the rest shape's sensitivity, bounded least squares): from 10 % of
    # the bound in every chamber, its first trial took 38 factorizations of 84 on the demo's section 1 at q = 1
    settings = InverseSettings(o.max_pressure_kpa, None, 0.25 * o.max_pressure_kpa,
                               tolerance_mm=1e-3, max_iterations=o.max_solves, time_limit_s=o.time_limit_s)
    with o.trial_progress or contextlib.nullcontext() as on_trial:
        found = find_pressures(section, law, target, settings, newton, on_trial, o.thread)
    return {"result": found.section, "inverse": found}


def inverses_in_child(section: Any, law: Any, o: SimulateOptions,
                      targets: list[tuple[float, tuple[float, float, float]]]) -> list[dict[str, Any]]:
    """The worker of the build's simulate stage: :func:`solve_in_child`'s inverse for each (q, target arc)."""
    return [solve_in_child(section, law, replace(o, target_q=q), target) for q, target in targets]


def section_mesh_of(case: Any, kinematics: Any, fit: Any, section: int, size_mm: float, angular_count: int,
                    layer_mm: float, feed_count: int | None = None) -> Any:
    """Section ``section``'s (0 at the base) mesh at q = 0 (ConfigError without chambers or for a bad index).

    ``feed_count``: the feeds that cross the section are meshed as cavities, and there must be that many
    (``--feed-pressures``' values; ConfigError naming the count, before the mesh); None: meshed solid.
    """
    from softdesign.mechanics.layout_section import layout_section_mesh
    from softdesign.pipeline.body_spec import body_spec
    from softdesign.pipeline.stages.actuation import actuation_layout, unsized_single

    unsized_single(case, "simulate")
    layout = actuation_layout(case, kinematics)
    if layout is None:
        raise ConfigError("simulate: the case has no actuation chambers; add an `actuation:` block")
    if not 0 <= section < layout.sections:
        raise ConfigError(f"simulate --section: got {section + 1}, the body has sections 1 to {layout.sections} "
                          "(numbered from 1 at the base)")
    if feed_count is not None and feed_count != len(layout.feeds_through(section)):
        raise ConfigError(f"simulate --feed-pressures: got {feed_count} values, section {section + 1} has "
                          f"{len(layout.feeds_through(section))} feeds of distal chambers crossing it; give one "
                          "pressure (kPa) per feed, in the order of actuation.csv's distal chambers")
    curve0 = kinematics.chain.shape.curve_at(0.0)
    return layout_section_mesh(curve0, fit.field, body_spec(case), layout, section, size_mm, angular_count, layer_mm,
                               feeds=feed_count is not None)


def check_node_count(section: Any, index: int, fix: str) -> None:
    """Refuse (ConfigError) a section mesh beyond MAX_SECTION_NODES, before its solve."""
    nodes = quadratic_node_count(section)
    if nodes > MAX_SECTION_NODES:
        raise ConfigError(f"simulate: section {index}'s mesh has {nodes} nodes (quadratic elements), more than "
                          f"{MAX_SECTION_NODES} (softdesign/limits/simulate.py); {fix}")


def quadratic_node_count(section: Any) -> int:
    """Nodes of the section's quadratic mesh: its corners and one per edge."""
    from softdesign.mechanics.quadratic import edge_midpoints

    tets = np.asarray(section.tets, np.int64)
    return len(section.points) + len(edge_midpoints(tets, len(section.points))[0])


def payload(o: SimulateOptions, section: Any, material: Any, answer: dict[str, Any],
            target: tuple[float, float, float] | None, seconds: float) -> dict[str, Any]:
    """The JSON-ready figures of a solve."""
    r, inverse = answer["result"], answer["inverse"]
    out: dict[str, Any] = {
        "section": o.section + 1,
        "material": {"name": material.name, "law": material.law.kind, "c1_kpa": material.law.c1,
                     "c2_kpa": material.law.c2, "c3_kpa": material.law.c3, "bulk_kpa": material.law.bulk_kpa,
                     "source": material.law.source},
        "formulation": ("quadratic (10-node) tetrahedra, mean dilatation per element (near-incompressible), "
                        "follower pressure on 6-node faces"
                        + (", volume continuation" if o.thread is None else
                           f", load steps, hoop thread on the chamber walls (pitch {o.thread.pitch_mm:g} mm, "
                           f"diameter {o.thread.diameter_mm:g} mm, modulus {o.thread.modulus_kpa:g} kPa)")),
        "mesh": {"nodes": len(section.points), "tets": len(section.tets),
                 "quadratic_nodes": quadratic_node_count(section), "size_mm": o.size_mm,
                 "layer_mm": o.layer_mm, "angular_count": o.angular_count},
        "pressures_kpa": [round(float(p), 6) for p in r.pressures_kpa],
        **({} if o.feed_pressures_kpa is None else {"feed_pressures_kpa": [float(p) for p in o.feed_pressures_kpa]}),
        "arc": {"kappa_per_mm": r.kappa, "phi_rad": r.phi, "length_mm": r.length,
                "misfit_max_mm": r.arc_max_mm, "misfit_rms_mm": r.arc_rms_mm},
        "chamber_lengths_mm": [float(v) for v in r.chamber_lengths],
        "rest_chamber_lengths_mm": [float(v) for v in r.rest_chamber_lengths],
        "max_stretch": r.max_stretch,
        "max_stress_kpa": r.max_stress_kpa,
        "tensile_strength_kpa": material.tensile_strength_kpa,
        "convergence": [{"load_factor": t, "iterations": n, "residuals_mN": h}
                        for t, n, h in zip(r.record.load_factors, r.record.iterations, r.record.residuals,
                                           strict=True)],
        "deformed_centerline_mm": np.round(r.centerline, 6).tolist(),
        "leaves_out": [("the body's slanted end cuts" if item.startswith("the feed lines") and o.feed_pressures_kpa
                        is not None else item) for item in (LEAVES_OUT if o.thread is None else LEAVES_OUT[1:])],
        "seconds": round(seconds, 2),
    }
    if target is not None and inverse is not None:
        out["target"] = {"q": o.target_q, "kappa_per_mm": target[0], "phi_rad": target[1], "length_mm": target[2],
                         "weighting": "error mm = [L/2 dtheta_x, L/2 dtheta_y, dL] (tip displacement, first order)",
                         "error_mm": [float(v) for v in inverse.error_mm], "converged": inverse.converged,
                         "best_within_bounds": inverse.best_within_bounds, "how": inverse.stopped_because,
                         "forward_solves": inverse.iterations}
    return out
