"""`softdesign pcc design CASE_FILE --d D`: one PCC section per link of a built design, and its chambers.

Parsing and printing live here; the fit is :mod:`softdesign.kinematics.pcc_fit`.
Registered on ``pcc_app`` in :mod:`softdesign.pcc_cli`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer

from softdesign.cli.common import TEXT_ANGLES, CaseArg, JsonOpt, OutOpt, emit_json, note, run_guarded
from softdesign.cli.pcc_bounds import MAX_DESIGN_SAMPLES
from softdesign.cli.pcc_options import spacing_from_text
from softdesign.errors import ConfigError, errors_named_for
from softdesign.kinematics.arc_tolerance import ARC_TOLERANCE_MM


def _print_design(document: dict, case_file: Path) -> None:
    typer.echo(f"{case_file}: one PCC arc per link; d = {', '.join(f'{v:g}' for v in document['d'])} mm")
    head = (f"{'link':>4}  {'l range':>13}  {'kappa [1/mm]':>12}  {'phi [deg]':>9}  {'L [mm]':>8}  "
            f"{'theta [deg]':>11}  {'chambers l1 l2 l3 [mm]':>24}  {'strain e1 e2 e3 [%]':>23}  "
            f"{'max [mm]':>9}  {'rms [mm]':>9}  "
            f"{'tip [mm]':>9}  {'tangent [deg]':>13}  {'rotation [deg]':>14}")
    for pose in document["poses"]:
        typer.echo(f"\nq = {pose['q']:g}")
        typer.echo(head)
        for k in pose["links"]:
            chambers = " ".join(f"{v:7.3f}" for v in k["chamber_lengths"])
            strain = " ".join(f"{100 * v:+7.2f}" for v in k["chamber_strain"])
            typer.echo(
                f"{k['index']:>4}  {k['l_start']:6.4f}-{k['l_end']:6.4f}  {k['kappa']:12.6f}  "
                f"{math.degrees(k['phi']):9.3f}  {k['length']:8.3f}  {math.degrees(k['theta']):11.4f}  "
                f"{chambers:>24}  {strain:>23}  "
                f"{k['backbone_max_mm']:9.3g}  {k['backbone_rms_mm']:9.3g}  {k['tip_error_mm']:9.3g}  "
                f"{math.degrees(k['tangent_error_rad']):13.2g}  {math.degrees(k['rotation_error_rad']):14.2g}"
            )
        w = pose["worst"]
        typer.echo(
            f"worst: link {w['index']}, backbone off by up to {w['backbone_max_mm']:.3g} mm "
            f"(rms {w['backbone_rms_mm']:.3g} mm), tip {w['tip_error_mm']:.3g} mm, "
            f"tangent {math.degrees(w['tangent_error_rad']):.3g} deg, "
            f"rotation {math.degrees(w['rotation_error_rad']):.3g} deg"
        )
    for line in document.get("warnings", []):
        typer.echo(f"warning: {line}")
    typer.echo(f"\n{TEXT_ANGLES}; convention: {document['convention']}")


def arc_warnings(document: dict, warn_mm: float) -> list[str]:
    """One sentence per q and link whose arc misses the backbone by more than ``warn_mm`` (backbone_max_mm)."""
    return [
        f"q = {pose['q']:g}, link {k['index']}: one constant-curvature arc misses the design by up to "
        f"{k['backbone_max_mm']:.3g} mm (--warn-mm {warn_mm:g}) and "
        f"{math.degrees(k['tangent_error_rad']):.3g} deg of end tangent; "
        f"a PCC section cannot make this link: use more links (softdesign design CASE --tolerance-mm {warn_mm:g})"
        for pose in document["poses"] for k in pose["links"] if k["backbone_max_mm"] > warn_mm
    ]


def design(
    case_file: CaseArg,
    d: Annotated[
        str,
        typer.Option("--d", help='Chamber distance from the backbone, mm: one value ("4") or one per link ("4,4,3.5").',
                     show_default=False),
    ],
    json_out: JsonOpt = False,
    out: OutOpt = None,
    samples: Annotated[int, typer.Option("--samples", min=3, max=MAX_DESIGN_SAMPLES,
                                         help="Backbone samples per link for the fit.")] = 201,
    warn_mm: Annotated[float, typer.Option(
        "--warn-mm", help="Warn when a link's arc misses its backbone by more than this, mm.")] = ARC_TOLERANCE_MM,
) -> None:
    """One PCC section per link of the built design at every export q, and the chambers it needs.

    Runs the build through kinematics (cached), then per export q and link fits
    one constant-curvature arc from the link's start frame to its backbone and
    reports kappa, phi, L, theta, the three chamber lengths (mm), their strain
    against q = 0 and how far the arc misses the design (backbone max and RMS,
    tip position, tangent and rotation errors).  JSON: {"d": [mm per link],
    "poses": [{"q", "links": [{"index", "l_start", "l_end", "kappa", "phi",
    "length", "theta", "dh" (Zou et al.'s five D-H rows), "chamber_lengths", "chamber_strain", "backbone_max_mm",
    "backbone_rms_mm", "tip_error_mm", "tangent_error_rad",
    "rotation_error_rad"}], "worst": {"index", and those five errors}}],
    "convention", "warnings": [one sentence per q and link whose backbone_max_mm
    exceeds --warn-mm]}.
    """

    def action() -> None:
        from softdesign.kinematics.pcc_fit import design_document, design_sections
        from softdesign.pipeline.api import build_through

        spacing_from_text(d, None)  # numbers > 0: fail before building
        if not (math.isfinite(warn_mm) and warn_mm > 0.0):
            raise ConfigError(f"--warn-mm must be a finite number > 0 mm, got {warn_mm:g}")
        outcome = build_through(case_file, out, target="kinematics", progress=note)
        chain = outcome.results["kinematics"].chain
        spacing = spacing_from_text(d, chain.count, where=f"{case_file} ({chain.count} links, one section each)")
        with errors_named_for(case_file):
            result = design_sections(chain, outcome.case.export.q_values(), spacing, samples)
        for line in result.notes:
            note(f"warning: {case_file}: {line}")
        document = design_document(result)
        document["warnings"] = arc_warnings(document, warn_mm)
        for line in document["warnings"]:
            note(f"warning: {case_file}: {line}")
        if json_out:
            emit_json(document)
        else:
            _print_design(document, case_file)

    run_guarded(action)
