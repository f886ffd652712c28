"""`softdesign simulate`: what pressures do to one section (finite elements), or which pressures reach a q."""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any

import typer

from softdesign.cli.common import (
    CaseArg,
    JsonOpt,
    OutOpt,
    check_output_file,
    emit_json,
    finite_number,
    note,
    run_guarded,
)
from softdesign.cli.simulate_all import AllOpt, PressureOpt, QOpt, run_all
from softdesign.errors import ConfigError

SectionOpt = Annotated[int, typer.Option(
    "--section", help="The section (link) to solve, numbered from 1 at the base (as actuation.csv and "
    "simulate.sections number them).")]
PressuresOpt = Annotated[str | None, typer.Option(
    "--pressures", help="Chamber pressures P1,P2,P3 in kPa (chambers 1, 2, 3 of the section, as actuation.csv).")]
FeedPressuresOpt = Annotated[str | None, typer.Option(
    "--feed-pressures", help="With --pressures: the feeds of distal chambers that cross the section, meshed as "
    "cavities with these pressures in kPa (one per feed, comma-separated); without it they are meshed solid.")]
TargetOpt = Annotated[float | None, typer.Option(
    "--target", help="Find the pressures whose section best matches the designed arc at this q.")]
TargetArcOpt = Annotated[str | None, typer.Option(
    "--target-arc", help="Find the pressures whose section best matches this arc rather than a designed one: "
    "KAPPA,PHI,L (1/mm, degrees, mm), as --json's arc gives them (phi in degrees), e.g. a forward solve's to "
    "search back. Otherwise as --target.")]
SizeOpt = Annotated[float, typer.Option("--size-mm", help="Element size in the cross-section, mm.")]
LayerOpt = Annotated[float, typer.Option("--layer-mm", help="Layer spacing along the section, mm.")]
#: --timeout's defaults, s: a section's solve or search, and the whole device's (--all: 8-9 minutes of CPU for the
#: sample device at P*; at 600 s it stopped short of P* on a machine running 1.7x slower than usual).
SECTION_TIMEOUT_S, DEVICE_TIMEOUT_S = 600.0, 1800.0
TimeoutOpt = Annotated[float | None, typer.Option(
    "--timeout", help=f"Longest time the solve may take, s (default {SECTION_TIMEOUT_S:g}; with --all "
    f"{DEVICE_TIMEOUT_S:g}).")]
FigureOpt = Annotated[Path | None, typer.Option(
    "--figure", help="Also draw the deformed centerline, its arcs and the convergence to this .png file.")]
WriteOpt = Annotated[bool, typer.Option(
    "--write", help="With --target: build with simulate enabled for this section and q, so that the build's "
    "actuation.csv carries the pressures found (as `simulate: {enabled: true}` does in build).")]
TimeLimitOpt = Annotated[float | None, typer.Option(
    "--time-limit", help="With --target: stop the search after the trial that passes this many seconds, keeping "
    "its best (exit 1: not converged). Below --timeout.")]
MaxPressureOpt = Annotated[float, typer.Option("--max-pressure", help="Upper bound of the inverse search, kPa.")]
ReplaceFigureOpt = Annotated[bool, typer.Option("--force", help="Replace the --figure file if it exists.")]

PRESSURES_FIX = "give three numbers in kPa separated by commas, e.g. --pressures 40,0,0"


def pressures_from_text(text: str) -> tuple[float, ...]:
    """``--pressures`` as three finite numbers (ConfigError naming the bad one)."""
    parts = text.split(",")
    if len(parts) != 3:
        raise ConfigError(f"--pressures: got {len(parts)} values in {text!r}, expected 3; {PRESSURES_FIX}")
    return tuple(finite_number(p, f"--pressures value {k + 1}", PRESSURES_FIX) for k, p in enumerate(parts))


def arc_from_text(text: str) -> tuple[float, float, float]:
    """``--target-arc`` as (kappa 1/mm, phi rad, L mm) from three finite numbers (ConfigError naming the bad one)."""
    fix = "give the curvature (1/mm), the bend's direction (degrees) and the length (mm), e.g. --target-arc 0.004,30,26"
    parts = text.split(",")
    if len(parts) != 3:
        raise ConfigError(f"--target-arc: got {len(parts)} values in {text!r}, expected 3; {fix}")
    kappa, phi, length = (finite_number(p, f"--target-arc value {k + 1}", fix) for k, p in enumerate(parts))
    return kappa, math.radians(phi), length


def feed_pressures_from_text(text: str) -> tuple[float, ...]:
    """``--feed-pressures`` as one or more finite numbers (ConfigError naming the bad one)."""
    fix = "give one pressure in kPa per feed crossing the section, separated by commas, e.g. --feed-pressures 20,0,0"
    return tuple(finite_number(p, f"--feed-pressures value {k + 1}", fix) for k, p in enumerate(text.split(",")))


def _check_figure_path(figure: Path | None, force: bool) -> None:
    """Refuse a ``--figure`` that is not a .png in an existing folder, or that writing would damage (an existing
    file without ``force``, anything but a regular file, a file in a build folder: as every ``--output``), before
    any work."""
    if figure is None:
        return
    if figure.suffix.lower() != ".png":
        raise ConfigError(f"--figure {figure}: expected a .png file, got the suffix {figure.suffix!r}")
    if not figure.parent.resolve().is_dir():
        raise ConfigError(f"--figure {figure}: the folder {figure.parent} does not exist; create it first")
    check_output_file("--figure", figure, force)


def _print(payload: dict[str, Any]) -> None:
    arc = payload["arc"]
    typer.echo(f"section {payload['section']}: {payload['mesh']['nodes']} nodes, {payload['mesh']['tets']} tets, "
               f"{payload['material']['name']} ({payload['material']['law']}), {payload['seconds']:.1f} s")
    typer.echo("pressures kPa: " + ", ".join(f"{p:.3f}" for p in payload["pressures_kpa"]))
    if "feed_pressures_kpa" in payload:
        typer.echo("feed pressures kPa: " + ", ".join(f"{p:.3f}" for p in payload["feed_pressures_kpa"]))
    typer.echo(f"best arc: kappa {arc['kappa_per_mm']:.6g} 1/mm, phi {math.degrees(arc['phi_rad']):.2f} deg, "
               f"L {arc['length_mm']:.4f} mm (misfit max {arc['misfit_max_mm']:.4f} mm)")
    # the cavity between its end walls, not actuation.csv's length_mm (the line at the chambers' distance over the
    # whole section): the extensions compare, the lengths do not
    lengths, rest = payload["chamber_lengths_mm"], payload["rest_chamber_lengths_mm"]
    typer.echo("chamber cavity lengths mm (each cavity between its end walls; actuation.csv's length_mm is the line "
               "at the chambers' distance over the whole section): " + ", ".join(f"{v:.4f}" for v in lengths)
               + " (extension " + ", ".join(f"{v / r:.4f}" for v, r in zip(lengths, rest, strict=True)) + ")")
    strength = payload["tensile_strength_kpa"]
    versus = f" (tensile strength {strength:.0f} kPa)" if strength else ""
    typer.echo(f"largest stretch {payload['max_stretch']:.4f}, largest principal stress "
               f"{payload['max_stress_kpa']:.2f} kPa{versus}")
    for k, step in enumerate(payload["convergence"], start=1):
        typer.echo(f"  step {k}: load {step['load_factor']:.3f}, {step['iterations']} iterations, residual "
                   f"{step['residuals_mN'][-1]:.2e} mN")
    if "target" in payload:
        t = payload["target"]
        asked = "the arc given" if t["q"] is None else f"q={t['q']:g}"
        typer.echo(f"target {asked}: error mm {', '.join(f'{e:.4f}' for e in t['error_mm'])} "
                   f"({'converged' if t['converged'] else 'NOT converged'}: {t['how']})")
    typer.echo("leaves out: " + "; ".join(payload["leaves_out"]))
    if "written" in payload:
        typer.echo(f"written to {payload['written']} (pressure_kpa, model estimates)")


def simulate(
    case_file: CaseArg,
    section: SectionOpt = 1,
    pressures: PressuresOpt = None,
    feed_pressures: FeedPressuresOpt = None,
    target: TargetOpt = None,
    target_arc: TargetArcOpt = None,
    out: OutOpt = None,
    size_mm: SizeOpt = 3.0,
    layer_mm: LayerOpt = 8.0,
    max_pressure: MaxPressureOpt = 100.0,
    timeout: TimeoutOpt = None,
    time_limit: TimeLimitOpt = None,
    figure: FigureOpt = None,
    force: ReplaceFigureOpt = False,
    write: WriteOpt = False,
    whole: AllOpt = False,
    q: QOpt = None,
    pressure: PressureOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """Solve one section under chamber pressures (hyperelastic finite elements), or find the pressures for a q.

    The section's base is clamped and each chamber's wall carries its pressure on the deformed surface. It
    reports the best arc through the deformed centerline, each chamber's length, the largest stretch and stress
    and the convergence; with --target, the pressures whose arc best matches the design at q, and with --write
    also into the build folder's actuation.csv (labelled as model estimates). A search shows its trials on a
    terminal (each one's residual and the time) and exits 1 when it does not converge. With --all, the whole
    device in one solve, against the designed chain and the rod model.
    """

    def action() -> None:
        if whole or q is not None or pressure is not None:
            if (not whole or pressures is not None or target is not None or target_arc is not None or write
                    or figure is not None):
                raise ConfigError("simulate: --q and --pressure go with --all (the whole device), and --all takes "
                                  "neither --pressures, --target, --target-arc, --write nor --figure")
            payload = run_all(case_file, out, q, pressure, size_mm, layer_mm,
                              DEVICE_TIMEOUT_S if timeout is None else timeout, as_json, note)
            if payload["reached"] is not None:  # the figures are printed; the solve did not reach its load
                note(f"simulate --all: {payload['reached']['stopped_because']}")
                raise typer.Exit(code=1)
            return
        from softdesign.pipeline.simulate_command import run_simulate, write_to_table
        from softdesign.pipeline.simulate_run import SimulateOptions

        _check_figure_path(figure, force)
        if section < 1:
            raise ConfigError(f"simulate --section: got {section}; sections are numbered from 1 at the base, as "
                              "actuation.csv numbers them")
        values = None if pressures is None else pressures_from_text(pressures)
        feeds = None if feed_pressures is None else feed_pressures_from_text(feed_pressures)
        arc = None if target_arc is None else arc_from_text(target_arc)
        shown = (target is not None or arc is not None) and not as_json and sys.stderr.isatty()
        options = SimulateOptions(section - 1, values, target, size_mm, layer_mm, max_pressure_kpa=max_pressure,
                                  target_arc=arc,
                                  timeout_s=SECTION_TIMEOUT_S if timeout is None else timeout,
                                  time_limit_s=time_limit,
                                  trial_progress=TrialProgress() if shown else None, feed_pressures_kpa=feeds)
        result = (write_to_table if write else run_simulate)(case_file, out, options, note)
        if figure is not None:
            from softdesign.io.atomic import write_bytes_atomically
            from softdesign.report.simulate_figures import simulate_figure_png

            write_bytes_atomically(figure, simulate_figure_png(result))
        emit_json(result) if as_json else _print(result)
        if "target" in result and not result["target"]["converged"]:
            found = result["target"]
            reach = ("out of the section's reach: its best within the bounds" if found.get("best_within_bounds")
                     else "the search stopped short")
            asked = "--target-arc" if target is None else f"--target {target:g}"
            note(f"simulate {asked}: not within tolerance ({reach}, error "
                 f"{math.hypot(*found['error_mm']):.4g} mm)")
            raise typer.Exit(code=1)

    run_guarded(action)


class TrialProgress:
    """The inverse's trials on a progress bar on stderr (:func:`softdesign.cli.progress.part_progress`): a
    context manager yielding the trial listener, entered in the process that solves (it is pickled there)."""

    def __init__(self) -> None:
        self._bar: Any = None

    def __enter__(self) -> Callable[[int, Any, float, float], None]:
        from softdesign.cli.progress import part_progress

        self._bar = part_progress("simulate --target", enabled=True)
        tick = self._bar.__enter__()

        def told(trial: int, pressures: Any, error_mm: float, seconds: float) -> None:
            kpa = ", ".join(f"{p:.2f}" for p in pressures)
            tick(f"trial {trial}, residual {error_mm:.3g} mm at {kpa} kPa", seconds)

        return told

    def __exit__(self, *exc: object) -> None:
        self._bar.__exit__(*exc)
