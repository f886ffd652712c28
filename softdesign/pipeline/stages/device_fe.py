"""Stage: device_fe -- the single-supply device solved whole by finite elements at the exported q (off by default).

With ``simulate: {enabled: true}``, ``actuation: {supply: single}`` and a
material with a hyperelastic law, this stage, after actuation (whose sizing it
solves):

1. meshes the whole device (:func:`~softdesign.pipeline.simulate_device.device_mesh_of`:
   every section, its chamber and thread, the backbone thread), its size checked
   against :data:`~softdesign.limits.simulate.MAX_DEVICE_NODES` before any solve;
2. at every exported q above 0, solves it at ``P = q P*`` in a child process with
   ``simulate.timeout_s`` (:mod:`softdesign.mechanics.device`); a solve that finds no
   equilibrium past some load keeps its figures at the largest load it held, the
   larger q are not solved, and the verdict says that pressure does not reach the
   shape (a reason); a solve past its time fails the build (exit 1);
3. keeps each solve's figures (:func:`~softdesign.pipeline.device_figures.device_payload`:
   the deformed centerline against the designed chain and the rod model, each
   section's arc, the largest stress, stretch and thread tension) in
   ``simulate/device.json`` and the manifest; the times go to the run log.

The verdict then carries "FE: within X mm at P*" beside the rod model's line; a
stress over the material's tensile strength, a thread over its limit, or a load the
device does not reach is a reason.
``supply: per_chamber`` keeps the simulate stage's per-section pressure search.
"""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace
from typing import TYPE_CHECKING, Any

from softdesign.errors import ConfigError, MeshError, SolveError
from softdesign.pipeline.notices import Judgement
from softdesign.pipeline.stage import Stage
from softdesign.pipeline.store import Staging

if TYPE_CHECKING:
    from softdesign.config import Case

VERSION = 8  # 2: area-matched polygons, the backbone thread embedded in the elements; 3: a stop is kept, judged;
#             4: the thread's stabilised rule, patched ends, the thread's ends in the figures; 5: the thread's
#             hourglass control a penalty (its tension the centroid's), load steps bounded by length; 6: the
#             steps before the last converged to 1e-4, load_steps.PATH_RTOL (the figures move by 1e-7 relative); 7: the
#             first step at most FIRST_STEP_MU shear moduli; 8: curved chamber walls (mechanics.curved_walls), a
#             step the mixed fibre strain fails retried by the plain method
SUMMARY = "simulate/device.json"


def wanted(case: Case) -> bool:
    """Whether the build solves the whole device: simulate enabled on a single-supply device."""
    return bool(case.simulate is not None and case.simulate.enabled and case.actuation is not None
                and case.actuation.supply == "single")


def run_device_stage(case: Case, results: dict[str, Any]) -> dict[str, Any] | None:
    """Every exported q's whole-device solve (None unless :func:`wanted`)."""
    import time

    from softdesign.limits.simulate import DEVICE_MEMORY_BYTES, MAX_PRESSURE_KPA
    from softdesign.pipeline.child import HUGE_PAGES, run_in_child
    from softdesign.pipeline.device_figures import LEAVES_OUT, device_payload
    from softdesign.pipeline.simulate_device import (
        DeviceOptions,
        device_mesh_of,
        device_pressures,
        device_threads,
        solve_device_in_child,
    )
    from softdesign.pipeline.simulate_run import no_law_error
    from softdesign.pipeline.stages.volume_sweep import material_of

    if not wanted(case):
        return None
    material = material_of(case)
    if material.law is None:
        raise no_law_error(case, "simulate.enabled")
    s = case.simulate
    assert s is not None
    outcome = SimpleNamespace(case=case, results=results)
    top = float(results["actuation"].summary["design_pressure_kpa"])
    if top > MAX_PRESSURE_KPA:
        raise ConfigError(f"simulate.enabled: the design pressure P* {top:.1f} kPa is above the finite elements' "
                          f"bound {MAX_PRESSURE_KPA:g} kPa (softdesign/limits/simulate.py); use a stiffer thread or a "
                          "thinner material.min_wall_mm, which lower P*, or leave simulate off")
    base = DeviceOptions(None, None, s.size_mm, s.layer_mm, s.angular_count, timeout_s=s.timeout_s)
    device = device_mesh_of(outcome, base)
    solves, times = [], []
    for q in [q for q in case.export.q_values() if q > 0.0]:
        options = DeviceOptions(q, None, s.size_mm, s.layer_mm, s.angular_count, timeout_s=s.timeout_s)
        loads = device_pressures(outcome, options)
        start = time.perf_counter()
        try:
            answer = run_in_child(solve_device_in_child, (device, material.law, loads[1], options,
                                                          device_threads(case)), s.timeout_s,
                                  f"simulate: the whole device at q = {q:g} ({len(device.whole.points)} nodes)",
                                  "raise simulate.size_mm or simulate.layer_mm, or raise simulate.timeout_s",
                                  DEVICE_MEMORY_BYTES, HUGE_PAGES)
        except MeshError as err:  # the child's failures, a stopped solve among them
            raise SolveError(str(err)) from err
        seconds = {"mesh_s": 0.0, "solve_s": time.perf_counter() - start, "solve_cpu_s": answer["cpu_s"]}
        figures = device_payload(outcome, options, device, material, loads, answer, seconds)
        times.append(f"q = {q:g}: {seconds['solve_s']:.1f} s wall, {answer['cpu_s']:.1f} s CPU")
        del figures["seconds"]  # the same build gives the same bytes: times go to the run log
        solves.append(figures)
        if figures["reached"] is not None:  # a larger q asks more of a device that already stopped
            if q < max(case.export.q_values()):
                times.append(f"q above {q:g} not solved: the solve at q = {q:g} stopped")
            break
    return {"solves": solves, "leaves_out": list(LEAVES_OUT), "design_pressure_kpa": top,
            "shape_tolerance_mm": s.shape_tolerance_mm, "times": times}


def fe_line(summary: dict[str, Any]) -> str | None:
    """The verdict's line from the largest exported q's solve: "FE: within X mm at P*" and its limits (None when
    no solve reached its load: :func:`stop_reason` says so)."""
    if not summary or not summary["solves"] or any(s["reached"] is not None for s in summary["solves"]):
        return None
    top = max(summary["solves"], key=lambda s: s["q"])
    at = "P*" if abs(top["q"] - 1.0) < 1e-12 else f"{top['q']:g} P*"
    thread = top["thread"]
    share = f", thread at {100 * thread['fraction_of_limit']:.1f} % of its limit" if thread and thread[
        "fraction_of_limit"] is not None else ""
    strength = top["max_stress_kpa"]["tensile_strength_kpa"]
    stress = f" of {strength:.0f} kPa" if strength else ""
    return (f"FE: within {top['versus_design']['max_mm']:.3g} mm of the designed chain at {at} "
            f"({top['pressure_kpa']:.1f} kPa; the whole device in finite elements, the rod model "
            f"{top['versus_rod_model']['max_mm']:.3g} mm from it), largest stress {top['max_stress_kpa']['value']:.0f} "
            f"kPa{stress}, stretch {top['max_stretch']['value']:.3f}{share}")


def stop_reason(solve: dict[str, Any]) -> str:
    """The verdict's reason when the whole device found no equilibrium at its q: where it stopped, against P*."""
    held, top = solve["reached"], solve["design_pressure_kpa"]
    at = (f"{held['pressure_kpa']:.1f} kPa ({100 * held['pressure_kpa'] / top:.1f} % of P* {top:.1f} kPa)" if top
          else f"{100 * held['load_factor']:.1f} % of the rod model's pressures at q = {solve['q']:g}")
    stretch = solve["max_stretch"]
    return (f"FE: pressure does not reach the shape: the whole device in finite elements finds no equilibrium past "
            f"{at}, bent to q = {held['q']:.3g} (the designed chain within {solve['versus_design']['max_mm']:.3g} "
            f"mm there; largest stretch {stretch['value']:.2f} in section {stretch['section']}): the design asks "
            f"more pressure than the body holds; {_stop_fix(solve.get('thread'))}ask less curvature per pressure "
            "(larger chambers further from the axis, a thinner material.min_wall_mm) and check again")


def _stop_fix(thread: dict[str, Any] | None) -> str:
    """The end reinforcement a stopped device's reason offers: patched ends when its chambers' ends are bare."""
    if thread is None or thread.get("ends") != "bare":
        return ""
    return "its chambers' ends carry no thread: patch them (actuation.reinforcement.ends: patch), or "


def device_judgement(summary: dict[str, Any] | None) -> Judgement | None:
    """A margin (:func:`fe_line`), or a reason per limit the FE's figures cross (each names the key to change),
    and one when the device stopped short of its load (:func:`stop_reason`)."""
    if not summary or not summary["solves"]:
        return None
    stopped = [stop_reason(s) for s in summary["solves"] if s["reached"] is not None]
    tolerance = summary.get("shape_tolerance_mm")  # absent from device.json before device_fe v4
    line = fe_line(summary)
    reasons = list(stopped)
    for solve in summary["solves"]:
        stress, thread = solve["max_stress_kpa"], solve["thread"]
        if stress["tensile_strength_kpa"] and stress["value"] > stress["tensile_strength_kpa"]:
            reasons.append(f"FE at q = {solve['q']:g}: stress {stress['value']:.0f} kPa in section "
                           f"{stress['section']} > the tensile strength {stress['tensile_strength_kpa']:.0f} kPa; "
                           "use a stronger material (material.name)")
        if solve["reached"] is None and tolerance is not None and solve["versus_design"]["max_mm"] > tolerance:
            reasons.append(f"FE at q = {solve['q']:g}: pressure does not reach the shape: the whole device in "
                           f"finite elements lies {solve['versus_design']['max_mm']:.3g} mm from the designed chain "
                           f"({_worst_arc(solve)}) > simulate.shape_tolerance_mm {tolerance:g}: the rod model's "
                           "sizing does not hold at this pressure; ask less curvature per pressure (larger chambers "
                           "further from the axis) or raise the tolerance")
        if thread and thread["fraction_of_limit"] is not None and thread["fraction_of_limit"] > 1.0:
            what = "hoop thread (winding or end patches)" if thread.get("ends") == "patch" else "hoop thread"
            reasons.append(f"FE at q = {solve['q']:g}: {what} {thread['value']:.3g} N > its limit "
                           f"{thread['limit_n']:.3g} N; use a finer actuation.reinforcement.pitch_mm or a stronger "
                           "thread")
    return Judgement(judged=False, reasons=tuple(reasons), margins=() if reasons or line is None else (line,))


def _worst_arc(solve: dict[str, Any]) -> str:
    """The section whose fitted arc's curvature is furthest from its designed one's, as words."""
    arcs = [a for a in solve["sections"] if a["designed"]["kappa"] > 0.0]
    if not arcs:
        return "no section's arc to compare"
    worst = max(arcs, key=lambda a: abs(a["kappa"] / a["designed"]["kappa"] - 1.0))
    return (f"the furthest arc section {worst['section']}'s, kappa {worst['kappa']:.3g} 1/mm against "
            f"{worst['designed']['kappa']:.3g} designed")


def write_device(result: dict[str, Any] | None, staging: Staging) -> None:
    """``simulate/device.json`` without the times (nothing when the stage is off)."""
    if result is not None:
        staging.write_json(SUMMARY, {k: v for k, v in result.items() if k != "times"})


def load_device(build_dir: Path) -> dict[str, Any] | None:
    """The kept figures, or None when the build solved no device."""
    path = Path(build_dir) / SUMMARY
    return json.loads(path.read_text(encoding="utf-8")) if path.is_file() else None


def describe_device(result: dict[str, Any] | None) -> list[str]:
    """One line per solve (:func:`~softdesign.pipeline.device_figures.device_lines`' first ones)."""
    if result is None:
        return []
    from softdesign.pipeline.device_figures import versus_line

    return [f"q={s['q']:g} ({s['pressure_kpa']:.1f} kPa): "
            + ("" if s["reached"] is None else f"stopped at {s['reached']['pressure_kpa']:.1f} kPa (q = "
               f"{s['reached']['q']:.3g}), there ")
            + versus_line("designed chain", s["versus_design"])
            + "; " + versus_line("rod model", s["versus_rod_model"]) for s in result["solves"]]


STAGE = Stage(
    name="device_fe",
    version=VERSION,
    reads=("simulate", "actuation", "material", "export.q", "export.frames"),
    upstream=("kinematics", "fit", "design", "actuation"),
    compute=run_device_stage,
    write=write_device,
    load=lambda build_dir, results: load_device(build_dir),
    describe=describe_device,
    metrics=lambda result: {} if result is None else {"solves": [
        {k: v for k, v in s.items() if k not in ("centerline", "convergence")} for s in result["solves"]]},
    log=lambda result: [] if result is None else list(result["times"]),
    judge=device_judgement,
)
