"""`softdesign pressure CASE [--q Q | --pressure P] [--json]`: the rod model's shape, from the build's rod model.

Parsing and printing live here; the numbers are :mod:`softdesign.pipeline.rod_pressure`'s.
"""

from __future__ import annotations

import math
from typing import Annotated

import typer

from softdesign.cli.common import CaseArg, JsonOpt, OutOpt, emit_json, note, run_guarded
from softdesign.errors import ConfigError, errors_named_for

#: The highest --pressure accepted, kPa (above every preset's tensile strength).
MAX_PRESSURE_KPA = 100_000.0


def _check(q: float | None, pressure: float | None) -> None:
    if q is not None and pressure is not None:
        raise ConfigError("pressure: give --q or --pressure, not both")
    if q is not None and not (math.isfinite(q) and 0.0 <= q <= 1.0):
        raise ConfigError(f"pressure: --q must be in [0, 1], got {q:g}")
    if pressure is not None and not (math.isfinite(pressure) and 0.0 <= pressure <= MAX_PRESSURE_KPA):
        raise ConfigError(f"pressure: --pressure must be in [0, {MAX_PRESSURE_KPA:g}] kPa, got {pressure:g}")


def pressure(
    case_file: CaseArg,
    q: Annotated[float | None, typer.Option("--q", help="The morph's q in [0, 1] (single supply: P = q P*).",
                                            show_default=False)] = None,
    pressure_kpa: Annotated[float | None, typer.Option("--pressure", help="One supply pressure, kPa (supply: single).",
                                                       show_default=False)] = None,
    json_out: JsonOpt = False,
    out: OutOpt = None,
) -> None:
    """The rod model's shape, chamber lengths and deviation at one q or pressure, from the build's rod model.

    Reads actuation/rod.json, which `softdesign build CASE` writes (with --out DIR, give the same --out), after
    checking that the case file and its inputs are those the build was made from (docs/reference.md: the rod
    model).  supply: single: the design pressure P*, the pressure and q = P / P*, each section's arc (kappa 1/mm,
    phi rad, length mm), each chamber's length and the largest distance from the designed chain at q;
    per_chamber: every chamber's pressure at q (kPa) and each section's arc (a q off the build's grid runs the
    stages through fit, cached, in seconds).  JSON: those keys, with "centerline" (the model's points, mm) for a
    single supply and "seconds" (the model's time).  Default: q = 1.
    """

    def action() -> None:
        from softdesign.pipeline.rod_pressure import answer_if_unchanged

        _check(q, pressure_kpa)
        quick = answer_if_unchanged(case_file, out, q, pressure_kpa)  # the build's own case and inputs: no models
        if quick is not None:
            _answer(quick, json_out)
            return
        from softdesign.config import load_case
        from softdesign.pipeline.rod_pressure import check_pressure_case, pressure_from_build

        case = load_case(case_file)
        with errors_named_for(case_file):
            check_pressure_case(case, pressure_kpa)
            document = pressure_from_build(case, str(case_file), out, q, pressure_kpa)
        if document is None:  # a per-chamber q off the build's grid: the stages through fit, as the build has them
            from softdesign.pipeline.api import build_through
            from softdesign.pipeline.rod_pressure import pressure_document

            outcome = build_through(case_file, out, target="fit", progress=note, case=case)
            with errors_named_for(case_file):
                document = pressure_document(outcome, q, pressure_kpa)
        _answer(document, json_out)

    run_guarded(action)


def _answer(document: dict, json_out: bool) -> None:
    if json_out:
        emit_json(document)
        return
    _print(document)


def _print(document: dict) -> None:
    if document["supply"] == "single":
        typer.echo(f"P = {document['pressure_kpa']:.2f} kPa (q = {document['q']:.4g} of P* = "
                   f"{document['design_pressure_kpa']:.2f} kPa); {document['deviation_mm']:.3g} mm from "
                   f"the designed chain at that q")
    else:
        typer.echo(f"q = {document['q']:g}: every chamber's pressure, kPa")
    for i, s in enumerate(document["sections"]):
        extra = ""
        if document["supply"] == "per_chamber":
            extra = "  pressures " + ", ".join(f"{p:.2f}" for p in document["pressures_kpa"][i])
            lengths = ", ".join(f"{v:.3f}" for v in document["chamber_lengths_mm"][i])
        else:
            lengths = f"{document['chamber_lengths_mm'][i]:.3f}"
        typer.echo(f"section {s['section']}: kappa {s['kappa']:.5f} 1/mm, phi {s['phi']:.4f} rad, length "
                   f"{s['length']:.3f} mm; chamber length {lengths} mm{extra}")
    typer.echo(f"rod model: {1000 * document['seconds']:.0f} ms")
