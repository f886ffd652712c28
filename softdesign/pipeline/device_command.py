"""``softdesign simulate CASE --all``: build through actuation, mesh the whole device, solve it in a child process.

The command's orchestration, apart from :mod:`softdesign.pipeline.simulate_device` (the mesh, the pressures and
the child's solve), which the ``device_fe`` stage also calls: this module reaches up to the build API, the stage
must not.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from softdesign.errors import MeshError, SolveError
from softdesign.limits.simulate import DEVICE_MEMORY_BYTES
from softdesign.pipeline.simulate_device import (
    DeviceOptions,
    check_device_case,
    check_device_options,
    device_mesh_of,
    device_pressures,
    device_threads,
    solve_device_in_child,
)


def run_device(case_file: Path, out: Path | None, o: DeviceOptions, progress: Any) -> dict[str, Any]:
    """Build through actuation, mesh the device, solve it in a child process; the figures as a dict."""
    from softdesign.config import load_case
    from softdesign.pipeline.api import build_through
    from softdesign.pipeline.child import HUGE_PAGES, run_in_child
    from softdesign.pipeline.device_figures import device_payload
    from softdesign.pipeline.simulate_run import no_law_error
    from softdesign.pipeline.stages.volume_sweep import material_of

    check_device_options(o)
    start = time.perf_counter()
    case = load_case(case_file)
    check_device_case(case, o)
    outcome = build_through(case_file, out, "actuation", progress=progress, case=case)
    material = material_of(outcome.case)
    if material.law is None:
        raise no_law_error(outcome.case, str(case_file))
    q, pressures, top = device_pressures(outcome, o)
    device = device_mesh_of(outcome, o)
    meshed = time.perf_counter()
    what = f"the finite-element solve of the whole device ({len(device.whole.points)} nodes)"
    fix = "raise --size-mm or --layer-mm, lower the pressure, or raise --timeout"
    try:
        answer = run_in_child(solve_device_in_child, (device, material.law, pressures, o,
                                                      device_threads(outcome.case)), o.timeout_s, what, fix,
                              DEVICE_MEMORY_BYTES, HUGE_PAGES)
    except MeshError as err:  # the child's failures, a stopped solve among them
        raise SolveError(str(err)) from err
    times = {"mesh_s": meshed - start, "solve_s": time.perf_counter() - meshed, "solve_cpu_s": answer["cpu_s"]}
    return device_payload(outcome, o, device, material, (q, pressures, top), answer, times)
