"""``softdesign simulate CASE --all``: the whole device in one finite-element solve, at q or at one pressure.

The stages through actuation run (cached); every section is meshed
(:mod:`softdesign.mechanics.device_layout`, the sized chambers of ``supply:
single``, the feeds that cross a section of ``per_chamber`` as cavities), the
mesh's size is checked against :data:`~softdesign.limits.simulate.MAX_DEVICE_NODES`
before any solve, and the solve runs in a child process with ``--timeout``
and the solve's memory limit (:mod:`softdesign.mechanics.device`).  The
pressures: ``supply: single``, one pressure ``P = q P*`` in every chamber
(``--pressure P`` gives it directly); ``per_chamber``, the rod model's
pressures of every chamber at q (:func:`~softdesign.pipeline.rod_pressure.pressure_document`).
The figures against the design and the rod model are
:mod:`softdesign.pipeline.device_figures`'.
"""

from __future__ import annotations

import contextlib
import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from softdesign.errors import ConfigError, SolveError
from softdesign.limits.simulate import (
    MAX_ANGULAR_COUNT,
    MAX_DEVICE_NODES,
    MAX_LOAD_STEPS,
    MAX_NEWTON_ITERATIONS,
    MAX_PRESSURE_KPA,
    MAX_SIMULATE_SECONDS,
    MIN_ANGULAR_COUNT,
    MIN_SIZE_MM,
)

FloatList = list[float]


@dataclass(frozen=True)
class DeviceOptions:
    """``simulate --all``'s choices (kPa, mm, s), each checked by :func:`check_device_options` before work."""

    q: float | None
    pressure_kpa: float | None
    size_mm: float = 3.0
    layer_mm: float = 8.0
    angular_count: int = 12
    load_steps: int = 8
    max_iterations: int = 12
    max_cutbacks: int = 10  #: the smallest load step: 1 / (load_steps 2^max_cutbacks) of the load
    timeout_s: float = 600.0
    #: a context manager yielding the solve's step listener (the command line's progress), or None
    step_progress: Any = None


def check_device_options(o: DeviceOptions) -> None:
    """Refuse options outside the bounds (ConfigError: the option, the value, the bound, the fix)."""
    def bound(name: str, value: float, low: float, high: float) -> None:
        if not (math.isfinite(value) and low <= value <= high):
            raise ConfigError(f"simulate --all {name}: got {value:g}, expected a number in [{low:g}, {high:g}] "
                              "(softdesign/limits/simulate.py)")
    if o.q is not None and o.pressure_kpa is not None:
        raise ConfigError("simulate --all: give --q Q or --pressure P (kPa), not both (default: --q 1)")
    if o.q is not None:
        bound("--q", o.q, 0.0, 1.0)
    if o.pressure_kpa is not None:
        bound("--pressure", o.pressure_kpa, 0.0, MAX_PRESSURE_KPA)
    bound("--size-mm", o.size_mm, MIN_SIZE_MM, 100.0)
    bound("--layer-mm", o.layer_mm, MIN_SIZE_MM, 100.0)
    bound("--angular-count", o.angular_count, MIN_ANGULAR_COUNT, MAX_ANGULAR_COUNT)
    bound("--load-steps", o.load_steps, 1, MAX_LOAD_STEPS)
    bound("--max-iterations", o.max_iterations, 1, MAX_NEWTON_ITERATIONS)
    bound("--timeout", o.timeout_s, 1.0, MAX_SIMULATE_SECONDS)


def device_threads(case: Any) -> tuple[Any, Any]:
    """The case's threads as the finite elements take them (:class:`~softdesign.mechanics.reinforcement.HoopThread`:
    ``actuation.reinforcement``'s pitch, its thread's diameter and modulus): the hoop winding (None for ``kind:
    none``) and the backbone along the axis (None for ``backbone: free``), the same thread (as the rod model's
    walls take it)."""
    actuation = getattr(case, "actuation", None)
    if actuation is None:
        return None, None
    from softdesign.pipeline.simulate_run import reinforcement_thread

    thread = reinforcement_thread(actuation.reinforcement)
    return ((thread if actuation.reinforcement.kind == "hoop" else None),
            (thread if actuation.backbone == "inextensible" else None))


def check_device_case(case: Any, o: DeviceOptions) -> None:
    """Refuse (ConfigError) a case the whole-device solve cannot take with these options, before any stage runs."""
    if case.actuation is None:
        raise ConfigError("simulate --all: the case has no actuation chambers; add an `actuation:` block")
    if o.pressure_kpa is not None and case.actuation.supply != "single":
        raise ConfigError("simulate --all --pressure: one supply pressure is for actuation.supply: single; this case "
                          "has a pressure per chamber (the rod model's, at q): give --q")


def device_pressures(outcome: Any, o: DeviceOptions) -> tuple[float, FloatList, float | None]:
    """(q, every chamber's pressure kPa in the layout's order, P* or None) for the options (ConfigError if none)."""
    from softdesign.pipeline.rod_pressure import pressure_document

    case = outcome.case
    check_device_case(case, o)
    if case.actuation.supply == "single":
        top = float(outcome.results["actuation"].summary["design_pressure_kpa"])
        q = o.pressure_kpa / top if o.pressure_kpa is not None else (1.0 if o.q is None else o.q)
        if q * top > MAX_PRESSURE_KPA:
            raise ConfigError(f"simulate --all: the pressure {q * top:.1f} kPa (q {q:g} of P* {top:.1f} kPa) is above "
                              f"{MAX_PRESSURE_KPA:g} kPa (softdesign/limits/simulate.py); give a lower --q or "
                              "--pressure")
        count = len(outcome.results["design"].lengths)
        return q, [q * top] * count, top
    q = 1.0 if o.q is None else o.q
    document = pressure_document(outcome, q, None)
    return q, [float(p) for row in document["pressures_kpa"] for p in row], None


#: Quadratic nodes per corner node of a swept mesh (edge midpoints): 6.6 measured on the demo's device.
QUADRATIC_PER_CORNER = 7.0


def estimated_nodes(curve0: Any, field: Any, sections: int, o: DeviceOptions) -> int:
    """About how many quadratic nodes the device's mesh will have, before meshing it: per layer, the largest
    cross-section's area over an equilateral triangle's share of a node (``sqrt(3) h^2 / 2``) and the outer
    circle's nodes; a layer per ``layer_mm`` and four more per section (the chambers' ends)."""
    angles = 2.0 * np.pi * np.arange(o.angular_count) / o.angular_count
    rho = float(np.max(field.evaluate_grid(0.0, np.linspace(0.0, 1.0, 64), angles)))
    per_layer = np.pi * rho**2 / (np.sqrt(3.0) / 2.0 * o.size_mm**2) + o.angular_count
    layers = curve0.length / o.layer_mm + 5 * sections
    return int(QUADRATIC_PER_CORNER * per_layer * layers)


def device_mesh_of(outcome: Any, o: DeviceOptions) -> Any:
    """The device's mesh (:class:`~softdesign.mechanics.device.DeviceMesh`), its size checked (ConfigError)."""
    from softdesign.mechanics.device import assemble_device
    from softdesign.mechanics.device_layout import device_parts
    from softdesign.pipeline.body_spec import body_spec
    from softdesign.pipeline.simulate_run import quadratic_node_count
    from softdesign.pipeline.stages.actuation import actuation_layout

    case, kinematics, fit = outcome.case, outcome.results["kinematics"], outcome.results["fit"]
    layout = actuation_layout(case, kinematics, outcome.results["actuation"])
    if layout is None:
        raise ConfigError("simulate --all: the case has no actuation chambers; add an `actuation:` block")
    curve0 = kinematics.chain.shape.curve_at(0.0)
    guess = estimated_nodes(curve0, fit.field, layout.sections, o)
    if guess > 2 * MAX_DEVICE_NODES:  # the estimate is rough: refuse before meshing only what is far over
        raise ConfigError(f"simulate --all: the device's mesh would have about {guess} nodes (quadratic elements), far "
                          f"more than {MAX_DEVICE_NODES} (softdesign/limits/simulate.py MAX_DEVICE_NODES); raise "
                          "--size-mm or --layer-mm")
    device = assemble_device(device_parts(curve0, fit.field, body_spec(case), layout, o.size_mm, o.angular_count,
                                          o.layer_mm))
    nodes = quadratic_node_count(device.whole)
    if nodes > MAX_DEVICE_NODES:
        raise ConfigError(f"simulate --all: the device's mesh has {nodes} nodes (quadratic elements), more than "
                          f"{MAX_DEVICE_NODES} (softdesign/limits/simulate.py MAX_DEVICE_NODES); raise --size-mm or "
                          "--layer-mm")
    return device


#: The solve stops itself after this share of ``--timeout`` (between two steps), to report the largest load reached;
#: the child is killed at the timeout itself.
DEADLINE_SHARE = 0.8


class _Deadline:
    """The step listener that remembers the largest load reached and stops the solve past its deadline."""

    def __init__(self, seconds: float, pressures: FloatList, told: Any) -> None:
        self.end, self.pressures, self.told, self.t = time.perf_counter() + seconds, pressures, told, 0.0
        self.seconds = seconds

    def __call__(self, t: float, history: list[float]) -> None:
        self.t = max(self.t, t)
        if self.told is not None:
            self.told(t, history)
        if time.perf_counter() > self.end:
            reached = ", ".join(f"{self.t * p:.4g}" for p in self.pressures)
            raise SolveError(f"the whole device's solve was stopped after {self.seconds:.0f} s ({DEADLINE_SHARE:g} "
                             f"of --timeout) at {reached} kPa (load factor {self.t:.4g}, the largest it reached); "
                             "raise --timeout (simulate.timeout_s in a build), or coarsen the mesh (--size-mm, "
                             "--layer-mm)")


def solve_device_in_child(device: Any, law: Any, pressures: FloatList, o: DeviceOptions,
                          threads: tuple[Any, Any]) -> Any:
    """The worker (module-level: pickled by name): the solve and its figures
    (:class:`~softdesign.mechanics.device_measure.DeviceFigures`, the path's record, seconds); a solve that stops
    short gives them at the largest load it held (``load_factor`` below 1, ``stopped_because``)."""
    from softdesign.mechanics.device import solve_device
    from softdesign.mechanics.device_measure import measure_device
    from softdesign.mechanics.newton import NewtonSettings

    start = time.process_time()
    settings = NewtonSettings(load_steps=o.load_steps, max_iterations=o.max_iterations, max_cutbacks=o.max_cutbacks)
    with o.step_progress or contextlib.nullcontext() as told:
        deadline = _Deadline(DEADLINE_SHARE * o.timeout_s, pressures, told)
        solve = solve_device(device, law, np.asarray(pressures, float), settings, threads[0], on_step=deadline,
                             backbone=threads[1], keep_stop=True)
    return {"figures": measure_device(solve), "record": solve.record, "cpu_s": time.process_time() - start,
            "load_factor": solve.load_factor, "stopped_because": solve.stopped_because}
