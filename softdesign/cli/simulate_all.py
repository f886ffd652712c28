"""`softdesign simulate CASE --all`: the whole device in one finite-element solve (the command's options, its
progress on a terminal and its printout; the work is :mod:`softdesign.pipeline.simulate_device`)."""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any

import typer

AllOpt = Annotated[bool, typer.Option(
    "--all", help="Solve the whole device at once (every section meshed, section 1's base clamped): at --q "
    "(supply single: P = q P*; per_chamber: the rod model's pressures at q) or at one --pressure.")]
QOpt = Annotated[float | None, typer.Option("--q", help="With --all: the q whose pressures are applied (default 1).")]
PressureOpt = Annotated[float | None, typer.Option(
    "--pressure", help="With --all: one supply pressure in kPa (actuation.supply: single).")]


def run_all(case_file: Path, out: Path | None, q: float | None, pressure: float | None, size_mm: float,
            layer_mm: float, timeout: float, as_json: bool, progress: Callable[[str], None]) -> dict[str, Any]:
    """The whole-device solve with the command's options; its payload (printed unless ``as_json``)."""
    from softdesign.cli.common import emit_json
    from softdesign.pipeline.device_command import run_device
    from softdesign.pipeline.device_figures import device_lines
    from softdesign.pipeline.simulate_device import DeviceOptions

    shown = not as_json and sys.stderr.isatty()
    options = DeviceOptions(q, pressure, size_mm, layer_mm, timeout_s=timeout,
                            step_progress=StepProgress() if shown else None)
    payload = run_device(case_file, out, options, progress)
    if as_json:
        emit_json(payload)
    else:
        for line in device_lines(payload):
            typer.echo(line)
        typer.echo("leaves out: " + "; ".join(payload["leaves_out"]))
    return payload


class StepProgress:
    """The solve's converged steps on a progress bar on stderr (:func:`softdesign.cli.progress.part_progress`): a
    context manager yielding the step listener, entered in the process that solves (it is pickled there)."""

    def __init__(self) -> None:
        self._bar: Any = None

    def __enter__(self) -> Callable[[float, list[float]], None]:
        from softdesign.cli.progress import part_progress

        self._bar = part_progress("simulate --all", enabled=True)
        tick = self._bar.__enter__()
        last = [time.perf_counter()]

        def told(t: float, history: list[float]) -> None:
            now = time.perf_counter()
            tick(f"load {t:.3f} of the pressures, {len(history)} iterations", now - last[0])
            last[0] = now

        return told

    def __exit__(self, *exc: object) -> None:
        self._bar.__exit__(*exc)
