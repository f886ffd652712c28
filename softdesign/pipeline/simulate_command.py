"""``softdesign simulate``'s two runs: a solve of one section printed (:func:`run_simulate`), or the pressures for a
q written into the build's actuation.csv through the simulate stage (:func:`write_to_table`).

They build through the actuation stage (cached) and so sit above the pipeline's stages; the pieces they share with
the simulate stage (the options and their bounds, the section's mesh, the child's solves, the figures) are in
:mod:`softdesign.pipeline.simulate_run`.
"""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path
from typing import Any

from softdesign.errors import ConfigError, MeshError, SolveError
from softdesign.limits.simulate import SIMULATE_MEMORY_BYTES
from softdesign.pipeline.simulate_run import (
    ARC_SAMPLES,
    SimulateOptions,
    check_node_count,
    check_options,
    no_law_error,
    payload,
    section_mesh_of,
    solve_in_child,
    thread_of,
)


def run_simulate(case_file: Path, out: Path | None, o: SimulateOptions, progress: Any) -> dict[str, Any]:
    """Build through actuation, mesh the section, solve it in a child process; the figures as a dict."""
    from softdesign.kinematics.pcc_fit import fit_links
    from softdesign.pipeline.api import build_through
    from softdesign.pipeline.child import HUGE_PAGES, run_in_child
    from softdesign.pipeline.stages.volume_sweep import material_of

    check_options(o)
    start = time.perf_counter()
    outcome = build_through(case_file, out, "actuation", progress=progress)
    if o.thread is None:  # the chambers as the case reinforces them (actuation.reinforcement)
        o = replace(o, thread=thread_of(outcome.case))
    material = material_of(outcome.case)
    if material.law is None:
        raise no_law_error(outcome.case, str(case_file))
    section = section_mesh_of(outcome.case, outcome.results["kinematics"], outcome.results["fit"], o.section,
                              o.size_mm, o.angular_count, o.layer_mm,
                              None if o.feed_pressures_kpa is None else len(o.feed_pressures_kpa))
    check_node_count(section, o.section + 1, "raise --size-mm or --layer-mm")
    target = None
    if o.target_q is not None:
        arc = fit_links(outcome.results["kinematics"].chain, o.target_q, ARC_SAMPLES)[o.section]
        target = (arc.kappa, arc.phi, arc.length)
    elif o.target_arc is not None:
        target = o.target_arc
    what = f"the finite-element solve of section {o.section + 1} ({len(section.points)} nodes)"
    fix = "raise --size-mm or --layer-mm, lower the pressures, or raise --timeout"
    try:
        answer = run_in_child(solve_in_child, (section, material.law, o, target), o.timeout_s, what, fix,
                              SIMULATE_MEMORY_BYTES, HUGE_PAGES)
    except MeshError as err:  # the child's failures, a non-converging solve among them
        raise SolveError(str(err)) from err
    return payload(o, section, material, answer, target, time.perf_counter() - start)


def write_to_table(case_file: Path, out: Path | None, o: SimulateOptions, progress: Any) -> dict[str, Any]:
    """``--target q --write``: build through actuation with ``simulate`` enabled for this section and q.

    The case file's ``simulate:`` block (or the defaults) with ``enabled: true``, ``q: [q]``, ``sections:
    [section + 1]`` and the command's mesh, bound and time: the simulate stage solves it and the actuation stage
    writes the pressures into the build folder's actuation.csv, the build's manifest recording that case.  The
    figures are the stage's for that section (as :func:`payload`, section numbered from 1, as --section).
    """
    from softdesign.config import load_case
    from softdesign.config.simulate import Simulate
    from softdesign.pipeline.api import build_through

    check_options(o)
    if o.target_q is None:
        raise ConfigError("simulate --write: writes the pressures found for --target q; give --target, not --pressures")
    case = load_case(case_file)
    if case.actuation is None:
        raise ConfigError("simulate: the case has no actuation chambers; add an `actuation:` block")
    settings = (case.simulate or Simulate()).model_dump()
    settings.update(enabled=True, q=[o.target_q], sections=[o.section + 1], size_mm=o.size_mm, layer_mm=o.layer_mm,
                    angular_count=o.angular_count, max_pressure_kpa=o.max_pressure_kpa, max_solves=o.max_solves,
                    timeout_s=o.timeout_s)
    start = time.perf_counter()
    outcome = build_through(case_file, out, "actuation", progress=progress,
                            case=case.model_copy(update={"simulate": Simulate.model_validate(settings)}))
    solve = dict(outcome.results["simulate"].summary["solves"][0])
    solve.update(section=o.section + 1, seconds=round(time.perf_counter() - start, 2),
                 written=str(outcome.build_dir / "actuation.csv"))
    return solve
